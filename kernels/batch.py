"""Parallel grids of rollouts: one part, one model, many (theta_i, d).

Notes
-----
Load balance: the flat grid (``d`` major) is cut into chunks of ``_CHUNK``
consecutive rollouts, and ``n_blocks`` blocks take the chunks in turn
(block ``b`` takes chunks ``b, b + n_blocks, ...``). The long rollouts (jams,
many contact changes) come in runs of neighbouring ``theta_i``; interleaving
spreads every run over all blocks, where contiguous blocks would give whole
runs to one thread. Use several blocks per thread (``blocks_for``) so that
Numba's static split of ``prange`` still evens out. A chunk's results fill
whole cache lines of the float64 outputs, so threads rarely write to the
same line. Each block owns its scratch array, and every rollout is computed
independently, so the result does not depend on the thread count.
"""
import numpy as np
from numba import prange

from ._numba import jit_parallel
from .rollout import _W_COLS, _W_ROWS, _rollout_core, max_steps_for
from .support import _table_sizes

_CHUNK = 8  # rollouts per chunk: 64 bytes of each float64 output
BLOCKS_PER_THREAD = 8


def blocks_for(threads, total):
    """Number of blocks for ``threads`` threads and ``total`` rollouts."""
    return max(1, min(int(threads) * BLOCKS_PER_THREAD, -(-int(total) // _CHUNK)))


@jit_parallel
def _rollout_grid(verts, area, a, quad, m_max, convex, model, mu_c, r_pin, theta_i, d, v_pin,
                  max_travel, ds_max, tol, n_blocks):
    """Rollouts over the outer product ``d x theta_i`` (radians for theta_i).

    ``n_blocks`` is the number of interleaved blocks the grid is cut into
    (see ``blocks_for``). Returns arrays of shape ``(len(d), len(theta_i))``:
    ``status``, ``jam_reason`` (int8), ``theta_f`` (radians), ``dy``,
    ``contact_travel``, ``feature_changes`` (int32) and ``peak_force``.
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
    n_chunks = (total + _CHUNK - 1) // _CHUNK
    n_blocks = max(1, min(n_blocks, n_chunks))
    max_steps = max_steps_for(_table_sizes(quad)[1])
    for b in prange(n_blocks):
        work = np.empty((_W_ROWS, _W_COLS))
        traj = np.empty((1, 4))
        force = np.empty((1, 3))
        for c in range(b, n_chunks, n_blocks):
            for flat in range(c * _CHUNK, min(total, (c + 1) * _CHUNK)):
                i, j = flat // nt, flat % nt
                res = _rollout_core(verts, area, a, quad, m_max, convex, model, mu_c, r_pin,
                                    theta_i[j], d[i], v_pin, max_travel, ds_max, tol, False,
                                    max_steps, work, traj, force)
                status[i, j] = res[0]
                reason[i, j] = res[1]
                theta_f[i, j] = res[2]
                dy[i, j] = res[3]
                travel[i, j] = res[4]
                changes[i, j] = res[5]
                peak[i, j] = res[6]
    return status, reason, theta_f, dy, travel, changes, peak
