"""``pinfeed support fit``: the point support that explains measured pushes.

A support is where the part presses on the belt. ``support fit`` searches the
point layouts (weights by statics) whose rollouts best reproduce measured
final orientations, prints them as a ``--support`` value, and compares their
residuals with uniform pressure.
"""
from __future__ import annotations

import argparse

from pipeline.cli.options import (add_config_option, add_json_option, add_outline_args, plan_part_arg,
                                  print_json)


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
    part = plan_part_arg(args, config)
    pushes = read_pushes(args.pushes)
    if args.family:
        _fit_family(args, part, pushes)
        return
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
        print_json(result)
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


def _fit_family(args, part, pushes) -> None:
    """``support fit --family``: the supports consistent with the pushes within their noise."""
    from pipeline.maps.support_fit import fit_support_family
    fam = fit_support_family(part, pushes, args.mu_c, args.pin_radius, noise_deg=args.noise_deg,
                             n_points=args.points, starts=args.starts, refine=args.refine, seed=args.seed)
    result = {"part": part.name, "part_id": part.id, **fam.to_dict()}
    if args.out:
        from pipeline.maps.io import write_json
        from pipeline.provenance import provenance_attrs
        write_json({**result, **provenance_attrs()}, args.out)
    if args.json:
        print_json(result)
        return
    print(fam.line())
    if args.out:
        print(f"stored at {args.out}")


def add_support_commands(sub) -> None:
    """``support fit``: a point support from measured pushes."""
    sup = sub.add_parser("support", help="support distributions: fit one to measured pushes")
    ssub = sup.add_subparsers(dest="support_command", required=True)
    q = ssub.add_parser("fit", help="the point support (weights by statics) whose rollouts best explain "
                        "measured pushes", epilog=PUSHES_FORMAT,
                        formatter_class=argparse.RawDescriptionHelpFormatter)
    q.add_argument("--part", default=None, help="part name or id from the config or catalog")
    add_outline_args(q, required=False)
    add_config_option(q)
    q.add_argument("--pushes", required=True, metavar="FILE.csv", help="measured pushes (format below)")
    q.add_argument("--mu-c", dest="mu_c", type=float, default=None,
                   help="pin-part friction of pushes without a mu_c column")
    q.add_argument("--pin-radius", dest="pin_radius", type=float, default=3.0, help="pin radius, mm (default 3)")
    q.add_argument("--points", type=int, default=3, help="support points to fit, 3 to 12 (default 3)")
    q.add_argument("--starts", type=int, default=48, help="random layouts tried before refining (default 48)")
    q.add_argument("--refine", type=int, default=8, help="best layouts refined by least squares (default 8)")
    q.add_argument("--seed", type=int, default=0, help="seed of the random layouts (default 0)")
    q.add_argument("--family", action="store_true",
                   help="return every support consistent with the pushes within their noise, as a "
                        "--support-family text (default: the one best support)")
    q.add_argument("--noise-deg", dest="noise_deg", type=float, default=None,
                   help="with --family: the pushes' measurement noise, deg (default: estimated from the best fit)")
    q.add_argument("--out", default=None, help="store the fit as JSON (with its settings and provenance)")
    add_json_option(q, "print JSON instead of text")
    q.set_defaults(func=cmd_support_fit)

