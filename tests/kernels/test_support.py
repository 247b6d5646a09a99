"""Support integrals E, G, N and the belt power P against brute-force quadrature.

Reference values come from ``tests/reference.py`` (fan + Duffy + graded
Gauss-Legendre, no closed forms), which is itself cross-checked here against
scipy's adaptive ``dblquad`` and against analytic results (square, regular
n-gon, disc).
"""
import itertools
import math
import os
import sys

import numpy as np
import pytest
from hypothesis import assume, given
from hypothesis import strategies as st
from scipy import integrate

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
import reference as ref
import strategies as sts

from kernels.rollout import _prepare
from kernels.support import _R_FAR, _max_moment, _power, _support


def kernel_support(verts, r):
    return np.array(_support(np.ascontiguousarray(verts, dtype=float), float(r[0]),
                             float(r[1])))


def assert_support_close(verts, r, got, want, rtol=1e-9):
    """|X - X_ref| <= rtol * max(|X_ref|, natural scale of X) for E, G and N."""
    area = ref.signed_area(verts)
    a = float(np.max(np.hypot(*(verts - verts.mean(axis=0)).T)))
    e_scale = max(abs(want[0]), area * a)
    g_scale = max(np.hypot(want[1], want[2]), area)
    n_scale = max(np.abs(want[3:]).max(), area / a)
    msg = f"r={r!r}\nverts={verts.tolist()!r}\ngot ={got}\nwant={want}"
    assert abs(got[0] - want[0]) <= rtol * e_scale, "E " + msg
    assert np.abs(got[1:3] - want[1:3]).max() <= rtol * g_scale, "G " + msg
    assert np.abs(got[3:] - want[3:]).max() <= rtol * n_scale, "N " + msg


def boundary_distance(verts, r):
    n = len(verts)
    best = np.inf
    for j in range(n):
        p, q = verts[j], verts[(j + 1) % n]
        e = q - p
        t = np.clip((r - p) @ e / (e @ e), 0.0, 1.0)
        best = min(best, float(np.hypot(*(p + t * e - r))))
    return best


# --------------------------------------------------------------------------- reference itself


def _convex_slices(verts):
    """y-limits of a convex polygon as functions of x (for dblquad)."""
    def limits(x):
        ys = []
        n = len(verts)
        for j in range(n):
            p, q = verts[j], verts[(j + 1) % n]
            if (p[0] - x) * (q[0] - x) <= 0.0 and p[0] != q[0]:
                t = (x - p[0]) / (q[0] - p[0])
                ys.append(p[1] + t * (q[1] - p[1]))
        return min(ys), max(ys)
    return limits


def _dblquad_support(verts, r, parts):
    lim = _convex_slices(verts)
    xs = np.unique(verts[:, 0])
    if xs[0] < r[0] < xs[-1]:
        xs = np.unique(np.append(xs, r[0]))  # the integrand's kink line
    out = []
    funcs = {
        "E": lambda y, x: math.hypot(x - r[0], y - r[1]),
        "Gx": lambda y, x: (x - r[0]) / math.hypot(x - r[0], y - r[1]),
        "Gy": lambda y, x: (y - r[1]) / math.hypot(x - r[0], y - r[1]),
        "Nxx": lambda y, x: (x - r[0]) ** 2 / math.hypot(x - r[0], y - r[1]) ** 3,
        "Nxy": lambda y, x: (x - r[0]) * (y - r[1]) / math.hypot(x - r[0], y - r[1]) ** 3,
        "Nyy": lambda y, x: (y - r[1]) ** 2 / math.hypot(x - r[0], y - r[1]) ** 3,
    }
    for name in parts:
        total = 0.0
        for x0, x1 in itertools.pairwise(xs):
            if x1 - x0 < 1e-14:
                continue
            val, _ = integrate.dblquad(funcs[name], x0, x1, lambda x: lim(x)[0],
                                       lambda x: lim(x)[1], epsabs=1e-12, epsrel=1e-11)
            total += val
        out.append(total)
    return np.array(out)


@pytest.mark.parametrize("r, parts", [
    ((0.31, 0.27), ("E", "Gx", "Gy")),   # inside: E has a kink, G a jump at r
    ((2.3, -0.9), ("E", "Gx", "Gy", "Nxx", "Nxy", "Nyy")),  # outside: smooth
    ((1.7, 1.4), ("E", "Gx", "Gy", "Nxx", "Nxy", "Nyy")),
])
def test_reference_matches_scipy_dblquad(r, parts):
    verts = np.array([[-0.6, -0.5], [1.2, -0.3], [1.0, 0.9], [-0.2, 1.1]])  # convex, CCW
    want = _dblquad_support(verts, r, parts)
    got_all = ref.support_ref(verts, r)
    idx = [["E", "Gx", "Gy", "Nxx", "Nxy", "Nyy"].index(p) for p in parts]
    np.testing.assert_allclose(got_all[idx], want, rtol=1e-8, atol=1e-9)


def test_reference_analytic_square_and_ngon():
    # E of a 2x2 square about its centre: (4/3)(sqrt 2 + asinh 1).
    sq = np.array([[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]])
    e = ref.support_ref(sq, (0.0, 0.0))
    assert e[0] == pytest.approx(4.0 / 3.0 * (math.sqrt(2.0) + math.asinh(1.0)), rel=1e-13)
    # E about a corner of a unit square: (1/3)(sqrt 2 + asinh 1).
    unit = sq * 0.5 + 0.5
    e = ref.support_ref(unit, (0.0, 0.0))
    assert e[0] == pytest.approx((math.sqrt(2.0) + math.asinh(1.0)) / 3.0, rel=1e-13)
    # Regular 7-gon, analytic per-triangle integral.
    ang = 2 * math.pi * np.arange(7) / 7
    hept = 1.3 * np.column_stack([np.cos(ang), np.sin(ang)])
    m = ref.support_ref(hept, (0.0, 0.0))[0] / ref.signed_area(hept)
    assert m == pytest.approx(ref.regular_ngon_moment(7, 1.3), rel=1e-13)


def test_reference_n_is_gradient_of_g():
    """dG/dr = N - tr(N) I (differentiate (w - r)/|w - r|), on the reference."""
    verts = np.array([[0.0, 0.0], [2.0, 0.0], [2.0, 0.5], [0.5, 0.5], [0.5, 2.0], [0.0, 2.0]])
    for r in [(0.25, 1.2), (1.3, 1.1), (-0.7, 0.4)]:
        r = np.array(r)
        n = ref.support_ref(verts, r)
        nmat = np.array([[n[3], n[4]], [n[4], n[5]]])
        h = 1e-5
        jac = np.empty((2, 2))
        for k in range(2):
            dr = np.zeros(2)
            dr[k] = h
            g_plus = ref.support_ref(verts, r + dr)[1:3]
            g_minus = ref.support_ref(verts, r - dr)[1:3]
            jac[:, k] = (g_plus - g_minus) / (2 * h)
        np.testing.assert_allclose(jac, nmat - np.trace(nmat) * np.eye(2), atol=1e-7)


# --------------------------------------------------------------------------- closed forms


@st.composite
def polygon_and_point(draw):
    xy = draw(sts.polygons())
    kind = draw(st.sampled_from(["inside", "outside", "near_edge", "on_edge", "vertex"]))
    if kind == "inside":
        r = draw(sts.point_inside_star(xy))
    elif kind == "outside":
        r = draw(sts.point_outside(xy))
    elif kind == "near_edge":
        r = draw(sts.point_near_edge(xy))
    elif kind == "on_edge":
        r = draw(sts.point_on_boundary(xy))[0]
    else:
        r = xy[draw(st.integers(0, len(xy) - 1))].copy()
    shift = np.array(draw(st.tuples(st.floats(-3, 3), st.floats(-3, 3))))
    scale = draw(st.floats(0.05, 20.0))
    return (xy + shift) * scale, (r + shift) * scale, kind


@given(polygon_and_point())
def test_support_matches_reference(case):
    verts, r, _ = case
    assert_support_close(verts, r, kernel_support(verts, r), ref.support_ref(verts, r))


@pytest.mark.parametrize("poly", range(len(sts.DYADIC_POLYGONS)))
def test_support_exactly_on_edges_and_vertices(poly):
    """Points exactly on an edge (dyadic polygon, dyadic edge fractions) and on
    every vertex; also continuity of E, G, N across the boundary."""
    verts = sts.DYADIC_POLYGONS[poly]
    n = len(verts)
    for j in range(n):
        p, q = verts[j], verts[(j + 1) % n]
        for t in (0.5, 0.25, 0.875):
            r = p + t * (q - p)  # exact in binary floating point
            want = ref.support_ref(verts, r)
            got = kernel_support(verts, r)
            assert_support_close(verts, r, got, want)
            # Continuity: values just inside/outside the edge converge to these.
            e = q - p
            m = np.array([e[1], -e[0]]) / math.hypot(*e)
            for sgn in (-1.0, 1.0):
                near = kernel_support(verts, r + sgn * 1e-9 * m)
                assert_support_close(verts, r, near, want, rtol=1e-6)
        assert_support_close(verts, p, kernel_support(verts, p), ref.support_ref(verts, p))


@given(sts.polygons(), st.data())
def test_g_is_minus_grad_e_and_n_is_grad_g(xy, data):
    kind = data.draw(st.sampled_from(["inside", "outside"]))
    r = data.draw(sts.point_inside_star(xy) if kind == "inside" else sts.point_outside(xy))
    assume(boundary_distance(xy, r) > 0.03)
    h = 1e-5
    s0 = kernel_support(xy, r)
    grad_e = np.empty(2)
    jac_g = np.empty((2, 2))
    for k in range(2):
        dr = np.zeros(2)
        dr[k] = h
        sp, sm = kernel_support(xy, r + dr), kernel_support(xy, r - dr)
        grad_e[k] = (sp[0] - sm[0]) / (2 * h)
        jac_g[:, k] = (sp[1:3] - sm[1:3]) / (2 * h)
    area = ref.signed_area(xy)
    np.testing.assert_allclose(s0[1:3], -grad_e, atol=1e-7 * area)
    nmat = np.array([[s0[3], s0[4]], [s0[4], s0[5]]])
    tol = 1e-6 * max(np.abs(nmat).max(), area)
    np.testing.assert_allclose(jac_g, nmat - np.trace(nmat) * np.eye(2), atol=tol)


# --------------------------------------------------------------------------- m_max, disc


@pytest.mark.parametrize("n", [3, 5, 8, 33, 400])
def test_max_moment_regular_ngon_analytic(n):
    radius = 1.7
    ang = 2 * math.pi * np.arange(n) / n + 0.3
    verts = radius * np.column_stack([np.cos(ang), np.sin(ang)])
    area = ref.signed_area(verts)
    m = _max_moment(verts, area)
    assert m == pytest.approx(ref.regular_ngon_moment(n, radius), rel=1e-11)
    if n >= 5:
        # Inscribed disc <= polygon <= circumscribed disc gives, for the mean
        # distance from the centre: 2 R cos(pi/n) / 3 <= m_max <= 2 R / 3.
        assert 2 * radius * math.cos(math.pi / n) / 3 <= m <= 2 * radius / 3


def test_max_moment_tends_to_disc():
    radius = 2.5
    for n in (256, 4096):
        ang = 2 * math.pi * np.arange(n) / n
        verts = radius * np.column_stack([np.cos(ang), np.sin(ang)])
        m = _max_moment(verts, ref.signed_area(verts))
        bound = 2 * radius / 3 * (1 - math.cos(math.pi / n))  # polygon error bound
        assert abs(m - 2 * radius / 3) <= bound
    # Prepared (a = 1) disc-like part: m_max -> 2/3.
    ang = 2 * math.pi * np.arange(1024) / 1024
    _, _, a, _, m_max, convex = _prepare(7.0 * np.column_stack([np.cos(ang), np.sin(ang)]) + 3.0)
    assert convex and a == pytest.approx(7.0, rel=1e-12)
    assert abs(m_max - 2.0 / 3.0) <= 2.0 / 3.0 * (1 - math.cos(math.pi / 1024))


@given(sts.polygons())
def test_max_moment_matches_reference(xy):
    verts, area, _ = ref.ccw_centred(xy)
    want = ref.support_ref(verts, (0.0, 0.0))[0] / area
    assert _max_moment(verts, area) == pytest.approx(want, rel=1e-10)


# --------------------------------------------------------------------------- quadrature


@given(sts.polygons())
def test_fan_quadrature_exact_for_low_degree_polynomials(xy):
    verts, _, _, quad, _, _ = _prepare(xy)
    x, y, w = quad[:, 0], quad[:, 1], quad[:, 2]
    area = ref.signed_area(verts)
    assert w.sum() == pytest.approx(area, rel=1e-13)
    assert abs((w * x).sum()) <= 1e-13 and abs((w * y).sum()) <= 1e-13  # centroid
    for i, j in [(2, 0), (1, 1), (0, 2), (3, 4), (7, 3), (0, 10)]:
        def mono(px, py, dx, dy, i=i, j=j):
            return (px ** i * py ** j)[None]

        want = ref.fan_integrate(verts, (0.0, 0.0), mono)[0]
        assert (w * x ** i * y ** j).sum() == pytest.approx(want, rel=1e-11, abs=1e-13)


# --------------------------------------------------------------------------- belt power


def kernel_power(verts, quad, area, xi):
    res = _power(quad, area, float(xi[0]), float(xi[1]), float(xi[2]))
    g = np.array(res[1:4])
    h = np.array([[res[4], res[5], res[6]], [res[5], res[7], res[8]], [res[6], res[8], res[9]]])
    return res[0], g, h


def twist_with_cor(r, om):
    """Twist with centre of rotation r and rate om: v = -om z x r = om (r_y, -r_x)."""
    return np.array([om * r[1], -om * r[0], om])


@st.composite
def prepared_and_twist(draw, regime):
    xy = draw(sts.polygons())
    verts, area, _, quad, _, _ = _prepare(xy)
    om = draw(st.floats(0.2, 3.0)) * draw(st.sampled_from([-1.0, 1.0]))
    ang = draw(st.floats(0.0, 2 * math.pi))
    u = np.array([math.cos(ang), math.sin(ang)])
    if regime == "near":
        kind = draw(st.sampled_from(["inside", "outside"]))
        if kind == "inside":
            r = draw(sts.point_inside_star(verts))
        else:
            r = draw(st.floats(1.05, 0.95 * _R_FAR)) * u
        assume(boundary_distance(verts, r) > 0.03)
        xi = twist_with_cor(r, om)
    else:
        kind = draw(st.sampled_from(["far", "translation"]))
        if kind == "far":
            xi = twist_with_cor(draw(st.floats(1.05 * _R_FAR, 25.0 * _R_FAR)) * u, om)
        else:
            xi = np.array([u[0], u[1], 0.0]) * abs(om)
    return verts, area, quad, xi


def _check_power_against_reference(verts, area, quad, xi):
    p, g, h = kernel_power(verts, quad, area, xi)
    pr, gr, hr = ref.power_ref(verts, *xi, derivatives=True)
    scale = np.hypot(xi[0], xi[1]) + abs(xi[2])
    assert p == pytest.approx(pr, rel=1e-9, abs=1e-12 * scale)
    np.testing.assert_allclose(g, gr, rtol=0, atol=1e-9 * max(1.0, np.abs(gr).max()))
    np.testing.assert_allclose(h, hr, rtol=0, atol=1e-8 * np.abs(hr).max())


def _check_power_derivatives_fd(verts, area, quad, xi):
    p, g, h = kernel_power(verts, quad, area, xi)
    # Positive homogeneity of degree 1: g . xi = P, H xi = 0.
    assert g @ xi == pytest.approx(p, rel=1e-10)
    np.testing.assert_allclose(h @ xi, 0.0, atol=1e-9 * np.abs(h).max() * np.abs(xi).max())
    step = 1e-5 * np.abs(xi).max()
    g_fd = np.empty(3)
    h_fd = np.empty((3, 3))
    for k in range(3):
        d = np.zeros(3)
        d[k] = step
        pp, gp, _ = kernel_power(verts, quad, area, xi + d)
        pm, gm, _ = kernel_power(verts, quad, area, xi - d)
        g_fd[k] = (pp - pm) / (2 * step)
        h_fd[:, k] = (gp - gm) / (2 * step)
    np.testing.assert_allclose(g, g_fd, rtol=0, atol=1e-7 * max(1.0, np.abs(g).max()))
    np.testing.assert_allclose(h, h_fd, rtol=0, atol=1e-6 * np.abs(h).max())


@given(prepared_and_twist("near"))
def test_power_closed_form_regime_matches_reference(case):
    _check_power_against_reference(*case)


@given(prepared_and_twist("far"))
def test_power_quadrature_regime_matches_reference(case):
    _check_power_against_reference(*case)


@given(prepared_and_twist("near"))
def test_power_derivatives_finite_differences_near(case):
    _check_power_derivatives_fd(*case)


@given(prepared_and_twist("far"))
def test_power_derivatives_finite_differences_far(case):
    _check_power_derivatives_fd(*case)


@given(sts.polygons(), st.floats(0.0, 2 * math.pi), st.floats(0.3, 3.0))
def test_power_continuous_across_regime_switch(xy, ang, om):
    """P, grad P and Hess P agree on both sides of the switch at |COR| =
    _R_FAR (8 a: closed forms inside, quadrature outside), and with the
    reference there."""
    verts, area, _, quad, _, _ = _prepare(xy)
    u = np.array([math.cos(ang), math.sin(ang)])
    lo = kernel_power(verts, quad, area, twist_with_cor(_R_FAR * (1 - 1e-12) * u, om))
    hi = kernel_power(verts, quad, area, twist_with_cor(_R_FAR * (1 + 1e-12) * u, om))
    pr, gr, hr = ref.power_ref(verts, *twist_with_cor(_R_FAR * u, om), derivatives=True)
    for p, g, h in (lo, hi):
        assert p == pytest.approx(pr, rel=1e-10)
        np.testing.assert_allclose(g, gr, rtol=0, atol=1e-9 * np.abs(gr).max())
        np.testing.assert_allclose(h, hr, rtol=0, atol=1e-8 * np.abs(hr).max())
    assert lo[0] == pytest.approx(hi[0], rel=1e-10)


def test_power_special_twists():
    """Pure translation: P = |v|, force = v/|v|, no moment about the centroid.
    Pure spin about the centroid: P = |om| m_max, moment = sign(om) m_max."""
    xy = np.array([[0.0, 0.0], [3.0, 0.0], [3.0, 1.0], [1.0, 1.0], [1.0, 2.5], [0.0, 2.5]])
    verts, area, _, quad, m_max, _ = _prepare(xy)
    p, g, _ = kernel_power(verts, quad, area, np.array([0.6, -0.8, 0.0]) * 2.0)
    assert p == pytest.approx(2.0, rel=1e-13)
    np.testing.assert_allclose(g, [0.6, -0.8, 0.0], atol=1e-13)
    s0 = ref.support_ref(verts, (0.0, 0.0))
    m_ref = s0[0] / ref.signed_area(verts)
    for om in (1.5, -0.5):
        p, g, _ = kernel_power(verts, quad, area, np.array([0.0, 0.0, om]))
        assert p == pytest.approx(abs(om) * m_ref, rel=1e-12)
        assert g[2] == pytest.approx(math.copysign(m_ref, om), rel=1e-12)
        # Net force of a spin about the centroid: (s/A) z x G(0) (not zero for
        # an asymmetric part: only int w dA vanishes, not int w/|w| dA).
        want = math.copysign(1.0, om) / ref.signed_area(verts) * np.array([-s0[2], s0[1]])
        assert np.abs(want).max() > 0.01
        np.testing.assert_allclose(g[:2], want, atol=1e-12)
    assert m_max == pytest.approx(m_ref, rel=1e-12)
