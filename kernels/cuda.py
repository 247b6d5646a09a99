"""GPU backend: the rollout grid on an NVIDIA GPU through numba-cuda.

The CUDA kernel runs ``rollout._rollout_core`` - the same scalar code the CPU
grid runs, compiled for the GPU (numba-cuda compiles the ``@jit`` kernels it
calls as device functions); there is no second copy of the physics. One
thread computes one rollout of the grid, final state only (no trajectory).

Scratch: each thread holds a fixed-size local array of ``_W_ROWS x _W_COLS``
float64 (19 x 29, 4.3 KiB) that does not depend on the polygon; the polygon, its
quadrature rule and the grid live in global memory. There is no polygon
size limit beyond the step budget that applies on the CPU too.

A point support (kernel code ``models.MINPOWER_POINTS``) needs
nothing more: its points travel in ``quad``, and the same scalar code runs.

Install with ``pip install .[cuda]`` (numba-cuda with the CUDA 12 wheels).
Import this module only when the backend is asked for: importing it does
not need a GPU, launching the kernel does.
"""
import math

import numpy as np
from numba import config, cuda, float64

from .rollout import _W_COLS, _W_ROWS
from .rollout import _rollout_core as _core

if config.ENABLE_CUDASIM:  # pragma: no cover - exercised in a subprocess by the tests
    # Under numba's CUDA simulator the kernel body runs in Python and calls
    # the compiled CPU ``_rollout_core``, which cannot unbox the simulator's
    # device arrays: hand it the NumPy arrays they wrap.
    def _rollout_core(*args):
        return _core(*[getattr(x, "_ary", x) for x in args])
else:
    _rollout_core = _core

THREADS_PER_BLOCK = 128


def _grid_kernel(verts, area, a, quad, m_max, convex, model, mu_c, r_pin, theta_i, d, v_pin,
                 max_travel, ds_max, tol, max_steps, status, reason, theta_f, dy, travel,
                 changes, peak):
    """One rollout per thread over the flat ``d x theta_i`` grid."""
    k = cuda.grid(1)
    nt = theta_i.shape[0]
    if k >= d.shape[0] * nt:
        return
    i = k // nt
    j = k - i * nt
    work = cuda.local.array((_W_ROWS, _W_COLS), float64)
    rec = cuda.local.array((1, 4), float64)
    res = _rollout_core(verts, area, a, quad, m_max, convex, model, mu_c, r_pin, theta_i[j],
                        d[i], v_pin, max_travel, ds_max, tol, False, max_steps, work, rec, rec)
    status[i, j] = res[0]
    reason[i, j] = res[1]
    theta_f[i, j] = res[2]
    dy[i, j] = res[3]
    travel[i, j] = res[4]
    changes[i, j] = res[5]
    peak[i, j] = res[6]


_kernel = cuda.jit(_grid_kernel)

def kernel_signature():
    """The Numba signature of ``_grid_kernel`` for the arrays ``rollout_grid`` passes."""
    from numba import types
    f8, i8 = types.float64, types.int64
    return (f8[:, ::1], f8, f8, f8[:, ::1], f8, types.boolean, i8, f8, f8, f8[::1], f8[::1],
            f8, f8, f8, f8, i8, types.int8[:, ::1], types.int8[:, ::1], f8[:, ::1],
            f8[:, ::1], f8[:, ::1], types.int32[:, ::1], f8[:, ::1])


def available():
    """True if numba-cuda sees a usable GPU (or the CUDA simulator is on)."""
    try:
        return bool(cuda.is_available())
    except Exception:  # pragma: no cover - driver errors vary
        return False


def rollout_grid(verts, area, a, quad, m_max, convex, model, mu_c, r_pin, theta_i, d, v_pin,
                 max_travel, ds_max, tol, max_steps):
    """The GPU counterpart of ``batch._rollout_grid`` (same arguments and
    results, but ``max_steps`` instead of a block count)."""
    theta_i = np.ascontiguousarray(theta_i, dtype=np.float64)
    d = np.ascontiguousarray(d, dtype=np.float64)
    nd, nt = d.shape[0], theta_i.shape[0]
    out = (np.empty((nd, nt), np.int8), np.empty((nd, nt), np.int8), np.empty((nd, nt)),
           np.empty((nd, nt)), np.empty((nd, nt)), np.empty((nd, nt), np.int32),
           np.empty((nd, nt)))
    total = nd * nt
    if total == 0:
        return out
    dev_out = [cuda.to_device(x) for x in out]
    blocks = math.ceil(total / THREADS_PER_BLOCK)
    _kernel[blocks, THREADS_PER_BLOCK](
        cuda.to_device(np.ascontiguousarray(verts)), float(area), float(a),
        cuda.to_device(np.ascontiguousarray(quad)), float(m_max), bool(convex), int(model),
        float(mu_c), float(r_pin), cuda.to_device(theta_i), cuda.to_device(d), float(v_pin),
        float(max_travel), float(ds_max), float(tol), int(max_steps), *dev_out)
    return tuple(x.copy_to_host() for x in dev_out)
