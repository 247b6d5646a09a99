"""Every command starts fast: what each path through ``pinfeed`` imports.

Building the parser (``--help``, ``--version``, the manual's command
reference) imports nothing heavy; ``pinfeed rollout`` imports the physics it
needs but not the planner; a bad environment setting is one line before
anything heavy is imported. Each check runs a fresh interpreter and asserts
on its ``sys.modules`` (the modules, never the time: timings are on the
performance page).
"""
from __future__ import annotations

import ast
import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
CLI = ROOT / "pipeline" / "cli"

# What no parser building may import (each with its submodules).
HEAVY = ("numpy", "numba", "scipy", "xarray", "matplotlib", "pandas", "kernels", "pipeline.planning",
         "pipeline.maps", "pipeline.workflow", "pipeline.present")
ENVIRONMENT = ("SOURCE_DATE_EPOCH", "PINFEED_PROGRESS_SECONDS")  # the settings pinfeed reads
ROLLOUT = ["rollout", "--vertices", "0,0 60,0 15,35", "--mu-c", "0.2", "--pin-radius", "3",
           "--theta-i", "30", "--d", "0.3"]

# Runs ``main(ARGV)`` and prints, as the last line of stdout, the heavy
# modules it left in sys.modules; the exit status is main's.
PROBE = """
import json, sys
from pipeline.cli import main
try:
    code = main(json.loads(sys.argv[1]))
except SystemExit as exc:
    code = exc.code
heavy = json.loads(sys.argv[2])
print(json.dumps(sorted(m for m in sys.modules if any(m == h or m.startswith(h + ".") for h in heavy))))
sys.exit(code)
"""


def probe(argv, env=None, heavy=HEAVY):
    """``(exit status, stdout without the last line, stderr, heavy modules imported)``
    of ``pinfeed argv`` in a fresh interpreter."""
    env = {**{k: v for k, v in os.environ.items() if k not in ENVIRONMENT}, "PYTHONPATH": str(ROOT),
           **(env or {})}
    run = subprocess.run([sys.executable, "-c", PROBE, json.dumps(argv), json.dumps(list(heavy))],
                         env=env, capture_output=True, text=True, timeout=300, cwd=ROOT)
    *out, last = run.stdout.splitlines() or [""]
    return run.returncode, "\n".join(out), run.stderr, json.loads(last)


def test_the_parser_imports_nothing_heavy():
    code = ("import json, sys, argparse\n"
            "from pipeline.cli import build_parser\n"
            "def walk(p):\n"
            "    p.format_help()\n"
            "    for a in p._actions:\n"
            "        if isinstance(a, argparse._SubParsersAction):\n"
            "            for s in a.choices.values(): walk(s)\n"
            "walk(build_parser())\n"
            "print(json.dumps(sorted(sys.modules)))\n")
    run = subprocess.run([sys.executable, "-c", code], env={**os.environ, "PYTHONPATH": str(ROOT)},
                         capture_output=True, text=True, timeout=120, cwd=ROOT)
    assert run.returncode == 0, run.stderr
    loaded = json.loads(run.stdout)
    assert "pipeline.cli" in loaded
    assert not [m for m in loaded if any(m == h or m.startswith(h + ".") for h in HEAVY)]


@pytest.mark.parametrize("argv", [["--version"], ["--help"], ["plan", "--help"], ["rollout"]],
                         ids=["version", "help", "plan-help", "usage-error"])
def test_version_help_and_usage_errors_import_nothing_heavy(argv):
    status, out, err, heavy = probe(argv, env={"SOURCE_DATE_EPOCH": "1700000000"})
    assert heavy == []
    if argv == ["--version"]:
        assert status == 0 and out.startswith("pinfeed ")
    elif argv == ["rollout"]:
        assert status == 2 and err.startswith("pinfeed: error: the following arguments are required")
    else:
        assert status == 0 and "usage: pinfeed" in out


def test_rollout_does_not_import_the_planner():
    status, out, err, heavy = probe(ROLLOUT, heavy=("pipeline.planning", "scipy.stats", "pipeline.present"))
    assert status == 0, err
    assert "theta_i" in out and "30.00" in out
    assert heavy == []


@pytest.mark.parametrize("name, value, says", [
    ("SOURCE_DATE_EPOCH", "abc", "SOURCE_DATE_EPOCH must be a whole number of seconds since 1970"),
    ("SOURCE_DATE_EPOCH", "99999999999999999", "SOURCE_DATE_EPOCH must be a whole number of seconds since 1970"),
    ("PINFEED_PROGRESS_SECONDS", "soon", "PINFEED_PROGRESS_SECONDS must be a positive number of seconds"),
])
@pytest.mark.parametrize("argv", [ROLLOUT, ["plan", "--part", "tri"]], ids=["rollout", "plan"])
def test_a_bad_environment_is_one_line_before_any_heavy_import(name, value, says, argv):
    status, out, err, heavy = probe(argv, env={name: value})
    assert status == 2 and out == ""
    assert err.startswith(f"pinfeed: error: {says}") and err.count("\n") == 1, err
    assert f"got {value!r}; fix or unset it" in err and "Traceback" not in err
    assert heavy == []


# Modules a verb module may import at its top: the standard library, the
# other CLI modules and the light utilities. Everything else is imported by
# the function that runs the verb.
LIGHT = ("pipeline.cli", "pipeline.errors", "pipeline.progress", "pipeline.provenance")


def top_level_imports(path: Path):
    """``(line, module)`` of every import at the top level of ``path`` (not inside a function)."""
    for node in ast.parse(path.read_text()).body:
        if isinstance(node, ast.Import):
            yield from ((node.lineno, a.name) for a in node.names)
        elif isinstance(node, ast.ImportFrom):
            yield node.lineno, node.module or ""


@pytest.mark.parametrize("path", sorted(CLI.glob("*.py")), ids=lambda p: p.name)
def test_verb_modules_import_heavy_modules_lazily(path):
    bad = [f"line {line}: {module}" for line, module in top_level_imports(path)
           if module.split(".")[0] not in sys.stdlib_module_names and module != "pipeline"
           and not any(module == m or module.startswith(m + ".") for m in LIGHT)]
    assert not bad, (f"{path.name} imports at its top what a verb should import when it runs "
                     f"(so that every command starts fast): {bad}")


def test_the_lazy_import_check_would_fail(tmp_path):
    probe_file = tmp_path / "probe.py"
    probe_file.write_text("import numpy as np\nfrom pipeline.planning import format_arcs\n\n"
                          "def f():\n    import xarray\n")
    with pytest.raises(AssertionError, match=r"line 1: numpy.*line 2: pipeline.planning"):
        test_verb_modules_import_heavy_modules_lazily(probe_file)
