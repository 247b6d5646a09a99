"""Parallel grids of rollouts: one part, one model, many (theta_i, d).

The grid's rollouts (``d`` major) run through ``drive._drive``, in chunks of
``_CHUNK`` consecutive rollouts that ``n_blocks`` blocks take in turn (see
``drive`` for the load balance; use several blocks per thread,
``blocks_for``): ``_rollout_grid`` for the quasi-static models,
``_dyn_rollout_grid`` for the dynamic one. Every rollout is independent, so
the result does not depend on the thread count.
"""
import numpy as np

from ._numba import jit, jit_alloc
from .drive import DYNAMIC, NO_DYNAMIC, NO_STATIC, STATIC, _as_grid, _drive
from .rollout import max_steps_for
from .support import _table_sizes

_CHUNK = 8  # rollouts per chunk: 64 bytes of each float64 output
BLOCKS_PER_THREAD = 8


def blocks_for(threads, total):
    """Number of blocks for ``threads`` threads and ``total`` rollouts."""
    return max(1, min(int(threads) * BLOCKS_PER_THREAD, -(-int(total) // _CHUNK)))


@jit_alloc
def _rollout_grid(verts, area, a, quad, m_max, convex, model, mu_c, r_pin, theta_i, d, v_pin,
                  max_travel, ds_max, tol, n_blocks):
    """Rollouts over the outer product ``d x theta_i`` (radians for theta_i).

    ``n_blocks`` is the number of interleaved blocks the grid is cut into
    (see ``blocks_for``). Returns arrays of shape ``(len(d), len(theta_i))``:
    ``status``, ``jam_reason`` (int8), ``theta_f`` (radians), ``dy``,
    ``contact_travel``, ``feature_changes`` (int32) and ``peak_force``.
    """
    nd, nt = d.shape[0], theta_i.shape[0]
    prm = (model, r_pin, v_pin, max_travel, ds_max, tol, max_steps_for(_table_sizes(quad)[1]))
    out = _drive(STATIC, True, nd * nt, _CHUNK, n_blocks, verts, area, a, quad, m_max, convex,
                 np.full(1, mu_c), theta_i, d, prm, NO_DYNAMIC)
    return _as_grid(out, nd, nt)


@jit_alloc
def _dyn_rollout_grid(verts, area, a, quad, convex, mu_c, r_pin, theta_i, d, v_pin, fr,
                      restitution, eps, h, max_travel, max_steps, n_blocks):
    """Dynamic rollouts (``dynamic._dyn_rollout``) over the outer product
    ``d x theta_i`` (radians).

    ``n_blocks`` as for ``_rollout_grid``; the other arguments as for
    ``dynamic._dyn_rollout``. Returns ``status``, ``reason`` (int8;
    ``dynamic.DYN_REASONS``), ``theta_f``, ``dy``, ``contact_travel``,
    ``feature_changes`` (int32), ``peak_force``, each of shape
    ``(len(d), len(theta_i))``.
    """
    nd, nt = d.shape[0], theta_i.shape[0]
    prm = (r_pin, v_pin, fr, restitution, eps, h, max_travel, max_steps)
    out = _drive(DYNAMIC, True, nd * nt, _CHUNK, n_blocks, verts, area, a, quad, 0.0, convex,
                 np.full(1, mu_c), theta_i, d, NO_STATIC, prm)
    return _as_grid(out, nd, nt)
