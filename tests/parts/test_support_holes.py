"""Supports of parts with holes: the belt presses on the material only, so
every support point lies on it (inside the outline, in no hole).

- A given point in a hole is a one-line error naming the point and the hole;
  a point on a hole's rim is material and taken.
- ``tripod`` balances about the material's centroid; ``rim`` is the outline's
  rim only; ``filled`` tiles the material, holes left out, and its rollouts
  converge to uniform pressure's for a holed part (which differ clearly from
  the solid outline's: a filled support ignoring the hole would not).
- The families (``tripods``, ``warp``), the worst-member search's starts and
  the support fit's projection keep their points on the material.
"""
from __future__ import annotations

import numpy as np
import pytest
from hypothesis import assume, given
from hypothesis import strategies as st

import strategies as sts
from conftest import TRIANGLE, circular_diff, fewer_examples
from drawn_shapes import circle
from pipeline.errors import PinfeedError
from pipeline.maps import simulate
from pipeline.maps.support_fit import _into_outline
from pipeline.parts.part import Part, PolygonError
from pipeline.parts.support import (INSIDE_TOL, _ears, boundary_distance, filled_support,
                                    material_distance, material_triangles, parse_support,
                                    point_support, rim_support, tripod_support)
from pipeline.parts.support_family import parse_support_family, sample_tripods, sample_warps
from pipeline.planning.family.member_spaces import TripodSpace, inset_corners, member_space


OUTLINE = np.array([(0.0, 0.0), (60.0, 0.0), (60.0, 40.0), (0.0, 40.0)])
HOLE_1 = np.array([(34.0, 8.0), (52.0, 8.0), (52.0, 30.0), (34.0, 30.0)])  # big, off-centre
HOLE_2 = circle(12.0, 30.0, 4.0, 12)
PLATE = Part.from_vertices(OUTLINE, "plate", holes=[HOLE_1, HOLE_2])
SOLID = Part.from_vertices(OUTLINE, "plate")
SHIFT = PLATE.vertices[0] - OUTLINE[0]  # drawing frame -> the plate's part frame
# The triangle with an off-centre hole: its uniform rollouts differ from the
# solid triangle's by up to 12 degrees on the grid below.
TRI_HOLED = Part.from_vertices(TRIANGLE, "tri-hole", holes=[circle(26.0, 9.0, 7.0, 16)])
TRI_SOLID = Part.from_vertices(TRIANGLE, "tri")
R_PIN = 3.0


def _frame(xy):
    """Drawing-frame points in the plate's part frame (material centroid at the origin)."""
    return np.asarray(xy, float) + SHIFT


def _material_centroid():
    """The plate's material centroid in the drawing frame: the loops' first
    moments, the holes' with the opposite sign (each loop's shoelace)."""
    area, first = 0.0, np.zeros(2)
    for k, xy in enumerate([OUTLINE, HOLE_1, HOLE_2]):
        x, y = xy[:, 0], xy[:, 1]
        xn, yn = np.roll(x, -1), np.roll(y, -1)
        cr = x * yn - xn * y
        sign = -1.0 if k else 1.0  # every loop given counter-clockwise
        area += sign * cr.sum() / 2.0
        first += sign * np.array([((x + xn) * cr).sum(), ((y + yn) * cr).sum()]) / 6.0
    return first / area


def _hole_distance(part, xy):
    """Distance from each point to the nearest hole rim."""
    return np.min([boundary_distance(np.asarray(h), np.asarray(xy).reshape(-1, 2)) for h in part.holes],
                  axis=0)


def _text(xy):
    return "points:" + " ".join(f"{float(x)!r},{float(y)!r},1" for x, y in xy)


def test_the_plate_is_what_the_tests_assume():
    np.testing.assert_allclose(PLATE.vertices, OUTLINE + SHIFT, atol=1e-12)
    assert np.hypot(*SHIFT) > 2.0  # the hole moves the centroid by mm, not by rounding
    assert PLATE.area == pytest.approx(2400.0 - 18 * 22 - 0.5 * 12 * 16 * np.sin(2 * np.pi / 12))


# --------------------------------------------------------------------------- given points

@pytest.mark.parametrize("hole, centre", [(1, (43.0, 19.0)), (2, (12.0, 30.0)), (2, (14.5, 31.0))])
def test_a_given_point_in_a_hole_is_a_one_line_error_naming_the_point_and_the_hole(hole, centre):
    legs = _frame([(5.0, 5.0), (20.0, 35.0), centre])
    with pytest.raises(PinfeedError) as exc:
        parse_support(_text(legs), PLATE)
    msg = str(exc.value)
    assert "\n" not in msg
    assert msg.startswith(f"support point 2 ({legs[2, 0]:g}, {legs[2, 1]:g}) lies in hole {hole} of the part")
    assert "give points on the material" in msg
    with pytest.raises(PinfeedError, match=f"support point 2 .* lies in hole {hole} "):
        point_support(PLATE, legs, [1.0, 2.0, 3.0])
    # The same points on the solid plate are fine: the hole is the reason.
    assert point_support(SOLID, legs).n_points == 3


def test_the_first_point_off_the_material_is_named_outside_before_a_later_hole():
    legs = _frame([(5.0, 5.0), (-3.0, 20.0), (43.0, 19.0)])
    with pytest.raises(PinfeedError, match=r"support point 1 .* outside the outline"):
        point_support(PLATE, legs)
    legs = _frame([(43.0, 19.0), (-3.0, 20.0)])
    with pytest.raises(PinfeedError, match=r"support point 0 .* lies in hole 1"):
        point_support(PLATE, legs)


def test_points_on_a_hole_rim_are_material():
    rim = _frame([(34.0, 8.0), (43.0, 30.0), (34.0, 19.0), HOLE_2[3]])  # a corner, edge midpoints, a vertex
    just = _frame([(34.0 + 0.5 * INSIDE_TOL * PLATE.a, 19.0)])  # inside the hole by less than the tolerance
    sup = point_support(PLATE, np.vstack([rim, just, _frame([(5.0, 35.0)])]))
    assert sup.n_points == 6
    deep = _frame([(34.0 + 1e-6 * PLATE.a, 19.0)])
    with pytest.raises(PinfeedError, match="lies in hole 1"):
        point_support(PLATE, np.vstack([rim, deep]))


def test_material_distance_is_signed_by_the_holes():
    xy = _frame([(43.0, 19.0), (30.0, 19.0), (12.0, 30.0), (70.0, 20.0), (5.0, 5.0)])
    on, dist = material_distance(PLATE, xy)
    np.testing.assert_array_equal(on, [False, True, False, False, True])
    np.testing.assert_allclose(dist, [9.0, 4.0, 4.0 * np.cos(np.pi / 12), 10.0, 5.0], atol=1e-9)
    on_solid, dist_solid = material_distance(SOLID, xy - SHIFT + (SOLID.vertices[0] - OUTLINE[0]))
    np.testing.assert_array_equal(on_solid, [True, True, True, False, True])


# --------------------------------------------------------------------------- built supports

def test_tripod_stands_on_hull_vertices_and_balances_about_the_material_centroid():
    tri = tripod_support(PLATE)
    assert tri.n_points == 3
    assert all(np.min(np.hypot(*(PLATE.vertices - p).T)) < 1e-12 for p in tri.points)
    assert tri.pressure_offset < 1e-12 * PLATE.a  # statics about the origin: the material's centroid
    assert np.all(tri.weights >= 0)
    # In the drawing frame the centre of pressure is the material's centroid
    # (shoelace over the signed loops), 2 mm from the outline's centre.
    cop = tri.weights @ (tri.points - SHIFT)
    np.testing.assert_allclose(cop, _material_centroid(), atol=1e-9)
    assert np.hypot(*(cop - (30.0, 20.0))) > 2.0


def test_rim_is_the_outline_rim_only():
    rim = rim_support(PLATE, 40)
    assert np.all(boundary_distance(PLATE.vertices, rim.points) < 1e-9)
    assert _hole_distance(PLATE, rim.points).min() > 2.0
    solid = rim_support(SOLID, 40)
    mine, theirs = rim.points - PLATE.vertices[0], solid.points - SOLID.vertices[0]  # both from a corner
    mine, theirs = (p[np.lexsort(np.round(p, 9).T[::-1])] for p in (mine, theirs))
    np.testing.assert_allclose(mine, theirs, atol=1e-9)
    np.testing.assert_allclose(rim.weights, solid.weights)


def test_material_triangles_tile_the_material():
    tris = material_triangles(PLATE)
    cross = ((tris[:, 1, 0] - tris[:, 0, 0]) * (tris[:, 2, 1] - tris[:, 0, 1])
             - (tris[:, 1, 1] - tris[:, 0, 1]) * (tris[:, 2, 0] - tris[:, 0, 0]))
    assert np.all(cross > 0)
    assert 0.5 * cross.sum() == pytest.approx(PLATE.area, rel=1e-12)
    assert material_distance(PLATE, tris.mean(axis=1))[0].all()
    # No more triangles than a triangulation without extra points needs, here.
    n = len(PLATE.vertices) + sum(len(h) for h in PLATE.holes)
    assert len(tris) == n + 2 * len(PLATE.holes) - 2


def test_a_solid_part_fills_as_before():
    """The ear-clipping triangulation, to the bit (stored warp members do not move)."""
    verts = TRI_SOLID.vertices
    np.testing.assert_array_equal(material_triangles(TRI_SOLID),
                                  np.array([[verts[i], verts[j], verts[k]] for i, j, k in _ears(verts)]))


def test_filled_points_fill_the_material_and_balance():
    sup = filled_support(PLATE, 6)
    on, _ = material_distance(PLATE, sup.points)
    assert on.all()
    assert sup.pressure_offset < 1e-9 * PLATE.a  # the midpoint rule is exact for linear pressure
    # Polar second moment of the material per unit area: a hole off the
    # centroid changes it by a quarter; the filled points get it within 0.5 %.
    j_over_a = float(sup.weights @ np.sum(sup.points ** 2, axis=1))
    solid = filled_support(SOLID, 6)
    j_solid = float(solid.weights @ np.sum(solid.points ** 2, axis=1))
    j_exact = _plate_polar_moment() / PLATE.area
    assert j_over_a == pytest.approx(j_exact, rel=5e-3)
    assert abs(j_solid / j_exact - 1.0) > 0.05


def _plate_polar_moment() -> float:
    """Polar second moment of the plate's material about its centroid (shoelace, signed loops)."""
    def loop(xy):
        x, y = xy[:, 0], xy[:, 1]
        xn, yn = np.roll(x, -1), np.roll(y, -1)
        cr = x * yn - xn * y
        return (cr * (x * x + x * xn + xn * xn + y * y + y * yn + yn * yn)).sum() / 12.0
    return loop(PLATE.vertices) + sum(loop(np.asarray(h)) for h in PLATE.holes)  # holes clockwise: negative


@st.composite
def _holed_parts(draw):
    outline = draw(sts.star_polygons(min_n=3, max_n=14)) * 40.0
    holes = []
    for _ in range(draw(st.integers(1, 3))):
        hole = draw(sts.star_polygons(min_n=3, max_n=9))
        scale = draw(st.floats(0.5, 8.0))
        at = np.array([draw(st.floats(-25.0, 25.0)), draw(st.floats(-25.0, 25.0))])
        holes.append(hole * scale + at)
    try:
        return Part.from_vertices(outline, "p", holes=holes)
    except PolygonError:
        assume(False)


@fewer_examples(0.5)
@given(_holed_parts())
def test_any_holed_part_is_tiled_and_filled_on_its_material(part):
    tris = material_triangles(part)
    cross = ((tris[:, 1, 0] - tris[:, 0, 0]) * (tris[:, 2, 1] - tris[:, 0, 1])
             - (tris[:, 1, 1] - tris[:, 0, 1]) * (tris[:, 2, 0] - tris[:, 0, 0]))
    assert np.all(cross > 0) and 0.5 * cross.sum() == pytest.approx(part.area, rel=1e-9)
    sup = filled_support(part, 2)
    assert material_distance(part, sup.points)[0].all()
    assert sup.pressure_offset < 1e-9 * part.a


# --------------------------------------------------------------------------- rollouts

THETA = np.arange(0.0, 360.0, 45.0) + 0.37
D = (-0.5, 0.3)


def _points(part, support=None, mu=0.2):
    th = np.repeat(THETA, len(D))
    dd = np.tile(D, len(THETA))
    return simulate.rollout_points(part, th, dd, mu, R_PIN, support=support)


def test_filled_points_of_a_holed_part_converge_to_its_uniform_rollouts():
    """theta_f of 16 rollouts with n^2 points per triangle of the material
    against uniform pressure on the holed triangle: the gap shrinks about 4x
    per halving and is 0.1 degree at n = 8; the holed triangle's uniform
    rollouts differ from the solid one's by degrees (a fill over the whole
    outline would converge to those)."""
    uni = _points(TRI_HOLED)
    one = simulate.rollout(TRI_HOLED, THETA[1], D[1], 0.2, R_PIN)  # the batch is the public rollout
    assert float(one.theta_f) == pytest.approx(uni["theta_f"][3], abs=1e-9)
    solid = _points(TRI_SOLID)
    hole_effect = np.abs(circular_diff(uni["theta_f"], solid["theta_f"]))[uni["status"] == 0].max()
    gaps = []
    for n in (2, 4, 8):
        got = _points(TRI_HOLED, filled_support(TRI_HOLED, n))
        np.testing.assert_array_equal(got["status"], uni["status"])
        ok = uni["status"] == 0
        gaps.append(np.abs(circular_diff(got["theta_f"][ok], uni["theta_f"][ok])).max())
    assert gaps[2] < 0.15, gaps
    assert gaps[1] < 0.5 * gaps[0] and gaps[2] < 0.5 * gaps[1], gaps
    assert hole_effect > 5.0 and hole_effect > 30 * gaps[2], (hole_effect, gaps)


# --------------------------------------------------------------------------- families

def test_tripods_stand_on_the_material_away_from_every_rim():
    inset = 0.1
    members = sample_tripods(PLATE, 8, inset=inset, seed=3)
    assert len(members) == 8
    for m in members:
        on, dist = material_distance(PLATE, m.points)
        assert on.all() and dist.min() >= inset * PLATE.a * (1 - 1e-12)
        assert _hole_distance(PLATE, m.points).min() >= inset * PLATE.a * (1 - 1e-12)
        assert m.pressure_offset < 1e-9 * PLATE.a


def test_tripods_of_a_washer_step_over_the_hole_under_the_centroid():
    """A square frame: the centroid sits in the (diamond) hole, so the smallest
    leg triangles about it fall in the hole and are dropped."""
    washer = Part.from_vertices(circle(0.0, 0.0, 30.0, 4), "frame", holes=[circle(0.0, 0.0, 14.0, 4)])
    inside_hole = 14.0 / np.sqrt(2.0)  # the diamond's inscribed radius
    for m in sample_tripods(washer, 6, inset=0.05):
        on, dist = material_distance(washer, m.points)
        assert on.all() and np.hypot(*m.points.T).min() > inside_hole
        assert m.pressure_offset < 1e-9 * washer.a
    space = TripodSpace(washer, 0.05)
    starts = space.corners() + space.random(np.random.default_rng(0), 5)
    assert len(starts) >= 5 and all(space.violation(x) == 0.0 for x in starts)
    assert all(material_distance(washer, np.reshape(x, (3, 2)))[0].all() for x in starts)


def test_warp_members_are_the_material_s_pressure():
    members = sample_warps(PLATE, 0.8, 4, seed=1)
    for m in members:
        assert material_distance(PLATE, m.points)[0].all()
        assert m.pressure_offset < 1e-9 * PLATE.a
    base = filled_support(PLATE, 5)
    np.testing.assert_array_equal(members[0].points, base.points)


def test_a_family_list_on_a_holed_part_and_its_errors():
    fam = parse_support_family("tripods:3:inset=0.1; warp:0.5:3; tripod; rim:16", PLATE)
    assert len(fam) == 3 + 3 + 1 + 1
    for m in fam.members:
        assert material_distance(PLATE, m.points)[0].all() or np.all(
            boundary_distance(PLATE.vertices, m.points) < 1e-9)
    leg = _frame([(43.0, 19.0)])[0]
    with pytest.raises(PinfeedError, match="lies in hole 1") as exc:
        parse_support_family(f"tripod; points:0,0,1 {float(leg[0])!r},{float(leg[1])!r},1", PLATE)
    assert "\n" not in str(exc.value)


def test_worst_member_starts_leave_legs_in_holes_out():
    """A small hole at the plate's top-right corner swallows that corner's
    inset point; every start stands on the material, inset from every rim."""
    part = Part.from_vertices(OUTLINE, "corner-hole", holes=[circle(52.0, 32.0, 3.0, 12)])
    d = 0.2 * part.a
    plain = inset_corners(part.vertices, d)
    kept = inset_corners(part.vertices, d, part.holes)
    assert len(plain) == 4 and len(kept) == 3
    gone = [p for p in plain if not np.any(np.all(np.isclose(kept, p), axis=1))]
    assert not material_distance(part, np.array(gone))[0].any()  # it lay in the hole
    space = TripodSpace(part, 0.2)
    shift = part.vertices[0] - OUTLINE[0]
    in_hole = (np.array([(10.0, 10.0), (50.0, 10.0), (52.0, 32.0)]) + shift).ravel()
    assert space.violation(in_hole) > 0.0
    assert space.violation((np.array([(10.0, 10.0), (50.0, 10.0), (30.0, 30.0)]) + shift).ravel()) == 0.0
    starts = space.corners() + space.random(np.random.default_rng(1), 6)
    assert len(starts) >= 6
    for x in starts:
        on, dist = material_distance(part, np.reshape(x, (3, 2)))
        assert on.all() and dist.min() >= d * (1 - 1e-9)
    assert "material" in member_space(part, "tripods:4").describe()


def test_the_fit_s_search_moves_a_point_in_a_hole_onto_its_rim():
    pts = _frame([(5.0, 5.0), (40.0, 19.0), (12.0, 31.0), (70.0, 20.0)])
    moved_pts, moved = _into_outline(PLATE.vertices, pts, PLATE.holes)
    rim_2 = float(boundary_distance(np.asarray(PLATE.holes[1]), pts[2:3])[0])
    np.testing.assert_allclose(moved, [0.0, 6.0, rim_2, 10.0], atol=1e-9)
    np.testing.assert_allclose(moved_pts[0], pts[0])
    np.testing.assert_allclose(moved_pts[1], _frame([(34.0, 19.0)])[0], atol=1e-9)
    assert boundary_distance(np.asarray(PLATE.holes[1]), moved_pts[2:3])[0] < 1e-9
    np.testing.assert_allclose(moved_pts[3], _frame([(60.0, 20.0)])[0], atol=1e-9)
    assert point_support(PLATE, moved_pts).n_points == 4  # on the material's edge: taken
