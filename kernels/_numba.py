"""One place for Numba defaults used by every kernel.

``cache=True`` keeps compiled code between runs, ``nogil=True`` lets dask or
threads run kernels side by side, ``fastmath=False`` keeps IEEE semantics so
the same inputs give the same bits (the catalog's reproducibility promise).

Numba's cache checks only the source file of the function it compiled, not
the files of the kernels it calls, so an edit to ``support.py`` would leave a
stale ``models`` in the cache. The cache therefore lives in a folder named
after a hash of every kernel source file: any kernel edit starts a new cache.

Reference counting. Numba counts references to every array a compiled
function touches, with atomic increments and decrements: at a call, at a
view, at every exit. A rollout's stages only ever borrow arrays from their
caller, so the counts change nothing, yet they took a sixth of a CAD part's
rollout time (measured with ``perf``), and on two threads the counts of the
shared part arrays bounce between the cores. ``jit`` and ``jit_inline``
therefore compile without them (Numba's ``_nrt=False``); a function that
allocates an array or returns one uses ``jit_alloc`` (or ``jit_parallel``).
Numba refuses to compile an allocation without reference counting; the
rest of the contract (a ``jit`` function neither calls a ``jit_alloc`` one
nor returns an array) is checked by ``tests/house/test_kernel_refcounts.py``.
The arithmetic is the same either way: the results are the same, bit for bit.
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
NO_REFCOUNT_OPTIONS = dict(JIT_OPTIONS, _nrt=False)  # see the module's docstring


def jit(fn):
    """Compile ``fn`` with the project's serial defaults, without reference
    counting: ``fn`` only borrows arrays (see the module's docstring)."""
    return njit(**NO_REFCOUNT_OPTIONS)(fn)


def jit_alloc(fn):
    """Compile ``fn`` with the project's serial defaults and reference
    counting, for a function that allocates an array or returns one."""
    return njit(**JIT_OPTIONS)(fn)


def jit_inline(fn):
    """``jit`` (no reference counting) plus ``inline="always"``: Numba
    inlines ``fn`` into its callers (in its own IR, before LLVM), for a stage
    of a kernel that is called once per step from one place and takes many
    arrays: a call that LLVM does not inline passes every array's fields one
    by one."""
    return njit(inline="always", **NO_REFCOUNT_OPTIONS)(fn)


def jit_parallel(fn):
    """Compile ``fn`` with the project's defaults plus ``parallel=True``."""
    return njit(**PARALLEL_OPTIONS)(fn)
