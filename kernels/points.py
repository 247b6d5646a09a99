"""Rollouts at scattered points: one part, one model, one pin speed, many
``(theta_i, d, mu_c)`` triples.

Notes
-----
The planner's uncertainty propagation and the verification replay need
rollouts at points that do not form a grid (adaptive refinement of a state's
box; perturbed trials). Each point is an independent rollout, so the result
does not depend on the thread count. ``prange`` hands the points to threads
in interleaved chunks of one (``k, k + n_threads, ...``) so that the long
rollouts (jams, many contact changes), which cluster in neighbouring points,
spread over every thread.
"""
import numpy as np
from numba import prange

from ._numba import jit_parallel
from .rollout import _rollout


@jit_parallel
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
    n = theta_i.shape[0]
    status = np.empty(n, dtype=np.int8)
    reason = np.empty(n, dtype=np.int8)
    theta_f = np.empty(n)
    dy = np.empty(n)
    n_threads = max(1, min(n_threads, n))
    for t in prange(n_threads):
        for k in range(t, n, n_threads):
            res = _rollout(verts, area, a, quad, m_max, convex, model, mu_c[k], r_pin,
                           theta_i[k], d[k], v_pin, max_travel, ds_max, tol, False)
            status[k] = res[0]
            reason[k] = res[1]
            theta_f[k] = res[2]
            dy[k] = res[3]
    return status, reason, theta_f, dy
