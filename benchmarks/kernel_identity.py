"""Bit-identity check for edits of the rollout kernels that must not change
any result (refactors): run a fixed set of rollouts and save, or compare
exactly (``np.array_equal``, no tolerance), every output.

The set: four parts (a scalene and an isosceles triangle, a seeded random
convex hexagon, the non-convex V-notch block), all three models, mu_c 0,
0.2 and 0.6, pin radii 3 and 12 mm, a static pin and (for every other
combination) a moving one, theta_i x d on a 12 x 6 grid: 5,184 rollouts
through ``rollout._rollout_budget`` (status, jam reason, theta_f, y shift,
contact travel, feature changes, peak force and the number of steps used),
the same grids through the parallel ``batch._rollout_grid`` and through
``points._rollout_points``, and the recorded trajectory and force history of
one rollout in eight.

    .venv/bin/python benchmarks/kernel_identity.py --save /tmp/before.npz
    # ... edit kernels/ ...
    .venv/bin/python benchmarks/kernel_identity.py --compare /tmp/before.npz
"""
import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from kernels.batch import _rollout_grid  # noqa: E402
from kernels.points import _rollout_points  # noqa: E402
from kernels.rollout import _prepare, _rollout_budget, max_steps_for  # noqa: E402


def _random_convex(seed=7, n=6):
    rng = np.random.default_rng(seed)
    ang = np.sort(rng.uniform(0.0, 2.0 * np.pi, n))
    rad = rng.uniform(20.0, 40.0, n)
    return np.column_stack([rad * np.cos(ang), rad * np.sin(ang)])


PARTS = {
    "scalene": np.array([(0.0, 0.0), (60.0, 0.0), (15.0, 35.0)]),
    "isosceles": np.array([(0.0, 0.0), (60.0, 0.0), (30.0, 40.0)]),
    "convex6": _random_convex(),
    "v-notch": np.array([(0.0, 0.0), (60.0, 0.0), (40.0, 15.0), (60.0, 30.0), (0.0, 30.0)]),
}
MODELS = (0, 1, 2)  # minpower, tip, ellipsoid
MUS = (0.0, 0.2, 0.6)
R_PINS = (3.0, 12.0)
THETA = np.radians(np.arange(0.0, 360.0, 30.0) + 0.37)
D = np.array([-1.4, -0.7, -0.2, 0.15, 0.55, 0.95])


def run():
    out = {}
    combo = 0
    for pname, xy in PARTS.items():
        prep = _prepare(np.ascontiguousarray(xy, dtype=np.float64))
        budget = max_steps_for(len(xy))
        for model in MODELS:
            for mu in MUS:
                for r_pin in R_PINS:
                    v_pin = 0.4 if combo % 2 else 0.0
                    combo += 1
                    key = f"{pname}_m{model}_mu{mu:g}_r{r_pin:g}_v{v_pin:g}"
                    rows = []
                    k = 0
                    for d in D:
                        for th in THETA:
                            record = k % 8 == 0
                            res = _rollout_budget(*prep, model, mu, r_pin, th, d, v_pin, np.inf,
                                                  0.1, 1e-7, record, budget)
                            rows.append((res[0], res[1], res[2], res[3], res[4], res[5],
                                         res[6], res[9]))
                            if record:
                                out[f"{key}_traj{k}"] = res[7]
                                out[f"{key}_force{k}"] = res[8]
                            k += 1
                    out[f"{key}_single"] = np.array(rows, dtype=np.float64)
                    grid = _rollout_grid(*prep, model, mu, r_pin, THETA, D, v_pin, np.inf, 0.1,
                                         1e-7, 4)
                    for i, arr in enumerate(grid):
                        out[f"{key}_grid{i}"] = arr
                    tt, dd = np.meshgrid(THETA, D)
                    pts = _rollout_points(*prep, model, np.full(tt.size, mu), r_pin,
                                          tt.ravel(), dd.ravel(), v_pin, np.inf, 0.1, 1e-7, 2)
                    for i, arr in enumerate(pts):
                        out[f"{key}_points{i}"] = arr
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    g = ap.add_mutually_exclusive_group(required=True)
    g.add_argument("--save", help="write the results to this .npz")
    g.add_argument("--compare", help="compare exactly with this .npz")
    args = ap.parse_args()
    t0 = time.perf_counter()
    out = run()
    n = sum(v.shape[0] for k, v in out.items() if k.endswith("_single"))
    print(f"{n} rollouts (x3 entry points) in {time.perf_counter() - t0:.1f} s")
    if args.save:
        np.savez(args.save, **out)
        print(f"saved {len(out)} arrays to {args.save}")
        return 0
    ref = np.load(args.compare)
    bad = sorted(set(ref.files) ^ set(out))
    bad += [k for k in ref.files if k in out and not np.array_equal(ref[k], out[k])]
    single = np.concatenate([out[k] for k in sorted(out) if k.endswith("_single")])
    status = single[:, 0].astype(int)
    print("statuses (ok, miss, jammed, truncated):", np.bincount(status, minlength=4).tolist(),
          "| steps: mean", f"{single[:, 7].mean():.1f}", "max", int(single[:, 7].max()))
    if bad:
        print(f"DIFFERENT: {len(bad)} of {len(ref.files)} arrays, e.g. {bad[:5]}")
        return 1
    print(f"bit-identical: all {len(ref.files)} arrays equal")
    return 0


if __name__ == "__main__":
    sys.exit(main())
