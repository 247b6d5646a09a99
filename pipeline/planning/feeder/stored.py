"""The layout of a stored plan: the plan's speed limit, the belt speed and the design.

What ``pinfeed layout`` and the workflow's layout stage compute from
``RESULTS/plans/NAME.json`` (:func:`layout_stored`): the tight plan of fixed
pins, its speed limit (stored with the plan, else computed), the belt speed
chosen from it, and :func:`pipeline.planning.feeder.layout.layout_plan`.
"""
from __future__ import annotations

from pipeline.errors import PinfeedError
from pipeline.maps import simulate
from pipeline.parts.part import Part
from pipeline.planning.core.arcs import format_arcs
from pipeline.planning.core.settings import LayoutSettings, PlannerSettings, SpeedPerturbation, friction_label
from pipeline.planning.core.types import as_plan_file
from pipeline.planning.family.certificate import family_assumption
from pipeline.planning.feeder.layout import layout_plan
from pipeline.planning.plans.stored_plan import pick_tight_plan
from pipeline.planning.plans.speed_limit import DEFAULT_SPEEDS, speed_curve, stored_speed_limit
from pipeline.provenance import provenance_attrs


def layout_stored(result, planner: PlannerSettings, plan_number: int = 1, mu_text=None,
                  belt_speed: float | None = None, mu_s: float | None = None,
                  quasi_static: bool = False, settings: LayoutSettings | None = None) -> dict:
    """The layout of tight plan ``plan_number`` of a stored plan result
    (``RESULTS/plans/NAME.json``; a :class:`~pipeline.planning.core.types.PlanFile`
    or its dict), as ``pinfeed layout`` and the workflow make it.

    The plan's speed limit is the one stored with the plan (at the same belt
    friction; ``speed_limit.attach_speed_limits``), else computed
    (``speed_limit.speed_curve`` with ``speed_trials`` trials per state);
    ``speed_limit_trials`` says which trials it comes from and
    ``stored_speed_limit`` the plan file's figure. Without ``belt_speed`` the
    belt runs at ``speed_fraction`` (80 %) of it. A belt speed above the limit is kept and
    named in ``warnings``. Trials use the dynamic model at that speed, or the
    plan's quasi-static model with ``quasi_static`` (or when no belt speed
    passes the speed grid at all: then there is no belt speed and no
    throughput, and ``warnings`` says so).

    ``planner``: the planner's settings (pin radius, the verification's
    perturbation sizes and claim); ``settings``: the layout's
    (``LayoutSettings.from_section`` of the config's ``layout`` section with
    any overrides; ``None``: the schema's).
    """
    layout = settings or LayoutSettings()
    result = as_plan_file(result)
    plan, mu_c, states = _fixed_pin_plan(result, plan_number, mu_text)
    part = Part.from_dict(result.part, name=result.name)
    pin_radius = float(result.extra.get("pin_radius", planner.search.pin_radius))
    mu_s = float(layout.mu_s if mu_s is None else mu_s)
    heights = [float(h) for h in plan.pin_heights_mm]
    # A bad belt speed or mu_s is refused before any work.
    simulate.check_belt(part, min(DEFAULT_SPEEDS) if belt_speed is None else belt_speed, mu_s)
    curve, trials, stored = _speed_limit(plan, part, list(states.values()), mu_c, mu_s, pin_radius,
                                         planner, layout)
    limit = curve["speed_limit_mm_s"]
    belt_speed, source, quasi_static, warnings = _belt_speed_choice(belt_speed, limit, layout,
                                                                    quasi_static)
    out = layout_plan(part, list(plan.pins), heights, states, mu_c, pin_radius, model=result.model,
                      belt_speed=None if quasi_static else belt_speed, mu_s=mu_s, settings=layout,
                      verify=planner.verify, claims=planner.claims)
    out["belt_speed_mm_s"] = None if belt_speed is None else float(belt_speed)
    out["mu_s"] = mu_s
    out["throughput_per_min"] = None if belt_speed is None else 60.0 * belt_speed / out["pitch_mm"]
    out["speed_limit_mm_s"] = float(limit)
    out["mu_c"] = list(mu_c) if isinstance(mu_c, tuple) else mu_c
    out["plan"] = {"number": int(plan_number), "friction": friction_label(mu_c),
                   "pins": list(plan.pins), "pin_heights_mm": heights,
                   "final_sets": [s.to_dict() for s in plan.final_sets],
                   "n_final_sets": plan.n_final_sets}
    verified = plan.verification.to_dict() if plan.verification else None
    out["warnings"] = warnings + final_sets_warning(dict(out["plan"], verification=verified))
    _family_assumption(out, result)
    out["method"]["belt_speed"] = source
    out["method"]["throughput"] = "60 x belt speed / pitch" if belt_speed else "none: no belt speed"
    _record_speed_limit(out, curve, trials, stored)
    out.update(provenance_attrs())
    return out


def _family_assumption(out: dict, result) -> None:
    """For a plan made for a support family: ``assumes`` and a one-line
    ``assumption`` (also among the warnings): the belt speed and spacing come
    from the dynamic model, which assumes uniform pressure."""
    note = family_assumption(result, "layout")
    if note:
        out.update(note)
        out["warnings"].append(note["assumption"])


def _record_speed_limit(out: dict, curve: dict, trials: int, stored: dict | None) -> None:
    """Write into the layout ``out`` where its speed limit comes from: the trials per
    state (``speed_limit_trials``), the plan file's figure (``stored_speed_limit``)
    and ``method.speed_limit``."""
    out["speed_limit_trials"] = int(trials)
    out["stored_speed_limit"] = None if stored is None else {
        k: stored[k] for k in ("speed_limit_mm_s", "trials", "mu_s")}
    out["method"]["speed_limit"] = {
        "model": "dynamic", "trials_per_state": int(trials), "corners_per_state": 4,
        "source": "stored with the plan" if curve is stored else "computed for this layout",
        "required_fraction": 0.99, "speeds_mm_s": list(DEFAULT_SPEEDS), "bisection_mm_s": 5.0,
        "curve": curve["curve"]}


def _speed_limit(plan, part, states, mu_c, mu_s, pin_radius, planner, layout: LayoutSettings) -> tuple:
    """``(curve, trials, stored)``: the speed limit stored with ``plan`` when it was
    computed at belt friction ``mu_s`` (one speed limit per plan), else one computed
    here with ``speed_trials`` trials per state; ``stored``: the plan's record or None."""
    stored = stored_speed_limit(plan)
    if stored and stored["settings"]["mu_s"] == mu_s:
        return stored, stored["trials"], stored
    heights = [float(h) for h in plan.pin_heights_mm]
    curve = speed_curve(part, heights, [0.0] * len(heights), states, plan.final_arcs, mu_c, mu_s=mu_s,
                        perturb=SpeedPerturbation.from_verify(planner.verify.perturbation),
                        trials=layout.speed_trials, r_pin=pin_radius, seed=layout.seed)
    return curve, layout.speed_trials, stored


def _fixed_pin_plan(result, plan_number, mu_text):
    """``(plan, mu_c, states)``: tight plan ``plan_number`` at friction ``mu_text``
    of the :class:`~pipeline.planning.core.types.PlanFile` ``result``
    (:func:`~pipeline.planning.plans.stored_plan.pick_tight_plan`), refused with a one-line
    :class:`PinfeedError` if it has moving pins; ``states``: label ->
    ``(theta_deg, y_c_mm)``, the entry's resting states, else the file's."""
    plan, mu_c, entry = pick_tight_plan(result, int(plan_number), mu_text)
    if any(float(v) for v in plan.pin_speeds or ()):
        fixed = [f"--plan {k} ({' '.join(p.pins)})" for k, p in enumerate(entry.plans, start=1)
                 if not any(float(v) for v in p.pin_speeds or ())]
        usable = (f"plans of fixed pins: {', '.join(fixed)}" if fixed else
                  "no stored plan at this friction has fixed pins only; re-plan with --dynamic-depth 0")
        raise PinfeedError(f"plan {plan_number} ({' '.join(plan.pins)}) has moving pins; a layout "
                           f"places fixed pins only; {usable}")
    stored_states = entry.initial_states or result.initial_states or {}
    return plan, mu_c, {k: (float(s.theta), float(s.y_c)) for k, s in stored_states.items()}


def _belt_speed_choice(belt_speed, limit, layout: LayoutSettings, quasi_static):
    """``(belt_speed, source, quasi_static, warnings)`` of a stored plan's layout.

    Without ``belt_speed`` (mm/s): ``speed_fraction`` of the speed ``limit``
    (mm/s), or none and the quasi-static model when no speed passes; a given
    speed above the limit is kept with a warning.
    """
    warnings = []
    if belt_speed is None and limit > 0:
        belt_speed = layout.speed_fraction * limit
        source = f"{100 * layout.speed_fraction:g} % of the plan's speed limit {limit:g} mm/s"
    elif belt_speed is None:
        source = "none"
        quasi_static = True
        warnings.append(f"no belt speed of the grid ({', '.join(f'{v:g}' for v in DEFAULT_SPEEDS)} "
                        f"mm/s) passes the plan's trials: laid out with the quasi-static model, no "
                        f"throughput; give --belt-speed MM_S")
    else:
        source = "given"
        if belt_speed > limit:
            warnings.append(f"belt speed {belt_speed:g} mm/s is above the plan's speed limit "
                            f"{limit:g} mm/s (fewer than 99 % of its trials end in the final set)")
    return belt_speed, source, quasi_static, warnings


def final_sets_warning(plan: dict) -> list[str]:
    """A warning (a list of none or one line) when a laid-out plan leaves the parts in
    several final orientation sets: such a feeder does not orient them fully. A
    plan whose verification says it orients (its trials end in one set within
    the tolerance, though the claim names several narrower ones) gets none."""
    n = plan.get("n_final_sets") or len(plan.get("final_sets") or ())
    orientation = (plan.get("verification") or {}).get("orientation") or {}
    if n <= 1 or orientation.get("orients"):
        # Claimed sets that the verified trials show to lie in one set of the
        # tolerance's width are one orientation to the user.
        return []
    return [f"plan {plan['number']} leaves {n} final orientation sets ({format_arcs(plan['final_sets'])}): "
            f"parts leave this feeder in more than one orientation"]
