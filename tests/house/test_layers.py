"""The import contract of the house (issue 14): lower layers never import
higher ones, and no module uses another module's private (``_name``) names.

Every module's imports are read from its source (``ast``), including imports
inside functions, so a lazy import cannot hide an upward edge. The layers,
lowest first, are in :data:`LAYERS`; a module may import its own layer and
the ones below it. README's "Layout" section draws the same picture.
"""
from __future__ import annotations

import ast
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]

# Lowest first. A module belongs to the layer of its longest matching prefix.
LAYERS = (
    ("kernels",),  # physics only: Numba, arrays in and out
    ("pipeline", "pipeline.errors", "pipeline.logs", "pipeline.progress", "pipeline.provenance", "pipeline.rows",
     "pipeline.checks"),  # utilities every layer may use
    ("pipeline.parts",),  # Part, families, outline readers
    ("pipeline.config",),  # schema, defaults; checks part outlines, so above parts
    ("pipeline.maps",),  # simulate, sweep, shard io, catalog
    ("pipeline.planning",),  # wings core, claims, tight, paper, family, plans (test_planning_wings)
    ("pipeline.sensing",),  # profiles, sign matrices, sensor plans
    ("pipeline.present",),  # figures, animate, layout, report
    ("pipeline.workflow",),  # one function per rule, the runner
    ("pipeline.cli",),  # parse, call, print
)

# Kernels name their Numba entry points with a leading underscore (their
# callers wrap them with checked arguments). Only these wrappers may use them:
KERNEL_WRAPPERS = {
    "pipeline.parts.part": "kernels.geometry: polygon checks, normalisation, stable edges; "
                           "kernels.rollout._prepare: the arrays a rollout takes",
    "pipeline.maps.simulate": "kernels.rollout, batch, points, dynamic: the rollout kernels",
}

# Private names used across modules of the same package, each with its reason
# and the way out. Keep this empty where possible.
SAME_PACKAGE_EXCEPTIONS: dict = {}


def module_name(path: Path) -> str:
    parts = list(path.relative_to(ROOT).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts = parts[:-1]
    return ".".join(parts)


MODULES = {module_name(p): p for top in ("kernels", "pipeline") for p in sorted((ROOT / top).rglob("*.py"))}


def layer(module: str) -> int:
    best, rank = -1, None
    for k, names in enumerate(LAYERS):
        for name in names:
            if (module == name or module.startswith(name + ".")) and len(name) > best:
                best, rank = len(name), k
    if rank is None:
        raise AssertionError(f"{module} is in no layer: add it to LAYERS")
    return rank


def is_package(module: str) -> bool:
    return MODULES.get(module, Path()).name == "__init__.py"


def imports(module: str, path: Path):
    """``(lineno, imported module, name or None, bound alias)`` for every import in ``path``."""
    tree = ast.parse(path.read_text(), filename=str(path))
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            for a in node.names:
                yield node.lineno, a.name, None, a.asname or a.name.split(".")[0]
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = module.split(".") if is_package(module) else module.split(".")[:-1]
                base = base[:len(base) - node.level + 1]
                source = ".".join(base + ([node.module] if node.module else []))
            else:
                source = node.module or ""
            for a in node.names:
                sub = f"{source}.{a.name}"
                if sub in MODULES:  # from package import module
                    yield node.lineno, sub, None, a.asname or a.name
                else:
                    yield node.lineno, source, a.name, a.asname or a.name


def ours(module: str) -> bool:
    return module.split(".")[0] in ("kernels", "pipeline")


def private(name: str | None) -> bool:
    return bool(name) and name.startswith("_") and not (name.startswith("__") and name.endswith("__"))


def test_exceptions_stay_within_a_package():
    for module, name in SAME_PACKAGE_EXCEPTIONS:
        assert module.rsplit(".", 1)[0] == name.rsplit(".", 2)[0], (module, name)


def test_every_module_has_a_layer():
    for module in MODULES:
        layer(module)
    assert {"pipeline.parts.part", "pipeline.maps.catalog", "pipeline.planning.plans.plan",
            "pipeline.sensing.sensor_plan", "pipeline.present.report", "pipeline.workflow.runner"} <= set(MODULES)


@pytest.mark.parametrize("module", sorted(MODULES))
def test_no_upward_imports(module):
    here = layer(module)
    up = [f"line {line}: {target}" + (f" ({name})" if name else "")
          for line, target, name, _ in imports(module, MODULES[module])
          if ours(target) and layer(target) > here]
    assert not up, f"{module} (layer {LAYERS[here][0]}) imports a higher layer: {up}"


def private_uses(module: str, path: Path) -> list[str]:
    """Private names of another module that ``module`` imports or reads as ``mod._name``."""
    found, aliases = [], {}
    for line, target, name, alias in imports(module, path):
        if not ours(target) or target == module:
            continue
        if name is None:
            aliases[alias] = target
        elif private(name):
            if (module, f"{target}.{name}") not in SAME_PACKAGE_EXCEPTIONS:
                found.append(f"line {line}: from {target} import {name}")
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Attribute) and private(node.attr) and isinstance(node.value, ast.Name) \
                and node.value.id in aliases:
            if (module, f"{aliases[node.value.id]}.{node.attr}") not in SAME_PACKAGE_EXCEPTIONS:
                found.append(f"line {node.lineno}: {aliases[node.value.id]}.{node.attr}")
    return found


@pytest.mark.parametrize("module", sorted(m for m in MODULES if m.startswith("pipeline")))
def test_no_private_names_of_other_modules(module):
    uses = private_uses(module, MODULES[module])
    if module in KERNEL_WRAPPERS:
        uses = [u for u in uses if not u.split(": ", 1)[1].replace("from ", "").startswith("kernels")]
    assert not uses, f"{module} uses private names of other modules: {uses}"


@pytest.mark.parametrize("script", sorted((ROOT / "rules" / "scripts").glob("*.py")), ids=lambda p: p.name)
def test_rule_scripts_are_thin(script):
    # The package is installed (and Snakemake puts the workflow's folder on the
    # script's path): no sys.path edits; only the workflow layer's public names.
    text = script.read_text()
    assert "sys.path" not in text
    for line, target, name, _ in imports("rules.scripts." + script.stem, script):
        if ours(target):
            assert target.startswith("pipeline.workflow.") or target == "pipeline.logs", (line, target)
            assert not private(name), (line, target, name)
