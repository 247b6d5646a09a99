"""The function of ``rules/layout.smk``: the feeder to build for one part."""
from __future__ import annotations

from pipeline.planning import validate_plan_file
from pipeline.present.layout import layout_part


def layout(plan_path, config: dict, outputs: dict) -> str:
    """Rule ``layout``: pin stations, pitch, belt width, throughput and the
    drawing (``outputs``: ``json``, ``dxf``, ``svg``, ``png``) of the part's
    stored plan; returns a one-line summary."""
    return layout_part(validate_plan_file(plan_path), config, outputs)
