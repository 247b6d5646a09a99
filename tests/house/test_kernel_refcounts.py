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
    """``{(file, name): (decorator, FunctionDef)}`` of every compiled kernel
    function (two modules may use one name)."""
    out = {}
    for path in sorted(KERNELS.glob("*.py")):
        for node in ast.parse(path.read_text()).body:
            if isinstance(node, ast.FunctionDef):
                decorators = {ast.unparse(d) for d in node.decorator_list} & (BORROWING | COUNTING)
                if decorators:
                    out[(path.name, node.name)] = (decorators.pop(), node)
    return out


def _decorator(kernels, name: str) -> str:
    """The decorator of the one kernel called ``name``."""
    found = [dec for (_, n), (dec, _) in kernels.items() if n == name]
    assert len(found) == 1, name
    return found[0]


def _called(fn: ast.FunctionDef) -> set:
    return {ast.unparse(n.func).split(".")[-1] for n in ast.walk(fn) if isinstance(n, ast.Call)}


def _may_be_view(v, arrays: set, two_d: set) -> bool:
    """Whether expression ``v`` may be an array taken from one of ``arrays``
    (names): the name itself, a slice of it, a row of one of ``two_d``
    (indexed by a pair elsewhere), its ``.T``, or what a method gives
    (``x.reshape(...)``; ``math`` and ``np`` excepted: Numba refuses an
    ``np`` array made without reference counting)."""
    if isinstance(v, ast.Name):
        return v.id in arrays
    if isinstance(v, ast.Subscript):
        if isinstance(v.slice, ast.Slice):
            return True
        return not isinstance(v.slice, ast.Tuple) and isinstance(v.value, ast.Name) and v.value.id in two_d
    if isinstance(v, ast.Attribute):
        return v.attr == "T"
    if isinstance(v, ast.Call) and isinstance(v.func, ast.Attribute):
        return ast.unparse(v.func.value) not in ("math", "np")
    return False


def _returned_arrays(fn: ast.FunctionDef) -> list:
    """Returned values that may be arrays (``_may_be_view``) of the
    parameters indexed in the body or of local names bound to views of them
    (``y = work[_W_Y]``, ``y`` then indexed), by a syntactic check: the
    compiled return types are not at hand when the kernels come from
    Numba's cache."""
    subscripts = [n for n in ast.walk(fn) if isinstance(n, ast.Subscript) and isinstance(n.value, ast.Name)]
    indexed = {n.value.id for n in subscripts}
    two_d = {n.value.id for n in subscripts if isinstance(n.slice, ast.Tuple)}
    arrays = {a.arg for a in fn.args.args} & indexed
    for node in ast.walk(fn):  # local views, in the order of the source
        if isinstance(node, ast.Assign) and len(node.targets) == 1 and isinstance(node.targets[0], ast.Name):
            name, v = node.targets[0].id, node.value
            row = (isinstance(v, ast.Subscript) and not isinstance(v.slice, ast.Tuple)
                   and isinstance(v.value, ast.Name) and v.value.id in arrays and name in indexed)
            if row or (_may_be_view(v, arrays, two_d) and not isinstance(v, ast.Name)):
                arrays.add(name)
    out = []
    for node in ast.walk(fn):
        if isinstance(node, ast.Return) and node.value is not None:
            values = node.value.elts if isinstance(node.value, ast.Tuple) else [node.value]
            out += [ast.unparse(v) for v in values if _may_be_view(v, arrays, two_d)]
    return out


def test_the_contract_covers_the_rollout_stages():
    kernels = _kernels()
    # The stages a rollout runs at every step borrow their arrays.
    for name in ("_rollout_core", "_derivative", "_step", "_events", "_locate", "_cached_gap", "_power",
                 "_table_support", "_contact_twist", "_belt_wrench"):
        assert _decorator(kernels, name) in BORROWING, name
    # Those that allocate count references.
    for name in ("_rollout", "_drive", "_outputs", "_dyn_rollout", "_table_from"):
        assert _decorator(kernels, name) in COUNTING, name
    # Both modules' functions of one name are checked.
    assert ("geometry.py", "_near_edges") in kernels and ("support_table.py", "_near_edges") in kernels


def test_no_borrowing_kernel_calls_a_counting_one():
    kernels = _kernels()
    counting = {n for (_, n), (dec, _) in kernels.items() if dec in COUNTING}
    wrong = {f"{file}:{name} calls {sorted(_called(fn) & counting)}"
             for (file, name), (dec, fn) in kernels.items() if dec in BORROWING and _called(fn) & counting}
    assert not wrong


def test_no_borrowing_kernel_returns_an_array():
    kernels = _kernels()
    wrong = {f"{file}:{name} returns {_returned_arrays(fn)}"
             for (file, name), (dec, fn) in kernels.items() if dec in BORROWING and _returned_arrays(fn)}
    assert not wrong


def test_the_return_check_sees_views():
    # The counting kernels that hand back views, and the returns a borrowing
    # stage must never have: a row of its scratch array, directly or by a
    # local name, a slice, a transpose.
    kernels = _kernels()
    assert _returned_arrays(kernels[("dynamic.py", "_dyn_rollout")][1])
    assert _returned_arrays(kernels[("drive.py", "_as_grid")][1])
    bad = ast.parse("def f(work, k, x, v):\n    y = work[k]\n    y[0] = 1.0\n    z = x[1:3]\n    if k:\n"
                    "        return 1.0, y\n    if z[0] > 0:\n        return z\n    if v[0, 1] > 0:\n"
                    "        return v[k]\n    return x.T\n").body[0]
    assert sorted(_returned_arrays(bad)) == ["v[k]", "x.T", "y", "z"]
    fine = ast.parse("def f(verts, j, g):\n    px, py = verts[j, 0], verts[j, 1]\n    m = g[j]\n"
                     "    return px + py, verts[j, 0], m, g[0]\n").body[0]
    assert _returned_arrays(fine) == []
