"""Time the planner on new parts: depth 4 over the default friction
range with pins fitted to each part, from an empty refinement store, on at
least eight parts of different shapes (the default triangles, a right and a
scalene triangle, a T bracket, an L bracket, a trapezoid, a slot-like hexagon
and a 20 mm and a 150 mm part).

    .venv/bin/python benchmarks/plan_speed.py [--depth 4] [--mu-c 0.1:0.3] [--tolerance 10]

Prints one line per part (wall seconds from an empty store, the recommended
plan, its verified width and trials in one set, what the search did) and the
median and worst time. Numbers quoted in the README come from this script.
"""
from __future__ import annotations

import argparse
import platform
import statistics
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

# The checkout this script lives in, not whichever pinfeed the environment
# has installed (an editable install of another worktree would win otherwise).
sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from pipeline.config import load_config  # noqa: E402
from pipeline.parts.part import Part  # noqa: E402
from pipeline.planning import PlannerSettings, plan_tight_all  # noqa: E402

PARTS = {
    "asym_triangle": [[0, 0], [60, 0], [15, 35]],
    "sym_triangle": [[0, 0], [40, 0], [20, 60]],
    "right_triangle": [[0, 0], [50, 0], [0, 30]],
    "scalene_triangle": [[0, 0], [70, 0], [20, 30]],
    "t_bracket": [[0, 0], [60, 0], [60, 10], [35, 10], [35, 40], [25, 40], [25, 10], [0, 10]],
    "l_bracket": [[0, 0], [60, 0], [60, 15], [15, 15], [15, 40], [0, 40]],
    "trapezoid": [[0, 0], [70, 0], [50, 25], [10, 25]],
    "hexagon_slot": [[0, 0], [50, 0], [60, 10], [50, 20], [0, 20], [-10, 10]],
    "small_20mm": (np.array([[0, 0], [60, 0], [15, 35]]) / 3.0).tolist(),
    "large_150mm": (np.array([[0, 0], [50, 0], [60, 30], [10, 25]]) * 2.5).tolist(),
}


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--depth", type=int, default=4)
    ap.add_argument("--mu-c", default="0.1:0.3")
    ap.add_argument("--tolerance", type=float, default=10.0)
    ap.add_argument("--parts", default=",".join(PARTS))
    args = ap.parse_args()
    config = load_config()
    pc = config["planner"]
    pc.update(mu_c=args.mu_c, frictions=[], depth=args.depth, pins="auto", tolerance_deg=args.tolerance)
    print(f"depth {args.depth}, mu_c {args.mu_c}, tolerance {args.tolerance:g} deg, fitted pins, "
          f"{platform.machine()}, empty refinement store per part")
    times = []
    for name in args.parts.split(","):
        part = Part.from_vertices(PARTS[name], name=name)
        with tempfile.TemporaryDirectory() as root:
            t0 = time.perf_counter()
            res = plan_tight_all(part, PlannerSettings.from_config(config), root)[0].to_dict()
            dt = time.perf_counter() - t0
        times.append(dt)
        rec = res["recommended"]
        search = res["fixed_pin_search"]
        if rec:
            o = rec["verification"]["orientation"]
            what = (f"{' '.join(rec['pins'])} ({len(res['pins_used'])} candidate pins): "
                    f"{'orients' if o['orients'] else 'does not orient'}, width {o['width_deg']} deg, "
                    f"{o['in_tolerance']}/{o['trials']} in one set")
        else:
            what = res["warning"]
        print(f"{name:<17} a {part.a:6.1f} mm  {dt:6.1f} s  {what}; levels "
              f"{[lv['sequences'] for lv in search['levels']]}", flush=True)
    print(f"median {statistics.median(times):.1f} s, worst {max(times):.1f} s over {len(times)} parts")


if __name__ == "__main__":
    main()
