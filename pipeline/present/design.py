"""The drawings of a design for feeding: the part before and after its change.

:func:`draw_design` draws both outlines on one set of axes (mm, the drawing
frame, edges and corners numbered as ``--keep-edges`` and the changes count them) as a PNG or SVG;
:func:`write_design_dxf` writes them to a DXF for CAD, the original on layer
ORIGINAL and the changed outline on layer MODIFIED (each with the part's
holes), so that ``pinfeed plan --outline FILE --layer MODIFIED`` reads the
changed part back. The same design gives the same files: the DXF apart
from its time stamps and the version GUID that every save renews. The search itself (:func:`pipeline.planning.design_part`)
computes everything drawn here.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from pipeline.maps.io import atomic_target

FIGURE_SUFFIXES = (".png", ".svg")
LAYERS = {"ORIGINAL": 8, "MODIFIED": 1, "NOTES": 7}  # DXF layers and their colours (ACI: grey, red, white)


def _closed(xy) -> np.ndarray:
    xy = np.asarray(xy, dtype=float)
    return np.vstack([xy, xy[:1]])


def design_title(result: dict) -> str:
    """One line: the part, the change and its area share, or why there is none."""
    name = result["part"]["name"]
    chosen = result.get("chosen")
    if chosen:
        return f"{name}: {chosen['description']} ({chosen['share']:.2%} of the area)"
    if result["outcome"] == "already orients":
        return f"{name}: fixed pins orient it as it is"
    return f"{name}: no change within the limits makes a fixed-pin plan"


def draw_design(result: dict, out) -> Path:
    """The original outline (grey, dashed) and the changed one (red) of a design
    result, on labelled axes in mm with a legend, the edges numbered; written
    atomically to ``out`` (.png or .svg)."""
    import matplotlib.pyplot as plt

    from pipeline.present.figures import save_figure
    out = Path(out)
    original = np.asarray(result["original"]["vertices"], dtype=float)
    fig, ax = plt.subplots(figsize=(7, 5.5))
    ax.plot(*_closed(original).T, color="0.45", ls="--", lw=1.5, label="original")
    for k, hole in enumerate(result["original"].get("holes") or ()):
        ax.plot(*_closed(hole).T, color="0.45", lw=1.0, label="holes (kept)" if k == 0 else None)
    chosen = result.get("chosen")
    if chosen:
        changed = np.asarray(chosen["vertices"], dtype=float)
        ax.fill(*changed.T, color="tab:red", alpha=0.12)
        ax.plot(*_closed(changed).T, color="tab:red", lw=2.0, label=f"changed: {chosen['description']}")
    _number_edges(ax, original)
    ax.set_aspect("equal")
    ax.set_xlabel("x (mm)")
    ax.set_ylabel("y (mm)")
    ax.set_title(design_title(result), fontsize=10)
    ax.grid(True, lw=0.3)
    ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.14), ncol=2, fontsize=8, frameon=False)
    plan = _plan_line(result)
    if plan:
        ax.annotate(plan, (0.5, -0.3), xycoords="axes fraction", ha="center", fontsize=8)
    with atomic_target(out) as tmp, plt.rc_context({"svg.hashsalt": "pinfeed-design"}):  # fixed SVG ids
        save_figure(fig, tmp, format=out.suffix.lstrip(".").lower(), bbox_inches="tight",
                    metadata={"Date": None} if out.suffix.lower() == ".svg" else None)
    return out


def _plan_line(result: dict) -> str:
    """The plan of the changed part (or of the original), as a footnote."""
    plans = (result.get("chosen") or {}).get("plan") or result.get("original_plan") or []
    rec = plans[0].get("recommended") if plans else None
    if not rec:
        return ""
    v = rec["verification"]["orientation"]
    return (f"plan {' '.join(rec['pins'])} (pins at {', '.join(f'{y:g}' for y in rec['pin_heights_mm'])} mm): "
            f"{v['in_tolerance']}/{v['trials']} held-out trials in one set of {v['tolerance_deg']:g} deg")


def _number_edges(ax, xy: np.ndarray) -> None:
    """Each edge's number (``e0``...) at its middle, just outside the outline,
    and each corner's (``c0``...) beside it."""
    nxt = np.roll(xy, -1, axis=0)
    size = float(np.ptp(xy, axis=0).max())
    for k, (p, q) in enumerate(zip(xy, nxt)):
        t = (q - p) / max(np.linalg.norm(q - p), 1e-12)
        at = 0.5 * (p + q) + np.array([t[1], -t[0]]) * 0.04 * size  # right of a ccw edge: outside
        ax.annotate(f"e{k}", at, ha="center", va="center", fontsize=7, color="0.3")
        ax.update_datalim([at])  # the axes make room for the number
    centre = xy.mean(axis=0)
    for k, p in enumerate(xy):  # corner k, where edge k starts
        away = (p - centre) / max(np.linalg.norm(p - centre), 1e-12)
        at = p + away * 0.035 * size
        ax.annotate(f"c{k}", at, ha="center", va="center", fontsize=7, color="tab:blue")
        ax.update_datalim([at])
    ax.autoscale_view()


def write_design_dxf(result: dict, out) -> Path:
    """The original (layer ORIGINAL) and changed (layer MODIFIED) outlines, each a
    closed LWPOLYLINE with the part's holes, in millimetres (R2010), and the
    change in words (layer NOTES); written atomically to ``out``."""
    import ezdxf
    out = Path(out)
    doc = ezdxf.new("R2010")
    doc.header["$INSUNITS"] = 4  # millimetres
    for name, colour in LAYERS.items():
        doc.layers.add(name, color=colour)
    msp = doc.modelspace()
    holes = [np.asarray(h, dtype=float) for h in result["original"].get("holes") or ()]
    original = np.asarray(result["original"]["vertices"], dtype=float)
    loops = {"ORIGINAL": original}
    if result.get("chosen"):
        loops["MODIFIED"] = np.asarray(result["chosen"]["vertices"], dtype=float)
    for layer, outline in loops.items():
        for loop in [outline, *holes]:
            msp.add_lwpolyline([tuple(p) for p in loop], close=True, dxfattribs={"layer": layer})
    low = original.min(axis=0)
    size = float(np.ptp(original, axis=0).max())
    msp.add_text(design_title(result), height=0.04 * size, dxfattribs={"layer": "NOTES"}).set_placement(
        (low[0], low[1] - 0.12 * size))
    _fixed_guids(doc, result)
    with atomic_target(out) as tmp:
        doc.saveas(tmp)
    return out


def _fixed_guids(doc, result: dict) -> None:
    """The drawing's GUIDs from its content, not random: the same design gives
    the same DXF apart from its time stamps ($TDCREATE, $TDUPDATE)."""
    import hashlib
    import json
    import uuid
    loops = [result["original"]["vertices"], (result.get("chosen") or {}).get("vertices")]
    digest = hashlib.sha256(json.dumps(loops).encode()).digest()
    doc.header["$FINGERPRINTGUID"] = "{" + str(uuid.UUID(bytes=digest[:16])).upper() + "}"
    doc.header["$VERSIONGUID"] = "{" + str(uuid.UUID(bytes=digest[16:])).upper() + "}"
