"""``pinfeed sweep``, ``plan`` and ``atlas``: catalog shards, pin sequences, the atlas.

``sweep`` computes the shards a config asks for; ``plan`` plans the pins for
one part (a named part, ``--vertices`` or a CAD ``--outline``), stores the plan
and prints the commands that use it; ``atlas`` prints the feedability atlas
the workflow made. How a plan reads for people is in
:mod:`pipeline.cli.plan_text`; what ``plan`` suggests next (the commands that
use a plan that orients the part, or what may still orient it) in
:mod:`pipeline.cli.next_steps`.
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

from pipeline.cli.next_steps import print_next_steps
from pipeline.cli.options import (add_config_option, add_json_option, add_part_options, parse_values,
                                  plan_part_arg, print_json, progress_line)
from pipeline.cli.plan_text import plan_json, print_plan_result
from pipeline.errors import PinfeedError


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


def cmd_plan(args, print_result=print_plan_result):
    """Plan a part (see :func:`pipeline.workflow.commands.plan_command`); ``print_result``
    prints the result for people (not with ``--json``)."""
    from pipeline.config import load_config
    from pipeline.workflow.commands import plan_command, plan_store_path, planner_settings
    speeds = None if args.speeds is None else (parse_values(args.speeds, "--speeds") if args.speeds else [])
    pins = parse_values(args.pins, "--pins") if args.pins else None
    config = planner_settings(load_config(args.config), catalog=args.catalog, mu_c=args.mu_c,
                              depth=args.depth, model=args.model, coverage=args.coverage, speeds=speeds,
                              dynamic_depth=args.dynamic_depth, pins=pins, belt_speed=args.belt_speed,
                              mu_s=args.mu_s, tolerance=args.tolerance,
                              support_family=args.support_family, shape_tolerance=args.shape_tolerance,
                              time_limit=args.time_limit)
    part = plan_part_arg(args, config)
    out = plan_store_path(config, part.name, args.out)  # checked before any work
    result = plan_command(part, config, args.mode, progress=progress_line)
    if out is not None:
        from pipeline.maps.io import write_json
        write_json(result, out)
    if args.json:
        print_json({**plan_json(result, args.mode), **time_limit_summary(result)}, default=float)
    else:
        print_result(result, part, config, args.mode)
        print_time_limit(result)
    print_next_steps(result, out, config, args, plan_options(), sys.stderr if args.json else sys.stdout)


def time_limit_summary(result: dict) -> dict:
    """The time limit's keys of ``plan --json``: ``time_limit_s`` (``None``: no
    limit), ``complete`` (False when the limit left something out) and
    ``unsearched`` (what, for people; labelled with the friction when several
    were planned)."""
    tight = result.get("tight") or []
    several = len(tight) > 1
    unsearched = [f"mu_c {t['friction']}: {u}" if several else u
                  for t in tight for u in t.get("unsearched") or ()]
    return {"time_limit_s": next((t["time_limit_s"] for t in tight if t.get("time_limit_s")), None),
            "complete": all(t.get("complete", True) for t in tight), "unsearched": unsearched}


def print_time_limit(result: dict, stream=None) -> None:
    """Under a time limit, what the plan is worth: complete within the limit,
    or not complete and what was left unsearched (one item a line)."""
    summary = time_limit_summary(result)
    if summary["time_limit_s"] is None:
        return
    stream = stream or sys.stdout
    seconds = max((t.get("stats", {}).get("wall_seconds", 0.0) for t in result.get("tight") or ()), default=0.0)
    if summary["complete"]:
        print(f"time limit {summary['time_limit_s']:g} s: the search was complete ({seconds:.0f} s)", file=stream)
        return
    print(f"time limit {summary['time_limit_s']:g} s: the search is NOT complete (stopped after {seconds:.0f} s); "
          "a \"no\" covers only the sequences searched. Not searched:", file=stream)
    for item in summary["unsearched"]:
        print(f"  - {item}", file=stream)
    print("  (run without --time-limit, or with a longer one, for the complete search)", file=stream)


def plan_options() -> list:
    """The option actions of the ``plan`` parser, in its order (the rerun commands
    that ``plan`` suggests after a plan that does not orient the part repeat them)."""
    sub = argparse.ArgumentParser().add_subparsers()
    add_plan_commands(sub)
    return [a for a in sub.choices["plan"]._actions if a.option_strings and a.dest != "help"]


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
        print_json(atlas)
        return
    print(f"feedability atlas of the config '{atlas['config']}' ({path}): tolerance "
          f"{atlas['tolerance_deg']:g} deg, depth {atlas['depth']}")
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


def add_sweep_plan_commands(sub) -> None:
    """``sweep`` (catalog shards of a config), ``plan`` (pin sequences) and ``atlas``."""
    add_sweep_commands(sub)
    add_plan_commands(sub)


def add_sweep_commands(sub) -> None:
    """``sweep``: the catalog shards of a config."""
    p = sub.add_parser("sweep", help="compute missing catalog shards of a config (locally or on dask)")
    add_config_option(p)
    p.add_argument("--catalog", default=None, help="catalog folder (default: the config's catalog_dir)")
    p.add_argument("--scheduler", default=None, help="dask.distributed scheduler address, e.g. tcp://host:8786")
    p.add_argument("--threads", type=int, default=None, help="Numba threads per shard")
    p.add_argument("--backend", choices=("cpu", "cuda"), default=None,
                   help="cpu or cuda (an NVIDIA GPU per worker; default: the config's "
                        "sweep.backend, else cpu)")
    p.add_argument("--quiet", action="store_true", help="no progress bar")
    p.set_defaults(func=cmd_sweep)


def add_plan_commands(sub) -> None:
    """``plan`` (pin sequences for a part) and ``atlas`` (the planned parts)."""
    p = sub.add_parser("plan", help="plan fixed pins for a part (computes missing maps)")
    add_part_options(p)
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
                   help="supports the plan must hold for: 'tripods:N[:inset=F][:seed=S]', "
                        "'warp:AMP[:N]', a support ('tripod', 'rim:N', 'points:x,y,w ...') or a list "
                        "'SPEC; SPEC'; 'uniform' for none (default: planner.support_family)")
    p.add_argument("--shape-tolerance", dest="shape_tolerance", type=float, default=None, metavar="MM",
                   help="certify the recommended fixed-pin plan for every part whose outline vertices lie "
                        "within MM of the drawing (a worst-member search and 300 fresh members); when it "
                        "does not hold, its certified radius (the largest tolerance that does); default: "
                        "the config's planner.shape_tolerance_mm")
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
    p.add_argument("--time-limit", dest="time_limit", type=float, default=None, metavar="S",
                   help="return within about S seconds (plus the step running then) with the best verified "
                        "answer so far, marked not complete, with what was left unsearched (default: the "
                        "config's planner.time_limit_s; none = the complete search); counted from after the kernels "
                        "are compiled, which the first run after an install does first")
    p.add_argument("--out", default=None, help="store the plan JSON here (default: RESULTS/plans/NAME.json, "
                   "where speed, layout and animate look; a part the workflow plans is stored only "
                   "with --out)")
    add_json_option(p, "print a summary of the plans as one JSON document instead of text (where the "
                    "plan is stored and the next steps go to stderr)")
    p.set_defaults(func=cmd_plan)

    p = sub.add_parser("atlas", help="the feedability atlas: which planned parts pins orient, with how "
                       "many pins, how precisely and how fast (RESULTS/atlas.json, made by the workflow)")
    add_config_option(p)
    p.add_argument("--results", default=None, help="results folder holding atlas.json "
                   "(default: the config's results_dir/NAME)")
    add_json_option(p, "print the atlas JSON")
    p.set_defaults(func=cmd_atlas)

