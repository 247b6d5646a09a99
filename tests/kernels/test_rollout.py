"""Single rollouts and grids: convergence, statuses, trajectory, forces,
determinism and parameter checks (spec section 4).

Expected values are physical or hand-derived (see comments); nothing here is
copied from a previous run of the code.
"""
from __future__ import annotations

import math
import time

import numpy as np
import pytest
import xarray as xr

from conftest import QUAD, RECTANGLE, TRIANGLE, circular_diff
from pipeline.errors import PinfeedError
from pipeline.maps import simulate
from pipeline.parts.part import Part

R_PIN = 3.0
STATUS = {name: code for code, name in enumerate(simulate.STATUSES)}


def _jam_code(ds, name):
    return ds.jam_reason.attrs["flag_meanings"].split().index(name)


# --------------------------------------------------------------------------- convergence

CONV_THETA = np.arange(0.0, 360.0, 1.5) + 0.37
CONV_D = np.array([-0.8, -0.5, -0.2, 0.2, 0.5, 0.8])
JUMP_PROBE = 0.05  # degrees of theta_i either side of a suspect point


def _is_band_jump(part, theta_i, d, mu_c, model):
    """True when theta_f jumps near (theta_i, d): rollouts 0.05 deg either side
    (at the finer setting) end more than 0.5 deg apart, or in other statuses."""
    probe = simulate.compute_map(part, [theta_i - JUMP_PROBE, theta_i + JUMP_PROBE], [d], mu_c, R_PIN,
                                 model=model, ds_max=0.05, tol=1e-7 / 32)
    s = probe.status.values[0]
    t = probe.theta_f.values[0]
    return bool(s[0] != s[1] or abs(circular_diff(t[0], t[1])) > 0.5)


@pytest.mark.parametrize("model", ["minpower", "ellipsoid", "tip"])
@pytest.mark.parametrize("mu_c", [0.0, 0.3])
@pytest.mark.parametrize("outline", [pytest.param(TRIANGLE, id="triangle"),
                                     pytest.param(QUAD, id="quad")])
def test_theta_f_converges_under_step_halving(outline, mu_c, model):
    part = Part.from_vertices(outline)
    base = simulate.compute_map(part, CONV_THETA, CONV_D, mu_c, R_PIN, model=model, ds_max=0.1, tol=1e-7)
    fine = simulate.compute_map(part, CONV_THETA, CONV_D, mu_c, R_PIN, model=model, ds_max=0.05,
                                tol=1e-7 / 32)
    # The step settings must reach the integrator (else this test is empty).
    assert not np.array_equal(base.theta_f.values, fine.theta_f.values)
    ok = base.status.values == STATUS["ok"]
    assert ok.mean() > 0.5  # most of the grid makes contact
    dth = np.abs(circular_diff(base.theta_f.values, fine.theta_f.values))
    ddy = np.abs(base.dy.values - fine.dy.values)
    bad = (dth > 0.05) | (ddy > 0.05) | (base.status.values != fine.status.values)
    assert bad.mean() <= 0.02, f"{bad.sum()} of {bad.size} points moved under step halving"
    for i, j in zip(*np.nonzero(bad)):
        assert _is_band_jump(part, CONV_THETA[j], CONV_D[i], mu_c, model), (
            f"theta_i={CONV_THETA[j]} d={CONV_D[i]}: theta_f {base.theta_f.values[i, j]:.4f} vs "
            f"{fine.theta_f.values[i, j]:.4f} with no band jump nearby")


def test_band_jump_probe(triangle):
    # The probe above must tell a jump from a smooth stretch. For the triangle
    # at d = 0.3, mu_c = 0.2, theta_f leaps from about 32 to about 150 degrees
    # near theta_i = 33.8 (the part tips over to the other side of the pin);
    # at theta_i = 30 the map is smooth.
    assert _is_band_jump(triangle, 33.835, 0.3, 0.2, "minpower")
    assert not _is_band_jump(triangle, 30.0, 0.3, 0.2, "minpower")


# --------------------------------------------------------------------------- miss

@pytest.mark.parametrize("outline", [TRIANGLE, QUAD, RECTANGLE], ids=["triangle", "quad", "rectangle"])
def test_far_pin_misses(outline):
    # Nothing of the part is farther than a from the centroid, so a pin with
    # |y_p - y_c| > a + r_pin can never touch it.
    part = Part.from_vertices(outline)
    d_far = 1.01 * (1.0 + R_PIN / part.a)
    theta = np.arange(0.0, 360.0, 7.5)
    m = simulate.compute_map(part, theta, [-d_far, d_far, -2.0, 3.0], 0.2, R_PIN)
    assert np.all(m.status.values == STATUS["miss"])
    assert np.all(np.abs(circular_diff(m.theta_f.values, theta[None, :])) < 1e-9)
    assert np.all(m.dy.values == 0.0)
    assert np.all(m.contact_travel.values == 0.0)
    assert np.all(m.peak_force.values == 0.0)
    assert np.all(m.feature_changes.values == 0)
    one = simulate.rollout(part, 123.0, -d_far, 0.2, R_PIN)
    assert one.status.item() == "miss"
    assert float(one.theta_f) == pytest.approx(123.0)
    assert float(one.dy) == 0.0


@pytest.mark.parametrize("theta_i, half_width", [(0.0, 10.0), (180.0, 10.0), (90.0, 30.0)])
@pytest.mark.parametrize("sign", [1.0, -1.0])
def test_miss_boundary_of_a_rectangle(rectangle, theta_i, half_width, sign):
    # The 60 x 20 rectangle turned by theta_i spans y_c +- half_width across
    # the belt; the pin (radius 3) touches it iff |y_p - y_c| < half_width + 3.
    reach = half_width + R_PIN
    near = simulate.rollout(rectangle, theta_i, sign * (reach - 0.2) / rectangle.a, 0.2, R_PIN)
    far = simulate.rollout(rectangle, theta_i, sign * (reach + 0.2) / rectangle.a, 0.2, R_PIN)
    assert far.status.item() == "miss"
    assert near.status.item() != "miss"
    assert float(near.contact_travel) > 0.0
    assert float(near.peak_force) > 0.0


# --------------------------------------------------------------------------- jams

@pytest.mark.parametrize("model", ["minpower", "tip", "ellipsoid"])
@pytest.mark.parametrize("theta_i", [0.0, 90.0, 180.0, 270.0])
def test_rectangle_hit_squarely_is_held(rectangle, warm_kernels, theta_i, model):
    # d = 0 on a face: the pin force passes through the centroid, so the part
    # translates without turning (every model); with mu_c > 0 it sticks and the
    # pin simply holds it while the belt slides under it: jammed, "no rotation",
    # declared after 3 a of pin travel (plus at most one step of 0.1 a).
    t0 = time.perf_counter()
    ds = simulate.rollout(rectangle, theta_i, 0.0, 0.2, R_PIN, model=model, trajectory=True)
    assert time.perf_counter() - t0 < 5.0
    assert ds.status.item() == "jammed"
    assert ds.jam_reason.item() == "no rotation"
    assert abs(circular_diff(float(ds.theta_f), theta_i)) < math.degrees(1e-5)
    assert abs(float(ds.dy)) < 1e-6
    a = rectangle.a
    assert 3.0 * a - 1e-9 <= float(ds.contact_travel) <= 3.1 * a + 1e-9
    # Pure translation: the pin carries the belt's full sliding friction (1 in
    # units of mu_s m g), straight downstream.
    push = np.hypot(ds.force_x.values, ds.force_y.values) > 0
    np.testing.assert_allclose(ds.force_x.values[push], 1.0, atol=1e-9)
    np.testing.assert_allclose(ds.force_y.values[push], 0.0, atol=1e-9)
    assert float(ds.peak_force) == pytest.approx(1.0, abs=1e-9)
    # Held by the pin, the part falls behind the belt by the pin travel.
    assert ds.traj_x.values[-1] == pytest.approx(-float(ds.contact_travel), rel=1e-9)


@pytest.mark.parametrize("mu_c", [0.0, 0.3])
@pytest.mark.parametrize("d", [0.0, 0.05, 0.1, -0.1])
def test_pin_entering_a_v_notch_jams(v_notch, warm_kernels, d, mu_c):
    # The pin runs head-on into the V-notch cut in the part's downstream face
    # (notch mouth spans |y| < 15 mm, apex 20 mm deep): it ends touching both
    # flanks at once and the part is caught.
    t0 = time.perf_counter()
    ds = simulate.rollout(v_notch, 0.0, d, mu_c, R_PIN)
    assert time.perf_counter() - t0 < 5.0
    assert ds.status.item() == "jammed"
    assert ds.jam_reason.item() == "notch"
    # Caught inside the notch: the part barely turned or moved across.
    assert abs(circular_diff(float(ds.theta_f), 0.0)) < 30.0
    assert abs(float(ds.dy)) < 15.0
    assert float(ds.contact_travel) < 20.0


@pytest.mark.parametrize("outline", [TRIANGLE, QUAD, RECTANGLE], ids=["triangle", "quad", "rectangle"])
def test_convex_parts_never_jam_in_a_notch(outline):
    # A convex part has no notch: the pin on a vertex must not count as two
    # simultaneous contacts.
    part = Part.from_vertices(outline)
    m = simulate.compute_map(part, np.arange(0.0, 360.0, 3.0), [-0.6, -0.3, -0.1, 0.1, 0.3, 0.6], 0.3, R_PIN)
    assert not np.any(m.jam_reason.values == _jam_code(m, "notch"))
    assert np.all(m.status.values != STATUS["jammed"])


# --------------------------------------------------------------------------- truncation

def test_max_travel_truncates_at_the_same_state(triangle):
    full = simulate.rollout(triangle, 30.0, 0.3, 0.2, R_PIN, trajectory=True)
    assert full.status.item() == "ok"
    k = full.sizes["step"] // 2
    cap = float(full.traj_s[k])
    assert 0.0 < cap < float(full.contact_travel)
    cut = simulate.rollout(triangle, 30.0, 0.3, 0.2, R_PIN, max_travel=cap, trajectory=True)
    assert cut.status.item() == "truncated"
    assert float(cut.contact_travel) == pytest.approx(cap, rel=1e-9)
    # Stopping early does not change the motion up to the cap.
    assert abs(circular_diff(float(cut.theta_f), float(full.traj_theta[k]))) < 1e-6
    assert float(cut.dy) == pytest.approx(float(full.traj_y[k]), abs=1e-6)
    assert float(cut.traj_s[-1]) == pytest.approx(cap, rel=1e-9)
    # A cap beyond the end of contact changes nothing.
    long = simulate.rollout(triangle, 30.0, 0.3, 0.2, R_PIN, max_travel=10 * float(full.contact_travel))
    assert long.status.item() == "ok"
    assert float(long.theta_f) == float(full.theta_f)
    assert float(long.dy) == float(full.dy)


def test_small_max_travel_truncates_in_a_map(triangle):
    m = simulate.compute_map(triangle, np.arange(0.0, 360.0, 30.0), [0.3, -0.3], 0.2, R_PIN, max_travel=0.5)
    hit = m.status.values != STATUS["miss"]
    assert hit.any()
    assert np.all(m.status.values[hit] == STATUS["truncated"])
    assert np.all(m.contact_travel.values <= 0.5 + 1e-9)


# --------------------------------------------------------------------------- trajectory

@pytest.mark.parametrize("outline, theta_i, d, mu_c", [
    (TRIANGLE, 30.0, 0.3, 0.2),
    (QUAD, 200.0, -0.5, 0.0),
    (RECTANGLE, 0.0, -0.3, 0.2),  # turns clockwise through 0: checks the unwrapping
    (RECTANGLE, 350.0, 0.3, 0.5),  # turns counter-clockwise through 360
])
def test_trajectory_is_consistent_with_the_result(outline, theta_i, d, mu_c):
    part = Part.from_vertices(outline)
    ds = simulate.rollout(part, theta_i, d, mu_c, R_PIN, trajectory=True)
    assert ds.status.item() == "ok"
    s, x, y, th = (ds[v].values for v in ("traj_s", "traj_x", "traj_y", "traj_theta"))
    np.testing.assert_allclose([s[0], x[0], y[0], th[0]], [0.0, 0.0, 0.0, theta_i], atol=1e-12)
    assert np.all(np.diff(s) >= 0.0)
    # Unwrapped: no 360-degree leaps between steps.
    assert np.all(np.abs(np.diff(th)) < 30.0)
    assert abs(circular_diff(th[-1], float(ds.theta_f))) < 1e-9
    assert y[-1] == pytest.approx(float(ds.dy), abs=1e-12)
    # A convex part is in contact over one stretch of belt travel.
    assert s[-1] == pytest.approx(float(ds.contact_travel), rel=1e-9)
    # Without trajectory=True the result is the same.
    plain = simulate.rollout(part, theta_i, d, mu_c, R_PIN)
    assert float(plain.theta_f) == float(ds.theta_f)
    assert float(plain.dy) == float(ds.dy)
    assert "traj_theta" not in plain


def test_trajectory_crossing_zero_is_unwrapped(rectangle):
    # The rectangle at theta 0 with the pin below its centroid turns clockwise
    # (see test_dy_sign_follows_the_pin_side): the unwrapped angle goes negative
    # while theta_f is reported in [0, 360).
    ds = simulate.rollout(rectangle, 0.0, -0.3, 0.2, R_PIN, trajectory=True)
    assert ds.traj_theta.values[-1] < -10.0
    assert 180.0 < float(ds.theta_f) < 360.0


# --------------------------------------------------------------------------- forces

@pytest.mark.parametrize("model", ["minpower", "tip", "ellipsoid"])
@pytest.mark.parametrize("mu_c", [0.0, 0.2, 0.6])
@pytest.mark.parametrize("outline", [TRIANGLE, QUAD], ids=["triangle", "quad"])
def test_force_on_the_pin(outline, mu_c, model):
    part = Part.from_vertices(outline)
    n_ok = 0
    for theta_i in range(0, 360, 30):
        for d in (-0.6, -0.3, 0.3, 0.6):
            ds = simulate.rollout(part, theta_i, d, mu_c, R_PIN, model=model, trajectory=True)
            if ds.status.item() != "ok":
                continue
            n_ok += 1
            fs, fx, fy = ds.force_s.values, ds.force_x.values, ds.force_y.values
            mag = np.hypot(fx, fy)
            pushing = mag > 0.0
            assert pushing.any()
            # The pin only pushes: the part drags it downstream (+x).
            assert np.all(fx[pushing] > 0.0), (theta_i, d, fx[pushing].min())
            # Contact over: no force at the end.
            assert fx[-1] == 0.0 and fy[-1] == 0.0
            assert np.all(np.diff(fs) >= 0.0)
            assert fs[-1] == pytest.approx(ds.traj_s.values[-1], rel=1e-12)
            assert float(ds.peak_force) == pytest.approx(mag.max(), rel=1e-12)
            # The pin balances the belt friction, which is at most mu_s m g (= 1).
            assert mag.max() <= 1.0 + 1e-9
    assert n_ok >= 20


# --------------------------------------------------------------------------- directions

@pytest.mark.parametrize("model", ["minpower", "tip", "ellipsoid"])
@pytest.mark.parametrize("mu_c", [0.0, 0.2])
def test_dy_sign_follows_the_pin_side(rectangle, model, mu_c):
    # Centred 60 x 20 rectangle at theta 0, pin 0.3 a above the centroid: the
    # pin catches the downstream face above the centroid, the belt drags the
    # lower part on, so the part turns counter-clockwise about the pin and its
    # centroid swings to -y (velocity omega z x (com - pin) has y part
    # -omega * x_face < 0). The mirror case (pin below) does the opposite.
    above = simulate.rollout(rectangle, 0.0, 0.3, mu_c, R_PIN, model=model)
    below = simulate.rollout(rectangle, 0.0, -0.3, mu_c, R_PIN, model=model)
    assert above.status.item() == "ok" and below.status.item() == "ok"
    assert float(above.dy) < 0.0 < float(below.dy)
    assert 0.0 < float(above.theta_f) < 180.0  # turned counter-clockwise
    assert 180.0 < float(below.theta_f) < 360.0  # turned clockwise


# --------------------------------------------------------------------------- determinism

def test_rollout_is_deterministic(quad):
    a = simulate.rollout(quad, 77.0, 0.4, 0.25, R_PIN, trajectory=True)
    b = simulate.rollout(quad, 77.0, 0.4, 0.25, R_PIN, trajectory=True)
    xr.testing.assert_identical(a, b)
    for v in a.data_vars:
        assert np.array_equal(a[v].values, b[v].values), v


def test_map_is_independent_of_thread_count(quad):
    theta = np.arange(0.0, 360.0, 10.0) + 0.5
    d = [-0.7, -0.3, 0.2, 0.6]
    one = simulate.compute_map(quad, theta, d, 0.25, R_PIN, threads=1)
    two = simulate.compute_map(quad, theta, d, 0.25, R_PIN, threads=2)
    xr.testing.assert_identical(one, two)
    for v in one.data_vars:
        assert np.array_equal(one[v].values, two[v].values), v


def test_map_entries_equal_single_rollouts(quad):
    theta = np.array([5.0, 95.0, 185.0, 275.0])
    d = np.array([-0.5, 0.35])
    m = simulate.compute_map(quad, theta, d, 0.25, R_PIN)
    assert m.theta_f.dims == ("d", "theta_i")
    np.testing.assert_array_equal(m.theta_i.values, theta)
    np.testing.assert_array_equal(m.d.values, d)
    for i, dd in enumerate(d):
        for j, th in enumerate(theta):
            one = simulate.rollout(quad, th, dd, 0.25, R_PIN)
            assert simulate.STATUSES[int(m.status.values[i, j])] == one.status.item()
            assert m.theta_f.values[i, j] == float(one.theta_f)
            assert m.dy.values[i, j] == float(one.dy)
            assert m.contact_travel.values[i, j] == float(one.contact_travel)
            assert m.feature_changes.values[i, j] == int(one.feature_changes)
            assert m.peak_force.values[i, j] == float(one.peak_force)


def test_theta_f_is_wrapped(quad):
    m = simulate.compute_map(quad, np.arange(-720.0, 720.0, 45.0), [0.3, -0.3], 0.1, R_PIN)
    assert np.all((m.theta_f.values >= 0.0) & (m.theta_f.values < 360.0))
    # theta_i and theta_i + 360 are the same orientation.
    a = simulate.rollout(quad, 20.0, 0.3, 0.1, R_PIN)
    b = simulate.rollout(quad, 380.0, 0.3, 0.1, R_PIN)
    assert abs(circular_diff(float(a.theta_f), float(b.theta_f))) < 1e-6
    assert float(a.dy) == pytest.approx(float(b.dy), abs=1e-6)


def test_dynamic_pin_mirror(triangle):
    # A pin moving across the belt: mirroring the part and negating d, theta_i
    # and the pin's cross speed mirrors the outcome.
    for v_pin in (0.3, -0.3):
        a = simulate.rollout(triangle, 40.0, 0.3, 0.2, R_PIN, v_pin=v_pin)
        b = simulate.rollout(triangle.mirrored(), -40.0, -0.3, 0.2, R_PIN, v_pin=-v_pin)
        assert a.status.item() == b.status.item() == "ok"
        assert abs(circular_diff(float(b.theta_f), -float(a.theta_f))) < 0.01
        assert float(b.dy) == pytest.approx(-float(a.dy), abs=0.01)
    # The moving pin really changes the outcome.
    static = simulate.rollout(triangle, 40.0, 0.3, 0.2, R_PIN)
    moving = simulate.rollout(triangle, 40.0, 0.3, 0.2, R_PIN, v_pin=0.3)
    assert abs(circular_diff(float(static.theta_f), float(moving.theta_f))) > 1.0


# --------------------------------------------------------------------------- parameters

@pytest.mark.parametrize("kwargs", [
    dict(mu_c=-0.1), dict(mu_c=float("nan")), dict(mu_c=float("inf")),
    dict(pin_radius=0.0), dict(pin_radius=-3.0), dict(pin_radius=float("nan")),
    dict(pin_radius=float("inf")),
    dict(model="nonsense"), dict(model="MinPower"),
    dict(theta_i=float("nan")), dict(d=float("inf")), dict(d=float("nan")),
    dict(v_pin=float("nan")),
    dict(max_travel=0.0), dict(max_travel=-1.0),
], ids=lambda kw: "-".join(f"{k}={v}" for k, v in kw.items()))
def test_bad_parameters_raise(triangle, kwargs):
    args = dict(theta_i=30.0, d=0.3, mu_c=0.2, pin_radius=R_PIN)
    args.update(kwargs)
    with pytest.raises(PinfeedError):
        simulate.rollout(triangle, **args)
    margs = dict(args, theta_i=[args["theta_i"], 10.0], d=[args["d"]])
    with pytest.raises(PinfeedError):
        simulate.compute_map(triangle, **margs)


def test_closest_feature_of_a_pin():
    """Edge interior, vertex, and the contact normal pointing into the part."""
    from kernels.geometry import EDGE, VERTEX, _closest_feature
    square = np.array([[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]])  # CCW
    kind, idx, dist, cx, cy, nx, ny = _closest_feature(square, 0.3, -1.5)
    assert (kind, idx) == (EDGE, 0) and dist == pytest.approx(0.5)
    assert (cx, cy) == pytest.approx((0.3, -1.0)) and (nx, ny) == pytest.approx((0.0, 1.0))
    kind, idx, dist, cx, cy, nx, ny = _closest_feature(square, 2.0, 2.0)
    assert (kind, idx) == (VERTEX, 2) and dist == pytest.approx(np.sqrt(2.0))
    assert (cx, cy) == pytest.approx((1.0, 1.0))
    assert (nx, ny) == pytest.approx((-np.sqrt(0.5), -np.sqrt(0.5)))
