"""Plans read back from a stored plan file: the tight entry at a friction,
plan ``n`` of it, the best fixed-pin plan, and how to make a missing one."""
from __future__ import annotations

from pathlib import Path

from pipeline.errors import PinfeedError
from pipeline.planning.core.plan_records import Plan
from pipeline.planning.core.settings import Friction
from pipeline.planning.core.types import TightEntry, as_plan_file


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
