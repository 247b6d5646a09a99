"""Dynamic passage of a part past one pin: Newton-Euler with belt and pin friction.

The quasi-static models (``models.py``) neglect inertia. On a fast belt the
part keeps turning and sliding after it leaves the pin until belt friction
stops it. This module integrates the planar rigid-body dynamics of the part.

Notes
-----
**Frame and units.** Work in the belt frame (belt at rest, pin moving with
velocity ``v_p = (-1, v_pin / v_b)``), lengths in units of ``a``, velocities
in units of the belt speed ``v_b``, time ``s`` in units of ``a / v_b`` (so
``s`` is belt travel in units of a, as in ``rollout.py``), forces in units of
``mu_s m g`` and impulses in ``mu_s m g a / v_b``. The part (uniform lamina,
mass ``m``, polar radius of gyration ``k`` about the centroid) has twist
``xi = (V, omega)``. Newton-Euler reads::

    Fr       dV/ds     = W_F(xi) + f
    Fr k^2   domega/ds = W_M(xi) + c x f,        Fr = v_b^2 / (mu_s g a)

so the mass drops out and only the Froude-like number ``Fr`` (the fast-belt model's
``v^2 / (mu_s g a)``) matters; ``Fr -> 0`` is the quasi-static limit.

**Belt friction.** Uniform pressure ``1/A`` and Coulomb friction ``mu_s``
give the wrench ``W(xi) = -grad P(xi)`` with ``P(xi) = (1/A) int |u(w)| dA``
the belt power of ``support.py`` (``P`` is positively homogeneous of degree
1, so ``W`` depends only on the direction of ``xi``). For a rotation about
the COR ``r`` it is the exact support integral: force ``-(s/A) z x G(r)``,
moment about ``r`` ``-(s/A) E(r)``; for a nearly pure translation (COR
beyond 8 a) ``support._power`` uses its fan quadrature, exact to rounding
there, with the limit ``F = -V / |V|``, no moment. The Hessian ``H`` of
``P`` comes with it. Near zero slip the wrench is regularised by the mean
slip speed ``P`` itself::

    W = -phi(P) grad P,   phi = min(1, P / eps),   eps = v_reg / v_b

(a linear viscous law below ``eps``, exact Coulomb above; ``v_reg`` about
0.2 mm/s as in the MuJoCo rig). ``W . xi = -phi P <= 0``: the belt only
removes kinetic energy in the belt frame.

**Time stepping (Moreau-Jean, linearly implicit belt friction).** The belt
friction is stiff (relaxation time ``~ Fr``, tiny on a slow belt), the pin is
a unilateral Coulomb contact. One step of size ``h`` from ``(q, xi)``:

1. the closest boundary feature to the pin gives the contact point ``c``,
   inward normal ``n``, tangent ``t = z x n`` and gap ``g = dist - r_pin``;
2. with ``M = Fr diag(1, 1, k^2)`` and ``K = -dW/dxi`` (``= H`` above
   ``eps``, ``(grad P grad P^T + P H) / eps`` below) the free twist is
   ``xi_free = xi + A^{-1} h W(xi)``, ``A = M + h K`` (one Newton step of the
   implicit Euler equation: L-stable, so ``h`` is not bounded by ``Fr``);
3. the pin impulse ``lambda = (lambda_n, lambda_t)`` acts through
   ``J = [n, c x n; t, c x t]``; relative contact velocity after the step
   ``v+ = v_free + D lambda``, ``D = J A^{-1} J^T`` (2x2, SPD). The
   one-contact Coulomb problem is solved in closed form:
   separate (``v_free,n >= b``, ``lambda = 0``); else stick
   (``v+ = (b, 0)`` with ``lambda_n >= 0``, ``|lambda_t| <= mu_c lambda_n``);
   else slide (``lambda_t = sigma mu_c lambda_n``, ``v+_n = b``, ``sigma``
   on the side of the sticking ``lambda_t`` and opposing the slip).
   The bound ``b = -g / h`` lets the gap close exactly within the step (a
   small penetration is pushed out at rate ``0.2 |g| / h``). At the first
   step of a contact the bound is ``max(b, -e v-_n)``: Newton restitution
   ``e`` (0, plastic, by default);
   Coulomb friction is set-valued at zero slip, and the linearised step
   does not see it (``H xi = 0``: ``P`` is homogeneous), so a part about to
   stop would overshoot and chatter; when ``xi_free . M xi <= 0`` (the
   friction impulse of the step exceeds the momentum) the belt's static
   friction stops a free part (no pin impulse): ``xi+ = 0``;
4. ``xi+ = xi_free + A^{-1} J^T lambda``; position and angle advance with
   the new twist (symplectic Euler).

Force on the pin: ``-lambda / h``; the impact step is left out of the peak
force (its value is an impulse over one step, which depends on ``h``).

**End of a passage.** When the part is out of contact and its mean slip
speed ``P`` falls below ``_REST`` (``1e-3 v_b``; the remaining travel is of
order ``_REST^2 Fr``) it is at rest; the pin's remaining straight path is
tested with ``geometry._ray_first_contact``: a miss ends the passage (status
ok), a hit (a non-convex part, or a part that came to rest in the pin's
path) jumps the pin there and goes on. Jam rules are those of
``rollout.py``: no rotation (``< 1e-5`` rad over 3 a of pin travel in
contact), a second contact (notch), pin travel in contact past 50 a. A step
budget ends a runaway passage with status truncated (reason
``step budget``); ``max_travel`` (belt travel since first contact) with
status truncated.

**Many passages.** The parallel grid and points kernels of this model are
``batch._dyn_rollout_grid`` and ``points._dyn_rollout_points``; they run
``_dyn_rollout`` through the driver loop the quasi-static kernels share
(``drive``).
"""
import math

import numpy as np

from ._numba import jit, jit_alloc
from .geometry import GAP_CACHE_HEAD, _cached_gap, _closest_feature, _ray_first_contact
from .support import _power, _table_sizes

# Statuses as in rollout.py (ok, miss, jammed, truncated).
OK = 0
MISS = 1
JAMMED = 2
TRUNCATED = 3

# Reasons (index into DYN_REASONS; the first five match rollout.JAM_REASONS).
R_NONE = 0
R_NO_ROTATION = 1
R_NOTCH = 2
R_TRAVEL = 3
R_STEP_BUDGET = 6
DYN_REASONS = ("", "no rotation", "notch", "travel limit", "no pushing solution", "chatter",
               "step budget")

DEFAULT_H = 4e-3  # time step, units of a / v_b (belt travel in units of a)
DEFAULT_V_REG = 0.2  # mm/s, slip regularisation (divided by the belt speed)
DEFAULT_MAX_STEPS = 200000
G_MM_S2 = 9810.0

_REST = 1e-3  # mean slip speed (units of v_b) below which a free part is at rest
_PUSH_OUT = 0.2  # fraction of a penetration removed per step
_JAM_ANGLE = 1e-5
_JAM_TRAVEL = 3.0
_MAX_TRAVEL = 50.0
_SAME_FEATURE = 1e-3


@jit
def _gyration(quad, area):
    """Polar radius of gyration squared ``k^2 = J / A`` about the centroid
    (the origin) of the material of the support table ``quad`` (its support
    polygon, holes left out; ``support._fan_quadrature``) of area ``area``."""
    f, n = _table_sizes(quad)
    j = 0.0
    for i in range(n):
        k = (i + 1) % n
        xi, yi = quad[f + i, 0], quad[f + i, 1]
        xk, yk = quad[f + k, 0], quad[f + k, 1]
        cr = xi * yk - xk * yi
        j += cr * (xi * xi + xi * xk + xk * xk + yi * yi + yi * yk + yk * yk)
    return j / 12.0 / area


@jit
def _belt_wrench(quad, area, vx, vy, om, eps):
    """Regularised belt friction wrench ``W`` and ``K = -dW/dxi`` (body frame).

    Returns ``(P, W0, W1, W2, K00, K01, K02, K11, K12, K22)``; units of
    ``mu_s m g`` (moment: times a) for a twist in units of ``v_b``.
    """
    if vx == 0.0 and vy == 0.0 and om == 0.0:
        return 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
    p, g0, g1, g2, h00, h01, h02, h11, h12, h22 = _power(quad, area, vx, vy, om)
    if p >= eps:
        return p, -g0, -g1, -g2, h00, h01, h02, h11, h12, h22
    f = p / eps
    ie = 1.0 / eps
    return (p, -f * g0, -f * g1, -f * g2,
            ie * g0 * g0 + f * h00, ie * g0 * g1 + f * h01, ie * g0 * g2 + f * h02,
            ie * g1 * g1 + f * h11, ie * g1 * g2 + f * h12, ie * g2 * g2 + f * h22)


@jit
def _solve3(a00, a01, a02, a11, a12, a22, b0, b1, b2):
    """Solve the symmetric 3x3 system ``A x = b`` (Cramer; A is SPD here)."""
    c00 = a11 * a22 - a12 * a12
    c01 = a02 * a12 - a01 * a22
    c02 = a01 * a12 - a02 * a11
    det = a00 * c00 + a01 * c01 + a02 * c02
    c11 = a00 * a22 - a02 * a02
    c12 = a01 * a02 - a00 * a12
    c22 = a00 * a11 - a01 * a01
    return ((c00 * b0 + c01 * b1 + c02 * b2) / det,
            (c01 * b0 + c11 * b1 + c12 * b2) / det,
            (c02 * b0 + c12 * b1 + c22 * b2) / det)


@jit
def _coulomb(dnn, dnt, dtt, vfn, vft, b, mu):
    """One-contact Coulomb impulse ``(lambda_n, lambda_t, mode)``.

    ``v+ = v_free + D lambda`` must satisfy ``v+_n >= b``, ``lambda_n >= 0``,
    complementarity, and Coulomb's law in the tangent. Mode 0 none, 1 stick,
    2 slide.
    """
    if vfn >= b:
        return 0.0, 0.0, 0
    rn, rt = b - vfn, -vft
    det = dnn * dtt - dnt * dnt
    ln = (dtt * rn - dnt * rt) / det
    lt = (dnn * rt - dnt * rn) / det
    if ln >= 0.0 and abs(lt) <= mu * ln:
        return ln, lt, 1
    sgn = 1.0 if lt >= 0.0 else -1.0
    for _ in range(2):
        den = dnn + sgn * mu * dnt
        if den > 0.0:
            ln = rn / den
            vt = vft + (dnt + sgn * mu * dtt) * ln
            if ln >= 0.0 and sgn * vt <= 1e-12:
                return ln, sgn * mu * ln, 2
        sgn = -sgn
    # No consistent sliding solution (Painleve-like): frictionless push.
    return rn / dnn, 0.0, 2


@jit_alloc
def _dyn_rollout(verts, area, a, quad, convex, mu_c, r_pin, theta_i, d, v_pin, fr, restitution,
                 eps, h, max_travel, max_steps, record):
    """Dynamic passage of a prepared part (``rollout._prepare``) past one pin.

    Parameters
    ----------
    verts, area, a, quad, convex : from ``rollout._prepare`` (``verts`` in units of a).
    mu_c : pin-part friction coefficient (>= 0).
    r_pin : pin radius (the part's length unit).
    theta_i : initial orientation (radians).
    d : contact parameter ``(y_pin - y_com) / a``.
    v_pin : pin speed across the belt over belt speed.
    fr : ``v_b^2 / (mu_s g a)`` (> 0).
    restitution : Newton restitution at a first contact (0: plastic).
    eps : slip regularisation, units of ``v_b``.
    h : time step, units of ``a / v_b``.
    max_travel : stop after this belt travel since first contact (inf: never).
    max_steps : step budget.
    record : keep trajectory, force history and twist history.

    Returns
    -------
    (status, reason, theta_f, dy, contact_travel, feature_changes, peak_force,
     trajectory, force, twist)
        As ``rollout._rollout``; ``reason`` indexes ``DYN_REASONS``;
        ``twist`` rows ``(s, V_x, V_y, omega, v_n, lambda_n)``: belt-frame
        velocity in units of ``v_b``, ``omega`` in ``v_b / a``, relative
        normal contact velocity and the normal impulse.
    """
    rp = r_pin / a
    s_cap = max_travel / a
    two_pi = 2.0 * math.pi
    k2 = _gyration(quad, area)
    mx_, mw_ = fr, fr * k2
    nrec = 256 if record else 0
    traj = np.empty((nrec, 4))
    force = np.empty((nrec, 3))
    twist = np.empty((nrec, 6))
    n_rec = 0
    gap_cache = np.empty(GAP_CACHE_HEAD + 32)  # the notch test's near edges
    gap_cache[0] = -1.0
    # Pin path in the belt frame: P(tau) = (-tau, d + v_pin tau); the part
    # starts at rest with its centroid at the origin.
    cs, sn = math.cos(theta_i), math.sin(theta_i)
    tau0 = -(2.0 + rp + abs(d)) * (1.0 + abs(v_pin))
    px, py = -tau0, d + v_pin * tau0
    qx, qy = cs * px + sn * py, -sn * px + cs * py
    wx, wy = -cs + sn * v_pin, sn + cs * v_pin
    sigma, kind0, idx0 = _ray_first_contact(verts, qx, qy, wx, wy, rp, 0.0)
    if not math.isfinite(sigma):
        return (MISS, R_NONE, theta_i % two_pi, 0.0, 0.0, 0, 0.0, traj[:0], force[:0],
                twist[:0])
    tau = tau0 + sigma  # pin parameter at the current time
    X, Y, th = 0.0, 0.0, theta_i
    V0, V1, om = 0.0, 0.0, 0.0
    s = 0.0  # belt travel since first contact
    travel = 0.0
    changes = 0
    peak = 0.0
    in_contact = False
    kind_c, idx_c = -1, -1
    theta_ref, travel_ref = theta_i, 0.0
    status, reason = OK, R_NONE
    steps = 0
    while True:
        steps += 1
        if steps > max_steps:
            status, reason = TRUNCATED, R_STEP_BUDGET
            break
        if s >= s_cap:
            status = TRUNCATED
            break
        cs, sn = math.cos(th), math.sin(th)
        # Pin in the body frame and the contact geometry.
        ppx, ppy = -tau - X, d + v_pin * tau - Y
        qx, qy = cs * ppx + sn * ppy, -sn * ppx + cs * ppy
        kind, idx, dist, cx, cy, nx, ny = _closest_feature(verts, qx, qy)
        gap = dist - rp
        # Twist and pin velocity in the body frame.
        vbx, vby = cs * V0 + sn * V1, -sn * V0 + cs * V1
        vpx, vpy = -cs + sn * v_pin, sn + cs * v_pin
        p, w0, w1, w2, k00, k01, k02, k11, k12, k22 = _belt_wrench(quad, area, vbx, vby,
                                                                   om, eps)
        a00, a01, a02 = mx_ + h * k00, h * k01, h * k02
        a11, a12, a22 = mx_ + h * k11, h * k12, mw_ + h * k22
        d0, d1, d2 = _solve3(a00, a01, a02, a11, a12, a22, h * w0, h * w1, h * w2)
        fx, fy, fw = vbx + d0, vby + d1, om + d2
        # Contact Jacobian rows (body frame) and the Delassus matrix.
        tx, ty = -ny, nx
        jn2 = cx * ny - cy * nx
        jt2 = cx * ty - cy * tx
        un0, un1, un2 = _solve3(a00, a01, a02, a11, a12, a22, nx, ny, jn2)
        ut0, ut1, ut2 = _solve3(a00, a01, a02, a11, a12, a22, tx, ty, jt2)
        dnn = nx * un0 + ny * un1 + jn2 * un2
        dnt = tx * un0 + ty * un1 + jt2 * un2
        dtt = tx * ut0 + ty * ut1 + jt2 * ut2
        vfn = nx * fx + ny * fy + jn2 * fw - (nx * vpx + ny * vpy)
        vft = tx * fx + ty * fy + jt2 * fw - (tx * vpx + ty * vpy)
        b = -gap / h if gap >= 0.0 else -_PUSH_OUT * gap / h
        impact = False
        if not in_contact:
            vn_pre = nx * vbx + ny * vby + jn2 * om - (nx * vpx + ny * vpy)
            if restitution > 0.0 and vn_pre < 0.0:
                b = max(b, -restitution * vn_pre)
            impact = True
        ln, lt, mode = _coulomb(dnn, dnt, dtt, vfn, vft, b, mu_c)
        if mode == 0 or ln <= 0.0:
            ln, lt = 0.0, 0.0
            if mx_ * (fx * vbx + fy * vby) + mw_ * fw * om <= 0.0:
                # Free part whose linearised friction impulse exceeds its
                # momentum: the belt's static friction stops it in this step.
                fx, fy, fw = 0.0, 0.0, 0.0
        vbx = fx + ln * un0 + lt * ut0
        vby = fy + ln * un1 + lt * ut1
        om = fw + ln * un2 + lt * ut2
        V0, V1 = cs * vbx - sn * vby, sn * vbx + cs * vby
        X += h * V0
        Y += h * V1
        th += h * om
        tau += h
        s += h
        touching = ln > 0.0
        if touching:
            travel += h
            if in_contact and (kind != kind_c or idx != idx_c):
                changes += 1
            kind_c, idx_c = kind, idx
            fwx = (ln * nx + lt * tx) / h
            fwy = (ln * ny + lt * ty) / h
            if not impact:
                peak = max(peak, math.hypot(fwx, fwy))
        else:
            fwx, fwy = 0.0, 0.0
        if record:
            if n_rec >= traj.shape[0]:
                m = 2 * traj.shape[0]
                t2 = np.empty((m, 4))
                t2[:n_rec] = traj[:n_rec]
                traj = t2
                f2 = np.empty((m, 3))
                f2[:n_rec] = force[:n_rec]
                force = f2
                w2_ = np.empty((m, 6))
                w2_[:n_rec] = twist[:n_rec]
                twist = w2_
            traj[n_rec] = (s * a, X * a, Y * a, th)
            c2, s2 = math.cos(th - h * om), math.sin(th - h * om)
            force[n_rec] = (s * a, -(c2 * fwx - s2 * fwy), -(s2 * fwx + c2 * fwy))
            vn_post = nx * vbx + ny * vby + jn2 * om - (nx * vpx + ny * vpy)
            twist[n_rec] = (s * a, V0, V1, om, vn_post, ln)
            n_rec += 1
        in_contact = touching
        if touching:
            if abs(th - theta_ref) >= _JAM_ANGLE:
                theta_ref, travel_ref = th, travel
            elif travel - travel_ref > _JAM_TRAVEL:
                status, reason = JAMMED, R_NO_ROTATION
                break
            if travel > _MAX_TRAVEL:
                status, reason = JAMMED, R_TRAVEL
                break
            # Only the sign counts, which the cached gap keeps exactly.
            if not convex and _cached_gap(verts, qx, qy, cx, cy, rp, _SAME_FEATURE,
                                          gap_cache, False) < 0.0:
                status, reason = JAMMED, R_NOTCH
                break
            continue
        # Free part: at rest?
        if gap > 0.0 and p < _REST:
            vbx2, vby2 = cs * V0 + sn * V1, -sn * V0 + cs * V1
            p2 = _power(quad, area, vbx2, vby2, om)[0] if (vbx2 != 0.0 or vby2 != 0.0
                                                                  or om != 0.0) else 0.0
            if p2 < _REST:
                cs, sn = math.cos(th), math.sin(th)
                ppx, ppy = -tau - X, d + v_pin * tau - Y
                qx, qy = cs * ppx + sn * ppy, -sn * ppx + cs * ppy
                wx, wy = -cs + sn * v_pin, sn + cs * v_pin
                sigma, kk, ii = _ray_first_contact(verts, qx, qy, wx, wy, rp, 1e-9)
                if not math.isfinite(sigma):
                    break
                if s + sigma >= s_cap:
                    status = TRUNCATED
                    break
                # The part rests until the pin reaches it again.
                V0, V1, om = 0.0, 0.0, 0.0
                tau += sigma
                s += sigma
    if status == OK and travel == 0.0:
        status = MISS
    return (status, reason, th % two_pi, Y * a, travel * a, changes, peak,
            traj[:n_rec].copy(), force[:n_rec].copy(), twist[:n_rec].copy())
