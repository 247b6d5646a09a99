"""The tight planner's answer at one friction as a typed record.

:func:`entry_record` turns what the search and the verification found (the
search's :class:`~pipeline.planning.tight.search.TightPlan` candidates and
its :class:`~pipeline.planning.tight.records.FixedSearch` records) into one
:class:`~pipeline.planning.core.types.TightEntry`, whose plans are
:class:`~pipeline.planning.core.plan_records.Plan` records
(:func:`plan_record`). The steps after it (family certificate, nearest
"yes", speed limits, shape tolerance) take that record and add to it; it is
turned into a dict only where it is written or printed.
"""
from __future__ import annotations

import math

from pipeline.planning.core.arcs import format_arcs
from pipeline.planning.core.plan_records import Arc, Plan, RestingState, State, Verification
from pipeline.planning.core.settings import PlannerSettings
from pipeline.planning.core.types import TightEntry
from pipeline.planning.claims.orient import describe_claim
from pipeline.planning.plans.candidates import MOVING_PREFIXES
from pipeline.planning.plans.planner import mechanics_label
from pipeline.planning.tight.records import FixedSearch


def plan_record(plan) -> Plan:
    """The record of one verified candidate (a ``TightPlan``): its pins, the
    sets it carries, its held-out verification and its one claim."""
    ver = plan.verification
    return Plan(tuple(plan.pins), tuple(Arc(s, w) for s, w in plan.final_sets), plan.n_sets,
                plan.margin if math.isfinite(plan.margin) else None, tuple(plan.sets_after), plan.n_dynamic,
                {label: tuple(tuple(br) for br in brs) for label, brs in plan.branches.items()},
                "tight", tuple(plan.pin_heights_mm), tuple(plan.pin_speeds), plan.jumps,
                {k: State.of_set(v) for k, v in plan.initial.items()},
                Verification.from_dict(ver) if ver is not None else None,
                carried_sets_kind=plan.carried, claim=plan.claim)


def no_plan_warning(depth: int, candidates, good, fixed: FixedSearch, tolerance: float,
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


def _moving_record(moving: FixedSearch | None) -> dict | None:
    """The moving-pin stage's record for the file (``moving_pin_search``)."""
    if moving is None:
        return None
    return {"orients": moving.orients, "depth": moving.depth, "levels": moving.levels,
            "found": [list(p.labels) for p in moving.plans], "skipped": moving.skipped,
            "nominal_rollouts": moving.rollouts, "seconds": round(moving.seconds, 2),
            **({} if moving.time_limit is None else {"complete": moving.complete,
                                                      "unsearched": list(moving.unsearched)})}


def _stats(planner, fixed: FixedSearch, moving: FixedSearch | None) -> dict:
    """The search's counters (``stats``): rollouts, joint states, seconds, sequences per level."""
    moving_rollouts = moving.rollouts if moving else 0
    return {"transitions": planner.stats.transitions,
            "rollouts": planner.stats.rollouts + fixed.rollouts + moving_rollouts,
            "nominal_rollouts": fixed.rollouts + moving_rollouts,
            "joint_states": planner.stats.nodes, "seconds": round(fixed.seconds + planner.stats.seconds, 2),
            "pruned_branching": planner.stats.pruned_branching, "unresolved": planner.stats.unresolved,
            "per_level": [lv["sequences"] for lv in fixed.levels]}


def entry_record(settings: PlannerSettings, depth: int, keep: int, planner, candidates, good, states,
                fixed: FixedSearch, moving: FixedSearch | None = None) -> TightEntry:
    """The tight planner's record at one friction: the verified ``good``
    plans (best first; the first is recommended), the ``candidates`` that
    failed, the searches' records and why nothing orients when nothing does."""
    recommended = plan_record(good[0]) if good else None
    tolerance = settings.claims.tolerance_deg
    plans = (recommended, *(plan_record(p) for p in good[1:keep])) if good else ()
    mu_c = settings.friction.to_json()
    return TightEntry(
        tuple(mu_c) if isinstance(mu_c, list) else mu_c, settings.friction.label, plans,
        initial_states={k: RestingState(t, y) for k, (t, y) in states.items()},
        recommended=recommended, warning=no_plan_warning(depth, candidates, good, fixed, tolerance, moving),
        belt_speed=planner.belt_speed, mu_s=planner.mu_s if planner.belt_speed else None,
        mechanics=mechanics_label(settings.search.model, planner.belt_speed, planner.mu_s),
        symmetry_order=planner.order, depth=depth, complete_depth=depth, beam=settings.search.beam,
        rejected=tuple(plan_record(p) for p in [p for p in candidates if p not in good][:keep]),
        stats=_stats(planner, fixed, moving), tolerance_deg=tolerance, required=settings.claims.required,
        orients=bool(recommended and good[0].verification["orientation"]["orients"]) or fixed.needs_no_pin,
        needs_no_pin=fixed.needs_no_pin,
        pins_used={label: pin.y for label, pin in planner.pins.items() if pin.v_pin == 0.0},
        fixed_pin_search=fixed.to_dict(), moving_pin_search=_moving_record(moving))
