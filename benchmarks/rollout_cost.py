"""Where a rollout's time goes on real outlines: counts per rollout and rates.

For each part (the default triangle, a plain rectangle, a 50 x 40 mm plate
with 6 mm fillets flattened to 60 vertices, with and without two holes of 16
vertices, and any CAD drawings given with ``--outline``):

- **counts per rollout** (deterministic): slope evaluations (six per
  Cash-Karp step, plus the steps that locate events), evaluations of the
  belt's power (near: centre of rotation within 8 a, closed forms or the
  support table; far: beyond it), event-function evaluations and contact
  feature changes. They come from a sample of rollouts run with the kernels
  as plain Python (``NUMBA_DISABLE_JIT``, in a subprocess), the same code
  that Numba compiles;
- **rates** (compiled, one thread, one run, so compare ratios): rollouts per
  second with the support table (what pinfeed uses for parts of
  ``TABLE_MIN_EDGES`` material edges or more) and with the exact edge sums,
  and the ratio of the part's cost to the triangle's;
- **one evaluation of E, G, N** at the sample's own centres of rotation,
  with the table and with the exact sums (nanoseconds).

    .venv/bin/python benchmarks/rollout_cost.py [--outline F.dxf ...] [--sample 30]

Prints a Markdown table for the performance page.
"""
from __future__ import annotations

import argparse
import datetime
import json
import math
import os
import platform
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

THETA = np.arange(0.0, 360.0, 4.0)
D = np.array([-0.9, -0.7, -0.5, -0.3, -0.2, -0.1, 0.1, 0.2, 0.3, 0.5, 0.7, 0.9])
MU_C, R_PIN = 0.2, 3.0


def _rounded_rectangle(w, h, r, per_corner):
    pts = []
    for cx, cy, a0 in ((w - r, r, -90), (w - r, h - r, 0), (r, h - r, 90), (r, r, 180)):
        for k in range(per_corner + 1):
            a = math.radians(a0 + 90.0 * k / per_corner)
            pts.append((cx + r * math.cos(a), cy + r * math.sin(a)))
    return pts


def _circle(cx, cy, r, n):
    return [(cx + r * math.cos(2 * math.pi * k / n), cy + r * math.sin(2 * math.pi * k / n)) for k in range(n)]


def parts(outlines) -> dict:
    """Name -> (outline, holes) in mm."""
    plate = _rounded_rectangle(50.0, 40.0, 6.0, 14)
    out = {"triangle": ([(0, 0), (60, 0), (15, 35)], []),
           "rectangle": ([(0, 0), (50, 0), (50, 40), (0, 40)], []),
           "filleted plate (60 v)": (plate, []),
           "filleted plate, 2 holes": (plate, [_circle(12, 20, 3.25, 16), _circle(38, 20, 3.25, 16)])}
    from pipeline.parts.outlines import read_outline
    for path in outlines:
        o = read_outline(path)
        out[Path(path).name] = (np.asarray(o.vertices).tolist(), [np.asarray(h).tolist() for h in o.holes])
    return out


_COUNT = r'''
import json, sys, numpy as np
import kernels.models as M, kernels.rollout as R, kernels.support as S
from pipeline.parts.part import Part
outline, holes, theta, d, mu, rp = json.loads(sys.argv[1])
cnt = dict(near=0, far=0, slopes=0, events=0)
power, deriv, events = S._power, R._derivative, R._events
cors = []
def counted_power(quad, area, vx, vy, om):
    if om != 0.0 and om * om * 64.0 > vx * vx + vy * vy:
        cnt["near"] += 1
        cors.append((-vy / om, vx / om))
    else:
        cnt["far"] += 1
    return power(quad, area, vx, vy, om)
def counted_deriv(*a):
    cnt["slopes"] += 1
    return deriv(*a)
def counted_events(*a):
    cnt["events"] += 1
    return events(*a)
M._power, R._derivative, R._events = counted_power, counted_deriv, counted_events
part = Part.from_vertices(outline, holes=holes)
verts, area, a, quad, m_max, convex = part.prepared()
n, changes = 0, 0
for th in theta:
    for dd in d:
        r = R._rollout(verts, area, a, quad, m_max, convex, 0, mu, rp, np.radians(th), dd, 0.0,
                       np.inf, R.DEFAULT_DS_MAX, R.DEFAULT_TOL, False)
        n += 1
        changes += r[5]
print(json.dumps({"per_rollout": {k: v / n for k, v in cnt.items()}, "changes": changes / n,
                  "cors": cors[::7]}))
'''


def counts(outline, holes, sample: int) -> dict:
    """Counts per rollout from ``sample`` rollouts run as plain Python."""
    rng = np.random.default_rng(0)
    theta = rng.uniform(0, 360, sample).round(1).tolist()
    env = dict(os.environ, NUMBA_DISABLE_JIT="1", PYTHONPATH=str(ROOT))
    pairs = json.dumps([outline, holes, theta[:max(1, sample // 6)], [-0.7, -0.3, -0.1, 0.2, 0.5, 0.8],
                        MU_C, R_PIN])
    res = subprocess.run([sys.executable, "-c", _COUNT, pairs], capture_output=True, text=True, env=env,
                         check=True)
    return json.loads(res.stdout)


def rates(part) -> tuple[float, float]:
    """Rollouts per second, one thread: (as pinfeed runs it, with the exact edge sums)."""
    from kernels.batch import _rollout_grid
    from kernels.edge_integrals import _table_sizes
    from kernels.rollout import DEFAULT_DS_MAX, DEFAULT_TOL
    verts, area, a, quad, m_max, convex = part.prepared()
    f, n = _table_sizes(quad)
    raw = np.vstack([quad[:f + 2 * n], [[f, n, 0.0]]])
    out = []
    for q in (quad, raw):
        args = (verts, area, a, q, m_max, convex, 0, MU_C, R_PIN)  # mm: the kernels take the part's unit
        _rollout_grid(*args, np.radians(THETA[:2]), D[:2], 0.0, np.inf, DEFAULT_DS_MAX, DEFAULT_TOL, 1)
        best = math.inf
        for _ in range(2):
            t0 = time.perf_counter()
            _rollout_grid(*args, np.radians(THETA), D, 0.0, np.inf, DEFAULT_DS_MAX, DEFAULT_TOL, 1)
            best = min(best, time.perf_counter() - t0)
        out.append(THETA.size * D.size / best)
    return out[0], out[1]


def evaluation_ns(part, cors) -> tuple[float, float]:
    """Nanoseconds per evaluation of E, G, N at ``cors``: (table, exact sums)."""
    import numba
    from kernels.edge_integrals import _support_sum, _table_sizes
    from kernels.support_table import _has_table, _table_support
    verts, area, a, quad, m_max, convex = part.prepared()
    if not _has_table(quad) or not cors:
        return math.nan, math.nan
    f, n = _table_sizes(quad)
    raw = np.vstack([quad[:f + 2 * n], [[f, n, 0.0]]])
    pts = np.tile(np.asarray(cors, dtype=float), (max(1, 100_000 // len(cors)), 1))

    @numba.njit
    def table(q, p):
        s = 0.0
        for k in range(p.shape[0]):
            s += _table_support(q, p[k, 0], p[k, 1])[1]
        return s

    @numba.njit
    def exact(q, p):
        s = 0.0
        for k in range(p.shape[0]):
            s += _support_sum(q, p[k, 0], p[k, 1])[1]
        return s
    out = []
    for fn, q in ((table, quad), (exact, raw)):
        fn(q, pts[:5])
        t0 = time.perf_counter()
        fn(q, pts)
        out.append((time.perf_counter() - t0) / pts.shape[0] * 1e9)
    return out[0], out[1]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--outline", action="append", default=[], help="a CAD drawing to add (repeat)")
    ap.add_argument("--sample", type=int, default=30, help="rollouts counted per part (as Python)")
    args = ap.parse_args()
    from kernels.edge_integrals import _table_sizes
    from kernels.support_table import _has_table
    from pipeline.parts.part import Part
    rows, tri_rate = [], None
    for name, (outline, holes) in parts(args.outline).items():
        part = Part.from_vertices(outline, holes=holes)
        quad = part.prepared()[3]
        c = counts(outline, holes, args.sample)
        fast, exact = rates(part)
        tri_rate = tri_rate or fast
        t_ns, e_ns = evaluation_ns(part, c["cors"])
        pr = c["per_rollout"]
        rows.append(dict(part=name, outline_vertices=len(outline), hole_vertices=sum(len(h) for h in holes),
                         material_edges=int(_table_sizes(quad)[1]), table=bool(_has_table(quad)),
                         slopes=pr["slopes"], power_near=pr["near"], power_far=pr["far"],
                         events=pr["events"], changes=c["changes"], rate=fast, rate_exact=exact,
                         cost_vs_triangle=tri_rate / fast, cost_vs_triangle_exact=tri_rate / exact,
                         eval_ns_table=t_ns, eval_ns_exact=e_ns))
        print(f"{name}: {fast:.0f}/s ({exact:.0f}/s exact sums)", file=sys.stderr, flush=True)
    print(f"\n{datetime.date.today()}, {platform.machine()}, {os.cpu_count()} CPUs, load average "
          f"{os.getloadavg()[0]:.1f}; one thread; {THETA.size} x {D.size} rollouts per rate, mu_c {MU_C}, "
          f"pin radius {R_PIN} mm; counts from {args.sample} rollouts as Python\n")
    print("| part | outline / hole vertices | material edges | slopes per rollout | power evaluations "
          "(near / far) | feature changes | rollouts/s | x triangle | exact sums: rollouts/s | x triangle "
          "| one E, G, N: table / exact (ns) |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for r in rows:
        ev = "-" if math.isnan(r["eval_ns_table"]) else f"{r['eval_ns_table']:.0f} / {r['eval_ns_exact']:.0f}"
        print(f"| {r['part']} | {r['outline_vertices']} / {r['hole_vertices']} | {r['material_edges']}"
              f"{' (table)' if r['table'] else ''} | {r['slopes']:.0f} | {r['power_near']:.0f} / "
              f"{r['power_far']:.0f} | {r['changes']:.1f} | {r['rate']:,.0f} | {r['cost_vs_triangle']:.1f} | "
              f"{r['rate_exact']:,.0f} | {r['cost_vs_triangle_exact']:.1f} | {ev} |")


if __name__ == "__main__":
    main()
