"""The functions of ``rules/plan.smk`` (bands, plan, verify) and the maps a
plan needs (``ensure_maps``, for ``pinfeed plan`` on a part the catalog lacks).

bands  -> one JSON per shard: B_j, K_j, COM_j and adjusted bands for every d
plan   -> one JSON per planned part: paper mode's ranked plans and the tight plans
verify -> one JSON per planned part: perturbed full rollouts of the plans to check
All of it lives in the config's results folder (``results_dir/NAME``,
:func:`pipeline.config.results_folder`; file names in
:func:`pipeline.workflow.report.part_files`). All JSON is written atomically."""
from __future__ import annotations

from pathlib import Path

from pipeline.errors import PinfeedError
from pipeline.maps.catalog import Catalog, nearest_stored
from pipeline.maps.io import read_map, write_json
from pipeline.maps.sweep import ShardJob, write_shard
from pipeline.parts.part import Part
from pipeline.parts.support import support_key
from pipeline.parts.families import config_part_id
from pipeline.planning import (Plan, PlanFile, PlannerSettings, RestingState, attach_shape_tolerance,
                               attach_speed_limits, build_planner, load_maps, paper_depth, plan_tight_all,
                               validate_plan_file, verify_plan)
from pipeline.progress import Heartbeat
from pipeline.provenance import provenance_attrs


def shard_bands(shard, threshold_T, factor_c) -> dict:
    """The bands of every map (every d) in one shard, with provenance: B_j, the
    kernels K_j as all their arcs, COM intervals and the bands adjusted by
    ``factor_c`` standard deviations (threshold ``threshold_T``)."""
    ds = read_map(shard)
    maps = load_maps(ds, threshold_T, factor_c)
    return {"part_id": ds.attrs["part_id"], "model": ds.attrs["model"], "mu_c": ds.attrs["mu_c"],
            "v_pin": float(ds.attrs.get("v_pin", 0.0)),
            "threshold_T": threshold_T, "factor_c": factor_c, "shard": str(shard),
            "maps": {f"{m.d:g}": [b.to_dict() for b in m.bands] for m in maps},
            **provenance_attrs()}


def plan_part(cat: Catalog, part_id: str, settings: PlannerSettings, keep: int = 5, progress=None,
              tight: bool = True) -> PlanFile:
    """Plans for one catalog part (``part_id``: its id or catalog name): the
    paper's adjusted-band planner (``plans``, ``best_static``: fixed pins,
    then moving pins) at the stored friction nearest the planner's, and the
    tight planner (``tight``) at every friction of ``settings.frictions``,
    each verified by full rollouts; the plan file's record."""
    search = settings.search
    part, planner, mu_used, selection = build_planner(cat, part_id, settings)
    depth = paper_depth(search)
    plans = planner.search(depth, keep=keep, dynamic_depth=search.dynamic_depth, dynamic_beam=search.beam)
    states = planner.initial_states()
    static_only = [p for p in plans if p.n_dynamic == 0]
    if planner.dynamic_labels and not static_only:
        static_only = [p for p in planner.search(depth, keep=1) if p.n_dynamic == 0]
    return PlanFile(
        part.to_dict(), search.model,
        tight=tuple(plan_tight_all(part, settings, cat.root, keep=keep, progress=progress)) if tight else (),
        plans=tuple(Plan.from_dict(p.to_dict()) for p in plans),  # the paper-mode planner writes dicts
        best_static=Plan.from_dict(static_only[0].to_dict()) if static_only else None,
        pins=planner.pins, pin_speeds={k: v for k, v in planner.speeds.items() if v != 0.0}, mu_c=mu_used,
        initial_states={k: RestingState(s.arc[0], s.y_lo) for k, s in states.items()},
        extra={"selection": selection, "depth": depth,
               "dynamic_depth": search.dynamic_depth if planner.dynamic_labels else 0,
               "d_min": search.d_min, "d_max": search.d_max, "coverage": planner.coverage,
               "found": bool(plans), **provenance_attrs()})


def ensure_maps(config, part: Part, family: str = "adhoc") -> Catalog:
    """Make sure the catalog holds the maps the planner needs for ``part``:
    the planner's model at its mu_c over the sweep's d grid, for a static pin
    and for every dynamic speed the planner may use. Missing ones are
    computed with the sweep settings, stored atomically and indexed (how
    many, on the progress report of :func:`pipeline.progress.reporting`)."""
    root = Path(config["catalog_dir"])
    settings = PlannerSettings.from_config(config)
    search, mu = settings.search, settings.friction.nominal
    cat = Catalog.open(root) if (root / "index.json").is_file() else None
    entries = cat.entries if cat else []
    fam = next((e["family"] for e in entries if e["part_id"] == part.id), family)
    missing = [v for v in [0.0, *search.dynamic_speeds]
               if not any(e["part_id"] == part.id and e["model"] == search.model and e["mu_c"] == mu
                          and e.get("v_pin", 0.0) == v and not e.get("support_key") for e in entries)]
    with Heartbeat(f"maps of {part.name} for the paper-mode planner", len(missing), "map") as beat:
        for k, v in enumerate(missing):
            write_shard(config, ShardJob(fam, part, search.model, mu, v))
            beat.tick(k + 1)
    if missing:
        cat = Catalog.rebuild(root)
    return cat


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


def verify_part(plan_result: dict, settings: PlannerSettings) -> dict:
    """Perturbed full rollouts of the paper-mode plans (best fixed-pin plan and
    best plan with dynamic pins, if any) and of the tight planner's
    recommended plan at every friction: ``{"part", "checks": [verify_plan
    result + "kind"]}``."""
    name = plan_result["part"]["name"]
    out = {"part": name, "checks": [], **provenance_attrs()}
    part = Part.from_dict(plan_result["part"], name=name)
    states = {k: (v["theta"], v["y_c"]) for k, v in plan_result["initial_states"].items()}
    radius, kernel = settings.search.pin_radius, settings.search.kernel_step
    for kind, plan in plans_to_check(plan_result).items():
        res = verify_plan(part, plan, plan_result["pins"], states, plan_result["mu_c"], radius,
                          plan_result["model"], settings.verify,
                          speeds=plan_result.get("pin_speeds", {}), kernel=kernel)
        res.pop("trials_detail")
        out["checks"].append({"kind": f"paper mode, {kind}", **res})
    for tight in PlanFile.from_dict(plan_result).tight or ():
        plan = tight.recommended
        if plan is None:
            continue
        res = verify_plan(part, plan.to_dict(), dict(zip(plan.pins, plan.pin_heights_mm)), states,
                          tight.mu_c, radius, plan_result["model"], settings.verify, kernel=kernel,
                          speeds=dict(zip(plan.pins, plan.pin_speeds)),
                          belt_speed=tight.belt_speed, mu_s=tight.mu_s or 0.5)
        res.pop("trials_detail")
        out["checks"].append({"kind": f"tight, mu_c {tight.friction}", **res})
    if not out["checks"]:
        out["note"] = "no allowed plan within the depth"
    return out


# ---------------------------------------------------------------------- one function per rule


def bands(shard, settings: dict, out) -> dict:
    """Rule ``bands``: the bands of one shard with the config's ``bands``
    settings (``threshold_T``, ``factor_c``), written to ``out``."""
    result = shard_bands(shard, settings["threshold_T"], settings["factor_c"])
    write_json(result, out)
    return result


def planner_shards(config: dict, jobs: dict, name: str) -> list[str]:
    """The shard files the plan of part ``name`` reads, of ``jobs`` (path ->
    :class:`~pipeline.maps.sweep.ShardJob`, the config's sweep): the part's
    uniform-pressure shards of ``planner.model``, quasi-static belt, at the
    sweep friction nearest the planner's (as the catalog query picks it), with
    a static pin and at every ``planner.dynamic`` speed. The plan job takes
    these as input, so the atlas needs these shards alone, and a shard of
    another model, friction or support re-plans nothing."""
    settings = PlannerSettings.from_config(config)
    own = {path: job for path, job in jobs.items()
           if job.part.name == name and not support_key(job.support) and job.model == settings.search.model
           and not job.belt_speed}
    if not own:
        return []
    mu_c = nearest_stored({job.mu_c for job in own.values()}, settings.friction.nominal)
    speeds = {0.0, *settings.search.dynamic_speeds}
    return sorted(path for path, job in own.items() if job.mu_c == mu_c and float(job.v_pin) in speeds)


def plan(config: dict, name: str, out, shards=None) -> dict:
    """Rule ``plan``: the plans of the config's part ``name`` (:func:`plan_part`)
    with their speed limits (``attach_speed_limits``), written to ``out``;
    from the shard files ``shards`` alone when given (the job's input,
    :func:`planner_shards`), else from the catalog's index."""
    root = config["catalog_dir"]
    if shards is None:
        cat = Catalog.open(root)
    else:
        shards = list(shards)
        if not shards:
            model = config["planner"]["model"]
            raise PinfeedError(f"{name}: the sweep has no maps of this part for the planner "
                               f"(planner.model {model}, sweep.models {', '.join(config['sweep']['models'])}); "
                               f"add {model} to sweep.models")
        cat = Catalog.of_files(root, shards)
    settings = PlannerSettings.from_config(config)
    result = attach_speed_limits(plan_part(cat, config_part_id(config, name), settings), settings)
    result = with_shape_tolerance(result, Part.from_dict(result.part, name=result.name), settings).to_dict()
    write_json(result, out)
    return result


def with_shape_tolerance(result: PlanFile, part: Part, settings: PlannerSettings, progress=None) -> PlanFile:
    """``result`` (a plan file's record) with its tight entries'
    ``shape_tolerance`` when the settings give the outline's tolerance
    (``planner.shape_tolerance_mm``)."""
    tol = settings.search.shape_tolerance_mm
    if tol is not None and result.tight:
        return attach_shape_tolerance(result, part, settings, float(tol), progress)
    return result


def verify(plan_path, config: dict, out) -> dict:
    """Rule ``verify``: :func:`verify_part` of the stored plans at ``plan_path``,
    written to ``out``."""
    result = verify_part(validate_plan_file(plan_path), PlannerSettings.from_config(config))
    write_json(result, out)
    return result
