"""Rollouts per second per model for a scalene triangle (issue: kernels).

Grid: theta_i every 1 degree x the paper's 18 d values, mu_c = 0.2 and 0.0,
pin radius 3 mm, on 1 thread and on all cores (``--threads``). Compile time
is excluded (one warm-up call). Prints a Markdown table for the README,
including the cost ratio minpower / ellipsoid and the parallel efficiency
measured in this same run. Rates are given by wall time and by the process's
CPU time: on a shared machine the wall-time rate of N threads is only
meaningful next to the load average (printed at the end). ``--backend cuda`` adds the GPU rate (needs
``pip install '.[cuda]'`` and an NVIDIA GPU; a larger grid, ``--gpu-scale``
times more theta_i, keeps the device busy).

    .venv/bin/python benchmarks/rollout_speed.py [--repeat 3] [--threads N] [--backend cuda]
"""
import argparse
import datetime
import os
import platform
import time

import sys
from pathlib import Path

import numba
import numpy as np

# The checkout this script lives in, not whichever pinfeed the environment
# has installed (an editable install of another worktree would win otherwise).
sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from pipeline.cli import PAPER_D  # noqa: E402
from pipeline.maps import simulate  # noqa: E402
from pipeline.parts.part import Part  # noqa: E402

TRIANGLE = [(0, 0), (60, 0), (15, 35)]


def rate(part, model, mu_c, threads, repeat, backend="cpu", scale=1):
    """Rollouts per second: ``(by wall time, by the process's CPU time)``,
    each the best of ``repeat`` timings."""
    theta = np.arange(0.0, 360.0, 1.0 / scale)
    simulate.compute_map(part, theta[:4], PAPER_D[:2], mu_c, 3.0, model=model, threads=threads,
                         backend=backend)
    wall = cpu = np.inf
    for _ in range(repeat):
        t0, c0 = time.perf_counter(), time.process_time()
        simulate.compute_map(part, theta, PAPER_D, mu_c, 3.0, model=model, threads=threads,
                             backend=backend)
        wall = min(wall, time.perf_counter() - t0)
        cpu = min(cpu, time.process_time() - c0)
    n = theta.size * len(PAPER_D)
    return n / wall, n / cpu


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=3, help="best of N timings")
    ap.add_argument("--threads", type=int, default=numba.config.NUMBA_NUM_THREADS,
                    help="the 'all cores' column (default: every Numba thread)")
    ap.add_argument("--backend", choices=("cpu", "cuda"), default="cpu",
                    help="cuda: also time the GPU backend")
    ap.add_argument("--gpu-scale", type=int, default=100,
                    help="GPU grid: this many times more theta_i (default 100)")
    args = ap.parse_args()
    nt = args.threads
    import kernels
    print(f"kernels from {Path(kernels.__file__).parent}")
    part = Part.from_vertices(TRIANGLE, name="scalene")
    cpu = platform.processor() or platform.machine()
    print(f"{datetime.date.today()} | {platform.node()} | {cpu} | {os.cpu_count()} cores | "
          f"numba {numba.__version__} | numba threads available {numba.config.NUMBA_NUM_THREADS}\n")
    gpu = args.backend == "cuda"
    print(f"| mu_c | model | 1 thread (rollouts/s, wall / CPU time) | {nt} threads (wall) | "
          f"{nt} threads (per CPU second) | parallel efficiency (wall) | "
          f"cost vs ellipsoid (1 thread, CPU time) |" + (" GPU (rollouts/s) |" if gpu else ""))
    print("|---|---|---|---|---|---|---|" + ("---|" if gpu else ""))
    for mu_c in (0.2, 0.0):
        rates = {m: [rate(part, m, mu_c, t, args.repeat) for t in (1, nt)]
                 for m in ("ellipsoid", "tip", "minpower")}
        for m, ((w1, c1), (wn, cn)) in rates.items():
            row = (f"| {mu_c:g} | {m} | {w1:,.0f} / {c1:,.0f} | {wn:,.0f} | {cn:,.0f} | "
                   f"{wn / (nt * w1):.0%} | {rates['ellipsoid'][0][1] / c1:.2f} |")
            if gpu:
                row += f" {rate(part, m, mu_c, None, args.repeat, 'cuda', args.gpu_scale)[0]:,.0f} |"
            print(row, flush=True)
    print(f"\nload average at the end: {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores")


if __name__ == "__main__":
    main()
