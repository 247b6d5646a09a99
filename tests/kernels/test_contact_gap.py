"""The second-contact gap of a non-convex outline against a plain reference.

``geometry._other_contact_gap`` skips edges whose bounding box is too far to
lower the gap found so far; the value must be the same, bit for bit, as the
minimum over every edge (the reference below, the function as it was).
``geometry._cached_gap`` measures only the edges near the pin while the
others provably stay clear: it must give that same value wherever the value
is negative (a second contact), and a positive value no larger than it
elsewhere; asked for the exact value, that value everywhere.
"""
import math

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from kernels._numba import jit
from kernels.geometry import (GAP_CACHE_HEAD, GAP_NEAR_REACH, _cached_gap, _closest_on_segment, _other_contact_gap,
                              _other_feature)
from strategies import star_polygons


@jit
def _reference(verts, qx, qy, cx, cy, r_pin, same_feature):
    """Every edge's distance, compiled as the kernels are (the same libm)."""
    gap = np.inf
    for j in range(verts.shape[0]):
        px, py, t, length = _closest_on_segment(verts, j, qx, qy)
        if math.hypot(px - cx, py - cy) > same_feature:
            gap = min(gap, math.hypot(qx - px, qy - py) - r_pin)
    return gap


@settings(max_examples=60, deadline=None)
@given(star_polygons(min_n=8, max_n=40), st.integers(min_value=0, max_value=2**31 - 1),
       st.floats(min_value=0.01, max_value=0.3))
def test_gap_is_the_minimum_over_every_edge(xy, seed, r_pin):
    verts = np.ascontiguousarray(xy, dtype=float)
    rng = np.random.default_rng(seed)
    n = len(verts)
    for _ in range(20):
        j = rng.integers(n)
        s = rng.uniform()
        cx, cy = verts[j] + s * (verts[(j + 1) % n] - verts[j])  # a contact on edge j
        ang = rng.uniform(0, 2 * math.pi)
        qx, qy = cx + r_pin * math.cos(ang), cy + r_pin * math.sin(ang)
        if rng.uniform() < 0.3:
            qx, qy = rng.uniform(-2, 2, 2)
        got = _other_contact_gap(verts, qx, qy, cx, cy, r_pin, 1e-3)
        assert got == _reference(verts, qx, qy, cx, cy, r_pin, 1e-3)


@settings(max_examples=60, deadline=None)
@given(star_polygons(min_n=8, max_n=40, min_radius=0.1), st.integers(min_value=0, max_value=2**31 - 1),
       st.floats(min_value=0.01, max_value=0.3), st.floats(min_value=0.005, max_value=0.2),
       st.sampled_from([GAP_CACHE_HEAD + 3, GAP_CACHE_HEAD + 25]))
def test_cached_gap_is_exact_wherever_it_is_negative(xy, seed, r_pin, stride, size):
    # A pin walking along the outline and across it, one cache for the walk:
    # the cache is made at one point and read at the next ones, as in a
    # rollout, including where the pin dips into the part (negative gaps) and
    # with a cache too small for the near edges (the exact fallback).
    verts = np.ascontiguousarray(xy, dtype=float)
    rng = np.random.default_rng(seed)
    n = len(verts)
    cache = np.empty(size)
    cache[0] = -1.0
    j, s, side = rng.integers(n), rng.uniform(), rng.uniform(0.5, 1.2)
    for _ in range(120):
        s += rng.uniform(-0.2, 1.0) * stride / np.linalg.norm(verts[(j + 1) % n] - verts[j])
        while s > 1.0:
            s -= 1.0
            j = (j + 1) % n
        s = max(s, 0.0)
        cx, cy = verts[j] + s * (verts[(j + 1) % n] - verts[j])
        ex, ey = verts[(j + 1) % n] - verts[j]
        normal = np.array([ey, -ex]) / math.hypot(ex, ey)  # outward (counter-clockwise outline)
        side = min(max(side + rng.normal(0, 0.1), 0.3), 1.5)
        qx, qy = np.array([cx, cy]) + side * r_pin * normal
        want = _reference(verts, qx, qy, cx, cy, r_pin, 1e-3)
        got = _cached_gap(verts, qx, qy, cx, cy, r_pin, 1e-3, cache, False)
        if want <= 0.0:
            assert got == want
        else:
            assert 0.0 < got <= want + 1e-12
        # Asked for the exact value (locating a crossing), it is the
        # reference's everywhere, bit for bit, from the same cache.
        assert _cached_gap(verts, qx, qy, cx, cy, r_pin, 1e-3, cache, True) == want


def test_cached_gap_walk_meets_second_contacts():
    # The walk of the property test, on a comb whose teeth are closer than
    # the pin: with the pin pressed in, far edges become second contacts.
    comb = np.array([[0, 0], [1, 0], [1, 0.3], [0.8, 0.3], [0.8, 0.1], [0.7, 0.1], [0.7, 0.3],
                     [0.5, 0.3], [0.5, 0.1], [0.4, 0.1], [0.4, 0.3], [0, 0.3]], dtype=float)
    cache = np.empty(GAP_CACHE_HEAD + 25)
    cache[0] = -1.0
    seen = {"negative": 0, "bound": 0}
    for y in np.linspace(0.35, 0.12, 60):
        for x in np.linspace(0.3, 0.9, 25):
            cx, cy = x, 0.3 if not (0.4 < x < 0.5 or 0.7 < x < 0.8) else 0.1
            want = _reference(comb, x, y, cx, cy, 0.06, 1e-3)
            got = _cached_gap(comb, x, y, cx, cy, 0.06, 1e-3, cache, False)
            assert _cached_gap(comb, x, y, cx, cy, 0.06, 1e-3, cache, True) == want
            if want <= 0.0:
                seen["negative"] += 1
                assert got == want
            else:
                seen["bound"] += got != want
                assert 0.0 < got <= want + 1e-12
    assert seen["negative"] > 50 and seen["bound"] > 50


@jit
def _hypot_over(px, py, cx, cy, same_feature):
    """The plain comparison ``_other_feature`` stands for, compiled (the same libm)."""
    return math.hypot(px - cx, py - cy) > same_feature


def test_other_feature_is_the_hypot_comparison_at_the_limit():
    # Points a few ulps either side of the limit, where the squared lengths
    # cannot decide and math.hypot must, and points well clear of it.
    rng = np.random.default_rng(7)
    undecided = 0
    for same in (1e-3, 0.37, 2.5):
        for _ in range(3000):
            cx, cy = rng.uniform(-2.0, 2.0, 2)
            ang = rng.uniform(0.0, 2.0 * math.pi)
            r = same * (1.0 + int(rng.integers(-6, 7)) * 2.0**-52 if rng.uniform() < 0.8 else rng.uniform(0.5, 1.5))
            px, py = cx + r * math.cos(ang), cy + r * math.sin(ang)
            d2 = (px - cx) ** 2 + (py - cy) ** 2
            undecided += abs(d2 / same**2 - 1.0) <= 1e-9
            assert _other_feature(px, py, cx, cy, same) == _hypot_over(px, py, cx, cy, same)
    assert undecided > 5000  # the hand-over to math.hypot ran
    # A squared limit among the subnormals, whose rounding is coarser than the slack.
    for same in (1e-160, 3e-162):
        for _ in range(3000):
            ang, r = rng.uniform(0.0, 2.0 * math.pi), same * (1.0 + rng.uniform(-1e-2, 1e-2))
            px, py = r * math.cos(ang), r * math.sin(ang)
            assert _other_feature(px, py, 0.0, 0.0, same) == _hypot_over(px, py, 0.0, 0.0, same)


def test_an_exact_fallback_keeps_the_nearest_other_edge():
    # Above the comb's middle tooth, farther from the other teeth than the
    # near reach: an exact gap measures every edge, and the list made there
    # holds the nearest other edge, so the next point of a search nearby is
    # served from it (the same value as over every edge).
    comb = np.array([[0, 0], [1, 0], [1, 0.3], [0.8, 0.3], [0.8, 0.1], [0.7, 0.1], [0.7, 0.3],
                     [0.5, 0.3], [0.5, 0.1], [0.4, 0.1], [0.4, 0.3], [0, 0.3]], dtype=float)
    r_pin, x, cx, cy = 0.04, 0.6, 0.6, 0.3
    cache = np.empty(GAP_CACHE_HEAD + 25)
    cache[0] = -1.0
    y = cy + r_pin
    want = _reference(comb, x, y, cx, cy, r_pin, 1e-3)
    assert GAP_NEAR_REACH < want < 0.1  # beyond the near reach: the first list cannot decide
    assert _cached_gap(comb, x, y, cx, cy, r_pin, 1e-3, cache, True) == want
    gaps = [(_closest_on_segment(comb, j, x, y), j) for j in range(len(comb))]
    nearest = min(j for (p, j) in gaps if math.hypot(p[0] - cx, p[1] - cy) > 1e-3
                  and math.hypot(x - p[0], y - p[1]) - r_pin == want)
    listed = [int(cache[GAP_CACHE_HEAD + 2 * m]) for m in range(int(cache[0]))]
    assert nearest in listed
    y2 = y + 1e-4
    assert _cached_gap(comb, x, y2, cx, cy, r_pin, 1e-3, cache, True) == _reference(comb, x, y2, cx, cy, r_pin,
                                                                                       1e-3)
    assert [int(cache[GAP_CACHE_HEAD + 2 * m]) for m in range(int(cache[0]))] == listed  # served, not remade


_BOTH_WAYS = r'''
import json, math, sys
import numpy as np
import kernels.dynamic as D, kernels.geometry as G, kernels.rollout as R
prepared, static_cases, dynamic_cases = json.loads(sys.argv[1])
arrays = np.load(prepared)
verts, quad = arrays["verts"], arrays["quad"]
area, a, m_max = (float(x) for x in arrays["scalars"])
convex = False
def run():
    out = []
    for th, d, mu, r_pin in static_cases:
        r = R._rollout(verts, area, a, quad, m_max, convex, 0, mu, r_pin, math.radians(th), d, 0.0,
                       np.inf, R.DEFAULT_DS_MAX, R.DEFAULT_TOL, False)
        out.append([float(x) for x in r[:7]])
    for th, d, v_pin, r_pin in dynamic_cases:
        r = D._dyn_rollout(verts, area, a, quad, convex, 0.2, r_pin, math.radians(th), d, v_pin, 0.5,
                           0.0, D.DEFAULT_V_REG, D.DEFAULT_H, np.inf, 3000, False)
        out.append([float(x) for x in r[:7]])
    return out
cached = run()
def exact(verts, qx, qy, cx, cy, r_pin, same_feature, cache, exact):
    return G._other_contact_gap(verts, qx, qy, cx, cy, r_pin, same_feature)
R._cached_gap = D._cached_gap = exact
print(json.dumps({"cached": cached, "exact": run()}))
'''


def _u_bracket():
    """A 60 x 40 mm U with 4 mm fillets at its four outer corners and a 20 mm
    wide, 25 mm deep slot: pins meet the slot's walls (notches) and the
    fillets' short edges bring edges in and out of the near list."""
    pts = []
    for cx, cy, a0 in ((56, 4, -90), (56, 36, 0)):
        pts += [(cx + 4 * math.cos(math.radians(a0 + 15 * k)), cy + 4 * math.sin(math.radians(a0 + 15 * k)))
                for k in range(7)]
    pts += [(40.0, 40.0), (40.0, 15.0), (20.0, 15.0), (20.0, 40.0)]
    for cx, cy, a0 in ((4, 36, 90), (4, 4, 180)):
        pts += [(cx + 4 * math.cos(math.radians(a0 + 15 * k)), cy + 4 * math.sin(math.radians(a0 + 15 * k)))
                for k in range(7)]
    return pts


def test_rollouts_are_the_same_with_the_cached_gap(tmp_path):
    # Static and dynamic rollouts of a slotted part, run as plain Python
    # twice: with the near-edge cache and with every edge measured at every
    # test (the code before the cache). Every result must be the same, bit
    # for bit, notch jams included.
    import json
    import os
    import subprocess
    import sys
    from pathlib import Path
    # Pins of 3 and 8 mm (the kernels take the part's length unit).
    static_cases = [[float(th), d, 0.3, r_pin] for r_pin in (3.0, 8.0) for th in range(0, 360, 30)
                    for d in (-0.3, 0.0, 0.3)]
    dynamic_cases = [[th, d, v_pin, r_pin] for r_pin in (3.0, 8.0)
                     for th, d, v_pin in ((0.0, 0.0, 0.0), (90.0, 0.2, 0.5), (270.0, -0.1, 0.0))]
    root = Path(__file__).resolve().parents[2]
    env = dict(os.environ, NUMBA_DISABLE_JIT="1", PYTHONPATH=str(root))
    # The part is prepared here, compiled (its support table would take
    # half a minute as plain Python).
    from pipeline.parts.part import Part
    verts, area, a, quad, m_max, convex = Part.from_vertices(_u_bracket()).prepared()
    assert not convex
    np.savez(tmp_path / "part.npz", verts=verts, quad=quad, scalars=[area, a, m_max])
    args = json.dumps([str(tmp_path / "part.npz"), static_cases, dynamic_cases])
    res = subprocess.run([sys.executable, "-c", _BOTH_WAYS, args], capture_output=True, text=True,
                         env=env, check=True, cwd=root)
    got = json.loads(res.stdout)
    assert got["cached"] == got["exact"]
    reasons = [row[1] for row in got["exact"][:len(static_cases)]]
    assert reasons.count(2) >= 10  # rollout.JAM_NOTCH: the slot caught the pin
