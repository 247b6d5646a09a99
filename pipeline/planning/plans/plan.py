"""Plans with tight propagation for one part and one friction, verified.

This is what ``pinfeed plan`` and the workflow's plan stage call: it runs the
search (``search.TightPlanner``), replays the best candidates by full
rollouts on held-out trials (``verify.verify_plan`` with
``verify.holdout_settings``: perturbed trials from a seed no screen or
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
kept plans' held-out replays only, and says so; the family certificate (a
search of its own) is
skipped under a limit. The entry then says so (``time_limit_s``,
``complete``, ``unsearched``).

With ``planner.belt_speed`` (mm/s) set, the planner plans with the dynamic
model (``kernels.dynamic``) at that belt speed and belt friction
``planner.mu_s``, stores its outcomes apart
(``refine/PART_ID/dynamic/v_pin=V_belt=S_mu_s=M.h5``) and verification
replays with the dynamic model at the same speed.
"""
from __future__ import annotations

import time
from pathlib import Path

from pipeline.errors import PinfeedError
from pipeline.parts.part import Part
from pipeline.planning.core.arcs import format_arcs
from pipeline.planning.tight.certify import carried_plan
from pipeline.planning.tight.complete import FixedPinSearch
from pipeline.planning.tight.records import FixedPlan, FixedSearch, orientation_rank, robust_order
from pipeline.planning.family.members import planning_family
from pipeline.planning.family.certificate import family_certificate
from pipeline.planning.family.nearest import nearest_yes
from pipeline.planning.plans.nearest_part import part_nearest_yes
from pipeline.planning.family.worst_member import FamilyChecker, FamilyCheckSettings
from pipeline.planning.tight.store import load_lattice, save_lattice
from pipeline.planning.claims.orient import describe_claim, judge_verification
from pipeline.planning.tight.propagate import Tolerances, Uncertainty
from pipeline.planning.core.resting import resting_states
from pipeline.planning.tight.search import TightPlanner
from pipeline.planning.core.settings import (TRUNCATE_SIGMA, Friction, PlannerSettings, SearchSettings,
                                             candidate_pins)
from pipeline.planning.core.types import Plan, TightEntry, as_plan_file
from pipeline.planning.claims.verify import ReplayMemo, holdout_settings, verify_plan
from pipeline.planning.claims.tails import describe_untruncated, untruncated_check
from pipeline.progress import NO_DEADLINE, SILENT, Deadline, Heartbeat


MAX_FAILURE = 0.01  # a recommended plan fails at most this fraction of its trials
MOVING_PREFIXES = 3  # best fixed-pin results (besides none) that moving pins may follow
MOVING_NOT_REACHED = "moving pins: not reached"  # how a time limit that came first is listed


def planner_belt(search: SearchSettings, part: Part | None = None):
    """``(belt_speed, mu_s)`` the planner plans at: ``belt_speed`` (mm/s;
    ``None`` = quasi-static) and ``mu_s`` of the search settings. With
    ``part``, a bad belt (speed <= 0, mu_s out of range, a part thrown rather
    than pushed) raises a one-line :class:`PinfeedError`."""
    if search.belt_speed is None:
        return None, float(search.mu_s)
    if part is not None:
        from pipeline.checks import check_belt
        check_belt(part, search.belt_speed, search.mu_s)
    return float(search.belt_speed), float(search.mu_s)


def mechanics_label(model: str, belt_speed: float | None, mu_s: float) -> str:
    """What the plans were computed with: ``'minpower'`` or ``'dynamic at 150 mm/s, mu_s 0.5'``."""
    return model if belt_speed is None else f"dynamic at {belt_speed:g} mm/s, mu_s {mu_s:g}"


def planner_for(part: Part, settings: PlannerSettings, lattices=None, moving: bool = False) -> TightPlanner:
    """A :class:`TightPlanner` at ``settings.friction`` with the settings' pins,
    limits, model and sizes (and, with ``moving``, every candidate height at
    every moving-pin speed, labelled like ``P23v-2``); at the search's belt
    speed when it is set (:func:`planner_belt`)."""
    search = settings.search
    belt_speed, mu_s = planner_belt(search, part)
    static = candidate_pins(part, search.pins)
    speeds = list(search.dynamic_speeds) if moving else []
    moving_pins = {f"{k}v{v:+g}": (y, v) for k, y in static.items() for v in speeds}
    return TightPlanner(part, static, search.d_min, search.d_max, settings.friction.value,
                        search.pin_radius, search.model, Uncertainty.from_verify(settings.verify),
                        Tolerances(), moving=moving_pins, lattices=lattices, kernel=search.kernel_settings or None,
                        max_branches=search.max_branches, hard_limits=search.hard_d_limits,
                        belt_speed=belt_speed, mu_s=mu_s)


def plan_tight(part: Part, settings: PlannerSettings, lattices=None, depth: int | None = None,
               keep: int = 5, progress=None, family=None, deadline: Deadline = NO_DEADLINE) -> dict:
    """Search, verify and rank plans for ``part`` at ``settings.friction`` (a
    value or a range); returns a JSON-ready dict (``plans`` best first, each
    with its ``verification`` and orientation verdict; ``recommended``;
    ``warning``; ``fixed_pin_search``: what the complete search found, or its
    evidence that no fixed-pin plan orients the part; search statistics).

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
    fixed = _fixed_search(part, settings, planner, depth, keep, progress, family, checker, deadline)
    unsearched = list(fixed.unsearched)
    # No pin is the plan with the fewest pins: then nothing is certified or recommended.
    chosen = [] if fixed.needs_no_pin else fixed.plans or fixed.best_effort
    candidates = _carried(planner, chosen, settings.verify, family, progress, deadline, unsearched)
    selections = [p.selection or p.verdict for p in chosen[:len(candidates)]]
    planner, moving_search = _add_moving_pins(part, settings, planner, fixed, chosen, keep, progress, family,
                                              checker, deadline, candidates, selections, unsearched)
    states = resting_states(part)
    _verify_candidates(part, settings, planner, candidates, states, progress, family, selections)
    judge_for_family(candidates, checker)
    candidates = robust_order(candidates, _rank, lambda p: p.verification["orientation"].get("width_deg"),
                              lambda p: p.margin, settings.search.width_slack_deg)
    good = [p for p in candidates if _acceptable(p)]
    if good and deadline.over():
        unsearched.append("the recommended plan's replay on untruncated normals: skipped")
    else:
        _check_tails(part, settings, planner, good[0] if good else None, states, progress, family)
    result = _tight_result(settings, depth, keep, planner, candidates, good, states, fixed, moving_search)
    _add_certificate_or_nearest_yes(result, part, settings, planner, fixed, candidates, good, keep, progress,
                                    family, checker, deadline, unsearched)
    if deadline.limited:
        result.update(time_limit_s=deadline.seconds, complete=not unsearched, unsearched=unsearched)
    return result


def _add_moving_pins(part: Part, settings: PlannerSettings, planner, fixed: FixedSearch, chosen, keep, progress,
                     family, checker, deadline: Deadline, candidates: list, selections: list,
                     unsearched: list) -> tuple:
    """When fixed pins neither orient the part nor are unneeded: the moving
    pins' search after the ``chosen`` fixed-pin results (if the settings
    allow moving pins and the search time lasts; else ``unsearched`` says
    so). Its plans' carried sets join ``candidates`` and their selection
    verdicts ``selections``; what it left out joins ``unsearched``.

    Returns
    -------
    tuple
        ``(planner, moving_search)``: the planner whose pins the candidates
        use (the moving one once moving pins were searched) and the moving
        pins' :class:`FixedSearch` (``None`` when not searched).
    """
    moving = None if fixed.orients or fixed.needs_no_pin else _moving_planner(part, settings, planner)
    if moving is None:
        return planner, None
    if deadline.search_over():
        unsearched.append(f"{MOVING_NOT_REACHED} (up to {settings.search.dynamic_depth} moving pin(s) after "
                          f"no fixed pin and after the {MOVING_PREFIXES} best fixed-pin results)")
        return planner, None
    moving_search = _moving_search(part, settings, moving, chosen, keep, progress, family, checker, deadline)
    unsearched += moving_search.unsearched
    carried = _carried(moving, moving_search.plans, settings.verify, family, progress, deadline, unsearched)
    candidates += carried
    selections += [p.selection or p.verdict for p in moving_search.plans[:len(carried)]]
    return moving, moving_search


def _add_certificate_or_nearest_yes(result: dict, part: Part, settings: PlannerSettings, planner,
                                    fixed: FixedSearch, candidates, good, keep, progress, family, checker,
                                    deadline: Deadline, unsearched: list) -> None:
    """Add to ``result`` what follows the answer: with a support family, the
    family and (without a time limit) the recommended plan's certificate and
    nearest "yes"; without one, when nothing orients, the nearest "yes" of
    the best ``keep`` candidates (unless a time limit or an incomplete fixed
    search rules it out: then only the kept plans are replayed, without
    searches at looser tolerances). What is skipped or cut short joins
    ``unsearched``."""
    if family is not None:
        result["support_family"] = family.to_dict()
        if deadline.limited:  # the certificate and the nearest "yes" are searches of their own
            unsearched.append("the support family's certificate of the recommended plan and its nearest "
                              '"yes": skipped under a time limit')
        else:
            certify_for_family(result, part, settings, family, checker, good)
    elif not result["orients"] and candidates:
        kept = [(p.pins, p.pin_heights_mm, p.pin_speeds or ()) for p in candidates[:keep]]
        fixed_pins = {label: pin.y for label, pin in planner.pins.items() if pin.v_pin == 0.0}
        if deadline.over():
            unsearched.append('the nearest "yes": skipped (no time left)')
            return
        # After a cut search the kept plans' held-out replays still answer "which tolerance would
        # do"; only the searches at looser tolerances (the answer when no kept plan does) are left out.
        cut = deadline.search_over() or not fixed.complete
        moving_cut = any(u.startswith(MOVING_NOT_REACHED) for u in unsearched)
        nearest = part_nearest_yes(part, settings, result, kept, None if cut else fixed_pins, progress, deadline,
                                   moving_cut)
        result["nearest_yes"] = nearest
        tolerance = next(a for a in nearest["axes"] if a["axis"] == "tolerance")
        if tolerance["kept_plans_only"]:
            how = "cut by the time limit" if tolerance["searches_cut"] else "not run"
            unsearched.append(f'the nearest "yes": kept plans only ({tolerance["replayed"]} of {len(kept)} '
                              f'replayed; the complete searches at looser tolerances {how})')


def _carried(planner, chosen, verify, family, progress, deadline: Deadline = NO_DEADLINE,
             unsearched: list | None = None) -> list:
    """The carried sets of each chosen plan (``certify.carried_plan``), telling
    ``progress`` how many are done (and, between the propagation's rollout
    batches, that it is still at it). Once ``deadline`` has passed no further
    plan is started (each one started is then verified): the plans left are
    named in ``unsearched``. Sampled carried sets of plans that share their
    first pins share those rollouts (``verify.ReplayMemo``)."""
    out, memo = [], ReplayMemo()
    with Heartbeat("carried sets of the chosen plans", len(chosen), "plan", progress) as beat:
        try:
            for p in chosen:
                if deadline.over():
                    left = chosen[len(out):]
                    beat.finish(len(out), "the time limit has passed")
                    if unsearched is not None:
                        unsearched.append(f"carried sets and held-out verification of {len(left)} chosen "
                                          f"plan(s): skipped ({', '.join(' '.join(q.labels) for q in left)})")
                    break
                for lattice in planner.lattices.values():
                    lattice.stretch = beat.stretch(len(out), len(out))
                out.append(carried_plan(planner, p.labels, p.margin, verify, family, memo))
                beat.tick(len(out))
        finally:
            for lattice in planner.lattices.values():
                lattice.stretch = SILENT
    return out


def _pin_search(part, settings: PlannerSettings, planner, moving: bool, family=None,
                checker=None) -> FixedPinSearch:
    """The complete search over the planner's fixed pins (``moving`` False) or
    its moving pins (True), with the settings' claim, trials and search."""
    pins = {k: p for k, p in planner.pins.items() if bool(p.v_pin) == moving}
    search = FixedPinSearch(part, {k: p.y for k, p in pins.items()}, settings.friction, settings.claims,
                            settings.verify, settings.search,
                            speeds={k: p.v_pin for k, p in pins.items()}, family=family)
    search.member_check = checker
    search.evidence = not moving  # the moving-pin stage keeps its plans only
    return search


def _fixed_search(part, settings: PlannerSettings, planner, depth, keep, progress, family=None,
                  checker=None, deadline: Deadline = NO_DEADLINE) -> FixedSearch:
    """The complete fixed-pin search with the planner's pins and the settings."""
    search = _pin_search(part, settings, planner, moving=False, family=family, checker=checker)
    return search.run(depth, candidates=settings.search.candidates, keep=keep, progress=progress,
                      deadline=deadline)


def _moving_planner(part, settings: PlannerSettings, planner):
    """The planner with moving pins, if the settings allow them (else ``None``)."""
    if not (settings.search.dynamic_depth and settings.search.dynamic_speeds):
        return None
    return planner_for(part, settings, planner.lattices, moving=True)


def _moving_search(part, settings: PlannerSettings, moving, chosen, keep, progress, family=None,
                   checker=None, deadline: Deadline = NO_DEADLINE) -> FixedSearch:
    """Up to ``search.dynamic_depth`` moving pins after no fixed pin and after
    each of the ``MOVING_PREFIXES`` best fixed-pin results, by the same
    enumeration, screen and judgement as the fixed pins; the orienting plans,
    best first.

    A plan that orients ranks before every plan with more pins
    (:func:`~pipeline.planning.tight.records.orientation_rank`), so once some
    sequence orients with ``k`` pins a prefix of ``L`` fixed pins is searched
    only up to ``k - L`` moving pins, and not at all when ``L >= k``
    (``skipped`` in the search's record): the plans left out could only rank
    after the one found. Under a time limit (``deadline``) the prefixes
    not reached and what each search left out are in ``unsearched``."""
    if progress:
        progress(f"mu_c {settings.friction.label}: fixed pins do not orient the part: adding moving pins")
    search = _pin_search(part, settings, moving, moving=True, family=family, checker=checker)
    depth = settings.search.dynamic_depth
    total = FixedSearch([], [], depth, settings.claims.tolerance_deg, settings.claims.required,
                        time_limit=deadline.seconds)
    for prefix in [None, *chosen[:MOVING_PREFIXES]]:
        after = list(prefix.labels) if prefix else []
        if deadline.search_over():
            total.unsearched.append(f"moving pins after {' '.join(after) or 'no fixed pin'}: not reached")
            continue
        room = moving_room(total.plans, len(after), depth, fewer=family is not None)
        if room < 1:  # then room = (pins of the shortest plan found) - len(after), less one with a family
            total.skipped.append({"after": after,
                                  "why": f"a plan of {len(after) + room + (family is not None)} pins already "
                                         f"orients the part" + (" for the family" if family is not None else "")})
            continue
        res = search.run(room, candidates=settings.search.candidates, keep=keep, progress=progress,
                         prefix=prefix, deadline=deadline)
        total.plans += res.plans
        total.unsearched += res.unsearched
        total.levels += [dict(lv, after=after) for lv in res.levels]
        total.rollouts += res.rollouts
        total.seconds += res.seconds
    total.plans = sorted(total.plans, key=FixedPlan.rank_key)[:keep]
    return total


def moving_room(found: list, n_prefix: int, depth: int, fewer: bool = False) -> int:
    """How many moving pins to try after a prefix of ``n_prefix`` fixed pins:
    ``depth``, or fewer so that no sequence has more pins than the shortest
    orienting plan of ``found`` (0 or less: none); ``fewer``: so that each
    has fewer pins than it (with a support family, where a plan of as many
    pins would only be an alternative and each costs worst-member searches)."""
    fewest = min((len(p.labels) for p in found), default=None)
    return depth if fewest is None else min(depth, fewest - n_prefix - int(fewer))


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
                       family=None, selections=None) -> None:
    """Replay each candidate by perturbed full rollouts on the held-out trials
    (``verify_plan`` with ``holdout_settings``) and attach the summary as
    ``plan.verification``, with the orientation verdict (``orient.judge``: one
    set within the tolerance, with confidence?) as ``orientation`` and the
    verdict on the trials that chose it (``selections``, in order) as
    ``selection``. The candidates' replays share the states after their
    common first pins (``verify.ReplayMemo``: same numbers, fewer rollouts)."""
    verify_cfg = holdout_settings(settings.verify)
    memo = ReplayMemo()
    claims, search = settings.claims, settings.search
    selections = list(selections or []) + [None] * len(candidates)
    speeds = {label: pin.v_pin for label, pin in planner.pins.items() if pin.v_pin}
    beat = Heartbeat("verifying the chosen plans on held-out trials", len(candidates), "plan", progress).start()
    for k, (plan, selection) in enumerate(zip(candidates, selections)):
        res = verify_plan(part, plan.to_dict(), planner_pin_heights(planner), states, settings.friction.value,
                          search.pin_radius, search.model, verify_cfg, speeds=speeds,
                          kernel=search.kernel_settings, belt_speed=planner.belt_speed,
                          mu_s=planner.mu_s, family=family, stretch=beat.stretch(k, k + 1), memo=memo)
        verdict = judge_verification(res, claims.tolerance_deg, planner.order, claims.required,
                                     claims.confidence, claims.rule)
        plan.verification = {"held_out": True, "seed": verify_cfg["seed"],
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
    record = untruncated_check(part, plan.to_dict(), planner_pin_heights(planner), states,
                               settings.friction.value, search.pin_radius, search.model, settings.verify,
                               per_state, settings.claims, planner.order, speeds=speeds,
                               kernel=search.kernel_settings, belt_speed=planner.belt_speed,
                               mu_s=planner.mu_s, family=family)
    plan.verification["untruncated"] = record
    if progress:
        progress(f"mu_c {settings.friction.label}: {' '.join(plan.pins)} on "
                 + describe_untruncated(record, TRUNCATE_SIGMA))


def _no_plan_warning(depth: int, candidates, good, fixed: FixedSearch, tolerance: float,
                     moving: FixedSearch | None = None):
    """Why the recommended plan does not orient the part, or why nothing is
    recommended (None when a plan orients it)."""
    if good and good[0].verification["orientation"]["orients"]:
        return None
    if fixed.needs_no_pin:
        return fixed.evidence()
    why = fixed.evidence()
    if moving is not None and not moving.complete:
        why += (f"; nor do the moving-pin sequences searched before the time limit (up to {moving.depth} moving "
                f"pins after no fixed pin or after the {MOVING_PREFIXES} best fixed-pin results; not searched: "
                f"{'; '.join(moving.unsearched)})")
    elif moving is not None:
        why += (f"; nor do up to {moving.depth} moving pins after no fixed pin or after the "
                f"{MOVING_PREFIXES} best fixed-pin results")
    if not candidates and not fixed.complete:
        return f"{why}; no plan was verified within the time limit"
    if not candidates:
        return f"{why}; no allowed pin sequence within depth {depth}"
    if not good:
        best = candidates[0]
        return (f"{why}; no plan passed verification: the best, {' '.join(best.pins)} "
                f"({format_arcs(best.final_sets)}), failed {best.verification['failures']} of "
                f"{best.verification['trials']} trials")
    verdict = good[0].verification["orientation"]
    if verdict.get("point_rule"):
        return (f"no plan clears the confidence bound on held-out trials; the best, "
                f"{' '.join(good[0].pins)}, is a near miss: {describe_claim(verdict)}")
    return (f"{why}; the recommended plan ends in {verdict['sets_within_tolerance']} "
            f"sets of at most {tolerance:g} deg: a sensor must tell them apart")


def _tight_result(settings: PlannerSettings, depth: int, keep: int, planner, candidates, good, states,
                  fixed: FixedSearch, moving: FixedSearch | None = None) -> dict:
    """The JSON-ready tight-planner entry at one friction (the stored format)."""
    recommended = good[0] if good else None
    tolerance = settings.claims.tolerance_deg
    return {
        "mu_c": settings.friction.to_json(),
        "friction": settings.friction.label,
        "belt_speed": planner.belt_speed, "mu_s": planner.mu_s if planner.belt_speed else None,
        "mechanics": mechanics_label(settings.search.model, planner.belt_speed, planner.mu_s),
        "symmetry_order": planner.order,
        "depth": depth, "complete_depth": depth,
        "beam": settings.search.beam,
        "tolerance_deg": tolerance, "required": settings.claims.required,
        "orients": bool(recommended and recommended.verification["orientation"]["orients"])
        or fixed.needs_no_pin,
        "needs_no_pin": fixed.needs_no_pin,
        "plans": [p.to_dict() for p in good[:keep]],
        "rejected": [p.to_dict() for p in candidates if p not in good][:keep],
        "recommended": recommended.to_dict() if recommended else None,
        "warning": _no_plan_warning(depth, candidates, good, fixed, tolerance, moving),
        "fixed_pin_search": fixed.to_dict(),
        "moving_pin_search": None if moving is None else {
            "orients": moving.orients, "depth": moving.depth, "levels": moving.levels,
            "found": [list(p.labels) for p in moving.plans], "skipped": moving.skipped,
            "nominal_rollouts": moving.rollouts,
            "seconds": round(moving.seconds, 2),
            **({} if moving.time_limit is None else {"complete": moving.complete,
                                                      "unsearched": list(moving.unsearched)})},
        "pins_used": {label: pin.y for label, pin in planner.pins.items() if pin.v_pin == 0.0},
        "stats": {"transitions": planner.stats.transitions,
                  "rollouts": planner.stats.rollouts + fixed.rollouts + (moving.rollouts if moving else 0),
                  "nominal_rollouts": fixed.rollouts + (moving.rollouts if moving else 0),
                  "joint_states": planner.stats.nodes, "seconds": round(fixed.seconds + planner.stats.seconds, 2),
                  "pruned_branching": planner.stats.pruned_branching,
                  "unresolved": planner.stats.unresolved,
                  "per_level": [lv["sequences"] for lv in fixed.levels]},
        "initial_states": {k: {"theta": t, "y_c": y} for k, (t, y) in states.items()},
        "lattices": planner.lattices,
    }


def planner_pin_heights(planner: TightPlanner) -> dict:
    """Pin label -> pin height across the belt (mm) of ``planner``."""
    return {label: pin.y for label, pin in planner.pins.items()}


def tight_entry(plan_result, friction=None) -> TightEntry:
    """The stored tight-planner entry at ``friction`` (a value, a range or its
    text ``LO:HI``; default the first planned friction, ``planner.mu_c``) of a
    stored plan (a :class:`PlanFile` or its dict), as a :class:`TightEntry`."""
    tight = as_plan_file(plan_result).tight or ()
    if not tight:
        raise PinfeedError("the stored plan has no tight-planner plans; re-plan with 'pinfeed plan' "
                           "(--mode tight or both) or re-run the workflow")
    if friction is None:
        return tight[0]
    want = Friction.parse(friction).label
    found = [t for t in tight if t.friction == want]
    if not found:
        raise PinfeedError(f"no stored plan at mu_c {want}; stored: {', '.join(t.friction for t in tight)}")
    return found[0]


def pick_tight_plan(result, n: int, mu_text) -> tuple:
    """``(plan, mu_c, entry)``: plan ``n`` (1 = recommended, a :class:`Plan`) of
    the stored tight plans at friction ``mu_text`` (default: the first planned
    friction) of a stored plan (a :class:`PlanFile` or its dict), that
    friction (a value or ``(lo, hi)``) and its :class:`TightEntry`."""
    entry = tight_entry(result, mu_text)
    if not entry.plans:
        raise PinfeedError(f"no verified plan at mu_c {entry.friction}: {entry.warning}")
    if not 1 <= n <= len(entry.plans):
        raise PinfeedError(f"--plan must be 1 to {len(entry.plans)}, got {n}")
    return entry.plans[n - 1], entry.mu_c, entry


def best_fixed_plan(plan_result) -> Plan | None:
    """The best plan of fixed pins only in a stored plan (a :class:`PlanFile` or
    its dict; paper mode's ``best_static``, else its first plan without moving
    pins), as a :class:`Plan` (None if none)."""
    result = as_plan_file(plan_result)
    if result.best_static:
        return result.best_static
    return next((p for p in result.plans or () if not p.n_dynamic_pins), None)


def plan_hint(planned_parts, name: str, root) -> str:
    """How to make the stored plan of ``name`` under results folder ``root``: the
    workflow plans its ``planned_parts`` (``PlannerSettings.parts``); a part
    planned from --vertices or --outline needs 'pinfeed plan'."""
    if name in planned_parts:
        return "run the workflow ('make run')"
    return f"run 'pinfeed plan --part {name} --out {Path(root) / 'plans' / (name + '.json')}'"


# ---------------------------------------------------------------------- every configured friction


def plan_tight_all(part: Part, settings: PlannerSettings, catalog_root, keep: int = 5, progress=None,
                   deadline: Deadline | None = None) -> list:
    """Tight plans at every friction of ``settings.frictions`` (the first is the
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
                                search.kernel_settings or None, belt_speed=belt_speed, mu_s=mu_s)
                for v in speeds}
    out = []
    try:
        for friction in settings.frictions:
            t0 = time.perf_counter()
            at = settings.at(friction)
            family = planning_family(part, search.support_family or "uniform", at)
            res = plan_tight(part, at, lattices=lattices, keep=keep,
                             progress=_labelled(progress, f"mu_c {friction.label}"), family=family,
                             deadline=deadline)
            res["stats"]["wall_seconds"] = round(time.perf_counter() - t0, 2)  # search, verification and all
            res.pop("lattices")
            out.append(res)
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


# ---------------------------------------------------------------------- support families: the family's edge

def family_checker(part: Part, settings: PlannerSettings, family, progress=None) -> FamilyChecker | None:
    """The worst-member check for plans for ``family`` (None without a family),
    with the planner's verification settings and ``planner.worst_member_budget``;
    each search tells ``progress`` how far it has got."""
    if family is None or family.is_uniform:
        return None
    return FamilyChecker(part, family, FamilyCheckSettings.from_settings(settings), progress)


def judge_for_family(candidates, checker: FamilyChecker | None) -> None:
    """Each candidate that orients on the sampled verification is checked for
    the family's worst member (``worst_member.check_plan_for_family``): the
    record goes into ``verification["family_check"]`` and a plan the worst
    member breaks no longer orients (and cannot be recommended)."""
    if checker is None:
        return
    for plan in candidates:
        if not plan.verification["orientation"]["orients"]:
            continue
        checker(plan.pins, plan.pin_heights_mm, None, plan.pin_speeds)
        check = {k: v for k, v in checker.result(plan.pins, plan.pin_heights_mm).items()
                 if not k.startswith("_")}
        plan.verification["family_check"] = check
        if not check["holds"]:
            plan.verification["orientation"] = dict(plan.verification["orientation"], orients=False,
                                                    broken_by_worst_member=True)


def certify_for_family(result: dict, part: Part, settings: PlannerSettings, family, checker, good) -> None:
    """The family certificate of the recommended plan (``family_certificate``
    in ``result`` and in the recommended plan), or, when no plan holds for the
    family, a warning naming the worst member that broke the best one."""
    if checker is None:
        return
    rec = good[0] if good else None
    check = rec and rec.verification.get("family_check")
    moving_yes = None
    if check and check["holds"]:
        cert = family_certificate(part, rec.pin_heights_mm, family, check, checker.settings,
                                  speeds=rec.pin_speeds, progress=checker.progress)
        result["family_certificate"] = cert
        result["recommended"]["family_certificate"] = cert
        if not any(rec.pin_speeds or ()):
            return
        # A moving-pin plan holds: the nearest "yes" without one is still asked for.
        moving_yes = {"labels": rec.pins, "heights": rec.pin_heights_mm, "speeds": rec.pin_speeds or (),
                      "certificate": cert}
    broken = [(key, r) for key, r in checker.results.items() if not r["holds"] and r["worst_member"]]
    if broken and moving_yes is None:
        (labels, heights), record = max(broken, key=lambda kr: kr[1]["verdict"]["in_tolerance"])
        worst = record["worst_member"]
        result["family_certificate"] = None
        # The evidence, kept whole: the best plan it broke, that plan's set, the member.
        result["family_worst_member"] = {"plan": list(labels), "pin_heights_mm": list(heights),
                                         "set_deg": record["set_deg"], **worst}
        result["warning"] = ((result["warning"] + "; ") if result["warning"] else "") + (
            f"no plan of up to {result['depth']} pins holds for the whole family {family.label}: "
            f"{len(broken)} plan(s) that passed the sampled verification are broken by a worst member "
            f"(e.g. {worst['parameters']}, nominal finals {worst['nominal_finals_deg']} deg, "
            f"{worst['outside_deg']:.2f} deg outside the set)")
    result["nearest_yes"] = nearest_yes(part, family, checker, result,
                                        lambda text: planning_family(part, text, settings), checker.progress,
                                        moving_yes)
