"""The functions of ``rules/sense.smk``: a force/torque sensor on the first pin."""
from __future__ import annotations

from pathlib import Path

from pipeline.maps.io import read_json, write_json
from pipeline.present.figures.sensing import sensing_figures as plot_sensing
from pipeline.sensing.sensor_plan import sense_part


def sense(plan_path, config: dict, out) -> dict:
    """Rule ``sense``: the sensor plan of one part, chosen among its stored tight
    plans (``plan_path``; no search of its own), written to ``out``."""
    result = sense_part(plan_path, config)
    write_json(result, out)
    return result


def sensing_figures(sensing_path, out_profiles, out_scores) -> tuple[Path, Path]:
    """Rule ``sensing_figures``: the F/T profiles (the paper's Table 3) and the
    score matrix (Table 4) of one part's sensing result."""
    return plot_sensing(read_json(sensing_path), out_profiles, out_scores)
