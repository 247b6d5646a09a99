"""Compare the working tree's rollout kernels with those of a git revision,
in one process: speed (CPU time, one thread) and answers (theta_f, status).

The reference kernels are read with ``git show REF:kernels/*.py`` into a
package ``kernels_ref`` in a folder of the temp
directory named after the commit (kept, for Numba's cache), and imported beside ``kernels``, so both
run in the same process under the same load; only ratios measured in one
run mean anything on a shared machine.

Speed: the benchmark triangle (``0,0 60,0 15,35`` mm, pin radius 3 mm),
theta_i every 1 degree x the paper's 18 d values, one Numba thread, best of
``--repeat`` rounds (each times every kernel
once, in turn) of the process's CPU time, models minpower and
ellipsoid, mu_c 0.2 and 0 (``--speed``).

Answers: the triangle, an irregular quad and a non-convex V-notch block,
mu_c 0, 0.2 and 0.5, all three models, theta_i every 1 degree (offset
0.37 degree) x the paper's d values; prints max |delta theta_f| over the
rollouts that are 'ok' in both, the same for each against a fine
reference (ds_max 0.05, tol 1e-7 / 32), and the status changes
(``--accuracy``).

    .venv/bin/python benchmarks/compare_kernels.py --ref HEAD [--speed] [--accuracy]
"""
import argparse
import importlib
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numba
import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

import kernels.batch  # noqa: E402
import kernels.rollout  # noqa: E402
from pipeline.cli import PAPER_D  # noqa: E402

TRIANGLE = [(0.0, 0.0), (60.0, 0.0), (15.0, 35.0)]
QUAD = [(0.0, 0.0), (50.0, 0.0), (60.0, 30.0), (10.0, 25.0)]
V_NOTCH = [(0.0, 0.0), (60.0, 0.0), (40.0, 15.0), (60.0, 30.0), (0.0, 30.0)]
PARTS = {"triangle": TRIANGLE, "quad": QUAD, "v-notch": V_NOTCH}
MODELS = {"minpower": 0, "tip": 1, "ellipsoid": 2}
R_PIN = 3.0


def load_ref(ref):
    """Import the kernels of git revision ``ref`` as the package ``kernels_ref``."""
    sha = subprocess.run(["git", "rev-parse", ref], cwd=ROOT, check=True, capture_output=True,
                         text=True).stdout.strip()
    # A folder per commit, kept, so Numba's cache of the reference survives.
    tmp = Path(tempfile.gettempdir()) / f"pinfeed_kernels_ref_{sha[:12]}"
    pkg = tmp / "kernels_ref"
    pkg.mkdir(parents=True, exist_ok=True)
    names = subprocess.run(["git", "ls-tree", "--name-only", f"{ref}:kernels"], cwd=ROOT,
                           check=True, capture_output=True, text=True).stdout.split()
    for name in names:
        if name.endswith(".py"):
            src = subprocess.run(["git", "show", f"{ref}:kernels/{name}"], cwd=ROOT, check=True,
                                 capture_output=True, text=True).stdout
            (pkg / name).write_text(src)
    sys.path.insert(0, str(tmp))
    batch = importlib.import_module("kernels_ref.batch")
    rollout = importlib.import_module("kernels_ref.rollout")
    return tmp, batch, rollout


def grid(batch, rollout, outline, model, mu_c, theta_deg, d, ds_max=0.1, tol=1e-7):
    prep = rollout._prepare(np.ascontiguousarray(outline, dtype=np.float64))
    return batch._rollout_grid(*prep, model, float(mu_c), R_PIN, np.radians(theta_deg),
                               np.asarray(d, dtype=np.float64), 0.0, np.inf, ds_max, tol, 1)


def circ_deg(a, b):
    """Circular difference of two angles in radians, in degrees."""
    return np.degrees(np.angle(np.exp(1j * (a - b))))


def cpu_time(batch, rollout, model, mu_c):
    theta = np.arange(0.0, 360.0, 1.0)
    t0 = time.process_time()
    grid(batch, rollout, TRIANGLE, model, mu_c, theta, PAPER_D)
    return time.process_time() - t0


def speed(kits, repeat, mus):
    """Best of ``repeat`` rounds; each round times every (kit, model) once in
    turn, so a change of the machine's load hits all of them alike."""
    n = 360 * len(PAPER_D)
    print("| mu_c | model | " + " | ".join(f"{k} (rollouts/s)" for k in kits)
          + " | " + " | ".join(f"minpower/ellipsoid {k}" for k in kits) + " |")
    print("|---|---|" + "---|" * (2 * len(kits)))
    for mu_c in mus:
        best = {}
        for k, (b, r) in kits.items():
            for m in ("minpower", "ellipsoid"):
                grid(b, r, TRIANGLE, MODELS[m], mu_c, np.zeros(4), PAPER_D[:2])  # compile
                best[k, m] = np.inf
        for _ in range(repeat):
            for k, (b, r) in kits.items():
                for m in ("minpower", "ellipsoid"):
                    best[k, m] = min(best[k, m], cpu_time(b, r, MODELS[m], mu_c))
        for m in ("minpower", "ellipsoid"):
            ratios = " | ".join(f"{best[k, 'minpower'] / best[k, 'ellipsoid']:.2f}"
                                if m == "minpower" else "" for k in kits)
            print(f"| {mu_c:g} | {m} | " + " | ".join(f"{n / best[k, m]:,.0f}" for k in kits)
                  + f" | {ratios} |", flush=True)


def accuracy(kits, models=tuple(MODELS)):
    """Both kernels at the default settings, and a fine reference (the
    worktree kernel at ds_max 0.05, tol 1e-7 / 32, the settings of the
    step-halving test): max |delta theta_f| between the two, and of each
    from the reference, over rollouts 'ok' in all three."""
    (k0, (b0, r0)), (k1, (b1, r1)) = list(kits.items())
    theta = np.arange(0.0, 360.0, 1.0) + 0.37
    worst = np.zeros(3)
    print(f"| part | model | mu_c | max abs delta theta_f {k0} vs {k1} (deg) | {k0} vs fine | "
          f"{k1} vs fine | status changes |")
    print("|---|---|---|---|---|---|---|")
    for pname, outline in PARTS.items():
        for mname in models:
            model = MODELS[mname]
            for mu_c in (0.0, 0.2, 0.5):
                a = grid(b0, r0, outline, model, mu_c, theta, PAPER_D)
                b = grid(b1, r1, outline, model, mu_c, theta, PAPER_D)
                f = grid(b1, r1, outline, model, mu_c, theta, PAPER_D, 0.05, 1e-7 / 32)
                ok = (a[0] == 0) & (b[0] == 0) & (f[0] == 0)
                d = [float(np.max(np.abs(circ_deg(x[2], y[2])[ok]))) if ok.any() else 0.0
                     for x, y in ((a, b), (a, f), (b, f))]
                worst = np.maximum(worst, d)
                changed = np.argwhere(a[0] != b[0])
                where = ", ".join(f"d={PAPER_D[i]:g} th={theta[j]:.2f}: {a[0][i, j]}->"
                                  f"{b[0][i, j]} (fine {f[0][i, j]})" for i, j in changed[:4])
                print(f"| {pname} | {mname} | {mu_c:g} | {d[0]:.2e} | {d[1]:.2e} | {d[2]:.2e} | "
                      f"{len(changed)}" + (f" ({where})" if where else "") + " |", flush=True)
    print(f"\nworst over all grids: {k0} vs {k1} {worst[0]:.2e} deg, {k0} vs fine "
          f"{worst[1]:.2e}, {k1} vs fine {worst[2]:.2e}")


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--ref", default="HEAD", help="git revision of the reference kernels")
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--speed", action="store_true")
    ap.add_argument("--accuracy", action="store_true")
    ap.add_argument("--mu", type=float, nargs="+", default=[0.2, 0.0], help="speed: mu_c values")
    ap.add_argument("--models", nargs="+", choices=tuple(MODELS), default=list(MODELS),
                    help="accuracy: the models to compare")
    args = ap.parse_args()
    numba.set_num_threads(1)
    _, rb, rr = load_ref(args.ref)
    kits = {args.ref: (rb, rr), "worktree": (kernels.batch, kernels.rollout)}
    if args.speed or not args.accuracy:
        speed(kits, args.repeat, args.mu)
        print()
    if args.accuracy:
        accuracy(kits, args.models)


if __name__ == "__main__":
    main()
