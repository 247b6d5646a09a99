"""Part validation, normalisation, identity and resting states (spec sections 1 and 6).

Expected values are worked out by hand in the comments (or, for random
polygons, by an independent computation with scipy's convex hull).
"""
from __future__ import annotations

import math
import subprocess
import sys

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from scipy.spatial import ConvexHull

from conftest import QUAD, TRIANGLE, circular_diff
from pipeline.errors import PinfeedError
from pipeline.parts.part import Part, PolygonError, parse_vertices
from reference import centroid
from reference import signed_area as shoelace


def same_point_set(a, b, tol=1e-9):
    a = np.asarray(a, dtype=float)
    b = np.asarray(b, dtype=float)
    if a.shape != b.shape:
        return False
    dist = np.linalg.norm(a[:, None, :] - b[None, :, :], axis=2)
    return bool(np.all(dist.min(axis=1) < tol) and np.all(dist.min(axis=0) < tol))


def same_cyclic_order(a, b, tol=1e-9):
    """``a`` equals ``b`` up to a cyclic shift of the vertex list."""
    a = np.asarray(a, dtype=float)
    b = np.asarray(b, dtype=float)
    return a.shape == b.shape and any(np.allclose(np.roll(a, k, axis=0), b, atol=tol)
                                      for k in range(len(a)))


# --------------------------------------------------------------------------- validation

@pytest.mark.parametrize("vertices, words", [
    pytest.param([(0, 0), (1, 0)], ["at least 3"], id="too-few"),
    pytest.param([(0, 0), (10, float("nan")), (0, 10)], ["finite"], id="nan"),
    pytest.param([(0, 0), (10, 0), (float("inf"), 10)], ["finite"], id="inf"),
    pytest.param([(0, 0), (10, 0), (10, 10), (0, 10), (0, 0)], ["same point"], id="closed-repeat"),
    pytest.param([(0, 0), (10, 0), (5, 5), (10, 0), (0, 8)], ["same point"], id="repeated"),
    pytest.param([(0, 0), (10, 10), (10, 0), (0, 10)], ["self-intersecting"], id="bow-tie"),
    pytest.param([(0, 0), (10, 0), (1e-13 * 20, 1e-13)], ["zero area"], id="sliver"),
])
def test_invalid_outline_is_rejected_with_named_problem(vertices, words):
    with pytest.raises(PolygonError) as info:
        Part.from_vertices(vertices)
    msg = str(info.value).lower()
    for w in words:
        assert w in msg, msg


@pytest.mark.parametrize("vertices", [
    pytest.param([(0, 0), (10, 0), (20, 0)], id="3-collinear"),
    pytest.param([(0, 0), (10, 5), (20, 10), (30, 15)], id="4-collinear"),
])
def test_collinear_outline_is_reported_as_zero_area(vertices):
    # All vertices on one line: the "polygon" has zero area. The message must
    # name that problem (spec: >= 3 vertices, simple, non-zero area).
    with pytest.raises(PolygonError) as info:
        Part.from_vertices(vertices)
    msg = str(info.value).lower()
    assert "zero area" in msg or "collinear" in msg, msg


def test_polygon_error_is_a_pinfeed_value_error():
    assert issubclass(PolygonError, PinfeedError)
    assert issubclass(PolygonError, ValueError)
    with pytest.raises(ValueError):
        Part.from_vertices([(0, 0), (1, 1)])


@pytest.mark.parametrize("bad", [[], [1, 2, 3], [[0, 0, 0], [1, 0, 0], [0, 1, 0]], "abc", [("a", "b")] * 3])
def test_badly_shaped_vertices_raise_polygon_error(bad):
    with pytest.raises(PolygonError):
        Part.from_vertices(bad)


def test_parse_vertices():
    xy = parse_vertices("0,0 60,0 15,35")
    np.testing.assert_array_equal(xy, np.array(TRIANGLE))
    np.testing.assert_array_equal(parse_vertices("0,0; 60,0;15,35"), np.array(TRIANGLE))
    for bad in ("0,0 60 15,35", "0,0 60,0 a,b", "0,0 1,1"):
        with pytest.raises(PolygonError):
            parse_vertices(bad)


# --------------------------------------------------------------------------- normalisation

def test_clockwise_input_is_made_ccw_and_centred():
    cw = QUAD[::-1]
    assert shoelace(cw) < 0
    part = Part.from_vertices(cw, name="q")
    # Area of the quad by hand: shoelace terms 0 + 1500 + 1200 + 0 -> 1350.
    assert part.area == pytest.approx(1350.0, rel=1e-12)
    assert shoelace(part.vertices) == pytest.approx(1350.0, rel=1e-12)  # CCW
    np.testing.assert_allclose(centroid(part.vertices), [0.0, 0.0], atol=1e-10)
    # The outline is the input moved by its centroid, same vertices in CCW order.
    c = centroid(QUAD)
    assert same_cyclic_order(part.vertices, np.array(QUAD) - c)
    assert part.a == pytest.approx(np.linalg.norm(np.array(QUAD) - c, axis=1).max(), rel=1e-12)
    # Same part from either winding.
    ccw = Part.from_vertices(QUAD, name="q")
    assert same_cyclic_order(ccw.vertices, part.vertices)


def test_right_triangle_normalisation_by_hand():
    # Right triangle with legs 30 (x) and 40 (y): area 600, centroid (10, 40/3),
    # farthest vertex (0, 40) at sqrt(10^2 + (80/3)^2) from the centroid.
    part = Part.from_vertices([(0, 40), (30, 0), (0, 0)])  # clockwise on input
    assert part.area == pytest.approx(600.0)
    assert part.a == pytest.approx(math.hypot(10.0, 80.0 / 3.0))
    want = np.array([(0, 0), (30, 0), (0, 40)]) - np.array([10.0, 40.0 / 3.0])
    assert same_cyclic_order(part.vertices, want)


def test_rectangle_a_and_convexity(rectangle, v_notch, triangle):
    assert rectangle.a == pytest.approx(math.hypot(30.0, 10.0))
    assert rectangle.area == pytest.approx(1200.0)
    assert rectangle.is_convex and triangle.is_convex
    assert not v_notch.is_convex
    # The notch removes a triangle of base 30 and height 20 from a 60 x 30 block.
    assert v_notch.area == pytest.approx(60 * 30 - 0.5 * 30 * 20)


def test_vertices_are_read_only(triangle):
    with pytest.raises(ValueError):
        triangle.vertices[0, 0] = 1.0


def test_mirrored_scaled_rotated(quad):
    m = quad.mirrored()
    assert same_point_set(m.vertices, quad.vertices * [1.0, -1.0])
    assert shoelace(m.vertices) > 0
    assert m.area == pytest.approx(quad.area) and m.a == pytest.approx(quad.a)

    s = quad.scaled(2.5)
    assert same_cyclic_order(s.vertices, quad.vertices * 2.5)
    assert s.area == pytest.approx(quad.area * 6.25) and s.a == pytest.approx(quad.a * 2.5)

    phi = 37.0
    c, sn = math.cos(math.radians(phi)), math.sin(math.radians(phi))
    r = quad.rotated(phi)
    # Counter-clockwise rotation of the drawing: (x, y) -> (c x - s y, s x + c y).
    want = np.column_stack([c * quad.vertices[:, 0] - sn * quad.vertices[:, 1],
                            sn * quad.vertices[:, 0] + c * quad.vertices[:, 1]])
    assert same_cyclic_order(r.vertices, want)
    assert r.area == pytest.approx(quad.area) and r.a == pytest.approx(quad.a)


# --------------------------------------------------------------------------- identity

def test_id_is_stable_and_tracks_geometry():
    p1 = Part.from_vertices(TRIANGLE, name="tri")
    p2 = Part.from_vertices([list(v) for v in TRIANGLE], name="tri")
    assert p1.id == p2.id
    assert p1.id.startswith("tri")
    # The same outline drawn elsewhere normalises to the same geometry.
    shifted = Part.from_vertices(np.array(TRIANGLE) + [123.0, -45.0], name="tri")
    assert shifted.id == p1.id
    # Another name, or a changed outline, gives another id.
    assert Part.from_vertices(TRIANGLE, name="other").id != p1.id
    moved = [(0.0, 0.0), (60.0, 0.0), (15.0, 35.01)]
    assert Part.from_vertices(moved, name="tri").id != p1.id
    assert p1.scaled(2.0).id != p1.id
    assert p1.mirrored().id != p1.id


def test_id_is_the_same_in_a_fresh_process(triangle):
    code = ("from pipeline.parts.part import Part; "
            f"print(Part.from_vertices({TRIANGLE!r}, name='triangle').id)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         timeout=120, check=True).stdout.strip()
    assert out == triangle.id


# --------------------------------------------------------------------------- stable states

def _rows(part):
    rows = np.asarray(part.stable_states(), dtype=float)
    assert rows.ndim == 2 and rows.shape[1] == 2
    return rows[np.argsort(rows[:, 0])]


def _assert_states(part, want):
    got = _rows(part)
    want = np.array(sorted(want))
    assert got.shape == want.shape, (got, want)
    assert np.all(np.abs(circular_diff(got[:, 0], want[:, 0])) < 1e-7), (got, want)
    np.testing.assert_allclose(got[:, 1], want[:, 1], rtol=1e-9, atol=1e-9)


def test_stable_states_right_triangle():
    # Legs 30 along x and 40 along y, centroid (10, 40/3). All three edges hold
    # the part: the centroid projects inside each of them.
    # - leg on the x axis, part above: theta 0, y_c = 40/3
    # - leg on the y axis: turn +90 deg so the part (on +x) lies on +y: y_c = 10
    # - hypotenuse 4x + 3y = 120, outward normal (0.8, 0.6): turn it to (0, -1)
    #   with cos = -0.6, sin = -0.8: theta = 233.130 deg; y_c = |40 + 40 - 120| / 5 = 8
    part = Part.from_vertices([(0, 0), (30, 0), (0, 40)])
    _assert_states(part, [(0.0, 40.0 / 3.0), (90.0, 10.0),
                          (math.degrees(math.atan2(-0.8, -0.6)) % 360.0, 8.0)])


def test_stable_states_rectangle(rectangle):
    # 60 x 20 rectangle: long sides give y_c = 10, short sides y_c = 30.
    _assert_states(rectangle, [(0.0, 10.0), (90.0, 30.0), (180.0, 10.0), (270.0, 30.0)])


def test_stable_states_skip_edges_the_centroid_overhangs():
    # Obtuse triangle (0,0) (10,0) (40,10), centroid (50/3, 10/3): the centroid
    # projects outside the short edge (0,0)-(10,0), so only two states:
    # - edge (10,0)-(40,10), slope 1/3: theta = -atan(1/3); distance
    #   |x - 3y - 10| / sqrt(10) = (10/3) / sqrt(10)
    # - edge (40,10)-(0,0), direction 180 + atan(1/4): theta = 180 - atan(1/4);
    #   distance |x - 4y| / sqrt(17) = (10/3) / sqrt(17)
    part = Part.from_vertices([(0, 0), (10, 0), (40, 10)])
    _assert_states(part, [(360.0 - math.degrees(math.atan(1 / 3)), (10 / 3) / math.sqrt(10)),
                          (180.0 - math.degrees(math.atan(1 / 4)), (10 / 3) / math.sqrt(17))])


def test_stable_states_of_a_non_convex_part_use_the_hull():
    # A 40 x 20 block with a V-notch (apex (20, 10)) cut into its bottom: the
    # part rests on the hull edge that bridges the notch. Area 800 - 200 = 600,
    # centroid y = (800 * 10 - 200 * 10/3) / 600 = 110/9.
    part = Part.from_vertices([(0, 0), (20, 10), (40, 0), (40, 20), (0, 20)])
    yc = 110.0 / 9.0
    _assert_states(part, [(0.0, yc), (90.0, 20.0), (180.0, 20.0 - yc), (270.0, 20.0)])


def test_stable_states_v_notch_part(v_notch):
    # The V-notch block (60 x 30, notch in the +x face): its hull is the full
    # 60 x 30 rectangle; the centroid is on the mid-line y = 15 and at
    # x = (1800 * 30 - 300 * (40 + 60 + 60) / 3) / 1500 = 76/3 from the left face.
    xc = (1800 * 30 - 300 * (160 / 3)) / 1500
    _assert_states(v_notch, [(0.0, 15.0), (90.0, xc), (180.0, 15.0), (270.0, 60.0 - xc)])


def _independent_stable_states(vertices):
    """Stable hull edges by scipy's hull: (theta_deg, y_c) rows."""
    xy = np.asarray(vertices, dtype=float)
    c = centroid(xy)
    hull = ConvexHull(xy)
    h = xy[hull.vertices]  # counter-clockwise for 2-D hulls
    rows = []
    for j in range(len(h)):
        p, q = h[j] - c, h[(j + 1) % len(h)] - c
        e = q - p
        length = np.linalg.norm(e)
        t = -np.dot(p, e) / length**2
        if not (1e-9 < t < 1 - 1e-9):
            continue
        out_n = np.array([e[1], -e[0]]) / length
        theta = (-90.0 - math.degrees(math.atan2(out_n[1], out_n[0]))) % 360.0
        rows.append((theta, float(np.dot(p, out_n))))
    return rows


@st.composite
def star_polygons(draw):
    n = draw(st.integers(3, 8))
    base = np.arange(n) * 2 * np.pi / n
    jitter = np.array(draw(st.lists(st.floats(-0.3, 0.3), min_size=n, max_size=n))) * 2 * np.pi / n
    radii = np.array(draw(st.lists(st.floats(5.0, 40.0), min_size=n, max_size=n)))
    ang = base + jitter
    return np.column_stack([radii * np.cos(ang), radii * np.sin(ang)]) + draw(
        st.tuples(st.floats(-50, 50), st.floats(-50, 50)))


@given(star_polygons())
def test_stable_states_match_independent_hull_computation(xy):
    part = Part.from_vertices(xy)
    want = _independent_stable_states(xy)
    got = _rows(part)
    assert len(got) == len(want), (got, want)
    want = np.array(sorted(want))
    assert np.all(np.abs(circular_diff(got[:, 0], want[:, 0])) < 1e-6), (got, want)
    np.testing.assert_allclose(got[:, 1], want[:, 1], rtol=1e-9, atol=1e-9)
    # Physical check of each state: turned by theta, the part's lowest points
    # lie at -y_c below the centroid, on a flat edge the centroid projects into.
    for theta, yc in got:
        c, s = math.cos(math.radians(theta)), math.sin(math.radians(theta))
        world = part.vertices @ np.array([[c, -s], [s, c]]).T
        ymin = world[:, 1].min()
        assert ymin == pytest.approx(-yc, abs=1e-9)
        low = world[np.abs(world[:, 1] - ymin) < 1e-7 * part.a]
        assert len(low) >= 2
        assert low[:, 0].min() < 0.0 < low[:, 0].max()
