"""Slow, obviously-correct reference implementations for the support integrals.

Nothing here uses the kernels' closed forms. Every area integral over a
simple polygon is computed the same brute-force way:

* Fan-triangulate the polygon from a chosen centre ``o`` into signed
  triangles ``(o, V_j, V_j+1)``. For a counter-clockwise simple polygon their
  signed indicator functions add up to the polygon's indicator, whatever ``o``
  is (inside, outside, on an edge, on a vertex).
* Map each triangle from the unit square by the Duffy collapse
  ``w = o + u ((p - o) + v (q - p))``, ``dA = u * cross(p - o, q - o) du dv``.
  A point singularity of the integrand at ``o`` (``|w - o|``,
  ``(w - o)/|w - o|``, ``1/|w - o|``) becomes polynomial in ``u``, so a
  Gauss-Legendre rule in ``u`` is exact.
* In ``v`` the integrand is analytic but has complex singularities at
  distance ``dist(o, edge line) / |q - p|`` from the foot of the perpendicular
  ``v0`` (they approach the real axis when ``o`` is near the edge's line).
  A composite Gauss-Legendre rule on panels graded geometrically towards
  ``v0`` keeps every panel at least its own length away from them, so each
  panel converges geometrically and the total is good to ~1e-14 relative.

Units and conventions follow the spec (section 3): ``u(w) = v + omega z x w``
with ``z x w = (-w_y, w_x)``.
"""
import math

import numpy as np

# --------------------------------------------------------------------------- polygons


def signed_area(xy):
    xy = np.asarray(xy, dtype=float)
    x, y = xy[:, 0], xy[:, 1]
    return 0.5 * float(np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y))


def centroid(xy):
    xy = np.asarray(xy, dtype=float)
    x, y = xy[:, 0], xy[:, 1]
    xn, yn = np.roll(x, -1), np.roll(y, -1)
    cr = x * yn - xn * y
    a2 = cr.sum()
    return np.array([((x + xn) * cr).sum() / (3.0 * a2), ((y + yn) * cr).sum() / (3.0 * a2)])


def ccw_centred(xy):
    """Counter-clockwise copy with the area centroid at the origin, its area and a."""
    xy = np.asarray(xy, dtype=float)
    if signed_area(xy) < 0:
        xy = xy[::-1]
    out = xy - centroid(xy)
    return out, signed_area(out), float(np.max(np.hypot(out[:, 0], out[:, 1])))


def cross2(a, b):
    return a[0] * b[1] - a[1] * b[0]


# --------------------------------------------------------------------------- quadrature

_GL = {}


def gauss01(n):
    """Gauss-Legendre nodes and weights on [0, 1]."""
    if n not in _GL:
        x, w = np.polynomial.legendre.leggauss(n)
        _GL[n] = (0.5 * (x + 1.0), 0.5 * w)
    return _GL[n]


def _v_rule(p, q, nv):
    """Composite Gauss rule on [0, 1] graded towards the near-singularity of
    the edge ``p -> q`` (coordinates relative to the fan centre)."""
    e = q - p
    l2 = float(e @ e)
    v0 = -float(p @ e) / l2
    eps = abs(cross2(p, e)) / l2
    brk = [0.0, 1.0]
    if eps < 1.0:
        brk.append(v0)
        # Below ~1e-16 of the parameter range the integrand is not resolved
        # anyway, and those panels contribute below rounding.
        s = max(eps, 1e-16)
        while s < 4.0:
            brk.extend((v0 - s, v0 + s))
            s *= 2.0
    b = np.unique(np.clip(np.array(brk), 0.0, 1.0))
    x, w = gauss01(nv)
    lo, hi = b[:-1], b[1:]
    nodes = (lo[:, None] + (hi - lo)[:, None] * x[None, :]).ravel()
    weights = ((hi - lo)[:, None] * w[None, :]).ravel()
    return nodes, weights


def fan_integrate(verts, centre, func, nu=8, nv=20):
    """Integral over the CCW polygon ``verts`` of ``func(wx, wy, dx, dy)``.

    ``func`` takes flat arrays of the points ``w`` and of their offsets
    ``d = w - centre`` (computed directly as ``u (p - o + v (q - p))``, so they
    stay accurate, and non-zero, right next to the centre) and returns an
    array whose last axis runs over the points; the result has the remaining
    shape.
    """
    verts = np.asarray(verts, dtype=float)
    o = np.asarray(centre, dtype=float)
    xu, wu = gauss01(nu)
    total = None
    n = len(verts)
    for j in range(n):
        p = verts[j] - o
        q = verts[(j + 1) % n] - o
        cr = cross2(p, q)
        if cr == 0.0:
            continue  # degenerate triangle: contributes nothing
        xv, wv = _v_rule(p, q, nv)
        uu, vv = np.meshgrid(xu, xv, indexing="ij")
        wt = (np.outer(wu, wv) * uu * cr).ravel()
        dx = p[0] + vv * (q[0] - p[0])
        dy = p[1] + vv * (q[1] - p[1])
        ox_, oy_ = (uu * dx).ravel(), (uu * dy).ravel()
        vals = np.asarray(func(o[0] + ox_, o[1] + oy_, ox_, oy_)) @ wt
        total = vals if total is None else total + vals
    return total


# --------------------------------------------------------------------------- support


def support_ref(verts, r):
    """``(E, Gx, Gy, Nxx, Nxy, Nyy)`` about ``r`` by brute-force quadrature."""
    rx, ry = float(r[0]), float(r[1])

    def f(wx, wy, dx, dy):
        rho = np.hypot(dx, dy)
        # A node can land within rounding of r when r is on an edge's line (in
        # floating point); its weight is ~1e-16 of the panel, so drop it.
        rho = np.where(rho > 0.0, rho, np.inf)
        hx, hy = dx / rho, dy / rho
        return np.array([np.where(np.isfinite(rho), rho, 0.0), hx, hy, hx * hx / rho,
                         hx * hy / rho, hy * hy / rho])

    return fan_integrate(verts, (rx, ry), f)


def area_ref(verts):
    return float(fan_integrate(verts, (0.0, 0.0), lambda wx, wy, dx, dy: np.ones((1, wx.size)))[0])


def regular_ngon_moment(n, radius):
    """E(0) / A for a regular n-gon with circumradius ``radius``, analytically.

    One of the n isosceles triangles with apothem ``h`` and half-angle
    ``alpha = pi / n``: E = (h^3 / 3) (sec(alpha) tan(alpha) + ln(sec + tan)),
    area = h^2 tan(alpha).
    """
    alpha = math.pi / n
    h = radius * math.cos(alpha)
    sec, tan = 1.0 / math.cos(alpha), math.tan(alpha)
    e_tri = h ** 3 / 3.0 * (sec * tan + math.log(sec + tan))
    return e_tri / (h * h * tan)


# --------------------------------------------------------------------------- belt power


def power_ref(verts, vx, vy, om, derivatives=False):
    """P(xi) = (1/A) int |v + om z x w| dA (and optionally gradient, Hessian).

    The fan centre is the centre of rotation when it is at a moderate
    distance (there the integrand has its kink / singularity), else the
    centroid (the integrand is then smooth over the part).
    Returns ``P`` or ``(P, grad (3,), hess (3, 3))``.
    """
    verts = np.asarray(verts, dtype=float)
    area = signed_area(verts)
    scale = float(np.max(np.hypot(verts[:, 0], verts[:, 1])))
    speed = math.hypot(vx, vy)
    at_cor = om != 0.0 and speed <= 20.0 * scale * abs(om)
    centre = (-vy / om, vx / om) if at_cor else (0.0, 0.0)

    def f(wx, wy, dx, dy):
        if at_cor:  # u(w) = om z x (w - r)
            ux, uy = -om * dy, om * dx
        else:
            ux, uy = vx - om * wy, vy + om * wx
        nu = np.hypot(ux, uy)
        if not derivatives:
            return nu[None, :]
        # A node within rounding of the COR (COR on an edge's line) carries a
        # weight ~1e-16 of its panel: drop it rather than divide by zero.
        nu = np.where(nu > 0.0, nu, np.inf)
        hx, hy = ux / nu, uy / nu
        # J(w) = [[1, 0, -w_y], [0, 1, w_x]]; grad = J^T u_hat
        g = np.array([hx, hy, wx * hy - wy * hx])
        # Hessian = J^T (I - u_hat u_hat^T) J / |u| = a a^T / |u|, a = J^T perp
        ax, ay = -hy, hx
        aw = wx * ay - wy * ax
        c = 1.0 / nu
        hs = np.array([c * ax * ax, c * ax * ay, c * ax * aw, c * ay * ay, c * ay * aw,
                       c * aw * aw])
        return np.concatenate([np.where(np.isfinite(nu), nu, 0.0)[None, :], g, hs])

    res = fan_integrate(verts, centre, f) / area
    if not derivatives:
        return float(res[0])
    p, g, h = res[0], res[1:4], res[4:]
    hess = np.array([[h[0], h[1], h[2]], [h[1], h[3], h[4]], [h[2], h[4], h[5]]])
    return float(p), g, hess
