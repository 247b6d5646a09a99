"""The feeder drawing of a layout (:func:`pipeline.planning.layout_stored`'s dict,
written by ``pipeline.present.layout``): a top view to build from.

One geometry (:func:`drawing_items`), two writers: :func:`draw_feeder`
(matplotlib: PNG or SVG) and :func:`write_dxf` (ezdxf, millimetres, layers
BELT, FENCE, PINS, DIMENSIONS, PARTS and TITLE). World frame of the spec:
x downstream (the belt moves to the right), y across the belt, the fence at
y = 0, the first pin at x = 0.
"""
from __future__ import annotations

import textwrap
from pathlib import Path

import numpy as np

from pipeline.maps.io import atomic_target

LAYERS = {"BELT": 8, "FENCE": 7, "PINS": 1, "DIMENSIONS": 3, "PARTS": 5, "TITLE": 7}  # ACI colours
TEXT_MM = 3.5


def _fmt(value, unit="", digits=1) -> str:
    return "n/a" if value is None else f"{value:.{digits}f}{unit}"


def title_lines(layout: dict) -> list[str]:
    """The title block, line by line: part, plan, frictions, belt speed, pitch,
    throughput, pinfeed version and date (``SOURCE_DATE_EPOCH`` if set)."""
    from pipeline import __version__
    from pipeline.provenance import creation_time
    plan = layout.get("plan") or {}
    pins = " ".join(plan.get("pins") or layout.get("pins") or [])
    mu_c = layout.get("mu_c")
    mu_c = f"{mu_c[0]:g}:{mu_c[1]:g}" if isinstance(mu_c, list) else ("n/a" if mu_c is None else f"{mu_c:g}")
    mu_s = layout.get("mu_s")
    limit = layout.get("speed_limit_mm_s")
    return [f"pinfeed feeder layout: {layout['part']}",
            f"plan {plan.get('number', '-')}: {pins}",
            f"mu_c {mu_c}   mu_s {'n/a' if mu_s is None else f'{mu_s:g}'}",
            f"belt speed {_fmt(layout.get('belt_speed_mm_s'), ' mm/s')}"
            f" (limit {_fmt(limit, ' mm/s')}"
            + (f", {layout['speed_limit_trials']} trials/state)" if layout.get("speed_limit_trials") else ")"),
            f"pitch {_fmt(layout['pitch_mm'], ' mm')}   belt width {_fmt(layout['belt_width_mm'], ' mm')}",
            f"throughput {_fmt(layout.get('throughput_per_min'), ' parts/min')}",
            f"pinfeed {layout.get('pinfeed_version', __version__)}   "
            f"{(layout.get('created') or creation_time())[:10]}   units mm"]


def drawing_items(layout: dict) -> dict:
    """Everything to draw, in mm: ``belt`` and ``fence`` segments, ``pins``
    (centre, radius, label), ``dims`` (``(p1, p2, offset point, text, angle)``),
    ``parts`` (closed outlines), ``holes`` (per part, its holes' closed
    outlines: none for a solid part), ``arrow`` (tail, head), ``title``
    (origin, lines), ``extent`` (x_lo, x_hi, y_lo, y_hi)."""
    stations = layout["stations"]
    y_lo, y_hi = layout["belt_y_mm"]
    drawn = [p for key in ("entry_parts", "exit_parts") for p in layout["drawing"][key]]
    parts = [np.asarray(p["outline"], float) for p in drawn]
    holes = [[np.asarray(h, float) for h in p.get("holes") or ()] for p in drawn]
    xs = np.concatenate([p[:, 0] for p in parts] + [[s["x_mm"] for s in stations]])
    x_lo, x_hi = float(xs.min()) - 15.0, float(xs.max()) + 15.0
    pin_r = max(s["radius_mm"] for s in stations)
    dims = []
    row = label_row_mm(x_hi - x_lo)
    # Stations: each pin's x from the first pin, stacked above the belt.
    for k, s in enumerate(stations[1:], start=1):
        y = y_hi + 8.0 + row * (k - 1)
        dims.append(((stations[0]["x_mm"], s["y_mm"]), (s["x_mm"], s["y_mm"]), (0.0, y),
                     f"{s['x_mm']:.1f}", 0.0))
    # Heights: each pin's y from the fence line, just left of the pin.
    for s in stations:
        dims.append(((s["x_mm"], 0.0), (s["x_mm"], s["y_mm"]), (s["x_mm"] - pin_r - 3.0, 0.0),
                     f"{s['y_mm']:.1f}", 90.0))
    entry = layout["drawing"]["entry_parts"]
    if len(entry) >= 2:
        a, b = entry[1], entry[0]
        dims.append(((a["x_mm"], a["y_mm"]), (b["x_mm"], b["y_mm"]), (0.0, y_lo - 8.0),
                     f"pitch {layout['pitch_mm']:.1f}", 0.0))
    dims.append(((x_lo, y_lo), (x_lo, y_hi), (x_lo - 6.0, 0.0),
                 f"belt {layout['belt_width_mm']:.1f}", 90.0))
    arrow_y = y_hi - 4.0
    # Pin labels: one row each above the station dimensions, joined to their pin by a
    # leader, so labels of close pins never cover one another or a dimension.
    label_y0 = y_hi + 8.0 + row * max(len(stations) - 1, 0)
    return {
        "belt": [((x_lo, y_lo), (x_hi, y_lo)), ((x_lo, y_hi), (x_hi, y_hi))],
        "fence": [((x_lo, layout["fence_y_mm"]), (layout["fence_end_x_mm"], layout["fence_y_mm"]))],
        "pins": [((s["x_mm"], s["y_mm"]), s["radius_mm"], f"{s['label']} y={s['y_mm']:g}",
                  (s["x_mm"], label_y0 + row * (k + 1))) for k, s in enumerate(stations)],
        "dims": dims,
        "parts": parts,
        "holes": holes,
        "arrow": ((x_lo + 5.0, arrow_y), (x_lo + 35.0, arrow_y)),
        # The title block's top right corner, under the belt and its dimensions.
        "title": ((x_hi, y_lo - 16.0), title_lines(layout)),
        "extent": (x_lo - 12.0, x_hi, y_lo - 16.0, label_y0 + row * (len(stations) + 1)),
    }


DRAWING_WIDTH_IN = 11.0  # the PNG/SVG figure's width, inches


def label_row_mm(span_mm: float) -> float:
    """Height of one pin label's row (mm): 1.6 lines of 7-point text at the
    drawing's scale (``span_mm`` across about 10 inches), at least 7 mm."""
    return max(7.0, 1.6 * span_mm / (DRAWING_WIDTH_IN - 1.0) * 7.0 / 72.0)


ALERT_COLOUR = "#bb0000"  # warnings (several final sets, a belt above its limit): red
#: The PNG text field that records the drawing's plan (its pins, space-separated).
PLAN_FIELD = "pinfeed-plan"


def draw_feeder(layout: dict, out) -> Path:
    """The drawing as PNG or SVG (by ``out``'s suffix), written atomically. A PNG
    records the plan it draws in its :data:`PLAN_FIELD` text field."""
    import matplotlib.pyplot as plt
    fig = feeder_figure(layout)
    out = Path(out)
    kind = out.suffix.lower().lstrip(".")
    plan = (layout.get("plan") or {}).get("pins")
    metadata = {PLAN_FIELD: " ".join(plan)} if kind == "png" and plan else None
    with atomic_target(out) as tmp:
        fig.savefig(tmp, format=kind, dpi=110, metadata=metadata)
    plt.close(fig)
    return out


def feeder_figure(layout: dict):
    """The matplotlib figure of the drawing; the layout's warnings above it, in red."""
    import matplotlib.pyplot as plt
    from matplotlib.patches import Circle, PathPatch

    from pipeline.present.figures import save_figure  # noqa: F401 (selects the Agg backend)
    from pipeline.present.figures.outline import loops_path
    items = drawing_items(layout)
    x0, x1, y0, y1 = items["extent"]
    width = DRAWING_WIDTH_IN
    y0 -= 1.2 * (x1 - x0) / (width - 1.0)  # about 1.2 inches for the title block
    fig, ax = plt.subplots(figsize=(width, max(3.0, width * (y1 - y0) / (x1 - x0)) + 0.4))
    for (a, b) in items["belt"]:
        ax.plot([a[0], b[0]], [a[1], b[1]], color="0.4", lw=1.0)
    for (a, b) in items["fence"]:
        ax.plot([a[0], b[0]], [a[1], b[1]], color="k", lw=3.0)
        ax.text(a[0] + 2, a[1] - 1.0, "fence", fontsize=7, va="top")
    for poly, holes in zip(items["parts"], items["holes"]):  # holes left empty
        ax.add_patch(PathPatch(loops_path([poly, *holes]), fc="tab:blue", ec="k", alpha=0.35, lw=0.8))
    for centre, r, label, at in items["pins"]:
        ax.add_patch(Circle(centre, r, color="tab:red", zorder=3))
        ax.plot([centre[0], at[0]], [centre[1] + r, at[1]], color="tab:red", lw=0.4, ls=":")
        ax.text(at[0] + 1.0, at[1], label, fontsize=7, color="tab:red", va="center")
    for p1, p2, at, text, angle in items["dims"]:
        if angle == 0.0:
            a, b = (p1[0], at[1]), (p2[0], at[1])
            ax.plot([p1[0], p1[0]], [p1[1], at[1]], color="tab:green", lw=0.4)
            ax.plot([p2[0], p2[0]], [p2[1], at[1]], color="tab:green", lw=0.4)
        else:
            a, b = (at[0], p1[1]), (at[0], p2[1])
        ax.annotate("", xy=b, xytext=a, arrowprops=dict(arrowstyle="<->", color="tab:green", lw=0.7))
        ax.text(0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1]), text, fontsize=6, color="tab:green",
                rotation=angle, ha="center", va="bottom" if angle == 0.0 else "center",
                bbox=dict(fc="white", ec="none", pad=0.5))
    tail, head = items["arrow"]
    ax.annotate("", xy=head, xytext=tail, arrowprops=dict(arrowstyle="-|>", color="0.3", lw=1.2))
    ax.text(head[0] + 2.0, head[1], "belt direction", fontsize=7, va="center")
    origin, lines = items["title"]
    ax.text(origin[0], origin[1], "\n".join(lines), fontsize=7, family="monospace", va="top",
            ha="right", multialignment="left", bbox=dict(fc="white", ec="k", lw=0.6))
    ax.set_xlim(x0, x1)
    ax.set_ylim(y0, y1)
    ax.set_aspect("equal")
    ax.set_xlabel("x along the belt (mm)", fontsize=8)
    ax.set_ylabel("y across the belt (mm)", fontsize=8)
    ax.tick_params(labelsize=7)
    if layout.get("warnings"):
        ax.set_title("\n".join(textwrap.fill(w, 150) for w in layout["warnings"]), color=ALERT_COLOUR,
                     fontsize=7, loc="left")
    fig.tight_layout()
    return fig


def write_dxf(layout: dict, out) -> Path:
    """The drawing as a DXF (R2010, millimetres), written atomically: a CIRCLE
    per pin at its station, each part outline (and each hole of a part with
    holes) a closed LWPOLYLINE on PARTS."""
    import ezdxf
    items = drawing_items(layout)
    doc = ezdxf.new("R2010", setup=True)
    doc.header["$INSUNITS"] = 4  # millimetres
    for name, colour in LAYERS.items():
        doc.layers.add(name, color=colour)
    msp = doc.modelspace()
    for a, b in items["belt"]:
        msp.add_line(a, b, dxfattribs={"layer": "BELT"})
    for a, b in items["fence"]:
        msp.add_line(a, b, dxfattribs={"layer": "FENCE"})
    for centre, r, label, at in items["pins"]:
        msp.add_circle(centre, r, dxfattribs={"layer": "PINS"})
        msp.add_line((centre[0], centre[1] + r), at, dxfattribs={"layer": "PINS"})
        msp.add_text(label, height=TEXT_MM * 0.7, dxfattribs={"layer": "PINS"}).set_placement(
            (at[0] + 1.0, at[1] - 0.5 * TEXT_MM * 0.7))
    for p1, p2, at, text, angle in items["dims"]:
        base = (p1[0], at[1]) if angle == 0.0 else (at[0], p1[1])
        dim = msp.add_linear_dim(base=base, p1=p1, p2=p2, angle=angle, text=text,
                                 dxfattribs={"layer": "DIMENSIONS"},
                                 override={"dimtxt": TEXT_MM * 0.7, "dimasz": 2.0})
        dim.render()
    for poly in items["parts"] + [h for holes in items["holes"] for h in holes]:
        msp.add_lwpolyline([tuple(p) for p in poly], close=True, dxfattribs={"layer": "PARTS"})
    tail, head = items["arrow"]
    msp.add_line(tail, head, dxfattribs={"layer": "BELT"})
    msp.add_lwpolyline([head, (head[0] - 4.0, head[1] + 1.5), (head[0] - 4.0, head[1] - 1.5)],
                       close=True, dxfattribs={"layer": "BELT"})
    msp.add_text("belt direction", height=TEXT_MM * 0.7, dxfattribs={"layer": "BELT"}).set_placement(
        (head[0] + 2.0, head[1] - 1.0))
    origin, lines = items["title"]
    step = TEXT_MM * 1.6
    box_w = max(len(s) for s in lines) * TEXT_MM * 0.75 + 4.0
    box_h = step * len(lines) + 2.0
    origin = (origin[0] - box_w, origin[1])  # right-aligned under the belt
    msp.add_lwpolyline([origin, (origin[0] + box_w, origin[1]), (origin[0] + box_w, origin[1] - box_h),
                        (origin[0], origin[1] - box_h)], close=True, dxfattribs={"layer": "TITLE"})
    for k, line in enumerate(lines):
        msp.add_text(line, height=TEXT_MM * 0.8, dxfattribs={"layer": "TITLE"}).set_placement(
            (origin[0] + 2.0, origin[1] - step * (k + 1)))
    x_lo, _, _, y_top = items["extent"]
    for k, warning in enumerate(layout.get("warnings") or ()):  # red (ACI 1), above the drawing
        msp.add_text(warning, height=TEXT_MM * 0.8, dxfattribs={"layer": "TITLE", "color": 1}).set_placement(
            (x_lo, y_top + step * (len(layout["warnings"]) - k)))
    out = Path(out)
    with atomic_target(out) as tmp:
        doc.saveas(tmp)
    return out
