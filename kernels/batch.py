"""Parallel grids of rollouts: one part, one model, many (theta_i, d).

Notes
-----
The grid is split into one contiguous block per thread (``prange`` over
blocks), so each thread reuses its own buffers and the result does not depend
on the thread count: every rollout is computed independently.
"""
import numpy as np
from numba import prange

from ._numba import jit_parallel
from .rollout import _rollout


@jit_parallel
def _rollout_grid(verts, area, a, quad, m_max, convex, model, mu_c, r_pin, theta_i, d, v_pin,
                  max_travel, ds_max, tol, n_blocks):
    """Rollouts over the outer product ``d x theta_i`` (radians for theta_i).

    ``n_blocks`` is the number of contiguous blocks the grid is cut into
    (use the thread count). Returns arrays of shape ``(len(d), len(theta_i))``: ``status``,
    ``jam_reason`` (int8), ``theta_f`` (radians), ``dy``, ``contact_travel``,
    ``feature_changes`` (int32) and ``peak_force``.
    """
    nd, nt = d.shape[0], theta_i.shape[0]
    total = nd * nt
    status = np.empty((nd, nt), dtype=np.int8)
    reason = np.empty((nd, nt), dtype=np.int8)
    theta_f = np.empty((nd, nt))
    dy = np.empty((nd, nt))
    travel = np.empty((nd, nt))
    changes = np.empty((nd, nt), dtype=np.int32)
    peak = np.empty((nd, nt))
    n_blocks = max(1, min(n_blocks, total))
    for b in prange(n_blocks):
        start = b * total // n_blocks
        stop = (b + 1) * total // n_blocks
        for flat in range(start, stop):
            i, j = flat // nt, flat % nt
            res = _rollout(verts, area, a, quad, m_max, convex, model, mu_c, r_pin,
                           theta_i[j], d[i], v_pin, max_travel, ds_max, tol, False)
            status[i, j] = res[0]
            reason[i, j] = res[1]
            theta_f[i, j] = res[2]
            dy[i, j] = res[3]
            travel[i, j] = res[4]
            changes[i, j] = res[5]
            peak[i, j] = res[6]
    return status, reason, theta_f, dy, travel, changes, peak
