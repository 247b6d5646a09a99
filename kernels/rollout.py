"""One passage of a part past one pin (spec section 4).

Notes
-----
The state is integrated in the belt frame, where the belt is at rest and the
pin moves with ``v_p = (-1, v_pin / v_b)`` per unit belt travel ``s``. The
variables are ``y = (theta, q_x, q_y, X_x, X_y)``: the part's orientation, the
pin axis in the part's body frame (centroid origin) and the centroid in the
belt frame, all lengths in units of ``a``. With the body twist ``(v, omega)``
from ``models._contact_twist``::

    d theta / ds = omega
    d q / ds     = R(theta)^T v_p - (v + omega z x q)   (pin relative to the body)
    d X / ds     = R(theta) v

Within one contact feature (an edge or a vertex) the right-hand side is
smooth, and an embedded Runge-Kutta pair (Cash-Karp 5(4)) with local error
control takes large steps where the motion is slow and small ones where it
is not (on a vertex the geometry varies on the scale of ``r_pin``, not a);
the control keeps its proposed step per kind of feature (a travel on edges,
a turn on vertices, ``_first_step_size``), so the short edges and small
vertices of a flattened arc each take a step or two.
The pin is projected back to distance ``r_pin`` after every step to stop
drift. Feature
changes, separation and second contacts are events located by the Illinois
method on the step fraction, so the step never straddles one.

The kernel runs in named stages (``_rollout_core`` loops over them):
``_first_contact``; per step the slope ``_derivative``, ``_recontact``
after a separation, ``_adaptive_step`` (Cash-Karp steps ``_step`` under
error control), the end slope and events ``_events``, an event's location
``_locate`` and ``_handle_event`` (jams and feature changes).
The stages take the part's arrays ``verts`` and ``quad`` (from ``_prepare``)
as they are, and the rollout's scalar parameters as one record, a tuple
that Numba passes by value::

    prm = (model, mu, rp, vpwx, vpwy, area, m_max, convex, take)

(the contact model and friction, the pin radius in units of a, the pin's
velocity in the belt frame, the part's area, largest support moment and
convexity, and the minpower solve's stopping threshold, ``_solve_take``). ``_locate`` takes the arrays of the step it shortens and its
scratch as two tuples. Tuples of arrays are kept off the per-step path:
taking an array out of a tuple costs a reference-count update that a plain
array argument does not (measured: grouping the part and the Runge-Kutta
scratch that way cost about 10 % of the ellipsoid model's speed).

Lengths are ``sqrt(x*x + y*y)`` rather than ``math.hypot`` (twice as slow),
safe in units of a.
"""
import math

import numpy as np

from ._numba import jit, jit_alloc, jit_inline
from .geometry import (EDGE, VERTEX, _cached_gap, _is_convex, _keyhole, _normalise_loops,
                       _ray_first_contact)
from .models import (_DEC_TAKE, MINPOWER, MINPOWER_POINTS, NO_MODEL, SEPARATE, SLIDE_NEG,
                     SLIDE_POS, TWIST_OK, _contact_twist, _continued_slide, _minpower_twist,
                     _minpower_twist_points)
from .support import _fan_quadrature, _max_moment, _table_sizes
from .support_table import TABLE_MIN_EDGES, _with_table

OK = 0
MISS = 1
JAMMED = 2
TRUNCATED = 3
STATUS_NAMES = ("ok", "miss", "jammed", "truncated")

JAM_NONE = 0
JAM_NO_ROTATION = 1  # held by the pin: no rotation over 3 a of pin travel
JAM_NOTCH = 2  # two simultaneous contacts
JAM_TRAVEL = 3  # pin travel in contact past 50 a
JAM_NO_PUSH = 4  # the pin moves into the part and no pushing solution exists
JAM_CHATTER = 5  # contact feature changes without progress
TRUNC_STEP_BUDGET = 6  # status truncated: the integrator's step budget ran out
JAM_REASONS = ("", "no rotation", "notch", "travel limit", "no pushing solution", "chatter",
               "step budget")

_EVENT_TOL = 1e-10  # event functions may dip this far below zero (units of a)
# Event location stops within this of the crossing (units of a, or of the
# event function). Every event is a point where the right-hand side stays
# continuous (the contact normal is continuous from an edge to its vertex,
# and the sliding twist scales with n . v_p down to zero at separation), so
# ending the feature delta early or late moves the end state by O(delta^2)
# (an edge's end reached delta early puts the pin delta^2 / (2 r_pin) off the
# vertex's circle, which the projection removes). A rollout locates to
# ``_locate_tol``: at most 1e-5 (most events then take one real step after
# the interpolant's root; 1e-8 took two), less where that error would pass
# the step tolerance or the angle delta / r_pin would pass 1e-3 rad (small
# pins, fine tolerances).
_LOCATE_TOL = 1e-5
_LOCATE_ANGLE = 1e-3  # radians
_SAME_FEATURE = 1e-3  # contact points closer than this (units of a) are one feature
_NOTCH_TOL = 1e-6  # a second contact counts when this much closer than r_pin
_JAM_ANGLE = 1e-5  # radians
_JAM_TRAVEL = 3.0  # units of a
_MAX_TRAVEL = 50.0  # units of a
_MAX_CHANGES = 10000

DEFAULT_DS_MAX = 0.1  # units of a
DEFAULT_TOL = 1e-7  # local error per step, units of a and radians
_TAKE_PER_TOL = 0.1  # minpower solve threshold per unit of tol (see _solve_take)
_DTHETA_CAP = 0.2  # radians of contact-normal turn per step
_VERTEX_TURN = 1.25  # a vertex step's turn, in exterior angles (_first_step_size)
_VERTEX_TURN_MIN = 0.01  # radians: a floor for nearly straight vertices
_GROW_MAX = 2.0  # largest step growth between accepted steps

# Step budget: a rollout ends with status ``truncated`` and reason
# "step budget" after this many integration steps (accepted, rejected and
# event-locating steps, plus re-contacts after a separation), so no input can
# make it run without end. A normal rollout takes 20 to 200 steps; the budget
# shrinks with the polygon size because a step's cost grows with it.
# The largest budget seen used on the test grids is about 500 steps; a step
# of a degenerate contact (a pin 1e5 times the part) costs up to ~80 us for a
# triangle, so 5,000 steps stay near a second on a slow core. A 500-vertex
# outline gets 1,000 steps (~1.3 ms each).
MAX_STEPS = 5000  # for parts of up to MAX_STEPS_WORK / MAX_STEPS vertices
MAX_STEPS_WORK = 150000  # steps x vertices
MIN_STEPS = 1000

# Rows of the scratch array ``work`` (``_W_ROWS`` x ``_W_COLS`` float64) that
# ``_rollout_core`` uses instead of allocating, so the same code runs in a
# CUDA thread with a fixed-size local array.
_W_Y, _W_YNEW, _W_K1, _W_KEND, _W_YLOC, _W_TMP, _W_YI, _W_YTRY = 0, 1, 2, 3, 4, 5, 6, 7
_W_KS = 8  # six rows: the Runge-Kutta stages
_W_GEND, _W_GWORK, _W_MASK, _W_WARM, _W_WSAVE = 14, 15, 16, 17, 18
_W_GAP = 19  # the near-edge cache of the second-contact test (geometry._cached_gap)
_W_ROWS = 20
_W_COLS = 29
# The warm-start history (row ``_W_WARM``): three entries of ``_WARM_STRIDE``
# values, latest first, each the twist (3), the travel and P's gradient (3),
# then the count of entries, the latest mode and the latest Hessian (6).
_WARM_STRIDE = 7
_WARM_S, _WARM_G = 3, 4
_WARM_COUNT, _WARM_MODE, _WARM_H = 21, 22, 23
_WARM_SIZE = 29


@jit
def _solve_take(tol):
    """Stopping threshold of the minpower solves within a rollout of step
    tolerance ``tol`` (``models._minimise``'s ``take``).

    Notes
    -----
    The solve's last Newton step is taken unchecked once the decrement is
    below ``take * P``, which leaves a relative error of about ``take`` in
    the twist (quadratic convergence from ``sqrt(take)``). A step of size
    ``h`` then carries an error of about ``h take`` from the solves, against
    a local error allowed of ``tol``: ``take = _TAKE_PER_TOL * tol`` keeps the
    solves an order of magnitude below the integration error, and saves the
    confirming evaluation of P that ``models._DEC_TAKE`` (1e-12, the answer
    of a single solve) would need from a start ~1e-4 off.
    """
    return max(_DEC_TAKE, _TAKE_PER_TOL * tol)


def _prepare(xy):
    """Normalise a solid part's vertex list for rollouts (``_prepare_loops``
    with one loop)."""
    return _prepare_loops(xy, np.array([0, xy.shape[0]], dtype=np.int64))


def _prepare_loops(xy, starts):
    """Normalise a part with holes for rollouts.

    Parameters
    ----------
    xy : ``(N, 2)`` vertices of the outline, then of each hole, in either
        winding (checked simple, holes strictly inside the outline and apart).
    starts : ``(L + 1,)`` int64 offsets of the loops in ``xy``: the outline
        is ``xy[starts[0]:starts[1]]``, hole ``k`` ``xy[starts[k]:starts[k + 1]]``.

    Returns
    -------
    ``(verts, area, a, quad, m_max, convex)`` with ``verts`` the outline
    (what a pin touches) counter-clockwise, centred on the material's area
    centroid and scaled to ``a = 1``; ``area`` the material's area and
    ``m_max`` its largest support moment in those units; ``quad`` the support
    table (``support._fan_quadrature``) of the material, holes left out
    (``geometry._keyhole``), with the tabulated integrals of
    ``support_table`` when the material has ``TABLE_MIN_EDGES`` edges or
    more.

    A Python function over Numba kernels (``_prepared_loops``, then
    ``support_table._with_table``, whose cells are computed in parallel).
    """
    verts, area, a, quad, m_max, convex, n_material = _prepared_loops(xy, starts)
    if n_material >= TABLE_MIN_EDGES:
        quad = _with_table(quad)
    return verts, area, a, quad, m_max, convex


@jit_alloc
def _prepared_loops(xy, starts):
    """``_prepare_loops`` without the support table, and the number of
    material edges (outline, holes and their bridges)."""
    loops, area, a = _normalise_loops(xy, starts)
    n = starts[1] - starts[0]
    verts = loops[:n] / a
    material = _keyhole(loops, starts) / a
    area = area / (a * a)
    quad = _fan_quadrature(material)
    return verts, area, a, quad, _max_moment(material, area), _is_convex(verts), material.shape[0]


@jit
def _contact_geometry(verts, kind, idx, qx, qy):
    """Contact point ``c``, inward normal ``n`` and the two feature-bound event
    values (negative once the pin leaves the feature) for the pin at ``q``."""
    n = verts.shape[0]
    if kind == EDGE:
        k = (idx + 1) % n
        ex, ey = verts[k, 0] - verts[idx, 0], verts[k, 1] - verts[idx, 1]
        length = math.sqrt(ex * ex + ey * ey)
        ex /= length
        ey /= length
        t = (qx - verts[idx, 0]) * ex + (qy - verts[idx, 1]) * ey
        return verts[idx, 0] + t * ex, verts[idx, 1] + t * ey, -ey, ex, t, length - t
    i = (idx - 1 + n) % n
    k = (idx + 1) % n
    vx, vy = verts[idx, 0], verts[idx, 1]
    ox, oy = qx - vx, qy - vy
    dist = math.sqrt(ox * ox + oy * oy)
    # Outward normals of the edges before and after the vertex.
    ax, ay = vx - verts[i, 0], vy - verts[i, 1]
    la = math.sqrt(ax * ax + ay * ay)
    bx, by = verts[k, 0] - vx, verts[k, 1] - vy
    lb = math.sqrt(bx * bx + by * by)
    mpx, mpy = ay / la, -ax / la
    mnx, mny = by / lb, -bx / lb
    g_prev = (mpx * oy - mpy * ox) / dist
    g_next = (ox * mny - oy * mnx) / dist
    return vx, vy, -ox / dist, -oy / dist, g_prev, g_next


@jit_inline
def _warm_start(warm, sp):
    """The minpower warm start at travel ``sp`` from the history ``warm``:
    ``(vx, vy, om, p_model)``, a twist and a local model of P there
    (``models._model_step``; ``models.NO_MODEL`` before the first solve).

    Notes
    -----
    ``warm`` holds the last three solved twists, the travels at which they
    were solved and P's gradient there, and the Hessian of the latest (see
    ``_WARM_*`` for the layout). The twist and the gradient are extrapolated
    to ``sp`` alike: quadratically (Lagrange) when the three travels differ
    and ``sp`` lies within 1.5 times their spread of the latest; with only
    two solves so far, linearly (within 1.5 spans); else the latest. The
    twist is smooth in the travel within a contact feature, but the stage
    states of a Runge-Kutta step are off the trajectory by O(ds^2): the
    extrapolated start is ~1e-4 (median, relative) off, and the model step
    corrects it to first order for the stage's own family of twists.
    """
    wa, wb, wc = 1.0, 0.0, 0.0
    if warm[_WARM_COUNT] >= 3.0:
        sa, sb, sc = warm[_WARM_S], warm[_WARM_S + _WARM_STRIDE], warm[_WARM_S + 2 * _WARM_STRIDE]
        dab, dac, dbc = sa - sb, sa - sc, sb - sc
        span = max(abs(dab), abs(dac))
        if dab != 0.0 and dac != 0.0 and dbc != 0.0 and abs(sp - sa) <= 1.5 * span:
            wa = (sp - sb) * (sp - sc) / (dab * dac)
            wb = -(sp - sa) * (sp - sc) / (dab * dbc)
            wc = (sp - sa) * (sp - sb) / (dac * dbc)
    elif warm[_WARM_COUNT] >= 2.0:
        span = warm[_WARM_S] - warm[_WARM_S + _WARM_STRIDE]
        r = (sp - warm[_WARM_S]) / span if span != 0.0 else 0.0
        if -1.5 <= r <= 1.5:
            wa, wb = 1.0 + r, -r
    vx = _extrapolate(warm, 0, wa, wb, wc)
    vy = _extrapolate(warm, 1, wa, wb, wc)
    om = _extrapolate(warm, 2, wa, wb, wc)
    if warm[_WARM_COUNT] < 1.0:
        return vx, vy, om, NO_MODEL
    h = _WARM_H
    return vx, vy, om, (1.0, vx, vy, om, _extrapolate(warm, _WARM_G, wa, wb, wc),
                        _extrapolate(warm, _WARM_G + 1, wa, wb, wc),
                        _extrapolate(warm, _WARM_G + 2, wa, wb, wc), warm[h], warm[h + 1],
                        warm[h + 2], warm[h + 3], warm[h + 4], warm[h + 5])


@jit_inline
def _extrapolate(warm, j, wa, wb, wc):
    """Value ``j`` of the history's entries, weighted ``wa, wb, wc``
    (entries not filled yet are zero, from ``_first_contact``)."""
    return wa * warm[j] + wb * warm[j + _WARM_STRIDE] + wc * warm[j + 2 * _WARM_STRIDE]


@jit_inline
def _remember(warm, sp, vx, vy, om, mode, g, hess):
    """Add a solved twist at travel ``sp`` to the history ``warm``."""
    if warm[_WARM_COUNT] >= 2.0 and sp == warm[_WARM_S + _WARM_STRIDE] and sp != warm[_WARM_S]:
        # The travel of the one before last (a step's end slope after its
        # last stage, at the same travel as the stage before): replace that
        # one, so the three travels stay distinct.
        for i in range(_WARM_STRIDE):
            warm[_WARM_STRIDE + i] = warm[i]
    elif sp != warm[_WARM_S] or warm[_WARM_COUNT] < 1.0:
        for i in range(_WARM_STRIDE):
            warm[2 * _WARM_STRIDE + i] = warm[_WARM_STRIDE + i]
            warm[_WARM_STRIDE + i] = warm[i]
        warm[_WARM_COUNT] = min(warm[_WARM_COUNT] + 1.0, 3.0)
    warm[0], warm[1], warm[2], warm[_WARM_S] = vx, vy, om, sp
    warm[_WARM_G], warm[_WARM_G + 1], warm[_WARM_G + 2] = g[0], g[1], g[2]
    warm[_WARM_MODE] = mode
    for i in range(6):
        warm[_WARM_H + i] = hess[i]


@jit
def _derivative(verts, quad, prm, kind, idx, y, sp, warm, out):
    """Right-hand side at state ``y`` (belt travel ``sp``) into ``out``;
    updates the warm-start history ``warm``.

    Parameters
    ----------
    verts, quad, prm : the part's arrays and the scalar parameters (see the
        module's Notes).
    kind, idx : the contact feature (``geometry.EDGE`` or ``VERTEX``, index).
    y : state ``(theta, q_x, q_y, X_x, X_y)``.
    sp : belt travel at ``y`` (units of a).
    warm : warm-start history of the contact solve (updated; see
        ``_warm_start``).
    out : the five slopes ``d y / ds`` (written).

    Returns
    -------
    (status, mode, fx, fy)
        The contact solve's status and mode, and the pin force on the part in
        the body frame.

    Notes
    -----
    Where the pin moves away (mode ``SEPARATE``) after sliding, the slope is
    that of the sliding contact continued past the separation
    (``models._continued_slide``), so that a step crossing it sees a smooth
    right-hand side; the rollout ends the contact at the located crossing
    and never integrates past it.
    """
    model, mu, _, vpwx, vpwy, area, m_max, _, take = prm
    cx, cy, nx, ny, _, _ = _contact_geometry(verts, kind, idx, y[1], y[2])
    cs, sn = math.cos(y[0]), math.sin(y[0])
    vpx = cs * vpwx + sn * vpwy
    vpy = -sn * vpwx + cs * vpwy
    hint = int(warm[_WARM_MODE])
    if vpx * nx + vpy * ny <= 0.0:
        st, vx, vy, om, fx, fy, mode = TWIST_OK, 0.0, 0.0, 0.0, 0.0, 0.0, SEPARATE
        if warm[_WARM_COUNT] >= 1.0 and (hint == SLIDE_POS or hint == SLIDE_NEG):
            # Past a separation within a step: the smooth continuation of the
            # sliding contact (see models._continued_slide); the mode stays
            # SEPARATE, so a step that starts here still ends the contact.
            wvx, wvy, wom, p_model = _warm_start(warm, sp)
            vx, vy, om = _continued_slide(model, quad, area, m_max, cx, cy, nx, ny, vpx,
                                          vpy, mu, wvx, wvy, wom, hint, p_model, take)
    elif model == MINPOWER or model == MINPOWER_POINTS:
        wvx, wvy, wom, p_model = _warm_start(warm, sp)
        if model == MINPOWER:
            st, vx, vy, om, fx, fy, mode, g, hess = _minpower_twist(
                quad, area, cx, cy, nx, ny, vpx, vpy, mu, wvx, wvy, wom, hint, p_model,
                take)
        else:
            st, vx, vy, om, fx, fy, mode, g, hess = _minpower_twist_points(
                quad, area, cx, cy, nx, ny, vpx, vpy, mu, wvx, wvy, wom, hint, p_model,
                take)
        if st == TWIST_OK:
            _remember(warm, sp, vx, vy, om, mode, g, hess)
    else:
        # The closed-form models need no warm start: keep the mode only.
        st, vx, vy, om, fx, fy, mode = _contact_twist(model, quad, area, m_max, cx, cy,
                                                      nx, ny, vpx, vpy, mu, 0.0, 0.0, 0.0, hint)
        if st == TWIST_OK:
            warm[_WARM_MODE] = mode
            warm[_WARM_COUNT] = 1.0
    out[0] = om
    out[1] = vpx - (vx - om * y[2])
    out[2] = vpy - (vy + om * y[1])
    out[3] = cs * vx - sn * vy
    out[4] = sn * vx + cs * vy
    return st, mode, fx, fy


@jit
def _project(verts, kind, idx, rp, y):
    """Put the pin back at distance ``rp`` from its contact feature."""
    n = verts.shape[0]
    if kind == EDGE:
        k = (idx + 1) % n
        ex, ey = verts[k, 0] - verts[idx, 0], verts[k, 1] - verts[idx, 1]
        length = math.sqrt(ex * ex + ey * ey)
        mx, my = ey / length, -ex / length
        off = rp - ((y[1] - verts[idx, 0]) * mx + (y[2] - verts[idx, 1]) * my)
        y[1] += off * mx
        y[2] += off * my
    else:
        ox, oy = y[1] - verts[idx, 0], y[2] - verts[idx, 1]
        dist = math.sqrt(ox * ox + oy * oy)
        y[1] = verts[idx, 0] + rp * ox / dist
        y[2] = verts[idx, 1] + rp * oy / dist


# Cash-Karp embedded Runge-Kutta 5(4) tableau.
_CK_C = np.array([0.0, 0.2, 0.3, 0.6, 1.0, 0.875])
_CK_A = np.array([
    [0.0, 0.0, 0.0, 0.0, 0.0],
    [0.2, 0.0, 0.0, 0.0, 0.0],
    [3.0 / 40.0, 9.0 / 40.0, 0.0, 0.0, 0.0],
    [0.3, -0.9, 1.2, 0.0, 0.0],
    [-11.0 / 54.0, 2.5, -70.0 / 27.0, 35.0 / 27.0, 0.0],
    [1631.0 / 55296.0, 175.0 / 512.0, 575.0 / 13824.0, 44275.0 / 110592.0, 253.0 / 4096.0],
])
_CK_B5 = np.array([37.0 / 378.0, 0.0, 250.0 / 621.0, 125.0 / 594.0, 0.0, 512.0 / 1771.0])
_CK_B4 = np.array([2825.0 / 27648.0, 0.0, 18575.0 / 48384.0, 13525.0 / 55296.0,
                   277.0 / 14336.0, 0.25])


@jit
def _step(verts, quad, prm, kind, idx, y0, s0, k1, h, y1, ks, tmp, warm):
    """One Cash-Karp step of size ``h`` from ``y0`` at travel ``s0`` (slope
    ``k1`` given) into ``y1`` (5th-order solution, projected back onto the
    contact).

    Parameters
    ----------
    verts, quad, prm : the part's arrays and the scalar parameters (see the
        module's Notes).
    kind, idx : the contact feature.
    y0, s0, k1 : start state, its belt travel and its slope.
    h : step size (units of belt travel, a).
    y1 : the end state (written).
    ks, tmp, warm : the six stage slopes and a stage state (scratch), and
        the warm-start history of ``_derivative``.

    Returns
    -------
    (ok, err)
        ``ok`` is False if a stage found no pushing solution; ``err`` is the
        max-norm of the embedded error estimate.

    Notes
    -----
    Cash-Karp embedded 5(4) pair (Cash and Karp 1990, ACM TOMS 16, 201;
    tableau ``_CK_*``): ``y1 = y0 + h sum_j b5_j k_j`` and the error
    estimate ``h max_i |sum_j (b5_j - b4_j) k_j,i|``.
    """
    for i in range(5):
        ks[0, i] = k1[i]
    ok = True
    for st in range(1, 6):
        for i in range(5):
            acc = 0.0
            for j in range(st):
                acc += _CK_A[st, j] * ks[j, i]
            tmp[i] = y0[i] + h * acc
        res = _derivative(verts, quad, prm, kind, idx, tmp, s0 + _CK_C[st] * h, warm, ks[st])
        ok = ok and res[0] == TWIST_OK
    err = 0.0
    for i in range(5):
        acc5 = 0.0
        acc4 = 0.0
        for j in range(6):
            acc5 += _CK_B5[j] * ks[j, i]
            acc4 += _CK_B4[j] * ks[j, i]
        y1[i] = y0[i] + h * acc5
        err = max(err, abs(h * (acc5 - acc4)))
    _project(verts, kind, idx, prm[2], y1)
    return ok, err


@jit
def _events(verts, prm, kind, idx, y, g, gap_cache, exact_gap):
    """Event values at ``y`` into ``g``: leave the feature at its start/end,
    separation (``n . v_p``) and a second contact; all negative when crossed.

    The second contact's value is exact when negative; when positive it may
    be a lower bound (``geometry._cached_gap``, with the near-edge cache
    ``gap_cache``) unless ``exact_gap``, for locating its crossing."""
    _, _, rp, vpwx, vpwy, _, _, convex, _ = prm
    cx, cy, nx, ny, g[0], g[1] = _contact_geometry(verts, kind, idx, y[1], y[2])
    cs, sn = math.cos(y[0]), math.sin(y[0])
    g[2] = nx * (cs * vpwx + sn * vpwy) + ny * (-sn * vpwx + cs * vpwy)
    if convex:
        g[3] = np.inf
    else:
        g[3] = _cached_gap(verts, y[1], y[2], cx, cy, rp, _SAME_FEATURE, gap_cache,
                           exact_gap) + _NOTCH_TOL


@jit
def _first_event(g, tol):
    """Index of the most negative event value below ``-tol``, or -1."""
    ev = -1
    worst = -tol
    for j in range(4):
        if g[j] < worst:
            worst = g[j]
            ev = j
    return ev


@jit
def _min_over(g, mask):
    m = np.inf
    for j in range(4):
        if mask[j] != 0.0 and g[j] < m:
            m = g[j]
    return m


@jit
def _hermite(y0, k0, y1, k1, h, alpha, out):
    """Cubic Hermite dense output of a step at fraction ``alpha`` (first 3 components)."""
    a2 = alpha * alpha
    a3 = a2 * alpha
    h00 = 2.0 * a3 - 3.0 * a2 + 1.0
    h10 = a3 - 2.0 * a2 + alpha
    h01 = -2.0 * a3 + 3.0 * a2
    h11 = a3 - a2
    for i in range(3):
        out[i] = h00 * y0[i] + h10 * h * k0[i] + h01 * y1[i] + h11 * h * k1[i]


@jit
def _locate(verts, quad, prm, kind, idx, s0, h, trial, scratch, loc_tol):
    """Shrink the step from ``y0`` to end on the first event crossed by the
    full step of size ``h`` to ``y1`` (slope ``k_end``, event values ``g1``).

    Parameters
    ----------
    verts, quad, prm : the part's arrays and the scalar parameters (see the
        module's Notes).
    kind, idx : the contact feature.
    s0, h : belt travel at the step's start, and the full step's size.
    trial : ``(y0, k1, y1, k_end, g1)``: the full step's start state and
        slope, end state and slope, and event values at its end.
    scratch : ``(y_out, ks, tmp, warm, g, mask, yi, y_try, gap_cache)``:
        the state just before the crossing (written); ``ks, tmp, warm`` as
        for ``_step``; event values, the events that count, an interpolated
        and a trial state; the near-edge cache of ``_events`` (the second
        contact's value is measured exactly once it counts).
    loc_tol : how close to the crossing the kept state must be
        (``_locate_tol``).

    Returns
    -------
    (fraction, event, steps)
        The step fraction kept, the event crossed (index into the event
        values of ``_events``) and the number of real steps taken.

    Notes
    -----
    The crossing is first found on the step's cubic Hermite interpolant (no
    contact solves) by the Illinois variant of regula falsi (Dowell and
    Jarratt 1971, BIT 11, 168), then refined with real steps by safeguarded
    secant iterations kept inside the bracket of real evaluations. The
    event function is the least of the event values crossed so far (a mask
    over the four), so an earlier event found while refining takes over.
    """
    y0, k1, y1, k_end, g1 = trial
    y_out, ks, tmp, warm, g, mask, yi, y_try, gap_cache = scratch
    for j in range(4):
        mask[j] = 1.0 if g1[j] < -_EVENT_TOL else 0.0
    _events(verts, prm, kind, idx, y0, g, gap_cache, mask[3] != 0.0)
    f0 = _min_over(g, mask)
    f1 = _min_over(g1, mask)
    # 1. Root of the event function along the interpolant (Illinois).
    for i in range(5):
        yi[i] = y0[i]
    lo, hi, f_lo, f_hi, side = 0.0, 1.0, f0, f1, 0
    alpha = 0.5
    for _ in range(60):
        alpha = hi - f_hi * (hi - lo) / (f_hi - f_lo) if f_lo > f_hi else 0.5 * (lo + hi)
        if not (lo < alpha < hi):
            alpha = 0.5 * (lo + hi)
        _hermite(y0, k1, y1, k_end, h, alpha, yi)
        _events(verts, prm, kind, idx, yi, g, gap_cache, mask[3] != 0.0)
        f = _min_over(g, mask)
        if f < 0.0:
            hi, f_hi = alpha, f
            if side == -1:
                f_lo *= 0.5
            side = -1
        else:
            lo, f_lo = alpha, f
            if side == 1:
                f_hi *= 0.5
            side = 1
        if abs(f) < 1e-14 or hi - lo < 1e-14:
            break
    # 2. Refine with real steps: secant from the interpolant's root, kept
    #    inside the bracket of real evaluations.
    for i in range(5):
        y_out[i] = y0[i]
    lo, hi, f_lo = 0.0, 1.0, f0
    frac = 0.0
    prev_alpha, prev_f = -1.0, 0.0
    n_steps = 0
    for it in range(60):
        if not (lo < alpha < hi):
            alpha = 0.5 * (lo + hi)
        n_steps += 1
        _step(verts, quad, prm, kind, idx, y0, s0, k1, alpha * h, y_try, ks, tmp, warm)
        _events(verts, prm, kind, idx, y_try, g, gap_cache, mask[3] != 0.0)
        for j in range(4):
            if mask[j] == 0.0 and g[j] < -_EVENT_TOL:
                mask[j] = 1.0  # an earlier event than the ones seen so far
        f = _min_over(g, mask)
        # Close enough when within loc_tol of the crossing; a state a hair
        # past it (f >= -loc_tol / 10) is kept too.
        close = -0.1 * loc_tol <= f <= loc_tol
        if f < 0.0:
            hi = alpha
        else:
            lo, f_lo = alpha, f
        if f >= 0.0 or close:
            frac = alpha
            for i in range(5):
                y_out[i] = y_try[i]
        if close or (hi - lo) * h < 1e-15:
            break
        if prev_alpha >= 0.0 and f != prev_f and it < 8:
            nxt = alpha - f * (alpha - prev_alpha) / (f - prev_f)
        else:
            # First refinement: a Newton step with the interpolant's slope at
            # the guess (a difference of two interpolated values: the real
            # value f differs from the interpolated one by the interpolation
            # error, which would swamp a difference over 1e-7).
            slope = 0.0
            if it < 8:
                _hermite(y0, k1, y1, k_end, h, alpha + 1e-7, yi)
                _events(verts, prm, kind, idx, yi, g, gap_cache, mask[3] != 0.0)
                f_up = _min_over(g, mask)
                _hermite(y0, k1, y1, k_end, h, alpha, yi)
                _events(verts, prm, kind, idx, yi, g, gap_cache, mask[3] != 0.0)
                slope = (f_up - _min_over(g, mask)) / 1e-7
            nxt = alpha - f / slope if slope < 0.0 else 0.5 * (lo + hi)
        prev_alpha, prev_f = alpha, f
        # Aim slightly early so the kept state lies before the crossing.
        alpha = nxt - 1e-13 / h
    _events(verts, prm, kind, idx, y_out, g, gap_cache, mask[3] != 0.0)
    ev = 0
    best = np.inf
    for j in range(4):
        if mask[j] != 0.0 and g[j] < best:
            best, ev = g[j], j
    return frac, ev, n_steps


@jit_inline
def _locate_tol(rp, tol):
    """How close to its crossing an event is located (units of the event
    function): ``_LOCATE_TOL``, or less where the state's error delta^2 /
    (2 rp) would pass ``tol`` or the pin's angle delta / rp around a vertex
    would pass ``_LOCATE_ANGLE``."""
    return min(_LOCATE_TOL, math.sqrt(2.0 * rp * tol), _LOCATE_ANGLE * rp)


@jit
def max_steps_for(n_vertices):
    """Default step budget of a rollout for a polygon of ``n_vertices``."""
    return max(MIN_STEPS, min(MAX_STEPS, MAX_STEPS_WORK // max(n_vertices, 1)))


@jit_alloc
def _rollout(verts, area, a, quad, m_max, convex, model, mu_c, r_pin, theta_i, d, v_pin,
             max_travel, ds_max, tol, record):
    """Roll a prepared part (see ``_prepare``) past one pin.

    Parameters
    ----------
    verts, area, a, quad, m_max, convex : output of ``_prepare``.
    model : ``models.MINPOWER``, ``TIP``, ``ELLIPSOID`` or ``MINPOWER_POINTS``
        (minpower over the point support that ``quad`` then holds; see
        ``models``).
    mu_c : contact friction coefficient (>= 0).
    r_pin : pin radius (same length unit as the part).
    theta_i : initial orientation (radians).
    d : contact parameter ``(y_pin - y_com) / a``, the pin's offset as it
        passes the centroid's starting station.
    v_pin : pin speed across the belt in units of the belt speed (0: static).
    max_travel : stop after this belt travel since first contact (inf: never).
    ds_max : largest step (units of a).
    tol : local error tolerance per step (units of a and radians).
    record : keep the trajectory and force history.

    Returns
    -------
    (status, jam_reason, theta_f, dy, contact_travel, feature_changes,
     peak_force, trajectory, force)
        ``theta_f`` in radians in [0, 2 pi); lengths in the part's unit;
        ``trajectory`` rows ``(s, x, y, theta)`` (theta unwrapped, radians) and
        ``force`` rows ``(s, f_x, f_y)`` (force on the pin, units of mu_s m g);
        both empty unless ``record``. A rollout that uses up the step budget
        ``max_steps_for`` of the support polygon's size ends ``TRUNCATED`` with reason
        ``TRUNC_STEP_BUDGET``.
    """
    res = _rollout_budget(verts, area, a, quad, m_max, convex, model, mu_c, r_pin, theta_i, d,
                          v_pin, max_travel, ds_max, tol, record,
                          max_steps_for(_table_sizes(quad)[1]))
    return res[0], res[1], res[2], res[3], res[4], res[5], res[6], res[7], res[8]


@jit_alloc
def _rollout_budget(verts, area, a, quad, m_max, convex, model, mu_c, r_pin, theta_i, d, v_pin,
                    max_travel, ds_max, tol, record, max_steps):
    """``_rollout`` with an explicit step budget ``max_steps``; returns its
    nine results plus the number of steps used (at most ``max_steps`` plus
    one event location, 61 steps)."""
    work = np.empty((_W_ROWS, _W_COLS))
    cap = max_steps + 4 if record else 1
    traj = np.empty((cap, 4))
    force = np.empty((cap, 3))
    res = _rollout_core(verts, area, a, quad, m_max, convex, model, mu_c, r_pin, theta_i, d,
                        v_pin, max_travel, ds_max, tol, record, max_steps, work, traj, force)
    n_traj, n_force = res[7], res[8]
    return (res[0], res[1], res[2], res[3], res[4], res[5], res[6], traj[:n_traj].copy(),
            force[:n_force].copy(), res[9])


@jit
def _first_contact(verts, prm, theta_i, d, y, warm, mask):
    """Stage 1: the pin's first touch of the part, and the initial state.

    Parameters
    ----------
    verts, prm : the part's vertices and the scalar parameters (see the
        module's Notes).
    theta_i : initial orientation (radians).
    d : contact parameter (units of a).
    y, warm, mask : state, warm-start history and event mask (written when
        the pin touches the part).

    Returns
    -------
    (sigma, kind, idx)
        Belt travel from the start station to the touch (``inf`` for a
        miss) and the feature touched.

    Notes
    -----
    The pin path passes ``y = 0`` at the centroid's starting station
    ``x = 0``; it starts far enough back to clear the part, and the first
    contact is found by casting the pin disc along its path in the body
    frame (``geometry._ray_first_contact``). The warm start is a translation
    along the pin's path.
    """
    _, _, rp, vpwx, vpwy, _, _, _, _ = prm
    v_pin = vpwy
    s0 = -(2.0 + rp + abs(d)) * (1.0 + abs(v_pin))
    px, py = -s0 * 1.0, s0 * v_pin
    cs, sn = math.cos(theta_i), math.sin(theta_i)
    dx, dy0 = px - 0.0, py + d
    qx, qy = cs * dx + sn * dy0, -sn * dx + cs * dy0
    wx, wy = cs * vpwx + sn * vpwy, -sn * vpwx + cs * vpwy
    sigma, kind, idx = _ray_first_contact(verts, qx, qy, wx, wy, rp, 0.0)
    if math.isfinite(sigma):
        y[0], y[1], y[2], y[3], y[4] = theta_i, qx + sigma * wx, qy + sigma * wy, 0.0, -d
        for j in range(_WARM_SIZE):
            warm[j] = 0.0
        warm[0], warm[1] = wx, wy
        for j in range(4):
            mask[j] = 0.0
    return sigma, kind, idx


@jit_inline
def _recontact(verts, prm, y):
    """After a separation: the part rests while the pin travels on; a
    non-convex part may be caught again further along the pin's path.

    Returns ``(sigma, kind, idx, wx, wy)``: the pin travel to the next
    touch (``inf`` if none), the feature touched and the pin's direction in
    the body frame. The caller moves the pin.
    """
    _, _, rp, vpwx, vpwy, _, _, _, _ = prm
    cs, sn = math.cos(y[0]), math.sin(y[0])
    wx, wy = cs * vpwx + sn * vpwy, -sn * vpwx + cs * vpwy
    sigma, kind, idx = _ray_first_contact(verts, y[1], y[2], wx, wy, rp, 1e-9)
    return sigma, kind, idx, wx, wy


@jit_inline
def _first_step_size(verts, k1, h_max, kind, idx, rp, vertex_turn):
    """Step size to try: ``h_max`` capped so that the contact normal turns
    by at most ``_DTHETA_CAP`` (with the part on an edge; around the vertex
    on a vertex), so no event function can cross zero twice within one
    step.

    On a vertex the turn is also capped at ``vertex_turn`` (the step
    control's last proposal on a vertex, as a turn) and at 1.25 times the
    vertex's exterior angle (but at least 0.01 rad): the pin leaves the vertex
    within that turn, so a longer step would be cut back by the event
    anyway, and on a flattened arc (exterior angles of a few degrees) it was
    mostly rejected first by the error control (the pin circles the vertex
    on the scale of r_pin)."""
    h = h_max
    if abs(k1[0]) * h > _DTHETA_CAP:
        h = _DTHETA_CAP / abs(k1[0])
    if kind == VERTEX:
        turn = _turn_rate(k1, rp)
        cap = min(_DTHETA_CAP, max(min(vertex_turn, _VERTEX_TURN * _exterior_angle(verts, idx)),
                                   _VERTEX_TURN_MIN))
        if turn * h > cap:
            h = cap / turn
    return h


@jit_inline
def _turn_rate(k1, rp):
    """How fast the contact normal turns with the pin on a vertex (radians
    per unit travel): the pin's speed around it over ``rp``."""
    return math.sqrt(k1[1] * k1[1] + k1[2] * k1[2]) / rp


@jit_inline
def _exterior_angle(verts, idx):
    """The angle (radians, in [0, pi]) between the edges into and out of
    vertex ``idx``: how far the contact normal turns around it."""
    n = verts.shape[0]
    i, k = (idx - 1 + n) % n, (idx + 1) % n
    ax, ay = verts[idx, 0] - verts[i, 0], verts[idx, 1] - verts[i, 1]
    bx, by = verts[k, 0] - verts[idx, 0], verts[k, 1] - verts[idx, 1]
    return abs(math.atan2(ax * by - ay * bx, ax * bx + ay * by))


@jit_inline
def _adaptive_step(verts, quad, prm, kind, idx, y, s, k1, h, tol, y_new, ks, tmp, warm,
                   warm_saved):
    """Stage 2: one accepted step from ``y`` (travel ``s``, slope ``k1``)
    into ``y_new``, shrinking ``h`` until the error is within ``tol``.

    Returns
    -------
    (ok, err, h, rejected, attempts)
        ``ok`` False if no pushing solution exists at a stage of the last
        attempt; the error estimate and size of the step taken; whether an
        attempt was rejected; the number of attempts (each counts against
        the step budget).

    Notes
    -----
    Standard step-size control of an embedded pair of orders 5 and 4
    (Hairer, Norsett and Wanner, *Solving ODEs I*, II.4):
    ``h <- h max(0.2, 0.8 (tol / err)^(1/5))`` after a rejection, halving
    when a stage has no pushing solution, and giving up below ``1e-12``.
    """
    rejected = False
    attempts = 0
    keep = prm[0] == MINPOWER or prm[0] == MINPOWER_POINTS
    if keep:
        for i in range(_WARM_SIZE):
            warm_saved[i] = warm[i]
    while True:
        attempts += 1
        if rejected and keep:
            # Warm-start a retry from the solves before the rejected attempt
            # (near s), not from the rejected attempt's far stages.
            for i in range(_WARM_SIZE):
                warm[i] = warm_saved[i]
        ok, err = _step(verts, quad, prm, kind, idx, y, s, k1, h, y_new, ks, tmp, warm)
        if h < 1e-12:
            break
        if not ok:
            h *= 0.5
        elif err > tol:
            h *= max(0.2, 0.8 * (tol / err) ** 0.2)
        else:
            break
        rejected = True
    return ok, err, h, rejected, attempts


@jit_inline
def _next_step_size(err, tol, h, rejected, ds_max):
    """Size of the next step: grow gently (at most ``_GROW_MAX``), and not
    at all right after a rejection (rejected steps cost five contact solves
    each); never above ``ds_max``."""
    grow = _GROW_MAX if err <= 0.0 else min(_GROW_MAX, 0.8 * (tol / err) ** 0.2)
    if rejected:
        grow = min(grow, 1.0)
    return min(ds_max, h * grow)


@jit_inline
def _handle_event(verts, rp, ev, y, travel, kind, idx, changes, theta_ref, travel_ref):
    """Stage 4: after a step, the jam tests and the event crossed.

    Parameters
    ----------
    verts, rp : the part's vertices and the pin radius (units of a).
    ev : the event the step ended on (-1: none; see ``_events``).
    y, travel : the state (the pin is projected onto a new feature) and the
        pin travel in contact so far.
    kind, idx : the contact feature.
    changes : feature changes so far.
    theta_ref, travel_ref : orientation and travel at the last rotation of
        at least ``_JAM_ANGLE``.

    Returns
    -------
    (reason, kind, idx, changes, theta_ref, travel_ref)
        ``reason`` is ``JAM_NONE`` unless the rollout jams.

    Notes
    -----
    Tests in this order: no rotation of ``_JAM_ANGLE`` over ``_JAM_TRAVEL``
    of pin travel, travel past ``_MAX_TRAVEL``, a second contact (notch),
    then a feature change (an edge to its end vertex or a vertex to the
    adjacent edge, events 0 and 1), which fails past ``_MAX_CHANGES``.
    Separation (event 2) is handled by the caller.
    """
    if abs(y[0] - theta_ref) >= _JAM_ANGLE:
        theta_ref, travel_ref = y[0], travel
    elif travel - travel_ref > _JAM_TRAVEL:
        return JAM_NO_ROTATION, kind, idx, changes, theta_ref, travel_ref
    if travel > _MAX_TRAVEL:
        return JAM_TRAVEL, kind, idx, changes, theta_ref, travel_ref
    if ev == 3:
        return JAM_NOTCH, kind, idx, changes, theta_ref, travel_ref
    if ev == 0 or ev == 1:
        changes += 1
        if changes > _MAX_CHANGES:
            return JAM_CHATTER, kind, idx, changes, theta_ref, travel_ref
        n = verts.shape[0]
        if kind == EDGE:
            kind, idx = VERTEX, (idx if ev == 0 else (idx + 1) % n)
        else:
            kind, idx = EDGE, ((idx - 1 + n) % n if ev == 0 else idx)
        _project(verts, kind, idx, rp, y)
    return JAM_NONE, kind, idx, changes, theta_ref, travel_ref


@jit
def _rollout_core(verts, area, a, quad, m_max, convex, model, mu_c, r_pin, theta_i, d, v_pin,
                  max_travel, ds_max, tol, record, max_steps, work, traj, force):
    """The rollout itself, without allocating: the scalar code path shared by
    the CPU kernels and the CUDA kernel (``kernels.cuda``).

    ``work`` is a ``(_W_ROWS, _W_COLS)`` float64 scratch array; ``traj`` and
    ``force`` take the records when ``record`` (at least ``max_steps + 4``
    rows; unused otherwise). Returns ``(status, jam_reason, theta_f, dy,
    contact_travel, feature_changes, peak_force, n_traj, n_force, steps)``.

    Notes
    -----
    The loop runs the stages ``_first_contact``, then per step: the slope
    (``_derivative``, unless the last step's end slope is known), a
    re-contact after a separation (``_recontact``), ``_adaptive_step``,
    the end slope and events (``_events``), an event's location
    (``_locate``) and ``_handle_event``.

    Every integration attempt counts against ``max_steps``: accepted and
    rejected steps, the real steps of an event location and each re-contact
    after a separation. The budget is checked before each step, so at most
    one event location (61 steps) runs past it.
    """
    rp = r_pin / a
    s_cap = max_travel / a
    n_traj = 0
    n_force = 0
    two_pi = 2.0 * math.pi
    prm = (model, mu_c, rp, -1.0, v_pin, area, m_max, convex, _solve_take(tol))
    loc_tol = _locate_tol(rp, tol)
    y = work[_W_Y]
    y_new = work[_W_YNEW]
    k1 = work[_W_K1]
    k_end = work[_W_KEND]
    y_located = work[_W_YLOC]
    tmp = work[_W_TMP]
    ks = work[_W_KS:_W_KS + 6]
    g_end = work[_W_GEND]
    mask = work[_W_MASK]
    warm = work[_W_WARM]
    gap_cache = work[_W_GAP]
    gap_cache[0] = -1.0  # empty: the work array may come from another part
    sigma, kind, idx = _first_contact(verts, prm, theta_i, d, y, warm, mask)
    if not math.isfinite(sigma):
        return MISS, JAM_NONE, theta_i % two_pi, 0.0, 0.0, 0, 0.0, 0, 0, 0
    s = 0.0
    h_next = ds_max
    travel = 0.0
    changes = 0
    steps = 0
    peak = 0.0
    theta_ref, travel_ref = theta_i, 0.0
    status, reason = OK, JAM_NONE
    if record:
        traj[0, 0], traj[0, 1], traj[0, 2], traj[0, 3] = 0.0, 0.0, 0.0, theta_i
        n_traj = 1
    separated = False
    have_k1 = False
    # The step control's proposal is kept per kind of feature: a travel on
    # edges, a turn on vertices (where the motion's scale is r_pin, not a).
    # Along a flattened arc the pin alternates between short edges and
    # vertices; restarting each edge from the vertex's short steps took
    # three or four steps an edge where one or two do.
    h_edge, vertex_turn, last_kind = ds_max, _DTHETA_CAP, kind
    st, mode, fx, fy = TWIST_OK, SEPARATE, 0.0, 0.0
    while True:
        if steps >= max_steps:
            status, reason = TRUNCATED, TRUNC_STEP_BUDGET
            break
        if not have_k1:
            st, mode, fx, fy = _derivative(verts, quad, prm, kind, idx, y, s, warm, k1)
        if separated:
            # A located separation ends just before n . v_p crosses zero.
            st, mode, separated = TWIST_OK, SEPARATE, False
        if st != TWIST_OK:
            status, reason = JAMMED, JAM_NO_PUSH
            break
        # The force on the pin, in the belt frame.
        cs, sn = math.cos(y[0]), math.sin(y[0])
        fwx, fwy = cs * fx - sn * fy, sn * fx + cs * fy
        if mode == SEPARATE:
            fwx, fwy = 0.0, 0.0
        peak = max(peak, math.sqrt(fwx * fwx + fwy * fwy))
        if record:
            force[n_force, 0], force[n_force, 1], force[n_force, 2] = s * a, -fwx, -fwy
            n_force += 1
        if mode == SEPARATE:
            steps += 1
            sigma, kind, idx, wx, wy = _recontact(verts, prm, y)
            if not math.isfinite(sigma):
                break
            if s + sigma >= s_cap:
                status = TRUNCATED
                break
            y[1] += sigma * wx
            y[2] += sigma * wy
            s += sigma
            changes += 1
            have_k1 = False
            continue
        if s >= s_cap:
            status = TRUNCATED
            break
        if kind != last_kind:
            h_next = h_edge if kind == EDGE else ds_max  # on a vertex, vertex_turn caps it
            last_kind = kind
        h = _first_step_size(verts, k1, min(h_next, s_cap - s), kind, idx, rp, vertex_turn)
        ok, err, h, rejected, attempts = _adaptive_step(verts, quad, prm, kind, idx, y, s, k1, h,
                                                        tol, y_new, ks, tmp, warm,
                                                        work[_W_WSAVE])
        steps += attempts
        if not ok:
            status, reason = JAMMED, JAM_NO_PUSH
            break
        h_next = _next_step_size(err, tol, h, rejected, ds_max)
        if kind == VERTEX:
            vertex_turn = _turn_rate(k1, rp) * h_next
        else:
            h_edge = h_next
        # Slope at the step's end: the next step's first stage when no event
        # intervenes (FSAL), and the end slope of the dense output otherwise.
        st_e, mode_e, fx_e, fy_e = _derivative(verts, quad, prm, kind, idx, y_new, s + h, warm,
                                               k_end)
        _events(verts, prm, kind, idx, y_new, g_end, gap_cache, False)
        ev = _first_event(g_end, _EVENT_TOL)
        frac = 1.0
        if ev >= 0:
            trial = (y, k1, y_new, k_end, g_end)
            scratch = (y_located, ks, tmp, warm, work[_W_GWORK], mask, work[_W_YI],
                       work[_W_YTRY], gap_cache)
            frac, ev, n_loc = _locate(verts, quad, prm, kind, idx, s, h, trial, scratch,
                                      loc_tol)
            steps += n_loc
            for i in range(5):
                y_new[i] = y_located[i]
            have_k1 = False
        else:
            for i in range(5):
                k1[i] = k_end[i]
            st, mode, fx, fy = st_e, mode_e, fx_e, fy_e
            have_k1 = True
        for i in range(5):
            y[i] = y_new[i]
        s += frac * h
        travel += frac * h
        if record:
            traj[n_traj, 0], traj[n_traj, 1] = s * a, y[3] * a
            traj[n_traj, 2], traj[n_traj, 3] = (y[4] + d) * a, y[0]
            n_traj += 1
        reason, kind, idx, changes, theta_ref, travel_ref = _handle_event(
            verts, rp, ev, y, travel, kind, idx, changes, theta_ref, travel_ref)
        if reason != JAM_NONE:
            status = JAMMED
            break
        separated = ev == 2
    if record:
        force[n_force, 0], force[n_force, 1], force[n_force, 2] = s * a, 0.0, 0.0
        n_force += 1
    if status == OK and travel == 0.0:
        status = MISS
    return (status, reason, y[0] % two_pi, (y[4] + d) * a, travel * a, changes, peak,
            n_traj, n_force, steps)
