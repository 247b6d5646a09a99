"""Watch a plan work: every initial state rolls past the pins on the moving belt.

The core takes plain inputs (a part, pin heights and speeds, initial states,
friction, model, pin radius), so it does not depend on the planner's
internals. Each contact is the rollout kernel's own trajectory
(``simulate.rollout(..., trajectory=True)``), placed in the world frame: the
belt carries the part downstream (+x) at unit speed, the clock is the belt
travel B (mm); a pin stands at station X_k and, if it moves, its height is
``h_k + v_k * (x_free - X_k)`` with ``x_free`` the centroid's belt-carried
station (spec section 3's convention for d). Between pins the part rides the
belt unchanged. One lane per initial state, all on the same clock.

A laid-out feeder (``pinfeed layout``'s JSON; :func:`animate_layout`) is drawn
on one belt instead: the pins at the layout's stations, parts arriving at its
pitch, each replaying its state's passage with the layout's model.
"""
from __future__ import annotations

import math
import re
import textwrap
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from pipeline.errors import PinfeedError
from pipeline.parts.contact import contact_parameter
from pipeline.present.figures import LABEL_ROW_PT, label_above, stagger_labels
from pipeline.present.lanes import build_lane, pin_height, pin_reach, rotated


def roll_plan(part, heights, speeds, states: dict, mu_c, model, pin_radius, spacing=None):
    """Lanes for every initial state and the pin stations.

    ``heights``/``speeds``: per pin of the plan, in order (mm; v_pin / v_b).
    ``states``: label -> (theta_deg, y_c mm). Returns ``(lanes, stations, B_end)``.
    """
    from pipeline.maps import simulate
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


DPI = 80


def _check_animation_out(out, frames: int, fps: int) -> Path:
    """``out`` as a Path, checked before any work: a .gif, or an .mp4 where ffmpeg
    is installed, and at least 2 frames at 1 fps or more."""
    from matplotlib import animation
    out = Path(out)
    suffix = out.suffix.lower()
    if suffix not in (".gif", ".mp4"):
        raise PinfeedError(f"--out {out}: write a .gif or an .mp4 file")
    if suffix == ".mp4" and not animation.writers.is_available("ffmpeg"):
        raise PinfeedError("writing MP4 needs ffmpeg, which is not installed here; write a .gif "
                           "instead (--out plan.gif) or install ffmpeg")
    if frames < 2 or fps < 1:
        raise PinfeedError(f"--frames must be at least 2 and --fps at least 1, got {frames} and {fps}")
    return out


def _write_animation(fig, draw, b_end: float, out: Path, frames: int, fps: int) -> int:
    """Draw ``frames`` evenly spaced belt travels 0..``b_end`` with ``draw(B)``,
    write them to ``out`` (Pillow for .gif, ffmpeg for .mp4), close ``fig`` and
    return the number of frames written; the frames drawn so far go to the
    progress report of :func:`pipeline.progress.reporting`, if any."""
    import matplotlib.pyplot as plt
    from matplotlib import animation

    from pipeline.progress import Heartbeat
    B = np.linspace(0.0, b_end, int(frames))
    anim = animation.FuncAnimation(fig, lambda i: draw(B[i]), frames=len(B), blit=False)
    out.parent.mkdir(parents=True, exist_ok=True)
    writer = animation.PillowWriter(fps=fps) if out.suffix.lower() == ".gif" else animation.FFMpegWriter(fps=fps)
    with Heartbeat(f"writing {out.name}", len(B), "frame") as beat:
        anim.save(str(out), writer=writer, dpi=DPI, progress_callback=lambda i, n: beat.tick(i + 1))
    plt.close(fig)
    return int(len(B))


def animate_plan(part, heights, speeds, states: dict, mu_c, model, pin_radius, out,
                 labels=None, frames: int = 120, fps: int = 20, title: str | None = None) -> dict:
    """Write the animation to ``out`` (.gif through Pillow; .mp4 needs ffmpeg).
    Returns ``{"out", "frames", "belt_travel", "outcomes"}``.

    The still parts (axes, fence, fixed pins, labels) are drawn once into an
    image; each frame draws only the moving ones over it, in pixel coordinates
    taken from the still figure's transforms, so long animations stay quick."""
    import matplotlib.pyplot as plt

    from pipeline.present.figures import save_figure  # noqa: F401 (selects the Agg backend)
    out = _check_animation_out(out, frames, fps)
    labels = labels or [f"P{k + 1}" for k in range(len(heights))]
    lanes, stations, b_end = roll_plan(part, heights, speeds, states, mu_c, model, pin_radius)
    still, panes = _still_figure(part, lanes, stations, heights, speeds, labels, pin_radius, b_end,
                                 title or f"{part.name}: pins {' → '.join(labels)}")
    fig, draw = _moving_figure(part, still, panes, stations, heights, speeds, pin_radius)
    plt.close(still)
    n_frames = _write_animation(fig, draw, b_end, out, frames, fps)
    return {"out": str(out), "frames": n_frames, "belt_travel": float(b_end),
            "outcomes": {ln.label: ln.outcome for ln in lanes}}


def _still_figure(part, lanes, stations, heights, speeds, labels, pin_radius, b_end, title):
    """The figure without moving parts; returns it and, per lane, ``(lane, axes, y_low)``."""
    import matplotlib.pyplot as plt
    from matplotlib.patches import Circle
    a = part.a
    ys = [y for ln in lanes for y in ln.y] + list(heights)
    lo, hi = min(ys + [0.0]) - 1.3 * a, max(ys) + 1.3 * a
    x_lo, x_hi = -1.5 * a, b_end + 1.5 * a
    lane_h = max(1.6, 9.0 * (hi - lo) / (x_hi - x_lo))
    fig, axes = plt.subplots(len(lanes), 1, figsize=(9.0, lane_h * len(lanes) + 1.0), squeeze=False,
                             dpi=DPI)
    panes = []
    for ax, lane in zip(axes[:, 0], lanes):
        ax.set_xlim(x_lo, x_hi)
        ax.set_ylim(lo, hi)
        ax.set_aspect("equal")
        # The fence guides the parts up to the pins; downstream the belt is open.
        fence_end = stations[0] - 1.2 * a if stations else x_hi
        ax.plot([x_lo, fence_end], [0.0, 0.0], color="k", lw=2.5)
        ax.text(x_lo + 0.1 * a, 0.0, "fence", fontsize=7, va="bottom")
        ax.set_ylabel(f"{lane.label}\n$y$ (mm)", fontsize=8)
        ax.tick_params(labelsize=7)
        pin_labels = []
        for k, (h, v, x) in enumerate(zip(heights, speeds, stations)):
            colour = "tab:purple" if v else "tab:red"
            if not v:  # moving pins are drawn frame by frame
                ax.add_patch(Circle((x, h), pin_radius, color=colour, zorder=3))
            ax.axvline(x, color=colour, lw=0.4, ls=":", zorder=0)
            pin_labels.append(label_above(ax, x, f"{labels[k]}: {h:g} mm" + (
                f", $v_{{pin}}$ = {v:+g} $v_b$" if v else ""), fontsize=7, color=colour))
        stagger_labels(fig, pin_labels)
        panes.append((lane, ax, lo))
    axes[-1, 0].set_xlabel("along the belt $x$ (mm), belt moving to the right", fontsize=8)
    fig.suptitle(textwrap.fill(title, 110), fontsize=9)
    fig.tight_layout(rect=(0, 0, 1, 0.96))
    fig.canvas.draw()
    return fig, panes


def _moving_figure(part, still, panes, stations, heights, speeds, pin_radius):
    """A figure showing the still one as an image, and ``draw(b)`` that poses the
    moving artists (parts, moving pins, belt marks, notes, clock) at belt travel b."""
    import matplotlib.pyplot as plt
    from matplotlib.patches import Circle, Rectangle

    from pipeline.present.figures.outline import PartPatch
    a = part.a
    w, h = still.canvas.get_width_height()
    image = np.asarray(still.canvas.buffer_rgba()).copy()
    fig = plt.figure(figsize=(w / DPI, h / DPI), dpi=DPI)
    bg = fig.add_axes((0, 0, 1, 1))
    bg.imshow(image, extent=(0, w, 0, h), origin="upper", interpolation="nearest")
    bg.set_xlim(0, w)
    bg.set_ylim(0, h)
    bg.axis("off")
    movers = []
    for lane, ax, lo in panes:
        to_px = ax.transData.frozen()  # lane data (mm) -> pixels of the still figure
        scale = to_px.transform((1.0, 0.0))[0] - to_px.transform((0.0, 0.0))[0]
        (x0, y0), (x1, y1) = ax.bbox.get_points()
        clip = Rectangle((x0, y0), x1 - x0, y1 - y0, transform=bg.transData, visible=False)
        bg.add_patch(clip)
        body = PartPatch(part, to=to_px, fc="tab:blue", ec="k", alpha=0.7, zorder=2)
        bg.add_patch(body)
        body.set_clip_path(clip)
        pins = {}
        for k, v in enumerate(speeds):
            if v:
                pins[k] = Circle((0, 0), pin_radius * scale, color="tab:purple", zorder=3)
                bg.add_patch(pins[k])
                pins[k].set_clip_path(clip)
        marks, = bg.plot([], [], "|", color="0.6", ms=6)
        marks.set_clip_path(clip)
        note = bg.text(x1 - 4, y0 + 4, "", ha="right", va="bottom", fontsize=7)
        x_lo, x_hi = ax.get_xlim()
        movers.append((lane, to_px, body, pins, marks, note, lo, x_lo, x_hi))
    clock = fig.text(0.01, 0.99, "", ha="left", va="top", fontsize=9, family="monospace")

    def draw(b):
        clock.set_text(f"belt travel {b:6.1f} mm")
        for lane, to_px, body, pins, marks, note, lo, x_lo, x_hi in movers:
            x, y, th = lane.pose(b)
            body.set_pose(th, x, y)
            for k, pin in pins.items():
                pin.center = tuple(to_px.transform((stations[k], pin_height(
                    lane, k, b, heights[k], speeds[k], stations[k]))))
            ticks = np.arange((b % (0.5 * a)) + x_lo, x_hi, 0.5 * a)  # the belt's texture moves with it
            px = to_px.transform(np.column_stack([ticks, np.full_like(ticks, lo + 0.15 * a)]))
            marks.set_data(px[:, 0], px[:, 1])
            done = b >= lane.B[-1]
            jammed = lane.outcome != "ok"
            note.set_text(lane.outcome if jammed and done else (rf"$\theta$ = {th % 360:.1f}°" if done else ""))
            note.set_color("tab:red" if jammed else "black")
        return []

    return fig, draw


# ---------------------------------------------------------------- stored plans


_LABEL = re.compile(r"^P(\d+)(?:v([+-]?[\d.]+))?$")


def recommended_index(result):
    """Which plan of a stored result (a :class:`~pipeline.planning.core.types.PlanFile`
    or its dict) is the recommended one: ``"tight"`` (the tight planner's
    recommended plan at the first friction), else ``1`` (paper mode's best),
    else None (no plan)."""
    from pipeline.planning import as_plan_file
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
    (label -> :class:`~pipeline.planning.core.types.RestingState` maps or None):
    ``pinfeed plan --mode tight`` files keep them per friction entry only."""
    found = next((s for s in stored if s), {})
    return {k: (float(s.theta), float(s.y_c)) for k, s in found.items()}


def plan_inputs(result, plan_index, config: dict) -> dict:
    """Plain inputs of a plan of a stored plan result (``RESULTS/plans/NAME.json``;
    a :class:`~pipeline.planning.core.types.PlanFile` or its dict): pin labels,
    heights, speeds, states, physics, and ``what`` (which plan).
    ``plan_index``: None for the recommended plan (the tight planner's, else
    paper mode's best), ``"tight"``, or a 1-based paper-mode plan. Heights: the
    plan's ``pin_heights_mm`` if present, else the result's label -> height
    table, else the config's ``planner.pins`` by label P1..."""
    from pipeline.planning import as_plan_file
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
        elif m and isinstance(config["planner"].get("pins"), list) \
                and int(m.group(1)) <= len(config["planner"]["pins"]):
            h = float(config["planner"]["pins"][int(m.group(1)) - 1])
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
            "pin_radius": float(result.extra.get("pin_radius", config["sweep"]["pin_radius"]))}


def layout_inputs(result, layout: dict) -> dict:
    """The plan a layout (``pinfeed layout``'s JSON) was made from, in a stored plan
    result (a :class:`~pipeline.planning.core.types.PlanFile` or its dict):
    ``{"labels", "heights", "states", "mu_c", "what"}``. A one-line
    :class:`PinfeedError` when the layout is of another part, has no plan, or
    its pins are not the stored plan's."""
    from pipeline.planning import pick_tight_plan
    from pipeline.planning import as_plan_file
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


def animation_subject(result, config: dict, layout: dict | None = None) -> str:
    """What the workflow's animation of a stored plan result shows, in words, from
    the records it is drawn from (the caption of that animation): the laid-out
    plan of ``layout`` when it has stations, else the recommended plan
    (:func:`recommended_index`); ``'no plan'`` without one."""
    if layout is not None and layout.get("stations"):
        return f"the laid-out {layout_inputs(result, layout)['what']}"
    which = recommended_index(result)
    return "no plan" if which is None else f"the {plan_inputs(result, which, config)['what']}"


def animate_stored(result, config: dict, out, plan_index=None, frames: int = 120,
                   fps: int = 20, layout: dict | None = None) -> dict:
    """Animate a plan of a stored plan result (``plan_index`` as in :func:`plan_inputs`;
    what ``pinfeed animate`` and the workflow's animate rule call). Returns
    :func:`animate_plan`'s summary plus the inputs.

    With ``layout`` (``pinfeed layout``'s JSON for this part) the layout's own
    plan is animated on one belt instead (:func:`animate_layout`): pins at the
    stations, parts arriving at the layout's pitch; ``plan_index`` is then
    not used."""
    from pipeline.parts.part import Part
    from pipeline.planning import as_plan_file
    result = as_plan_file(result)
    if layout is not None:
        inputs = layout_inputs(result, layout)
        part = Part.from_dict(result.part, name=result.name)
        done = animate_layout(part, layout, inputs["states"], inputs["mu_c"], out, frames=frames, fps=fps,
                              what=f"{inputs['what']}, pins {' → '.join(inputs['labels'])}")
        return {**done, **inputs}
    inputs = plan_inputs(result, plan_index, config)
    part = Part.from_dict(result.part, name=result.name)
    done = animate_plan(part, inputs["heights"], inputs["speeds"], inputs["states"], inputs["mu_c"],
                        inputs["model"], inputs["pin_radius"], out, labels=inputs["labels"],
                        frames=frames, fps=fps,
                        title=f"{part.name}: {inputs['what']}, pins {' → '.join(inputs['labels'])}")
    return {**done, **inputs}


# ------------------------------------------------------- a layout's feeder


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
    its quasi-static model: ``lanes.run_trials(nominal=True)``, the kernels'
    trajectories) past the layout's stations, and set up the stream of parts.

    ``layout``: the JSON of ``pinfeed layout`` (``stations``, ``pitch_mm``,
    ``fence_y_mm``, ``fence_end_x_mm``, ``belt_y_mm``, ``belt_speed_mm_s``,
    ``mu_s``, ``method.model``, ``method.margins_mm``). ``states``: label ->
    ``(theta_deg, y_c_mm)``. ``n_parts``: default one per state, at least 3."""
    from pipeline.present.lanes import run_trials, trial_lanes
    from pipeline.planning import nominal_friction
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


def station_figure(scene: StationScene, title: str) -> dict:
    """The feeder's figure: belt, fence up to its end, pins (circles at the
    stations), and one outline per part of the stream. Returns ``{"fig", "ax",
    "pins", "parts", "draw"}``: ``pins`` the pin circles in station order,
    ``parts`` the part polygons (part k first), ``draw(b)`` poses the parts at
    belt travel ``b`` and returns the artists it changed."""
    import matplotlib.pyplot as plt
    from matplotlib.patches import Circle, Rectangle

    from pipeline.present.figures import save_figure  # noqa: F401 (selects the Agg backend)
    from pipeline.present.figures.outline import PartPatch
    part, a = scene.part, scene.part.a
    x_lo = -scene.entry - 1.5 * a
    x_hi = max([float(ln.x[-1]) for ln in scene.lanes]
               + [float(r["x_mm"]) + float(r["radius_mm"]) for r in scene.stations]) + 2.0 * a
    y_lo, y_hi = min(scene.belt_y[0], scene.fence_y) - 0.3 * a, scene.belt_y[1] + 0.6 * a
    fig, ax = plt.subplots(figsize=(9.0, max(2.2, 9.0 * (y_hi - y_lo) / (x_hi - x_lo) + 1.2)), dpi=DPI)
    ax.set_xlim(x_lo, x_hi)
    ax.set_ylim(y_lo, y_hi)
    ax.set_aspect("equal")
    ax.add_patch(Rectangle((x_lo, scene.belt_y[0]), x_hi - x_lo, scene.belt_y[1] - scene.belt_y[0],
                           fc="0.93", ec="0.5", lw=0.8, zorder=0))
    ax.plot([x_lo, scene.fence_end], [scene.fence_y] * 2, color="k", lw=2.5, zorder=1)
    ax.text(x_lo + 0.1 * a, scene.fence_y, "fence", fontsize=7, va="bottom")
    pins, labels = [], []
    for row in scene.stations:
        x, y, r = float(row["x_mm"]), float(row["y_mm"]), float(row["radius_mm"])
        pins.append(ax.add_patch(Circle((x, y), r, color="tab:red", zorder=3, gid=f"pin {row['label']}")))
        ax.axvline(x, color="tab:red", lw=0.4, ls=":", zorder=0)
        labels.append(label_above(ax, x, f"{row['label']}: x {x:.0f}, y {y:g} mm", fontsize=7,
                                  color="tab:red"))
    parts = [ax.add_patch(PartPatch(part, fc=f"C{k % len(scene.lanes)}", ec="k", alpha=0.75, zorder=2))
             for k in range(scene.n_parts)]
    marks, = ax.plot([], [], "|", color="0.6", ms=5, zorder=1)
    clock = ax.text(0.005, 0.98, "", transform=ax.transAxes, ha="left", va="top", fontsize=8,
                    family="monospace")
    ax.set_xlabel("along the belt $x$ (mm), belt moving to the right", fontsize=8)
    ax.set_ylabel("across the belt $y$ (mm)", fontsize=8)
    ax.tick_params(labelsize=7)
    rows = stagger_labels(fig, labels)  # close stations: their labels in rows
    ax.set_title(textwrap.fill(title, 110), fontsize=9, pad=6.0 + LABEL_ROW_PT * rows)
    fig.tight_layout()

    def draw(b):
        for (k, _, x, y, th), body in zip(scene.part_poses(b), parts):
            body.set_pose(th, x, y)
        ticks = np.arange(x_lo + b % (0.5 * a), x_hi, 0.5 * a)  # the belt's texture moves with it
        marks.set_data(ticks, np.full_like(ticks, scene.belt_y[0] + 0.1 * a))
        clock.set_text(f"belt travel {b:6.1f} mm")
        return parts + [marks, clock]

    return {"fig": fig, "ax": ax, "pins": pins, "parts": parts, "draw": draw}


def station_title(part_name: str, scene: StationScene, what: str = "") -> str:
    """Belt speed, pitch and the replay model, for the layout animation's title."""
    if scene.model == "dynamic":
        how = f"belt {scene.belt_speed:g} mm/s (dynamic model)"
    elif scene.belt_speed is not None:
        how = f"belt {scene.belt_speed:g} mm/s, replayed quasi-statically ({scene.model}) as the layout was"
    else:
        how = f"no belt speed: quasi-static replay ({scene.model})"
    return f"{part_name}{': ' + what if what else ''}; {how}; pitch {scene.pitch:.1f} mm"


def animate_layout(part, layout: dict, states: dict, mu_c, out, frames: int = 120, fps: int = 20,
                   title: str | None = None, n_parts: int | None = None, what: str = "") -> dict:
    """Write the animation of a laid-out feeder (:func:`station_scene`,
    :func:`station_figure`) to ``out`` (.gif; .mp4 needs ffmpeg). Returns
    ``{"out", "frames", "belt_travel", "outcomes", "pitch_mm", "model"}``."""
    out = _check_animation_out(out, frames, fps)
    scene = station_scene(part, layout, states, mu_c, n_parts)
    fig = station_figure(scene, title or station_title(part.name, scene, what))
    n_frames = _write_animation(fig["fig"], fig["draw"], scene.b_end, out, frames, fps)
    return {"out": str(out), "frames": n_frames, "belt_travel": float(scene.b_end),
            "outcomes": {ln.label: ln.outcome for ln in scene.lanes}, "pitch_mm": scene.pitch,
            "model": scene.model}
