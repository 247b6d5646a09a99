"""Outline changes for design for feeding: closed-form areas, valid polygons, the limits."""
from __future__ import annotations

import math

import numpy as np
import pytest

from pipeline.planning.design.edits import (ChangeRefused, DesignGrid, OutlineChange, apply_change,
                                            candidate_changes, ccw_outline, changed_area, interior_angle,
                                            signed_area, touched_edges, wall_behind)

L_BRACKET = np.array([[0, 0], [50, 0], [50, 12], [18, 12], [18, 30], [0, 30]], dtype=float)
TRIANGLE = np.array([[0, 0], [60, 0], [15, 35]], dtype=float)


def removed(xy, new) -> float:
    return signed_area(xy) - signed_area(new)


@pytest.mark.parametrize("corner", [0, 1, 2])
@pytest.mark.parametrize("legs", [(3.0, 3.0), (5.0, 2.0)])
def test_chamfer_removes_half_s1_s2_sin_angle(corner, legs):
    new = apply_change(TRIANGLE, OutlineChange("chamfer", corner, legs))
    angle = interior_angle(TRIANGLE, corner)
    assert removed(TRIANGLE, new) == pytest.approx(0.5 * legs[0] * legs[1] * math.sin(angle), rel=1e-12)
    assert changed_area(TRIANGLE, OutlineChange("chamfer", corner, legs)) == pytest.approx(removed(TRIANGLE, new))
    assert len(new) == 4 and signed_area(new) > 0


def test_interior_angles_of_the_bracket_sum_to_the_polygon_rule():
    angles = [interior_angle(L_BRACKET, k) for k in range(6)]
    assert sum(angles) == pytest.approx((6 - 2) * math.pi)
    assert angles[3] == pytest.approx(1.5 * math.pi)  # the inner corner of the L


@pytest.mark.parametrize("kind,sign", [("notch", 1.0), ("tab", -1.0)])
@pytest.mark.parametrize("edge,at", [(0, 0.5), (0, 0.3), (2, 0.6), (5, 0.5)])
def test_notch_removes_and_tab_adds_w_times_h(kind, sign, edge, at):
    change = OutlineChange(kind, edge, (6.0, 4.0), at)
    new = apply_change(L_BRACKET, change)
    assert removed(L_BRACKET, new) == pytest.approx(sign * 24.0, rel=1e-12)
    assert len(new) == 10
    from pipeline.parts.part import check_outline
    check_outline(new)  # a simple polygon


def test_a_clockwise_outline_is_read_counter_clockwise_from_the_same_vertex():
    cw = L_BRACKET[::-1].copy()
    ccw = ccw_outline(cw)
    assert signed_area(ccw) > 0 and np.array_equal(ccw[0], cw[0])
    assert signed_area(ccw) == pytest.approx(signed_area(L_BRACKET))


def test_kept_edges_are_never_changed():
    grid = DesignGrid(chamfer=(0.1, 0.2), notch=((0.2, 0.1),), tab=((0.2, 0.1),))
    keep = {0, 2}
    allowed = []
    for change in candidate_changes(L_BRACKET, 30.0, grid):
        try:
            new = apply_change(L_BRACKET, change, keep_edges=keep)
        except ChangeRefused as exc:
            assert "kept" in str(exc) or "wall" in str(exc) or "fit" in str(exc) or "edge" in str(exc)
            continue
        assert not touched_edges(6, change) & keep
        allowed.append((change, new))
        # every kept edge is still an edge of the changed outline
        segments = {tuple(map(tuple, (p, q))) for p, q in zip(new, np.roll(new, -1, axis=0))}
        for k in keep:
            assert (tuple(L_BRACKET[k]), tuple(L_BRACKET[(k + 1) % 6])) in segments
    assert allowed
    with pytest.raises(ChangeRefused, match="edge 0, which is kept"):
        apply_change(L_BRACKET, OutlineChange("chamfer", 1, (2.0, 2.0)), keep_edges=[0])


def test_chamfers_only_at_convex_corners_and_never_a_whole_edge():
    changes = candidate_changes(L_BRACKET, 30.0, DesignGrid(kinds=("chamfer",), chamfer=(0.1,)))
    assert sorted(c.index for c in changes) == [0, 1, 2, 4, 5]  # corner 3 is the inner corner
    with pytest.raises(ChangeRefused, match="not convex"):
        apply_change(L_BRACKET, OutlineChange("chamfer", 3, (2.0, 2.0)))
    with pytest.raises(ChangeRefused, match="edge 1"):  # edge 1 is 12 mm long
        apply_change(L_BRACKET, OutlineChange("chamfer", 1, (11.5, 11.5)), min_wall=1.0)


def test_a_notch_leaves_the_minimum_wall():
    # a notch 8 mm deep into edge 0 (the foot is 12 mm high there) leaves a 4 mm wall.
    change = OutlineChange("notch", 0, (6.0, 8.0), 0.8)
    new = apply_change(L_BRACKET, change, min_wall=3.9)
    assert wall_behind(new, 2) == pytest.approx(4.0)  # behind the notch's bottom
    with pytest.raises(ChangeRefused, match="wall of 4 mm"):
        apply_change(L_BRACKET, change, min_wall=4.5)


def test_a_notch_through_the_part_is_not_a_simple_polygon():
    with pytest.raises(ChangeRefused, match="invalid outline"):
        apply_change(L_BRACKET, OutlineChange("notch", 0, (6.0, 14.0), 0.8))


def test_a_change_that_does_not_fit_its_edge_is_refused():
    with pytest.raises(ChangeRefused, match="does not fit"):
        apply_change(L_BRACKET, OutlineChange("tab", 1, (12.0, 2.0), 0.5))


def test_holes_stay_inside_the_changed_outline():
    square = np.array([[0, 0], [40, 0], [40, 40], [0, 40]], dtype=float)
    hole = np.array([[2, 2], [8, 2], [8, 8], [2, 8]], dtype=float)
    with pytest.raises(ChangeRefused, match="invalid outline"):
        apply_change(square, OutlineChange("chamfer", 0, (9.0, 9.0)), holes=[hole])
    assert len(apply_change(square, OutlineChange("chamfer", 2, (9.0, 9.0)), holes=[hole])) == 5
