"""GPU backend: the rollout grid on an NVIDIA GPU through numba-cuda.

The CUDA kernel runs ``drive._static_rollout`` - the same scalar code the CPU
driver runs for each rollout of a grid (its cell, ``rollout._rollout_core``,
where its results go), compiled for the GPU (numba-cuda compiles the ``@jit``
kernels it calls as device functions); there is no second copy of the
physics or of the driver's bookkeeping. One thread computes one rollout of
the grid, final state only (no trajectory).

Scratch: each thread holds a fixed-size local array of ``_W_ROWS x _W_COLS``
float64 (20 x 29, 4.5 KiB) that does not depend on the polygon; the polygon, its
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

from .drive import _outputs
from .drive import _static_rollout as _rollout
from .rollout import _W_COLS, _W_ROWS

if config.ENABLE_CUDASIM:  # pragma: no cover - exercised in a subprocess by the tests
    # Under numba's CUDA simulator the kernel body runs in Python and calls
    # the compiled CPU ``_static_rollout``, which cannot unbox the simulator's
    # device arrays: hand it the NumPy arrays they wrap (it writes its
    # results into them).
    def _static_rollout(*args):
        return _rollout(*[getattr(x, "_ary", x) for x in args])
else:
    _static_rollout = _rollout

THREADS_PER_BLOCK = 128


def _grid_kernel(verts, area, a, quad, m_max, convex, model, mu_c, r_pin, theta_i, d, v_pin,
                 max_travel, ds_max, tol, max_steps, status, reason, theta_f, dy, travel,
                 changes, peak):
    """One rollout per thread over the flat ``d x theta_i`` grid
    (``drive._static_rollout``, as on the CPU; ``mu_c`` an array of one)."""
    k = cuda.grid(1)
    if k >= d.shape[0] * theta_i.shape[0]:
        return
    work = cuda.local.array((_W_ROWS, _W_COLS), float64)
    rec = cuda.local.array((1, 4), float64)
    _static_rollout(k, True, verts, area, a, quad, m_max, convex, mu_c, theta_i, d,
                    (model, r_pin, v_pin, max_travel, ds_max, tol, max_steps), work, rec, rec,
                    status, reason, theta_f, dy, travel, changes, peak)


_kernel = cuda.jit(_grid_kernel)

def kernel_signature():
    """The Numba signature of ``_grid_kernel`` for the arrays ``rollout_grid`` passes."""
    from numba import types
    f8, i8 = types.float64, types.int64
    return (f8[:, ::1], f8, f8, f8[:, ::1], f8, types.boolean, i8, f8[::1], f8, f8[::1],
            f8[::1], f8, f8, f8, f8, i8, types.int8[::1], types.int8[::1], f8[::1], f8[::1],
            f8[::1], types.int32[::1], f8[::1])


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
    total = nd * nt
    out = _outputs(total)
    if total == 0:
        return tuple(x.reshape(nd, nt) for x in out)
    dev_out = [cuda.to_device(x) for x in out]
    blocks = math.ceil(total / THREADS_PER_BLOCK)
    _kernel[blocks, THREADS_PER_BLOCK](
        cuda.to_device(np.ascontiguousarray(verts)), float(area), float(a),
        cuda.to_device(np.ascontiguousarray(quad)), float(m_max), bool(convex), int(model),
        cuda.to_device(np.full(1, float(mu_c))), float(r_pin), cuda.to_device(theta_i),
        cuda.to_device(d), float(v_pin), float(max_travel), float(ds_max), float(tol),
        int(max_steps), *dev_out)
    return tuple(x.copy_to_host().reshape(nd, nt) for x in dev_out)
