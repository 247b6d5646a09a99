"""The nearest "yes" for one part (uniform pressure) that no plan orients.

When the complete search finds no plan of up to ``N`` pins whose final set
fits the tolerance, the engineer asks what would. For one part the axes are:

* **a looser tolerance**: the smallest ``tolerance_deg`` (on a half-degree
  ladder, up to ``MAX_TOLERANCE``) at which one of the plans the search
  kept (the recommended one and the other verified candidates) orients the
  part on *held-out* trials: trials from a seed no search or selection drew
  from (``VerifySettings.held_out``). For each plan the answer is the
  narrowest arc that holds the claim's count of those trials (the rule's
  ``max_failures`` left out), rounded up to the ladder, and the verdict at
  that tolerance is the claim's own judgement of the same finals. When no
  kept plan gets there (they end in several sets far apart), the complete
  fixed-pin search runs again at looser tolerances, by bisection, and its
  plan (certified on held-out trials) is the answer, at the narrowest
  tolerance its held-out trials allow (which may be tighter than the
  tolerance of the search that found it);
* **moving pins**: what the search's moving-pin stage found (it runs when
  pin speeds are configured and fixed pins do not orient the part);
* **a sensor**: when the recommended plan ends in a few sets within the
  tolerance, a force/torque-sensing pin that tells them apart finishes the
  job (``pinfeed sense``);
* **more pins or a wider pin grid**: not searched here; the line says how.

The tolerance answer is a statement about that plan at that tolerance on
trials it was not chosen on; a search at the looser tolerance may find a
plan with fewer pins, which this does not look for.
"""
from __future__ import annotations

import dataclasses
import math

import numpy as np

from pipeline.planning.claims import orient
from pipeline.planning.core.nearest_axes import LADDER, MAX_TOLERANCE, SUBJECT_PART, more_pins_axis
from pipeline.planning.core.types import TightEntry
from pipeline.planning.tight.judge import TrialBench
from pipeline.planning.tight.records import FixedSearch
from pipeline.progress import NO_DEADLINE, Deadline, OutOfTime


def _axis(axis: str, found: bool, statement: str, **extra) -> dict:
    return {"axis": axis, "found": found, "holds": found, "statement": statement, **extra}


STEPS_BELOW = 3  # searches half a step below the plan found before the bisection (see _next_tolerance)


def loosest_needed(finals, jammed, n_trials: int, order: int, required: float, confidence: float,
                   rule: str) -> float | None:
    """The smallest tolerance (deg, on the ``LADDER``) whose claim the finals
    meet: the narrowest arc holding all but the allowed failures; None when
    no tolerance up to ``MAX_TOLERANCE`` does (or too few trials)."""
    keep = np.asarray(finals)[~np.asarray(jammed)]
    allowed = orient.max_failures(n_trials, required, confidence, rule)
    arc = None if allowed < 0 else orient.narrowest_arc(keep, n_trials - allowed, order)
    if arc is None:
        return None
    tol = max(LADDER, math.ceil(arc[1] / LADDER - 1e-9) * LADDER)
    while tol <= MAX_TOLERANCE:  # the claim's own judgement at that tolerance
        if orient.judge(keep, n_trials, tol, order, required, confidence, rule=rule)["orients"]:
            return float(tol)
        tol += LADDER
    return None


def searched_tolerance(part, settings, pins: dict, depth: int, candidates: int, progress=None,
                       deadline: Deadline = NO_DEADLINE, reuse=None) -> tuple | None:
    """``(tolerance, plan, exact)``: the smallest tolerance on the ``LADDER`` up to
    ``MAX_TOLERANCE`` at which the complete fixed-pin search over ``pins``
    (label -> height, mm) finds a plan of up to ``depth`` pins, certified on
    its held-out trials, by bisection; None when none does at ``MAX_TOLERANCE``.

    Exact bisection: on the same trials, a sequence that orients within ``t``
    orients within any looser tolerance, and its nominal finals pass the
    looser filter too, so "some plan orients" is monotone in ``t``. A plan
    found answers at its own tolerance (:func:`_own_tolerance`), where the
    upper end moves: never looser than the plain bisection's answer. The
    first steps are half a step below it (:func:`_next_tolerance`). The
    searches reuse the rollouts of ``reuse`` (the planner's own search, say)
    when it shares them (``FixedPinSearch.shares_rollouts_with``), else
    those of the first: an outcome depends on its key only, so each finds
    what it would alone. Under a time limit (``deadline``) a search it cuts
    short gives no answer at its tolerance (over part searches the bisection
    would give a wrong one): the first raises :class:`~pipeline.progress.OutOfTime`;
    a later one ends the bisection with the loosest tolerance it certified,
    an upper bound (``exact`` False). Its searches keep no evidence."""
    from pipeline.planning.tight.complete import FixedPinSearch

    donor = reuse  # whose rollouts serve the searches (tolerance changes no outcome)

    def found(t):
        nonlocal donor
        claims = dataclasses.replace(settings.claims, tolerance_deg=float(t))
        search = FixedPinSearch(part, pins, settings.friction, claims, settings.verify, settings.search)
        if donor is not None and search.shares_rollouts_with(donor):
            search.reuse_rollouts(donor)
        else:
            donor = search
        search.evidence = False
        result = search.run(depth, candidates=candidates, keep=1, progress=_at(progress, t), deadline=deadline)
        if not result.complete:
            raise OutOfTime(f"the search at {t:g} deg was not finished")
        return _own_tolerance(result.plans[0], search.bench, settings.claims, lo) if result.plans else None

    lo = math.floor(settings.claims.tolerance_deg / LADDER) * LADDER  # does not orient (the question)
    first = found(MAX_TOLERANCE)
    if first is None:
        return None
    hi, best = first
    tries = 0
    while hi - lo > LADDER + 1e-9:
        mid = _next_tolerance(lo, hi, tries)
        tries += 1
        try:
            got = found(mid)
        except OutOfTime:
            return hi, best, False  # certified at hi; tighter ones not decided
        if got is None:
            lo = mid
        else:
            hi, best = got
    return hi, best, True


def _next_tolerance(lo: float, hi: float, tries: int) -> float:
    """The tolerance to search next between ``lo`` (no plan) and ``hi`` (the
    plan found last), ``tries`` searches after the widest: half a step below
    ``hi`` for the first ``STEPS_BELOW``, then the middle, on the ``LADDER``.

    A plan found is often the answer, or close: a "no" half a step below it
    settles the question in one search, and a "yes" moves ``hi`` to the new
    plan's own tolerance. The searches just short of the answer, where near
    misses are screened deep, are the dear ones; the plain bisection made
    four of them on a 20 mm triangle, where this makes one."""
    return hi - LADDER if tries < STEPS_BELOW else math.floor((lo + hi) / 2 / LADDER) * LADDER


def _own_tolerance(plan, bench: TrialBench, claims, asked: float) -> tuple:
    """``(tolerance, plan)``: the smallest tolerance on the ``LADDER`` above
    ``asked`` (the question's, which no search answered) at which ``plan``,
    certified by a search on ``bench``, orients the part on its held-out
    trials (:func:`loosest_needed`; never looser than the search's), and the
    plan with its held-out verdict at that tolerance. The certification
    replayed those trials, so the bench has their states and this rolls out
    nothing."""
    rows = bench.held_out(len(plan.heights))
    speeds = plan.speeds or (0.0,) * len(plan.heights)
    tf, jam = bench.replay(np.atleast_2d(np.asarray(plan.heights, float)), np.atleast_2d(np.asarray(speeds, float)),
                           rows)
    searched = float(plan.verdict["tolerance_deg"])
    tol = loosest_needed(tf[0], jam[0], rows[0].size, bench.order, claims.required, claims.confidence, claims.rule)
    if tol is not None:
        # held-out trials easier than the ones that rejected it at the asked tolerance: the next step
        tol = max(tol, asked + LADDER)
    if tol is None or tol >= searched:
        return searched, plan
    verdict = orient.judge(tf[0][~jam[0]], rows[0].size, tol, bench.order, claims.required, claims.confidence,
                           interval=True, rule=claims.rule)
    return tol, dataclasses.replace(plan, verdict=verdict)


def _at(progress, tolerance):
    """``progress`` with each line saying which tolerance the search tries."""
    if progress is None:
        return None
    return lambda line: progress(f"nearest yes, tolerance {tolerance:g} deg: {line}")


def _kept_tolerance(part, settings, plans, deadline: Deadline, reuse=None) -> tuple:
    """``(best, replayed)``: the kept ``plans`` replayed on held-out trials
    while ``deadline`` lasts; ``best`` is ``(tolerance, labels, heights,
    speeds, verdict)`` of the one with the smallest tolerance (None if none
    orients within ``MAX_TOLERANCE``), ``replayed`` how many were replayed.
    The replays read the trial states of ``reuse`` (the planner's search,
    whose memo the final verification filled with these replays)."""
    bench = TrialBench(part, settings.friction, settings.claims, settings.verify, settings.search)
    if reuse is not None:
        bench.kept = reuse.bench.kept
    claims = settings.claims
    best, tried = None, 0
    for labels, heights, speeds in plans:
        if deadline.over():
            break  # the answer names the plans it replayed
        tried += 1
        rows = bench.held_out(len(heights))
        tf, jam = bench.replay(np.atleast_2d(np.asarray(heights, float)),
                               np.atleast_2d(np.asarray(speeds or [0.0] * len(heights), float)), rows)
        tol = loosest_needed(tf[0], jam[0], rows[0].size, bench.order, claims.required, claims.confidence,
                             claims.rule)
        if tol is not None and (best is None or tol < best[0]):
            verdict = orient.judge(tf[0][~jam[0]], rows[0].size, tol, bench.order, claims.required,
                                   claims.confidence, rule=claims.rule)
            best = (tol, labels, heights, speeds, verdict)
    return best, tried


def part_tolerance_axis(part, settings, plans, pins: dict | None = None, depth: int | None = None,
                        progress=None, deadline: Deadline = NO_DEADLINE, reuse=None) -> dict:
    """The smallest tolerance at which one of ``plans`` (``(labels, heights,
    speeds)``) orients ``part`` on held-out trials; when none does within
    ``MAX_TOLERANCE`` and ``pins`` are given, the smallest at which the
    complete search over them finds a plan (:func:`searched_tolerance`).

    Without ``pins`` (a search cut by its time limit: a bisection over
    searches would be cut too) only the kept plans are replayed. Under a
    time limit (``deadline``) the kept plans are replayed while it lasts,
    and a bisection it cuts gives no tolerance: the axis then answers from
    the kept plans replayed and says so (``kept_plans_only``, ``replayed``;
    ``searches_cut`` when the limit cut the searches at looser tolerances).
    ``reuse``: a search whose rollouts the searches may share
    (:func:`searched_tolerance`)."""
    claims = settings.claims
    best, tried = _kept_tolerance(part, settings, plans, deadline, reuse)
    cut = tried < len(plans)  # the limit passed before every kept plan was replayed
    searches_cut, bound = False, False
    if best is None and pins is not None and not cut:
        try:
            searched = searched_tolerance(part, settings, pins, depth or settings.search.depth,
                                          settings.search.candidates, progress, deadline, reuse)
        except OutOfTime:
            searches_cut = True
        else:
            if searched is not None:
                tol, plan, exact = searched
                best = (tol, plan.labels, plan.heights, plan.speeds, plan.verdict)
                searches_cut = bound = not exact
    kept_only = pins is None or cut or (searches_cut and not bound)
    flags = {"kept_plans_only": kept_only, "replayed": tried, "searches_cut": searches_cut}
    if best is None and tried == 0 and plans:
        return _axis("tolerance", False, "not searched: no time was left to replay the kept plans", **flags)
    if best is None and kept_only:
        how = "cut by the time limit" if searches_cut else "not run"
        return _axis("tolerance", False, f"none of the {tried} kept plan(s) replayed orients the part within "
                                         f"{MAX_TOLERANCE:g} deg on held-out trials; the search at looser "
                                         f"tolerances was {how}", **flags)
    if best is None:
        return _axis("tolerance", False, f"no plan of up to {depth or settings.search.depth} fixed pins orients "
                                         f"the part within {MAX_TOLERANCE:g} deg on held-out trials", **flags)
    tol, labels, heights, speeds, verdict = best
    scope = f"; among the {tried} kept plan(s) replayed, no search at looser tolerances" if kept_only else ""
    if bound:
        scope = "; an upper bound: the time limit cut the search at tighter tolerances"
    return _axis("tolerance", True, f"a tolerance of {'at most ' if bound else ''}{tol:g} deg "
                                    f"(asked: {claims.tolerance_deg:g} deg{scope})",
                 value=tol, unit="deg", plan=list(labels), pin_heights_mm=[float(h) for h in heights],
                 pin_speeds=[float(v) for v in (speeds or ())], verdict=verdict, **flags)


def part_moving_axis(entry: TightEntry, moving: FixedSearch | None, cut: bool = False) -> dict:
    """What the moving-pin stage (``moving``: its record, ``None`` when it
    did not run) found for the part of ``entry`` (``cut``: a time limit
    ended the search before that stage)."""
    if moving is None and cut:
        return _axis("moving pins", False, "not searched: the time limit ended the search before the moving pins",
                     partial=True)
    rec = entry.recommended
    moving_plan = rec is not None and any(rec.pin_speeds or ())
    if moving is not None and moving.orients and not moving_plan:
        found = list(moving.plans[0].labels)
        if found in [list(r.pins) for r in entry.rejected or ()]:
            return _axis("moving pins", False, f"searched: {' '.join(found)} orients on the search's trials "
                                               "but fails the final verification")
        return _axis("moving pins", False, f"found, not verified: {' '.join(found)} orients on the search's "
                                           "trials; the time limit left no time to verify it", partial=True)
    if moving is not None and moving.time_limit is not None and not moving.complete and not moving.orients:
        return _axis("moving pins", False, "searched in part: the time limit cut the moving-pin search "
                                           f"(not searched: {'; '.join(moving.unsearched)})", partial=True)
    if moving is None:
        return _axis("moving pins", False, "not searched: no pin speeds given (planner.dynamic.speeds, --speeds)")
    if moving.orients and moving_plan:
        n = sum(1 for v in rec.pin_speeds if v)
        return _axis("moving pins", True, f"{n} moving pin(s)", value=n, unit="moving pins",
                     plan=list(rec.pins), verdict=(rec.verification.orientation or None) if rec.verification else None)
    return _axis("moving pins", False, "searched after the fixed pins: no moving-pin plan orients the part either")


def sensor_axis(entry: TightEntry) -> dict:
    """A force/torque-sensing pin after the recommended plan, when it ends in a few sets."""
    rec = entry.recommended
    verdict = (rec.verification.orientation if rec is not None and rec.verification else None) or {}
    sets = verdict.get("sets_within_tolerance")
    if rec and sets and sets > 1:
        return _axis("sensor", True, f"a force/torque-sensing pin after {' '.join(rec.pins)} tells its "
                                     f"{sets} sets apart (pinfeed sense)", value=int(sets), unit="sets",
                     plan=list(rec.pins))
    return _axis("sensor", False, "no recommended plan ends in a few sets for a sensor to tell apart")


def part_nearest_yes(part, settings, entry: TightEntry, fixed: FixedSearch, moving: FixedSearch | None, plans,
                     pins: dict | None = None, progress=None, deadline: Deadline = NO_DEADLINE,
                     moving_cut: bool = False, reuse=None) -> dict:
    """The nearest "yes" on each axis for a part no plan orients (see the
    module docstring); ``entry``: its tight entry; ``fixed`` and
    ``moving``: the fixed-pin and moving-pin searches' records (``moving``
    ``None`` when that stage did not run); ``plans``: the kept plans
    ``(labels, heights, speeds)``, best first; ``pins``: the fixed pins the
    search chose from (label -> height, mm), searched again at looser
    tolerances when no kept plan answers. ``deadline``: a time limit; one
    that passes before the tolerance answer is whole leaves it to the kept
    plans replayed, and the axis says so (see :func:`part_tolerance_axis`).
    Without ``pins`` only the kept plans are replayed; ``moving_cut``: a
    time limit ended the search before its moving pins; ``reuse``: the
    planner's fixed-pin search, whose rollouts the searches at looser
    tolerances share (:func:`searched_tolerance`)."""
    depth = entry.depth
    tolerance = part_tolerance_axis(part, settings, plans, pins, depth, progress, deadline, reuse)
    more = more_pins_axis(depth)
    if fixed.time_limit is not None and not fixed.complete and fixed.complete_to < (depth or 0):
        # depth N itself was not searched in full
        more = _axis("more pins", False, "not searched: the time limit cut the search before its depth; "
                                         "run with a longer --time-limit first", partial=True)
    return {"subject": SUBJECT_PART, "plans_tried": [list(p[0]) for p in plans[:tolerance["replayed"]]],
            "axes": [tolerance, part_moving_axis(entry, moving, moving_cut), sensor_axis(entry), more]}
