"""Parts with holes: the material's integrals and rollouts.

For uniform pressure every integral over the material is the outline's
integral minus the holes' (an identity the kernels must keep whatever the
part), and min-power rollouts of holed parts agree with a brute-force
quadrature over the material (``tests/material_rollout.py``), which shares no
arithmetic with the kernels; the plate's big off-centre hole changes the
outcome by far more than the tolerance, so ignoring holes fails.
"""
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import reference as ref
from kernels.dynamic import _gyration
from kernels.geometry import _keyhole, _normalise_loops
from kernels.rollout import _prepare_loops
from kernels.support import _fan_quadrature, _support
from material_rollout import MaterialPart, material_rollout
from pipeline.maps.simulate import rollout
from pipeline.parts.part import Part, PolygonError


def _circle(cx, cy, r, n=24, clockwise=False):
    t = np.linspace(0.0, 2 * math.pi, n, endpoint=False)
    pts = np.column_stack([cx + r * np.cos(t), cy + r * np.sin(t)])
    return pts[::-1] if clockwise else pts


PLATE = [(0, 0), (80, 0), (80, 40), (0, 40)]
PLATE_HOLE = [(45, 6), (75, 6), (75, 34), (45, 34)]  # big and off-centre
BRACKET = [(0, 0), (50, 0), (50, 40), (0, 40)]
BRACKET_HOLES = [_circle(8, 8, 3.25, 16), _circle(42, 8, 3.25, 16),
                 [(15, 26), (35, 26), (35, 32), (15, 32)]]  # two mounting holes and a slot
TRIANGLE = [(0, 0), (60, 0), (15, 35)]
TRIANGLE_HOLES = [_circle(22, 10, 6, 20)]


@st.composite
def holed_polygons(draw):
    """A random star-shaped outline about the origin and 1 to 3 small holes
    strictly inside it (regular polygons of random size and place)."""
    n = draw(st.integers(3, 9))
    angles = np.sort(np.array(draw(st.lists(st.floats(0.0, 2 * math.pi), min_size=n, max_size=n,
                                            unique=True))))
    gaps = np.diff(np.r_[angles, angles[0] + 2 * math.pi])
    if np.min(gaps) < 0.2 or np.max(gaps) > 2.0:  # keep the origin well inside
        angles = np.linspace(0.0, 2 * math.pi, n, endpoint=False) + angles[0]
    radii = np.array(draw(st.lists(st.floats(0.6, 1.0), min_size=n, max_size=n)))
    outline = np.column_stack([radii * np.cos(angles), radii * np.sin(angles)])
    # The inscribed circle of a star polygon about the origin contains the disc of
    # radius r_in: holes inside r_in never touch the outline.
    e = np.roll(outline, -1, axis=0) - outline
    cross = outline[:, 0] * e[:, 1] - outline[:, 1] * e[:, 0]
    r_in = float(np.min(np.abs(cross) / np.hypot(*e.T)))
    holes = []
    k = draw(st.integers(1, 3))
    for j in range(k):
        ang = 2 * math.pi * j / k + draw(st.floats(0.0, 0.5))
        place = r_in * 0.55 * draw(st.floats(0.0, 1.0)) if k == 1 else r_in * 0.55
        size = r_in * draw(st.floats(0.05, 0.3)) * (1.0 if k == 1 else 0.6)
        holes.append(_circle(place * math.cos(ang), place * math.sin(ang), size,
                             draw(st.integers(3, 8)), clockwise=draw(st.booleans())))
    return outline, holes


def _stack(outline, holes):
    loops = [np.asarray(outline, float)] + [np.asarray(h, float) for h in holes]
    starts = np.concatenate([[0], np.cumsum([len(lp) for lp in loops])]).astype(np.int64)
    return np.ascontiguousarray(np.vstack(loops)), starts


def _ccw(xy):
    xy = np.asarray(xy, float)
    return np.ascontiguousarray(xy if ref.signed_area(xy) > 0 else xy[::-1])


@settings(max_examples=60, deadline=None)
@given(holed_polygons(), st.floats(-1.5, 1.5), st.floats(-1.5, 1.5))
def test_material_integrals_are_outline_minus_holes(polygon, rx, ry):
    """E, G, N over the material (the keyhole polygon of the kernels) equal
    the outline's minus each hole's, at any point r."""
    outline, holes = polygon
    xy, starts = _stack(outline, holes)
    loops, _, _ = _normalise_loops(xy, starts)
    got = np.array(_support(_keyhole(loops, starts), rx, ry))
    pieces = [np.array(_support(_ccw(loops[starts[k]:starts[k + 1]]), rx, ry))
              for k in range(len(starts) - 1)]
    want = pieces[0] - sum(pieces[1:])
    assert np.allclose(got, want, rtol=1e-10, atol=1e-11 * np.max(np.abs(pieces[0])))


@settings(max_examples=40, deadline=None)
@given(holed_polygons())
def test_area_centroid_and_inertia_leave_the_holes_out(polygon):
    outline, holes = polygon
    loops, area, a = _normalise_loops(*_stack(outline, holes))
    areas = [ref.signed_area(_ccw(outline))] + [-ref.signed_area(_ccw(h)) for h in holes]
    moments = [ref.signed_area(_ccw(outline)) * ref.centroid(_ccw(outline))]
    moments += [-ref.signed_area(_ccw(h)) * ref.centroid(_ccw(h)) for h in holes]
    assert area == pytest.approx(sum(areas), rel=1e-12)
    centroid = np.sum(moments, axis=0) / sum(areas)
    # The loops come back centred on the material's centroid.
    assert np.allclose(np.asarray(outline)[0] - centroid, loops[0], atol=1e-12) or \
        np.allclose(_ccw(outline) - centroid, loops[:len(outline)], atol=1e-12)
    assert a == pytest.approx(np.max(np.hypot(*(np.asarray(outline) - centroid).T)), rel=1e-12)
    # Polar moment about the centroid: outline's minus holes', each by the
    # brute-force fan rule about the material's centroid.

    def polar(xy):
        return ref.fan_integrate(_ccw(np.asarray(xy) - centroid), (0.0, 0.0),
                                 lambda wx, wy, dx, dy: (wx * wx + wy * wy)[None])[0]
    j = polar(outline) - sum(polar(h) for h in holes)
    _, _, _, quad, _, _ = _prepare_loops(*_stack(outline, holes))
    assert _gyration(quad, area / (a * a)) * a * a == pytest.approx(j / area, rel=1e-9)


@settings(max_examples=30, deadline=None)
@given(holed_polygons())
def test_fan_quadrature_integrates_over_the_material(polygon):
    outline, holes = polygon
    verts, area, a, quad, m_max, _ = _prepare_loops(*_stack(outline, holes))
    f = int(quad[-1, 0])
    x, y, w = quad[:f, 0], quad[:f, 1], quad[:f, 2]
    assert w.sum() == pytest.approx(area, rel=1e-12)
    assert abs((w * x).sum()) <= 1e-12 and abs((w * y).sum()) <= 1e-12  # the material's centroid
    # m_max = E(0) / A over the material: outline's E minus the holes'.
    loops, _, _ = _normalise_loops(*_stack(outline, holes))
    starts = _stack(outline, holes)[1]
    e0 = _support(_ccw(loops[:starts[1]] / a), 0.0, 0.0)[0]
    for k in range(1, len(starts) - 1):
        e0 -= _support(_ccw(loops[starts[k]:starts[k + 1]] / a), 0.0, 0.0)[0]
    assert m_max == pytest.approx(e0 / area, rel=1e-10)


def test_holes_change_the_part_and_its_id():
    solid = Part.from_vertices(PLATE, "plate")
    holed = Part.from_vertices(PLATE, "plate", holes=[PLATE_HOLE])
    assert holed.id != solid.id
    assert holed.area == pytest.approx(80 * 40 - 30 * 28)
    # Centroid moved left by the hole: the outline's vertices shift right.
    cx = (80 * 40 * 40 - 30 * 28 * 60) / (80 * 40 - 30 * 28)
    assert holed.vertices[0, 0] == pytest.approx(0 - cx)
    # The id does not depend on the holes' order, winding or first vertex.
    two = [PLATE_HOLE, [(5, 5), (15, 5), (10, 12)]]
    ids = {Part.from_vertices(PLATE, "p", holes=hs).id
           for hs in (two, two[::-1], [h[::-1] for h in two], [two[0][1:] + two[0][:1], two[1]])}
    assert len(ids) == 1


@pytest.mark.parametrize("holes, message", [
    ([[(70, 10), (90, 10), (80, 20)]], "the outline and hole 1 cross or touch"),
    ([[(0, 10), (10, 10), (10, 20), (0, 20)]], "the outline and hole 1 cross or touch"),
    ([[(100, 10), (110, 10), (105, 20)]], "hole 1 is not inside the outline"),
    ([[(10, 10), (40, 10), (40, 30), (10, 30)], [(20, 15), (30, 15), (25, 25)]], "hole 2 lies inside hole 1"),
    ([[(10, 10), (40, 10), (40, 30), (10, 30)], [(40, 10), (50, 10), (45, 20)]], "hole 1 and hole 2 cross or touch"),
    ([[(10, 10), (20, 10)]], "hole 1: a polygon needs at least 3 vertices"),
    ([[(10, 10), (20, 20), (20, 10), (10, 20)]], "hole 1: edges"),
])
def test_bad_holes_are_one_line_errors(holes, message):
    with pytest.raises(PolygonError) as err:
        Part.from_vertices(PLATE, "plate", holes=holes)
    text = str(err.value)
    assert message in text and "\n" not in text


def test_symmetry_order_counts_the_holes():
    square = [(-10, -10), (10, -10), (10, 10), (-10, 10)]
    assert Part.from_vertices(square, holes=[_circle(0, 0, 4, 8)]).symmetry_order() == 4
    assert Part.from_vertices(square, holes=[_circle(3, 0, 2, 8)]).symmetry_order() == 1
    two = [_circle(5, 0, 2, 8), _circle(-5, 0, 2, 8)]
    assert Part.from_vertices(square, holes=two).symmetry_order() == 2


def test_mirror_scale_rotate_keep_the_holes():
    part = Part.from_vertices(BRACKET, "bracket", holes=BRACKET_HOLES)
    for other in (part.mirrored(), part.scaled(2.0), part.rotated(30.0)):
        assert len(other.holes) == 3
    assert part.scaled(2.0).area == pytest.approx(4 * part.area)
    assert part.rotated(30.0).area == pytest.approx(part.area)


# ------------------------------------------------------------ rollouts vs brute force

# (outline, holes, theta_i, d, mu_c): mu 0 slides, 0.3 mostly sticks.
CASES = [
    ("plate", PLATE, [PLATE_HOLE], 100.0, -0.4, 0.0),
    ("plate", PLATE, [PLATE_HOLE], 200.0, 0.5, 0.3),
    ("bracket", BRACKET, BRACKET_HOLES, 20.0, 0.35, 0.2),
    ("triangle", TRIANGLE, TRIANGLE_HOLES, 100.0, -0.4, 0.0),
]
PIN_MM = 3.0
TOL_DEG = 0.6  # the grid quadrature's error (160 cells across) is ~0.2 deg on these parts
DY_TOL = 0.02  # units of a


@pytest.mark.parametrize("name, outline, holes, theta_i, d, mu_c", CASES)
def test_minpower_rollout_matches_brute_force_over_the_material(name, outline, holes, theta_i, d, mu_c):
    part = Part.from_vertices(outline, name, holes=holes)
    brute = MaterialPart(outline, holes, cells=160)
    assert brute.a == pytest.approx(part.a, rel=5e-3)
    status, theta_f, dy = material_rollout(brute, theta_i, d, mu_c, PIN_MM / part.a, ds=0.006)
    got = rollout(part, theta_i, d, mu_c, PIN_MM)
    assert str(got.status.values) == status == "ok"
    gap = (float(got.theta_f) - theta_f + 180.0) % 360.0 - 180.0
    assert abs(gap) <= TOL_DEG, (float(got.theta_f), theta_f)
    assert float(got.dy) / part.a == pytest.approx(dy, abs=DY_TOL)


def test_the_plate_hole_changes_the_outcome():
    """Ignoring the hole (the solid plate) misses the brute-force answer by far
    more than the tolerance: the comparison above would fail without holes."""
    part = Part.from_vertices(PLATE, "plate", holes=[PLATE_HOLE])
    solid = Part.from_vertices(PLATE, "plate")
    brute = MaterialPart(PLATE, [PLATE_HOLE], cells=160)
    _, theta_f, _ = material_rollout(brute, 100.0, -0.4, 0.0, PIN_MM / part.a, ds=0.006)
    wrong = float(rollout(solid, 100.0, -0.4, 0.0, PIN_MM).theta_f)
    assert abs((wrong - theta_f + 180.0) % 360.0 - 180.0) > 10 * TOL_DEG
