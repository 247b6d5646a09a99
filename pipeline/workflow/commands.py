"""What the ``pinfeed`` commands do, below the command line.

The CLI (``pipeline.cli``) parses options, calls one of these functions with
explicit arguments and prints what it returns; the choices and the checks
live here, where a script or a test can call them without argparse.

Each function imports the planner's names it uses when it runs, so that
``pinfeed rollout`` (which needs none) does not import the planner.
"""
from __future__ import annotations

import copy
import dataclasses
import math

from pipeline.errors import PinfeedError
from pipeline.maps.catalog import Catalog, entry_part
from pipeline.parts.families import family_parts
from pipeline.parts.part import Part
from pipeline.provenance import provenance_attrs


def planner_settings(config: dict, *, catalog=None, mu_c=None, depth=None, model=None, coverage=None,
                     speeds=None, dynamic_depth=None, pins=None, belt_speed=None, mu_s=None,
                     tolerance=None, support_family=None, shape_tolerance=None, time_limit=None) -> dict:
    """A copy of ``config`` with ``pinfeed plan``'s overrides applied, each checked.

    ``None`` leaves the config's value. ``catalog``: the catalog folder;
    ``mu_c``: a friction text (a value or ``lo:hi``; it replaces the
    ``planner.frictions`` list); ``depth`` (>= 1), ``model``, ``coverage``;
    ``speeds``: the moving pins' speed ratios (no 0; ``[]`` none);
    ``dynamic_depth`` (>= 0; 0 plans fixed pins only, dropping the speeds);
    ``pins``: candidate pin heights (mm); ``belt_speed`` (mm/s) and ``mu_s``
    (only with a belt speed); ``tolerance``: the full width (deg) a final set
    may have, in (0, 360); ``support_family``: the supports plans must hold
    for (``planner.support_family``; ``"uniform"`` for none); ``shape_tolerance``:
    the outline's tolerance, mm (``planner.shape_tolerance_mm``, > 0);
    ``time_limit``: seconds the planning may take (``planner.time_limit_s``,
    > 0). Raises :class:`PinfeedError` on a bad value before any work."""
    from pipeline.planning import Friction, check_tolerance
    config = copy.deepcopy(config)
    if catalog:
        config["catalog_dir"] = catalog
    pc = config["planner"]
    if mu_c is not None:
        pc["mu_c"] = mu_c
        pc["frictions"] = []
    Friction.parse(pc["mu_c"])  # a clear error before any work
    if depth is not None and depth < 1:
        raise PinfeedError(f"--depth must be at least 1 (the largest number of pins), got {depth}")
    for key, value in (("model", model), ("depth", depth), ("coverage", coverage)):
        if value is not None:
            pc[key] = value
    _dynamic_settings(pc["dynamic"], speeds, dynamic_depth)
    if pins is not None:
        pc["pins"] = [float(x) for x in pins]
    if tolerance is not None:
        pc["tolerance_deg"] = check_tolerance(tolerance)
    if shape_tolerance is not None:
        if not float(shape_tolerance) > 0:
            raise PinfeedError(f"--shape-tolerance must be a length > 0 mm, got {float(shape_tolerance):g}")
        pc["shape_tolerance_mm"] = float(shape_tolerance)
    if support_family is not None:
        if not support_family.strip():
            raise PinfeedError("--support-family is empty; give a family such as 'tripods:12' or "
                               "'warp:0.3', or 'uniform' for none")
        pc["support_family"] = None if support_family.strip() == "uniform" else support_family
    if time_limit is not None:
        from pipeline.checks import check_time_limit
        pc["time_limit_s"] = check_time_limit(time_limit, "--time-limit")
    if belt_speed is not None:
        pc["belt_speed"] = belt_speed
    if mu_s is not None:
        if pc.get("belt_speed") is None:
            raise PinfeedError("--mu-s is the belt friction of the dynamic model: give --belt-speed too")
        pc["mu_s"] = mu_s
    return config


def _dynamic_settings(dynamic: dict, speeds, dynamic_depth) -> None:
    """Apply ``--speeds`` and ``--dynamic-depth`` to ``planner.dynamic`` (in place)."""
    if speeds is not None:
        dynamic["speeds"] = [float(v) for v in speeds]
        if any(v == 0.0 for v in dynamic["speeds"]):
            raise PinfeedError("--speeds lists moving pins: drop 0 (static pins are always candidates)")
    if dynamic_depth is not None:
        if dynamic_depth < 0:
            raise PinfeedError("--dynamic-depth must be 0 (fixed pins only) or more")
        dynamic["depth"] = dynamic_depth
    if dynamic["depth"] == 0:
        dynamic["speeds"] = []


def named_part(config: dict, name: str | None) -> Part:
    """The part called ``name`` (a name or id): from the config's families, else
    from the catalog (whose error lists the known names)."""
    if not name:
        raise PinfeedError("give --part NAME, --vertices \"x0,y0 x1,y1 ...\" or --outline FILE")
    found = [p for fam, spec in config["families"].items() for p in family_parts(fam, spec)
             if name in (p.name, p.id)]
    if found:
        return found[0]
    cat = Catalog.open(config["catalog_dir"])
    e = cat.entries_for(name)[0]  # raises 'unknown part' with the known names
    return entry_part(e)


def plan_tight_only(part: Part, settings: PlannerSettings, catalog_root, progress=None, deadline=None):
    """The record of a plan file with the tight planner's plans only
    (``pinfeed plan --mode tight``; a
    :class:`~pipeline.planning.core.types.PlanFile`); ``deadline``: its time
    limit (default: ``planner.time_limit_s`` from now)."""
    from pipeline.planning import PlanFile, plan_tight_all, planner_belt
    belt_speed, mu_s = planner_belt(settings.search, part)
    belt = {} if belt_speed is None else {"belt_speed": belt_speed, "mu_s": mu_s}
    return PlanFile(part.to_dict(), settings.search.model,
                    tight=tuple(plan_tight_all(part, settings, catalog_root, progress=progress, deadline=deadline)),
                    extra={**belt, **provenance_attrs()})


def plan_command(part: Part, config: dict, mode: str, progress=None) -> dict:
    """What ``pinfeed plan`` stores: plans of ``part`` with the planner(s) of
    ``mode`` (``tight``, ``paper`` or ``both``), each verified, the tight ones
    with their speed limit (``speed_limit.attach_speed_limits``). A belt speed
    plans with the tight planner only (a one-line error otherwise). The
    planner's settings are made here, once, from ``config``. The plans are
    records until the end, where the plan file's dict is made.

    With ``planner.time_limit_s`` (``--time-limit``, tight mode only) the
    time runs from here, after the kernels are compiled or loaded
    (:func:`_warm_up`): the planner stops its searches in time
    (:func:`pipeline.planning.plan_tight_all`), the speed limits are found
    only while time is left and the shape tolerance's search is skipped; each
    entry's ``unsearched`` says what was left out."""
    from pipeline.planning import PlannerSettings, planner_belt
    settings = PlannerSettings.from_config(config)
    belt_speed, _ = planner_belt(settings.search, part)  # a bad belt: a one-line error before any work
    if belt_speed is not None and mode != "tight":
        raise PinfeedError("--belt-speed plans with the tight planner (its rollouts at that speed); "
                           "the paper-mode planner uses the quasi-static map shards: use --mode tight")
    family = settings.search.support_family
    if family:
        from pipeline.parts.support_family import parse_support_family
        from pipeline.planning import check_family_mechanics
        if mode != "tight":
            raise PinfeedError("--support-family plans with the tight planner (its trials sample the "
                               "family); the paper-mode planner's map shards assume one support: use "
                               "--mode tight")
        check_family_mechanics(settings.search)
        parse_support_family(family, part)  # a bad family: a one-line error before any work
    from pipeline.planning import attach_speed_limits
    from pipeline.progress import Deadline
    if settings.search.time_limit_s is not None and mode != "tight":
        raise PinfeedError("--time-limit (planner.time_limit_s) bounds the tight planner's search; "
                           "use --mode tight, or leave the time limit out")
    _warm_up(progress, settings.search.time_limit_s)
    deadline = Deadline(settings.search.time_limit_s)
    if mode == "tight":
        result = plan_tight_only(part, settings, config["catalog_dir"], progress=progress, deadline=deadline)
        if deadline.limited:
            return _time_limited_stages(result, part, settings, deadline).to_dict()
        from pipeline.workflow.plan import with_shape_tolerance
        return with_shape_tolerance(attach_speed_limits(result, settings, part), part, settings, progress).to_dict()
    from pipeline.workflow.plan import ensure_maps, plan_part
    cat = ensure_maps(config, part)
    result = plan_part(cat, part.id, settings, progress=progress, tight=mode == "both")
    if mode == "paper":
        result = dataclasses.replace(result, tight=None)
    return attach_speed_limits(result, settings, part).to_dict()


def _warm_up(progress, time_limit_s) -> None:
    """Compile (or load from the cache) the kernels before the search
    (:func:`pipeline.maps.warm.warm_kernels`), so a first run's compile is
    not taken for the pace of the search's first level. The compile is done
    once after an install and takes longer than most time limits, so a time
    limit runs from after it (a first run would otherwise search nothing);
    ``progress`` is told so when it compiled."""
    from pipeline.maps.warm import NOTICE_AFTER, warm_kernels
    took = warm_kernels(progress)
    if progress is not None and took > NOTICE_AFTER:
        progress(f"kernels compiled in {took:.0f} s"
                 + ("; the time limit counts from now" if time_limit_s is not None else ""))


def _time_limited_stages(result, part: Part, settings, deadline):
    """The stages after the tight planner under a time limit, on the plan
    file's record ``result``: the speed limits while time is left; the shape
    tolerance's search (a search of its own) not at all. What is skipped
    joins the first entry's ``unsearched``."""
    from pipeline.planning import attach_speed_limits
    skipped = []
    if not any(t.plans for t in result.tight or ()):
        pass  # no plan: no speed limit to find
    elif deadline.over():
        skipped.append("the speed limits of the plans: skipped")
    else:
        result = attach_speed_limits(result, settings, part)
    if settings.search.shape_tolerance_mm is not None:
        skipped.append("the shape tolerance's worst-member search: skipped under a time limit")
    if skipped and result.tight:
        entry = result.tight[0]
        entry = dataclasses.replace(entry, unsearched=list(entry.unsearched or []) + skipped, complete=False)
        result = dataclasses.replace(result, tight=(entry, *result.tight[1:]))
    return result


def layout_settings(margin=None, trials=None) -> dict:
    """``pinfeed layout``'s overrides of the config's ``layout`` section:
    ``station_margin_mm`` (a length >= 0 mm) and ``trials``."""
    settings = {}
    if margin is not None:
        if not (math.isfinite(margin) and margin >= 0):
            raise PinfeedError(f"--margin must be a length >= 0 mm, got {margin:g}")
        settings["station_margin_mm"] = margin
    if trials is not None:
        settings["trials"] = trials
    return settings


def rollout_belt(part: Part, model: str, belt_speed: float | None, mu_s: float) -> dict:
    """The belt settings of ``pinfeed rollout``: a belt model (``dynamic``,
    ``mujoco``) needs ``belt_speed`` (mm/s; checked with ``mu_s`` for this
    part), a quasi-static one takes none. Returns ``{"belt_speed", "mu_s"}``
    or ``{}`` (quasi-static)."""
    from pipeline.maps import simulate
    if model in simulate.BELT_MODELS:
        if belt_speed is None:
            raise PinfeedError(f"--model {model} needs --belt-speed MM_S")
        simulate.check_belt(part, belt_speed, mu_s)
        return dict(belt_speed=belt_speed, mu_s=mu_s)
    if belt_speed is not None:
        raise PinfeedError(f"--belt-speed is for --model dynamic or mujoco, not {model} "
                           f"(quasi-static: no belt speed)")
    return {}


def rollout_rows(part: Part, thetas, d: float, mu_c: float, pin_radius: float, model: str, *,
                 v_pin: float = 0.0, max_travel=None, trajectory: bool = False,
                 belt: dict | None = None, support=None) -> list[dict]:
    """``pinfeed rollout``: one rollout of ``part`` per initial orientation in
    ``thetas`` (degrees) at contact parameter ``d``, with the belt settings
    ``belt`` of :func:`rollout_belt` and the ``support`` (``None``: uniform;
    see ``simulate.resolve_support``). Returns a dict per rollout (the keys of
    ``--json``; with ``trajectory`` also the samples ``[s, x, y, theta]`` and
    the forces ``[s, F_x, F_y]``)."""
    import numpy as np

    from pipeline.maps import simulate
    belt = belt or {}
    support = simulate.resolve_support(part, support, model)
    rows = []
    for theta in thetas:
        ds = simulate.rollout(part, theta, d, mu_c, pin_radius, model=model, v_pin=v_pin,
                              max_travel=max_travel, trajectory=trajectory, support=support,
                              **belt)
        row = {"theta_i": float(theta), "status": str(ds.status.item()),
               "theta_f": float(ds.theta_f), "dy": float(ds.dy),
               "contact_travel": float(ds.contact_travel),
               "feature_changes": int(ds.feature_changes), "peak_force": float(ds.peak_force),
               "jam_reason": str(ds.jam_reason.item())}
        if trajectory:
            row["trajectory"] = np.column_stack([ds.traj_s, ds.traj_x, ds.traj_y,
                                                 ds.traj_theta]).tolist()
            row["force"] = np.column_stack([ds.force_s, ds.force_x, ds.force_y]).tolist()
        rows.append(row)
    return rows


def pinfeed_command(*words, config_path=None, results=None) -> str:
    """The text of a ``pinfeed`` command line (words quoted for a POSIX shell),
    with ``--config`` and ``--results`` when they are given: the hints the CLI
    prints, so that each one works as printed."""
    import shlex
    words = [str(w) for w in words]
    if config_path:
        words += ["--config", str(config_path)]
    if results:
        words += ["--results", str(results)]
    return " ".join(["pinfeed", *map(shlex.quote, words)])


def plan_store_path(config: dict, name: str, out=None, results=None):
    """Where ``pinfeed plan`` stores the plan of part ``name``: ``out`` if given,
    else ``RESULTS/plans/NAME.json`` (``results``, default the config's results
    folder), where ``speed``, ``layout`` and ``animate`` look; ``None`` for a
    part the workflow plans (``planner.parts``), whose file the workflow owns.
    The path is checked before any work."""
    from pathlib import Path

    from pipeline.checks import check_out_path
    from pipeline.config import results_folder
    if out is None and name in config["planner"]["parts"] and results is None:
        return None
    path = Path(out) if out else Path(results or results_folder(config)) / "plans" / f"{name}.json"
    return check_out_path(path, (".json",))


def next_step_hints(result: dict, path, config: dict, config_path=None) -> list[str]:
    """The commands that use a plan stored at ``path``: ``speed``, ``layout`` (of
    the first tight plan of fixed pins, if any; its JSON beside the plans) and
    ``animate``; none if the file is not ``RESULTS/plans/NAME.json``, where
    those commands look. ``--results`` appears where ``RESULTS`` is not the
    config's folder, ``--config`` where one was given."""
    from pathlib import Path

    from pipeline.config import results_folder
    path = Path(path)
    name = result["part"]["name"]
    if path.name != f"{name}.json" or path.parent.name != "plans":
        return []
    root = path.parent.parent
    opts = dict(config_path=config_path, results=None if root == results_folder(config) else root)
    hints = []
    if result.get("tight") and result["tight"][0]["plans"]:
        hints.append(pinfeed_command("speed", "--part", name, **opts))
        fixed = fixed_pin_plans(result)
        if fixed:
            plan = [] if fixed[0] == 1 else ["--plan", fixed[0]]
            layout = root / f"layout_{name}.json"
            hints.append(pinfeed_command("layout", "--part", name, *plan, "--out", layout, **opts))
    layout = ["--layout"] if len(hints) == 2 else []  # the layout just hinted at
    hints.append(pinfeed_command("animate", "--part", name, *layout, "--out",
                                 root / "animations" / f"{name}.gif", **opts))
    return hints


def fixed_pin_plans(result) -> list[int]:
    """Numbers (1 = recommended) of the tight plans of fixed pins only at the first
    planned friction of a stored plan (a :class:`PlanFile` or its dict)."""
    from pipeline.planning import as_plan_file
    tight = as_plan_file(result).tight
    plans = tight[0].plans if tight else ()
    return [k for k, p in enumerate(plans, start=1) if not any(float(v) for v in p.pin_speeds or ())]


def plan_hint(config: dict, name: str, root, config_path=None) -> str:
    """How to make the stored plan of ``name`` under results folder ``root``: the
    workflow for the parts it plans; ``pinfeed plan --part NAME`` for a part the
    config or the catalog knows; else ``pinfeed plan`` with its outline."""
    from pathlib import Path

    from pipeline.config import results_folder
    root = Path(root)
    default_root = root == results_folder(config)
    if name in config["planner"]["parts"] and default_root:
        return "run the workflow ('make run')"
    out = [] if default_root else ["--out", root / "plans" / f"{name}.json"]
    try:
        named_part(config, name)
    except PinfeedError:
        return (f"plan it from its outline: {pinfeed_command('plan', '--outline', 'FILE', '--name', name, *out, config_path=config_path)} "
                f"(or --vertices \"x0,y0 x1,y1 ...\")")
    return f"run '{pinfeed_command('plan', '--part', name, *out, config_path=config_path)}'"


def stored_plan(config: dict, root, part_name: str, config_path=None) -> tuple:
    """``(plan result, path)`` of the plan file stored for ``part_name`` under the
    results folder ``root``; a missing file is a one-line error saying how to make it
    (``config_path``: the ``--config`` the hint repeats)."""
    from pathlib import Path

    from pipeline.planning import validate_plan_file
    path = Path(root) / "plans" / f"{part_name}.json"
    if not path.is_file():
        raise PinfeedError(f"no stored plan for {part_name} at {path}; "
                           f"{plan_hint(config, part_name, path.parent.parent, config_path)} first")
    return validate_plan_file(path), path  # checked against the plan schema


def animation_inputs(result: dict, config: dict, part_name: str, plan, layout, stored_layout,
                     hint_opts=None) -> tuple:
    """``(inputs, layout)`` for ``pinfeed animate``: with ``layout`` (a path, or
    ``"auto"`` for ``stored_layout``) the laid-out plan and that layout (a dict);
    else plan ``plan`` of the stored ``result`` and ``None``. Fails early on a
    bad ``--plan``, a missing layout (saying how to make it, with the
    ``config_path``/``results`` of ``hint_opts``) or a layout of another part or plan."""
    from pathlib import Path

    from pipeline.maps.io import read_json
    from pipeline.planning import PlannerSettings, layout_inputs, plan_inputs
    if layout is None:
        return plan_inputs(result, plan, PlannerSettings.from_config(config)), None
    if plan is not None:
        raise PinfeedError("--layout animates the layout's own plan; leave out --plan")
    layout_path = stored_layout if layout == "auto" else Path(layout)
    if not layout_path.is_file():
        raise PinfeedError(f"no layout at {layout_path}; {layout_hint(result, part_name, layout_path, hint_opts)}")
    stored = read_json(layout_path)
    return layout_inputs(result, stored), stored


def animate_stored(result, config: dict, out, plan_index=None, frames: int = 120,
                   fps: int = 20, layout: dict | None = None) -> dict:
    """Animate a plan of a stored plan result (``plan_index`` as in
    :func:`pipeline.planning.plan_inputs`; what ``pinfeed animate`` and the
    workflow's animate rule call): the passages rolled by the planner
    (:func:`pipeline.planning.roll_plan`), drawn by
    :func:`pipeline.present.animate.animate_plan`. Returns its summary plus the inputs.

    With ``layout`` (``pinfeed layout``'s JSON for this part) the layout's own
    plan is animated on one belt instead (:func:`pipeline.planning.station_scene`,
    :func:`pipeline.present.animate.animate_layout`): pins at the stations, parts
    arriving at the layout's pitch; ``plan_index`` is then not used."""
    from pipeline.planning import (PlannerSettings, as_plan_file, layout_inputs, plan_inputs, roll_plan,
                                   station_scene)
    from pipeline.present.animate import animate_layout, animate_plan, check_animation_out
    check_animation_out(out, frames, fps)  # before any rollout
    result = as_plan_file(result)
    part = Part.from_dict(result.part, name=result.name)
    if layout is not None:
        inputs = layout_inputs(result, layout)
        scene = station_scene(part, layout, inputs["states"], inputs["mu_c"])
        done = animate_layout(scene, out, frames=frames, fps=fps,
                              what=f"{inputs['what']}, pins {' → '.join(inputs['labels'])}")
        return {**done, **inputs}
    inputs = plan_inputs(result, plan_index, PlannerSettings.from_config(config))
    lanes, stations, b_end = roll_plan(part, inputs["heights"], inputs["speeds"], inputs["states"],
                                       inputs["mu_c"], inputs["model"], inputs["pin_radius"])
    done = animate_plan(part, lanes, stations, b_end, inputs["heights"], inputs["speeds"],
                        inputs["pin_radius"], out, labels=inputs["labels"], frames=frames, fps=fps,
                        title=f"{part.name}: {inputs['what']}, pins {' → '.join(inputs['labels'])}")
    return {**done, **inputs}


def layout_hint(result, part_name: str, layout_path, hint_opts=None) -> str:
    """How to make the layout JSON at ``layout_path``: ``pinfeed layout`` of the
    first tight plan of fixed pins; or why no layout can be made."""
    fixed = fixed_pin_plans(result)
    if not fixed:
        return ("no stored tight plan of fixed pins to lay out (a layout places fixed pins only); "
                "re-plan with --dynamic-depth 0")
    plan = [] if fixed[0] == 1 else ["--plan", fixed[0]]
    return (f"run '{pinfeed_command('layout', '--part', part_name, *plan, '--out', layout_path, **(hint_opts or {}))}' "
            f"first")


def speed_command(result, config: dict, plan: int = 1, mu_text=None, mu_s=None, trials=None) -> tuple:
    """``pinfeed speed``: ``(speed result, stored record or None)``. The settings
    default to those of the speed limit stored with the plan (else the config's
    ``speed`` section); with the same settings the stored figure is returned
    (``source``: ``stored with the plan``), else it is computed (``computed``)."""
    from dataclasses import replace

    from pipeline.planning import PlannerSettings, SpeedSettings, pick_tight_plan, stored_plan_speed, stored_speed_limit
    planner = PlannerSettings.from_config(config)
    chosen, _, _ = pick_tight_plan(result, plan, mu_text)
    stored = stored_speed_limit(chosen)
    speed = SpeedSettings.from_json(stored["settings"]) if stored else planner.speed
    if mu_s is not None:
        if not mu_s > 0:
            raise PinfeedError(f"--mu-s must be > 0, got {mu_s}")
        speed = replace(speed, mu_s=float(mu_s))
    if trials is not None:
        if trials < 1:
            raise PinfeedError(f"--trials must be at least 1, got {trials}")
        speed = replace(speed, trials=int(trials))
    if stored and SpeedSettings.from_json(stored["settings"]) == speed:
        return dict({k: v for k, v in stored.items() if k != "settings"}, source="stored with the plan"), stored
    out = stored_plan_speed(result, planner, plan=plan, mu_text=mu_text, speed=speed)
    return dict(out, source="computed"), stored
