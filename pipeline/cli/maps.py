"""``pinfeed rollout``, ``map``, ``plot-map`` and ``demo``: one part past one pin.

``rollout`` prints single passages (and their trajectories), ``map`` computes
one map set (dims ``d x theta_i``) into an HDF5 file, ``plot-map`` draws such a
file like the paper's Table 1, and ``demo`` does both for a default triangle.
"""
from __future__ import annotations

import math

from pipeline.cli.options import (add_json_option, add_physics, bands_option, parse_values, part_from_args,
                                  print_json)
from pipeline.errors import PinfeedError

PAPER_D = [-0.9, -0.8, -0.7, -0.6, -0.5, -0.4, -0.3, -0.2, -0.1,
           0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9]
DEFAULT_TRIANGLE = "0,0 60,0 15,35"


def _holes_note(part) -> str:
    """`` (2 holes)`` for a part with holes, else nothing."""
    n = len(part.holes)
    return f" ({n} hole{'s' if n > 1 else ''})" if n else ""


def cmd_rollout(args):
    """Roll a part past one pin (see :func:`pipeline.workflow.commands.rollout_rows`)."""
    from pipeline.workflow.commands import rollout_belt, rollout_rows
    part = part_from_args(args)
    belt = rollout_belt(part, args.model, args.belt_speed, args.mu_s)
    rows = rollout_rows(part, parse_values(args.theta_i, "--theta-i"), args.d, args.mu_c, args.pin_radius,
                        args.model, v_pin=args.v_pin, max_travel=args.max_travel,
                        trajectory=args.trajectory, belt=belt, support=args.support)
    if args.json:
        print_json(rows)
        return
    speed = f"  belt {args.belt_speed:g} mm/s  mu_s = {args.mu_s:g}" if belt else ""
    support = f"  support {args.support}" if args.support else ""
    print(f"part {part.id}{_holes_note(part)}  a = {part.a:.3f} mm  model {args.model}  mu_c = {args.mu_c:g}  "
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
    import numpy as np
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
    import numpy as np

    from pipeline.checks import MAP_SUFFIXES, MAX_MAP, check_grid_size, check_out_path
    from pipeline.maps import simulate
    from pipeline.maps.io import write_atomic
    from pipeline.provenance import provenance_attrs
    part = part_from_args(args)
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


def cmd_plot_map(args):
    """``pinfeed plot-map``: draw a stored map file to an image."""
    from pipeline.checks import IMAGE_SUFFIXES, check_out_path
    from pipeline.maps.io import read_map
    from pipeline.present.figures.maps import plot_map
    check_out_path(args.out, IMAGE_SUFFIXES)
    out = plot_map(read_map(args.map), args.out, bands=bands_option(args.bands))
    print(f"wrote {out}")


def cmd_demo(args):
    """The main job until the workflow lands: one map set of a default triangle."""
    from pathlib import Path

    import numpy as np

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



def add_map_commands(sub) -> None:
    """``rollout``, ``map`` and ``plot-map``: one passage, one map set, its drawing."""
    p = sub.add_parser("rollout", help="roll a part past one pin for some initial orientations")
    add_physics(p, belt=True)
    p.add_argument("--theta-i", required=True, help="initial orientations, degrees: 'a,b,c' or 'start:stop:step'")
    p.add_argument("--d", type=float, required=True, help="contact parameter (y_pin - y_com)/a")
    p.add_argument("--trajectory", action="store_true", help="also show the trajectory: a short table, or every sample and the "
                   "force history with --json")
    p.add_argument("--max-travel", type=float, default=None,
                   help="stop after this belt travel since first contact (mm): status truncated")
    add_json_option(p, "print JSON instead of a table")
    p.set_defaults(func=cmd_rollout)

    p = sub.add_parser("map", help="compute one map set (dims d, theta_i) into an HDF5 file")
    add_physics(p)
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



def add_demo_command(sub) -> None:
    """``demo``: one map set of a default triangle, computed and drawn."""
    p = sub.add_parser("demo", help="compute and plot one map set of a default triangle")
    p.add_argument("--out", default="results/demo", help="output folder")
    p.set_defaults(func=cmd_demo)

