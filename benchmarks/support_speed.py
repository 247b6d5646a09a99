"""Cost of a point-support rollout against a uniform one (at most twice).

The scalene triangle, theta_i every 2 degrees x the paper's 18 d values,
pin radius 3 mm, mu_c = 0.2 and 0.0, on one Numba thread; the rate is
counted in the process's CPU time (the machine may be shared), best of
``--repeat`` timings, compile time excluded. Supports: uniform, tripod,
four weighted points, rim with 16 and 64 points, and 64 points filling the
area. Prints a Markdown table for the README: rollouts per CPU second, the
cost relative to uniform, and the mean integration steps per rollout.

    .venv/bin/python benchmarks/support_speed.py [--repeat 3] [--step 2]
"""
import argparse
import datetime
import os
import platform
import sys
import time
from pathlib import Path

import numba
import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from pipeline.cli import PAPER_D  # noqa: E402
from pipeline.maps import simulate  # noqa: E402
from pipeline.parts.part import Part  # noqa: E402
from pipeline.parts.support import filled_support, point_support  # noqa: E402

TRIANGLE = [(0, 0), (60, 0), (15, 35)]
FOUR = ([[-12.0, -8.0], [15.0, -9.0], [-6.0, 12.0], [2.0, 0.0]], [1.0, 1.0, 1.0, 2.0])


def supports(part):
    """The supports timed: ``{label: support or None}``."""
    return {"uniform": None, "tripod": "tripod",
            "4 points": point_support(part, *FOUR, label="4 points"),
            "rim:16": "rim:16", "rim:64": "rim:64", "filled:8 (64 points)": filled_support(part, 8)}


def rate(part, support, mu_c, theta, repeat):
    """``(rollouts per CPU second, mean feature changes)`` of the map, best of ``repeat``."""
    simulate.compute_map(part, theta[:3], PAPER_D[:2], mu_c, 3.0, threads=1, support=support)
    best = np.inf
    for _ in range(repeat):
        c0 = time.process_time()
        ds = simulate.compute_map(part, theta, PAPER_D, mu_c, 3.0, threads=1, support=support)
        best = min(best, time.process_time() - c0)
    return theta.size * len(PAPER_D) / best, float(ds.feature_changes.mean())


def main():
    """Time every support at both frictions and print the table."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=3, help="best of N timings")
    ap.add_argument("--step", type=float, default=2.0, help="theta_i step, degrees")
    args = ap.parse_args()
    part = Part.from_vertices(TRIANGLE, name="scalene")
    theta = np.arange(0.0, 360.0, args.step)
    print(f"{datetime.date.today()} | {platform.node()} | {platform.machine()} | "
          f"{os.cpu_count()} cores | numba {numba.__version__} | 1 thread, CPU time\n")
    print("| mu_c | support | rollouts / CPU s | cost vs uniform | mean feature changes |")
    print("|---|---|---|---|---|")
    for mu_c in (0.2, 0.0):
        base = None
        for label, sup in supports(part).items():
            r, changes = rate(part, sup, mu_c, theta, args.repeat)
            base = base or r
            print(f"| {mu_c:g} | {label} | {r:,.0f} | {base / r:.2f} | {changes:.2f} |",
                  flush=True)
    print(f"\nload average at the end: {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores")


if __name__ == "__main__":
    main()
