"""One place for Numba defaults used by every kernel.

``cache=True`` keeps compiled code between runs, ``nogil=True`` lets dask or
threads run kernels side by side, ``fastmath=False`` keeps IEEE semantics so
the same inputs give the same bits (the catalog's reproducibility promise).

Numba's cache checks only the source file of the function it compiled, not
the files of the kernels it calls, so an edit to ``support.py`` would leave a
stale ``models`` in the cache. The cache therefore lives in a folder named
after a hash of every kernel source file: any kernel edit starts a new cache.
"""
import hashlib
import os
from pathlib import Path

from numba import config, njit


def _kernel_sources_hash() -> str:
    h = hashlib.sha256()
    for path in sorted(Path(__file__).parent.glob("*.py")):
        h.update(path.name.encode())
        h.update(path.read_bytes())
    return h.hexdigest()[:16]


_base = os.environ.get("NUMBA_CACHE_DIR") or str(Path(__file__).parent / "__pycache__")
config.CACHE_DIR = os.path.join(_base, f"pinfeed-kernels-{_kernel_sources_hash()}")

JIT_OPTIONS = dict(cache=True, nogil=True, fastmath=False, error_model="numpy")
PARALLEL_OPTIONS = dict(JIT_OPTIONS, parallel=True)


def jit(fn):
    """Compile ``fn`` with the project's serial defaults."""
    return njit(**JIT_OPTIONS)(fn)


def jit_inline(fn):
    """``jit`` plus ``inline="always"``: Numba inlines ``fn`` into its callers
    (in its own IR, before LLVM), for a stage of a kernel that is called once
    per step from one place and takes many arrays: a call that LLVM does not
    inline passes every array's fields one by one."""
    return njit(inline="always", **JIT_OPTIONS)(fn)


def jit_parallel(fn):
    """Compile ``fn`` with the project's defaults plus ``parallel=True``."""
    return njit(**PARALLEL_OPTIONS)(fn)
