"""Downstream workflow stages, shared by the Snakemake rule scripts and the CLI.

bands  -> one JSON per shard: B_j, K_j, COM_j and adjusted bands for every d
plan   -> one JSON per planned part: the ranked fixed-pins plans
verify -> one JSON per planned part: perturbed full rollouts of the best plan
figures, report -> PNGs and one HTML page linking everything
All JSON is written atomically.
"""
from __future__ import annotations

import json
from pathlib import Path

from .bands import map_bands
from .catalog import Catalog
from .errors import PinfeedError
from .io import read_map, write_json  # noqa: F401 (write_json is part of this module's API)
from .parts import Part
from .planner import Planner, load_maps, pins_from_config
from .provenance import provenance_attrs


def read_json(path) -> dict:
    path = Path(path)
    if not path.is_file():
        raise PinfeedError(f"no result file at {path}; run the workflow ('make run') first")
    try:
        return json.loads(path.read_text())
    except json.JSONDecodeError:
        raise PinfeedError(f"{path} is corrupt; delete it and re-run the workflow") from None


# ---------------------------------------------------------------------- bands


def shard_bands(shard, threshold_T, factor_c) -> dict:
    ds = read_map(shard)
    bands = map_bands(ds, threshold_T, factor_c)
    return {"part_id": ds.attrs["part_id"], "model": ds.attrs["model"], "mu_c": ds.attrs["mu_c"],
            "threshold_T": threshold_T, "factor_c": factor_c, "shard": str(shard),
            "maps": {f"{d:g}": [b.to_dict() for b in bs] for d, bs in bands.items()},
            **provenance_attrs()}


# ---------------------------------------------------------------------- plan


def catalog_part(cat: Catalog, name: str) -> Part:
    e = cat._entries_for(name)[0]
    return Part.from_vertices(e["part_vertices"], name=e["part_name"])


def build_planner(cat: Catalog, name: str, config: dict):
    pc, bc = config["planner"], config["bands"]
    part = catalog_part(cat, name)
    ds = cat.query(name, model=pc["model"], mu_c=pc["mu_c"])
    selection = ds.attrs["selection"]
    ds = ds.isel(mu_c=0).load()
    maps = load_maps(ds, bc["threshold_T"], bc["factor_c"])
    planner = Planner(part, maps, pins_from_config(pc["pins"]), pc["d_min"], pc["d_max"],
                      coverage=pc.get("coverage", "bracket"))
    return part, planner, float(ds["mu_c"]), selection


def plan_part(cat: Catalog, name: str, config: dict, keep: int = 5) -> dict:
    pc = config["planner"]
    part, planner, mu_used, selection = build_planner(cat, name, config)
    plans = planner.search(pc["depth"], keep=keep)
    states = planner.initial_states()
    return {
        "part": part.to_dict(), "model": pc["model"], "mu_c": mu_used, "selection": selection,
        "pins": planner.pins, "depth": pc["depth"], "d_min": pc["d_min"], "d_max": pc["d_max"],
        "coverage": planner.coverage,
        "initial_states": {k: {"theta": s.arc[0], "y_c": s.y_lo} for k, s in states.items()},
        "plans": [p.to_dict() for p in plans],
        "found": bool(plans),
        **provenance_attrs(),
    }


# ---------------------------------------------------------------------- verify


def verify_part(plan_result: dict, config: dict) -> dict:
    from .planner import State
    from .verify import verify_plan
    if not plan_result["plans"]:
        return {"part": plan_result["part"]["name"], "plan": [], "rows": [], "trials": [],
                "note": "no allowed plan within the depth"}
    part = Part.from_vertices(plan_result["part"]["vertices"], name=plan_result["part"]["name"])
    states = {k: State((v["theta"], 0.0), v["y_c"], v["y_c"])
              for k, v in plan_result["initial_states"].items()}
    res = verify_plan(part, plan_result["plans"][0], plan_result["pins"], states,
                      plan_result["mu_c"], config["sweep"]["pin_radius"], plan_result["model"],
                      config.get("verify", {}))
    res["part"] = part.name
    res.update(provenance_attrs())
    return res


def nominal_paths(plan_result: dict, config: dict) -> dict:
    """Unperturbed rollouts of the best plan: (theta, y_c) before and after each pin."""
    from . import simulate
    part = Part.from_vertices(plan_result["part"]["vertices"], name=plan_result["part"]["name"])
    best = plan_result["plans"][0]
    paths = {}
    for label, s in plan_result["initial_states"].items():
        theta, y = s["theta"], s["y_c"]
        path = [(theta, y)]
        for pin in best["pins"]:
            r = simulate.rollout(part, theta, (plan_result["pins"][pin] - y) / part.a,
                                 plan_result["mu_c"], config["sweep"]["pin_radius"],
                                 model=plan_result["model"])
            theta, y = float(r.theta_f), y + float(r.dy)
            path.append((theta, y))
        paths[label] = path
    return paths


# ---------------------------------------------------------------------- figures, report


def make_figures(config, plan_paths, verify_paths, out_maps, out_sequence, out_verification,
                 out_table):
    from .figures.bands import plot_band_maps
    from .figures.sequence import plot_sequence
    from .figures.tables import markdown_table, plot_table, verification_rows
    cat = Catalog.open(config["catalog_dir"])
    verifications = {}
    for plan_path, verify_path, maps_png, seq_png in zip(plan_paths, verify_paths, out_maps,
                                                          out_sequence):
        res = read_json(plan_path)
        name = res["part"]["name"]
        maps = {}
        for model in config["sweep"]["models"]:
            ds = cat.query(name, model=model, mu_c=res["mu_c"])
            maps[model] = ds.isel(mu_c=0).load()
        plot_band_maps(maps, config["figures"]["d"], config["bands"]["threshold_T"],
                       config["bands"]["factor_c"],
                       f"{name}: configuration maps, mu_c = {res['mu_c']:g} (rows: models)", maps_png)
        if res["plans"]:
            part = Part.from_vertices(res["part"]["vertices"], name=name)
            plot_sequence(part, res["plans"][0], res["pins"], nominal_paths(res, config),
                          config["sweep"]["pin_radius"], f"{name}: best fixed-pin plan", seq_png)
        else:
            _placeholder(seq_png, f"{name}: no allowed plan within depth {res['depth']}")
        verifications[name] = read_json(verify_path)
    rows = verification_rows(verifications)
    plot_table(rows, "Verification of the best plans by perturbed full rollouts", out_verification)
    Path(out_table).write_text(markdown_table(rows))


def _placeholder(path, text):
    import matplotlib.pyplot as plt

    from .figures import save_figure
    fig, ax = plt.subplots(figsize=(6, 1.5))
    ax.axis("off")
    ax.text(0.5, 0.5, text, ha="center", va="center")
    save_figure(fig, path, dpi=100)


def make_report(config, plan_paths, verify_paths, out, sensing_paths=()):
    from .report import write_report
    results = Path(config["results_dir"]) / "figures"
    plans, verifications, figures = {}, {}, {"verification": results / "verification.png"}
    for plan_path, verify_path in zip(plan_paths, verify_paths):
        res = read_json(plan_path)
        name = res["part"]["name"]
        plans[name] = res
        verifications[name] = read_json(verify_path)
        figures[name] = {"maps": results / f"maps_{name}.png", "sequence": results / f"sequence_{name}.png"}
    sensing = {}  # force/torque sensor on the first pin (rules/sense.smk)
    for path in sensing_paths:
        res = read_json(path)
        name = res["part"]["name"]
        sensing[name] = res
        figures.setdefault(name, {}).update(profiles=results / f"profiles_{name}.png",
                                            scores=results / f"scores_{name}.png")
    return write_report(config, plans, verifications, figures, out, sensing=sensing)


def ensure_maps(config, part: Part, family: str = "adhoc") -> Catalog:
    """Make sure the catalog holds the maps the planner needs for ``part``:
    the planner's model at its mu_c over the sweep's d grid. Missing ones are
    computed with the sweep settings, stored atomically and indexed."""
    from .sweep import ShardJob, write_shard
    root = Path(config["catalog_dir"])
    pc = config["planner"]
    cat = Catalog.open(root) if (root / "index.json").is_file() else None
    have = cat is not None and any(
        e["part_id"] == part.id and e["model"] == pc["model"] and e["mu_c"] == float(pc["mu_c"])
        for e in cat.entries)
    if not have:
        fam = next((e["family"] for e in (cat.entries if cat else []) if e["part_id"] == part.id), family)
        write_shard(config, ShardJob(fam, part, pc["model"], float(pc["mu_c"])))
        cat = Catalog.rebuild(root)
    return cat
