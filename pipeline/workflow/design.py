"""Design for feeding, below the command line and the workflow's rule.

:func:`design_command` runs the search (:func:`pipeline.planning.design_part`)
for one outline with a config's planner and design settings, draws the part
before and after (:mod:`pipeline.present.design`: a PNG or SVG and a DXF)
and stores the self-describing JSON; :func:`design_rule` is the workflow's
rule for one planned part, which searches only when the part's plan file says
that its plan does not orient it.
"""
from __future__ import annotations

from pathlib import Path

from pipeline.config import config_hash, results_folder
from pipeline.errors import PinfeedError
from pipeline.maps.io import read_json, write_json
from pipeline.planning import DesignSettings, PlannerSettings, design_part
from pipeline.provenance import provenance_attrs

FIGURE_FORMATS = ("png", "svg")


def design_paths(config: dict, name: str, out_dir=None, figure_format: str = "png") -> dict:
    """Where the design of part ``name`` goes: ``json``, ``dxf`` and ``figure``
    under ``out_dir`` (default ``RESULTS/designs/``), checked before any work."""
    from pipeline.checks import check_out_path
    if figure_format not in FIGURE_FORMATS:
        raise PinfeedError(f"--figure-format must be one of {', '.join(FIGURE_FORMATS)}, got {figure_format!r}")
    folder = Path(out_dir) if out_dir else results_folder(config) / "designs"
    if folder.exists() and not folder.is_dir():
        raise PinfeedError(f"--out {folder} is a file; give a folder for the design's files")
    paths = {"json": folder / f"{name}.json", "dxf": folder / f"{name}.dxf",
             "figure": folder / f"{name}.{figure_format}"}
    for key, suffix in (("json", ".json"), ("dxf", ".dxf"), ("figure", f".{figure_format}")):
        check_out_path(paths[key], (suffix,))
    return paths


def design_command(outline, holes, name: str, config: dict, *, keep_edges=(), paths: dict,
                   progress=None) -> dict:
    """Search, draw and store the design of one outline (drawing frame, mm).

    ``config``: a validated config with the command's overrides (its planner,
    verify and design sections are used; fixed pins only); ``keep_edges``:
    edges that must not change; ``paths``: from :func:`design_paths`. Returns
    the stored JSON dict."""
    settings = PlannerSettings.from_config(config)
    design = DesignSettings.from_section(config["design"], keep_edges)
    result = design_part(outline, holes, name, settings, design, config["catalog_dir"], progress=progress)
    return store_design(result, config, paths)


def store_design(result: dict, config: dict, paths: dict) -> dict:
    """Draw the figure and the DXF of ``result`` and write its JSON with the
    code version, the config's name and hash and the settings it used."""
    from pipeline.present.design import draw_design, write_design_dxf
    draw_design(result, paths["figure"])
    write_design_dxf(result, paths["dxf"])
    stored = {**result, "config": config["name"], "config_hash": config_hash(config),
              "parameters": {"design": config["design"], "planner": config["planner"],
                             "verify": config["verify"]},
              "files": {"dxf": str(paths["dxf"]), "figure": str(paths["figure"])},
              **provenance_attrs()}
    write_json(stored, paths["json"])
    return stored


def design_rule(config: dict, name: str, plan_path, out) -> dict:
    """The workflow's design of planned part ``name``: when its plan file
    (``plan_path``) says that the recommended plan orients it, a short design
    file saying so; else the search with the config's settings. Writes
    ``out`` (JSON) with the DXF and figure beside it."""
    from pipeline.workflow.commands import named_part
    plan = read_json(plan_path)
    tight = plan.get("tight") or []
    out = Path(out)
    paths = {"json": out, "dxf": out.with_suffix(".dxf"), "figure": out.with_suffix(".png")}
    part = named_part(config, name)
    if tight and all(entry.get("orients") for entry in tight):
        pins = (tight[0].get("recommended") or {}).get("pins") or []
        print(f"{name}: its plan file says that fixed pins orient it ({' '.join(pins) or 'no pin'}): no change")
        result = {"part": part.to_dict(), "outcome": "already orients",
                  "original": {"vertices": part.vertices.tolist(), "holes": [h.tolist() for h in part.holes],
                               "orients": True, "pins": list(pins), "summary": "from the plan file"},
                  "plan_file": str(plan_path), "tried": [], "refused": [], "chosen": None}
        return store_design(result, config, paths)
    return design_command(part.vertices, part.holes, name, config, paths=paths, progress=print)
