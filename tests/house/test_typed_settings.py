"""Typed settings all the way down in the planner: no settings parameter is a dict.

The planner's settings are read from a config once, in the package
``pipeline/planning/core/settings/`` (:data:`READER`: ``PlannerSettings``
and the typed parts beside it, every module of it), and travel as those
objects. So no function
of ``pipeline/planning`` takes a parameter whose name says it carries
settings (:data:`SETTINGS_NAMES`, or a name ending in one of
:data:`SETTINGS_SUFFIXES`) annotated as a dict (``dict``, ``dict | None``,
``Mapping``, ``dict[str, float]``, ``Optional[dict]`` ...), and no parameter
is named ``cfg`` or ``config`` (:data:`LOOSE_NAMES`: a loose dict by its
name, whatever its annotation). The reader itself takes the config's dicts,
so it is not checked. The fields of a class (a dataclass's settings) are
held to the same rule as parameters.

Parameters in files that other work is changing at the same time are listed
in :data:`NOT_YET_SWITCHED`; the merge that switches them empties it. An entry
that no longer applies fails the test, so the list cannot go stale.
"""
from __future__ import annotations

import ast
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
PLANNING = ROOT / "pipeline" / "planning"
READER = "pipeline/planning/core/settings/"  # the one package where config dicts become typed settings

SETTINGS_NAMES = frozenset({"settings", "cfg", "config", "verify", "claims", "search", "planner", "options",
                            "params"})
SETTINGS_SUFFIXES = ("_settings", "_cfg", "_config")
# A class's ``params`` field holds data, not settings (a worst member's support parameters).
FIELD_NAMES_NOT_SETTINGS = frozenset({"params"})
LOOSE_NAMES = frozenset({"cfg", "config"})
DICT_NAMES = frozenset({"dict", "Dict", "Mapping", "MutableMapping"})

# ``path:function:parameter`` -> why it is still a dict. Files another branch
# edits in parallel (plans/plan.py, tight/complete.py, family/*, core/types.py)
# switch to the typed settings when that work is merged; then this empties.
NOT_YET_SWITCHED: dict[str, str] = {}


def is_dict_annotation(node) -> bool:
    """Whether an annotation (an ``ast`` expression, or its text) names a dict
    type anywhere: ``dict``, ``Mapping``, ``dict[...]``, ``X | dict``,
    ``Optional[dict]``, ``typing.Mapping`` ..."""
    if node is None:
        return False
    if isinstance(node, ast.Constant) and isinstance(node.value, str):
        try:
            return is_dict_annotation(ast.parse(node.value, mode="eval").body)
        except SyntaxError:
            return False
    if isinstance(node, ast.Name):
        return node.id in DICT_NAMES
    if isinstance(node, ast.Attribute):
        return node.attr in DICT_NAMES
    if isinstance(node, ast.Subscript):
        return is_dict_annotation(node.value) or is_dict_annotation(node.slice)
    if isinstance(node, ast.BinOp) and isinstance(node.op, ast.BitOr):
        return is_dict_annotation(node.left) or is_dict_annotation(node.right)
    if isinstance(node, ast.Tuple):
        return any(is_dict_annotation(e) for e in node.elts)
    return False


def carries_settings(name: str) -> bool:
    """Whether a parameter's name says it carries settings."""
    return name in SETTINGS_NAMES or name.endswith(SETTINGS_SUFFIXES)


def dict_settings_parameters(source: str, where: str = "") -> dict[str, str]:
    """``where:qualname:parameter`` (``where:Class:field`` for a class's
    fields) -> what is wrong, for every settings parameter or field
    annotated as a dict and every parameter named ``cfg`` or ``config`` in
    ``source``."""
    out = {}

    def visit(node, prefix):
        for child in ast.iter_child_nodes(node):
            if isinstance(child, ast.ClassDef):
                for item in child.body:
                    if (isinstance(item, ast.AnnAssign) and isinstance(item.target, ast.Name)
                            and item.target.id not in FIELD_NAMES_NOT_SETTINGS
                            and carries_settings(item.target.id) and is_dict_annotation(item.annotation)):
                        out[f"{where}:{prefix}{child.name}:{item.target.id}"] = \
                            f"a settings field annotated {ast.unparse(item.annotation)}"
                visit(child, f"{prefix}{child.name}.")
            elif isinstance(child, (ast.FunctionDef, ast.AsyncFunctionDef)):
                args = child.args
                for arg in [*args.posonlyargs, *args.args, *args.kwonlyargs,
                            *(a for a in (args.vararg, args.kwarg) if a is not None)]:
                    key = f"{where}:{prefix}{child.name}:{arg.arg}"
                    if arg.arg in LOOSE_NAMES:
                        out[key] = f"a parameter named {arg.arg!r} (a loose dict by its name)"
                    elif carries_settings(arg.arg) and is_dict_annotation(arg.annotation):
                        out[key] = f"settings annotated {ast.unparse(arg.annotation)}"
                visit(child, f"{prefix}{child.name}.")

    visit(ast.parse(source), "")
    return out


def planning_offenders() -> dict[str, str]:
    """Every offending parameter in ``pipeline/planning`` outside :data:`READER`."""
    out = {}
    for path in sorted(PLANNING.rglob("*.py")):
        where = path.relative_to(ROOT).as_posix()
        if not where.startswith(READER):
            out.update(dict_settings_parameters(path.read_text(), where))
    return out


def test_the_check_sees_what_it_checks():
    src = '''
def a(settings: dict): pass
def b(verify: dict | None = None): pass
def c(search_settings: "Mapping[str, float]"): pass
def d(claims: typing.Optional[dict]): pass
def e(cfg): pass
def f(x, *, config=None): pass
class K:
    verify: dict
    params: dict
    kernel: dict = None
    def m(self, planner: Dict): pass
def fine(settings: "VerifySettings | None" = None, kernel: dict | None = None, layout: dict = None): pass
'''
    found = dict_settings_parameters(src, "f.py")
    assert sorted(found) == ["f.py:K.m:planner", "f.py:K:verify", "f.py:a:settings", "f.py:b:verify",
                             "f.py:c:search_settings", "f.py:d:claims", "f.py:e:cfg", "f.py:f:config"]


def test_the_reader_is_the_settings_package():
    reader = ROOT / READER
    assert (reader / "__init__.py").is_file(), f"{READER} is not a package"
    modules = sorted(p.name for p in reader.glob("*.py") if p.name != "__init__.py")
    assert modules, f"{READER} has no modules"
    # what the reader skips is the package alone: the planner's other modules are all checked
    skipped = [p for p in PLANNING.rglob("*.py") if p.relative_to(ROOT).as_posix().startswith(READER)]
    assert sorted(p.name for p in skipped if p.name != "__init__.py") == modules
    assert all(p.parent == reader for p in skipped)


def test_no_settings_parameter_in_the_planner_is_a_dict():
    found = planning_offenders()
    new = {k: v for k, v in found.items() if k not in NOT_YET_SWITCHED}
    assert not new, ("settings parameters taken as dicts (take the typed settings of "
                     f"{READER} instead): {new}")


def test_the_list_of_parameters_not_yet_switched_is_current():
    found = planning_offenders()
    stale = sorted(k for k in NOT_YET_SWITCHED if k not in found)
    assert not stale, f"these no longer take a dict: remove them from NOT_YET_SWITCHED: {stale}"
