"""Symmetry invariants of rollouts on random parts (spec section 4).

Each test computes a small configuration map of a random part and the map of
a transformed problem (mirrored part, scaled part and pin, shifted theta_i of
a k-fold symmetric part, rotated drawing) and checks that the two agree as the
physics demands.

Points near a band jump (where theta_f jumps as theta_i or d change) may
legitimately land on different sides of the jump in the two computations,
since the transformed problem is rounded differently. So every disagreeing
point must be shown to sit near a jump: re-running the original problem
0.05 deg either side in theta_i, or 0.002 either side in d, must change the
status or move theta_f by more than 0.5 deg (or dy by more than 0.5 mm).
Besides, at most 10 % of the points may disagree. A broken invariant makes
most points disagree, far from any jump, and fails.
"""
from __future__ import annotations

import math

import numpy as np
from hypothesis import assume, given
from hypothesis import note as _hypothesis_note
from hypothesis import strategies as st

from conftest import circular_diff, fewer_examples
from pipeline.maps import simulate
from pipeline.parts.part import Part, PolygonError

R_PIN = 3.0
THETA_TOL = 0.05  # degrees: integrator accuracy is far better (see test_rollout)
DY_TOL = 0.02  # mm, for parts of size ~20-40 mm
MAX_DISAGREE = 0.10
MODELS = ("minpower", "tip", "ellipsoid")



def note(msg):
    """``hypothesis.note`` that also works outside a Hypothesis test."""
    try:
        _hypothesis_note(msg)
    except Exception:
        pass


# --------------------------------------------------------------------------- strategies

@st.composite
def triangles(draw):
    """Random triangles without slivers: base 20-60 mm, base angles of at least
    15 degrees and an apex angle of at least 15 degrees, at a random turn."""
    length = draw(st.floats(20.0, 60.0))
    alpha = math.radians(draw(st.floats(15.0, 150.0)))
    beta = math.radians(draw(st.floats(15.0, 165.0 - math.degrees(alpha))))
    # Apex from the law of sines: side from A = length * sin(beta) / sin(alpha + beta).
    side = length * math.sin(beta) / math.sin(alpha + beta)
    xy = np.array([(0.0, 0.0), (length, 0.0), (side * math.cos(alpha), side * math.sin(alpha))])
    turn = draw(st.floats(0.0, 2 * math.pi))
    c, s = math.cos(turn), math.sin(turn)
    return xy @ np.array([[c, -s], [s, c]]).T


@st.composite
def star_polygons(draw):
    """Random star-shaped polygons with 4-7 vertices, convex or not: vertex
    angles around a centre jittered from even spacing (so the outline is
    simple), radii between 45 % and 100 % of a random size."""
    n = draw(st.integers(4, 7))
    size = draw(st.floats(20.0, 40.0))
    turn = draw(st.floats(0.0, 2 * math.pi))
    jitter = draw(st.lists(st.floats(-0.3, 0.3), min_size=n, max_size=n))
    radii = draw(st.lists(st.floats(0.45, 1.0), min_size=n, max_size=n))
    ang = turn + (np.arange(n) + np.array(jitter)) * 2 * math.pi / n
    r = size * np.array(radii)
    return np.column_stack([r * np.cos(ang), r * np.sin(ang)])


@st.composite
def parts(draw):
    xy = draw(st.one_of(triangles(), star_polygons()))
    offset = np.array(draw(st.tuples(st.floats(-100, 100), st.floats(-100, 100))))
    try:
        part = Part.from_vertices(xy + offset, name="random")
    except PolygonError:  # pragma: no cover - the constructions above are simple
        assume(False)
    note(f"vertices={np.round(xy + offset, 6).tolist()} convex={part.is_convex}")
    return part


def d_values():
    """Three contact parameters away from the metastable |d| < 0.15."""
    one = st.floats(0.15, 0.85).flatmap(lambda m: st.sampled_from([m, -m]))
    return st.lists(one, min_size=3, max_size=3).map(np.array)


def theta_grid(step):
    return st.floats(0.0, step).map(lambda off: off + np.arange(0.0, 360.0, step))


mu_values = st.sampled_from([0.0, 0.15, 0.4])
models = st.sampled_from(MODELS)


# --------------------------------------------------------------------------- comparison

def _near_jump(part, theta_i, d, mu_c, model, r_pin, v_pin=0.0):
    th = [theta_i - 0.05, theta_i, theta_i + 0.05]
    dd = [d - 0.002, d, d + 0.002]
    m = simulate.compute_map(part, th, dd, mu_c, r_pin, model=model, v_pin=v_pin)
    s = m.status.values
    t = m.theta_f.values
    y = m.dy.values
    t0, y0, s0 = t[1, 1], y[1, 1], s[1, 1]
    return bool(np.any(s != s0) or np.any(np.abs(circular_diff(t, t0)) > 0.5)
                or np.any(np.abs(y - y0) > 0.5))


def assert_maps_agree(base, part, mu_c, model, r_pin, want_theta, want_dy, got, dy_tol=DY_TOL,
                      v_pin=0.0):
    """``got`` (a map Dataset, same shape as ``base``) must have the status of
    ``base`` and theta_f, dy equal to ``want_theta``, ``want_dy`` (``None``: not
    compared), except at points next to a band jump of the ``base`` problem
    (``base`` computed at pin speed ``v_pin``)."""
    bad = ((got.status.values != base.status.values)
           | (np.abs(circular_diff(got.theta_f.values, want_theta)) > THETA_TOL))
    if want_dy is not None:
        bad |= np.abs(got.dy.values - want_dy) > dy_tol
    note(f"{bad.sum()} of {bad.size} points disagree")
    assert bad.mean() <= MAX_DISAGREE, (
        f"{bad.sum()} of {bad.size} points disagree; first: "
        f"theta_f {got.theta_f.values[bad][:5]} vs {np.asarray(want_theta)[bad][:5]}")
    th = base.theta_i.values
    dd = base.d.values
    for i, j in zip(*np.nonzero(bad)):
        assert _near_jump(part, th[j], dd[i], mu_c, model, r_pin, v_pin), (
            f"theta_i={th[j]} d={dd[i]}: status {base.status.values[i, j]} -> "
            f"{got.status.values[i, j]}, theta_f {got.theta_f.values[i, j]:.4f} vs "
            f"{want_theta[i, j]:.4f}, dy {got.dy.values[i, j]:.4f}, and no band jump nearby")


def _contact_fraction(m):
    return float(np.mean(m.status.values != simulate.STATUSES.index("miss")))


# --------------------------------------------------------------------------- invariants

# Each example sweeps maps of full rollouts: 15 in CI.
@fewer_examples(0.15)
@given(part=parts(), theta=theta_grid(15.0), d=d_values(), mu_c=mu_values, model=models)
def test_mirror(part, theta, d, mu_c, model):
    # Reflecting the whole scene in the belt's centre line (y -> -y) maps the
    # part to its mirror image at -theta_i, the pin to -d, and the outcome to
    # -theta_f, -dy; Coulomb friction and the support are symmetric.
    base = simulate.compute_map(part, theta, d, mu_c, R_PIN, model=model)
    assume(_contact_fraction(base) > 0.3)
    got = simulate.compute_map(part.mirrored(), np.mod(-theta, 360.0), -d, mu_c, R_PIN, model=model)
    assert_maps_agree(base, part, mu_c, model, R_PIN, -base.theta_f.values, -base.dy.values, got)


# Each example sweeps maps of full rollouts: 15 in CI.
@fewer_examples(0.15)
@given(part=parts(), theta=theta_grid(15.0), d=d_values(), mu_c=mu_values, model=models,
       k=st.floats(0.2, 5.0))
def test_scale(part, theta, d, mu_c, model, k):
    # Quasi-static motion has no length scale but the part and the pin: scaling
    # both by k leaves angles unchanged and scales displacements by k.
    base = simulate.compute_map(part, theta, d, mu_c, R_PIN, model=model)
    assume(_contact_fraction(base) > 0.3)
    big = part.scaled(k)
    assert math.isclose(big.a, k * part.a, rel_tol=1e-12)
    got = simulate.compute_map(big, theta, d, mu_c, k * R_PIN, model=model)
    assert_maps_agree(base, part, mu_c, model, R_PIN, base.theta_f.values, k * base.dy.values,
                      got, dy_tol=DY_TOL * max(k, 1.0))


@st.composite
def symmetric_parts(draw):
    """(part, k): a regular k-gon (k = 3..6) or a non-convex k-pointed star
    (k = 3, 4), drawn at a random angle."""
    size = draw(st.floats(20.0, 40.0))
    turn = draw(st.floats(0.0, 2 * math.pi))
    if draw(st.booleans()):
        k = draw(st.integers(3, 6))
        ang = turn + np.arange(k) * 2 * math.pi / k
        r = np.full(k, size)
    else:
        k = draw(st.integers(3, 4))
        inner = draw(st.floats(0.35, 0.6))
        ang = turn + np.arange(2 * k) * math.pi / k
        r = size * np.where(np.arange(2 * k) % 2 == 0, 1.0, inner)
    part = Part.from_vertices(np.column_stack([r * np.cos(ang), r * np.sin(ang)]), name=f"{k}-fold")
    note(f"k={k} n={len(ang)} convex={part.is_convex}")
    return part, k


# Each example sweeps maps of full rollouts: 15 in CI.
@fewer_examples(0.15)
@given(sym=symmetric_parts(), d=d_values(), mu_c=mu_values, model=models,
       offset=st.floats(0.0, 10.0))
def test_k_fold_symmetry(sym, d, mu_c, model, offset):
    # Turning a k-fold symmetric part by 360/k gives the same shape, so the map
    # repeats: theta_f(theta_i + 360/k) = theta_f(theta_i) + 360/k, same dy.
    part, k = sym
    per = 8  # grid points per period
    step = 360.0 / k / per
    theta = offset + np.arange(k * per) * step
    m = simulate.compute_map(part, theta, d, mu_c, R_PIN, model=model)
    assume(_contact_fraction(m) > 0.3)
    # Compare each point with the one a period later (wrapping around).
    shift = np.roll(np.arange(theta.size), -per)
    got = m.isel(theta_i=shift)
    assert_maps_agree(m, part, mu_c, model, R_PIN, m.theta_f.values + 360.0 / k, m.dy.values, got)


# Each example sweeps maps of full rollouts: 15 in CI.
@fewer_examples(0.15)
@given(part=parts(), theta=theta_grid(15.0), d=d_values(), mu_c=mu_values, model=models,
       phi=st.floats(1.0, 359.0))
def test_drawing_frame(part, theta, d, mu_c, model, phi):
    # Body axes are the drawing axes. Drawing the part rotated by phi
    # (counter-clockwise) means the rotated part at orientation theta has the
    # world shape of the original at theta + phi. So the map shifts by phi on
    # both axes: theta_f_rot(theta_i - phi) = theta_f(theta_i) - phi, same dy.
    base = simulate.compute_map(part, theta, d, mu_c, R_PIN, model=model)
    assume(_contact_fraction(base) > 0.3)
    rot = part.rotated(phi)
    c, s = math.cos(math.radians(phi)), math.sin(math.radians(phi))
    by_hand = part.vertices @ np.array([[c, -s], [s, c]]).T
    assert np.allclose(rot.vertices, by_hand, atol=1e-9) or any(
        np.allclose(np.roll(rot.vertices, j, axis=0), by_hand, atol=1e-9)
        for j in range(len(by_hand)))
    got = simulate.compute_map(rot, np.mod(theta - phi, 360.0), d, mu_c, R_PIN, model=model)
    assert_maps_agree(base, part, mu_c, model, R_PIN, base.theta_f.values - phi, base.dy.values,
                      got)


# --------------------------------------------------------------------------- the checks can fail

def test_comparison_rejects_a_wrong_transformation():
    # Guard against a toothless comparison: with the mirror rule applied
    # wrongly (theta_f not negated) the maps must disagree almost everywhere,
    # far from any jump.
    import pytest

    part = Part.from_vertices([(0, 0), (60, 0), (15, 35)])
    theta = np.arange(0.0, 360.0, 15.0) + 2.0
    d = np.array([-0.6, 0.3, 0.5])
    base = simulate.compute_map(part, theta, d, 0.15, R_PIN)
    got = simulate.compute_map(part.mirrored(), np.mod(-theta, 360.0), -d, 0.15, R_PIN)
    with pytest.raises(AssertionError):
        assert_maps_agree(base, part, 0.15, "minpower", R_PIN, base.theta_f.values,
                          -base.dy.values, got)
    # ... and applied rightly it agrees.
    assert_maps_agree(base, part, 0.15, "minpower", R_PIN, -base.theta_f.values, -base.dy.values,
                      got)
