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

Beyond the quasi-static models on uniform supports: the minpower model on
point supports (kernel code ``MINPOWER_POINTS``, tables from
``support._point_table``) and on a part with a hole (``_prepare_loops``),
each through the three entry points; the dynamic model
(``dynamic._dyn_rollout`` with its records, ``batch._dyn_rollout_grid`` and
``points._dyn_rollout_points``) on a smaller grid; and the support code itself:
``support._power`` (both branches) and ``support._point_power`` and the
minimisations ``models._minimise`` and ``models._minimise_points`` at
seeded random twists and families.

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

from kernels.batch import _dyn_rollout_grid, _rollout_grid  # noqa: E402
from kernels.dynamic import _dyn_rollout  # noqa: E402
from kernels.models import _minimise, _minimise_points  # noqa: E402
from kernels.points import _dyn_rollout_points, _rollout_points  # noqa: E402
from kernels.rollout import (_prepare, _prepare_loops, _rollout_budget,  # noqa: E402
                             max_steps_for)
from kernels.support import _point_power, _point_table, _power, _table_sizes  # noqa: E402


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
MINPOWER_POINTS = 3
# Point supports (x, y, w) in units of a, weights summing to 1, per part.
POINT_SUPPORTS = {
    "scalene": np.array([[-0.6, -0.3, 0.3], [0.8, -0.3, 0.3], [-0.2, 0.5, 0.4]]),
    "convex6": np.array([[0.3, 0.2, 0.1], [-0.4, 0.3, 0.25], [-0.2, -0.4, 0.2],
                         [0.5, -0.3, 0.25], [0.0, 0.0, 0.2]]),
}
# A 40 x 30 block with a 10 x 8 hole off centre (outline, then the hole).
HOLED = (np.array([(0.0, 0.0), (40.0, 0.0), (40.0, 30.0), (0.0, 30.0),
                   (8.0, 6.0), (18.0, 6.0), (18.0, 14.0), (8.0, 14.0)]), np.array([0, 4, 8]))
# Dynamic model: (mu_c, Froude number, v_pin, restitution) per case, a smaller grid.
DYN_CASES = ((0.2, 0.5, 0.0, 0.0), (0.6, 3.0, 0.4, 0.3))
DYN_THETA = np.radians(np.arange(0.0, 360.0, 45.0) + 0.37)
DYN_D = np.array([-0.9, -0.2, 0.4, 0.95])
DYN_EPS, DYN_H, DYN_STEPS = 0.002, 4e-3, 200000


def _quasi_static(out, key, prep, model, mu, r_pin, v_pin, budget):
    """The three entry points of the quasi-static kernels on the ``THETA x D`` grid."""
    rows = []
    k = 0
    for d in D:
        for th in THETA:
            record = k % 8 == 0
            res = _rollout_budget(*prep, model, mu, r_pin, th, d, v_pin, np.inf,
                                  0.1, 1e-7, record, budget)
            rows.append((res[0], res[1], res[2], res[3], res[4], res[5], res[6], res[9]))
            if record:
                out[f"{key}_traj{k}"] = res[7]
                out[f"{key}_force{k}"] = res[8]
            k += 1
    out[f"{key}_single"] = np.array(rows, dtype=np.float64)
    grid = _rollout_grid(*prep, model, mu, r_pin, THETA, D, v_pin, np.inf, 0.1, 1e-7, 4)
    for i, arr in enumerate(grid):
        out[f"{key}_grid{i}"] = arr
    tt, dd = np.meshgrid(THETA, D)
    pts = _rollout_points(*prep, model, np.full(tt.size, mu), r_pin, tt.ravel(), dd.ravel(),
                          v_pin, np.inf, 0.1, 1e-7, 2)
    for i, arr in enumerate(pts):
        out[f"{key}_points{i}"] = arr


def _dynamic(out, pname, prep):
    """The dynamic model's single rollout (records of one in five), grid and points."""
    verts, area, a, quad, _, convex = prep
    for c, (mu, fr, v_pin, rest) in enumerate(DYN_CASES):
        key = f"dyn_{pname}_c{c}"
        args = (fr, rest, DYN_EPS, DYN_H, np.inf, DYN_STEPS)
        rows = []
        for k, (d, th) in enumerate((d, th) for d in DYN_D for th in DYN_THETA):
            res = _dyn_rollout(verts, area, a, quad, convex, mu, 3.0, th, d, v_pin, *args,
                               k % 5 == 0)
            rows.append(res[:7])
            if k % 5 == 0:
                for name, arr in zip(("traj", "force", "twist"), res[7:]):
                    out[f"{key}_{name}{k}"] = arr
        out[f"{key}_single"] = np.array(rows, dtype=np.float64)
        grid = _dyn_rollout_grid(verts, area, a, quad, convex, mu, 3.0, DYN_THETA, DYN_D,
                                 v_pin, *args, 3)
        for i, arr in enumerate(grid):
            out[f"{key}_grid{i}"] = arr
        tt, dd = np.meshgrid(DYN_THETA, DYN_D)
        pts = _dyn_rollout_points(verts, area, a, quad, convex, np.full(tt.size, mu), 3.0,
                                  tt.ravel(), dd.ravel(), v_pin, *args, 2)
        for i, arr in enumerate(pts):
            out[f"{key}_points{i}"] = arr


def _support_code(out, pname, quad, area):
    """``_power``, ``_point_power``, ``_minimise`` and ``_minimise_points`` at
    seeded random twists and affine families, on the part's uniform support
    table ``quad`` and on a point support built from it."""
    rng = np.random.default_rng(11)
    pts = POINT_SUPPORTS["convex6"]
    ptab = _point_table(quad, pts)
    m = _table_sizes(ptab)[0]
    rows, prow, mins = [], [], []
    for n in range(200):
        v = rng.normal(size=3) * (10.0 if n % 4 == 0 else 1.0) ** np.array([1, 1, -1])
        rows.append(_power(quad, area, *v))
        r = _point_power(ptab, m, *v, n % 7 - 1)
        prow.append(r[:10] + (float(r[10]), r[11], r[12]))
        x, b, c = rng.normal(size=(3, 3))
        fam = (*x, *b, *c, 1 + n % 2, 0.1, -0.1, 1e-12 if n % 3 else 1e-8)
        for p, y1, y2, g, h, conv in (_minimise(quad, area, *fam), _minimise_points(ptab, *fam)):
            mins.append((p, y1, y2) + tuple(g) + tuple(h) + (float(conv),))
    out[f"support_{pname}_power"] = np.array(rows, dtype=np.float64)
    out[f"support_{pname}_point_power"] = np.array(prow, dtype=np.float64)
    out[f"support_{pname}_minimise"] = np.array(mins, dtype=np.float64)


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
                    _quasi_static(out, key, prep, model, mu, r_pin, v_pin, budget)
        if pname in POINT_SUPPORTS:
            pprep = prep[:3] + (_point_table(prep[3], POINT_SUPPORTS[pname]),) + prep[4:]
            for mu in MUS:
                v_pin = 0.4 if mu == 0.2 else 0.0
                _quasi_static(out, f"{pname}_points_mu{mu:g}_v{v_pin:g}", pprep,
                              MINPOWER_POINTS, mu, 3.0, v_pin, budget)
        _dynamic(out, pname, prep)
        _support_code(out, pname, prep[3], prep[1])
    hprep = _prepare_loops(*HOLED)
    for mu in MUS:
        _quasi_static(out, f"holed_m0_mu{mu:g}", hprep, 0, mu, 3.0, 0.0,
                      max_steps_for(_table_sizes(hprep[3])[1]))
    _dynamic(out, "holed", hprep)
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
    single = np.concatenate([out[k] for k in sorted(out)
                             if k.endswith("_single") and not k.startswith("dyn_")])
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
