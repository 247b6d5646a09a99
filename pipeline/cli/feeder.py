"""``pinfeed speed``, ``layout`` and ``animate``: what a stored plan does on a real belt.

All three read the plan ``pinfeed plan`` (or the workflow) stored at
``RESULTS/plans/NAME.json``: ``speed`` finds the belt speed up to which the
plan still orients, ``layout`` places the pin stations of a feeder to build
(and draws it), ``animate`` shows every initial state passing the pins.
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

from pipeline.cli.options import (add_config_option, add_json_option, add_results_option, print_json,
                                  results_arg)


def cmd_speed(args):
    """A plan's success rate against belt speed and its speed limit (dynamic model)."""
    from pipeline.config import load_config
    from pipeline.planning import speed_label
    from pipeline.workflow.commands import speed_command, stored_plan
    config = load_config(args.config)
    result, _ = stored_plan(config, results_arg(args, config), args.part, args.config)
    out, stored = speed_command(result, config, args.plan, args.mu_c, args.mu_s, args.trials)
    if args.json:
        print_json(out, default=float)
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
    from pipeline.planning import LayoutSettings, PlannerSettings, layout_stored
    from pipeline.present.layout import check_drawing_path, write_drawing
    from pipeline.workflow.commands import layout_settings, stored_plan
    config = load_config(args.config)
    as_json = args.out is not None and Path(args.out).suffix.lower() == ".json"
    if args.out:  # before minutes of trials
        check_out_path(args.out, (".json",)) if as_json else check_drawing_path(args.out)
    settings = layout_settings(args.margin, args.trials)
    result, _ = stored_plan(config, results_arg(args, config), args.part, args.config)
    out = layout_stored(result, PlannerSettings.from_config(config), args.plan, args.mu_c,
                        belt_speed=args.belt_speed, mu_s=args.mu_s, quasi_static=args.quasi_static,
                        settings=LayoutSettings.from_section({**config.get("layout", {}), **settings}))
    for warning in out["warnings"]:
        print(f"pinfeed: warning: {warning}", file=sys.stderr)
    if as_json:
        from pipeline.maps.io import write_json
        write_json(out, args.out)
    elif args.out:
        write_drawing(out, args.out)
    if args.json:
        print_json(out, default=float)
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
    from pipeline.workflow.commands import animate_stored, animation_inputs, stored_plan
    config = load_config(args.config)
    result, path = stored_plan(config, results_arg(args, config), args.part, args.config)
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


def add_stored_plan_commands(sub) -> None:
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
    add_config_option(p)
    add_results_option(p)
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
    add_config_option(p)
    add_results_option(p)
    add_json_option(p, "print JSON instead of text")
    p.set_defaults(func=cmd_speed)


def add_layout_commands(sub) -> None:
    """``layout``: a feeder to build (stations, pitch, belt width, throughput, a drawing)."""
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
    add_config_option(p)
    add_results_option(p)
    add_json_option(p, "print JSON instead of text")
    p.set_defaults(func=cmd_layout)
