"""Exact support integrals of a polygon as sums over its edges.

With ``rho = |w - r|`` and ``w_hat = (w - r) / rho`` over the polygon area:

    E(r) = integral rho dA                (polar moment about r)
    G(r) = integral w_hat dA              (= -grad E)
    N(r) = integral w_hat w_hat^T / rho dA (enters the Hessian of the power)

Notes
-----
Each integral is a signed sum over edges of the triangle (r, p, q); the
closed forms are in ``support``'s module notes and in ``_edge_support``.
``support._power`` evaluates them through ``_support_sum`` for parts with
few edges, and ``support_table`` tabulates their far part for parts with
many (the near edges still come from here).
"""
import math

from ._numba import jit


@jit
def _edge_support(px, py, r1, i1, qx, qy, r2, i2, ex, ey):
    """Scaled signed E, G, N of the triangle (0, p, q); coordinates relative
    to r, ``r1 = |p|``, ``i1 = 1 / r1`` (likewise ``r2``, ``i2`` for q; both
    shared with the neighbouring edges) and ``(ex, ey)`` the unit direction
    from p to q.

    Returns ``(6 E, 2 Gx, 2 Gy, Nxx, Nxy, Nyy)``; ``_support_sum`` applies
    the factors 1/6 and 1/2 once for the whole polygon.

    Notes
    -----
    With ``m = (e_y, -e_x)``, ``h = cross(p, e)``, ``t = (p . e, q . e)`` and
    ``[S] = log((t_2 + r_2) / (t_1 + r_1))`` (module notes)::

        6 E = h [t R] + h^3 [S]
        2 G = h [R] e + h^2 [S] m
        N   = c_ee e e^T + c_em (e m^T + m e^T) + c_mm m m^T
        c_ee = h ([S] - [t/R]),  c_em = -h^2 [1/R],  c_mm = h [t/R]

    Written out with ``m`` in terms of ``e``, the off-diagonal and diagonal
    entries need no further products of unit vectors. Only multiplications
    by the reciprocal distances remain: no division by a distance per edge.
    """
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
    hds = h * math.log(p2 / p1)
    dtor = t2 * i2 - t1 * i1
    e6 = h * (t2 * r2 - t1 * r1) + hh * hds
    a = h * (r2 - r1)
    gx2 = a * ex + h * hds * ey
    gy2 = a * ey - h * hds * ex
    cee = hds - h * dtor
    cem = -hh * (i2 - i1)
    cmm = h * dtor
    exx, eyy, exy = ex * ex, ey * ey, ex * ey
    nxx = cee * exx + 2.0 * cem * exy + cmm * eyy
    nxy = (cee - cmm) * exy + cem * (eyy - exx)
    nyy = cee * eyy - 2.0 * cem * exy + cmm * exx
    return e6, gx2, gy2, nxx, nxy, nyy


@jit
def _table_sizes(quad):
    """``(F, S)``: the number of quadrature (or support point) rows of a
    support table and the number of vertices of its support polygon (its
    last row; see ``_fan_quadrature``)."""
    return int(quad[quad.shape[0] - 1, 0]), int(quad[quad.shape[0] - 1, 1])


@jit
def _support_sum(quad, rx, ry):
    """E(r), G(r), N(r) of the support polygon of the table ``quad`` (see
    ``_fan_quadrature``: its vertex positions and edges' unit directions).

    Returns ``(E, Gx, Gy, Nxx, Nxy, Nyy)``.

    Notes
    -----
    Per vertex one square root and one reciprocal; per edge one logarithm
    and, only for an edge end behind the foot of the perpendicular, one
    division (see ``_edge_support``). The unit directions do not depend on
    r, so the prepared table saves a square root and a division per edge.
    The edges are signed: the outline counter-clockwise, holes clockwise,
    so the sum is the integral over the material (module notes).
    """
    f, n = _table_sizes(quad)
    pos = f
    base = f + n
    e_val = gx = gy = nxx = nxy = nyy = 0.0
    x0, y0 = quad[pos, 0] - rx, quad[pos, 1] - ry
    r0 = math.sqrt(x0 * x0 + y0 * y0)
    i0 = 1.0 / r0
    px, py, r1, i1 = x0, y0, r0, i0
    for j in range(n):
        if j + 1 < n:
            qx, qy = quad[pos + j + 1, 0] - rx, quad[pos + j + 1, 1] - ry
            r2 = math.sqrt(qx * qx + qy * qy)
            i2 = 1.0 / r2
        else:
            qx, qy, r2, i2 = x0, y0, r0, i0
        ex, ey = quad[base + j, 0], quad[base + j, 1]
        a0, a1, a2, a3, a4, a5 = _edge_support(px, py, r1, i1, qx, qy, r2, i2, ex, ey)
        e_val += a0
        gx += a1
        gy += a2
        nxx += a3
        nxy += a4
        nyy += a5
        px, py, r1, i1 = qx, qy, r2, i2
    return e_val / 6.0, 0.5 * gx, 0.5 * gy, nxx, nxy, nyy
