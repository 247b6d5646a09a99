"""The functions of ``rules/report.smk``: figures, outline, animation and the
HTML page that links every result of the planned parts (read from the
results folder and the catalog; nothing is recomputed but the nominal paths
and replays the figures draw)."""
from __future__ import annotations

from pathlib import Path

from pipeline.maps import simulate
from pipeline.maps.catalog import Catalog
from pipeline.maps.io import read_json
from pipeline.parts.families import config_part_source
from pipeline.parts.part import Part
from pipeline.planning import Friction
from pipeline.planning import (KernelSettings, PlanFile, VerifySettings, recommended_index, replayed_paths,
                               validate_plan_file)
from pipeline.present.figures import placeholder, placeholder_gif
from pipeline.present.figures.bands import plot_band_maps
from pipeline.present.figures.carried import plot_carried
from pipeline.present.figures.outline import plot_outline
from pipeline.present.figures.sequence import plot_sequence
from pipeline.present.figures.tables import markdown_table, plot_table, plot_verification, verification_rows
from pipeline.present.report import write_report
from pipeline.workflow.commands import animate_stored
from pipeline.workflow.plan import plans_to_check


def nominal_paths(plan_result: dict, config: dict, plan: dict | None = None, pins: dict | None = None,
                  speeds: dict | None = None, mu_c: float | None = None) -> dict:
    """Unperturbed rollouts of a plan (default: the best): (theta, y_c) before and after each pin;
    ``pins`` (label -> mm), ``speeds`` (label -> v_pin / v_b) and ``mu_c`` default to the
    file's tables and paper mode's friction."""
    part = Part.from_dict(plan_result["part"])
    best = plan or plan_result["plans"][0]
    pins = plan_result["pins"] if pins is None else pins
    speeds = plan_result.get("pin_speeds", {}) if speeds is None else speeds
    mu_c = plan_result["mu_c"] if mu_c is None else mu_c
    return {label: simulate.nominal_path(part, s["theta"], s["y_c"], [pins[p] for p in best["pins"]], mu_c,
                                         config["sweep"]["pin_radius"], plan_result["model"],
                                         [speeds.get(p, 0.0) for p in best["pins"]])
            for label, s in plan_result["initial_states"].items()}


def tight_plan_pins(plan: dict) -> tuple[dict, dict]:
    """A tight plan's own pins: label -> height (mm), and label -> speed (v_pin / v_b)
    of its moving pins."""
    pins = dict(zip(plan["pins"], plan["pin_heights_mm"]))
    speeds = {q: v for q, v in zip(plan["pins"], plan.get("pin_speeds") or ()) if v}
    return pins, speeds


def make_figures(config, plan_paths, verify_paths, out: dict):
    """Every figure of the planned parts. ``out`` holds lists (one path per
    part, in plan order) under ``maps`` (models side by side), ``speeds``
    (the planner's model at each pin speed), ``sequence`` (best fixed-pin
    plan), ``sequence_dynamic`` (best plan with dynamic pins), optionally
    ``sequence_tight`` (the recommended tight plan; see
    :func:`sequence_subjects`), and single
    paths ``verification`` (PNG) and ``table`` (Markdown)."""
    cat = Catalog.open(config["catalog_dir"])
    bc, fc = config["bands"], config["figures"]
    verifications = {}
    for k, (plan_path, verify_path) in enumerate(zip(plan_paths, verify_paths)):
        res = validate_plan_file(plan_path)
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
        for kind, (what, plan) in sequence_subjects(res).items():
            if kind in out:
                _sequence_figure(config, res, plan, what, out[kind][k])
        if "carried" in out:
            carried_figure(config, res, out["carried"][k])
        verifications[name] = read_json(verify_path)
        if out.get("verification_plans"):  # optional: one figure per part, its plans stacked
            _verification_figure(verifications[name], out["verification_plans"][k])
    rows = verification_rows(verifications)
    plot_table(rows, "Verification of the best plans by perturbed full rollouts", out["verification"])
    Path(out["table"]).write_text(markdown_table(rows))


def _verification_figure(result: dict, path):
    """The verification figure of a part: every checked plan (``verify_part`` result)."""
    if not result["checks"]:
        placeholder(path, f"{result['part']}: {result.get('note', 'nothing verified')}")
        return
    plot_verification(result["checks"], f"{result['part']}: verification by perturbed rollouts", path)


def sequence_subjects(res: dict) -> dict:
    """What each pin-sequence figure of a plan file draws, ``kind -> (what, plan
    dict or None)``: ``sequence`` (paper mode's best plan of fixed pins),
    ``sequence_dynamic`` (its best plan with dynamic pins) and ``sequence_tight``
    (the tight planner's recommended plan at the first friction). The figures'
    titles and the report's captions both come from here."""
    to_draw = plans_to_check(res)
    tight = (res.get("tight") or [None])[0]
    return {"sequence": ("best fixed-pin plan (paper mode)", to_draw.get("fixed pins")),
            "sequence_dynamic": ("best plan with dynamic pins (paper mode)", to_draw.get("with dynamic pins")),
            "sequence_tight": ("recommended tight plan" + (f" at mu_c {tight['friction']}" if tight else ""),
                               tight.get("recommended") if tight else None)}


def figure_captions(res: dict, speed: dict | None = None, layout: dict | None = None) -> dict:
    """The report's caption of each figure of a part, kind -> text, from the records
    the figure is drawn from: the plan file (maps, sequences, carried sets), the
    speed JSON and the layout JSON."""
    out = {"maps": f"Configuration maps with bands at mu_c {res['mu_c']:g} (rows: models)",
           "speeds": f"Maps by pin speed (dynamic pins), {res['model']} at mu_c {res['mu_c']:g}"}
    for kind, (what, plan) in sequence_subjects(res).items():
        out[kind] = f"Pin sequence: {what}: " + (" → ".join(plan["pins"]) if plan else "none")
    _, rec = sequence_subjects(res)["sequence_tight"]
    if rec:
        out["carried"] = (f"Carried sets against replayed rollouts: {out['sequence_tight'].split(': ', 1)[1]}")
    if speed and speed.get("speed_limit_mm_s") is not None:
        out["speed_limit"] = (f"Success against belt speed (dynamic model) of tight plan "
                              f"{' → '.join(speed['pin_labels'])} at mu_c {speed['friction']}: speed limit "
                              f"{speed['speed_limit_mm_s']:g} mm/s ({speed['trials']} trials per state)")
    if layout and layout.get("plan"):
        out["layout_png"] = (f"Feeder drawing (top view) of tight plan {layout['plan']['number']}: "
                             f"{' → '.join(layout['plan']['pins'])}")
    return out


def _sequence_figure(config, res, plan, what, path):
    name = res["part"]["name"]
    if plan is None:
        if "tight" in what:
            tight = (res.get("tight") or [None])[0]
            why = (tight or {}).get("warning") or "no tight plan"
        elif not res["plans"]:
            why = f"no allowed plan within depth {res['depth']}"
        elif "fixed" in what:
            why = "no allowed plan of fixed pins only"
        else:
            why = "no plan with dynamic pins beats the fixed pins (or none allowed)"
        placeholder(path, f"{name}, {what}: {why}")
        return
    part = Part.from_dict(res["part"], name=name)
    pins, speeds, mu_c = res["pins"], res.get("pin_speeds", {}), None
    if plan.get("pin_heights_mm") is not None:  # a tight plan: its own heights, speeds and friction
        pins, speeds = tight_plan_pins(plan)
        mu_c = Friction.parse(res["tight"][0]["mu_c"]).nominal
    plot_sequence(part, plan, pins, nominal_paths(res, config, plan, pins, speeds, mu_c),
                  config["sweep"]["pin_radius"], f"{name}: {what}", path, speeds=speeds)


def carried_figure(config, res, path):
    """The tight planner's recommended plan (first friction): carried sets against replays."""
    stored = PlanFile.from_dict(res)
    name = stored.name
    tight = (stored.tight or [None])[0]
    if not tight or not tight.recommended:
        placeholder(path, f"{name}: no recommended tight plan" + (f" ({tight.warning})" if tight else ""))
        return
    plan = tight.recommended.to_dict()
    part = Part.from_dict(res["part"], name=name)
    starts = {k: (v["theta"], v["y_c"]) for k, v in res["initial_states"].items()}
    replays = replayed_paths(part, plan, starts, tight.mu_c, config["sweep"]["pin_radius"], res["model"],
                             VerifySettings.from_section(config.get("verify")),
                             kernel=KernelSettings.from_section(config["sweep"].get("kernel")),
                             belt_speed=tight.belt_speed, mu_s=tight.mu_s or 0.5)
    plot_carried(plan, replays, f"{name}: carried sets of plan {' '.join(plan['pins'])} (mu_c "
                 f"{tight.friction}) against {len(next(iter(replays.values()))[0])} replayed "
                 f"rollouts per state", path)


def outline_figure(plan_result: dict, config: dict, out) -> Path:
    """The outline figure of a planned part (from its plan JSON)."""
    part = Part.from_dict(plan_result["part"])
    return plot_outline(part, out, source=config_part_source(config, part.name))


def animate_part(plan_result: dict, config: dict, out, frames: int, fps: int,
                 layout: dict | None = None) -> dict:
    """The part's recommended plan as an animation: the tight planner's
    recommended plan (first friction) if there is one, else paper mode's best;
    with no plan at all, a one-frame note. With ``layout`` (the layout stage's
    JSON) that has stations, the laid-out plan on one belt instead: pins at the
    stations, parts at the pitch. Returns the summary (``plan``: which one)."""
    if layout is not None and layout.get("stations"):
        return animate_stored(plan_result, config, out, frames=frames, fps=fps, layout=layout)
    which = recommended_index(plan_result)
    if which is None:
        placeholder_gif(out, f"{plan_result['part']['name']}: no plan to animate")
        return {"out": str(out), "frames": 1, "plan": None, "outcomes": {}}
    return animate_stored(plan_result, config, out, which, frames=frames, fps=fps)


PART_FIGURES = ("outline", "maps", "speeds", "sequence", "sequence_dynamic", "sequence_tight", "carried",
                "verification", "profiles", "scores", "speed_limit", "support_maps")


def part_files(results, name: str) -> dict:
    """Where the workflow writes a part's files under ``results`` (RESULTS_DIR/NAME):
    JSON (``plan``, ``verify``, ``sensing``, ``speed``, ``support``), figures
    (:data:`PART_FIGURES`) and the ``animation``; the rules in rules/*.smk use
    the same names."""
    results = Path(results)
    out = {kind: results / kind.replace("plan", "plans") / f"{name}.json"
           for kind in ("plan", "verify", "sensing", "speed", "support")}
    out.update({kind: results / "figures" / f"{kind}_{name}.png" for kind in PART_FIGURES})
    out["animation"] = results / "animations" / f"{name}.gif"
    out.update({f"layout_{ext}": results / f"layout_{name}.{ext}" for ext in ("json", "png", "dxf", "svg")})
    return out


def make_report(config, plan_paths, verify_paths, out, sensing_paths=(), speed_paths=(), atlas_path=None,
                support_paths=()):
    """The HTML page (``out``, in the results folder) of the planned parts: the
    feedability atlas (``atlas_path``) first, their results, every figure found
    beside them, and the catalog shards they use."""
    results = Path(out).parent
    cat = Catalog.open(config["catalog_dir"])
    parts = {}
    for plan_path, verify_path in zip(plan_paths, verify_paths):
        plan = validate_plan_file(plan_path)
        name = plan["part"]["name"]
        files = {k: p for k, p in part_files(results, name).items() if Path(p).is_file()}
        files.update(plan=Path(plan_path), verify=Path(verify_path))
        if "layout_json" in files:  # the feeder layout (rules/layout.smk)
            parts.setdefault(name, {})["layout"] = read_json(files["layout_json"])
        parts[name] = {**parts.get(name, {}), "plan": plan, "verify": read_json(verify_path), "files": files,
                       "shards": sorted((e for e in cat.entries if e["part_id"] == plan["part"]["id"]),
                                        key=lambda e: (e["model"], e["mu_c"], e.get("v_pin", 0.0),
                                                      e.get("support_key", "")))}
    for path in sensing_paths:  # force/torque sensor on the first pin (rules/sense.smk)
        res = read_json(path)
        parts[res["part"]["name"]]["sensing"] = res
        parts[res["part"]["name"]]["files"]["sensing"] = Path(path)
    for path in speed_paths:  # speed curve and limit of the recommended plan (rules/speed.smk)
        res = read_json(path)
        parts[res["part"]]["speed"] = res
        parts[res["part"]]["files"]["speed"] = Path(path)
    for path in support_paths:  # plans against the support family (rules/support.smk)
        res = read_json(path)
        parts[res["part"]]["support"] = res
        parts[res["part"]]["files"]["support"] = Path(path)
    for part in parts.values():
        part["captions"] = figure_captions(part["plan"], part.get("speed"), part.get("layout"))
    overview = {k: results / f for k, f in (("verification figure", "figures/verification.png"),
                                            ("verification table", "verification.md"))
                if (results / f).is_file()}
    return write_report(config, parts, out, overview=overview, catalog=cat.root,
                        atlas=read_json(atlas_path) if atlas_path else None)


# ---------------------------------------------------------------------- rules reading a plan file


def outline(plan_path, config: dict, out) -> Path:
    """Rule ``outline``: :func:`outline_figure` of the stored plans at ``plan_path``."""
    return outline_figure(validate_plan_file(plan_path), config, out)


def animate(plan_path, config: dict, out, frames: int, fps: int, layout_path=None) -> dict:
    """Rule ``animate``: :func:`animate_part` of the stored plans at ``plan_path``,
    on the feeder of the layout stage's JSON at ``layout_path`` when given."""
    layout = read_json(layout_path) if layout_path else None
    return animate_part(validate_plan_file(plan_path), config, out, frames, fps, layout=layout)
