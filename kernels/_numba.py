"""One place for Numba defaults used by every kernel.

``cache=True`` keeps compiled code between runs, ``nogil=True`` lets dask or
threads run kernels side by side, ``fastmath=False`` keeps IEEE semantics so
the same inputs give the same bits (the catalog's reproducibility promise).
"""
from numba import njit

JIT_OPTIONS = dict(cache=True, nogil=True, fastmath=False, error_model="numpy")
PARALLEL_OPTIONS = dict(JIT_OPTIONS, parallel=True)


def jit(fn):
    """Compile ``fn`` with the project's serial defaults."""
    return njit(**JIT_OPTIONS)(fn)


def jit_parallel(fn):
    """Compile ``fn`` with the project's defaults plus ``parallel=True``."""
    return njit(**PARALLEL_OPTIONS)(fn)
