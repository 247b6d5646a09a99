"""Contact models: from a pin contact to the part's twist and the pin force.

All quantities are in the part's body frame with the centroid at the origin
and lengths in units of a (the rollout normalises). A contact is the body
point ``c``, the unit normal ``n`` pointing into the part, the pin velocity
``v_p`` relative to the belt and the contact friction ``mu_c``.

Models (spec section 3):

``MINPOWER``
    The twist minimises the belt power ``P`` over the twists the contact
    allows (Peshkin and Sanderson). Sticking: ``u(c) = v_p``; sliding:
    ``e . u(c) = 1`` with ``e`` the friction-cone edge, then rescaled so the
    pin does not penetrate. Both are convex problems in 1 or 2 unknowns,
    solved by ``_minimise`` (damped Newton, warm-started; inside a rollout
    the start is first improved on a local model of P, ``_model_step``).
``TIP``
    The centre of rotation is the tip of Peshkin's COR locus for the force
    line: on the perpendicular from the centroid to the line, on the far
    side, at distance ``a^2 / rho``.
``ELLIPSOID``
    Ellipsoidal limit surface ``H = |f|^2 + m^2 / m_max^2``; the twist is
    ``grad H``.

Support: ``MINPOWER`` presses the part evenly over its area (the
spec's uniform pressure, closed forms of ``support.py``); ``MINPOWER_POINTS``
presses it on K weighted points, ``P = sum_k w_k |u(p_k)|``, with the points
in the first K rows of ``quad`` (``(x, y, w)``, weights summing to 1) and the
edge directions in the last n rows as usual. The sticking and sliding logic
is the same code for both; only the minimisation differs
(``_minimise_points``: P has kinks at the points, and a centre of rotation
exactly at a support point is a real outcome).

Every model returns ``(status, vx, vy, om, fx, fy, mode)``: ``status`` is
``TWIST_OK`` or ``TWIST_NO_PUSH`` (the pin moves into the part but no pushing
solution exists, i.e. the part is jammed), the twist, the force ``f`` of the
pin on the part (units of mu_s m g) and the contact ``mode`` (``STICK``,
``SLIDE_POS`` with friction along ``+t``, ``SLIDE_NEG``; ``t = z x n``).

Lengths of vectors are ``sqrt(x*x + y*y)``, not ``math.hypot`` (twice as
slow): all quantities are in units of a, far from overflow and underflow.
"""
import math

from ._numba import jit, jit_inline
from .support import _point_power, _power, _table_sizes

MINPOWER = 0
TIP = 1
ELLIPSOID = 2
MODEL_NAMES = ("minpower", "tip", "ellipsoid")
# Kernel code of the minpower model over a point support: the
# rollout's ``quad`` then holds the support points (see ``_minimise_points``)
# instead of the fan quadrature. Not a public model name: the public API
# selects it with ``model="minpower"`` and a ``support``.
MINPOWER_POINTS = 3

STICK = 0
SLIDE_POS = 1
SLIDE_NEG = -1
SEPARATE = 2

TWIST_OK = 0
TWIST_NO_PUSH = 1

_NEWTON_MAX_IT = 60
# Take the last Newton step unchecked once the decrement is below this
# fraction of P (see ``_minimise``).
_DEC_TAKE = 1e-12


# No local model of P for ``_minimise`` (see ``_model_step``).
NO_MODEL = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
# A model step longer than this fraction of ``1 + |y|`` is not taken.
_MODEL_STEP_MAX = 0.1


@jit_inline
def _newton_direction(g0, g1, g2, h00, h01, h02, h11, h12, h22, b0, b1, b2, c0, c1, c2, k):
    """Newton step ``(d1, d2)`` for ``y`` on the family ``x + y1 b + y2 c`` from the
    gradient ``g`` and Hessian ``H`` of P in the twist, and the decrement
    ``lambda^2 = -(g . B) d`` (a gradient step where ``B^T H B`` is not
    positive definite)."""
    gb = g0 * b0 + g1 * b1 + g2 * b2
    hb0 = h00 * b0 + h01 * b1 + h02 * b2
    hb1 = h01 * b0 + h11 * b1 + h12 * b2
    hb2 = h02 * b0 + h12 * b1 + h22 * b2
    hbb = b0 * hb0 + b1 * hb1 + b2 * hb2
    if k == 1:
        d1 = -gb / hbb if hbb > 0.0 else -gb
        return d1, 0.0, -gb * d1
    gc = g0 * c0 + g1 * c1 + g2 * c2
    hbc = c0 * hb0 + c1 * hb1 + c2 * hb2
    hcc = (c0 * (h00 * c0 + h01 * c1 + h02 * c2) + c1 * (h01 * c0 + h11 * c1 + h12 * c2)
           + c2 * (h02 * c0 + h12 * c1 + h22 * c2))
    det = hbb * hcc - hbc * hbc
    if det <= 1e-14 * (hbb * hcc) or hbb <= 0.0:
        d1, d2 = -gb, -gc  # not positive definite here: gradient step
    else:
        d1 = -(hcc * gb - hbc * gc) / det
        d2 = -(hbb * gc - hbc * gb) / det
    return d1, d2, -(gb * d1 + gc * d2)


@jit_inline
def _model_step(model, x0, x1, x2, b0, b1, b2, c0, c1, c2, k, y1, y2):
    """Improve the start ``y`` with a Newton step on a local quadratic model of P.

    ``model`` is ``(use, m0, m1, m2, g0, g1, g2, h00, h01, h02, h11, h12,
    h22)``: a twist ``m`` near the start, with a prediction of P's gradient
    there and a Hessian nearby (from the solves before; see
    ``rollout._derivative``). The model's gradient at the start
    ``xi = x + y1 b + y2 c`` is ``g + H (xi - m)``; the step minimises the
    model over the family, costs no evaluation of P, and is skipped when
    ``use`` is 0 or the step is longer than ``_MODEL_STEP_MAX (1 + |y|)``.

    Notes
    -----
    A warm start extrapolated in the belt travel lies close to the solution
    for the trajectory, but a Runge-Kutta stage state is off the trajectory
    by O(h^2), and so is its family of twists. The model step corrects that
    to first order, which leaves the start O(h^3) off instead of O(h^2):
    most solves then end with one evaluation and one unchecked Newton step.
    The answer does not depend on the start (``_minimise`` converges from
    anywhere).
    """
    if model[0] == 0.0:
        return y1, y2
    dx0 = x0 + y1 * b0 + y2 * c0 - model[1]
    dx1 = x1 + y1 * b1 + y2 * c1 - model[2]
    dx2 = x2 + y1 * b2 + y2 * c2 - model[3]
    h00, h01, h02, h11, h12, h22 = model[7], model[8], model[9], model[10], model[11], model[12]
    g0 = model[4] + h00 * dx0 + h01 * dx1 + h02 * dx2
    g1 = model[5] + h01 * dx0 + h11 * dx1 + h12 * dx2
    g2 = model[6] + h02 * dx0 + h12 * dx1 + h22 * dx2
    d1, d2, _ = _newton_direction(g0, g1, g2, h00, h01, h02, h11, h12, h22, b0, b1, b2,
                                  c0, c1, c2, k)
    if abs(d1) + abs(d2) <= _MODEL_STEP_MAX * (1.0 + abs(y1) + abs(y2)):
        return y1 + d1, y2 + d2
    return y1, y2


@jit_inline
def _evaluate(points, quad, area, m, vx, vy, om):
    """P, its gradient and Hessian at the twist ``(vx, vy, om)``, laid out as
    ``support._point_power`` returns them: over the ``m`` points of the
    point support in ``quad`` if ``points``, else over the uniform support
    ``(quad, area)`` (``support._power``, with no nearest point: ``jmin``
    -1, ``rmin`` and ``umin`` inf)."""
    if points:
        return _point_power(quad, m, vx, vy, om, -1)
    return _power(quad, area, vx, vy, om) + (-1, math.inf, math.inf)


@jit_inline
def _line_search(points, quad, area, m, x0, x1, x2, b0, b1, b2, c0, c1, c2, y1, y2, d1, d2, p,
                 dec):
    """Armijo backtracking from ``y`` along the Newton direction ``d`` of
    ``_minimise`` and ``_minimise_points`` (support as for ``_evaluate``).

    Returns ``(accepted, t, y1, y2, vx, vy, om, r)``: whether a step was
    accepted, its length ``t``, the parameters and twist there and
    ``_evaluate`` there (the last ones tried if none was accepted).

    Notes
    -----
    From ``t = 1``, halving down to ``1e-12``, the step is accepted when
    ``P(y + t d) <= P(y) - 1e-4 t lambda^2 + 1e-12 P(y)`` (``dec`` =
    ``lambda^2``, the Newton decrement). The slack is above the rounding
    noise of P (sums of closed forms with cancellation, ~1e-14 relative):
    near the minimum the Armijo decrease is unmeasurable and must not block
    the last Newton step.
    """
    t = 1.0
    while True:
        ty1 = y1 + t * d1
        ty2 = y2 + t * d2
        vx = x0 + ty1 * b0 + ty2 * c0
        vy = x1 + ty1 * b1 + ty2 * c1
        om = x2 + ty1 * b2 + ty2 * c2
        r = _evaluate(points, quad, area, m, vx, vy, om)
        if r[0] <= p - 1e-4 * t * dec + 1e-12 * p:
            return True, t, ty1, ty2, vx, vy, om, r
        t *= 0.5
        if not t > 1e-12:
            return False, t, ty1, ty2, vx, vy, om, r


@jit
def _minimise(quad, area, x0, x1, x2, b0, b1, b2, c0, c1, c2, k, y1, y2, take):
    """Minimise ``P(x + y1 b + y2 c)`` over ``y`` (``k`` = 1 or 2 unknowns).

    Parameters
    ----------
    quad, area : the support table (``support._fan_quadrature``) and the
        area of the material.
    x0..x2, b0..b2, c0..c2 : the affine family of twists ``x + y1 b + y2 c``.
    k : number of free parameters (``c`` is ignored when ``k == 1``).
    y1, y2 : warm start.
    take : the last Newton step is taken unchecked once the decrement is
        below ``take * P`` (``_DEC_TAKE`` for a converged answer; see Notes).

    Returns
    -------
    (P, y1, y2, g, H, converged)
        The minimum and its parameters, the gradient ``(g0, g1, g2)`` of P
        there (its force part is the pin's force) and the Hessian ``(h00,
        h01, h02, h11, h12, h22)`` at the last evaluation.

    Notes
    -----
    P is convex and positively homogeneous in the twist, and strictly convex
    on these affine families, which do not contain the origin. Newton's
    method with an Armijo backtracking line search (``_line_search``)
    converges from any start; warm-started from the previous integration
    stages it needs one to three iterations. The stopping test is the Newton decrement ``lambda^2 = -g . d``:
    at rounding level, or below ``take * P``, when the relative error of
    the iterate is about ``sqrt(lambda^2 / P)`` (1e-6 for ``_DEC_TAKE``) and
    one more full step, taken without a confirming evaluation, brings it to
    about ``take`` (~1e-12) by quadratic convergence. The gradient returned
    then is moved along that step to first order, ``g + H d``, with an error
    of the same order. A rollout passes a larger ``take`` tied to its step
    tolerance (``rollout._solve_take``).
    """
    vx = x0 + y1 * b0 + y2 * c0
    vy = x1 + y1 * b1 + y2 * c1
    om = x2 + y1 * b2 + y2 * c2
    p, g0, g1, g2, h00, h01, h02, h11, h12, h22 = _power(quad, area, vx, vy, om)
    converged = False
    for _ in range(_NEWTON_MAX_IT):
        d1, d2, dec = _newton_direction(g0, g1, g2, h00, h01, h02, h11, h12, h22, b0, b1, b2,
                                        c0, c1, c2, k)
        if dec <= 1e-28 * (p + 1e-300):
            converged = True
            break
        if dec <= take * p:
            # Quadratic convergence: the relative error here is about
            # sqrt(dec / p) <= 1e-6, so this Newton step lands near 1e-12;
            # take it without paying for a confirming evaluation, and move
            # the gradient along the step to first order.
            y1 += d1
            y2 += d2
            s0 = d1 * b0 + d2 * c0
            s1 = d1 * b1 + d2 * c1
            s2 = d1 * b2 + d2 * c2
            g0 += h00 * s0 + h01 * s1 + h02 * s2
            g1 += h01 * s0 + h11 * s1 + h12 * s2
            g2 += h02 * s0 + h12 * s1 + h22 * s2
            converged = True
            break
        accepted, t, y1n, y2n, _, _, _, r = _line_search(False, quad, area, 0, x0, x1, x2, b0,
                                                         b1, b2, c0, c1, c2, y1, y2, d1, d2, p,
                                                         dec)
        if not accepted:
            converged = dec <= 1e-20 * (p + 1e-300)
            break
        y1, y2 = y1n, y2n
        p, g0, g1, g2, h00, h01, h02, h11, h12, h22 = r[:10]
        if t * (abs(d1) + abs(d2)) <= 1e-15 * (1.0 + abs(y1) + abs(y2)):
            converged = True
            break
    return p, y1, y2, (g0, g1, g2), (h00, h01, h02, h11, h12, h22), converged


# --------------------------------------------------------------------------- point supports

# A kink is optimal when its subgradient multiplier s has |s|^2 <= 1 + this.
_KINK_SLACK = 1e-10
# In the one-unknown (sticking) family a point is a kink when the family's
# closest approach to turning about it is below this, relative: closer than
# that, P's curvature there is beyond what Newton resolves in floating point,
# and the kink (off by at most this, relative) is the answer.
_KINK_LINE = 1e-10
# An iterate whose slip at a point, over its weight, is below this fraction
# of the twist is at that point's kink (``_minimise_points``).
_KINK_NEAR = 1e-6
# ... and is near enough to it to check the kink (a check costs an
# evaluation of P; iterates that head for a kink get there: see
# ``_minimise_points``).
_KINK_TEST = 0.05


@jit
def _kink(pts, x0, x1, x2, b0, b1, b2, c0, c1, c2, k, j):
    """The parameters ``y`` at which the twist ``x + y1 b + y2 c`` turns about
    support point ``j`` (``u_j = 0``): ``(found, y1, y2)``.

    Notes
    -----
    ``u_j`` is affine in ``y``: ``u_j(y) = u0 + y1 ub + y2 uc`` with
    ``u0, ub, uc`` the velocities of point j under ``x, b, c``. With two
    unknowns the kink is the solution of that 2 x 2 system (none if it is
    singular: then no twist of the family turns about the point). With one
    unknown, ``u_j`` vanishes only where ``u0`` and ``ub`` are parallel: the
    least-squares ``y1`` counts when its residual is below ``_KINK_LINE``
    (relative).
    """
    px, py = pts[j, 0], pts[j, 1]
    u0x, u0y = x0 - x2 * py, x1 + x2 * px
    ubx, uby = b0 - b2 * py, b1 + b2 * px
    if k == 1:
        bb = ubx * ubx + uby * uby
        if bb == 0.0:
            return False, 0.0, 0.0
        y1 = -(u0x * ubx + u0y * uby) / bb
        rx, ry = u0x + y1 * ubx, u0y + y1 * uby
        scale = math.sqrt(u0x * u0x + u0y * u0y) + abs(y1) * math.sqrt(bb)
        return math.sqrt(rx * rx + ry * ry) <= _KINK_LINE * scale, y1, 0.0
    ucx, ucy = c0 - c2 * py, c1 + c2 * px
    det = ubx * ucy - uby * ucx
    if abs(det) <= 1e-13 * math.sqrt((ubx * ubx + uby * uby) * (ucx * ucx + ucy * ucy)):
        return False, 0.0, 0.0
    return True, (-u0x * ucy + u0y * ucx) / det, (-ubx * u0y + uby * u0x) / det


@jit
def _kink_optimal(pts, m, x0, x1, x2, b0, b1, b2, c0, c1, c2, k, j, y1, y2):
    """Whether the kink of point ``j`` at ``y`` (from ``_kink``) minimises P
    over the family: ``(optimal, P, g, H, d1, d2, slope)``.

    Notes
    -----
    P is convex, so ``y`` is a minimiser iff 0 lies in the subdifferential of
    P restricted to the family (the Clarke condition at a kink)::

        g_r . b + w_j s . ub = 0,   g_r . c + w_j s . uc = 0,   |s| <= 1

    with ``g_r`` the gradient of the other points' terms at ``y`` and ``s``
    the friction direction of point j (``w_j s`` its friction force, static:
    any magnitude up to ``w_j``). Two unknowns: ``s`` is the solution of the
    2 x 2 system. One unknown (sticking): ``s`` is the least-norm solution of
    the one equation; the pin force is then not unique (a sticking contact
    and a pivot share the load), and this choice is the one of least
    friction at the pivot. ``g = g_r + w_j J_j^T s`` is P's subgradient
    there: its force part is the pin's force. ``H`` is the Hessian of the
    other points' terms (the kink's own is unbounded).

    Where the kink is not optimal, ``d`` is the steepest way out of it: the
    directional derivative ``g_r . d + w_j |M d|`` (``M = [ub, uc]``) is
    smallest, ``slope = w_j (1 - |s|) < 0``, for ``M d = s / |s|`` (one
    unknown: ``d = -sign(g_r . b) / |ub|``).
    """
    vx = x0 + y1 * b0 + y2 * c0
    vy = x1 + y1 * b1 + y2 * c1
    om = x2 + y1 * b2 + y2 * c2
    r = _point_power(pts, m, vx, vy, om, j)
    gb = r[1] * b0 + r[2] * b1 + r[3] * b2
    px, py, w = pts[j, 0], pts[j, 1], pts[j, 2]
    ubx, uby = b0 - b2 * py, b1 + b2 * px
    if k == 1:
        bb = ubx * ubx + uby * uby
        f = -gb / (w * bb)
        sx, sy = f * ubx, f * uby
        d1 = (-1.0 if gb > 0.0 else 1.0) / math.sqrt(bb)
        d2 = 0.0
    else:
        gc = r[1] * c0 + r[2] * c1 + r[3] * c2
        ucx, ucy = c0 - c2 * py, c1 + c2 * px
        det = ubx * ucy - uby * ucx
        sx = (-gb * ucy + gc * uby) / (w * det)
        sy = (-ubx * gc + ucx * gb) / (w * det)
        ns = math.sqrt(sx * sx + sy * sy)
        zx, zy = (sx / ns, sy / ns) if ns > 0.0 else (0.0, 0.0)
        d1 = (ucy * zx - ucx * zy) / det
        d2 = (-uby * zx + ubx * zy) / det
    ns2 = sx * sx + sy * sy
    ok = ns2 <= 1.0 + _KINK_SLACK
    g = (r[1] + w * sx, r[2] + w * sy, r[3] + w * (px * sy - py * sx))
    return (ok, r[0], g, (r[4], r[5], r[6], r[7], r[8], r[9]), d1, d2,
            w * (1.0 - math.sqrt(ns2)))


@jit
def _minimise_points(quad, x0, x1, x2, b0, b1, b2, c0, c1, c2, k, y1, y2, take):
    """``_minimise`` for a point support: minimise ``P = sum_j w_j |u_j|``
    over ``y`` on the family ``x + y1 b + y2 c``, exactly, kinks included.

    Parameters
    ----------
    quad : the support table: its first ``F`` rows are the points
        ``(x, y, w)`` (``support._point_power``, ``support._table_sizes``).
    x0..x2, b0..b2, c0..c2, k, y1, y2, take : as for ``_minimise``.

    Returns
    -------
    (P, y1, y2, g, H, converged) as ``_minimise``; at a kink ``g`` is the
    subgradient that satisfies the optimality condition (``_kink_optimal``).

    Notes
    -----
    P is convex and smooth except at the kinks, one per point: the twist of
    the family that turns about that point (``_kink``). Its minimiser is
    either a kink at which 0 lies in the subdifferential, or a smooth point
    with zero gradient. The solve is damped Newton with an Armijo line search
    (``_line_search``, as ``_minimise``) on the smooth part, and at every
    iterate it checks the kink of the point nearest to turning (smallest
    ``|u_j| / w_j``), once per point and solve, when the iterate is near it
    (``_KINK_TEST``): Newton iterates that head for a kink make that point
    the nearest, and the check then returns the kink exactly (the centre of
    rotation on the point to rounding). An iterate stuck at the apex of a
    kink that is not optimal leaves it along its steepest way out
    (``_KINK_NEAR``). A smooth minimum ends on the Newton decrement, as in
    ``_minimise``: the last step, once the decrement is below ``take * P``,
    is taken unchecked when no point's slip can reach zero within it, else
    checked by an evaluation. If Newton stalls, every kink is checked.
    The family's parameters are exact at a kink; no smoothing of ``|u|`` is
    used anywhere.
    """
    m = _table_sizes(quad)[0]
    vx = x0 + y1 * b0 + y2 * c0
    vy = x1 + y1 * b1 + y2 * c1
    om = x2 + y1 * b2 + y2 * c2
    r = _point_power(quad, m, vx, vy, om, -1)
    p, g0, g1, g2 = r[0], r[1], r[2], r[3]
    h00, h01, h02, h11, h12, h22 = r[4], r[5], r[6], r[7], r[8], r[9]
    jmin = r[10]
    tested_a = tested_b = escaped = -1
    converged = False
    for _ in range(_NEWTON_MAX_IT):
        if jmin >= 0 and jmin != tested_a and jmin != tested_b and \
                r[11] <= _KINK_TEST * (abs(vx) + abs(vy) + abs(om)):
            tested_b, tested_a = tested_a, jmin
            found, ky1, ky2 = _kink(quad, x0, x1, x2, b0, b1, b2, c0, c1, c2, k, jmin)
            if found:
                ok, kp, kg, kh, e1, e2, slope = _kink_optimal(
                    quad, m, x0, x1, x2, b0, b1, b2, c0, c1, c2, k, jmin, ky1, ky2)
                if ok:
                    return kp, ky1, ky2, kg, kh, True
        elif jmin >= 0 and jmin != escaped and r[11] <= _KINK_NEAR * (abs(vx) + abs(vy) + abs(om)):
            # Stuck at the apex of a kink that is not optimal, where Newton's
            # steps shrink with the distance to it: leave along the steepest
            # way out (``_kink_optimal``), if that does better than here.
            escaped = jmin
            found, ky1, ky2 = _kink(quad, x0, x1, x2, b0, b1, b2, c0, c1, c2, k, jmin)
            if found:
                ok, kp, kg, kh, e1, e2, slope = _kink_optimal(
                    quad, m, x0, x1, x2, b0, b1, b2, c0, c1, c2, k, jmin, ky1, ky2)
                t = 0.1 * (1.0 + abs(ky1) + abs(ky2)) / (abs(e1) + abs(e2) + 1e-300)
                while t * (abs(e1) + abs(e2)) > 1e-14 * (1.0 + abs(ky1) + abs(ky2)):
                    ty1, ty2 = ky1 + t * e1, ky2 + t * e2
                    vx = x0 + ty1 * b0 + ty2 * c0
                    vy = x1 + ty1 * b1 + ty2 * c1
                    om = x2 + ty1 * b2 + ty2 * c2
                    res = _point_power(quad, m, vx, vy, om, -1)
                    if res[0] <= kp + 0.5 * t * slope and res[0] < p:
                        y1, y2, r = ty1, ty2, res
                        p, g0, g1, g2 = r[0], r[1], r[2], r[3]
                        h00, h01, h02, h11, h12, h22 = r[4], r[5], r[6], r[7], r[8], r[9]
                        jmin = r[10]
                        break
                    t *= 0.5
        d1, d2, dec = _newton_direction(g0, g1, g2, h00, h01, h02, h11, h12, h22, b0, b1, b2,
                                        c0, c1, c2, k)
        if dec <= 1e-28 * (p + 1e-300):
            converged = True
            break
        s0 = d1 * b0 + d2 * c0
        s1 = d1 * b1 + d2 * c1
        s2 = d1 * b2 + d2 * c2
        if dec <= take * p and 4.0 * (abs(s0) + abs(s1) + 2.0 * abs(s2)) < r[12]:
            # As ``_minimise``: the last Newton step unchecked, when no
            # point's slip can reach zero within it (|p_j| <= 1 in units of
            # a), so P is smooth there and the quadratic model holds.
            y1 += d1
            y2 += d2
            g0 += h00 * s0 + h01 * s1 + h02 * s2
            g1 += h01 * s0 + h11 * s1 + h12 * s2
            g2 += h02 * s0 + h12 * s1 + h22 * s2
            converged = True
            break
        accepted, t, y1n, y2n, vx, vy, om, res = _line_search(True, quad, 1.0, m, x0, x1, x2,
                                                              b0, b1, b2, c0, c1, c2, y1, y2,
                                                              d1, d2, p, dec)
        if not accepted:
            converged = dec <= 1e-20 * (p + 1e-300)
            break
        y1, y2, r = y1n, y2n, res
        p, g0, g1, g2 = r[0], r[1], r[2], r[3]
        h00, h01, h02, h11, h12, h22 = r[4], r[5], r[6], r[7], r[8], r[9]
        jmin = r[10]
        if (t == 1.0 and dec <= take * p) or \
                t * (abs(d1) + abs(d2)) <= 1e-15 * (1.0 + abs(y1) + abs(y2)):
            converged = True
            break
    if not converged:
        for j in range(m):
            found, ky1, ky2 = _kink(quad, x0, x1, x2, b0, b1, b2, c0, c1, c2, k, j)
            if found:
                ok, kp, kg, kh, _, _, _ = _kink_optimal(quad, m, x0, x1, x2, b0, b1, b2, c0, c1,
                                                        c2, k, j, ky1, ky2)
                if ok:
                    return kp, ky1, ky2, kg, kh, True
    return p, y1, y2, (g0, g1, g2), (h00, h01, h02, h11, h12, h22), converged


@jit
def _cone_side(fx, fy, nx, ny, mu):
    """Contact mode of a sticking force: ``STICK`` if ``f`` lies in the friction
    cone, else the side to slide on (the sign of ``f . t``)."""
    fn = fx * nx + fy * ny
    ft = -fx * ny + fy * nx  # t = z x n = (-n_y, n_x)
    if fn > 0.0 and abs(ft) <= mu * fn:
        return STICK
    return SLIDE_POS if ft >= 0.0 else SLIDE_NEG


@jit
def _cone_edge(nx, ny, mu, side):
    """Unit edge ``normalise(n + side mu t)`` of the friction cone."""
    ex = nx - side * mu * ny
    ey = ny + side * mu * nx
    inv = 1.0 / math.sqrt(ex * ex + ey * ey)
    return ex * inv, ey * inv


@jit
def _push_scale(vx, vy, om, cx, cy, nx, ny, vpx, vpy):
    """Factor that makes ``n . u(c) = n . v_p`` (no penetration), or -1 if the
    twist does not push the part away from the pin at the contact."""
    ucn = (vx - om * cy) * nx + (vy + om * cx) * ny
    if ucn <= 1e-14 * (abs(vx) + abs(vy) + abs(om)):
        return -1.0
    return (vpx * nx + vpy * ny) / ucn


# --------------------------------------------------------------------------- minpower


@jit_inline
def _stick_solve(quad, area, cx, cy, vpx, vpy, om_warm, model, take, points=False):
    """Sticking: minimise P over twists with ``u(c) = v_p`` (1 unknown, omega).

    ``points``: the part rests on the point support in ``quad``
    (``_minimise_points``; no local model step, whose quadratic model does
    not hold across a kink). Returns ``(vx, vy, om, g, H, converged)``
    (``g``, ``H``: see ``_minimise``)."""
    if points:
        _, om, _, g, hess, conv = _minimise_points(quad, vpx, vpy, 0.0, cy, -cx, 1.0,
                                                   0.0, 0.0, 0.0, 1, om_warm, 0.0, take)
        if not conv and om_warm != 0.0:
            _, om, _, g, hess, conv = _minimise_points(quad, vpx, vpy, 0.0, cy, -cx,
                                                       1.0, 0.0, 0.0, 0.0, 1, 0.0, 0.0, take)
        return vpx + om * cy, vpy - om * cx, om, g, hess, conv
    om_warm, _ = _model_step(model, vpx, vpy, 0.0, cy, -cx, 1.0, 0.0, 0.0, 0.0, 1, om_warm,
                             0.0)
    _, om, _, g, hess, conv = _minimise(quad, area, vpx, vpy, 0.0, cy, -cx, 1.0,
                                        0.0, 0.0, 0.0, 1, om_warm, 0.0, take)
    if not conv and om_warm != 0.0:  # a poor warm start: solve again from translation
        _, om, _, g, hess, conv = _minimise(quad, area, vpx, vpy, 0.0, cy, -cx, 1.0,
                                            0.0, 0.0, 0.0, 1, 0.0, 0.0, take)
    return vpx + om * cy, vpy - om * cx, om, g, hess, conv


@jit_inline
def _slide_solve(quad, area, cx, cy, ex, ey, wvx, wvy, wom, model, take, points=False):
    """Sliding: minimise P over twists with ``e . u(c) = 1`` (2 unknowns).

    ``(wvx, wvy, wom)`` is a warm-start twist of any scale, and ``model`` a
    local model of P at that twist (or ``NO_MODEL``; see ``_model_step``).
    ``points``: the point support in ``quad`` (see ``_stick_solve``).
    Returns ``(vx, vy, om, g, H, converged)`` on the family's scale."""
    ke = cx * ey - cy * ex  # e . (z x c)
    uwx, uwy = wvx - wom * cy, wvy + wom * cx
    ue = uwx * ex + uwy * ey
    # Rescaling a warm start whose contact velocity is nearly tangent to e
    # would throw it far away: start from translation along e instead. A
    # negative ue (a twist continued past separation, ``_continued_slide``)
    # rescales too: P is even, P(-xi) = P(xi).
    if abs(ue) > 1e-3 * math.sqrt(uwx * uwx + uwy * uwy):
        iu = 1.0 / ue
        y1 = (-wvx * ey + wvy * ex) * iu
        y2 = wom * iu
        if model[0] != 0.0 and not points:
            # The start is the warm twist / ue: move the model with it (P's
            # gradient is odd and homogeneous of degree 0, its Hessian even
            # and of degree -1).
            sg, au = (1.0, ue) if ue > 0.0 else (-1.0, -ue)
            model = (1.0, model[1] * iu, model[2] * iu, model[3] * iu, sg * model[4],
                     sg * model[5], sg * model[6], model[7] * au, model[8] * au, model[9] * au,
                     model[10] * au, model[11] * au, model[12] * au)
            y1, y2 = _model_step(model, ex, ey, 0.0, -ey, ex, 0.0, -ke * ex, -ke * ey, 1.0, 2,
                                 y1, y2)
    else:
        y1 = 0.0
        y2 = 0.0
    if points:
        _, y1, y2, g, hess, conv = _minimise_points(quad, ex, ey, 0.0, -ey, ex, 0.0,
                                                    -ke * ex, -ke * ey, 1.0, 2, y1, y2, take)
        if not conv and (y1 != 0.0 or y2 != 0.0):
            _, y1, y2, g, hess, conv = _minimise_points(quad, ex, ey, 0.0, -ey, ex, 0.0,
                                                        -ke * ex, -ke * ey, 1.0, 2, 0.0, 0.0,
                                                        take)
    else:
        _, y1, y2, g, hess, conv = _minimise(quad, area, ex, ey, 0.0, -ey, ex, 0.0,
                                             -ke * ex, -ke * ey, 1.0, 2, y1, y2, take)
        if not conv and (y1 != 0.0 or y2 != 0.0):
            _, y1, y2, g, hess, conv = _minimise(quad, area, ex, ey, 0.0, -ey, ex, 0.0,
                                                 -ke * ex, -ke * ey, 1.0, 2, 0.0, 0.0, take)
    vx = ex - y1 * ey - y2 * ke * ex
    vy = ey + y1 * ex - y2 * ke * ey
    return vx, vy, y2, g, hess, conv


@jit
def _slip_opposes_friction(vx, vy, om, cx, cy, nx, ny, vpx, vpy, side):
    """True if the part slips past the pin against the friction of cone side
    ``side`` (tangential slip of the part relative to the pin along ``-side t``)."""
    ut = -(vx - om * cy - vpx) * ny + (vy + om * cx - vpy) * nx
    return side * ut <= 0.0


@jit_inline
def _scaled_hessian(hess, scale):
    """``H / scale``: the Hessian of P at ``scale`` times the twist."""
    k = 1.0 / scale
    return (hess[0] * k, hess[1] * k, hess[2] * k, hess[3] * k, hess[4] * k, hess[5] * k)


@jit_inline
def _minpower_twist(quad, area, cx, cy, nx, ny, vpx, vpy, mu, wvx, wvy, wom, hint,
                    model, take, points=False):
    """Minpower twist, force and mode (see ``_contact_twist``), plus P's
    gradient and Hessian at the twist returned, for the next warm start;
    ``model`` and ``take`` as for ``_slide_solve`` and ``_minimise``;
    ``points`` for the point support in ``quad`` (``_minimise_points``)."""
    if mu > 0.0 and (hint == SLIDE_POS or hint == SLIDE_NEG):
        # Shortcut while sliding: the spec's rule (solve sticking, slide on the
        # side its force leaves the cone) has a unique consistent answer, so a
        # sliding solution on the previous side whose slip opposes friction is
        # that answer. Otherwise fall through to the full rule.
        ex, ey = _cone_edge(nx, ny, mu, hint)
        vx, vy, om, g, hess, conv = _slide_solve(quad, area, cx, cy, ex, ey, wvx,
                                                 wvy, wom, model, take, points)
        scale = _push_scale(vx, vy, om, cx, cy, nx, ny, vpx, vpy)
        if scale > 0.0:
            vx, vy, om = scale * vx, scale * vy, scale * om
            if _slip_opposes_friction(vx, vy, om, cx, cy, nx, ny, vpx, vpy, hint):
                return (TWIST_OK, vx, vy, om, g[0], g[1], hint, g,
                        _scaled_hessian(hess, scale))
    if mu > 0.0:
        vx, vy, om, g, hess, conv = _stick_solve(quad, area, cx, cy, vpx, vpy, wom,
                                                 model, take, points)
        side = _cone_side(g[0], g[1], nx, ny, mu)
        if side == STICK:
            return TWIST_OK, vx, vy, om, g[0], g[1], STICK, g, hess
        # Slide from the sticking twist, with P's model there: near the
        # stick-slip change the two twists are close.
        model = (1.0, vx, vy, om, g[0], g[1], g[2], hess[0], hess[1], hess[2], hess[3],
                 hess[4], hess[5])
    else:
        side = SLIDE_POS
        vx, vy, om = wvx, wvy, wom
    ex, ey = _cone_edge(nx, ny, mu, side)
    vx, vy, om, g, hess, conv = _slide_solve(quad, area, cx, cy, ex, ey, vx, vy, om,
                                             model, take, points)
    scale = _push_scale(vx, vy, om, cx, cy, nx, ny, vpx, vpy)
    if scale <= 0.0:
        return TWIST_NO_PUSH, 0.0, 0.0, 0.0, g[0], g[1], side, g, hess
    return (TWIST_OK, scale * vx, scale * vy, scale * om, g[0], g[1], side, g,
            _scaled_hessian(hess, scale))


@jit
def _minpower_twist_points(quad, area, cx, cy, nx, ny, vpx, vpy, mu, wvx, wvy, wom, hint,
                           model, take):
    """``_minpower_twist`` over the point support in ``quad``: the same code,
    compiled as a function of its own so that the uniform model's callers,
    which inline ``_minpower_twist``, keep their code (and speed) as before."""
    return _minpower_twist(quad, area, cx, cy, nx, ny, vpx, vpy, mu, wvx, wvy, wom, hint,
                           model, take, True)


# --------------------------------------------------------------------------- tip


@jit
def _tip_twist_for_line(cx, cy, fx, fy):
    """Twist (unit rotation rate, or unit translation) about the COR-locus tip
    for the force line through ``c`` along unit ``f`` (a = 1)."""
    along = cx * fx + cy * fy
    qx, qy = cx - along * fx, cy - along * fy  # foot of the perpendicular
    rho2 = qx * qx + qy * qy
    if rho2 <= 1e-24:
        return fx, fy, 0.0
    rx, ry = -qx / rho2, -qy / rho2
    om = 1.0 if cx * fy - cy * fx > 0.0 else -1.0
    return om * ry, -om * rx, om


@jit
def _power_balance_force(quad, area, vx, vy, om, cx, cy, fx, fy):
    """Scale the unit force direction ``f`` so the pin's power ``f . u(c)``
    equals the belt's dissipation ``P`` of the twist (uniform pressure)."""
    ucf = (vx - om * cy) * fx + (vy + om * cx) * fy
    p = _power(quad, area, vx, vy, om)[0]
    k = p / ucf if ucf > 0.0 else 0.0
    return k * fx, k * fy


@jit
def _tip_twist(quad, area, cx, cy, nx, ny, vpx, vpy, mu):
    # Sticking: the COR lies on the line through c perpendicular to v_p
    # (r = c + lam t_v, t_v = z x v_p / |v_p|) and is the tip for a line
    # through c iff c . r = -a^2, which fixes lam in closed form.
    vp = math.sqrt(vpx * vpx + vpy * vpy)
    tvx, tvy = -vpy / vp, vpx / vp
    ct = cx * tvx + cy * tvy
    if abs(ct) <= 1e-14:
        fx, fy = vpx / vp, vpy / vp
        vx, vy, om = vpx, vpy, 0.0
    else:
        lam = -(1.0 + cx * cx + cy * cy) / ct
        rx, ry = cx + lam * tvx, cy + lam * tvy
        r2 = rx * rx + ry * ry
        qx, qy = -rx / r2, -ry / r2
        dx, dy = cx - qx, cy - qy
        dn = math.sqrt(dx * dx + dy * dy)
        if dn <= 1e-14:
            dx, dy, dn = -qy, qx, math.sqrt(qx * qx + qy * qy)
        fx, fy = dx / dn, dy / dn
        vx, vy, om = _tip_twist_for_line(cx, cy, fx, fy)
        ucx, ucy = vx - om * cy, vy + om * cx
        if ucx * vpx + ucy * vpy < 0.0:
            fx, fy, vx, vy, om = -fx, -fy, -vx, -vy, -om
            ucx, ucy = -ucx, -ucy
        k = vp / math.sqrt(ucx * ucx + ucy * ucy)
        vx, vy, om = k * vx, k * vy, k * om
    side = _cone_side(fx, fy, nx, ny, mu)
    if side == STICK and mu > 0.0:
        fx, fy = _power_balance_force(quad, area, vx, vy, om, cx, cy, fx, fy)
        return TWIST_OK, vx, vy, om, fx, fy, STICK
    if mu == 0.0:
        side = SLIDE_POS
    ex, ey = _cone_edge(nx, ny, mu, side)
    vx, vy, om = _tip_twist_for_line(cx, cy, ex, ey)
    scale = _push_scale(vx, vy, om, cx, cy, nx, ny, vpx, vpy)
    if scale <= 0.0:
        return TWIST_NO_PUSH, 0.0, 0.0, 0.0, 0.0, 0.0, side
    vx, vy, om = scale * vx, scale * vy, scale * om
    fx, fy = _power_balance_force(quad, area, vx, vy, om, cx, cy, ex, ey)
    return TWIST_OK, vx, vy, om, fx, fy, side


# --------------------------------------------------------------------------- ellipsoid


@jit
def _ellipsoid_twist(cx, cy, nx, ny, vpx, vpy, mu, m_max):
    mm2 = m_max * m_max
    # Sticking: (I + k k^T / m_max^2) f = v_p with k = z x c (Sherman-Morrison).
    kx, ky = -cy, cx
    kv = kx * vpx + ky * vpy
    den = mm2 + kx * kx + ky * ky
    fx, fy = vpx - kx * kv / den, vpy - ky * kv / den
    side = _cone_side(fx, fy, nx, ny, mu)
    if side == STICK and mu > 0.0:
        m = cx * fy - cy * fx
        vx, vy, om = fx, fy, m / mm2
        hs = math.sqrt(fx * fx + fy * fy + m * m / mm2)
        return TWIST_OK, vx, vy, om, fx / hs, fy / hs, STICK
    if mu == 0.0:
        side = SLIDE_POS
    ex, ey = _cone_edge(nx, ny, mu, side)
    m = cx * ey - cy * ex
    vx, vy, om = ex, ey, m / mm2
    scale = _push_scale(vx, vy, om, cx, cy, nx, ny, vpx, vpy)
    if scale <= 0.0:
        return TWIST_NO_PUSH, 0.0, 0.0, 0.0, 0.0, 0.0, side
    hs = math.sqrt(1.0 + m * m / mm2)
    return TWIST_OK, scale * vx, scale * vy, scale * om, ex / hs, ey / hs, side


@jit
def _continued_slide(model, quad, area, m_max, cx, cy, nx, ny, vpx, vpy, mu,
                     wvx, wvy, wom, side, p_model, take):
    """Sliding twist on cone side ``side`` continued past separation.

    For a pin that moves away (``n . v_p <= 0``) the physical answer is no
    force and no motion (``_contact_twist`` returns ``SEPARATE``). The
    integrator wants a smooth right-hand side within a step, so inside a
    step that crosses the separation it uses this continuation instead.

    ``(wvx, wvy, wom)``, ``p_model`` and ``take`` warm-start and stop the
    minpower solve (see ``_slide_solve``).

    Returns ``(vx, vy, om)``: the model's sliding twist for the cone edge
    ``e`` of ``side``, rescaled so that ``n . u(c) = n . v_p`` (a factor
    <= 0 here), or zeros if that twist has no normal contact velocity.

    Notes
    -----
    Before separation a sliding contact moves by ``k xi_e`` with
    ``k = (n . v_p) / (n . u_e(c))``, where ``xi_e`` is the twist for a force
    along ``e`` and depends smoothly on the contact. Keeping the same formula
    for ``n . v_p <= 0`` extends the right-hand side smoothly through the
    separation, which is a root of ``n . v_p``; the event location then
    finds the crossing on a smooth path. Cutting to zero instead leaves a
    kink in the right-hand side within the step, whose error estimate
    scales like ``h^2`` and makes the step control reject step after step.
    """
    ex, ey = _cone_edge(nx, ny, mu, side)
    if model == MINPOWER:
        vx, vy, om, _, _, _ = _slide_solve(quad, area, cx, cy, ex, ey, wvx, wvy, wom,
                                           p_model, take)
    elif model == MINPOWER_POINTS:
        vx, vy, om, _, _, _ = _slide_solve(quad, area, cx, cy, ex, ey, wvx, wvy, wom,
                                           p_model, take, True)
    elif model == TIP:
        vx, vy, om = _tip_twist_for_line(cx, cy, ex, ey)
    else:
        vx, vy, om = ex, ey, (cx * ey - cy * ex) / (m_max * m_max)
    ucn = (vx - om * cy) * nx + (vy + om * cx) * ny
    if ucn <= 1e-14 * (abs(vx) + abs(vy) + abs(om)):
        return 0.0, 0.0, 0.0
    k = (vpx * nx + vpy * ny) / ucn
    return k * vx, k * vy, k * om


@jit
def _contact_twist(model, quad, area, m_max, cx, cy, nx, ny, vpx, vpy, mu,
                   wvx, wvy, wom, hint):
    """Twist and pin force for one contact under ``model`` (see module doc).

    ``(wvx, wvy, wom)`` is the previous twist and ``hint`` the previous mode,
    used to warm-start minpower (the answer does not depend on them).
    A pin moving away from the part (``n . v_p <= 0``) exerts no force and the
    part stays at rest: mode ``SEPARATE``. ``rollout._derivative`` calls
    ``_minpower_twist`` itself, with a local model of P for the warm start.
    """
    if vpx * nx + vpy * ny <= 0.0:
        return TWIST_OK, 0.0, 0.0, 0.0, 0.0, 0.0, SEPARATE
    if model == MINPOWER:
        res = _minpower_twist(quad, area, cx, cy, nx, ny, vpx, vpy, mu, wvx, wvy, wom,
                              hint, NO_MODEL, _DEC_TAKE)
        return res[0], res[1], res[2], res[3], res[4], res[5], res[6]
    if model == MINPOWER_POINTS:
        res = _minpower_twist_points(quad, area, cx, cy, nx, ny, vpx, vpy, mu, wvx, wvy,
                                     wom, hint, NO_MODEL, _DEC_TAKE)
        return res[0], res[1], res[2], res[3], res[4], res[5], res[6]
    if model == TIP:
        return _tip_twist(quad, area, cx, cy, nx, ny, vpx, vpy, mu)
    return _ellipsoid_twist(cx, cy, nx, ny, vpx, vpy, mu, m_max)
