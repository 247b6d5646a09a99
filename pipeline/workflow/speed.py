"""The function of ``rules/speed.smk``: how fast may a part's recommended plan run."""
from __future__ import annotations

from pathlib import Path

from pipeline.maps.io import write_json
from pipeline.planning import PlanFile, PlannerSettings, stored_plan_speed, stored_speed_limit, validate_plan_file
from pipeline.present.figures import placeholder
from pipeline.present.figures.speed import plot_speed_curve
from pipeline.provenance import provenance_attrs


def speed_part(plan_result: dict, settings: PlannerSettings) -> dict:
    """The speed curve and speed limit of a part's recommended tight plan (first
    friction), with the speed settings of ``settings`` (trials per state,
    ``mu_s``, speed grid, resolution, required fraction, seed): the JSON of
    ``speed_limit.stored_plan_speed`` plus provenance; the speed limit stored
    with the plan when it was made with these settings. A part without a
    recommended plan gets ``speed_limit_mm_s: None`` and a ``note``."""
    stored = PlanFile.from_dict(plan_result)
    name = stored.name
    tight = (stored.tight or [None])[0]
    if not tight or not tight.plans:
        why = tight.warning if tight else "no tight plan"
        return {"part": name, "speed_limit_mm_s": None, "curve": [], "note": why,
                **provenance_attrs()}
    stored_limit = stored_speed_limit(tight.plans[0])
    if stored_limit and stored_limit.get("settings") == settings.speed.to_json():  # the plan file's own figure
        res = {k: v for k, v in stored_limit.items() if k != "settings"}
    else:
        res = stored_plan_speed(plan_result, settings, plan=1)
    return {**res, **provenance_attrs()}


def speed_figure(result: dict, out) -> Path:
    """The speed curve figure of a :func:`speed_part` result (a note if no plan)."""
    if result.get("speed_limit_mm_s") is None:
        placeholder(out, f"{result['part']}: no speed limit ({result.get('note', 'no plan')})")
        return Path(out)
    return plot_speed_curve(result, out)


def speed(plan_path, config: dict, out, figure) -> dict:
    """Rule ``speed``: :func:`speed_part` of the stored plans at ``plan_path``,
    written to ``out``, and its figure (:func:`speed_figure`) to ``figure``."""
    result = speed_part(validate_plan_file(plan_path), PlannerSettings.from_config(config))
    write_json(result, out)
    speed_figure(result, figure)
    return result
