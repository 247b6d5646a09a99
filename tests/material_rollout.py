"""A slow, obviously-correct minimum-power rollout over the material of a part
with holes: brute-force quadrature, brute-force minimisation, small steps.

Nothing here uses the kernels or ``pipeline``: the part is given as its loops
(outline and holes, in any winding, any frame), and

* the belt's friction power ``P(xi) = sum_i w_i |u(w_i)| / sum_i w_i`` is a
  midpoint rule on a fine square grid over the material: the cells whose
  centre is inside the outline and outside every hole (even-odd rule over all
  loops), so a hole carries no pressure by construction;
* the twist is the spec's minimum-power twist (section 3): sticking minimises
  P over the one-parameter family with ``u(c) = v_p`` (scipy's bounded Brent
  search in omega); if the pin's force ``f = dP/dv`` leaves the friction
  cone, sliding minimises P over the two-parameter family ``e . u(c) = 1``
  (``e`` the cone edge on the side ``f . t`` points to; BFGS), rescaled so
  that ``n . u(c) = n . v_p``;
* the pose is stepped by midpoint (RK2) steps of fixed belt travel, the part
  moved along the contact normal after each step to keep the pin on its
  boundary, until the pin moves away from the part.

Convex outlines only (one contact at a time, no re-contact after the pin
leaves): the holes are where the difference lies. Lengths in units of ``a``
(the largest distance from the material's centroid to an outline vertex), the
belt frame as in the spec: the pin moves with ``v_p = (-1, 0)`` per unit of
belt travel ``s``.
"""
from __future__ import annotations

import math

import numpy as np
from scipy import optimize


def _signed_area(xy):
    x, y = xy[:, 0], xy[:, 1]
    return 0.5 * float(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1)))


def _inside(loop, pts):
    """Even-odd rule: whether each point of ``pts`` is inside the closed ``loop``."""
    x0, y0 = loop[:, 0][None, :], loop[:, 1][None, :]
    x1, y1 = np.roll(loop[:, 0], -1)[None, :], np.roll(loop[:, 1], -1)[None, :]
    px, py = pts[:, 0][:, None], pts[:, 1][:, None]
    crosses = (y0 > py) != (y1 > py)
    with np.errstate(divide="ignore", invalid="ignore"):
        xc = x0 + (py - y0) * (x1 - x0) / (y1 - y0)
    return np.sum(crosses & (px < xc), axis=1) % 2 == 1


class MaterialPart:
    """A part as grid cells of its material, centred on their centroid, in units of a."""

    def __init__(self, outline, holes=(), cells=160):
        outline = np.asarray(outline, float)
        holes = [np.asarray(h, float) for h in holes]
        lo, hi = outline.min(axis=0), outline.max(axis=0)
        h = float(np.max(hi - lo)) / cells
        gx = np.arange(lo[0] + h / 2, hi[0], h)
        gy = np.arange(lo[1] + h / 2, hi[1], h)
        pts = np.array(np.meshgrid(gx, gy)).reshape(2, -1).T
        keep = _inside(outline, pts)
        for hole in holes:
            keep &= ~_inside(hole, pts)
        pts = pts[keep]
        centre = pts.mean(axis=0)  # equal cells: the material's centroid
        outline = outline - centre
        if _signed_area(outline) < 0:
            outline = outline[::-1]
        self.a = float(np.max(np.hypot(*outline.T)))
        self.outline = outline / self.a
        self.points = (pts - centre) / self.a
        self.area_mm2 = len(pts) * h * h

    # ----------------------------------------------------------------- power

    def power(self, vx, vy, om):
        """P and its gradient in (vx, vy, om) (units of mu_s m g)."""
        x, y = self.points[:, 0], self.points[:, 1]
        ux, uy = vx - om * y, vy + om * x
        nu = np.maximum(np.hypot(ux, uy), 1e-300)
        hx, hy = ux / nu, uy / nu
        grad = np.array([hx.mean(), hy.mean(), (x * hy - y * hx).mean()])
        return float(nu.mean()), grad

    def stick(self, c, vp):
        """Minimum-power twist with ``u(c) = vp``, and the pin's force ``dP/dv``."""
        def twist(om):
            return vp[0] + om * c[1], vp[1] - om * c[0], om
        res = optimize.minimize_scalar(lambda om: self.power(*twist(om))[0], bounds=(-60.0, 60.0),
                                       method="bounded", options={"xatol": 1e-10})
        xi = np.array(twist(res.x))
        return xi, self.power(*xi)[1][:2]

    def slide(self, c, e, n, vp):
        """Minimum-power twist with ``e . u(c) = 1``, rescaled to ``n . u(c) = n . vp``."""
        # u(c) = v + om z x c; e . u(c) = e.v + om (e_y c_x - e_x c_y) = 1
        t_e = np.array([-e[1], e[0]])
        k = e[1] * c[0] - e[0] * c[1]

        def twist(y):
            # v = e + y0 t_e - y1 k e ... chosen so e . u(c) = 1 for all y
            v = e * (1.0 - y[1] * k) + y[0] * t_e
            return np.array([v[0], v[1], y[1]])

        def f(y):
            p, g = self.power(*twist(y))
            b0 = np.array([t_e[0], t_e[1], 0.0])
            b1 = np.array([-k * e[0], -k * e[1], 1.0])
            return p, np.array([g @ b0, g @ b1])

        res = optimize.minimize(f, np.zeros(2), jac=True, method="BFGS", options={"gtol": 1e-12})
        xi = twist(res.x)
        uc = np.array([xi[0] - xi[2] * c[1], xi[1] + xi[2] * c[0]])
        return xi * (n @ vp) / (n @ uc)

    def twist(self, c, n, vp, mu):
        """The spec's minimum-power twist at contact ``c`` with inward normal ``n``."""
        xi, f = self.stick(c, vp)
        t = np.array([-n[1], n[0]])
        fn, ft = f @ n, f @ t
        if fn > 0.0 and abs(ft) <= mu * fn:
            return xi
        side = 1.0 if ft > 0.0 else -1.0
        e = n + side * mu * t
        return self.slide(c, e / np.hypot(*e), n, vp)

    # -------------------------------------------------------------- geometry

    def closest(self, q):
        """Closest outline point to the body-frame point ``q`` and its distance."""
        p = self.outline
        e = np.roll(p, -1, axis=0) - p
        t = np.clip(np.sum((q - p) * e, axis=1) / np.sum(e * e, axis=1), 0.0, 1.0)
        foot = p + t[:, None] * e
        dist = np.hypot(*(q - foot).T)
        j = int(np.argmin(dist))
        return foot[j], float(dist[j])


def _rot(theta):
    c, s = math.cos(theta), math.sin(theta)
    return np.array([[c, -s], [s, c]])


def material_rollout(part: MaterialPart, theta_i_deg, d, mu_c, r_pin, ds=0.004, max_travel=20.0):
    """One passage past one pin: ``(status, theta_f_deg, dy)`` (dy in units of a).

    ``r_pin`` in units of a. Status ``"ok"``, ``"miss"``, or ``"jammed"`` when
    the part turns less than 1e-5 rad over 3 a of contact (or the travel runs out).
    """
    theta = math.radians(theta_i_deg)
    com = np.zeros(2)
    # The pin's path: y = d, moving in -x; find its first touch by marching then bisection.
    start = 3.0 + r_pin

    def gap(s):
        q = _rot(theta).T @ (np.array([start - s, d]) - com)
        return part.closest(q)[1] - r_pin

    grid = np.linspace(0.0, 2.0 * start, 801)
    gaps = np.array([gap(s) for s in grid])
    hit = np.nonzero(gaps <= 0.0)[0]
    if not len(hit):
        return "miss", theta_i_deg % 360.0, 0.0
    s = optimize.brentq(gap, grid[hit[0] - 1], grid[hit[0]], xtol=1e-13)
    pin = np.array([start - s, d])
    vp = np.array([-1.0, 0.0])
    travel, turned_at, theta_at = 0.0, 0.0, theta

    def rate(theta, com):
        rot = _rot(theta)
        q = rot.T @ (pin - com)
        c, dist = part.closest(q)
        n = (c - q) / dist
        vpb = rot.T @ vp
        if n @ vpb <= 0.0:
            return None
        xi = part.twist(c, n, vpb, mu_c)
        return xi[2], rot @ xi[:2]

    while travel < max_travel:
        k1 = rate(theta, com)
        if k1 is None:
            return "ok", math.degrees(theta) % 360.0, float(com[1])
        h = ds
        th_mid = theta + 0.5 * h * k1[0]
        com_mid = com + 0.5 * h * k1[1]
        pin_mid = pin + 0.5 * h * vp
        pin_save = pin
        pin = pin_mid
        k2 = rate(th_mid, com_mid)
        pin = pin_save
        if k2 is None:
            k2 = k1
        theta += h * k2[0]
        com = com + h * k2[1]
        pin = pin + h * vp
        travel += h
        # Keep the pin on the boundary: move the part along the contact normal.
        rot = _rot(theta)
        q = rot.T @ (pin - com)
        c, dist = part.closest(q)
        n_world = rot @ ((c - q) / dist)
        com = com + (r_pin - dist) * n_world
        if abs(theta - theta_at) > 1e-5:
            turned_at, theta_at = travel, theta
        elif travel - turned_at > 3.0:
            return "jammed", math.degrees(theta) % 360.0, float(com[1])
    return "jammed", math.degrees(theta) % 360.0, float(com[1])
