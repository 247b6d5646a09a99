"""Rollouts at scattered points: one part, one model, one pin speed, many
``(theta_i, d, mu_c)`` triples.

Notes
-----
The planner's uncertainty propagation and the verification replay need
rollouts at points that do not form a grid (adaptive refinement of a state's
box; perturbed trials). Each point is an independent rollout, so the result
does not depend on the thread count. The points run through ``drive._drive``
in interleaved chunks of one (``k, k + n_threads, ...``) so that the long
rollouts (jams, many contact changes), which cluster in neighbouring points,
spread over every thread: ``_rollout_points`` for the quasi-static models,
``_dyn_rollout_points`` for the dynamic one.
"""
from ._numba import jit, jit_alloc
from .drive import DYNAMIC, NO_DYNAMIC, NO_STATIC, STATIC, _drive
from .rollout import max_steps_for
from .support import _table_sizes


@jit_alloc
def _rollout_points(verts, area, a, quad, m_max, convex, model, mu_c, r_pin, theta_i, d, v_pin,
                    max_travel, ds_max, tol, n_threads):
    """Final states of rollouts at the points ``(theta_i[k], d[k], mu_c[k])``.

    Parameters
    ----------
    verts, area, a, quad, m_max, convex : output of ``rollout._prepare``.
    model : model code (``models.MINPOWER``, ...).
    mu_c, theta_i, d : 1-D float64 arrays of equal length (theta_i in radians).
    r_pin, v_pin, max_travel, ds_max, tol : as for ``rollout._rollout``.
    n_threads : number of interleaved chunks (use the thread count).

    Returns
    -------
    (status, jam_reason, theta_f, dy)
        int8, int8, float64 (radians in [0, 2 pi)), float64 (part's length unit).
    """
    prm = (model, r_pin, v_pin, max_travel, ds_max, tol, max_steps_for(_table_sizes(quad)[1]))
    out = _drive(STATIC, False, theta_i.shape[0], 1, n_threads, verts, area, a, quad, m_max,
                 convex, mu_c, theta_i, d, prm, NO_DYNAMIC)
    return out[0], out[1], out[2], out[3]


@jit_alloc
def _dyn_rollout_points(verts, area, a, quad, convex, mu_c, r_pin, theta_i, d, v_pin, fr,
                        restitution, eps, h, max_travel, max_steps, n_threads):
    """Dynamic rollouts at scattered points ``(theta_i[k], d[k], mu_c[k])``.

    The belt-speed twin of ``_rollout_points``: the planner's propagation and
    the verification replay at a belt speed need rollouts at points that do
    not form a grid.

    Parameters
    ----------
    verts, area, a, quad, convex : from ``rollout._prepare``.
    mu_c, theta_i, d : 1-D float64 arrays of equal length (theta_i in radians).
    r_pin, v_pin, fr, restitution, eps, h, max_travel, max_steps : as for
        ``dynamic._dyn_rollout``.
    n_threads : number of interleaved chunks (use the thread count).

    Returns
    -------
    (status, reason, theta_f, dy)
        int8, int8 (``dynamic.DYN_REASONS``), float64 (radians), float64 (part's unit).
    """
    prm = (r_pin, v_pin, fr, restitution, eps, h, max_travel, max_steps)
    out = _drive(DYNAMIC, False, theta_i.shape[0], 1, n_threads, verts, area, a, quad, 0.0,
                 convex, mu_c, theta_i, d, NO_STATIC, prm)
    return out[0], out[1], out[2], out[3]
