"""The drawing of a feeder you can build, from its layout.

The layout (pin stations, part pitch, belt width, throughput and the outlines
to draw) is computed by the planner's feeder wing
(:func:`pipeline.planning.layout_plan`, :func:`pipeline.planning.layout_stored`:
trials replayed past the pins, stations where no pin meets a part still
moving from an earlier one, the touch-free pitch); see
:mod:`pipeline.planning.feeder.layout` for how each number is obtained. This
module only draws and words it: :func:`write_drawing` (DXF, SVG or PNG of a
layout dict), :func:`write_note_drawings` (the drawings of a part that has no
layout) and :func:`speed_limit_text`.
"""
from __future__ import annotations

from pipeline.errors import PinfeedError


def speed_limit_text(layout: dict) -> str:
    """A layout's speed limit with the trials it comes from, and the plan file's
    figure when that differs: one speed limit per plan, or a labelled other one."""
    trials = layout.get("speed_limit_trials")
    text = f"{layout['speed_limit_mm_s']:g} mm/s" + (f" ({trials} trials per state)" if trials else "")
    stored = layout.get("stored_speed_limit")
    if stored and (stored["speed_limit_mm_s"], stored["trials"]) != (layout["speed_limit_mm_s"], trials):
        text += (f"; the plan file stores {stored['speed_limit_mm_s']:g} mm/s ({stored['trials']} trials "
                 f"per state, mu_s {stored['mu_s']:g})")
    return text


DRAWING_SUFFIXES = (".dxf", ".svg", ".png")


def check_drawing_path(path):
    """A drawing path: a known suffix and a folder that exists (or can be made)
    and is writable; a one-line :class:`PinfeedError` otherwise."""
    import os
    from pathlib import Path

    from pipeline.checks import check_out_path
    path = check_out_path(path, DRAWING_SUFFIXES)
    parent = next((p for p in Path(path).absolute().parents if p.exists()), Path("."))
    if not os.access(parent, os.W_OK | os.X_OK):
        raise PinfeedError(f"--out {path}: cannot write in {parent} (not writable); choose another path")
    return Path(path)


def write_drawing(layout: dict, path):
    """Write the feeder drawing of ``layout`` to ``path`` (.dxf, .svg or .png), atomically."""
    from pipeline.present.figures.feeder import draw_feeder, write_dxf
    path = check_drawing_path(path)
    if path.suffix.lower() == ".dxf":
        return write_dxf(layout, path)
    return draw_feeder(layout, path)


def write_note_drawings(note: str, outputs: dict) -> None:
    """Drawings of a part with no layout: ``note`` written as the SVG and PNG
    (``outputs``: ``svg``, ``png``, ``dxf`` paths) and as the DXF's only text, atomically."""
    import ezdxf

    from pipeline.maps.io import atomic_target
    from pipeline.present.figures import placeholder
    for key in ("svg", "png"):
        with atomic_target(outputs[key]) as tmp:
            placeholder(tmp + "." + key, note)
            import os
            os.replace(tmp + "." + key, tmp)
    doc = ezdxf.new("R2010")
    doc.layers.add("TITLE")
    doc.modelspace().add_text(note, height=3.5, dxfattribs={"layer": "TITLE"})
    with atomic_target(outputs["dxf"]) as tmp:
        doc.saveas(tmp)
