"""The tight planner a plan is searched with: its candidate pins (fixed, and
moving at every moving-pin speed), belt and mechanics."""
from __future__ import annotations

from pipeline.parts.part import Part
from pipeline.planning.core.settings import PlannerSettings, SearchSettings, candidate_pins
from pipeline.planning.tight.propagate import Tolerances, Uncertainty
from pipeline.planning.tight.search import TightPlanner


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
                        Tolerances(), moving=moving_pins, lattices=lattices, kernel=search.kernel_step,
                        max_branches=search.max_branches, hard_limits=search.hard_d_limits,
                        belt_speed=belt_speed, mu_s=mu_s)


def planner_pin_heights(planner: TightPlanner) -> dict:
    """Pin label -> pin height across the belt (mm) of ``planner``."""
    return {label: pin.y for label, pin in planner.pins.items()}
