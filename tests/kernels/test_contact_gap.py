"""The second-contact gap of a non-convex outline against a plain reference.

``geometry._other_contact_gap`` skips edges whose bounding box is too far to
lower the gap found so far; the value must be the same, bit for bit, as the
minimum over every edge (the reference below, the function as it was).
"""
import math

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from kernels._numba import jit
from kernels.geometry import _closest_on_segment, _other_contact_gap
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
