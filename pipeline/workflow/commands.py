"""What the ``pinfeed`` commands do, below the command line.

The CLI (``pipeline.cli``) parses options, calls one of these functions with
explicit arguments and prints what it returns; the choices and the checks
live here, where a script or a test can call them without argparse.
"""
from __future__ import annotations

import copy
import math

from pipeline.errors import PinfeedError
from pipeline.maps.catalog import Catalog
from pipeline.parts.families import family_parts
from pipeline.parts.part import Part
from pipeline.planning.orient import check_tolerance
from pipeline.planning.plan import plan_tight_all, planner_belt
from pipeline.planning.settings import parse_friction
from pipeline.provenance import provenance_attrs


def planner_settings(config: dict, *, catalog=None, mu_c=None, depth=None, model=None, coverage=None,
                     speeds=None, dynamic_depth=None, pins=None, belt_speed=None, mu_s=None,
                     tolerance=None) -> dict:
    """A copy of ``config`` with ``pinfeed plan``'s overrides applied, each checked.

    ``None`` leaves the config's value. ``catalog``: the catalog folder;
    ``mu_c``: a friction text (a value or ``lo:hi``; it replaces the
    ``planner.frictions`` list); ``depth`` (>= 1), ``model``, ``coverage``;
    ``speeds``: the moving pins' speed ratios (no 0; ``[]`` none);
    ``dynamic_depth`` (>= 0; 0 plans fixed pins only, dropping the speeds);
    ``pins``: candidate pin heights (mm); ``belt_speed`` (mm/s) and ``mu_s``
    (only with a belt speed); ``tolerance``: the full width (deg) a final set
    may have, in (0, 360). Raises :class:`PinfeedError` on a bad value
    before any work."""
    config = copy.deepcopy(config)
    if catalog:
        config["catalog_dir"] = catalog
    pc = config["planner"]
    if mu_c is not None:
        pc["mu_c"] = mu_c
        pc["frictions"] = []
    parse_friction(pc["mu_c"])  # a clear error before any work
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
    return Part.from_vertices(e["part_vertices"], name=e["part_name"])


def plan_tight_only(part: Part, config: dict, progress=None) -> dict:
    """A plan file with the tight planner's plans only (``pinfeed plan --mode tight``)."""
    belt_speed, mu_s = planner_belt(config, part)
    belt = {} if belt_speed is None else {"belt_speed": belt_speed, "mu_s": mu_s}
    return {"part": part.to_dict(), "model": config["planner"]["model"], **belt,
            "tight": plan_tight_all(part, config, config["catalog_dir"], progress=progress),
            **provenance_attrs()}


def plan_command(part: Part, config: dict, mode: str, progress=None) -> dict:
    """What ``pinfeed plan`` stores: plans of ``part`` with the planner(s) of
    ``mode`` (``tight``, ``paper`` or ``both``), each verified. A belt speed
    plans with the tight planner only (a one-line error otherwise)."""
    belt_speed, _ = planner_belt(config, part)  # a bad belt: a one-line error before any work
    if belt_speed is not None and mode != "tight":
        raise PinfeedError("--belt-speed plans with the tight planner (its rollouts at that speed); "
                           "the paper-mode planner uses the quasi-static map shards: use --mode tight")
    if mode == "tight":
        return plan_tight_only(part, config, progress=progress)
    from pipeline.workflow.plan import ensure_maps, plan_part
    cat = ensure_maps(config, part)
    if mode == "paper":
        pc = config["planner"]
        config = dict(config, planner=dict(pc, mu_c=pc["mu_c"], frictions=[]))
    result = plan_part(cat, part.id, config, progress=progress, tight=mode == "both")
    if mode == "paper":
        result.pop("tight")
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


def stored_plan(config: dict, root, part_name: str) -> tuple:
    """``(plan result, path)`` of the plan file stored for ``part_name`` under the
    results folder ``root``; a missing file is a one-line error saying how to make it."""
    from pathlib import Path

    from pipeline.planning.plan import plan_hint
    from pipeline.planning.types import validate_plan_file
    path = Path(root) / "plans" / f"{part_name}.json"
    if not path.is_file():
        raise PinfeedError(f"no stored plan for {part_name} at {path}; "
                           f"{plan_hint(config, part_name, path.parent.parent)} first")
    return validate_plan_file(path), path  # checked against the plan schema


def animation_inputs(result: dict, config: dict, part_name: str, plan, layout, stored_layout) -> tuple:
    """``(inputs, layout)`` for ``pinfeed animate``: with ``layout`` (a path, or
    ``"auto"`` for ``stored_layout``) the laid-out plan and that layout (a dict);
    else plan ``plan`` of the stored ``result`` and ``None``. Fails early on a
    bad ``--plan``, a missing layout or a layout of another part or plan."""
    from pathlib import Path

    from pipeline.maps.io import read_json
    from pipeline.present.animate import layout_inputs, plan_inputs
    if layout is None:
        return plan_inputs(result, plan, config), None
    if plan is not None:
        raise PinfeedError("--layout animates the layout's own plan; leave out --plan")
    layout_path = stored_layout if layout == "auto" else Path(layout)
    if not layout_path.is_file():
        raise PinfeedError(f"no layout at {layout_path}; run 'pinfeed layout --part {part_name}' "
                           f"or the workflow first")
    stored = read_json(layout_path)
    return layout_inputs(result, stored), stored
