"""Plans with tight propagation for one part and one friction, verified.

This is what ``pinfeed plan`` and the workflow's plan stage call: it runs the
search (``search.TightPlanner``), replays the best candidates by full
rollouts on held-out trials (``verify.verify_plan`` with
``VerifySettings.held_out``: perturbed trials from a seed no screen or
selection drew from, at least as many per initial state as the
verification's, plus every corner of the perturbation box), re-ranks them
with that verdict and recommends the best plan that fails at most
``MAX_FAILURE`` of its trials. A plan that fails more is never recommended:
a warning with the reason is returned instead. Each plan keeps its verdict
on the trials that chose it apart, as ``verification.selection``.

Outcomes computed for the propagation are kept in the catalog under
``refine/PART_ID/MODEL/v_pin=V.h5`` (see :mod:`pipeline.planning.tight.store`) and
reused by later runs.

With ``planner.time_limit_s`` (``pinfeed plan --time-limit``) a
:class:`~pipeline.progress.Deadline` runs through the stages: the complete
searches stop between their steps once their time is over, the chosen plans
are carried and verified one by one while the limit lasts, and the moving
pins and the untruncated replay are skipped when there is no time left for
them; the nearest "yes" runs its searches under the same limit, and after
a cut search, or when the limit cuts its own searches, answers from the
kept plans' held-out replays only, and says so (with no time left at all,
only its axes that need no rollout answer: a sensor after the recommended
plan, what the moving-pin stage found); the family certificate (a search
of its own) is skipped under a limit. The entry then says so (``time_limit_s``,
``complete``, ``unsearched``).

With ``planner.belt_speed`` (mm/s) set, the planner plans with the dynamic
model (``kernels.dynamic``) at that belt speed and belt friction
``planner.mu_s``, stores its outcomes apart
(``refine/PART_ID/dynamic/v_pin=V_belt=S_mu_s=M.h5``) and verification
replays with the dynamic model at the same speed.
"""
from __future__ import annotations

import time
from dataclasses import dataclass, replace

from pipeline.parts.part import Part
from pipeline.planning.core.types import TightEntry
from pipeline.planning.tight.records import FixedSearch, orientation_rank, robust_order
from pipeline.planning.family.members import planning_family
from pipeline.planning.plans.candidates import MOVING_NOT_REACHED, add_moving_pins, carried_sets, fixed_search
from pipeline.planning.plans.entry import entry_record, plan_record
from pipeline.planning.plans.for_family import certify_for_family, family_checker, judge_for_family
from pipeline.planning.plans.nearest_part import part_nearest_yes
from pipeline.planning.plans.planner import planner_belt, planner_for, planner_pin_heights
from pipeline.planning.tight.store import load_lattice, save_lattice
from pipeline.planning.claims.orient import describe_claim, judge_verification, verification_finals
from pipeline.planning.core.resting import resting_states
from pipeline.planning.core.settings import TRUNCATE_SIGMA, PlannerSettings
from pipeline.planning.claims.replay import ReplayMemo
from pipeline.planning.claims.verify import verify_plan
from pipeline.planning.claims.tails import describe_untruncated, untruncated_check
from pipeline.planning.claims.plan_claim import (UNIFORM, drawn_members, held_out_claim, perturbations,
                                                 trials_drawn, with_untruncated)
from pipeline.progress import NO_DEADLINE, Deadline, Heartbeat


MAX_FAILURE = 0.01  # a recommended plan fails at most this fraction of its trials


def plan_tight(part: Part, settings: PlannerSettings, lattices=None, depth: int | None = None,
               keep: int = 5, progress=None, family=None, deadline: Deadline = NO_DEADLINE) -> TightEntry:
    """Search, verify and rank plans for ``part`` at ``settings.friction`` (a
    value or a range); returns the answer as a
    :class:`~pipeline.planning.core.types.TightEntry` record (``plans``: the
    verified :class:`~pipeline.planning.core.plan_records.Plan` records, best
    first, each with its ``verification`` and its one ``claim``;
    ``recommended``; ``warning``; ``fixed_pin_search``: what the complete
    search found, or its evidence that no fixed-pin plan orients the part;
    search statistics), built by :func:`~pipeline.planning.plans.entry.entry_record`.

    Fixed pins first, by the complete search (``complete.FixedPinSearch``);
    only when no fixed-pin sequence of up to ``depth`` pins (default: the
    search settings') orients the part within the claim's tolerance do
    moving pins follow the best fixed-pin prefixes.

    ``family`` (a :class:`~pipeline.parts.support_family.SupportFamily`, see
    :func:`pipeline.planning.family.members.planning_family`): the plans must
    orient the part for every member; the search, the carried sets and the
    verification sample its members (``support_family`` in the result).
    ``None``: uniform pressure.

    ``deadline``: a time limit (see the module's docstring); the result then
    has ``time_limit_s``, ``complete`` and ``unsearched``."""
    depth = int(depth if depth is not None else settings.search.depth)
    family = None if family is None or family.is_uniform else family
    planner = planner_for(part, settings, lattices)
    checker = family_checker(part, settings, family, progress)
    fixed, rollouts = fixed_search(part, settings, planner, depth, keep, progress, family, checker, deadline)
    unsearched = list(fixed.unsearched)
    # No pin is the plan with the fewest pins: then nothing is certified or recommended.
    chosen = [] if fixed.needs_no_pin else fixed.plans or fixed.best_effort
    candidates = carried_sets(planner, chosen, settings.verify, family, progress, deadline, unsearched)
    selections = [p.selection or p.verdict for p in chosen[:len(candidates)]]
    planner, moving_search = add_moving_pins(part, settings, planner, fixed, chosen, keep, progress, family,
                                              checker, deadline, candidates, selections, unsearched,
                                              rollouts.bench.kept)
    states = resting_states(part)
    _verify_candidates(part, settings, planner, candidates, states, progress, family, selections,
                       rollouts.bench.kept)
    judge_for_family(candidates, checker)
    candidates = robust_order(candidates, _rank, lambda p: p.verification["orientation"].get("width_deg"),
                              lambda p: p.margin, settings.search.width_slack_deg)
    good = [p for p in candidates if _acceptable(p)]
    if good and deadline.over():
        unsearched.append("the recommended plan's replay on untruncated normals: skipped")
    else:
        _check_tails(part, settings, planner, good[0] if good else None, states, progress, family)
    entry = entry_record(settings, depth, keep, planner, candidates, good, states, fixed, moving_search)
    search = SearchRecords(fixed, moving_search, candidates[:keep], rollouts)
    entry = _with_certificate_or_nearest_yes(entry, part, settings, search, progress, family, checker, deadline,
                                             unsearched)
    if deadline.limited:
        entry = replace(entry, time_limit_s=deadline.seconds, complete=not unsearched, unsearched=unsearched)
    return entry


@dataclass(frozen=True)
class SearchRecords:
    """What the steps after the answer read of the search: the fixed-pin and
    moving-pin searches' records, the best ``kept`` candidates and the
    fixed-pin search itself (``rollouts``), whose rollouts the nearest
    "yes"'s searches at looser tolerances reuse."""
    fixed: FixedSearch
    moving: FixedSearch | None
    kept: list
    rollouts: object = None


def _with_certificate_or_nearest_yes(entry: TightEntry, part: Part, settings: PlannerSettings,
                                     search: SearchRecords, progress, family, checker, deadline: Deadline,
                                     unsearched: list) -> TightEntry:
    """``entry`` with what follows the answer: with a support family, the
    family and (without a time limit) the recommended plan's certificate and
    nearest "yes"; without one, when nothing orients, the nearest "yes" of
    the best kept candidates (unless a time limit or an incomplete fixed
    search rules it out: then only the kept plans are replayed, without
    searches at looser tolerances; with no time left, none is replayed and
    only the axes that need no rollout answer). What is skipped or cut short
    joins ``unsearched``."""
    if family is not None:
        entry = replace(entry, support_family=family.to_dict())
        if deadline.limited:  # the certificate and the nearest "yes" are searches of their own
            unsearched.append("the support family's certificate of the recommended plan and its nearest "
                              '"yes": skipped under a time limit')
            return entry
        return certify_for_family(entry, part, settings, family, checker, search.moving)
    if entry.orients or not search.kept:
        return entry
    kept = [(p.pins, p.pin_heights_mm, p.pin_speeds or ()) for p in search.kept]
    # With no time left the axes that need no rollout (a sensor after the recommended plan, what
    # the moving-pin stage found) still answer; the kept plans are then not replayed.
    over = deadline.over()
    # After a cut search the kept plans' held-out replays still answer "which tolerance would
    # do"; only the searches at looser tolerances (the answer when no kept plan does) are left out.
    cut = deadline.search_over() or not search.fixed.complete
    moving_cut = any(u.startswith(MOVING_NOT_REACHED) for u in unsearched)
    nearest = part_nearest_yes(part, settings, entry, search.fixed, search.moving, kept,
                               None if cut else dict(entry.pins_used), progress, deadline, moving_cut,
                               search.rollouts)
    tolerance = next(a for a in nearest["axes"] if a["axis"] == "tolerance")
    if over:
        unsearched.append('the nearest "yes": only the axes that need no rollout (no time was left to replay '
                          'the kept plans or search at looser tolerances)')
    elif tolerance["kept_plans_only"]:
        how = "cut by the time limit" if tolerance["searches_cut"] else "not run"
        unsearched.append(f'the nearest "yes": kept plans only ({tolerance["replayed"]} of {len(kept)} '
                          f'replayed; the complete searches at looser tolerances {how})')
    return replace(entry, nearest_yes=nearest)


def _rank(plan) -> tuple:
    v = plan.verification or {}
    return orientation_rank(v.get("orientation"), len(plan.pins), plan.margin, plan.n_dynamic)


def _acceptable(plan) -> bool:
    """May ``plan`` be recommended? It orients the part, or it ends in several
    sets within the tolerance (for a sensor or moving pins to finish) and its
    claimed sets hold all but ``MAX_FAILURE`` of the trials."""
    v = plan.verification
    verdict = v["orientation"]
    if not v.get("family_check", {}).get("holds", True):
        return False  # the family's worst member breaks it
    return verdict["orients"] or v["failures"] <= MAX_FAILURE * v["trials"]


def _verify_candidates(part: Part, settings: PlannerSettings, planner, candidates, states, progress,
                       family=None, selections=None, memo: ReplayMemo | None = None) -> None:
    """Replay each candidate by perturbed full rollouts on the held-out trials
    (``verify_plan`` with ``VerifySettings.held_out``) and attach the summary as
    ``plan.verification``, with the orientation verdict (``orient.judge``: one
    set within the tolerance, with confidence?) as ``orientation`` and the
    verdict on the trials that chose it (``selections``, in order) as
    ``selection``. The candidates' replays share the states after their
    common first pins (a :class:`ReplayMemo`: same numbers, fewer rollouts);
    ``memo``, the searches' own, also has the held-out trials that certified
    their plans."""
    held_out = settings.verify.held_out()
    memo = ReplayMemo() if memo is None else memo
    claims, search = settings.claims, settings.search
    selections = list(selections or []) + [None] * len(candidates)
    speeds = {label: pin.v_pin for label, pin in planner.pins.items() if pin.v_pin}
    beat = Heartbeat("verifying the chosen plans on held-out trials", len(candidates), "plan", progress).start()
    for k, (plan, selection) in enumerate(zip(candidates, selections)):
        res = verify_plan(part, plan_record(plan), planner_pin_heights(planner), states, settings.friction.value,
                          search.pin_radius, search.model, held_out, speeds=speeds,
                          kernel=search.kernel_step, belt_speed=planner.belt_speed,
                          mu_s=planner.mu_s, family=family, stretch=beat.stretch(k, k + 1), memo=memo)
        verdict = judge_verification(res, claims.tolerance_deg, planner.order, claims.required,
                                     claims.confidence, claims.rule)
        plan.claim = _held_out_claim(settings, held_out, res, verdict, planner.order, family)
        plan.verification = {"held_out": True, "seed": held_out.seed,
                             "trials": res["trials"], "successes": res["successes"],
                             "failures": res["failures"], "rows": res["rows"], "model": res["model"],
                             **({"belt_speed": res["belt_speed"], "mu_s": res["mu_s"]}
                                if "belt_speed" in res else {}),
                             **({"support_family": res["support_family"]}
                                if "support_family" in res else {}),
                             "orientation": verdict, "truncation_sigma": TRUNCATE_SIGMA,
                             "selection": selection}
        if progress:
            progress(f"mu_c {settings.friction.label}: verified {' '.join(plan.pins)} on held-out trials: "
                     + describe_claim(verdict))
    beat.finish()


def _held_out_claim(settings: PlannerSettings, held_out, res: dict, verdict: dict, order: int, family=None):
    """The plan's one claim on its replay ``res`` (``verify_plan``) of the
    ``held_out`` trials (``VerifySettings.held_out``), judged as ``verdict``
    (with a support ``family``: on its drawn members, until the family's own
    check makes it the family's claim)."""
    return held_out_claim(verdict, verification_finals(res), settings.claims, order,
                          trials_drawn(held_out, res["rows"]), perturbations(held_out, settings.friction.value),
                          UNIFORM if family is None else drawn_members(family.label))


def _check_tails(part: Part, settings: PlannerSettings, planner, plan, states, progress=None,
                 family=None) -> None:
    """Replay the recommended ``plan`` (``None``: nothing) on untruncated
    normals (``tails.untruncated_check``), as many trials per initial state
    as its held-out trials, and keep the verdict beside its claim as
    ``verification["untruncated"]``."""
    if plan is None:
        return
    search = settings.search
    speeds = {label: pin.v_pin for label, pin in planner.pins.items() if pin.v_pin}
    per_state = max(row["trials"] for row in plan.verification["rows"])
    record = untruncated_check(part, plan_record(plan), planner_pin_heights(planner), states,
                               settings.friction.value, search.pin_radius, search.model, settings.verify,
                               per_state, settings.claims, planner.order, speeds=speeds,
                               kernel=search.kernel_step, belt_speed=planner.belt_speed,
                               mu_s=planner.mu_s, family=family)
    plan.verification["untruncated"] = record
    plan.claim = with_untruncated(plan.claim, record)
    if progress:
        progress(f"mu_c {settings.friction.label}: {' '.join(plan.pins)} on "
                 + describe_untruncated(record, TRUNCATE_SIGMA))


# ---------------------------------------------------------------------- every configured friction


def plan_tight_all(part: Part, settings: PlannerSettings, catalog_root, keep: int = 5, progress=None,
                   deadline: Deadline | None = None) -> list:
    """Tight plans (a :class:`~pipeline.planning.core.types.TightEntry` each)
    at every friction of ``settings.frictions`` (the first is the
    recommended one), at the search's belt speed when it is set, for every
    member of its support family when it is set (its extremes found at each
    friction); the planner's rollouts are stored in the catalog (keyed by
    model, pin speed and belt). ``deadline``: the time limit of them all
    (default: one of ``settings.search.time_limit_s`` from now, if set)."""
    if deadline is None:
        deadline = Deadline(settings.search.time_limit_s)
    search = settings.search
    belt_speed, mu_s = planner_belt(search, part)
    speeds = [0.0, *search.dynamic_speeds]
    lattices = {v: load_lattice(catalog_root, part, search.model, v, search.pin_radius,
                                search.kernel_step, belt_speed=belt_speed, mu_s=mu_s)
                for v in speeds}
    out = []
    try:
        for friction in settings.frictions:
            t0 = time.perf_counter()
            at = settings.at(friction)
            family = planning_family(part, search.support_family or "uniform", at)
            entry = plan_tight(part, at, lattices=lattices, keep=keep,
                               progress=_labelled(progress, f"mu_c {friction.label}"), family=family,
                               deadline=deadline)
            wall = round(time.perf_counter() - t0, 2)  # search, verification and all
            out.append(replace(entry, stats={**entry.stats, "wall_seconds": wall}))
    finally:  # also on Ctrl-C: the rollouts done so far are reused by the next run
        for lattice in lattices.values():
            save_lattice(catalog_root, lattice)
    return out


def _labelled(progress, label: str):
    """``progress`` with each message prefixed by ``label`` (which friction it is
    for), unless the message already starts with it."""
    if progress is None:
        return None
    return lambda message: progress(message if message.startswith(label) else f"{label}: {message}")


