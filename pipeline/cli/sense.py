"""``pinfeed sense classify``: which initial state a measured force profile comes from.

The profile (a CSV of time, F_x, F_y) is scored against the simulated profile
of every initial state at the sensor pin (the paper's sign matrix); with a
stored sensor plan the verdict also names the final orientation.
"""
from __future__ import annotations

import argparse

from pipeline.cli.options import (add_config_option, add_json_option, add_results_option, print_json,
                                  results_arg)


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
    result, context = classify_measured(config, args.part, args.profile, results_arg(args, config),
                                        catalog=args.catalog, y_pin=args.y_pin)
    if args.json:
        print_json(result)
        return
    _print_classification(result, context, args.profile)


def _print_classification(result: dict, context: dict, profile):
    """A measured profile's verdict and final orientation, for people."""
    from pipeline.planning import format_arcs
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


def add_sense_commands(sub) -> None:
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
    add_config_option(q)
    q.add_argument("--catalog", default=None, help="catalog folder (default: the config's)")
    add_results_option(q, "plans/ and sensing/")
    add_json_option(q, "print JSON instead of text")
    q.set_defaults(func=cmd_sense_classify)

