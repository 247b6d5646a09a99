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
brute-force quadrature. The sums themselves are in ``edge_integrals``.

The belt's power for a twist ``xi = (v_x, v_y, omega)`` (spec section 3) is
``P = (1/A) integral |v + omega z x w| dA``. For a centre of rotation within
``_R_FAR`` of the centroid it is evaluated from E, G, N; farther out (nearly a
translation) the closed forms lose digits to cancellation, and a collapsed
Gauss rule on the centroid fan is exact to rounding because the integrand is
smooth there. A part with many edges carries a support table
(``support_table``, built by ``rollout._prepare_loops``): ``_power`` then
takes E, G, N from the table and, far out, the power from the material's
moment series, at a cost that does not grow with the number of edges.

A point support replaces the area integral by a weighted sum over
K points, ``P = sum_k w_k |u(p_k)|``: ``_point_power`` at the end of this
module (the quadrature branch's sums, one loop for both: ``_point_sums``;
the kinks of P at the points are left to ``models._minimise_points``).
"""
import math

import numpy as np

from ._numba import jit, jit_alloc, jit_inline
from .edge_integrals import _edge_support, _support_sum, _table_sizes  # noqa: F401 (re-exported)
from .support_table import _has_table, _moment_power, _table_support

# Centre-of-rotation distance (in units of a) beyond which the power uses the
# smooth quadrature instead of the closed forms (see module notes).
_R_FAR = 8.0
_GL_N = 6
_GL_X, _GL_W = np.polynomial.legendre.leggauss(_GL_N)
_GL_X = 0.5 * (_GL_X + 1.0)
_GL_W = 0.5 * _GL_W


@jit_alloc
def _support(verts, rx, ry):
    """E(r), G(r) and N(r) of the polygon ``verts`` (counter-clockwise; a
    keyhole polygon of ``geometry._keyhole`` for a part with holes).

    Returns ``(E, Gx, Gy, Nxx, Nxy, Nyy)``.
    """
    return _support_sum(_fan_quadrature(verts), rx, ry)


@jit_alloc
def _fan_quadrature(verts):
    """The support table of the polygon ``verts``: a collapsed
    Gauss-Legendre rule over its centroid fan, its vertices and its edges'
    unit directions.

    Returns an ``(F + 2 n + 1, 3)`` array (``F = n g^2``, ``g = _GL_N``):

    - ``F`` rows ``(x, y, weight)`` with signed weights, so the rule
      integrates smooth functions over non-convex polygons, and over a
      keyhole polygon (``_keyhole``) the material without its holes;
    - ``n`` rows ``(x_j, y_j, 0)``: the vertices;
    - ``n`` rows ``(e_x, e_y, 0)``: the unit direction of edge ``j``
      (vertex ``j`` to ``j + 1``);
    - one row ``(F, n, 0)`` that says so (``_table_sizes``).

    The weights after row ``F`` are zero, so a sum over all rows but the
    last is still the quadrature. ``_power`` reads the vertices and
    directions from here (see ``_support_sum``) instead of normalising every
    edge in every evaluation. A point support replaces the first ``F`` rows
    by its points and ``F`` by their count (``maps.simulate``).
    """
    n = verts.shape[0]
    g = _GL_X.shape[0]
    f = n * g * g
    out = np.empty((f + 2 * n + 1, 3))
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
    for j in range(n):
        k = (j + 1) % n
        ex, ey = verts[k, 0] - verts[j, 0], verts[k, 1] - verts[j, 1]
        length = math.sqrt(ex * ex + ey * ey)
        out[f + j, 0] = verts[j, 0]
        out[f + j, 1] = verts[j, 1]
        out[f + j, 2] = 0.0
        out[f + n + j, 0] = ex / length
        out[f + n + j, 1] = ey / length
        out[f + n + j, 2] = 0.0
    out[f + 2 * n, 0] = f
    out[f + 2 * n, 1] = n
    out[f + 2 * n, 2] = 0.0
    return out


@jit_alloc
def _point_table(quad, pts):
    """The support table ``quad`` with its quadrature rows replaced by the
    point support ``pts`` (``(K, 3)`` rows ``(x, y, w)``, units of a,
    weights summing to 1): what ``MINPOWER_POINTS`` rolls on."""
    f = _table_sizes(quad)[0]
    k = pts.shape[0]
    out = np.empty((k + quad.shape[0] - f, 3))
    out[:k] = pts
    out[k:] = quad[f:]
    out[out.shape[0] - 1, 0] = k
    return out


@jit
def _power(quad, area, vx, vy, om):
    """Belt power P(xi), its gradient and Hessian for the twist ``(vx, vy, om)``.

    Units: ``mu_s m g`` times speed. The gradient's first two entries are the
    force the pin must supply to balance belt friction (spec section 3).

    Returns ``(P, gx, gy, gw, Hxx, Hxy, Hxw, Hyy, Hyw, Hww)``.
    """
    if om * om * (_R_FAR * _R_FAR) > vx * vx + vy * vy and om != 0.0:
        # Rotation about r = z x v / omega within _R_FAR: closed forms.
        inv_om = 1.0 / om
        rx, ry = -vy * inv_om, vx * inv_om
        if _has_table(quad):
            e_val, gx, gy, nxx, nxy, nyy = _table_support(quad, rx, ry)
        else:
            e_val, gx, gy, nxx, nxy, nyy = _support_sum(quad, rx, ry)
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
    if _has_table(quad) and (vx != 0.0 or vy != 0.0):
        return _moment_power(quad, area, vx, vy, om)
    # The quadrature rows as weighted points (no point skipped: a tiny of -1).
    r = _point_sums(quad, _table_sizes(quad)[0], vx, vy, om, -1, -1.0)
    f = 1.0 / area
    return (f * r[0], f * r[1], f * r[2], f * r[3], f * r[4], f * r[5], f * r[6], f * r[7],
            f * r[8], f * r[9])


@jit_alloc
def _max_moment(verts, area):
    """m_max = E(0) / A: the belt's friction moment on a part spinning about its
    centroid, in units of mu_s m g times length (2R/3 for a disc of radius R)."""
    return _support(verts, 0.0, 0.0)[0] / area


# --------------------------------------------------------------------------- point supports


@jit
def _point_power(pts, m, vx, vy, om, skip):
    """Belt power of a point support, its gradient and Hessian in the twist.

    Parameters
    ----------
    pts : array whose first ``m`` rows are ``(x, y, w)``: support points in
        the part frame (units of a) and weights that sum to 1 (the rows after
        them are ignored; ``models.MINPOWER_POINTS`` passes the rollout's
        ``quad`` built that way).
    m : number of support points.
    vx, vy, om : the twist.
    skip : index of a point left out of the sums (-1: none).

    Returns
    -------
    (P, g0, g1, g2, H00, H01, H02, H11, H12, H22, jmin, rmin, umin)
        P and its gradient and Hessian over the points whose slip speed is
        not zero, the point ``jmin`` with the smallest ``|u_j| / w_j`` (the
        kink the twist is nearest, -1 if none), that ratio, and the
        smallest slip speed ``|u_j|``.

    Notes
    -----
    With ``u_j = (vx - om y_j, vy + om x_j)`` the velocity of point j::

        P = sum_j w_j |u_j|
        grad P = sum_j w_j J_j^T u_j / |u_j|,     J_j = [[1, 0, -y_j], [0, 1, x_j]]
        Hess P = sum_j (w_j / |u_j|) a_j a_j^T,   a_j = J_j^T (z x u_j / |u_j|)

    (the sums of ``_power``'s quadrature branch, with the points as the
    rule: both are ``_point_sums``). A point with ``u_j = 0`` (the centre of
    rotation on it) is a kink of P: it adds nothing to P, and the zero
    vector of its subdifferential ``w_j J_j^T B`` (B the unit disc) to the
    gradient; it is left out of the Hessian, where its term is unbounded.
    ``models._minimise_points`` picks the element of B that the optimality
    condition needs.
    """
    return _point_sums(pts, m, vx, vy, om, skip, 1e-15 * (abs(vx) + abs(vy) + abs(om)))


@jit_inline
def _point_sums(pts, m, vx, vy, om, skip, tiny):
    """The sums of ``_point_power`` over the first ``m`` rows ``(x, y, w)`` of
    ``pts``, leaving out point ``skip`` and the points whose slip speed is at
    most ``tiny`` (none for a negative ``tiny``); the one loop that
    accumulates P, its gradient and Hessian, for a point support and for
    ``_power``'s quadrature rule (signed weights, not normalised; the
    caller divides by the area).

    Returns ``_point_power``'s 13 values.

    Notes
    -----
    Per point, ``h = u / |u|`` and the unit perpendicular ``p = z x h``:
    ``(I - h h^T) / |u| = p p^T / |u|``, so the Hessian term is
    ``(w / |u|) a a^T`` with ``a = J^T p`` (``_point_power``'s notes).
    """
    p_val = g0 = g1 = g2 = 0.0
    h00 = h01 = h02 = h11 = h12 = h22 = 0.0
    jmin = -1
    rmin = math.inf
    umin = math.inf
    for i in range(m):
        wx, wy, wt = pts[i, 0], pts[i, 1], pts[i, 2]
        ux = vx - om * wy
        uy = vy + om * wx
        nu = math.sqrt(ux * ux + uy * uy)
        if nu < rmin * wt:
            rmin = nu / wt
            jmin = i
        umin = min(umin, nu)
        if i == skip or nu <= tiny:
            continue
        p_val += wt * nu
        hx, hy = ux / nu, uy / nu
        g0 += wt * hx
        g1 += wt * hy
        g2 += wt * (wx * hy - wy * hx)
        ax, ay = -hy, hx
        aw = wx * ay - wy * ax
        c = wt / nu
        h00 += c * ax * ax
        h01 += c * ax * ay
        h02 += c * ax * aw
        h11 += c * ay * ay
        h12 += c * ay * aw
        h22 += c * aw * aw
    return p_val, g0, g1, g2, h00, h01, h02, h11, h12, h22, jmin, rmin, umin
