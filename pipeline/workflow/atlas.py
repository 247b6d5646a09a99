"""The feedability atlas: which of a family's parts pins can orient, with how
many pins, how precisely and how fast (``RESULTS/atlas.json`` and
``RESULTS/atlas.csv``, one row per planned part).

Every row is read from files the workflow already wrote for that part: the
plan (``plans/NAME.json``: the recommended tight plan at ``planner.mu_c``,
its verification and orientation verdict, the planning time), the speed
limit (``speed/NAME.json``) and the layout (``layout_NAME.json``:
throughput at the layout's belt speed). Nothing is recomputed, so the atlas
always agrees with the files it summarises.

Outcome of a part: ``fixed pins`` (fixed pins orient it within the
tolerance), ``moving pins`` (it takes moving pins), ``no pin needed`` (its
resting states are already one orientation within the tolerance, as for a
regular polygon, and no pin plan does better), ``sensor`` (no plan of up to
the depth orients it: a sensor or a person must finish), ``no plan``
(nothing passed verification).

For a part planned for a support family that no plan holds for, the
``nearest_*`` columns give the nearest "yes" of its plan file on each axis
(the smallest tripod inset, the widest friction range, the smallest
tolerance, moving pins): the value, or ``none`` when that axis found none.
"""
from __future__ import annotations

import csv
import io
import json
import os
import tempfile
from pathlib import Path

from pipeline.maps.io import read_json, write_json
from pipeline.planning import validate_plan_file
from pipeline.provenance import provenance_attrs

COLUMNS = ("part", "part_id", "outcome", "orients", "tolerance_deg", "fixed_pins", "moving_pins",
           "sensor_needed", "verified_width_deg", "width_low_deg", "width_high_deg", "sets", "trials",
           "in_set", "share", "share_lower_bound", "confidence", "plan", "mu_c",
           "speed_limit_mm_s", "belt_speed_mm_s", "throughput_per_min", "planning_seconds", "evidence",
           "nearest_inset_a", "nearest_mu_c", "nearest_tolerance_deg", "nearest_moving_pins")
NEAREST = {"nearest_inset_a": "inset", "nearest_mu_c": "friction", "nearest_tolerance_deg": "tolerance",
           "nearest_moving_pins": "moving pins"}  # column -> the nearest "yes" axis it shows


def _outcome(orients: bool, plan: dict | None, needs_no_pin: bool = False) -> str:
    if plan is None:
        return "no pin needed" if needs_no_pin else "no plan"
    if not orients:
        return "sensor"
    return "moving pins" if plan.get("n_dynamic_pins") else "fixed pins"


def atlas_row(plan_result: dict, speed: dict | None = None, layout: dict | None = None) -> dict:
    """One atlas row from a stored plan file (a dict) and, if there, the part's
    speed and layout results."""
    entry = (plan_result.get("tight") or [None])[0] or {}
    plan = entry.get("recommended")
    search = entry.get("fixed_pin_search") or {}
    no_pin = bool(search.get("needs_no_pin")) and plan is None
    verdict = (search.get("resting") if no_pin else
               ((plan or {}).get("verification") or {}).get("orientation")) or {}
    orients = bool(verdict.get("orients"))
    n_moving = int((plan or {}).get("n_dynamic_pins") or 0)
    return {
        "part": plan_result["part"]["name"], "part_id": plan_result["part"]["id"],
        "outcome": _outcome(orients, plan, no_pin), "orients": orients,
        "tolerance_deg": entry.get("tolerance_deg"),
        "fixed_pins": 0 if no_pin else None if plan is None else len(plan["pins"]) - n_moving,
        "moving_pins": 0 if no_pin else None if plan is None else n_moving,
        "sensor_needed": not orients,
        "verified_width_deg": verdict.get("width_deg"),
        "width_low_deg": (verdict.get("width_interval_deg") or [None, None])[0],
        "width_high_deg": (verdict.get("width_interval_deg") or [None, None])[1],
        "sets": 1 if orients else verdict.get("sets_within_tolerance"),
        "trials": verdict.get("trials"), "in_set": verdict.get("in_tolerance"),
        "share": verdict.get("share"), "share_lower_bound": verdict.get("share_lower_bound"),
        "confidence": verdict.get("confidence"),
        "plan": None if plan is None else " ".join(plan["pins"]),
        "mu_c": entry.get("friction"),
        "speed_limit_mm_s": (speed or {}).get("speed_limit_mm_s"),
        "belt_speed_mm_s": (layout or {}).get("belt_speed_mm_s"),
        "throughput_per_min": (layout or {}).get("throughput_per_min"),
        "planning_seconds": (entry.get("stats") or {}).get("wall_seconds"),
        "evidence": search.get("evidence") or entry.get("warning"),
        **{column: _nearest(entry, axis) for column, axis in NEAREST.items()},
    }


def _nearest(entry: dict, axis: str):
    """The nearest "yes" on ``axis`` of a family no plan holds for: its value,
    ``"none"`` when the axis found none, ``None`` when the question was not
    asked (a plan holds, or no support family) or not answered in full (a
    time limit: the kept plans only and none of them, or an axis it cut)."""
    for answer in (entry.get("nearest_yes") or {}).get("axes", []):
        if answer["axis"] == axis:
            if answer["found"]:
                return answer["value"]
            return None if answer.get("kept_plans_only") or answer.get("partial") else "none"
    return None


def build_atlas(config: dict, plan_paths, speed_paths=(), layout_paths=()) -> dict:
    """The atlas of the planned parts (one row per plan file, in order); speed
    and layout files are matched to a part by name and may be missing."""
    speeds = {read_json(p)["part"]: read_json(p) for p in speed_paths if Path(p).is_file()}
    layouts = {}
    for p in layout_paths:
        if Path(p).is_file():
            lay = read_json(p)
            layouts[lay.get("part", Path(p).stem.removeprefix("layout_"))] = lay
    rows = []
    for path in plan_paths:
        res = validate_plan_file(path)
        name = res["part"]["name"]
        rows.append(atlas_row(res, speeds.get(name), layouts.get(name)))
    return {"config": config.get("name"), "tolerance_deg": config["planner"].get("tolerance_deg"),
            "required": config.get("verify", {}).get("required"),
            "confidence": config.get("verify", {}).get("confidence", 0.95),
            "rule": config.get("verify", {}).get("rule", "bound"), "depth": config["planner"]["depth"],
            "columns": list(COLUMNS), "rows": rows, **provenance_attrs()}


def atlas_csv(atlas: dict) -> str:
    """The atlas rows as CSV text (header = :data:`COLUMNS`)."""
    buf = io.StringIO()
    writer = csv.DictWriter(buf, fieldnames=COLUMNS, lineterminator="\n")
    writer.writeheader()
    for row in atlas["rows"]:
        writer.writerow({k: "" if row.get(k) is None else row[k] for k in COLUMNS})
    return buf.getvalue()


def write_atlas(atlas: dict, json_out, csv_out) -> None:
    """Write the atlas as JSON and CSV, each atomically (a temporary file renamed)."""
    write_json(atlas, json_out)
    csv_out = Path(csv_out)
    csv_out.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=csv_out.parent, prefix=f".{csv_out.name}.", suffix=".tmp")
    with os.fdopen(fd, "w", newline="") as fh:
        fh.write(atlas_csv(atlas))
    os.replace(tmp, csv_out)


def atlas(config: dict, plan_paths, speed_paths, layout_paths, json_out, csv_out) -> dict:
    """Rule ``atlas``: :func:`build_atlas`, written to ``json_out`` and ``csv_out``."""
    result = build_atlas(config, plan_paths, speed_paths, layout_paths)
    write_atlas(result, json_out, csv_out)
    return result


def read_atlas(path) -> dict:
    """A stored atlas (``RESULTS/atlas.json``)."""
    with open(path) as fh:
        return json.load(fh)
