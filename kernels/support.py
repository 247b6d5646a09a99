"""Exact support integrals of a uniformly pressed polygon and the belt's power.

With ``rho = |w - r|`` and ``w_hat = (w - r) / rho`` over the polygon area:

    E(r) = integral rho dA                (polar moment about r)
    G(r) = integral w_hat dA              (= -grad E)
    N(r) = integral w_hat w_hat^T / rho dA (enters the Hessian of the power)

Notes
-----
Each integral is a signed sum over edges of the triangle (r, p, q). In the
edge's own frame (unit direction ``e``, outward normal ``m = (e_y, -e_x)``,
signed height ``h = cross(p - r, e)``, positions ``t`` of the edge ends along
``e`` from the foot of the perpendicular, ``R = sqrt(h^2 + t^2)``) polar
integration about r gives, with ``S = asinh(t / |h|) = log((t + R) / |h|)``
and ``[.]`` the difference between the two ends::

    E_edge = h/6 [t R] + h^3/6 [S]
    G_edge = h/2 (e [R] + h m [S])
    N_edge = h (e e^T ([S] - [t/R]) - h (e m^T + m e^T) [1/R] + m m^T [t/R])

An edge whose line passes through r (h = 0) contributes nothing, so the forms
hold for r inside, outside, on an edge and on a vertex. The derivation is in
the README's "Mechanics notes"; ``tests/reference.py`` checks them against
brute-force quadrature.

The belt's power for a twist ``xi = (v_x, v_y, omega)`` (spec section 3) is
``P = (1/A) integral |v + omega z x w| dA``. For a centre of rotation within
``_R_FAR`` of the centroid it is evaluated from E, G, N; farther out (nearly a
translation) the closed forms lose digits to cancellation, and a collapsed
Gauss rule on the centroid fan is exact to rounding because the integrand is
smooth there.
"""
import math

import numpy as np

from ._numba import jit

# Centre-of-rotation distance (in units of a) beyond which the power uses the
# smooth quadrature instead of the closed forms (see module notes).
_R_FAR = 8.0
_GL_N = 6
_GL_X, _GL_W = np.polynomial.legendre.leggauss(_GL_N)
_GL_X = 0.5 * (_GL_X + 1.0)
_GL_W = 0.5 * _GL_W


@jit
def _edge_support(px, py, r1, qx, qy, r2):
    """Signed E, G, N of the triangle (0, p, q); coordinates relative to r,
    ``r1 = |p|`` and ``r2 = |q|`` (shared with the neighbouring edges).

    Returns ``(E, Gx, Gy, Nxx, Nxy, Nyy)``.
    """
    ex, ey = qx - px, qy - py
    inv = 1.0 / math.sqrt(ex * ex + ey * ey)
    ex *= inv
    ey *= inv
    mx, my = ey, -ex
    h = px * ey - py * ex
    if abs(h) <= 1e-15 * (r1 + r2):
        return 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
    t1 = px * ex + py * ey
    t2 = qx * ex + qy * ey
    # [asinh(t/|h|)] = log of (t2 + R2)/(t1 + R1), each written without
    # cancellation: t + R = h^2 / (R - t) when t < 0.
    hh = h * h
    p1 = t1 + r1 if t1 >= 0.0 else hh / (r1 - t1)
    p2 = t2 + r2 if t2 >= 0.0 else hh / (r2 - t2)
    ds = math.log(p2 / p1)
    dtr = t2 * r2 - t1 * r1
    dr = r2 - r1
    dtor = t2 / r2 - t1 / r1
    dinv = 1.0 / r2 - 1.0 / r1
    e_val = h * dtr / 6.0 + hh * h * ds / 6.0
    gx = 0.5 * h * (ex * dr + h * mx * ds)
    gy = 0.5 * h * (ey * dr + h * my * ds)
    cee = h * (ds - dtor)
    cem = -hh * dinv
    cmm = h * dtor
    nxx = cee * ex * ex + 2.0 * cem * ex * mx + cmm * mx * mx
    nxy = cee * ex * ey + cem * (ex * my + mx * ey) + cmm * mx * my
    nyy = cee * ey * ey + 2.0 * cem * ey * my + cmm * my * my
    return e_val, gx, gy, nxx, nxy, nyy


@jit
def _support(verts, rx, ry):
    """E(r), G(r) and N(r) of the counter-clockwise polygon ``verts``.

    Returns ``(E, Gx, Gy, Nxx, Nxy, Nyy)``.
    """
    n = verts.shape[0]
    e_val = gx = gy = nxx = nxy = nyy = 0.0
    px, py = verts[0, 0] - rx, verts[0, 1] - ry
    r_first = math.sqrt(px * px + py * py)
    r1 = r_first
    for j in range(n):
        if j + 1 < n:
            qx, qy = verts[j + 1, 0] - rx, verts[j + 1, 1] - ry
            r2 = math.sqrt(qx * qx + qy * qy)
        else:
            qx, qy = verts[0, 0] - rx, verts[0, 1] - ry
            r2 = r_first
        a0, a1, a2, a3, a4, a5 = _edge_support(px, py, r1, qx, qy, r2)
        e_val += a0
        gx += a1
        gy += a2
        nxx += a3
        nxy += a4
        nyy += a5
        px, py, r1 = qx, qy, r2
    return e_val, gx, gy, nxx, nxy, nyy


@jit
def _fan_quadrature(verts):
    """Collapsed Gauss-Legendre rule over the centroid fan of ``verts``.

    Returns an ``(m, 3)`` array of ``(x, y, weight)``; weights are signed, so
    the rule integrates smooth functions over non-convex polygons too.
    """
    n = verts.shape[0]
    g = _GL_X.shape[0]
    out = np.empty((n * g * g, 3))
    m = 0
    for j in range(n):
        k = (j + 1) % n
        px, py = verts[j, 0], verts[j, 1]
        qx, qy = verts[k, 0], verts[k, 1]
        jac = px * qy - py * qx
        for a in range(g):
            u = _GL_X[a]
            for b in range(g):
                v = _GL_X[b]
                out[m, 0] = u * (px + v * (qx - px))
                out[m, 1] = u * (py + v * (qy - py))
                out[m, 2] = _GL_W[a] * _GL_W[b] * u * jac
                m += 1
    return out


@jit
def _power(verts, quad, area, vx, vy, om):
    """Belt power P(xi), its gradient and Hessian for the twist ``(vx, vy, om)``.

    Units: ``mu_s m g`` times speed. The gradient's first two entries are the
    force the pin must supply to balance belt friction (spec section 3).

    Returns ``(P, gx, gy, gw, Hxx, Hxy, Hxw, Hyy, Hyw, Hww)``.
    """
    speed = math.hypot(vx, vy)
    if abs(om) * _R_FAR > speed and om != 0.0:
        # Rotation about r = z x v / omega: closed forms.
        rx, ry = -vy / om, vx / om
        e_val, gx, gy, nxx, nxy, nyy = _support(verts, rx, ry)
        s = 1.0 if om > 0.0 else -1.0
        p_val = abs(om) * e_val / area
        f = s / area
        g0 = -f * gy
        g1 = f * gx
        g2 = f * (e_val + rx * gx + ry * gy)
        k = 1.0 / (area * abs(om))
        px, py = -ry, rx
        npx = nxx * px + nxy * py
        npy = nxy * px + nyy * py
        return (p_val, g0, g1, g2, k * nxx, k * nxy, k * npx, k * nyy, k * npy,
                k * (px * npx + py * npy))
    p_val = g0 = g1 = g2 = 0.0
    h00 = h01 = h02 = h11 = h12 = h22 = 0.0
    for i in range(quad.shape[0]):
        wx, wy, wt = quad[i, 0], quad[i, 1], quad[i, 2]
        ux = vx - om * wy
        uy = vy + om * wx
        nu = math.sqrt(ux * ux + uy * uy)
        p_val += wt * nu
        hx, hy = ux / nu, uy / nu
        g0 += wt * hx
        g1 += wt * hy
        g2 += wt * (wx * hy - wy * hx)
        # (I - u u^T)/|u| = p p^T/|u| with p the unit perpendicular.
        ax, ay = -hy, hx
        aw = wx * ay - wy * ax
        c = wt / nu
        h00 += c * ax * ax
        h01 += c * ax * ay
        h02 += c * ax * aw
        h11 += c * ay * ay
        h12 += c * ay * aw
        h22 += c * aw * aw
    f = 1.0 / area
    return (f * p_val, f * g0, f * g1, f * g2, f * h00, f * h01, f * h02, f * h11,
            f * h12, f * h22)


@jit
def _max_moment(verts, area):
    """m_max = E(0) / A: the belt's friction moment on a part spinning about its
    centroid, in units of mu_s m g times length (2R/3 for a disc of radius R)."""
    return _support(verts, 0.0, 0.0)[0] / area
