"""The function of ``rules/layout.smk``: the feeder to build for one part."""
from __future__ import annotations

from pipeline.planning import LayoutSettings, PlannerSettings, as_plan_file, layout_stored, validate_plan_file
from pipeline.present.layout import write_drawing, write_note_drawings


def layout(plan_path, config: dict, outputs: dict) -> str:
    """Rule ``layout``: pin stations, pitch, belt width, throughput and the
    drawing (``outputs``: ``json``, ``dxf``, ``svg``, ``png``) of the part's
    stored plan; returns a one-line summary."""
    return layout_part(validate_plan_file(plan_path), config, outputs)


def layout_part(plan_result, config: dict, outputs: dict) -> str:
    """The workflow's layout stage: the first tight plan of fixed pins at the
    first planned friction, laid out (:func:`pipeline.planning.layout_stored`)
    and drawn; ``outputs`` maps ``json``, ``dxf``, ``svg`` and ``png`` to paths.
    A part with no such plan gets a JSON saying why and drawings of that note.
    Returns a one-line summary."""
    import time

    from pipeline.maps.io import write_json
    start = time.perf_counter()
    plan_result = as_plan_file(plan_result)
    first_plans = plan_result.tight[0].plans if plan_result.tight else ()
    number = next((k for k, p in enumerate(first_plans, start=1) if not any(p.pin_speeds or [])), None)
    name = plan_result.name
    if number is None:
        note = f"{name}: no tight plan of fixed pins to lay out"
        write_json({"part": name, "plan": None, "note": note}, outputs["json"])
        write_note_drawings(note, outputs)
        return note
    out = layout_stored(plan_result, PlannerSettings.from_config(config), number,
                        settings=LayoutSettings.from_section(config.get("layout")))
    out["method"]["seconds"] = round(time.perf_counter() - start, 1)
    for key in ("dxf", "svg", "png"):
        write_drawing(out, outputs[key])
    write_json(out, outputs["json"])
    return (f"{name}: plan {number} ({' '.join(out['plan']['pins'])}), pitch {out['pitch_mm']:.1f} mm, "
            f"belt {out['belt_speed_mm_s']} mm/s (limit {out['speed_limit_mm_s']:g}), throughput "
            f"{out['throughput_per_min']} parts/min, {out['method']['seconds']} s; warnings {out['warnings']}")
