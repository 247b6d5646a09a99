"""The kernels' reference-counting contract (``kernels._numba``).

``jit`` and ``jit_inline`` compile without Numba's reference counting, which
is sound only for a function that borrows its arrays: it must not take a
new reference from a function that allocates (``jit_alloc``,
``jit_parallel``: the array would never be freed), nor hand one back to a
counting caller (the caller would free an array it does not own). Numba
itself refuses an allocation without reference counting; these two rules
are checked here on the source, so a new kernel that breaks them fails.
"""
from __future__ import annotations

import ast
from pathlib import Path

KERNELS = Path(__file__).resolve().parents[2] / "kernels"
BORROWING = {"jit", "jit_inline"}
COUNTING = {"jit_alloc", "jit_parallel"}


def _kernels():
    """``{name: (file, decorator, FunctionDef)}`` of every compiled kernel function."""
    out = {}
    for path in sorted(KERNELS.glob("*.py")):
        for node in ast.parse(path.read_text()).body:
            if isinstance(node, ast.FunctionDef):
                decorators = {ast.unparse(d) for d in node.decorator_list} & (BORROWING | COUNTING)
                if decorators:
                    out[node.name] = (path.name, decorators.pop(), node)
    return out


def _called(fn: ast.FunctionDef) -> set:
    return {ast.unparse(n.func).split(".")[-1] for n in ast.walk(fn) if isinstance(n, ast.Call)}


def _returned_arrays(fn: ast.FunctionDef) -> list:
    """Returned values that may be arrays: a parameter indexed in the body, a
    slice, or what a method gives (``x.reshape(...)``, ``x.copy()``; the
    functions of ``math`` and ``np`` excepted: Numba refuses an ``np`` array
    made without reference counting)."""
    params = {a.arg for a in fn.args.args}
    indexed = {n.value.id for n in ast.walk(fn) if isinstance(n, ast.Subscript) and isinstance(n.value, ast.Name)}
    out = []
    for node in ast.walk(fn):
        if isinstance(node, ast.Return) and node.value is not None:
            values = node.value.elts if isinstance(node.value, ast.Tuple) else [node.value]
            for v in values:
                if isinstance(v, ast.Name) and v.id in params & indexed:
                    out.append(v.id)
                if isinstance(v, ast.Subscript) and isinstance(v.slice, ast.Slice):
                    out.append(ast.unparse(v))
                if (isinstance(v, ast.Call) and isinstance(v.func, ast.Attribute)
                        and ast.unparse(v.func.value) not in ("math", "np")):
                    out.append(ast.unparse(v))
    return out


def test_the_contract_covers_the_rollout_stages():
    kernels = _kernels()
    # The stages a rollout runs at every step borrow their arrays.
    for name in ("_rollout_core", "_derivative", "_step", "_events", "_locate", "_cached_gap", "_power",
                 "_table_support", "_contact_twist", "_belt_wrench"):
        assert kernels[name][1] in BORROWING, name
    # Those that allocate count references.
    for name in ("_rollout", "_drive", "_outputs", "_dyn_rollout", "_table_from"):
        assert kernels[name][1] in COUNTING, name


def test_no_borrowing_kernel_calls_a_counting_one():
    kernels = _kernels()
    counting = {n for n, (_, dec, _) in kernels.items() if dec in COUNTING}
    wrong = {f"{file}:{name} calls {sorted(_called(fn) & counting)}"
             for name, (file, dec, fn) in kernels.items() if dec in BORROWING and _called(fn) & counting}
    assert not wrong


def test_no_borrowing_kernel_returns_an_array():
    kernels = _kernels()
    wrong = {f"{file}:{name} returns {_returned_arrays(fn)}"
             for name, (file, dec, fn) in kernels.items() if dec in BORROWING and _returned_arrays(fn)}
    assert not wrong
    # The check sees such returns: the counting kernels that hand back views.
    assert _returned_arrays(kernels["_dyn_rollout"][2]) and _returned_arrays(kernels["_as_grid"][2])
