"""The ``pinfeed`` command line: thin over ``pipeline`` modules.

Every error a user can cause prints one line ``pinfeed: error: ...`` on
stderr and exits with status 2; nothing already stored is touched.
"""
from __future__ import annotations

import argparse
import json
import math
import sys

import numpy as np

from .errors import PinfeedError

PAPER_D = [-0.9, -0.8, -0.7, -0.6, -0.5, -0.4, -0.3, -0.2, -0.1,
           0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9]
DEFAULT_TRIANGLE = "0,0 60,0 15,35"


def parse_values(text: str, what: str) -> np.ndarray:
    """``"a,b,c"`` or an inclusive range ``"start:stop:step"``."""
    try:
        if ":" in text:
            start, stop, step = (float(x) for x in text.split(":"))
            if step <= 0 or stop < start:
                raise ValueError
            n = int(math.floor((stop - start) / step + 1e-9)) + 1
            return np.round(start + step * np.arange(n), 10) + 0.0
        return np.array([float(x) for x in text.split(",") if x.strip()])
    except ValueError:
        raise PinfeedError(f"{what} {text!r} is not a list 'a,b,c' or a range 'start:stop:step' "
                           f"with step > 0") from None


def _part_from_args(args):
    from .parts import Part, parse_vertices
    return Part.from_vertices(parse_vertices(args.vertices), name=args.name)


def _add_physics(p, d_required=True):
    p.add_argument("--vertices", required=True, help='part outline "x0,y0 x1,y1 ..." (mm)')
    p.add_argument("--name", default="part", help="part name used in outputs")
    p.add_argument("--mu-c", type=float, required=True, help="pin-part friction coefficient (>= 0)")
    p.add_argument("--pin-radius", type=float, required=True, help="pin radius (mm, > 0)")
    p.add_argument("--model", default="minpower", choices=["minpower", "tip", "ellipsoid"],
                   help="contact model (default minpower)")
    p.add_argument("--v-pin", type=float, default=0.0,
                   help="pin speed across the belt / belt speed (default 0: static pin)")


def cmd_rollout(args):
    from . import simulate
    part = _part_from_args(args)
    rows = []
    for theta in parse_values(args.theta_i, "--theta-i"):
        ds = simulate.rollout(part, theta, args.d, args.mu_c, args.pin_radius, model=args.model,
                              v_pin=args.v_pin, max_travel=args.max_travel,
                              trajectory=args.trajectory)
        row = {"theta_i": float(theta), "status": str(ds.status.item()),
               "theta_f": float(ds.theta_f), "dy": float(ds.dy),
               "contact_travel": float(ds.contact_travel),
               "feature_changes": int(ds.feature_changes), "peak_force": float(ds.peak_force),
               "jam_reason": str(ds.jam_reason.item())}
        if args.trajectory:
            row["trajectory"] = np.column_stack([ds.traj_s, ds.traj_x, ds.traj_y,
                                                 ds.traj_theta]).tolist()
            row["force"] = np.column_stack([ds.force_s, ds.force_x, ds.force_y]).tolist()
        rows.append(row)
    if args.json:
        json.dump(rows, sys.stdout)
        sys.stdout.write("\n")
        return
    print(f"part {part.id}  a = {part.a:.3f} mm  model {args.model}  mu_c = {args.mu_c:g}  "
          f"pin radius {args.pin_radius:g} mm  d = {args.d:+g}")
    print(f"{'theta_i':>8} {'status':>9} {'theta_f':>9} {'dy (mm)':>9} {'travel':>8} "
          f"{'changes':>7} {'peak F':>7}")
    for r in rows:
        note = f"  ({r['jam_reason']})" if r["status"] == "jammed" else ""
        print(f"{r['theta_i']:8.2f} {r['status']:>9} {r['theta_f']:9.3f} {r['dy']:9.3f} "
              f"{r['contact_travel']:8.2f} {r['feature_changes']:7d} {r['peak_force']:7.3f}{note}")


def cmd_map(args):
    from . import simulate
    from .io import write_atomic
    from .provenance import provenance_attrs
    part = _part_from_args(args)
    d = parse_values(args.d, "--d")
    if not args.theta_step > 0 or args.theta_step > 360:
        raise PinfeedError(f"--theta-step must be in (0, 360] degrees, got {args.theta_step}")
    theta = np.arange(0.0, 360.0 - 1e-9, args.theta_step)
    ds = simulate.map(part, theta, d, args.mu_c, args.pin_radius, model=args.model,
                      v_pin=args.v_pin, threads=args.threads)
    ds.attrs.update(provenance_attrs())
    write_atomic(ds, args.out)
    counts = {name: int((ds.status.values == k).sum()) for k, name in enumerate(simulate.STATUSES)}
    print(f"wrote {args.out}: {d.size} d x {theta.size} theta_i, "
          + ", ".join(f"{v} {k}" for k, v in counts.items() if v))


def cmd_plot_map(args):
    from .figures.maps import plot_map
    from .io import read_map
    out = plot_map(read_map(args.map), args.out)
    print(f"wrote {out}")


def cmd_demo(args):
    """The main job until the workflow lands: one map set of a default triangle."""
    from pathlib import Path

    from . import simulate
    from .figures.maps import plot_map
    from .io import write_atomic
    from .parts import Part, parse_vertices
    from .provenance import provenance_attrs
    part = Part.from_vertices(parse_vertices(DEFAULT_TRIANGLE), name="triangle")
    theta = np.arange(0.0, 360.0, 1.0)
    print(f"computing {len(PAPER_D)} x {theta.size} minpower rollouts of {part.id} ...", flush=True)
    ds = simulate.map(part, theta, PAPER_D, 0.2, 3.0)
    ds.attrs.update(provenance_attrs())
    out = Path(args.out)
    write_atomic(ds, out / "map.h5")
    plot_map(ds, out / "map.png")
    print(f"wrote {out / 'map.h5'} and {out / 'map.png'}")


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="pinfeed", description=__doc__.splitlines()[0])
    sub = parser.add_subparsers(dest="command", required=True)

    p = sub.add_parser("rollout", help="roll a part past one pin for some initial orientations")
    _add_physics(p)
    p.add_argument("--theta-i", required=True, help="initial orientations, degrees: 'a,b,c' or 'start:stop:step'")
    p.add_argument("--d", type=float, required=True, help="contact parameter (y_pin - y_com)/a")
    p.add_argument("--trajectory", action="store_true", help="include trajectory and force history")
    p.add_argument("--max-travel", type=float, default=None,
                   help="stop after this belt travel since first contact (mm): status truncated")
    p.add_argument("--json", action="store_true", help="print JSON instead of a table")
    p.set_defaults(func=cmd_rollout)

    p = sub.add_parser("map", help="compute one map set (dims d, theta_i) into an HDF5 file")
    _add_physics(p)
    p.add_argument("--d", required=True, help="contact parameters: 'a,b,c' or inclusive 'start:stop:step'")
    p.add_argument("--theta-step", type=float, default=1.0, help="theta_i step, degrees (default 1)")
    p.add_argument("--threads", type=int, default=None, help="Numba threads (default: all cores)")
    p.add_argument("--out", required=True, help="output file (.h5)")
    p.set_defaults(func=cmd_map)

    p = sub.add_parser("plot-map", help="draw a map file like the paper's Table 1")
    p.add_argument("map", help="map file written by 'pinfeed map'")
    p.add_argument("--out", required=True, help="image file (.png, .pdf, .svg)")
    p.set_defaults(func=cmd_plot_map)

    p = sub.add_parser("demo", help="compute and plot one map set of a default triangle")
    p.add_argument("--out", default="results/demo", help="output folder")
    p.set_defaults(func=cmd_demo)
    return parser


def main(argv=None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        args.func(args)
    except PinfeedError as exc:
        print(f"pinfeed: error: {exc}", file=sys.stderr)
        return 2
    except BrokenPipeError:  # e.g. piped into head
        return 0
    return 0


if __name__ == "__main__":
    sys.exit(main())
