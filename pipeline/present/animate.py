"""Watch a plan work: every initial state rolls past the pins on the moving belt.

This module draws; the passages it draws are computed by the planner's
feeder wing (:func:`pipeline.planning.roll_plan`: one lane per initial state,
each contact the rollout kernel's own trajectory placed in the world frame,
the clock the belt travel B in mm; :func:`pipeline.planning.station_scene`:
a laid-out feeder's stream of parts). :func:`animate_plan` draws the lanes
of a plan, one pane per initial state; :func:`animate_layout` draws a laid-out
feeder (``pinfeed layout``'s JSON) on one belt: the pins at the layout's
stations, parts arriving at its pitch. The still parts are drawn once, the
moving ones frame by frame.
"""
from __future__ import annotations

import textwrap
from pathlib import Path

import numpy as np

from pipeline.errors import PinfeedError
from pipeline.planning import StationScene, layout_inputs, pin_height, plan_inputs, recommended_index
from pipeline.present.figures import LABEL_ROW_PT, label_above, stagger_labels


DPI = 80


def check_animation_out(out, frames: int, fps: int) -> Path:
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


def animate_plan(part, lanes, stations, b_end: float, heights, speeds, pin_radius, out,
                 labels=None, frames: int = 120, fps: int = 20, title: str | None = None) -> dict:
    """Write the animation of a plan's passages to ``out`` (.gif through Pillow;
    .mp4 needs ffmpeg). Returns ``{"out", "frames", "belt_travel", "outcomes"}``.

    ``lanes``, ``stations``, ``b_end``: :func:`pipeline.planning.roll_plan` of
    the plan's ``heights`` and ``speeds`` (mm; v_pin / v_b, per pin in order).
    The still parts (axes, fence, fixed pins, labels) are drawn once into an
    image; each frame draws only the moving ones over it, in pixel coordinates
    taken from the still figure's transforms, so long animations stay quick."""
    import matplotlib.pyplot as plt

    from pipeline.present.figures import save_figure  # noqa: F401 (selects the Agg backend)
    out = check_animation_out(out, frames, fps)
    labels = labels or [f"P{k + 1}" for k in range(len(heights))]
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


def animation_subject(result, planner, layout: dict | None = None) -> str:
    """What the workflow's animation of a stored plan result shows, in words, from
    the records it is drawn from (the caption of that animation): the laid-out
    plan of ``layout`` when it has stations, else the recommended plan
    (:func:`recommended_index`; ``planner``: the planner's settings, a
    :class:`~pipeline.planning.PlannerSettings`); ``'no plan'`` without one."""
    if layout is not None and layout.get("stations"):
        return f"the laid-out {layout_inputs(result, layout)['what']}"
    which = recommended_index(result)
    return "no plan" if which is None else f"the {plan_inputs(result, which, planner)['what']}"


# ------------------------------------------------------- a layout's feeder


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


def animate_layout(scene, out, frames: int = 120, fps: int = 20, title: str | None = None,
                   what: str = "") -> dict:
    """Write the animation of a laid-out feeder to ``out`` (.gif; .mp4 needs
    ffmpeg): ``scene`` (:func:`pipeline.planning.station_scene`) drawn by
    :func:`station_figure`, titled ``title`` or :func:`station_title` with
    ``what``. Returns ``{"out", "frames", "belt_travel", "outcomes", "pitch_mm", "model"}``."""
    out = check_animation_out(out, frames, fps)
    fig = station_figure(scene, title or station_title(scene.part.name, scene, what))
    n_frames = _write_animation(fig["fig"], fig["draw"], scene.b_end, out, frames, fps)
    return {"out": str(out), "frames": n_frames, "belt_travel": float(scene.b_end),
            "outcomes": {ln.label: ln.outcome for ln in scene.lanes}, "pitch_mm": scene.pitch,
            "model": scene.model}
