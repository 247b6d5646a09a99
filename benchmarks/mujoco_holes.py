"""Single-pin agreement of the MuJoCo rig with the kernels on parts with
holes, by the method the manual uses for solid parts, and the rig with the
holes filled as the counter-factual.

Two comparisons, each the one the manual gives for solid parts:

- **quasi-static** (``docs/explanation/supports.md``, uniform pressure, and
  ``tests/maps/test_mujoco_support.py``): the 6 pushes ``CASES`` of that
  test (theta_i, d, mu_c), pin radius 3 mm, the rig on a 50 mm/s belt
  against the quasi-static kernel (minpower); max |delta theta_f| and
  whether the statuses agree;
- **dynamic** (``docs/explanation/fast-belts.md`` and
  ``tests/kernels/test_dynamic_model.py``): the 5 pushes x mu_c 0 and 0.3
  of that test's ``CASES_FAST``, pin radius 1 mm, the rig against the
  dynamic model at 300 and 150 mm/s; max |delta theta_f| and how many of
  the 10 agree within the test's 2 deg with equal statuses.

The counter-factual (``filled``): the rig on the outline alone (the part
``Part.from_vertices(part.vertices)``: its mass properties and belt grid
the outline's, holes filled) pushed by the same physical pin (the same line
in the part's frame: the push's ``d`` re-expressed about the outline's
centroid and its ``a``), against the same kernel answer for the holed part.
``kernel shift`` is the kernel's own |theta_f(holed) - theta_f(filled)| on
those pushes: how far the holes move the answer the rig must follow.

The solid asymmetric triangle is run first: it must reproduce the manual's
solid numbers (the method is the same).

``--grid`` sets the rig's support grid spacing (mm; the rig's own 2.5 by
default): a finer grid shows how much of the disagreement is the grid's.

    .venv/bin/python benchmarks/mujoco_holes.py [--parts NAME,...] [--skip-dynamic] [--grid MM] [--json OUT]
"""
from __future__ import annotations

import argparse
import json
import math
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from pipeline.maps import simulate  # noqa: E402
from pipeline.parts.outlines import read_outline  # noqa: E402
from pipeline.parts.part import Part  # noqa: E402

# tests/maps/test_mujoco_support.py
CASES_QS = [(10.0, 0.3, 0.0), (200.0, -0.5, 0.3), (300.0, 0.3, 0.3), (100.0, -0.5, 0.0),
            (150.0, 0.5, 0.15), (60.0, -0.3, 0.15)]
BELT_QS, R_PIN_QS = 50.0, 3.0
# tests/kernels/test_dynamic_model.py (CASES_FAST)
CASES_DYN = [(th, d, mu) for th, d in ((10.0, 0.3), (200.0, -0.5), (300.0, 0.3), (40.0, 0.4), (70.0, -0.4))
             for mu in (0.0, 0.3)]
BELTS_DYN, R_PIN_DYN, AGREE_DYN = (300.0, 150.0), 1.0, 2.0


def _circle(cx, cy, r, n):
    t = np.linspace(0.0, 2 * np.pi, n, endpoint=False)
    return np.column_stack([cx + r * np.cos(t), cy + r * np.sin(t)])


def parts():
    """name -> Part: the solid reference first, then the holed parts."""
    tri = [(0, 0), (60, 0), (15, 35)]
    return {
        "asym_triangle (solid)": lambda: Part.from_vertices(tri, "asym_triangle"),
        "asym_triangle + hole": lambda: Part.from_vertices(tri, "asym_holed",
                                                           holes=[_circle(26.0, 9.0, 7.0, 16)]),
        "plate_offcentre_r12": lambda: read_outline(ROOT / "tests/data/cad/plate_offcentre_r12.dxf").part(),
        "gusset_bracket": lambda: read_outline(ROOT / "tests/data/cad/gusset_bracket.dxf").part(),
        "slotted_link": lambda: read_outline(ROOT / "benchmarks/corpus/slotted_link.svg").part(),
        "pawl_r2000": lambda: read_outline(ROOT / "benchmarks/corpus/pawl_r2000.dxf").part(),
    }


def filled_push(part: Part, filled: Part, theta: float, d: float) -> float:
    """The ``d`` of the filled part for the pin line ``d`` of the holed part at
    orientation ``theta`` (deg): both parts share the drawing's axes, the
    filled part's origin is the outline's centroid ``c`` (in the holed part's
    frame), so the pin's offset from it is ``d a - (R(theta) c)_y``."""
    x, y = part.vertices[:, 0], part.vertices[:, 1]
    xn, yn = np.roll(x, -1), np.roll(y, -1)
    cr = x * yn - xn * y
    area = 0.5 * cr.sum()
    c = np.array([((x + xn) * cr).sum(), ((y + yn) * cr).sum()]) / (6.0 * area)
    th = math.radians(theta)
    cy = math.sin(th) * c[0] + math.cos(th) * c[1]
    return (d * part.a - cy) / filled.a


def _circ(a, b):
    return abs((a - b + 180.0) % 360.0 - 180.0)


def _run(part, th, d, mu, r_pin, **kw):
    r = simulate.rollout(part, th, d, mu, r_pin, **kw)
    return str(r.status.item()), float(r.theta_f)


def compare(part: Part, cases, r_pin, ref_kw, belt):
    """Rows of one comparison: the reference model (``ref_kw``) on the holed
    part, the rig on it, the rig on the filled outline (same physical push)
    and the reference on the filled outline."""
    filled = Part.from_vertices(part.vertices, part.name + "_filled")
    rows = []
    for th, d, mu in cases:
        d_f = filled_push(part, filled, th, d) if part.holes else d
        row = {"theta_i": th, "d": d, "mu_c": mu, "d_filled": d_f}
        t0 = time.perf_counter()
        row["ref"] = _run(part, th, d, mu, r_pin, **ref_kw)
        row["rig"] = _run(part, th, d, mu, r_pin, model="mujoco", belt_speed=belt)
        if part.holes:
            row["rig_filled"] = _run(filled, th, d_f, mu, r_pin, model="mujoco", belt_speed=belt)
            row["ref_filled"] = _run(filled, th, d_f, mu, r_pin, **ref_kw)
        row["wall_s"] = time.perf_counter() - t0
        rows.append(row)
    return rows


def summary(rows, agree=None):
    """max |delta theta_f| of the rig (and of the filled rig) against the
    reference over the rows whose statuses agree, the status disagreements,
    the count within ``agree`` deg with equal statuses, and the kernel's own
    holed-vs-filled shift."""
    def stats(key):
        both = [r for r in rows if r[key][0] == r["ref"][0]]
        errs = [_circ(r[key][1], r["ref"][1]) for r in both]
        out = {"max_deg": max(errs) if errs else None,
               "median_deg": float(np.median(errs)) if errs else None,
               "status_differs": len(rows) - len(both)}
        if agree is not None:
            out["within"] = sum(e <= agree for e in errs)
        return out
    out = {"n": len(rows), "rig": stats("rig")}
    if "rig_filled" in rows[0]:
        out["rig_filled"] = stats("rig_filled")
        shifts = [_circ(r["ref"][1], r["ref_filled"][1]) for r in rows
                  if r["ref"][0] == r["ref_filled"][0] == "ok"]
        out["kernel_shift_max_deg"] = max(shifts) if shifts else None
        out["kernel_shift_median_deg"] = float(np.median(shifts)) if shifts else None
    return out


def _fmt(x):
    return "-" if x is None else f"{x:.2f}"


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--parts", default="", help="comma-separated names (default: all)")
    ap.add_argument("--skip-dynamic", action="store_true")
    ap.add_argument("--json", default=None, help="write every row and summary here")
    ap.add_argument("--grid", type=float, default=None,
                    help="the rig's support grid spacing, mm (default: mujoco_rig.GRID_MM, 2.5)")
    args = ap.parse_args(argv)
    if args.grid is not None:  # read by mujoco_rig._support at each passage
        import pipeline.maps.mujoco_rig as rig
        rig.GRID_MM = args.grid
    table = parts()
    names = [n for n in table if not args.parts or n in args.parts.split(",")]
    record = {}
    for name in names:
        part = table[name]()
        t0 = time.perf_counter()
        res = {"qs": compare(part, CASES_QS, R_PIN_QS, {}, BELT_QS)}
        res["qs_summary"] = summary(res["qs"])
        if not args.skip_dynamic:
            for v in BELTS_DYN:
                rows = compare(part, CASES_DYN, R_PIN_DYN, {"model": "dynamic", "belt_speed": v}, v)
                res[f"dyn{v:g}"] = rows
                res[f"dyn{v:g}_summary"] = summary(rows, AGREE_DYN)
        res["wall_s"] = time.perf_counter() - t0
        record[name] = res
        s = res["qs_summary"]
        line = (f"{name}: quasi-static @ {BELT_QS:g} mm/s, {s['n']} pushes: rig max {_fmt(s['rig']['max_deg'])} deg "
                f"(status differs {s['rig']['status_differs']})")
        if "rig_filled" in s:
            line += (f"; filled rig max {_fmt(s['rig_filled']['max_deg'])} (median {_fmt(s['rig_filled']['median_deg'])}"
                     f", status differs {s['rig_filled']['status_differs']}); rig median {_fmt(s['rig']['median_deg'])}"
                     f"; kernel shift max {_fmt(s['kernel_shift_max_deg'])} median {_fmt(s['kernel_shift_median_deg'])}")
        print(line, flush=True)
        for v in ([] if args.skip_dynamic else BELTS_DYN):
            s = res[f"dyn{v:g}_summary"]
            line = (f"    dynamic @ {v:g} mm/s, {s['n']} cases: rig max {_fmt(s['rig']['max_deg'])} deg, "
                    f"{s['rig']['within']}/{s['n']} within {AGREE_DYN:g} deg (status differs {s['rig']['status_differs']})")
            if "rig_filled" in s:
                line += (f"; filled rig max {_fmt(s['rig_filled']['max_deg'])}, {s['rig_filled']['within']}/{s['n']} "
                         f"within; dynamic shift max {_fmt(s['kernel_shift_max_deg'])}")
            print(line, flush=True)
        print(f"    ({res['wall_s']:.0f} s)", flush=True)
    if args.json:
        Path(args.json).write_text(json.dumps(record, indent=1))


if __name__ == "__main__":
    main()
