"""Minpower over a point support (issue 25): the exact kink-aware solve
(``models._minimise_points``) against brute-force minimisation of the
friction power, the centre of rotation exactly at a support point, the
subgradient (pin force) it returns, and the contact model's invariants.

The reference here uses no kernel code: ``P = sum_k w_k |u(p_k)|`` written
out in NumPy, minimised by scipy (bounded Brent in 1-D over
``omega = tan(phi)``, after a grid; Nelder-Mead in 2-D from many starts,
each kink among them). A minimum is only accepted as the reference when no
start does better.
"""
import math
import os
import sys

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from scipy import optimize

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
import strategies as sts
from conftest import fewer_examples

from kernels.models import (_DEC_TAKE, MINPOWER_POINTS, NO_MODEL, SLIDE_NEG, SLIDE_POS, STICK,
                            TWIST_OK, _contact_twist, _slide_solve, _stick_solve)
from kernels.rollout import _prepare
from kernels.support import _point_table

TRIANGLE = np.array([(0.0, 0.0), (60.0, 0.0), (15.0, 35.0)])


# --------------------------------------------------------------------------- reference


def power_ref(pts, w, xi):
    """P(xi) = sum_k w_k |u(p_k)| / sum w, straight from the definition."""
    u = np.column_stack([xi[0] - xi[2] * pts[:, 1], xi[1] + xi[2] * pts[:, 0]])
    return float(np.sum(w * np.hypot(u[:, 0], u[:, 1])) / np.sum(w))


def stick_family(c, vp):
    """Twists with u(c) = v_p: ``x + y b``."""
    return np.array([vp[0], vp[1], 0.0]), np.array([c[1], -c[0], 1.0])


def slide_family(c, e):
    """Twists with e . u(c) = 1: ``x + y1 b + y2 c`` (as ``models._slide_solve``)."""
    ke = c[0] * e[1] - c[1] * e[0]
    return (np.array([e[0], e[1], 0.0]), np.array([-e[1], e[0], 0.0]),
            np.array([-ke * e[0], -ke * e[1], 1.0]))


def brute_stick(pts, w, c, vp):
    """min over omega of P(x + omega b): a grid over omega = tan(phi), then
    bounded Brent on the best cell."""
    x, b = stick_family(c, vp)
    f = lambda om: power_ref(pts, w, x + om * b)  # noqa: E731
    phi = np.linspace(-math.pi / 2 + 1e-6, math.pi / 2 - 1e-6, 4001)
    vals = np.array([f(math.tan(p)) for p in phi])
    k = int(np.argmin(vals))
    lo, hi = phi[max(k - 1, 0)], phi[min(k + 1, len(phi) - 1)]
    res = optimize.minimize_scalar(lambda p: f(math.tan(p)), bounds=(lo, hi), method="bounded",
                                   options={"xatol": 1e-13})
    om = math.tan(res.x) if res.fun <= vals[k] else math.tan(phi[k])
    return om, f(om)


def kinks_2d(pts, c, e):
    """The parameters y at which a twist of the sliding family turns about each point."""
    x, b, cc = slide_family(c, e)
    out = []
    for p in pts:
        jac = np.array([[1.0, 0.0, -p[1]], [0.0, 1.0, p[0]]])
        m = np.column_stack([jac @ b, jac @ cc])
        if abs(np.linalg.det(m)) > 1e-12:
            out.append(np.linalg.solve(m, -(jac @ x)))
    return out


def brute_slide(pts, w, c, e):
    """min over y of P(x + y1 b + y2 c): Nelder-Mead from the origin and from
    every kink; the best end point."""
    x, b, cc = slide_family(c, e)
    f = lambda y: power_ref(pts, w, x + y[0] * b + y[1] * cc)  # noqa: E731
    best = None
    for y0 in [np.zeros(2)] + kinks_2d(pts, c, e):
        for step in (0.3, 0.01):
            res = optimize.minimize(f, y0, method="Nelder-Mead",
                                    options={"xatol": 1e-12, "fatol": 1e-15, "maxiter": 20000,
                                             "initial_simplex": [y0, y0 + [step, 0],
                                                                 y0 + [0, step]]})
            for y in (res.x, y0):
                if best is None or f(y) < best[1]:
                    best = (np.array(y), f(y))
    return best


# --------------------------------------------------------------------------- kernel calls


def support_quad(verts, pts, w):
    """The kernel's ``quad`` for a point support: points, weights / sum, then
    the edge directions (``pipeline.maps.simulate._kernel_part``)."""
    n = verts.shape[0]
    _, _, _, quad, _, _ = _prepare(np.ascontiguousarray(verts * 1.0))
    rows = np.column_stack([pts, w / np.sum(w)])
    return _point_table(quad, np.ascontiguousarray(rows))


def k_stick(verts, q, c, vp, warm=0.0):
    vx, vy, om, g, hess, conv = _stick_solve(q, 1.0, float(c[0]), float(c[1]),
                                             float(vp[0]), float(vp[1]), float(warm), NO_MODEL,
                                             _DEC_TAKE, True)
    return np.array([vx, vy, om]), np.array(g), conv


def k_slide(verts, q, c, e, warm=(0.0, 0.0, 0.0)):
    vx, vy, om, g, hess, conv = _slide_solve(q, 1.0, float(c[0]), float(c[1]),
                                             float(e[0]), float(e[1]), *map(float, warm),
                                             NO_MODEL, _DEC_TAKE, True)
    return np.array([vx, vy, om]), np.array(g), conv


def unit_triangle():
    verts, _, _, _, _, _ = _prepare(TRIANGLE)
    return verts


def edge_contact(verts, j, t):
    p, q = verts[j], verts[(j + 1) % len(verts)]
    e = (q - p) / np.linalg.norm(q - p)
    return p + t * (q - p), np.array([-e[1], e[0]])


def slip_at(pts, xi):
    return np.hypot(xi[0] - xi[2] * pts[:, 1], xi[1] + xi[2] * pts[:, 0])


def assert_subgradient(pts, w, xi, g, fam, tol=1e-9):
    """``g`` is an element of P's subdifferential at ``xi`` that is zero on the
    family's directions ``fam`` (the optimality condition), every point at a
    kink contributing ``w_k J_k^T s_k`` with ``|s_k| <= 1``."""
    w = w / np.sum(w)
    for d in fam:
        assert abs(g @ d) <= tol * (1 + np.linalg.norm(d)), f"g . d = {g @ d}"
    slip = slip_at(pts, xi)
    scale = np.abs(xi).sum()
    rest = np.zeros(3)
    at_kink = []
    for k, p in enumerate(pts):
        if slip[k] <= 1e-12 * scale:
            at_kink.append(k)
            continue
        u = np.array([xi[0] - xi[2] * p[1], xi[1] + xi[2] * p[0]]) / slip[k]
        rest += w[k] * np.array([u[0], u[1], p[0] * u[1] - p[1] * u[0]])
    left = g - rest
    if not at_kink:
        assert np.abs(left).max() <= tol, f"smooth point: g - grad P = {left}"
        return
    assert len(at_kink) == 1
    k = at_kink[0]
    s = left[:2] / w[k]
    assert np.linalg.norm(s) <= 1 + 1e-8, f"|s| = {np.linalg.norm(s)}"
    assert abs(left[2] - w[k] * (pts[k, 0] * s[1] - pts[k, 1] * s[0])) <= tol


# --------------------------------------------------------------------------- kinks, exactly


HEAVY = np.array([[0.1, -0.1], [-0.5, -0.25], [0.3, 0.2], [-0.2, 0.4]])


@pytest.mark.parametrize("heavy", range(4))
def test_slide_turns_exactly_about_a_support_point_where_brute_force_does(heavy):
    """One heavy point (0.7 of the weight, three of 0.1), pushed along three
    directions at three contacts. Where brute force finds the minimum at the
    heavy point's kink (the part pivots about it; the Clarke condition holds
    there), the kernel returns the centre of rotation on the point to
    rounding; everywhere its P is not above brute force's, it lies at brute
    force's minimiser, and its force is a valid subgradient. Most of these
    pushes pivot (checked, so the test cannot pass without kinks)."""
    verts = unit_triangle()
    w = np.full(4, 0.1)
    w[heavy] = 0.7
    q = support_quad(verts, HEAVY, w)
    pivots = 0
    for j, tt in ((0, 0.3), (1, 0.5), (2, 0.5)):
        c, n = edge_contact(verts, j, tt)
        for tilt in (0.0, 0.35, -0.35):
            e = np.array([n[0] * math.cos(tilt) - n[1] * math.sin(tilt),
                          n[0] * math.sin(tilt) + n[1] * math.cos(tilt)])
            xi, g, conv = k_slide(verts, q, c, e)
            assert conv
            y_ref, p_ref = brute_slide(HEAVY, w, c, e)
            assert power_ref(HEAVY, w, xi) <= p_ref + 1e-13
            x, b, cc = slide_family(c, e)
            xi_ref = x + y_ref[0] * b + y_ref[1] * cc
            assert np.linalg.norm(xi_ref - xi) <= 1e-6
            assert_subgradient(HEAVY, w, xi, g, (b, cc))
            if slip_at(HEAVY, xi_ref)[heavy] <= 1e-6:
                assert slip_at(HEAVY, xi)[heavy] <= 1e-13 * np.abs(xi).sum(), \
                    f"brute force pivots on point {heavy}, the kernel does not"
                pivots += 1
    assert pivots >= 4, f"only {pivots} of 9 pushes pivot: the test lost its kinks"


def test_stick_kink_on_the_line_of_centres():
    """Sticking with the support point on the line through the contact
    perpendicular to v_p: P(omega) has its kink there, and the minimum sits on
    it (brute force agrees); the returned force is a valid subgradient."""
    verts = unit_triangle()
    c, n = edge_contact(verts, 0, 0.4)
    vp = n.copy()
    # Turning about r moves c along z x (c - r): along n = v_p iff r lies on
    # the line c + lambda t (t = z x n), here on the contact edge itself.
    t = np.array([-n[1], n[0]])
    pts = np.array([c + 0.25 * t, [-0.2, 0.1], [0.1, 0.3]])
    w = np.array([0.8, 0.1, 0.1])
    q = support_quad(verts, pts, w)
    xi, g, conv = k_stick(verts, q, c, vp)
    om_ref, p_ref = brute_stick(pts, w, c, vp)
    assert conv
    assert power_ref(pts, w, xi) <= p_ref + 1e-13
    assert abs(xi[2] - om_ref) <= 1e-6 * (1 + abs(om_ref))
    slip = slip_at(pts, xi)
    assert slip[0] <= 1e-12, f"sticking minimum should sit on the kink: |u| = {slip}"
    x, b = stick_family(c, vp)
    assert_subgradient(pts, w, xi, g, (b,))


def test_single_point_support_pivots_at_zero_power():
    """One support point: the part turns about it freely (P = 0, no force)
    whenever the push allows a rotation about it."""
    verts = unit_triangle()
    pts = np.array([[0.2, 0.1]])
    q = support_quad(verts, pts, np.ones(1))
    c, n = edge_contact(verts, 0, 0.5)
    xi, g, conv = k_slide(verts, q, c, n)
    assert conv and slip_at(pts, xi)[0] <= 1e-14 * np.abs(xi).sum()
    assert np.abs(g).max() <= 1e-14


# --------------------------------------------------------------------------- random cases


@st.composite
def point_cases(draw):
    """A convex part, 1 to 6 support points inside it with random weights
    (sometimes one dominant, to make kinks likely), a contact on an edge, a
    direction e with e . n > 0 and a pin velocity into the part."""
    verts = draw(sts.convex_polygons())
    verts = verts - verts.mean(axis=0)
    k = draw(st.integers(1, 6))
    bary = np.array(draw(st.lists(st.floats(0.05, 1.0), min_size=k * 3, max_size=k * 3)))
    bary = bary.reshape(k, 3) / bary.reshape(k, 3).sum(axis=1, keepdims=True)
    tri = [draw(st.integers(0, len(verts) - 1)) for _ in range(k)]
    pts = np.array([bary[i, 0] * verts[tri[i]] + bary[i, 1] * verts[(tri[i] + 1) % len(verts)]
                    for i in range(k)])  # points on the fan (0, v_j, v_j+1), mixed with 0
    w = np.array(draw(st.lists(st.floats(0.05, 1.0), min_size=k, max_size=k)))
    if draw(st.booleans()):
        w[draw(st.integers(0, k - 1))] = 1.5 * w.sum()
    j = draw(st.integers(0, len(verts) - 1))
    tt = draw(st.floats(0.05, 0.95))
    p, q = verts[j], verts[(j + 1) % len(verts)]
    edge = (q - p) / np.linalg.norm(q - p)
    n = np.array([-edge[1], edge[0]])
    t = np.array([-n[1], n[0]])
    al = draw(st.floats(-1.2, 1.2))
    be = draw(st.floats(-1.3, 1.3))
    return (np.ascontiguousarray(verts), pts, w, p + tt * (q - p), n,
            math.cos(al) * n + math.sin(al) * t, math.cos(be) * n + math.sin(be) * t)


@fewer_examples(0.3)  # each example runs scipy from up to 7 starts
@given(point_cases())
def test_slide_solve_matches_brute_force(case):
    """The sliding solve is the minimum of P over the family (no start of the
    brute-force search does better), close to its minimiser, and its force is
    a valid subgradient; the answer does not depend on the warm start."""
    verts, pts, w, c, n, e, _ = case
    q = support_quad(verts, pts, w)
    xi, g, conv = k_slide(verts, q, c, e)
    assert conv
    y_ref, p_ref = brute_slide(pts, w, c, e)
    p_k = power_ref(pts, w, xi)
    assert p_k <= p_ref + 1e-12 * (1 + p_ref), f"kernel P {p_k} above brute force {p_ref}"
    x, b, cc = slide_family(c, e)
    assert_subgradient(pts, w, xi, g, (b, cc))
    xi2, _, _ = k_slide(verts, q, c, e, warm=(0.3, -0.7, 2.0))
    assert np.abs(xi2 - xi).max() <= 1e-7 * (1 + np.abs(xi).max())


@fewer_examples(0.3)  # each example runs a 4001-point grid and Brent
@given(point_cases())
def test_stick_solve_matches_brute_force(case):
    """The sticking solve is the minimum of P over omega (brute force), and its
    force is the gradient there (zero along the family)."""
    verts, pts, w, c, n, _, vp = case
    q = support_quad(verts, pts, w)
    xi, g, conv = k_stick(verts, q, c, vp)
    assert conv
    om_ref, p_ref = brute_stick(pts, w, c, vp)
    p_k = power_ref(pts, w, xi)
    assert p_k <= p_ref + 1e-12 * (1 + p_ref)
    assert abs(xi[2] - om_ref) <= 1e-5 * (1 + abs(om_ref)) or p_k <= p_ref
    x, b = stick_family(c, vp)
    assert_subgradient(pts, w, xi, g, (b,))


@fewer_examples(0.5)
@given(point_cases(), st.floats(0.0, 1.0))
def test_contact_model_force_and_mode(case, mu):
    """The full contact rule over a point support: a sticking force lies in
    the friction cone; a sliding force on its edge, pushing (f . n > 0), the
    pin not penetrating (n . u(c) = n . v_p), the slip against friction."""
    verts, pts, w, c, n, _, vp = case
    q = support_quad(verts, pts, w)
    st_, vx, vy, om, fx, fy, mode = _contact_twist(MINPOWER_POINTS, q, 1.0, 1.0,
                                                  c[0], c[1], n[0], n[1], vp[0], vp[1], mu,
                                                  0.0, 0.0, 0.0, STICK)
    if st_ != TWIST_OK:
        return
    f = np.array([fx, fy])
    t = np.array([-n[1], n[0]])
    uc = np.array([vx - om * c[1], vy + om * c[0]])
    if np.abs(f).max() <= 1e-12:  # no force: only a part pivoting freely on one point
        assert len(pts) == 1 and slip_at(pts, np.array([vx, vy, om]))[0] <= 1e-12
        return
    assert f @ n > 0
    if mode == STICK:
        assert abs(f @ t) <= mu * (f @ n) * (1 + 1e-9) + 1e-12
        assert np.abs(uc - vp).max() <= 1e-9
    else:
        assert mode in (SLIDE_POS, SLIDE_NEG)
        assert abs(f @ t - mode * mu * (f @ n)) <= 1e-9 * np.linalg.norm(f)
        assert abs(uc @ n - vp @ n) <= 1e-9
        if mu > 0:  # the part slips against friction
            assert mode * ((uc - vp) @ t) <= 1e-9


def test_power_of_the_answer_is_not_above_any_sampled_admissible_twist():
    """Spec invariant, over a point support with a pivot: P of the sliding
    twist (on its family's scale) is not above P of 2000 sampled twists of
    the same family, kinks included."""
    verts = unit_triangle()
    w = np.array([0.7, 0.1, 0.1, 0.1])
    q = support_quad(verts, HEAVY, w)
    c, n = edge_contact(verts, 1, 0.6)
    xi, _, _ = k_slide(verts, q, c, n)
    x, b, cc = slide_family(c, n)
    p0 = power_ref(HEAVY, w, xi)
    rng = np.random.default_rng(5)
    for y in list(rng.normal(scale=2.0, size=(2000, 2))) + kinks_2d(HEAVY, c, n):
        assert p0 <= power_ref(HEAVY, w, x + y[0] * b + y[1] * cc) + 1e-14


# --------------------------------------------------------------------------- the COR locus bound


def test_every_sampled_support_turns_within_the_cor_locus_bound():
    """Peshkin and Sanderson: for a support within radius a of the centre of
    pressure (at the centroid, as statics asks), a force line at distance
    rho from it turns the part about a centre of rotation no farther than
    the locus tip a^2 / rho, or than a itself when the centre lies within
    the support disc: |COR| <= max(a, a^2 / rho). Checked for 3000 seeded
    random point supports (2 to 7 points, random weights), pushes in every
    direction (frictionless pin: the force is along the push); the bound is
    reached (pivots at distance a, two-point supports at the tip), so the
    test also sees a solve that turned too slowly."""
    rng = np.random.default_rng(25)
    verts = unit_triangle()
    checked, worst = 0, 0.0
    for _ in range(3000):
        pts = rng.uniform(-1.0, 1.0, (int(rng.integers(2, 8)), 2))
        pts = pts[np.hypot(pts[:, 0], pts[:, 1]) < 1.0]
        if len(pts) < 2:
            continue
        w = rng.uniform(0.05, 1.0, len(pts))
        pts = pts - (w @ pts) / w.sum()  # centre of pressure at the centroid
        a = np.hypot(pts[:, 0], pts[:, 1]).max()
        ang = rng.uniform(0.0, 2.0 * math.pi)
        e = np.array([math.cos(ang), math.sin(ang)])
        c = rng.uniform(-1.5, 1.5, 2)
        xi, g, conv = k_slide(verts, support_quad(verts, pts, w), c, e)
        assert conv
        if abs(xi[2]) < 1e-12:
            continue  # a translation: the COR is at infinity, the line through the centroid
        f = g[:2] / np.linalg.norm(g[:2])
        rho = abs(c[0] * f[1] - c[1] * f[0])
        if rho < 1e-6:
            continue
        cor = np.array([-xi[1] / xi[2], xi[0] / xi[2]])
        bound = max(a, a * a / rho)
        worst = max(worst, np.linalg.norm(cor) / bound)
        checked += 1
    assert checked > 2000
    assert worst <= 1.0 + 1e-9, f"a COR lies {worst:.6f} times the bound from the centroid"
    assert worst >= 0.999, "no sample reached the bound: the test lost its edge"


def test_stick_solve_near_a_kink_converges_to_the_minimum():
    """Sticking with a heavy point at 1e-15 to 1e-6 (relative) from the line
    of centres of rotation through the contact: P(omega) is smooth there but
    its curvature is up to 1e15; the solve converges (no stall) and is not
    above brute force (150 seeded cases)."""
    verts = unit_triangle()
    rng = np.random.default_rng(11)
    for _ in range(150):
        c, nrm = edge_contact(verts, int(rng.integers(3)), rng.uniform(0.05, 0.95))
        t = np.array([-nrm[1], nrm[0]])
        al = rng.uniform(-1.2, 1.2)
        vp = math.cos(al) * nrm + math.sin(al) * t
        tv = np.array([-vp[1], vp[0]])
        k = int(rng.integers(2, 6))
        pts = rng.uniform(-0.6, 0.6, (k, 2))
        pts[0] = c + rng.uniform(-0.8, 0.8) * tv + 10 ** rng.uniform(-15, -6) * vp
        w = rng.uniform(0.05, 1.0, k)
        w[0] *= rng.uniform(1.0, 6.0)
        xi, g, conv = k_stick(verts, support_quad(verts, pts, w), c, vp, rng.normal())
        assert conv
        _, p_ref = brute_stick(pts, w, c, vp)
        assert power_ref(pts, w, xi) <= p_ref + 1e-12 * (1 + p_ref)
