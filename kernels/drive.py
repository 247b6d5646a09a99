"""The one driver loop of the rollout kernels: which rollouts a worker runs,
what each one rolls out and where its results go.

Every entry point of many rollouts - the grids and the scattered points of
``batch`` and ``points``, for the quasi-static models and the dynamic one,
and the CUDA kernel of ``cuda`` - is a thin wrapper around the code here.
Rollout ``k`` is entry ``k`` of a flat list: of the points, or of the grid
``d x theta_i`` with ``d`` major (``_grid_cell``). ``_static_rollout`` and
``_dynamic_rollout`` run rollout ``k`` of the two kernel families
(``rollout._rollout_core``, ``dynamic._dyn_rollout``: the one copy of each
physics) and store its seven results at ``k`` (``_store``); ``_drive`` hands
the rollouts to CPU threads, the CUDA kernel one to each GPU thread.

Notes
-----
Load balance: the flat list is cut into chunks of ``chunk`` consecutive
rollouts, and ``n_blocks`` blocks take the chunks in turn (block ``b`` takes
chunks ``b, b + n_blocks, ...``). The long rollouts (jams, many contact
changes) come in runs of neighbouring ``theta_i``; interleaving spreads every
run over all blocks, where contiguous blocks would give whole runs to one
thread. Grids use chunks of ``batch._CHUNK`` and several blocks per thread
(``batch.blocks_for``) so that Numba's static split of ``prange`` still evens out;
a chunk's results fill whole cache lines of the float64 outputs, so threads
rarely write to the same line. Scattered points use chunks of one and one
block per thread. Each block owns its scratch arrays, and every rollout is
computed independently, so the result does not depend on the thread count.

``_drive`` takes the parameters of both families, one tuple each, and
types both branches whatever ``kind``; a wrapper passes its own family's
parameters and ``NO_STATIC`` or ``NO_DYNAMIC`` for the other.
"""
import numpy as np
from numba import prange

from ._numba import jit, jit_alloc, jit_parallel
from .dynamic import _dyn_rollout
from .rollout import _W_COLS, _W_ROWS, _rollout_core

STATIC = 0  # the quasi-static models: ``rollout._rollout_core``
DYNAMIC = 1  # the dynamic model: ``dynamic._dyn_rollout``

# Placeholders for the parameters of the family a ``_drive`` call does not run.
NO_STATIC = (0, 0.0, 0.0, 0.0, 0.0, 0.0, 0)
NO_DYNAMIC = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0)


@jit
def _grid_cell(k, nt):
    """Row ``i`` (the ``d`` index) and column ``j`` (the ``theta_i`` index) of
    entry ``k`` of the flat ``d``-major grid with ``nt`` columns."""
    i = k // nt
    return i, k - i * nt


@jit
def _inputs(k, grid, theta_i, d, mu_c):
    """``(theta_i, d, mu_c)`` of rollout ``k``: the grid's cell
    (``_grid_cell``; one ``mu_c[0]`` for all) or the ``k``-th point."""
    if grid:
        i, j = _grid_cell(k, theta_i.shape[0])
        return theta_i[j], d[i], mu_c[0]
    return theta_i[k], d[k], mu_c[k]


@jit_alloc
def _outputs(n):
    """The seven result arrays of ``n`` rollouts: ``status``, ``reason``
    (int8), ``theta_f``, ``dy``, ``contact_travel``, ``feature_changes``
    (int32) and ``peak_force``."""
    return (np.empty(n, dtype=np.int8), np.empty(n, dtype=np.int8), np.empty(n), np.empty(n),
            np.empty(n), np.empty(n, dtype=np.int32), np.empty(n))


@jit
def _store(k, res, status, reason, theta_f, dy, travel, changes, peak):
    """Store the first seven results ``res`` of a rollout at entry ``k``."""
    status[k] = res[0]
    reason[k] = res[1]
    theta_f[k] = res[2]
    dy[k] = res[3]
    travel[k] = res[4]
    changes[k] = res[5]
    peak[k] = res[6]


@jit
def _static_rollout(k, grid, verts, area, a, quad, m_max, convex, mu_c, theta_i, d, prm, work,
                    traj, force, status, reason, theta_f, dy, travel, changes, peak):
    """Quasi-static rollout ``k`` (``_inputs``), final state only, stored at ``k``.

    ``prm`` is ``(model, r_pin, v_pin, max_travel, ds_max, tol, max_steps)``
    and ``work``, ``traj``, ``force`` the scratch of ``rollout._rollout_core``
    (``traj`` and ``force`` of one row: nothing is recorded). The CPU driver
    and the CUDA kernel both run rollouts through here.
    """
    model, r_pin, v_pin, max_travel, ds_max, tol, max_steps = prm
    th, dd, mu = _inputs(k, grid, theta_i, d, mu_c)
    res = _rollout_core(verts, area, a, quad, m_max, convex, model, mu, r_pin, th, dd, v_pin,
                        max_travel, ds_max, tol, False, max_steps, work, traj, force)
    _store(k, res, status, reason, theta_f, dy, travel, changes, peak)


@jit_alloc
def _dynamic_rollout(k, grid, verts, area, a, quad, convex, mu_c, theta_i, d, prm, status,
                     reason, theta_f, dy, travel, changes, peak):
    """Dynamic rollout ``k`` (``_inputs``), final state only, stored at ``k``.

    ``prm`` is ``(r_pin, v_pin, fr, restitution, eps, h, max_travel,
    max_steps)`` (see ``dynamic._dyn_rollout``).
    """
    r_pin, v_pin, fr, restitution, eps, h, max_travel, max_steps = prm
    th, dd, mu = _inputs(k, grid, theta_i, d, mu_c)
    res = _dyn_rollout(verts, area, a, quad, convex, mu, r_pin, th, dd, v_pin, fr, restitution,
                       eps, h, max_travel, max_steps, False)
    _store(k, res, status, reason, theta_f, dy, travel, changes, peak)


@jit_parallel
def _drive(kind, grid, n, chunk, n_blocks, verts, area, a, quad, m_max, convex, mu_c, theta_i,
           d, static_prm, dynamic_prm):
    """``n`` rollouts of the family ``kind`` on threads; their results, flat.

    Parameters
    ----------
    kind : ``STATIC`` (``_static_rollout``) or ``DYNAMIC`` (``_dynamic_rollout``).
    grid : the rollouts are the grid ``d x theta_i`` (``mu_c`` of length 1;
        ``n = len(d) len(theta_i)``), else the points ``(theta_i[k], d[k],
        mu_c[k])`` (``n`` of them).
    n : number of rollouts.
    chunk, n_blocks : rollouts per chunk and number of blocks (module notes).
    verts, area, a, quad, m_max, convex : the part (``rollout._prepare``).
    mu_c, theta_i, d : 1-D float64 arrays (theta_i in radians).
    static_prm, dynamic_prm : the scalar parameters of each family (``prm`` of
        ``_static_rollout`` and ``_dynamic_rollout``); ``NO_STATIC`` or
        ``NO_DYNAMIC`` for the family not run.

    Returns
    -------
    The seven arrays of ``_outputs``, of length ``n``, entry ``k`` for rollout ``k``.
    """
    status, reason, theta_f, dy, travel, changes, peak = _outputs(n)
    n_chunks = (n + chunk - 1) // chunk
    n_blocks = max(1, min(n_blocks, n_chunks))
    for b in prange(n_blocks):
        work = np.empty((_W_ROWS, _W_COLS))
        traj = np.empty((1, 4))
        force = np.empty((1, 3))
        for c in range(b, n_chunks, n_blocks):
            for k in range(c * chunk, min(n, (c + 1) * chunk)):
                if kind == DYNAMIC:
                    _dynamic_rollout(k, grid, verts, area, a, quad, convex, mu_c, theta_i, d,
                                     dynamic_prm, status, reason, theta_f, dy, travel, changes,
                                     peak)
                else:
                    _static_rollout(k, grid, verts, area, a, quad, m_max, convex, mu_c, theta_i,
                                    d, static_prm, work, traj, force, status, reason, theta_f,
                                    dy, travel, changes, peak)
    return status, reason, theta_f, dy, travel, changes, peak


@jit_alloc
def _as_grid(out, nd, nt):
    """The seven flat results of ``_drive`` over a grid as ``(nd, nt)`` arrays."""
    return (out[0].reshape((nd, nt)), out[1].reshape((nd, nt)), out[2].reshape((nd, nt)),
            out[3].reshape((nd, nt)), out[4].reshape((nd, nt)), out[5].reshape((nd, nt)),
            out[6].reshape((nd, nt)))
