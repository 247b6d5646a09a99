"""Hypothesis strategies for random parts and points (used by test_support and
test_models). Polygons come out counter-clockwise as ``(n, 2)`` float arrays;
they are simple by construction (star-shaped about the origin with every
angular gap below pi, or convex, or a non-degenerate triangle).
"""
import math

import numpy as np
from hypothesis import assume
from hypothesis import strategies as st


def _floats(lo, hi):
    return st.floats(lo, hi, allow_nan=False, allow_infinity=False)


def _sorted_angles(draw, n):
    """``n`` increasing angles around a full turn from a random phase, no gap
    reaching half a turn (so the polygon around the origin is not degenerate)."""
    gaps = np.array(draw(st.lists(_floats(0.15, 1.0), min_size=n, max_size=n)))
    gaps = gaps / gaps.sum() * 2.0 * math.pi
    assume(gaps.max() < 0.95 * math.pi)
    phase = draw(_floats(0.0, 2.0 * math.pi))
    return phase + np.concatenate([[0.0], np.cumsum(gaps[:-1])])


@st.composite
def star_polygons(draw, min_n=3, max_n=11, min_radius=0.25):
    """Star-shaped (usually non-convex) polygon: sorted random angles, random radii."""
    n = draw(st.integers(min_n, max_n))
    ang = _sorted_angles(draw, n)
    rad = np.array(draw(st.lists(_floats(min_radius, 1.0), min_size=n, max_size=n)))
    xy = np.column_stack([rad * np.cos(ang), rad * np.sin(ang)])
    return xy


@st.composite
def convex_polygons(draw, min_n=3, max_n=10):
    """Convex polygon: points at sorted random angles on a circle, then a random
    orientation-preserving affine map (convexity and winding survive)."""
    n = draw(st.integers(min_n, max_n))
    ang = _sorted_angles(draw, n)
    xy = np.column_stack([np.cos(ang), np.sin(ang)])
    stretch = draw(_floats(0.35, 1.0))
    rot = draw(_floats(0.0, math.pi))
    c, s = math.cos(rot), math.sin(rot)
    m = np.array([[c, -s], [s, c]]) @ np.diag([1.0, stretch])
    return xy @ m.T


@st.composite
def triangles(draw):
    pts = np.array(draw(st.lists(st.tuples(_floats(-1.0, 1.0), _floats(-1.0, 1.0)),
                                 min_size=3, max_size=3)))
    e = np.roll(pts, -1, axis=0) - pts
    area = 0.5 * (e[0, 0] * e[1, 1] - e[0, 1] * e[1, 0])
    lengths = np.hypot(e[:, 0], e[:, 1])
    assume(abs(area) > 0.02 * lengths.max() ** 2)
    return pts if area > 0 else pts[::-1].copy()


def polygons():
    """Any of the above."""
    return st.one_of(star_polygons(), convex_polygons(), triangles())


# Polygons with dyadic coordinates: edge midpoints (and other dyadic points of an
# axis-aligned edge) are exactly representable and exactly on the edge.
DYADIC_POLYGONS = [
    np.array([[0.0, 0.0], [2.0, 0.0], [2.0, 0.5], [0.5, 0.5], [0.5, 2.0], [0.0, 2.0]]),  # L
    np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]),  # square
    np.array([[0.0, 0.0], [3.0, 0.0], [3.0, 2.0], [2.0, 2.0], [2.0, 1.0], [1.0, 1.0],
              [1.0, 2.0], [0.0, 2.0]]),  # U (notch)
    np.array([[0.0, 0.0], [4.0, 1.0], [1.0, 1.5], [2.0, 3.0], [-1.0, 2.0]]),  # arrow-ish
]


@st.composite
def point_on_boundary(draw, xy):
    """(point, edge index, t) on the polygon's boundary, interpolated in floats."""
    n = len(xy)
    j = draw(st.integers(0, n - 1))
    t = draw(_floats(0.02, 0.98))
    p, q = xy[j], xy[(j + 1) % n]
    return p + t * (q - p), j, t


@st.composite
def point_inside_star(draw, xy):
    """A point strictly inside a polygon that is star-shaped about the origin (or
    convex with the origin inside): a random point of a random fan triangle."""
    n = len(xy)
    j = draw(st.integers(0, n - 1))
    a = draw(_floats(0.0, 1.0))
    b = draw(_floats(0.0, 1.0))
    if a + b > 1.0:
        a, b = 1.0 - a, 1.0 - b
    a, b = 0.01 + 0.97 * a, 0.01 + 0.97 * b  # a + b <= 0.99, both >= 0.01
    return a * xy[j] + b * xy[(j + 1) % n]


@st.composite
def point_outside(draw, xy):
    """A point beyond the circumscribed circle of the polygon (about the origin)."""
    rmax = float(np.max(np.hypot(xy[:, 0], xy[:, 1])))
    ang = draw(_floats(0.0, 2.0 * math.pi))
    k = draw(_floats(1.02, 4.0))
    return k * rmax * np.array([math.cos(ang), math.sin(ang)])


@st.composite
def point_near_edge(draw, xy):
    """A point very close to an edge (either side), to stress near-singular cases."""
    c, j, _ = draw(point_on_boundary(xy))
    n = len(xy)
    e = xy[(j + 1) % n] - xy[j]
    m = np.array([e[1], -e[0]]) / math.hypot(*e)
    expo = draw(_floats(-12.0, -2.0))
    sign = draw(st.sampled_from([-1.0, 1.0]))
    return c + sign * 10.0 ** expo * m


# --------------------------------------------------------------------------- contacts


def inward_normal(verts, j):
    """Inward unit normal of edge j (from vertex j to j + 1) of a CCW polygon."""
    n = len(verts)
    e = verts[(j + 1) % n] - verts[j]
    e = e / math.hypot(*e)
    return np.array([-e[1], e[0]])


@st.composite
def contact_on(draw, verts, allow_vertex=True):
    """A pin contact on the CCW polygon ``verts``: ``(c, n, kind)``.

    Edge contact: c inside edge j, n its inward normal. Vertex contact (convex
    vertices only, where a round pin can touch): n anywhere in the vertex's
    normal cone, between the inward normals of the two adjacent edges.
    """
    n_v = len(verts)
    kinds = ["edge", "vertex"] if allow_vertex else ["edge"]
    kind = draw(st.sampled_from(kinds))
    if kind == "vertex":
        convex = []
        for j in range(n_v):
            a, b, c = verts[j - 1], verts[j], verts[(j + 1) % n_v]
            if (b[0] - a[0]) * (c[1] - b[1]) - (b[1] - a[1]) * (c[0] - b[0]) > 1e-9:
                convex.append(j)
        j = draw(st.sampled_from(convex))
        s = draw(_floats(0.0, 1.0))
        nv = (1.0 - s) * inward_normal(verts, (j - 1) % n_v) + s * inward_normal(verts, j)
        return verts[j].copy(), nv / math.hypot(*nv), kind
    j = draw(st.integers(0, n_v - 1))
    t = draw(_floats(0.02, 0.98))
    p, q = verts[j], verts[(j + 1) % n_v]
    return p + t * (q - p), inward_normal(verts, j), kind


@st.composite
def pin_velocity(draw, n, max_angle=1.45, min_angle=0.0):
    """Pin velocity relative to the belt, moving into the part (n . v_p > 0):
    at angle alpha from n, min_angle <= |alpha| <= max_angle < pi/2,
    magnitude in [0.5, 2]."""
    alpha = draw(_floats(min_angle, max_angle)) * draw(st.sampled_from([-1.0, 1.0]))
    speed = draw(_floats(0.5, 2.0))
    t = np.array([-n[1], n[0]])
    return speed * (math.cos(alpha) * n + math.sin(alpha) * t)
