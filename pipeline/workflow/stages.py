"""Downstream workflow stages, shared by the Snakemake rule scripts and the CLI.

bands  -> one JSON per shard: B_j, K_j, COM_j and adjusted bands for every d
plan   -> one JSON per planned part: the ranked fixed-pins plans
verify -> one JSON per planned part: perturbed full rollouts of the best plan
figures, outline, animate, report -> PNGs, one GIF per part, one HTML page
All of it lives in the config's results folder (``results_dir/NAME``,
:func:`pipeline.config.results_folder`; file names in :func:`part_files`);
the catalog is shared. All JSON is written atomically.
"""
from __future__ import annotations

import json
from pathlib import Path

from pipeline.planning.bands import map_bands
from pipeline.maps.catalog import Catalog
from pipeline.errors import PinfeedError
from pipeline.maps.io import read_map, write_json  # noqa: F401 (write_json is part of this module's API)
from pipeline.parts.part import Part
from pipeline.planning.paper import Planner, load_maps, pins_from_config
from pipeline.provenance import provenance_attrs


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
            "v_pin": float(ds.attrs.get("v_pin", 0.0)),
            "threshold_T": threshold_T, "factor_c": factor_c, "shard": str(shard),
            "maps": {f"{d:g}": [b.to_dict() for b in bs] for d, bs in bands.items()},
            **provenance_attrs()}


# ---------------------------------------------------------------------- plan


def config_part_id(config: dict, name: str) -> str:
    """The id of the config's part called ``name`` (the catalog may also hold
    older outlines under the same name), or ``name`` itself if the config
    has no such part."""
    from pipeline.parts.families import family_parts
    for family, spec in config.get("families", {}).items():
        for part in family_parts(family, spec):
            if name in (part.name, part.id):
                return part.id
    return name


def catalog_part(cat: Catalog, name: str) -> Part:
    e = cat._entries_for(name)[0]
    return Part.from_vertices(e["part_vertices"], name=e["part_name"])


def build_planner(cat: Catalog, name: str, config: dict, dynamic: bool = True):
    """The planner of one catalog part: static maps at the planner's mu_c, plus
    (``dynamic``) the maps of every moving-pin speed the config allows
    (``planner.dynamic``)."""
    pc, bc = config["planner"], config["bands"]
    name = config_part_id(config, name)
    part = catalog_part(cat, name)
    from pipeline.planning.plan import nominal_friction, parse_friction
    ds = cat.query(name, model=pc["model"], mu_c=nominal_friction(parse_friction(pc["mu_c"])))
    selection = ds.attrs["selection"]
    mu_used = float(ds["mu_c"][0])
    maps = load_maps(ds.isel(mu_c=0).load(), bc["threshold_T"], bc["factor_c"])
    static = pins_from_config(pc["pins"])
    speeds = [float(v) for v in pc.get("dynamic", {}).get("speeds", [])] if dynamic else []
    dynamic_maps = {}
    for v in speeds:
        dv = cat.query(name, model=pc["model"], mu_c=mu_used, v_pin=v)
        if float(dv["mu_c"][0]) != mu_used:
            raise PinfeedError(f"{name}: the maps at v_pin/v_b = {v:g} have no mu_c = {mu_used:g} (the "
                               f"static maps' friction); add it to the sweep or re-run the workflow")
        dv = dv.isel(mu_c=0).load()
        dynamic_maps[v] = load_maps(dv, bc["threshold_T"], bc["factor_c"])
    moving = {dynamic_label(label, v): (y, v) for label, y in static.items() for v in speeds}
    planner = Planner(part, maps, static, pc["d_min"], pc["d_max"],
                      coverage=pc.get("coverage", "bracket"), dynamic=moving,
                      dynamic_maps=dynamic_maps)
    return part, planner, mu_used, selection


def dynamic_label(static_label: str, v_pin: float) -> str:
    """Label of a moving pin: its static label and speed ratio, e.g. ``P23v-2``."""
    return f"{static_label}v{v_pin:+g}"


def plan_part(cat: Catalog, name: str, config: dict, keep: int = 5, progress=None,
              tight: bool = True) -> dict:
    """Plans for one part: the paper's adjusted-band planner (``plans``,
    ``best_static``: fixed pins, then moving pins) at the stored friction
    nearest the planner's, and the tight planner (``tight``) at every
    friction of :func:`plan_frictions`, each verified by full rollouts."""
    pc = config["planner"]
    part, planner, mu_used, selection = build_planner(cat, name, config)
    dyn = pc.get("dynamic", {})
    plans = planner.search(paper_depth(config), keep=keep, dynamic_depth=dyn.get("depth", 0),
                           dynamic_beam=dyn.get("beam", 50))
    states = planner.initial_states()
    static_only = [p for p in plans if p.n_dynamic == 0]
    if planner.dynamic_labels and not static_only:
        static_only = [p for p in planner.search(paper_depth(config), keep=1) if p.n_dynamic == 0]
    return {
        "part": part.to_dict(), "model": pc["model"], "mu_c": mu_used, "selection": selection,
        "pins": planner.pins,
        "pin_speeds": {k: v for k, v in planner.speeds.items() if v != 0.0},
        "depth": paper_depth(config), "dynamic_depth": dyn.get("depth", 0) if planner.dynamic_labels else 0,
        "d_min": pc["d_min"], "d_max": pc["d_max"],
        "coverage": planner.coverage,
        "best_static": static_only[0].to_dict() if static_only else None,
        "initial_states": {k: {"theta": s.arc[0], "y_c": s.y_lo} for k, s in states.items()},
        "plans": [p.to_dict() for p in plans],
        "found": bool(plans),
        "tight": plan_tight_all(part, config, cat.root, keep=keep, progress=progress) if tight else [],
        **provenance_attrs(),
    }


def paper_depth(config: dict) -> int:
    """Depth of the paper-mode planner: ``planner.paper_depth``, at most
    ``planner.depth`` (the sensor planner reads the stored tight plans instead)."""
    pc = config["planner"]
    return int(min(pc["depth"], pc.get("paper_depth", 3)))


def plan_frictions(config: dict) -> list:
    """The frictions the workflow plans at: ``planner.mu_c`` (a value or a range
    ``LO:HI``; the recommended plan) first, then each of ``planner.frictions``."""
    from pipeline.planning.plan import parse_friction
    pc = config["planner"]
    out = [parse_friction(pc["mu_c"])]
    for f in pc.get("frictions", []):
        f = parse_friction(f)
        if f not in out:
            out.append(f)
    return out


def plan_tight_all(part: Part, config: dict, catalog_root, keep: int = 5, progress=None) -> list:
    """Tight plans at every friction of :func:`plan_frictions` (the first is the
    recommended one), at ``planner.belt_speed`` when it is set; the planner's
    rollouts are stored in the catalog (keyed by model, pin speed and belt)."""
    from pipeline.planning.lattice_store import load_lattice, save_lattice
    from pipeline.planning.plan import plan_tight, planner_belt
    sweep, model = config["sweep"], config["planner"]["model"]
    belt_speed, mu_s = planner_belt(config, part)
    speeds = [0.0] + [float(v) for v in config["planner"].get("dynamic", {}).get("speeds", [])]
    lattices = {v: load_lattice(catalog_root, part, model, v, sweep["pin_radius"], sweep.get("kernel"),
                                belt_speed=belt_speed, mu_s=mu_s)
                for v in speeds}
    out = []
    for mu_c in plan_frictions(config):
        res = plan_tight(part, config, mu_c, lattices=lattices, keep=keep, progress=progress)
        res.pop("lattices")
        out.append(res)
    for lattice in lattices.values():
        save_lattice(catalog_root, lattice)
    return out


# ---------------------------------------------------------------------- verify


def plans_to_check(plan_result: dict) -> dict:
    """The plans the verify stage replays and the figures draw: ``"fixed pins"``
    (the best plan of static pins only) and, when the best plan moves a pin,
    ``"with dynamic pins"`` (the best plan overall)."""
    plans = plan_result["plans"]
    if not plans:
        return {}
    best = plans[0]
    static = plan_result.get("best_static")
    if static is None and not best.get("n_dynamic_pins", 0):
        static = best
    out = {"fixed pins": static} if static else {}
    if best.get("n_dynamic_pins", 0):
        out["with dynamic pins"] = best
    return out


def verify_part(plan_result: dict, config: dict) -> dict:
    """Perturbed full rollouts of the paper-mode plans (best fixed-pin plan and
    best plan with dynamic pins, if any) and of the tight planner's
    recommended plan at every friction: ``{"part", "checks": [verify_plan
    result + "kind"]}``."""
    from pipeline.planning.verify import verify_plan
    name = plan_result["part"]["name"]
    out = {"part": name, "checks": [], **provenance_attrs()}
    part = Part.from_vertices(plan_result["part"]["vertices"], name=name)
    states = {k: (v["theta"], v["y_c"]) for k, v in plan_result["initial_states"].items()}
    radius, kernel = config["sweep"]["pin_radius"], config["sweep"].get("kernel")
    for kind, plan in plans_to_check(plan_result).items():
        res = verify_plan(part, plan, plan_result["pins"], states, plan_result["mu_c"], radius,
                          plan_result["model"], config.get("verify", {}),
                          speeds=plan_result.get("pin_speeds", {}), kernel=kernel)
        res.pop("trials_detail")
        out["checks"].append({"kind": f"paper mode, {kind}", **res})
    for tight in plan_result.get("tight", []):
        plan = tight["recommended"]
        if plan is None:
            continue
        mu = tuple(tight["mu_c"]) if isinstance(tight["mu_c"], list) else tight["mu_c"]
        res = verify_plan(part, plan, dict(zip(plan["pins"], plan["pin_heights_mm"])), states, mu,
                          radius, plan_result["model"], config.get("verify", {}), kernel=kernel,
                          speeds=dict(zip(plan["pins"], plan["pin_speeds"])),
                          belt_speed=tight.get("belt_speed"), mu_s=tight.get("mu_s") or 0.5)
        res.pop("trials_detail")
        out["checks"].append({"kind": f"tight, mu_c {tight['friction']}", **res})
    if not out["checks"]:
        out["note"] = "no allowed plan within the depth"
    return out


# ---------------------------------------------------------------------- speed


def speed_part(plan_result: dict, config: dict) -> dict:
    """The speed curve and speed limit of a part's recommended tight plan (first
    friction), with the settings of ``config["speed"]`` (trials per state,
    ``mu_s``, speed grid, resolution, required fraction, seed): the JSON of
    ``speed_limit.stored_plan_speed`` plus provenance. A part without a
    recommended plan gets ``speed_limit_mm_s: None`` and a ``note``."""
    from pipeline.planning.speed_limit import stored_plan_speed
    sc = config.get("speed", {})
    name = plan_result["part"]["name"]
    tight = (plan_result.get("tight") or [None])[0]
    if not tight or not tight.get("plans"):
        why = tight["warning"] if tight else "no tight plan"
        return {"part": name, "speed_limit_mm_s": None, "curve": [], "note": why,
                **provenance_attrs()}
    res = stored_plan_speed(plan_result, config, plan=1, mu_s=float(sc.get("mu_s", 0.5)),
                            trials=int(sc.get("trials", 30)),
                            speeds=[float(v) for v in sc.get("speeds", (10, 50, 100, 150, 200, 300, 400, 500))],
                            resolution=float(sc.get("resolution", 5.0)),
                            required=float(sc.get("required", 0.99)), seed=int(sc.get("seed", 0)))
    return {**res, **provenance_attrs()}


def speed_figure(result: dict, out) -> Path:
    """The speed curve figure of a :func:`speed_part` result (a note if no plan)."""
    from pipeline.present.figures.speed import plot_speed_curve
    if result.get("speed_limit_mm_s") is None:
        _placeholder(out, f"{result['part']}: no speed limit ({result.get('note', 'no plan')})")
        return Path(out)
    return plot_speed_curve(result, out)


def nominal_paths(plan_result: dict, config: dict, plan: dict | None = None) -> dict:
    """Unperturbed rollouts of a plan (default: the best): (theta, y_c) before and after each pin."""
    from pipeline.maps import simulate
    part = Part.from_vertices(plan_result["part"]["vertices"], name=plan_result["part"]["name"])
    best = plan or plan_result["plans"][0]
    speeds = plan_result.get("pin_speeds", {})
    paths = {}
    for label, s in plan_result["initial_states"].items():
        theta, y = s["theta"], s["y_c"]
        path = [(theta, y)]
        for pin in best["pins"]:
            r = simulate.rollout(part, theta, (plan_result["pins"][pin] - y) / part.a,
                                 plan_result["mu_c"], config["sweep"]["pin_radius"],
                                 model=plan_result["model"], v_pin=speeds.get(pin, 0.0))
            theta, y = float(r.theta_f), y + float(r.dy)
            path.append((theta, y))
        paths[label] = path
    return paths


# ---------------------------------------------------------------------- figures, report


def make_figures(config, plan_paths, verify_paths, out: dict):
    """Every figure of the planned parts. ``out`` holds lists (one path per
    part, in plan order) under ``maps`` (models side by side), ``speeds``
    (the planner's model at each pin speed), ``sequence`` (best fixed-pin
    plan), ``sequence_dynamic`` (best plan with dynamic pins), and single
    paths ``verification`` (PNG) and ``table`` (Markdown)."""
    from pipeline.present.figures.bands import plot_band_maps
    from pipeline.present.figures.tables import markdown_table, plot_table, verification_rows
    cat = Catalog.open(config["catalog_dir"])
    bc, fc = config["bands"], config["figures"]
    verifications = {}
    for k, (plan_path, verify_path) in enumerate(zip(plan_paths, verify_paths)):
        res = read_json(plan_path)
        name, part_id = res["part"]["name"], res["part"]["id"]
        maps = {model: cat.query(part_id, model=model, mu_c=res["mu_c"]).isel(mu_c=0).load()
                for model in config["sweep"]["models"]}
        plot_band_maps(maps, fc["d"], bc["threshold_T"], bc["factor_c"],
                       f"{name}: configuration maps, $\\mu_c$ = {res['mu_c']:g} (rows: models)", out["maps"][k])
        speeds = {f"$v_{{pin}}/v_b$ = {v:+g}": cat.query(part_id, model=res["model"], mu_c=res["mu_c"], v_pin=v)
                  .isel(mu_c=0).load() for v in sorted(config["sweep"]["v_pin"])}
        plot_band_maps(speeds, fc["d"], bc["threshold_T"], bc["factor_c"],
                       f"{name}: {res['model']} maps by pin speed, $\\mu_c$ = {res['mu_c']:g} "
                       f"(d at the centroid's station)", out["speeds"][k])
        to_draw = plans_to_check(res)
        _sequence_figure(config, res, to_draw.get("fixed pins"), "best fixed-pin plan", out["sequence"][k])
        _sequence_figure(config, res, to_draw.get("with dynamic pins"), "best plan with dynamic pins",
                         out["sequence_dynamic"][k])
        if "carried" in out:
            _carried_figure(config, res, out["carried"][k])
        verifications[name] = read_json(verify_path)
        if out.get("verification_plans"):  # optional: one figure per part, its plans stacked
            _verification_figure(verifications[name], out["verification_plans"][k])
    rows = verification_rows(verifications)
    plot_table(rows, "Verification of the best plans by perturbed full rollouts", out["verification"])
    Path(out["table"]).write_text(markdown_table(rows))


def _verification_figure(result: dict, path):
    """The verification figure of a part: every checked plan (``verify_part`` result)."""
    from pipeline.present.figures.tables import plot_verification
    if not result["checks"]:
        _placeholder(path, f"{result['part']}: {result.get('note', 'nothing verified')}")
        return
    plot_verification(result["checks"], f"{result['part']}: verification by perturbed rollouts", path)


def _sequence_figure(config, res, plan, what, path):
    from pipeline.present.figures.sequence import plot_sequence
    name = res["part"]["name"]
    if plan is None:
        if not res["plans"]:
            why = f"no allowed plan within depth {res['depth']}"
        elif "fixed" in what:
            why = "no allowed plan of fixed pins only"
        else:
            why = "no plan with dynamic pins beats the fixed pins (or none allowed)"
        _placeholder(path, f"{name}, {what}: {why}")
        return
    part = Part.from_vertices(res["part"]["vertices"], name=name)
    plot_sequence(part, plan, res["pins"], nominal_paths(res, config, plan),
                  config["sweep"]["pin_radius"], f"{name}: {what}", path,
                  speeds=res.get("pin_speeds", {}))


def _carried_figure(config, res, path):
    """The tight planner's recommended plan (first friction): carried sets against replays."""
    from pipeline.present.figures.carried import plot_carried, replayed_paths
    name = res["part"]["name"]
    tight = (res.get("tight") or [None])[0]
    if not tight or not tight["recommended"]:
        _placeholder(path, f"{name}: no recommended tight plan" + (f" ({tight['warning']})" if tight else ""))
        return
    plan = tight["recommended"]
    part = Part.from_vertices(res["part"]["vertices"], name=name)
    mu = tuple(tight["mu_c"]) if isinstance(tight["mu_c"], list) else tight["mu_c"]
    starts = {k: (v["theta"], v["y_c"]) for k, v in res["initial_states"].items()}
    replays = replayed_paths(part, plan, starts, mu, config["sweep"]["pin_radius"], res["model"],
                             config.get("verify", {}), kernel=config["sweep"].get("kernel"),
                             belt_speed=tight.get("belt_speed"), mu_s=tight.get("mu_s") or 0.5)
    plot_carried(plan, replays, f"{name}: carried sets of plan {' '.join(plan['pins'])} (mu_c "
                 f"{tight['friction']}) against {len(next(iter(replays.values()))[0])} replayed "
                 f"rollouts per state", path)


def config_part_source(config: dict, name: str) -> str | None:
    """The CAD outline file a config part was read from (None for vertices)."""
    for spec in config.get("families", {}).values():
        for p in spec.get("parts", []) if isinstance(spec, dict) else []:
            if isinstance(p, dict) and p.get("name") == name:
                return p.get("outline")
    return None


def outline_figure(plan_result: dict, config: dict, out) -> Path:
    """The outline figure of a planned part (from its plan JSON)."""
    from pipeline.present.figures.outline import plot_outline
    part = Part.from_vertices(plan_result["part"]["vertices"], name=plan_result["part"]["name"])
    return plot_outline(part, out, source=config_part_source(config, part.name))


def animate_part(plan_result: dict, config: dict, out, frames: int, fps: int) -> dict:
    """The part's recommended plan as an animation: the tight planner's
    recommended plan (first friction) if there is one, else paper mode's best;
    with no plan at all, a one-frame note. Returns the summary (``plan``:
    which one)."""
    from pipeline.present.animate import animate_stored, recommended_index
    which = recommended_index(plan_result)
    if which is None:
        _placeholder_gif(out, f"{plan_result['part']['name']}: no plan to animate")
        return {"out": str(out), "frames": 1, "plan": None, "outcomes": {}}
    return animate_stored(plan_result, config, out, which, frames=frames, fps=fps)


def _placeholder_gif(path, text):
    """A one-frame GIF saying ``text`` (a part with no plan)."""
    from PIL import Image
    png = Path(path).with_name(Path(path).stem + ".note.png")
    _placeholder(png, text)
    with Image.open(png) as im:
        im.convert("RGB").save(path, format="GIF")
    png.unlink()


def _placeholder(path, text):
    import matplotlib.pyplot as plt

    from pipeline.present.figures import save_figure
    fig, ax = plt.subplots(figsize=(6, 1.5))
    ax.axis("off")
    ax.text(0.5, 0.5, text, ha="center", va="center")
    save_figure(fig, path, dpi=100)


PART_FIGURES = ("outline", "maps", "speeds", "sequence", "sequence_dynamic", "carried", "verification",
                "profiles", "scores", "speed_limit")


def part_files(results, name: str) -> dict:
    """Where the workflow writes a part's files under ``results`` (RESULTS_DIR/NAME):
    JSON (``plan``, ``verify``, ``sensing``, ``speed``), figures
    (:data:`PART_FIGURES`) and the ``animation``; the rules in rules/*.smk use
    the same names."""
    results = Path(results)
    out = {kind: results / kind.replace("plan", "plans") / f"{name}.json"
           for kind in ("plan", "verify", "sensing", "speed")}
    out.update({kind: results / "figures" / f"{kind}_{name}.png" for kind in PART_FIGURES})
    out["animation"] = results / "animations" / f"{name}.gif"
    out.update({f"layout_{ext}": results / f"layout_{name}.{ext}" for ext in ("json", "png", "dxf", "svg")})
    return out


def make_report(config, plan_paths, verify_paths, out, sensing_paths=(), speed_paths=()):
    """The HTML page (``out``, in the results folder) of the planned parts: their
    results, every figure found beside them, and the catalog shards they use."""
    from pipeline.present.report import write_report
    results = Path(out).parent
    cat = Catalog.open(config["catalog_dir"])
    parts = {}
    for plan_path, verify_path in zip(plan_paths, verify_paths):
        plan = read_json(plan_path)
        name = plan["part"]["name"]
        files = {k: p for k, p in part_files(results, name).items() if Path(p).is_file()}
        files.update(plan=Path(plan_path), verify=Path(verify_path))
        if "layout_json" in files:  # the feeder layout (rules/layout.smk)
            parts.setdefault(name, {})["layout"] = read_json(files["layout_json"])
        parts[name] = {**parts.get(name, {}), "plan": plan, "verify": read_json(verify_path), "files": files,
                       "shards": sorted((e for e in cat.entries if e["part_id"] == plan["part"]["id"]),
                                        key=lambda e: (e["model"], e["mu_c"], e.get("v_pin", 0.0)))}
    for path in sensing_paths:  # force/torque sensor on the first pin (rules/sense.smk)
        res = read_json(path)
        parts[res["part"]["name"]]["sensing"] = res
        parts[res["part"]["name"]]["files"]["sensing"] = Path(path)
    for path in speed_paths:  # speed curve and limit of the recommended plan (rules/speed.smk)
        res = read_json(path)
        parts[res["part"]]["speed"] = res
        parts[res["part"]]["files"]["speed"] = Path(path)
    overview = {k: results / f for k, f in (("verification figure", "figures/verification.png"),
                                            ("verification table", "verification.md"))
                if (results / f).is_file()}
    return write_report(config, parts, out, overview=overview, catalog=cat.root)


def ensure_maps(config, part: Part, family: str = "adhoc") -> Catalog:
    """Make sure the catalog holds the maps the planner needs for ``part``:
    the planner's model at its mu_c over the sweep's d grid, for a static pin
    and for every dynamic speed the planner may use. Missing ones are
    computed with the sweep settings, stored atomically and indexed."""
    from pipeline.maps.sweep import ShardJob, write_shard
    root = Path(config["catalog_dir"])
    pc = config["planner"]
    cat = Catalog.open(root) if (root / "index.json").is_file() else None
    entries = cat.entries if cat else []
    fam = next((e["family"] for e in entries if e["part_id"] == part.id), family)
    from pipeline.planning.plan import nominal_friction, parse_friction
    mu = nominal_friction(parse_friction(pc["mu_c"]))
    wrote = False
    for v in [0.0] + [float(x) for x in pc.get("dynamic", {}).get("speeds", [])]:
        have = any(e["part_id"] == part.id and e["model"] == pc["model"]
                   and e["mu_c"] == mu and e.get("v_pin", 0.0) == v for e in entries)
        if not have:
            write_shard(config, ShardJob(fam, part, pc["model"], mu, v))
            wrote = True
    if wrote:
        cat = Catalog.rebuild(root)
    return cat
