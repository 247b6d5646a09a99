"""Rollouts per second per model for a scalene triangle (issue: kernels).

Grid: theta_i every 1 degree x the paper's 18 d values, mu_c = 0.2 and 0.0,
pin radius 3 mm, on 1 and 2 Numba threads. Compile time is excluded (one
warm-up call). Prints a Markdown table for the README, including the cost
ratio minpower / ellipsoid measured in this same run.

    .venv/bin/python benchmarks/rollout_speed.py [--repeat 3]
"""
import argparse
import datetime
import os
import platform
import time

import numba
import numpy as np

from pipeline import simulate
from pipeline.cli import PAPER_D
from pipeline.parts import Part

TRIANGLE = [(0, 0), (60, 0), (15, 35)]


def rate(part, model, mu_c, threads, repeat):
    theta = np.arange(0.0, 360.0, 1.0)
    simulate.map(part, theta[:4], PAPER_D[:2], mu_c, 3.0, model=model, threads=threads)
    best = np.inf
    for _ in range(repeat):
        t0 = time.perf_counter()
        simulate.map(part, theta, PAPER_D, mu_c, 3.0, model=model, threads=threads)
        best = min(best, time.perf_counter() - t0)
    return theta.size * len(PAPER_D) / best


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=3, help="best of N timings")
    args = ap.parse_args()
    part = Part.from_vertices(TRIANGLE, name="scalene")
    cpu = platform.processor() or platform.machine()
    print(f"{datetime.date.today()} | {platform.node()} | {cpu} | {os.cpu_count()} cores | "
          f"numba {numba.__version__} | numba threads available {numba.config.NUMBA_NUM_THREADS}\n")
    print("| mu_c | model | 1 thread (rollouts/s) | 2 threads (rollouts/s) | cost vs ellipsoid (1 thread) |")
    print("|---|---|---|---|---|")
    for mu_c in (0.2, 0.0):
        rates = {m: [rate(part, m, mu_c, t, args.repeat) for t in (1, 2)]
                 for m in ("ellipsoid", "tip", "minpower")}
        for m, (r1, r2) in rates.items():
            print(f"| {mu_c:g} | {m} | {r1:,.0f} | {r2:,.0f} | {rates['ellipsoid'][0] / r1:.1f} |")


if __name__ == "__main__":
    main()
