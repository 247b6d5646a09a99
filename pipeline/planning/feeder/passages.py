"""The passages an animation draws, and the plan it shows.

An animation of a plan (:func:`roll_plan`) places every initial state's
passage past the pins in the world frame: each contact is the rollout
kernel's own trajectory (``simulate.rollout(..., trajectory=True)``), the
belt carries the part downstream (+x) at unit speed, the clock is the belt
travel B (mm); a pin stands at station X_k and, if it moves, its height is
``h_k + v_k * (x_free - X_k)`` with ``x_free`` the centroid's belt-carried
station (spec section 3's convention for d). Between pins the part rides the
belt unchanged. One lane per initial state, all on the same clock.

A laid-out feeder (``pinfeed layout``'s JSON; :func:`station_scene`) is one
belt instead: the pins at the layout's stations, parts arriving at its
pitch, each replaying its state's passage with the layout's model.

:func:`plan_inputs` and :func:`layout_inputs` read which plan a stored plan
result's animation shows. :mod:`pipeline.present.animate` draws all this.
"""
from __future__ import annotations

import math
import re
from dataclasses import dataclass

import numpy as np

from pipeline.errors import PinfeedError
from pipeline.maps import simulate
from pipeline.parts.contact import contact_parameter
from pipeline.planning.core.settings import PlannerSettings, nominal_friction
from pipeline.planning.core.types import as_plan_file
from pipeline.planning.feeder.lanes import build_lane, pin_reach, rotated, run_trials, trial_lanes
from pipeline.planning.plans.stored_plan import pick_tight_plan


def roll_plan(part, heights, speeds, states: dict, mu_c, model, pin_radius, spacing=None):
    """Lanes for every initial state and the pin stations.

    ``heights``/``speeds``: per pin of the plan, in order (mm; v_pin / v_b).
    ``states``: label -> (theta_deg, y_c mm). Returns ``(lanes, stations, B_end)``.
    """
    if len(heights) != len(speeds):
        raise PinfeedError("give one speed per pin height")
    a = part.a
    runs = {}
    for label, (theta, y_c) in states.items():  # the kernel results do not depend on stations
        steps = []
        for h, v in zip(heights, speeds):
            r = simulate.rollout(part, theta, contact_parameter(h, y_c, a), mu_c, pin_radius, model=model,
                                 v_pin=float(v), trajectory=True)
            steps.append((theta, y_c, r))
            if str(r.status.item()) == "jammed":
                break
            theta, y_c = float(r.theta_f), y_c + float(r.dy)
        runs[label] = steps
    longest = max([float(r.traj_s[-1]) for steps in runs.values() for *_, r in steps if r.traj_s.size]
                  + [0.0])
    spacing = spacing or max(4.0 * a, longest + 3.0 * a)
    stations = [(k + 1) * spacing for k in range(len(heights))]
    lanes = [build_lane(part, label, steps, stations, heights, speeds, pin_radius)
             for label, steps in runs.items()]
    return lanes, stations, stations[-1] + spacing if stations else spacing


_LABEL = re.compile(r"^P(\d+)(?:v([+-]?[\d.]+))?$")


def recommended_index(result):
    """Which plan of a stored result (a :class:`~pipeline.planning.core.types.PlanFile`
    or its dict) is the recommended one: ``"tight"`` (the tight planner's
    recommended plan at the first friction), else ``1`` (paper mode's best),
    else None (no plan)."""
    result = as_plan_file(result)
    if result.tight and result.tight[0].recommended:
        return "tight"
    return 1 if result.plans else None


def _chosen_plan(result, plan_index):
    """(:class:`Plan`, friction, description) of ``plan_index`` in the
    :class:`PlanFile` ``result``: None (the recommended plan), ``"tight"``, or
    a 1-based paper-mode index."""
    name = result.name
    if plan_index is None:
        plan_index = recommended_index(result)
        if plan_index is None:
            raise PinfeedError(f"{name}: the stored result has no plan to animate")
    if plan_index == "tight":
        tight = result.tight[0] if result.tight else None
        if not tight or not tight.recommended:
            raise PinfeedError(f"{name}: the stored result has no recommended tight plan")
        mu = tight.planned_friction.nominal
        return tight.recommended, mu, f"tight plan at mu_c {tight.friction}"
    plans = result.plans or ()
    if not plans:
        raise PinfeedError(f"{name}: the stored result has no paper-mode plan to animate")
    if not 1 <= plan_index <= len(plans):
        raise PinfeedError(f"--plan {plan_index}: {name} has plans 1 to {len(plans)}")
    return plans[plan_index - 1], float(result.mu_c), f"plan {plan_index}"


def _resting_states(*stored) -> dict:
    """label -> ``(theta_deg, y_c_mm)`` of the first non-empty of ``stored``
    (label -> :class:`~pipeline.planning.core.plan_records.RestingState` maps or None):
    ``pinfeed plan --mode tight`` files keep them per friction entry only."""
    found = next((s for s in stored if s), {})
    return {k: (float(s.theta), float(s.y_c)) for k, s in found.items()}


def plan_inputs(result, plan_index, planner: PlannerSettings) -> dict:
    """Plain inputs of a plan of a stored plan result (``RESULTS/plans/NAME.json``;
    a :class:`~pipeline.planning.core.types.PlanFile` or its dict): pin labels,
    heights, speeds, states, physics, and ``what`` (which plan).
    ``plan_index``: None for the recommended plan (the tight planner's, else
    paper mode's best), ``"tight"``, or a 1-based paper-mode plan. Heights: the
    plan's ``pin_heights_mm`` if present, else the result's label -> height
    table, else the planner's configured pin heights by label P1..."""
    result = as_plan_file(result)
    plan, mu_c, what = _chosen_plan(result, plan_index)
    labels = list(plan.pins)
    table = result.pins if isinstance(result.pins, dict) else {}
    speeds_table = result.pin_speeds or {}
    heights, speeds = [], []
    for k, label in enumerate(labels):
        m = _LABEL.match(str(label))
        if plan.pin_heights_mm is not None:
            h = float(plan.pin_heights_mm[k])
        elif label in table:
            h = float(table[label])
        elif m and isinstance(planner.search.pins, tuple) and int(m.group(1)) <= len(planner.search.pins):
            h = float(planner.search.pins[int(m.group(1)) - 1])
        else:
            raise PinfeedError(f"pin {label!r} of the {what} has no height in the plan or the config")
        heights.append(h)
        if plan.pin_speeds is not None:
            speeds.append(float(plan.pin_speeds[k]))
        else:
            speeds.append(float(speeds_table.get(label, float(m.group(2)) if m and m.group(2) else 0.0)))
    states = _resting_states(result.initial_states, result.tight[0].initial_states if result.tight else None)
    return {"labels": labels, "heights": heights, "speeds": speeds, "states": states,
            "mu_c": mu_c, "model": result.model, "what": what,
            "pin_radius": float(result.extra.get("pin_radius", planner.search.pin_radius))}


def layout_inputs(result, layout: dict) -> dict:
    """The plan a layout (``pinfeed layout``'s JSON) was made from, in a stored plan
    result (a :class:`~pipeline.planning.core.types.PlanFile` or its dict):
    ``{"labels", "heights", "states", "mu_c", "what"}``. A one-line
    :class:`PinfeedError` when the layout is of another part, has no plan, or
    its pins are not the stored plan's."""
    result = as_plan_file(result)
    name = result.name
    if layout.get("part") != name:
        raise PinfeedError(f"the layout is of {layout.get('part')!r}, not {name!r}")
    if not layout.get("plan") or not layout.get("stations"):
        raise PinfeedError(f"the layout of {name} has no plan to animate ({layout.get('note', 'no stations')})")
    number, friction = int(layout["plan"]["number"]), layout["plan"].get("friction")
    plan, mu_c, entry = pick_tight_plan(result, number, friction)
    labels = [str(r["label"]) for r in layout["stations"]]
    if list(plan.pins) != labels:
        raise PinfeedError(f"the layout's pins {' '.join(labels)} are not tight plan {number}'s "
                           f"({' '.join(plan.pins)}) in the stored plan; re-run 'pinfeed layout'")
    return {"labels": labels, "heights": [float(r["y_mm"]) for r in layout["stations"]],
            "states": _resting_states(entry.initial_states, result.initial_states),
            "mu_c": layout.get("mu_c", list(mu_c) if isinstance(mu_c, tuple) else mu_c),
            "what": f"tight plan {number} at mu_c {entry.friction}"}


@dataclass
class StationScene:
    """A laid-out feeder (``pinfeed layout``'s JSON) on one belt, world frame:
    x downstream, the fence at y = ``fence_y``, pins at their stations. Parts
    arrive ``pitch`` apart, cycling through the initial states: part k runs
    ``lanes[k % len(lanes)]`` shifted ``k * pitch`` later on the belt clock B
    (mm); at B = 0 part 0's centroid stands at x = -``entry``."""

    part: object
    lanes: list  # one Lane per initial state, world frame (first pin at its x_mm)
    stations: list  # the layout's rows: label, x_mm, y_mm, radius_mm
    pitch: float
    entry: float
    n_parts: int
    fence_y: float
    fence_end: float
    belt_y: tuple
    belt_speed: float | None
    model: str  # what the passages were replayed with: "dynamic" or a quasi-static model
    b_end: float = 0.0

    def part_poses(self, b: float) -> list:
        """``(k, state, x, y, theta_deg)`` of every part of the stream at belt travel ``b``."""
        out = []
        for k in range(self.n_parts):
            lane = self.lanes[k % len(self.lanes)]
            x, y, th = (float(v[0]) for v in lane.poses(np.array([b - k * self.pitch])))
            out.append((k, lane.label, x, y, th))
        return out


def station_scene(part, layout: dict, states: dict, mu_c, n_parts: int | None = None) -> StationScene:
    """Replay one nominal passage per initial state with the layout's model (the
    dynamic model at its belt speed and ``mu_s`` when the layout used it, else
    its quasi-static model: :func:`~pipeline.planning.feeder.lanes.run_trials` with ``nominal``, the kernels'
    trajectories) past the layout's stations, and set up the stream of parts.

    ``layout``: the JSON of ``pinfeed layout`` (``stations``, ``pitch_mm``,
    ``fence_y_mm``, ``fence_end_x_mm``, ``belt_y_mm``, ``belt_speed_mm_s``,
    ``mu_s``, ``method.model``, ``method.margins_mm``). ``states``: label ->
    ``(theta_deg, y_c_mm)``. ``n_parts``: default one per state, at least 3."""
    rows = layout.get("stations") or []
    if not rows:
        raise PinfeedError(f"the layout of {layout.get('part', 'the part')} has no pin stations "
                           f"({layout.get('note', 'no plan')})")
    if not states:
        raise PinfeedError("give at least one initial state")
    pitch = float(layout["pitch_mm"])
    if not pitch > 0:
        raise PinfeedError(f"the layout's pitch must be > 0 mm, got {pitch!r}")
    heights = [float(r["y_mm"]) for r in rows]
    xs = [float(r["x_mm"]) for r in rows]
    pin_radius = float(rows[0]["radius_mm"])
    method = layout.get("method") or {}
    model = method.get("model", "minpower")
    speed = layout.get("belt_speed_mm_s")
    if model == "dynamic" and speed is None:
        raise PinfeedError("the layout used the dynamic model but gives no belt_speed_mm_s")
    mu = nominal_friction(tuple(mu_c) if isinstance(mu_c, list) else mu_c)
    trials = run_trials(part, heights, states, mu, pin_radius, model,
                        belt_speed=float(speed) if model == "dynamic" else None,
                        mu_s=float(layout.get("mu_s") or 0.5), nominal=True)
    margin = float((method.get("margins_mm") or {}).get("station_margin_mm", 5.0))
    # As the layout: every centroid starts far enough upstream of the first pin that nothing touches.
    reach = [float(pin_reach(rotated(part.vertices, t.theta), heights[0] - t.y_c, pin_radius))
             for t in trials]
    entry = max([r for r in reach if math.isfinite(r)] + [part.a + pin_radius]) + margin
    lanes = trial_lanes(part, trials, [x - xs[0] for x in xs], pin_radius, entry)
    for lane, t in zip(lanes, trials):
        lane.x = lane.x + xs[0]
        if t.jam:
            lane.outcome = t.jam
    n = int(n_parts or max(3, len(lanes)))
    fence_y = float(layout.get("fence_y_mm", 0.0))
    belt = layout.get("belt_y_mm") or [fence_y, max(float(ln.y.max()) for ln in lanes) + part.a]
    scene = StationScene(part, lanes, rows, pitch, entry - xs[0], n, fence_y,
                         float(layout.get("fence_end_x_mm", xs[0] - pin_radius)),
                         (float(belt[0]), float(belt[1])), None if speed is None else float(speed), model)
    # The clock runs until the last part has passed its last contact and ridden one size on.
    scene.b_end = (n - 1) * pitch + max(float(ln.B[-1]) for ln in lanes) + 2.0 * part.a
    return scene
