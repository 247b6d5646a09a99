"""Support distributions through the public API and the CLI (issue 25, phase 1).

- Points filling the area converge to the uniform support (rollouts agree
  ever closer as the points get finer: the midpoint rule, second order).
- ``rim`` points lie on the outline and ``tripod`` weights hold the part in
  equilibrium (centre of pressure at the centroid).
- Mirror invariance holds for a point support (mirrored with the part).
- The default (no support, or ``"uniform"``) gives the same arrays and
  attributes as before; a point support is named in the attributes.
- Bad input is a one-line ``PinfeedError`` (API) and exit status 2 (CLI).
"""
from __future__ import annotations

import json

import numpy as np
import pytest

import strategies as sts
from cli_runs import run_cli as run
from conftest import TRIANGLE, V_NOTCH, circular_diff, fewer_examples
from hypothesis import given
from hypothesis import strategies as st
from pipeline.errors import PinfeedError
from pipeline.maps import simulate
from pipeline.parts.part import Part
from pipeline.parts.support import (UNIFORM, filled_support, parse_support, point_support,
                                    rim_support, tripod_support)

PART = Part.from_vertices(TRIANGLE, name="tri")
R_PIN = 3.0
THETA = np.arange(0.0, 360.0, 45.0) + 0.37
D = (-0.5, 0.3)


def _points(support, part=PART, mu=0.2):
    th = np.repeat(THETA, len(D))
    dd = np.tile(D, len(THETA))
    return simulate.rollout_points(part, th, dd, mu, R_PIN, support=support)


def test_filled_points_converge_to_uniform():
    """theta_f of 16 rollouts with n^2 points per triangle against uniform
    pressure: the largest gap shrinks with n (about 4x per halving) and is
    below 0.1 degree at n = 16 (256 points); statuses agree."""
    uni = _points(None)
    gaps = []
    for n in (4, 8, 16):
        got = _points(filled_support(PART, n))
        np.testing.assert_array_equal(got["status"], uni["status"])
        gaps.append(np.abs(circular_diff(got["theta_f"], uni["theta_f"])).max())
    assert gaps[2] < 0.1, gaps
    assert gaps[2] < gaps[1] < gaps[0], gaps
    assert gaps[1] < 0.5 * gaps[0] and gaps[2] < 0.5 * gaps[1], gaps


def test_filled_points_of_a_non_convex_part_converge_too():
    """The V-notch block (ear-clipped): 12^2 points per triangle within 0.2
    degree of uniform."""
    part = Part.from_vertices(V_NOTCH, name="v")
    uni = _points(None, part)
    got = _points(filled_support(part, 12), part)
    ok = (uni["status"] == 0) & (got["status"] == 0)
    assert ok.sum() >= 10
    assert np.abs(circular_diff(got["theta_f"][ok], uni["theta_f"][ok])).max() < 0.2


def test_rim_points_lie_on_the_outline_and_tripod_balances():
    rim = rim_support(PART, 40)
    verts = PART.vertices
    edges = np.roll(verts, -1, axis=0) - verts
    for p in rim.points:
        rel = p - verts
        cross = np.abs(rel[:, 0] * edges[:, 1] - rel[:, 1] * edges[:, 0]) / np.hypot(*edges.T)
        assert cross.min() < 1e-9
    assert rim.n_points == 40 and abs(rim.weights.sum() - 1.0) < 1e-12
    quad = Part.from_vertices([(0, 0), (50, 0), (60, 30), (10, 25)], name="q")
    tri = tripod_support(quad)
    assert tri.n_points == 3 and np.all(tri.weights > 0)
    assert tri.pressure_offset < 1e-9  # centre of pressure at the centroid (statics)
    assert filled_support(PART, 6).pressure_offset < 1e-9


def test_mirror_invariance_with_a_point_support():
    """Mirroring the part and its support, negating d and theta_i negates theta_f."""
    pts = np.array([[-10.0, -5.0], [12.0, -6.0], [0.0, 9.0]])
    w = np.array([1.0, 2.0, 1.5])
    sup = point_support(PART, pts, w)
    mir = PART.mirrored()
    sup_m = point_support(mir, pts * [1.0, -1.0], w)
    a = simulate.rollout_points(PART, THETA, 0.3, 0.2, R_PIN, support=sup)
    b = simulate.rollout_points(mir, -THETA, -0.3, 0.2, R_PIN, support=sup_m)
    ok = a["status"] == 0
    assert ok.sum() >= 6
    assert np.abs(circular_diff(b["theta_f"][ok], -a["theta_f"][ok])).max() < 0.05
    np.testing.assert_allclose(b["dy"][ok], -a["dy"][ok], atol=0.05)


def test_default_outputs_unchanged_and_point_support_named():
    base = simulate.compute_map(PART, THETA, D, 0.2, R_PIN, threads=1)
    same = simulate.compute_map(PART, THETA, D, 0.2, R_PIN, threads=1, support="uniform")
    for name in base.data_vars:
        np.testing.assert_array_equal(base[name].values, same[name].values)
    assert set(base.attrs) == set(same.attrs)
    assert not any(k.startswith("support") for k in base.attrs)
    pts = simulate.compute_map(PART, THETA, D, 0.2, R_PIN, threads=1, support="tripod")
    assert pts.attrs["support"] == "tripod" and pts.attrs["support_kind"] == "tripod"
    assert pts.attrs["support_points"].shape == (6,)
    one = simulate.rollout(PART, THETA[1], D[1], 0.2, R_PIN, support="tripod")
    assert float(one.theta_f) == pytest.approx(float(pts.theta_f.values[1, 1]), abs=1e-9)
    assert not np.array_equal(pts.theta_f.values, base.theta_f.values)


@pytest.mark.parametrize("spec, words", [
    ("points:", "no points"),
    ("points:40,0,1", "outside the outline"),
    ("points:0,0,-1 1,1,1", "weight -1 < 0"),
    ("points:0,0,0 1,1,0", "every weight is zero"),
    ("points:0,0,nan", "not finite"),
    ("points:0;0", "is not 'x,y'"),
    ("wobble", "unknown support"),
    ("rim:2", "rim support needs"),
    ("rim:x", "whole number"),
])
def test_bad_support_is_a_one_line_error(spec, words):
    with pytest.raises(PinfeedError) as exc:
        simulate.rollout(PART, 0.0, 0.3, 0.2, R_PIN, support=spec)
    msg = str(exc.value)
    assert words in msg and "\n" not in msg


def test_point_support_needs_minpower():
    for model in ("tip", "ellipsoid"):
        with pytest.raises(PinfeedError, match="needs model minpower"):
            simulate.compute_map(PART, THETA, D, 0.2, R_PIN, model=model, support="tripod")
    with pytest.raises(PinfeedError, match="needs model minpower"):
        simulate.rollout(PART, 0.0, 0.3, 0.2, R_PIN, model="dynamic", belt_speed=100.0,
                         support="tripod")
    with pytest.raises(PinfeedError, match="no points"):
        point_support(PART, np.zeros((0, 2)))
    assert parse_support(None, PART) is UNIFORM and parse_support("uniform", PART).is_uniform


def test_support_checked_against_the_part_it_is_used_with():
    big = Part.from_vertices([(0, 0), (200, 0), (50, 120)], name="big")
    sup = point_support(big, [[30.0, -20.0], [0.0, 0.0]])
    with pytest.raises(PinfeedError, match="outside the outline"):
        simulate.rollout_points(PART, THETA, 0.3, 0.2, R_PIN, support=sup)


def test_cli_rollout_with_point_support_and_errors(capsys):
    base = ["rollout", "--vertices", "0,0 60,0 15,35", "--d", "0.3", "--mu-c", "0.2",
            "--pin-radius", "3", "--theta-i", "0,90", "--json"]
    code, out, err = run(capsys, base + ["--support", "points:-10,-5,1 10,-5,1 0,8,2"])
    assert code == 0, err
    rows = json.loads(out)
    ref = simulate.rollout(PART, 90.0, 0.3, 0.2, R_PIN,
                           support="points:-10,-5,1 10,-5,1 0,8,2")
    assert rows[1]["theta_f"] == pytest.approx(float(ref.theta_f), abs=1e-9)
    code, out, err = run(capsys, base + ["--support", "points:60,0,1"])
    assert code == 2 and "outside the outline" in err and err.count("\n") == 1
    code, out, err = run(capsys, base + ["--support", "tripod", "--model", "tip"])
    assert code == 2 and "needs model minpower" in err


@pytest.mark.parametrize("support", ["tripod", "points:-12,-8,3 15,-9,1 -6,12,1"])
def test_point_support_rollouts_converge_in_the_step(support):
    """Spec section 4 for a point support, whose power has kinks (pivots):
    tightening the step control 1000x (tol 1e-7 -> 1e-10, ds_max 0.1 -> 0.02)
    moves theta_f by less than 0.05 degree, statuses equal."""
    th = np.arange(0.0, 360.0, 15.0) + 0.37
    a = simulate.compute_map(PART, th, D, 0.4, R_PIN, threads=1, support=support)
    b = simulate.compute_map(PART, th, D, 0.4, R_PIN, threads=1, support=support, tol=1e-10,
                             ds_max=0.02)
    np.testing.assert_array_equal(a.status.values, b.status.values)
    ok = a.status.values == 0
    assert ok.sum() >= 30
    assert np.abs(circular_diff(a.theta_f.values[ok], b.theta_f.values[ok])).max() < 0.05


@pytest.mark.parametrize("weights, theta_i", [([8, 1, 1], 60.0), ([1, 8, 1], 300.0),
                                              ([1, 1, 8], 200.0)])
def test_rollout_pivots_about_a_heavy_support_point(weights, theta_i):
    """A rollout over a support with one heavy point turns about that point
    for tens of degrees: over those steps the point stays put in the belt
    frame (less than 1e-6 mm a step, the exact kink; a smoothed or inexact
    solve would let it creep) while the part turns."""
    pts = np.array([[-12.0, -8.0], [15.0, -9.0], [-6.0, 12.0]])
    sup = point_support(PART, pts, weights)
    ds = simulate.rollout(PART, theta_i, 0.3, 0.2, R_PIN, support=sup, trajectory=True)
    assert ds.status.item() == "ok"
    x, y, th = ds.traj_x.values, ds.traj_y.values, np.radians(ds.traj_theta.values)
    p = pts[int(np.argmax(weights))]
    px = x + np.cos(th) * p[0] - np.sin(th) * p[1]
    py = y + np.sin(th) * p[0] + np.cos(th) * p[1]
    moved = np.hypot(np.diff(px), np.diff(py))
    turned = np.abs(np.diff(th))
    pivot = (moved < 1e-6) & (turned > 1e-4)
    assert np.degrees(turned[pivot].sum()) > 40.0


def test_cli_map_with_a_support_stores_it(capsys, tmp_path):
    import xarray as xr
    out = tmp_path / "m.h5"
    code, _, err = run(capsys, ["map", "--vertices", "0,0 60,0 15,35", "--mu-c", "0.2",
                                "--pin-radius", "3", "--d", "0.3", "--theta-step", "90",
                                "--support", "rim:8", "--out", str(out)])
    assert code == 0, err
    with xr.open_dataset(out) as ds:
        assert ds.attrs["support"] == "rim:8"
        assert ds.attrs["support_points"].shape == (16,)
        np.testing.assert_allclose(ds.attrs["support_weights"], np.full(8, 0.125))


@fewer_examples(0.3)
@given(sts.star_polygons(), st.floats(1.05, 3.0), st.floats(0.0, 2 * np.pi))
def test_points_inside_any_outline_are_taken_and_outside_refused(xy, far, ang):
    """Random (mostly non-convex) outlines: the centroids of the triangles of
    the outline's triangulation (``filled_support(part, 1)``) are inside and
    taken; a point beyond every vertex is refused in one line that names it."""
    part = Part.from_vertices(np.asarray(xy) * 40.0, name="p")
    inside = filled_support(part, 1).points
    sup = point_support(part, inside, np.arange(1.0, len(inside) + 1.0))
    assert sup.n_points == len(inside) and abs(sup.weights.sum() - 1.0) < 1e-12
    outside = far * part.a * np.array([np.cos(ang), np.sin(ang)])
    with pytest.raises(PinfeedError) as exc:
        point_support(part, np.vstack([inside, outside]))
    assert f"point {len(inside)} " in str(exc.value) and "\n" not in str(exc.value)


def test_supports_compare_by_value():
    a = parse_support("points:0,0,1 5,2,3", PART)
    b = point_support(PART, [[5.0, 2.0], [0.0, 0.0]], [3.0, 1.0])
    assert a == b and hash(a) == hash(b) and len({a, b, UNIFORM}) == 2
    assert a != parse_support("points:0,0,1 5,2,2", PART)
