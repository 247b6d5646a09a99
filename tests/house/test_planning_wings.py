"""The planner's house: wings that import downwards, and one front door.

``pipeline/planning`` is split into wings (``core``, ``claims``, ``tight``,
``paper``, ``family``, ``plans``, ``design``, ``feeder``). A wing imports only the wings listed for
it in :data:`MAY_IMPORT`, so each can be read, and changed, knowing what it
stands on. Production code outside planning (the other layers, the rules,
the benchmarks, the docs' build scripts) imports only the package itself,
and only the names in its ``__all__``. Tests, which check wings from the
inside, may import wing modules.
"""
from __future__ import annotations

import ast
from pathlib import Path

import pytest

from test_layers import MODULES, ROOT, imports

WINGS = ("core", "claims", "tight", "paper", "family", "plans", "design", "feeder")
MAY_IMPORT = {
    "core": {"core"},
    "claims": {"core", "claims"},
    "tight": {"core", "claims", "tight"},
    "paper": {"core", "paper"},
    "family": {"core", "claims", "tight", "family"},
    "plans": set(WINGS) - {"design", "feeder"},
    # beside the feeder: design for feeding plans changed outlines with the plans wing
    "design": set(WINGS) - {"feeder"},
    # the top wing: a feeder's layout stands on the plans and their speed limits
    "feeder": set(WINGS) - {"design"},
}
PLANNING = "pipeline.planning"


def wing(module: str) -> str | None:
    """The wing of a planning module (``None`` for the front door itself)."""
    rest = module[len(PLANNING) + 1:].split(".") if module.startswith(PLANNING + ".") else []
    return rest[0] if rest else None


def front_door_names() -> set[str]:
    import pipeline.planning
    return set(pipeline.planning.__all__)


def test_every_planning_module_sits_in_a_wing():
    loose = [m for m in MODULES if m.startswith(PLANNING + ".") and wing(m) not in WINGS]
    assert not loose, f"planning modules outside the wings {WINGS}: {loose}"


@pytest.mark.parametrize("module", sorted(m for m in MODULES if wing(m) in WINGS))
def test_wings_import_downwards(module):
    allowed = MAY_IMPORT[wing(module)]
    bad = [f"line {line}: {target}" for line, target, _, _ in imports(module, MODULES[module])
           if target.startswith(PLANNING) and wing(target) not in allowed]
    assert not bad, f"{module} (wing {wing(module)}) may import only {sorted(allowed)}: {bad}"


def test_front_door_names_exist_and_are_unique():
    import pipeline.planning
    names = pipeline.planning.__all__
    assert len(names) == len(set(names))
    missing = [n for n in names if not hasattr(pipeline.planning, n)]
    assert not missing, missing


def outside_sources():
    """Production Python outside planning that may use the planner."""
    files = [p for p in (ROOT / "pipeline").rglob("*.py") if PLANNING.replace(".", "/") not in p.as_posix()]
    for folder in ("rules", "benchmarks", "docs/_ext", "docs/examples"):
        files += sorted((ROOT / folder).rglob("*.py"))
    return files


@pytest.mark.parametrize("path", outside_sources(), ids=lambda p: p.relative_to(ROOT).as_posix())
def test_outside_code_uses_the_front_door(path):
    public = front_door_names()
    bad = []
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.ImportFrom) and (node.module or "").startswith(PLANNING):
            if node.module != PLANNING:
                bad.append(f"line {node.lineno}: from {node.module} import ...")
            else:
                bad += [f"line {node.lineno}: {a.name} is not in pipeline.planning.__all__"
                        for a in node.names if a.name not in public]
        elif isinstance(node, ast.Import):
            bad += [f"line {node.lineno}: import {a.name}" for a in node.names
                    if a.name.startswith(PLANNING + ".")]
    assert not bad, f"{path.name} reaches past planning's front door: {bad}"


def test_the_check_would_fail(tmp_path):
    # A file that reaches into a wing is caught (the test above is not vacuous).
    probe = tmp_path / "probe.py"
    probe.write_text("from pipeline.planning.tight.propagate import propagate\n")
    with pytest.raises(AssertionError, match="front door"):
        test_outside_code_uses_the_front_door(probe)


def config_parameters(path: Path) -> list[str]:
    """Functions of ``path`` with a parameter named ``config`` (a loose config dict)."""
    found = []
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
            args = node.args.posonlyargs + node.args.args + node.args.kwonlyargs
            if any(a.arg == "config" for a in args):
                found.append(f"line {node.lineno}: {node.name}")
    return found


@pytest.mark.parametrize("module", sorted(m for m in MODULES if wing(m) in WINGS))
def test_planning_takes_settings_not_the_config_dict(module):
    # The config dict is read once, by PlannerSettings.from_config; everything
    # else in planning takes the typed settings or their parts.
    found = config_parameters(MODULES[module])
    if module == "pipeline.planning.core.settings" or module.startswith("pipeline.planning.core.settings."):
        found = [f for f in found if not f.endswith(": from_config")]
    assert not found, f"{module} takes a config dict: {found}; take PlannerSettings or a part of it"


def test_the_config_check_would_fail(tmp_path):
    probe = tmp_path / "probe.py"
    probe.write_text("def plan(part, config):\n    return config['planner']\n")
    assert config_parameters(probe) == ["line 1: plan"]
