"""The ``pinfeed`` command line: thin over ``pipeline`` modules.

Every error a user can cause prints one line ``pinfeed: error: ...`` on
stderr and exits with status 2; nothing already stored is touched.
"""
from __future__ import annotations

import argparse
import json
import math
import re
import sys
from pathlib import Path

import numpy as np

from pipeline.errors import PinfeedError

PAPER_D = [-0.9, -0.8, -0.7, -0.6, -0.5, -0.4, -0.3, -0.2, -0.1,
           0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9]
DEFAULT_TRIANGLE = "0,0 60,0 15,35"


def _print_json(obj, **kw):
    """One JSON document on stdout, newline-terminated (the ``--json`` outputs)."""
    json.dump(obj, sys.stdout, **kw)
    sys.stdout.write("\n")


def parse_values(text: str, what: str) -> np.ndarray:
    """``"a,b,c"`` or an inclusive range ``"start:stop:step"``: finite, distinct,
    at most ``checks.MAX_VALUES`` values (refused before anything is allocated)."""
    from pipeline.checks import check_grid_size, check_values, range_size
    bad = PinfeedError(f"{what} {text!r} is not a list 'a,b,c' or a range 'start:stop:step' "
                       f"of finite numbers with step > 0")
    try:
        if ":" in text:
            start, stop, step = (float(x) for x in text.split(":"))
        else:
            values = [float(x) for x in text.split(",") if x.strip()]
    except ValueError:
        raise bad from None
    if ":" in text:
        if not all(map(math.isfinite, (start, stop, step))) or step <= 0 or stop < start:
            raise bad
        n = range_size(start, stop, step)
        check_grid_size(n, f"{what} {text}")
        return np.round(start + step * np.arange(n), 10) + 0.0
    check_grid_size(len(values), what)
    return check_values(values, f"{what} {text!r}")


def _part_from_args(args):
    """The part of ``--vertices`` or ``--outline`` (saying how many vertices a CAD outline gave)."""
    from pipeline.parts.part import Part, parse_vertices
    if getattr(args, "outline", None):
        from pipeline.parts.outlines import read_outline
        out = read_outline(args.outline, layer=args.layer, id=args.id, flatten_tol=args.flatten_tol,
                           units=args.units, join_tol=args.join_tol)
        print(f"outline {out.describe()}", file=sys.stderr)
        for line in out.warnings():
            print(f"pinfeed: warning: {line}", file=sys.stderr)
        name = args.name or re.sub(r"[^A-Za-z0-9_]", "_", Path(args.outline).stem) or "part"
        return Part.from_vertices(out.vertices, name=name)
    if any(getattr(args, k, None) is not None for k in ("layer", "id", "units", "join_tol")):
        raise PinfeedError("--layer, --id, --units and --join-tol apply to an --outline file")
    return Part.from_vertices(parse_vertices(args.vertices), name=args.name or "part")


def _add_outline_args(p, required=True):
    """``--vertices`` or ``--outline FILE`` (with its choosers), and ``--name``."""
    g = p.add_mutually_exclusive_group(required=required)
    g.add_argument("--vertices", help='part outline "x0,y0 x1,y1 ..." (mm)')
    g.add_argument("--outline", metavar="FILE",
                   help="or a CAD outline: a .dxf or .svg file; its pieces are joined into closed loops "
                   "and the largest is the part (the others are reported). Holes are refused (not "
                   "modelled): put them on another layer and pick the outline with --layer")
    p.add_argument("--layer", default=None, metavar="NAME",
                   help="DXF layer of the outline (when the file holds several)")
    p.add_argument("--id", default=None, help="SVG element id or DXF entity handle of the outline")
    p.add_argument("--units", default=None, choices=["mm", "cm", "m", "in"],
                   help="units of the outline file's coordinates, overriding the file's own "
                   "(DXF $INSUNITS, unitless: mm; SVG width/height over viewBox)")
    p.add_argument("--join-tol", dest="join_tol", type=float, default=None, metavar="TOL",
                   help="largest gap between piece ends that are joined, in the drawing's units "
                   "(default 1e-4 of the drawing's size)")
    p.add_argument("--flatten-tol", dest="flatten_tol", type=float, default=0.05, metavar="MM",
                   help="chordal tolerance for flattening arcs and curves, mm (default 0.05)")
    p.add_argument("--name", default=None, help="part name used in outputs (default: part, or the "
                   "outline file's name)")


def _add_physics(p, d_required=True, belt=False):
    _add_outline_args(p)
    p.add_argument("--mu-c", type=float, required=True, help="pin-part friction coefficient (>= 0)")
    p.add_argument("--pin-radius", type=float, required=True, help="pin radius (mm, > 0)")
    if belt:
        p.add_argument("--model", default="minpower",
                       choices=["minpower", "tip", "ellipsoid", "dynamic", "mujoco"],
                       help="contact model (default minpower); dynamic and mujoco need --belt-speed")
        p.add_argument("--belt-speed", dest="belt_speed", type=float, default=None,
                       help="belt speed, mm/s (models dynamic and mujoco)")
        p.add_argument("--mu-s", dest="mu_s", type=float, default=0.5,
                       help="belt-part friction coefficient (models dynamic and mujoco; default 0.5)")
    else:
        p.add_argument("--model", default="minpower", choices=["minpower", "tip", "ellipsoid"],
                       help="contact model (default minpower)")
    p.add_argument("--v-pin", type=float, default=0.0,
                   help="pin speed across the belt / belt speed (default 0: static pin)")
    p.add_argument("--support", default=None, metavar="SPEC",
                   help=f"where the part presses on the belt (model minpower{' or mujoco' if belt else ''}): "
                   "uniform (default), "
                   "points:\"x0,y0,w0 x1,y1,w1 ...\" (mm, part frame: centroid at the origin, "
                   "drawing axes; w defaults to 1), rim or rim:N (N points on the outline), "
                   "tripod (three hull vertices holding the centroid)")


def cmd_rollout(args):
    """Roll a part past one pin (see :func:`pipeline.workflow.commands.rollout_rows`)."""
    from pipeline.workflow.commands import rollout_belt, rollout_rows
    part = _part_from_args(args)
    belt = rollout_belt(part, args.model, args.belt_speed, args.mu_s)
    rows = rollout_rows(part, parse_values(args.theta_i, "--theta-i"), args.d, args.mu_c, args.pin_radius,
                        args.model, v_pin=args.v_pin, max_travel=args.max_travel,
                        trajectory=args.trajectory, belt=belt, support=args.support)
    if args.json:
        _print_json(rows)
        return
    speed = f"  belt {args.belt_speed:g} mm/s  mu_s = {args.mu_s:g}" if belt else ""
    support = f"  support {args.support}" if args.support else ""
    print(f"part {part.id}  a = {part.a:.3f} mm  model {args.model}  mu_c = {args.mu_c:g}  "
          f"pin radius {args.pin_radius:g} mm  d = {args.d:+g}{speed}{support}")
    print(f"{'theta_i':>8} {'status':>9} {'theta_f':>9} {'dy (mm)':>9} {'travel':>8} "
          f"{'changes':>7} {'peak F':>7}")
    for r in rows:
        note = f"  ({r['jam_reason']})" if r["jam_reason"] != "none" else ""
        print(f"{r['theta_i']:8.2f} {r['status']:>9} {r['theta_f']:9.3f} {r['dy']:9.3f} "
              f"{r['contact_travel']:8.2f} {r['feature_changes']:7d} {r['peak_force']:7.3f}{note}")
    if args.trajectory:
        for r in rows:
            _print_trajectory(r)


def _print_trajectory(row, n_rows: int = 11):
    """A short table of one rollout's trajectory: about ``n_rows`` evenly spaced samples."""
    traj = np.asarray(row["trajectory"], float).reshape(-1, 4)
    print(f"\ntrajectory of theta_i = {row['theta_i']:g} deg ({len(traj)} samples; "
          f"--json gives them all): belt travel since first contact s, centroid displacement x, y, "
          f"orientation theta")
    if not len(traj):
        print("  no contact: the part rides past the pin")
        return
    print(f"{'s (mm)':>9} {'x (mm)':>9} {'y (mm)':>9} {'theta (deg)':>12}")
    for k in np.unique(np.linspace(0, len(traj) - 1, min(n_rows, len(traj))).round().astype(int)):
        s_, x, y, th = traj[k]
        print(f"{s_:9.2f} {x:9.3f} {y:9.3f} {th % 360:12.2f}")


def cmd_map(args):
    """``pinfeed map``: compute one map set (dims ``d x theta_i``) and write it to HDF5."""
    from pipeline.checks import MAP_SUFFIXES, MAX_MAP, check_grid_size, check_out_path
    from pipeline.maps import simulate
    from pipeline.maps.io import write_atomic
    from pipeline.provenance import provenance_attrs
    part = _part_from_args(args)
    d = parse_values(args.d, "--d")
    if not args.theta_step > 0 or args.theta_step > 360:
        raise PinfeedError(f"--theta-step must be in (0, 360] degrees, got {args.theta_step}")
    check_grid_size(math.ceil(360.0 / args.theta_step), f"--theta-step {args.theta_step:g} (theta_i grid)")
    check_grid_size(d.size * math.ceil(360.0 / args.theta_step), "the map (d x theta_i)", MAX_MAP)
    check_out_path(args.out, MAP_SUFFIXES)
    theta = np.arange(0.0, 360.0 - 1e-9, args.theta_step)
    ds = simulate.compute_map(part, theta, d, args.mu_c, args.pin_radius, model=args.model,
                              v_pin=args.v_pin, threads=args.threads, backend=args.backend,
                              support=args.support)
    ds.attrs.update(provenance_attrs())
    write_atomic(ds, args.out)
    counts = {name: int((ds.status.values == k).sum()) for k, name in enumerate(simulate.STATUSES)}
    print(f"wrote {args.out}: {d.size} d x {theta.size} theta_i, "
          + ", ".join(f"{v} {k}" for k, v in counts.items() if v))


def _bands_option(text):
    """``--bands T,C`` -> (threshold T in deg, factor c), or None."""
    if text is None:
        return None
    vals = parse_values(text, "--bands")
    if vals.size != 2 or not (vals[0] > 0 and vals[1] >= 0):
        raise PinfeedError(f"--bands {text!r}: give the band threshold T (deg, > 0) and the factor c "
                           f"(>= 0), e.g. --bands 5,2")
    return float(vals[0]), float(vals[1])


def cmd_plot_map(args):
    """``pinfeed plot-map``: draw a stored map file to an image."""
    from pipeline.checks import IMAGE_SUFFIXES, check_out_path
    from pipeline.maps.io import read_map
    from pipeline.present.figures.maps import plot_map
    check_out_path(args.out, IMAGE_SUFFIXES)
    out = plot_map(read_map(args.map), args.out, bands=_bands_option(args.bands))
    print(f"wrote {out}")


def cmd_demo(args):
    """The main job until the workflow lands: one map set of a default triangle."""
    from pathlib import Path

    from pipeline.maps import simulate
    from pipeline.maps.io import write_atomic
    from pipeline.parts.part import Part, parse_vertices
    from pipeline.present.figures.maps import plot_map
    from pipeline.provenance import provenance_attrs
    part = Part.from_vertices(parse_vertices(DEFAULT_TRIANGLE), name="triangle")
    theta = np.arange(0.0, 360.0, 1.0)
    print(f"computing {len(PAPER_D)} x {theta.size} minpower rollouts of {part.id} ...", flush=True)
    ds = simulate.compute_map(part, theta, PAPER_D, 0.2, 3.0)
    ds.attrs.update(provenance_attrs())
    out = Path(args.out)
    write_atomic(ds, out / "map.h5")
    plot_map(ds, out / "map.png")
    print(f"wrote {out / 'map.h5'} and {out / 'map.png'}")


def _catalog(args):
    from pipeline.maps.catalog import RECOMPUTE, Catalog
    cat = Catalog.open(args.catalog)
    for problem in cat.problems:
        print(f"pinfeed: warning: {problem} (not served; {RECOMPUTE})", file=sys.stderr)
    return cat


def cmd_catalog_index(args):
    """``pinfeed catalog index``: rebuild the catalog index from the shards on disk."""
    from pipeline.maps.catalog import Catalog
    cat = Catalog.rebuild(args.catalog)
    print(f"indexed {len(cat.entries)} shards under {args.catalog}")
    for problem in cat.problems:
        print(f"pinfeed: warning: {problem}", file=sys.stderr)


def cmd_catalog_list(args):
    """``pinfeed catalog list``: one row per stored part (or JSON)."""
    rows = _catalog(args).parts()
    if args.json:
        _print_json(rows, indent=1)
        return
    print(f"{'family':<18} {'part':<28} {'models':<22} {'mu_c':<18} {'v_pin/v_b':<16} {'d x theta_i':<12} "
          f"supports")
    for r in rows:
        print(f"{r['family']:<18} {r['part_id']:<28} {','.join(r['models']):<22} "
              f"{','.join(f'{m:g}' for m in r['mu_c']):<18} "
              f"{','.join(f'{v:g}' for v in r['v_pin']):<16} {r['n_d']} x {r['n_theta']:<8} "
              f"{'; '.join(r['supports'])}")


def cmd_catalog_show(args):
    """``pinfeed catalog show``: a part's stored shards and provenance."""
    cat = _catalog(args)
    entries = cat.entries_for(args.part)
    if args.support is not None:
        entries = cat.entries_on(args.part, args.support)
    e0 = entries[0]
    info = {k: e0[k] for k in ("family", "part_id", "part_name", "part_vertices", "pin_radius",
                               "d", "theta_step", "config_hash", "pinfeed_version", "git_commit")}
    info["shards"] = [dict({k: e[k] for k in ("model", "mu_c", "file", "sha256", "created")},
                           v_pin=e.get("v_pin", 0.0), support=e.get("support", "uniform"))
                      for e in sorted(entries, key=lambda e: (e["model"], e["mu_c"], e.get("v_pin", 0.0),
                                                              e.get("support_key", "")))]
    if args.json:
        _print_json(info, indent=1)
        return
    print(f"part {info['part_id']} (family {info['family']})")
    print("vertices (body frame, mm): " + " ".join(f"{x:.3f},{y:.3f}" for x, y in info["part_vertices"]))
    print(f"pin radius {info['pin_radius']:g} mm; theta step {info['theta_step']:g} deg; "
          f"d = {', '.join(f'{d:g}' for d in info['d'])}")
    print(f"made by pinfeed {info['pinfeed_version']} ({info['git_commit']}), config {info['config_hash']}")
    for sh in info["shards"]:
        print(f"  {sh['model']:<10} mu_c={sh['mu_c']:<6g} v_pin/v_b={sh['v_pin']:<5g} {sh['file']}  "
              f"{sh['created']}" + ("" if sh["support"] == "uniform" else f"  support {sh['support']}"))


def _query(args):
    cat = _catalog(args)
    d = parse_values(args.d, "--d") if args.d is not None else None
    ds = cat.query(args.part, model=args.model, mu_c=args.mu_c, d=d, method=args.method,
                   v_pin=args.v_pin, support=args.support)
    if getattr(args, "theta_i", None) is not None:
        ds = ds.sel(theta_i=parse_values(args.theta_i, "--theta-i"), method="nearest")
    return ds


def cmd_catalog_query(args):
    """``pinfeed catalog query``: outcomes of one part at the asked mu_c, d and theta_i."""
    from pipeline.maps.simulate import status_names
    ds = _query(args).load()
    rows = []
    for mu in ds["mu_c"].values:
        for d in ds["d"].values:
            sub = ds.sel(mu_c=mu, d=d)
            for k, th in enumerate(sub["theta_i"].values):
                rows.append({"mu_c": float(mu), "d": float(d), "theta_i": float(th),
                             "status": str(status_names(sub["status"].values[k])),
                             "theta_f": float(sub["theta_f"].values[k]), "dy": float(sub["dy"].values[k])})
    if args.json:
        _print_json({"part": ds.attrs.get("part_id"), "model": args.model, "v_pin": args.v_pin,
                     "support": str(ds["support"].values), "selection": ds.attrs["selection"], "rows": rows})
        return
    print(f"selection: {ds.attrs['selection']}")
    print(f"{'mu_c':>6} {'d':>6} {'theta_i':>8} {'status':>9} {'theta_f':>9} {'dy (mm)':>9}")
    for r in rows:
        print(f"{r['mu_c']:6g} {r['d']:6g} {r['theta_i']:8.2f} {r['status']:>9} {r['theta_f']:9.3f} {r['dy']:9.3f}")


def cmd_catalog_plot(args):
    """``pinfeed catalog plot``: draw one part's stored map at one friction."""
    from pipeline.checks import IMAGE_SUFFIXES, check_out_path
    from pipeline.present.figures.maps import plot_map
    check_out_path(args.out, IMAGE_SUFFIXES)
    ds = _query(args)
    if ds.sizes["mu_c"] != 1:
        raise PinfeedError("plot one friction at a time: give --mu-c")
    sub = ds.isel(mu_c=0).load()
    sub.attrs["mu_c"] = float(ds["mu_c"].values[0])
    print(f"selection: {ds.attrs['selection']}")
    print(f"wrote {plot_map(sub, args.out, bands=_bands_option(args.bands))}")


def cmd_sweep(args):
    """``pinfeed sweep``: compute the shards a config asks for into the catalog."""
    from pipeline.config import load_config
    from pipeline.maps.sweep import run_sweep
    config = load_config(args.config)
    if args.catalog:
        config["catalog_dir"] = args.catalog
    written = run_sweep(config, scheduler=args.scheduler, threads=args.threads,
                        progress=not args.quiet, backend=args.backend)
    index = Path(config["catalog_dir"]).resolve() / "index.json"
    print(f"computed {len(written)} shards; catalog index at {index}")



def cmd_plan(args):
    """Plan a part (see :func:`pipeline.workflow.commands.plan_command`)."""
    from pipeline.config import load_config
    from pipeline.workflow.commands import plan_command, plan_store_path, planner_settings
    speeds = None if args.speeds is None else (parse_values(args.speeds, "--speeds") if args.speeds else [])
    pins = parse_values(args.pins, "--pins") if args.pins else None
    config = planner_settings(load_config(args.config), catalog=args.catalog, mu_c=args.mu_c,
                              depth=args.depth, model=args.model, coverage=args.coverage, speeds=speeds,
                              dynamic_depth=args.dynamic_depth, pins=pins, belt_speed=args.belt_speed,
                              mu_s=args.mu_s, tolerance=args.tolerance,
                              support_family=args.support_family)
    part = _plan_part_arg(args, config)
    out = plan_store_path(config, part.name, args.out)  # checked before any work
    result = plan_command(part, config, args.mode, progress=None if args.json else _progress)
    if out is not None:
        from pipeline.maps.io import write_json
        write_json(result, out)
    if args.json:
        _print_json(_plan_json(result, args.mode), default=float)
    else:
        _print_plan_result(result, part, config, args.mode)
    _print_stored(result, out, config, args.config, sys.stderr if args.json else sys.stdout)


def _print_stored(result, out, config, config_path, stream):
    """Where the plan went and the commands that use it (``stream``: stderr with
    ``--json``, which keeps stdout one JSON document)."""
    from pipeline.workflow.commands import next_step_hints
    if out is None:
        print(f"not stored: the workflow stores {result['part']['name']}'s plan; give --out FILE.json "
              f"to keep this one", file=stream)
        return
    print(f"stored the plan at {out}", file=stream)
    hints = next_step_hints(result, out, config, config_path)
    if hints:
        print("next: " + "\n      ".join(hints), file=stream)
    else:
        print("(speed, layout and animate read RESULTS/plans/NAME.json: store it there to use them)",
              file=stream)


def _progress(message):
    print(f"  ... {message}", flush=True)


def _plan_part_arg(args, config):
    from pipeline.workflow.commands import named_part
    if args.vertices or args.outline:
        return _part_from_args(args)
    return named_part(config, args.part)


def _verification_counts(plan) -> dict | None:
    v = plan.get("verification")
    if not v:
        return None
    reasons = {}
    for row in v.get("rows", []):
        for k, n in row.get("reasons", {}).items():
            reasons[k] = reasons.get(k, 0) + n
    return {"trials": v["trials"], "successes": v["successes"], "failures": v["failures"],
            "reasons": reasons}


def _plan_summary(plan, pins=None) -> dict:
    heights = plan.get("pin_heights_mm") or [pins[p] for p in plan["pins"]]
    orientation = (plan.get("verification") or {}).get("orientation")
    return {"pins": list(plan["pins"]), "pin_heights_mm": list(heights),
            "final_sets": plan["final_sets"], "n_final_sets": plan["n_final_sets"],
            "claimed_width_deg": _claimed_width(plan), "claim": plan.get("claim"),
            "verified_width_deg": orientation["width_deg"] if orientation else None,
            "orients": orientation["orients"] if orientation else None,
            **_claim_numbers(orientation),
            "selection": _selection_counts(plan),
            "verification": _verification_counts(plan)}


def _claim_numbers(orientation) -> dict:
    """The held-out claim's share with its lower bound, and the width's interval."""
    o = orientation or {}
    return {key: o.get(key) for key in ("share", "share_lower_bound", "confidence", "point_rule",
                                        "width_interval_deg")}


def _selection_counts(plan) -> dict | None:
    """The verdict on the trials that chose the plan, apart from the held-out claim."""
    s = (plan.get("verification") or {}).get("selection")
    if not s:
        return None
    return {key: s.get(key) for key in ("orients", "in_tolerance", "trials", "width_deg")}


def _claimed_width(plan) -> float | None:
    """Width (deg) of the claimed final orientation, if it is one arc."""
    sets = plan.get("final_sets") or []
    return float(sets[0]["width"]) if len(sets) == 1 else None


def _plan_json(result, mode) -> dict:
    out = {"part": result["part"]["name"], "part_id": result["part"]["id"], "mode": mode,
           "belt_speed": result.get("belt_speed"), "mu_s": result.get("mu_s")}
    tight = result.get("tight")
    if tight:
        first = tight[0]
        out.update(mu_c=first["mu_c"], warning=first["warning"], tolerance_deg=first.get("tolerance_deg"),
                   support_family=(first.get("support_family") or {}).get("label", "uniform"),
                   orients=first.get("orients"), pins_used=first.get("pins_used"),
                   evidence=(first.get("fixed_pin_search") or {}).get("evidence"),
                   recommended=_plan_summary(first["recommended"]) if first["recommended"] else None,
                   plans=[_plan_summary(p) for p in first["plans"]],
                   rejected=[_plan_summary(p) for p in first["rejected"]],
                   frictions=[{"mu_c": t["mu_c"], "warning": t["warning"],
                               "plans": [_plan_summary(p) for p in t["plans"]]} for t in tight])
    if "plans" in result and mode != "tight":
        paper = {"mu_c": result["mu_c"], "plans": [_plan_summary(p, result["pins"]) for p in result["plans"]]}
        if mode == "paper":
            out.update(paper)
        else:
            out["paper"] = paper
    return out


def _print_plan_result(result, part, config, mode):
    """A plan result (the dict ``plan_command`` returns), for people."""
    from pipeline.planning.arcs import format_arcs
    from pipeline.planning.plan import mechanics_label, planner_belt
    from pipeline.planning.types import as_plan_file
    result = as_plan_file(result)
    pc = config["planner"]
    print(f"part {part.id}: model {mechanics_label(pc['model'], *planner_belt(config))}, depth {pc['depth']}")
    for k, (theta, y_c) in enumerate(part.stable_states(), start=1):
        print(f"  state {k}: resting on the fence at theta = {theta:.1f} deg, y_c = {y_c:.2f} mm")
    for t in result.tight or ():
        st = t.stats
        print(f"tight planner, friction {t.friction}: {st['rollouts']} new rollouts in "
              f"{st['seconds']:.0f} s, stored under {config['catalog_dir']}/refine/{part.id}/")
        family = t.extra.get("support_family")
        if family:
            print(f"  for every member of the support family {family['label']} ({len(family['members'])} "
                  f"supports; nominal paths under {', '.join(family['extremes'])})")
        search = t.extra.get("fixed_pin_search")
        if search:
            print(f"  {search['evidence']}")
        if t.warning:
            print(f"  WARNING: {t.warning}")
        for k, plan in enumerate(t.plans, start=1):
            v = plan.verification
            heights = ", ".join(f"{q} at {y:g} mm" for q, y in zip(plan.pins, plan.pin_heights_mm))
            mark = " (recommended)" if t.recommended is not None and plan == t.recommended else ""
            print(f"  #{k}{mark}: {heights} -> claimed {plan.n_final_sets} set(s) "
                  f"({plan.extra.get('claim', 'propagated')}): {format_arcs(plan.final_arcs)}; "
                  f"{_orientation_text(v)}; margin in d "
                  + (f"{plan.margin:+.3f}" if plan.margin is not None else "n/a (touches nothing)"))
            _print_claim(plan)
    if mode == "tight" or result.plans is None:
        return
    print(f"paper-mode planner (adjusted bands), {result.extra['selection']}:")
    if not result.plans:
        print("  no allowed pin sequence within the depth")
    speeds = result.pin_speeds
    for k, plan in enumerate(result.plans, start=1):
        heights = ", ".join(f"{q} at {result.pins[q]:g} mm" + (f" moving {speeds[q]:+g} v_b" if q in speeds else "")
                            for q in plan.pins)
        print(f"  #{k}: {heights} -> {plan.n_final_sets} final set(s): "
              f"{format_arcs(plan.final_arcs)}; "
              f"margin in d {plan.margin:.3f}")


def _print_claim(plan) -> None:
    """The held-out claim with its uncertainty, the selection trials apart, the margin in words."""
    from pipeline.planning.complete import margin_text
    from pipeline.planning.orient import describe_claim
    v = plan.verification
    o = v.extra.get("orientation") if v else None
    if o and "share_lower_bound" in o:
        where = "held-out trials" if v.extra.get("held_out") else "trials"
        print(f"      {where}: {describe_claim(o)}")
        sel = v.extra.get("selection")
        if sel:
            print(f"      selection trials (chose the plan; no claim): {sel['in_tolerance']}/{sel['trials']} "
                  "in one set" + (f", width {sel['width_deg']:.1f} deg" if sel.get("width_deg") is not None else ""))
    print(f"      {margin_text(plan.margin)}")


def _orientation_text(v) -> str:
    """Verified width next to the claim: how many trials ended in one set within the tolerance."""
    o = v.extra.get("orientation") if v else None
    if not o:
        return f"verified {v.successes}/{v.trials} trials in the claimed sets" if v else "not verified"
    width = "n/a" if o["width_deg"] is None else f"{o['width_deg']:.1f} deg"
    verdict = "orients" if o["orients"] else f"{o['sets_within_tolerance']} sets of {o['tolerance_deg']:g} deg"
    return (f"verified width {width} ({verdict}: {o['in_tolerance']}/{v.trials} trials in one set of "
            f"{o['tolerance_deg']:g} deg; {v.successes}/{v.trials} in the claimed sets)")


def _results_arg(args, config) -> Path:
    """The results folder of stored plans and sensing: --results, else the config's."""
    from pipeline.config import results_folder
    return Path(args.results) if args.results else results_folder(config)


def cmd_speed(args):
    """A plan's success rate against belt speed and its speed limit (dynamic model)."""
    from pipeline.config import load_config
    from pipeline.planning.speed_limit import speed_label
    from pipeline.workflow.commands import speed_command, stored_plan
    config = load_config(args.config)
    result, _ = stored_plan(config, _results_arg(args, config), args.part, args.config)
    out, stored = speed_command(result, config, args.plan, args.mu_c, args.mu_s, args.trials)
    if args.json:
        _print_json(out, default=float)
        return
    same = out["source"] == "stored with the plan"
    other = "" if same or not stored else f"; the plan file stores {speed_label(stored)}"
    print(f"{out['part']}, plan {' '.join(out['pin_labels'])} (mu_c {out['friction']}, mu_s "
          f"{out['mu_s']:g}): speed limit {speed_label(out)}"
          + (", stored with the plan" if same else f", {out['seconds']:.0f} s") + other)
    for speed, frac in out["curve"]:
        print(f"  {speed:7.1f} mm/s: {100 * frac:5.1f} % of trials in the final set")


def cmd_layout(args):
    """A feeder to build: pin stations, pitch, belt width, throughput and a drawing."""
    from pipeline.checks import check_out_path
    from pipeline.config import load_config
    from pipeline.present.layout import check_drawing_path, layout_stored, write_drawing
    from pipeline.workflow.commands import layout_settings, stored_plan
    config = load_config(args.config)
    as_json = args.out is not None and Path(args.out).suffix.lower() == ".json"
    if args.out:  # before minutes of trials
        check_out_path(args.out, (".json",)) if as_json else check_drawing_path(args.out)
    settings = layout_settings(args.margin, args.trials)
    result, _ = stored_plan(config, _results_arg(args, config), args.part, args.config)
    out = layout_stored(result, config, args.plan, args.mu_c, belt_speed=args.belt_speed,
                        mu_s=args.mu_s, quasi_static=args.quasi_static, settings=settings)
    for warning in out["warnings"]:
        print(f"pinfeed: warning: {warning}", file=sys.stderr)
    if as_json:
        from pipeline.maps.io import write_json
        write_json(out, args.out)
    elif args.out:
        write_drawing(out, args.out)
    if args.json:
        _print_json(out, default=float)
        return
    _print_layout(out)
    if args.out:
        print(f"wrote {args.out}")


def _print_layout(out: dict):
    """The stations, belt, pitch and throughput of a layout, for people."""
    from pipeline.present.layout import speed_limit_text
    m = out["method"]
    print(f"{out['part']}, plan {out['plan']['number']}: {' '.join(out['plan']['pins'])} "
          f"(mu_c {out['plan']['friction']}); model {m['model']}, {m['trials']['replayed']} trials "
          f"({m['trials']['jammed_left_out']} jammed, left out)")
    for s in out["stations"]:
        print(f"  pin {s['label']:<6} x = {s['x_mm']:8.1f} mm   y = {s['y_mm']:6.1f} mm   "
              f"radius {s['radius_mm']:g} mm")
    speed = out["belt_speed_mm_s"]
    print(f"belt speed {'n/a' if speed is None else f'{speed:.1f} mm/s'} ({m['belt_speed']}); "
          f"speed limit {speed_limit_text(out)}")
    print(f"pitch {out['pitch_mm']:.1f} mm; belt width {out['belt_width_mm']:.1f} mm "
          f"(y {out['belt_y_mm'][0]:.1f} to {out['belt_y_mm'][1]:.1f}); fence at y = 0 up to "
          f"x = {out['fence_end_x_mm']:.1f} mm")
    tp = out["throughput_per_min"]
    print(f"throughput {'n/a' if tp is None else f'{tp:.1f} parts/min'}")


def cmd_animate(args):
    """Animate a stored plan: every initial state past the pins on the moving belt."""
    from pipeline.config import load_config
    from pipeline.present.animate import animate_stored
    from pipeline.workflow.commands import animation_inputs, stored_plan
    config = load_config(args.config)
    result, path = stored_plan(config, _results_arg(args, config), args.part, args.config)
    stored_layout = path.parent.parent / f"layout_{args.part}.json"
    inputs, layout = animation_inputs(result, config, args.part, args.plan, args.layout, stored_layout,
                                      dict(config_path=args.config, results=args.results))
    if layout is not None:
        pins = " -> ".join(f"{r['label']} at x {r['x_mm']:.1f}, y {r['y_mm']:g} mm" for r in layout["stations"])
        print(f"animating the laid-out {inputs['what']} of {args.part}: {pins}; pitch "
              f"{layout['pitch_mm']:.1f} mm; {len(inputs['states'])} initial states", flush=True)
    else:
        pins = " -> ".join(f"{lbl} at {h:g} mm" + (f" moving {v:+g} v_b" if v else "")
                           for lbl, h, v in zip(inputs["labels"], inputs["heights"], inputs["speeds"]))
        print(f"animating the {inputs['what']} of {args.part}: {pins}; {len(inputs['states'])} initial "
              f"states", flush=True)
        if stored_layout.is_file():
            print(f"(a layout is stored at {stored_layout}: add --layout to draw its stations and pitch)")
    done = animate_stored(result, config, args.out, args.plan, frames=args.frames, fps=args.fps,
                          layout=layout)
    outcomes = ", ".join(f"{k}: {v}" for k, v in done["outcomes"].items())
    print(f"wrote {done['out']}: {done['frames']} frames over {done['belt_travel']:.0f} mm of belt "
          f"travel ({outcomes})")


def _plan_choice(text: str):
    """--plan: ``tight`` or a paper-mode plan number (1 = best)."""
    if text == "tight":
        return text
    try:
        return int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected 'tight' or a plan number, got {text!r}") from None


PROFILE_FORMAT = """\
A measured profile is a CSV file with three columns: time (s), F_x, F_y (the
force on the pin along and across the belt, any one force unit: the sign
matrix does not depend on it). A header row is optional (a first row that is
not numbers is skipped); further columns are ignored; time must increase.
The rows should cover the contact, from first touch to separation. The
profile is resampled to the sensor rate of the stored sensor plan (or of the
config) before it is smoothed."""


def cmd_sense_classify(args):
    """Classify a measured profile (see :func:`pipeline.sensing.measured.classify_measured`)."""
    from pipeline.config import load_config
    from pipeline.sensing.measured import classify_measured
    config = load_config(args.config)
    result, context = classify_measured(config, args.part, args.profile, _results_arg(args, config),
                                        catalog=args.catalog, y_pin=args.y_pin)
    if args.json:
        _print_json(result)
        return
    _print_classification(result, context, args.profile)


def _print_classification(result: dict, context: dict, profile):
    """A measured profile's verdict and final orientation, for people."""
    from pipeline.planning.arcs import format_arcs
    stored, final = context["stored"], result["final_sets"]
    mu_planned, margin = result["mu_c"], result["margin"]
    planned = f"{mu_planned[0]:g}:{mu_planned[1]:g}" if isinstance(mu_planned, list) else f"{mu_planned:g}"
    print(f"part {result['part_id']}: sensor pin at y = {result['y_pin']:g} mm ({result['y_pin_source']}); "
          f"model {result['model']}, mu_c {planned} (profiles simulated at {result['mu_c_profiles']:g}), "
          f"pin radius {result['pin_radius']:g} mm")
    print(f"profile {profile}: {result['samples']} samples over {result['duration']:.3f} s at "
          f"{result['sensor']['rate_hz']:g} Hz")
    if context["note"]:
        print(f"verdict: undecided ({context['note']})")
    elif result["decided"]:
        print(f"verdict: {result['best']} (decided: every other state scores at least "
              f"{margin} elements lower)")
    else:
        print(f"verdict: undecided between {', '.join(result['candidates'])} (scores within "
              f"{margin} elements of the best)")
    print(f"scores (equal elements of {result['elements']}):")
    for k, v in result["scores"].items():
        print(f"  {k}: {v}" + ("  <- best" if k == result["best"] else ""))
    if final is None and stored is None:
        print("final orientation: unknown (no sensor plan stored; the workflow's sense stage makes one)")
    elif final is None:
        print(f"final orientation: unknown (the stored sensor plan reads pin {stored['first_pin']} "
              f"at y = {stored['y_pin']:g} mm, not this one)")
    elif result["final_known"]:
        print(f"final orientation: {format_arcs(final)} (sensor plan {' -> '.join(stored['plan']['pins'])})")
    else:
        print(f"final orientation: one of {format_arcs(final)} (the verdict does not decide it)")


class _Parser(argparse.ArgumentParser):
    """argparse with the project's error contract: one line, exit status 2."""

    def error(self, message):
        self.exit(2, f"pinfeed: error: {message} (see '{self.prog} --help')\n")


# Options whose values may start with '-' (negative numbers, ranges such as
# -0.9:0.9:0.1) that argparse would otherwise take for an option.
_SIGNED_VALUE_OPTIONS = {"--d", "--theta-i", "--pins", "--v-pin", "--speeds", "--y-pin"}


def _join_signed_values(argv):
    out, i = [], 0
    while i < len(argv):
        tok = argv[i]
        if tok in _SIGNED_VALUE_OPTIONS and i + 1 < len(argv) and re.match(r"^-[\d.]", argv[i + 1]):
            out.append(f"{tok}={argv[i + 1]}")
            i += 2
        else:
            out.append(tok)
            i += 1
    return out


def build_parser() -> argparse.ArgumentParser:
    """The ``pinfeed`` argument parser, one subcommand per command."""
    parser = _Parser(prog="pinfeed", description="pinfeed: design part feeders that orient flat parts "
                     "on a conveyor with overhead pins.")
    sub = parser.add_subparsers(dest="command", required=True)

    _add_map_commands(sub)
    _add_sweep_plan_commands(sub)
    _add_catalog_commands(sub)
    _add_sense_commands(sub)
    _add_support_commands(sub)
    _add_stored_plan_commands(sub)
    _add_layout_commands(sub)
    return parser


def _add_map_commands(sub) -> None:
    """``rollout``, ``map`` and ``plot-map``: one passage, one map set, its drawing."""
    p = sub.add_parser("rollout", help="roll a part past one pin for some initial orientations")
    _add_physics(p, belt=True)
    p.add_argument("--theta-i", required=True, help="initial orientations, degrees: 'a,b,c' or 'start:stop:step'")
    p.add_argument("--d", type=float, required=True, help="contact parameter (y_pin - y_com)/a")
    p.add_argument("--trajectory", action="store_true", help="also show the trajectory: a short table, or every sample and the "
                   "force history with --json")
    p.add_argument("--max-travel", type=float, default=None,
                   help="stop after this belt travel since first contact (mm): status truncated")
    p.add_argument("--json", action="store_true", help="print JSON instead of a table")
    p.set_defaults(func=cmd_rollout)

    p = sub.add_parser("map", help="compute one map set (dims d, theta_i) into an HDF5 file")
    _add_physics(p)
    p.add_argument("--d", required=True, help="contact parameters: 'a,b,c' or inclusive 'start:stop:step'")
    p.add_argument("--theta-step", type=float, default=1.0, help="theta_i step, degrees (default 1)")
    p.add_argument("--threads", type=int, default=None, help="Numba threads (default: all cores)")
    p.add_argument("--backend", choices=("cpu", "cuda"), default="cpu",
                   help="cpu (Numba threads, default) or cuda (an NVIDIA GPU; pip install '.[cuda]')")
    p.add_argument("--out", required=True, help="output file (.h5)")
    p.set_defaults(func=cmd_map)

    p = sub.add_parser("plot-map", help="draw a map file like the paper's Table 1")
    p.add_argument("map", help="map file written by 'pinfeed map'")
    p.add_argument("--out", required=True, help="image file (.png, .pdf, .svg)")
    p.add_argument("--bands", default=None, metavar="T,C",
                   help="also draw the bands B_j x K_j and adjusted bands: threshold T (deg) and factor c")
    p.set_defaults(func=cmd_plot_map)


def _add_sweep_plan_commands(sub) -> None:
    """``sweep`` (catalog shards of a config), ``plan`` (pin sequences) and ``atlas``."""
    _add_sweep_command(sub)
    _add_plan_command(sub)


def _add_sweep_command(sub) -> None:
    """``sweep``: the catalog shards of a config."""
    p = sub.add_parser("sweep", help="compute missing catalog shards of a config (locally or on dask)")
    p.add_argument("--config", default=None, help="workflow config YAML (default: the embedded one)")
    p.add_argument("--catalog", default=None, help="catalog folder (default: the config's catalog_dir)")
    p.add_argument("--scheduler", default=None, help="dask.distributed scheduler address, e.g. tcp://host:8786")
    p.add_argument("--threads", type=int, default=None, help="Numba threads per shard")
    p.add_argument("--backend", choices=("cpu", "cuda"), default=None,
                   help="cpu or cuda (an NVIDIA GPU per worker; default: the config's "
                        "sweep.backend, else cpu)")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    p.set_defaults(func=cmd_sweep)


def _add_plan_command(sub) -> None:
    """``plan`` (pin sequences for a part) and ``atlas`` (the planned parts)."""
    p = sub.add_parser("plan", help="plan fixed pins for a part (computes missing maps)")
    p.add_argument("--part", default=None, help="part name or id from the config or catalog")
    _add_outline_args(p, required=False)
    p.add_argument("--config", default=None, help="workflow config YAML (default: the embedded one)")
    p.add_argument("--catalog", default=None, help="catalog folder (default: the config's)")
    p.add_argument("--mu-c", dest="mu_c", default=None,
                   help="friction the plan must work for: a value X or a range LO:HI (default: the config's)")
    p.add_argument("--mode", default="tight", choices=["tight", "paper", "both"],
                   help="tight propagation (default), the paper's adjusted bands, or both side by side")
    p.add_argument("--model", default=None, choices=["minpower", "tip", "ellipsoid"],
                   help="quasi-static contact model the plans are computed and verified with "
                        "(default: the config's planner.model, minpower)")
    p.add_argument("--depth", type=int, default=None, help="largest number of pins (>= 1)")
    p.add_argument("--pins", default=None, help="candidate pin heights, mm: 'a,b,c' or 'start:stop:step' "
                   "(default: the config's planner.pins; 'auto' there fits them to the part)")
    p.add_argument("--tolerance", type=float, default=None, metavar="DEG",
                   help="full width (deg) the final orientation set may have (default: planner.tolerance_deg, "
                   "10): a plan orients the part when verify.required (99.5%%) of its trials end in one "
                   "set this narrow")
    p.add_argument("--support-family", dest="support_family", default=None, metavar="SPEC",
                   help="supports the plan must hold for (issue 25): 'tripods:N[:inset=F][:seed=S]', "
                        "'warp:AMP[:N]', a support ('tripod', 'rim:N', 'points:x,y,w ...') or a list "
                        "'SPEC; SPEC'; 'uniform' for none (default: planner.support_family)")
    p.add_argument("--coverage", default=None, choices=["bracket", "nearest"],
                   help="paper mode only: which stored maps stand for an uncertain state; bracket "
                        "(the d maps around its d range and one theta_i step either side; "
                        "conservative) or nearest (the nearest d map, the grid points inside the "
                        "arc); default: the config's planner.coverage, bracket")
    p.add_argument("--speeds", default=None,
                   help="dynamic pin speeds v_pin/v_b after the static pins: 'a,b' ('' for none)")
    p.add_argument("--dynamic-depth", dest="dynamic_depth", type=int, default=None,
                   help="largest number of dynamic pins (0: fixed pins only)")
    p.add_argument("--belt-speed", dest="belt_speed", type=float, default=None, metavar="MM_S",
                   help="plan and verify with the dynamic model at this belt speed, mm/s "
                        "(default: the config's planner.belt_speed; none = quasi-static)")
    p.add_argument("--mu-s", dest="mu_s", type=float, default=None,
                   help="belt friction with --belt-speed (default: planner.mu_s, 0.5)")
    p.add_argument("--out", default=None, help="store the plan JSON here (default: RESULTS/plans/NAME.json, "
                   "where speed, layout and animate look; a part the workflow plans is stored only "
                   "with --out)")
    p.add_argument("--json", action="store_true")
    p.set_defaults(func=cmd_plan)

    p = sub.add_parser("atlas", help="the feedability atlas: which planned parts pins orient, with how "
                       "many pins, how precisely and how fast (RESULTS/atlas.json, made by the workflow)")
    p.add_argument("--config", default=None, help="workflow config YAML (default: the embedded one)")
    p.add_argument("--results", default=None, help="results folder holding atlas.json "
                   "(default: the config's results_dir/NAME)")
    p.add_argument("--json", action="store_true", help="print the atlas JSON")
    p.set_defaults(func=cmd_atlas)


def _add_catalog_commands(sub) -> None:
    """``catalog index|list|show|query|plot``: the map database."""
    cat = sub.add_parser("catalog", help="the map database: list, show, query, plot, index")
    csub = cat.add_subparsers(dest="catalog_command", required=True)

    def catalog_parser(name, help_text, func):
        q = csub.add_parser(name, help=help_text)
        q.add_argument("--catalog", default="catalog", help="catalog folder (default: catalog)")
        q.set_defaults(func=func)
        return q

    catalog_parser("index", "rebuild the index from the shards on disk", cmd_catalog_index)
    q = catalog_parser("list", "list the parts stored", cmd_catalog_list)
    q.add_argument("--json", action="store_true")
    q = catalog_parser("show", "everything stored about one part", cmd_catalog_show)
    q.add_argument("part", help="part name or id")
    q.add_argument("--support", default=None, metavar="SPEC",
                   help="only the shards of this support (its text or file key); default: every support")
    q.add_argument("--json", action="store_true")
    for name, func, help_text in (("query", cmd_catalog_query, "maps of one part, model, friction, d"),
                                  ("plot", cmd_catalog_plot, "draw stored maps like the paper's Table 1")):
        q = catalog_parser(name, help_text, func)
        q.add_argument("--part", required=True, help="part name or id")
        q.add_argument("--model", default="minpower", choices=["minpower", "tip", "ellipsoid"])
        q.add_argument("--mu-c", type=float, default=None, help="friction (nearest/bracketing stored value)")
        q.add_argument("--d", default=None, help="contact parameter(s): 'a,b' or 'start:stop:step'")
        q.add_argument("--method", default="nearest", choices=["nearest", "bracket"],
                       help="how to pick stored mu_c and d values (default nearest)")
        q.add_argument("--v-pin", dest="v_pin", type=float, default=0.0,
                       help="pin speed ratio v_pin/v_b of the maps (stored exactly; default 0, static)")
        q.add_argument("--support", default="uniform", metavar="SPEC",
                       help="support distribution of the maps (sweep.supports; stored exactly): its "
                            "text ('tripod', 'rim:64', 'points:...') or file key; default uniform")
        if name == "query":
            q.add_argument("--theta-i", default=None,
                           help="only these initial orientations (nearest stored)")
            q.add_argument("--json", action="store_true")
        else:
            q.add_argument("--out", required=True, help="image file (.png, .pdf, .svg)")
            q.add_argument("--bands", default=None, metavar="T,C",
                           help="also draw the bands: threshold T (deg) and factor c, e.g. 5,2")


def _add_sense_commands(sub) -> None:
    """``sense classify``: which initial state a measured force profile comes from."""
    sense = sub.add_parser("sense", help="force/torque sensor on the first pin: classify a measured profile")
    ssub = sense.add_subparsers(dest="sense_command", required=True)
    q = ssub.add_parser("classify", help="which initial state a measured force profile comes from",
                        description="Score a measured force profile against the simulated profile\n"
                        "of every initial state of a part at the sensor pin (the paper's sign\n"
                        "matrix) and print the verdict, the scores and, if a sensor plan is\n"
                        "stored, the final orientation that results.", epilog=PROFILE_FORMAT,
                        formatter_class=argparse.RawDescriptionHelpFormatter)
    q.add_argument("--part", required=True, help="part name or id in the catalog, or of a stored plan "
                   "under --results")
    q.add_argument("--profile", required=True, help="measured profile: CSV time (s), F_x, F_y (see below)")
    q.add_argument("--y-pin", dest="y_pin", type=float, default=None,
                   help="height of the sensor pin, mm (default: the stored sensor plan's first pin, "
                   "else the first pin of the stored recommended tight plan, else of paper mode's "
                   "best fixed-pin plan)")
    q.add_argument("--config", default=None, help="workflow config YAML (default: the embedded one)")
    q.add_argument("--catalog", default=None, help="catalog folder (default: the config's)")
    q.add_argument("--results", default=None, help="results folder holding plans/ and sensing/ "
                   "(default: the config's, RESULTS_DIR/NAME)")
    q.add_argument("--json", action="store_true", help="print JSON instead of text")
    q.set_defaults(func=cmd_sense_classify)


PUSHES_FORMAT = """pushes CSV: a header, then one push per row ('#' lines are comments):
  theta_i_deg,d,theta_f_deg[,mu_c]
  theta_i_deg  initial orientation of the part, degrees (paper convention)
  d            contact parameter (y_pin - y_com) / a of the push
  theta_f_deg  measured final orientation, degrees
  mu_c         pin-part friction of that push (optional; else --mu-c)"""


def cmd_support_fit(args):
    """``pinfeed support fit``: the point support that explains measured pushes."""
    from pipeline.config import load_config
    from pipeline.maps.support_fit import fit_support, read_pushes
    config = load_config(args.config)
    part = _plan_part_arg(args, config)
    pushes = read_pushes(args.pushes)
    fit = fit_support(part, pushes, args.mu_c, args.pin_radius, n_points=args.points,
                      starts=args.starts, refine=args.refine, seed=args.seed)
    result = {"part": part.name, "part_id": part.id, **fit.to_dict()}
    if args.out:
        from pipeline.maps.io import write_json
        from pipeline.provenance import provenance_attrs
        write_json({**result, "settings": {"mu_c": args.mu_c, "pin_radius": args.pin_radius,
                                           "points": args.points, "starts": args.starts,
                                           "refine": args.refine, "seed": args.seed, "pushes_file": str(args.pushes)},
                    **provenance_attrs()}, args.out)
    if args.json:
        _print_json(result)
        return
    print(f"part {part.id}: {fit.pushes} pushes, fitted {args.points} support points "
          f"(part frame, mm; weights by statics):")
    for (x, y), w in zip(fit.support.points, fit.support.weights):
        print(f"  ({x:8.3f}, {y:8.3f})  w = {w:.4f}")
    print(f"  --support \"{fit.spec}\"")
    print(f"residuals |theta_f model - measured|: rms {result['rms_deg']:.2f} deg, median "
          f"{result['median_deg']:.2f}, p90 {result['p90_deg']:.2f}, max {result['max_deg']:.2f}")
    print(f"uniform pressure on the same pushes: rms {result['uniform_rms_deg']:.2f} deg, median "
          f"{result['uniform_median_deg']:.2f}, p90 {result['uniform_p90_deg']:.2f}")
    if args.out:
        print(f"stored at {args.out}")


def _add_support_commands(sub) -> None:
    """``support fit``: a point support from measured pushes (issue 25)."""
    sup = sub.add_parser("support", help="support distributions: fit one to measured pushes")
    ssub = sup.add_subparsers(dest="support_command", required=True)
    q = ssub.add_parser("fit", help="the point support (weights by statics) whose rollouts best explain "
                        "measured pushes", epilog=PUSHES_FORMAT,
                        formatter_class=argparse.RawDescriptionHelpFormatter)
    q.add_argument("--part", default=None, help="part name or id from the config or catalog")
    _add_outline_args(q, required=False)
    q.add_argument("--config", default=None, help="workflow config YAML (default: the embedded one)")
    q.add_argument("--pushes", required=True, metavar="FILE.csv", help="measured pushes (format below)")
    q.add_argument("--mu-c", dest="mu_c", type=float, default=None,
                   help="pin-part friction of pushes without a mu_c column")
    q.add_argument("--pin-radius", dest="pin_radius", type=float, default=3.0, help="pin radius, mm (default 3)")
    q.add_argument("--points", type=int, default=3, help="support points to fit, 3 to 12 (default 3)")
    q.add_argument("--starts", type=int, default=48, help="random layouts tried before refining (default 48)")
    q.add_argument("--refine", type=int, default=4, help="best layouts refined by least squares (default 4)")
    q.add_argument("--seed", type=int, default=0, help="seed of the random layouts (default 0)")
    q.add_argument("--out", default=None, help="store the fit as JSON (with its settings and provenance)")
    q.add_argument("--json", action="store_true", help="print JSON instead of text")
    q.set_defaults(func=cmd_support_fit)


def cmd_atlas(args):
    """``pinfeed atlas``: the feedability atlas of a config's planned parts."""
    from pipeline.config import load_config, results_folder
    from pipeline.workflow.atlas import read_atlas
    config = load_config(args.config)
    path = (Path(args.results) if args.results else results_folder(config)) / "atlas.json"
    if not path.is_file():
        hint = f"snakemake --cores all --configfile {args.config}" if args.config else "make run"
        raise PinfeedError(f"no atlas at {path}; run the workflow first ('{hint}')")
    try:
        atlas = read_atlas(path)
    except (ValueError, KeyError):
        raise PinfeedError(f"{path} is corrupt; delete it and re-run the workflow") from None
    if args.json:
        _print_json(atlas)
        return
    print(f"feedability atlas of config {atlas['config']}: tolerance {atlas['tolerance_deg']:g} deg, "
          f"depth {atlas['depth']} ({path})")
    print(f"{'part':<18} {'outcome':<14} {'fixed':>5} {'moving':>6} {'sets':>4} {'width':>7} {'in set':>11} "
          f"{'limit':>7} {'parts/min':>9} {'plan s':>7}  plan")
    for r in atlas["rows"]:
        def num(key, fmt):
            return "-" if r.get(key) is None else format(r[key], fmt)
        inset = "-" if r.get("in_set") is None else f"{r['in_set']}/{r['trials']}"
        print(f"{r['part']:<18} {r['outcome']:<14} {num('fixed_pins', 'd'):>5} {num('moving_pins', 'd'):>6} "
              f"{num('sets', 'd'):>4} "
              f"{num('verified_width_deg', '.1f'):>7} {inset:>11} {num('speed_limit_mm_s', '.0f'):>7} "
              f"{num('throughput_per_min', '.0f'):>9} {num('planning_seconds', '.0f'):>7}  {r['plan'] or '-'}")


def _add_stored_plan_commands(sub) -> None:
    """``animate`` and ``speed``: a stored plan's animation and its belt-speed limit."""
    p = sub.add_parser("animate", help="animate a stored plan: every initial state past the pins")
    p.add_argument("--part", required=True, help="part name (its plan is RESULTS/plans/NAME.json)")
    p.add_argument("--plan", type=_plan_choice, default=None,
                   help="which plan: 'tight' (the tight planner's recommended plan) or N (paper "
                   "mode's Nth best; 1 = best); default: the tight one if any, else 1")
    p.add_argument("--layout", nargs="?", const="auto", default=None, metavar="LAYOUT.json",
                   help="draw the feeder of a 'pinfeed layout' JSON instead: one belt, the pins at "
                   "their stations, parts arriving at its pitch, each replayed with its model; "
                   "without a path RESULTS/layout_NAME.json (the workflow's); animates the "
                   "layout's own plan")
    p.add_argument("--out", required=True, help="animation file: .gif (Pillow) or .mp4 (needs ffmpeg)")
    p.add_argument("--frames", type=int, default=120, help="number of frames (default 120)")
    p.add_argument("--fps", type=int, default=20, help="frames per second (default 20)")
    p.add_argument("--config", default=None, help="workflow config YAML (default: the embedded one)")
    p.add_argument("--results", default=None, help="results folder holding plans/ "
                   "(default: the config's, RESULTS_DIR/NAME)")
    p.set_defaults(func=cmd_animate)

    p = sub.add_parser("speed", help="a stored plan's success against belt speed and its speed limit")
    p.add_argument("--part", required=True, help="part name (its plan is RESULTS/plans/NAME.json)")
    p.add_argument("--plan", type=int, default=1, help="which tight plan, 1 = the recommended one")
    p.add_argument("--mu-c", dest="mu_c", default=None, help="which planned friction: X or LO:HI")
    p.add_argument("--mu-s", dest="mu_s", type=float, default=None,
                   help="belt friction (default: the plan's stored speed limit's, else the config's "
                        "speed.mu_s, 0.5)")
    p.add_argument("--trials", type=int, default=None,
                   help="random trials per initial state (default: those of the speed limit stored "
                        "with the plan, else the config's speed.trials); other settings recompute it")
    p.add_argument("--config", default=None, help="workflow config YAML (default: the embedded one)")
    p.add_argument("--results", default=None, help="results folder holding plans/ "
                   "(default: the config's, RESULTS_DIR/NAME)")
    p.add_argument("--json", action="store_true")
    p.set_defaults(func=cmd_speed)


def _add_layout_commands(sub) -> None:
    """``layout`` (a feeder to build) and ``demo`` (one map set of a default triangle)."""
    p = sub.add_parser("layout", help="a feeder to build: pin stations, part pitch, belt width, "
                       "throughput and a drawing (DXF, SVG, PNG)")
    p.add_argument("--part", required=True, help="part name (its plan is RESULTS/plans/NAME.json)")
    p.add_argument("--plan", type=int, default=1, help="which tight plan, 1 = the recommended one")
    p.add_argument("--mu-c", dest="mu_c", default=None, help="which planned friction: X or LO:HI")
    p.add_argument("--belt-speed", dest="belt_speed", type=float, default=None,
                   help="belt speed, mm/s (default: 80%% of the plan's speed limit)")
    p.add_argument("--mu-s", dest="mu_s", type=float, default=None,
                   help="belt friction (default: the config's layout.mu_s, 0.5)")
    p.add_argument("--quasi-static", dest="quasi_static", action="store_true",
                   help="replay the trials with the plan's quasi-static model (no inertia) "
                        "instead of the dynamic model at the belt speed")
    p.add_argument("--margin", type=float, default=None,
                   help="station margin, mm (default: the config's layout.station_margin_mm, 5)")
    p.add_argument("--trials", type=int, default=None,
                   help="random trials per initial state (default: the config's layout.trials)")
    p.add_argument("--out", default=None, help="also draw the feeder (.dxf, .svg or .png) or write "
                   "the layout JSON (.json; 'pinfeed animate --layout' reads RESULTS/layout_NAME.json)")
    p.add_argument("--config", default=None, help="workflow config YAML (default: the embedded one)")
    p.add_argument("--results", default=None, help="results folder holding plans/ "
                   "(default: the config's, RESULTS_DIR/NAME)")
    p.add_argument("--json", action="store_true", help="print JSON instead of text")
    p.set_defaults(func=cmd_layout)

    p = sub.add_parser("demo", help="compute and plot one map set of a default triangle")
    p.add_argument("--out", default="results/demo", help="output folder")
    p.set_defaults(func=cmd_demo)


def main(argv=None) -> int:
    """Run the ``pinfeed`` command; returns the exit status.

    Parameters
    ----------
    argv : the arguments after the program name (default ``sys.argv[1:]``).
    """
    parser = build_parser()
    args = parser.parse_args(_join_signed_values(sys.argv[1:] if argv is None else list(argv)))
    try:
        from pipeline.provenance import source_date_epoch
        source_date_epoch()  # before numpy's f2py reads it (and crashes on a bad value)
        args.func(args)
    except PinfeedError as exc:
        print(f"pinfeed: error: {exc}", file=sys.stderr)
        return 2
    except BrokenPipeError:  # e.g. piped into head
        return 0
    except KeyboardInterrupt:  # Ctrl-C: one line; writes are atomic, finished work is kept
        return _interrupted()
    except SystemError as exc:  # Ctrl-C inside a Numba kernel call arrives wrapped
        if not _caused_by_interrupt(exc):
            raise
        return _interrupted()
    return 0


def _interrupted() -> int:
    """Ctrl-C: one line on stderr and the shell's status 130 (128 + SIGINT)."""
    print("pinfeed: interrupted; finished files and the rollouts computed so far are kept "
          "(the next run reuses them)", file=sys.stderr)
    return 130


def _caused_by_interrupt(exc: BaseException) -> bool:
    """Whether ``exc`` was raised because of a KeyboardInterrupt (its cause chain)."""
    seen = set()
    while exc is not None and id(exc) not in seen:
        if isinstance(exc, KeyboardInterrupt):
            return True
        seen.add(id(exc))
        exc = exc.__cause__ or exc.__context__
    return False


if __name__ == "__main__":
    sys.exit(main())
