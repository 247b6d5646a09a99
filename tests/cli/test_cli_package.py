"""The command line as a package: small modules, no tracker numbers in what a
user reads, shell completion, and plans of symmetric parts printed once per set."""
from __future__ import annotations

import argparse
import ast
import json
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

from cli_runs import run_cli, small_config_file
from pipeline.cli import build_parser
from pipeline.cli.plan_text import sets_text

ROOT = Path(__file__).resolve().parents[2]
CLI = ROOT / "pipeline" / "cli"
TRACKER = re.compile(r"\bissues?\s*#?\s*\d+", re.IGNORECASE)


def _parsers(parser, prog="pinfeed"):
    """``(prog, parser)`` for the parser and every subcommand's, depth first."""
    yield prog, parser
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for name, sub in action.choices.items():
                yield from _parsers(sub, f"{prog} {name}")


def test_every_module_is_short_and_says_what_it_holds():
    for path in sorted(CLI.glob("*.py")):
        text = path.read_text()
        assert len(text.splitlines()) <= 300, path.name
        assert ast.get_docstring(ast.parse(text)), f"{path.name} has no module docstring"


def test_no_tracker_numbers_in_help_or_docstrings():
    helps = {prog: p.format_help() for prog, p in _parsers(build_parser())}
    assert {"pinfeed plan", "pinfeed catalog query", "pinfeed sense classify", "pinfeed support fit"} <= set(helps)
    found = [f"{prog}: {m.group()}" for prog, text in helps.items() for m in TRACKER.finditer(text)]
    for path in sorted(CLI.glob("*.py")):
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, (ast.Module, ast.FunctionDef, ast.ClassDef)):
                found += [f"{path.name}: {m.group()}" for m in TRACKER.finditer(ast.get_docstring(node) or "")]
    assert not found
    assert TRACKER.search("supports (issue 25)") and not TRACKER.search("the issue is 25 mm")


def _complete(line: str, tmp_path, shell="bash") -> list[str]:
    """What argcomplete answers the shell for ``line`` (the cursor at its end)."""
    pytest.importorskip("argcomplete")
    out = tmp_path / "completions.txt"
    env = dict(os.environ, _ARGCOMPLETE="1", _ARGCOMPLETE_SHELL=shell, COMP_LINE=line,
               COMP_POINT=str(len(line)), _ARGCOMPLETE_IFS="\n", _ARGCOMPLETE_STDOUT_FILENAME=str(out),
               PYTHONPATH=str(ROOT))
    run = subprocess.run([sys.executable, "-m", "pipeline.cli"], env=env, capture_output=True, text=True,
                         timeout=120)
    assert run.returncode == 0, run.stderr
    return [w.strip() for w in out.read_text().split("\n") if w.strip()]


def test_completion_offers_the_verbs_and_options(tmp_path):
    assert _complete("pinfeed ca", tmp_path) == ["catalog"]
    assert set(_complete("pinfeed ", tmp_path)) >= {"rollout", "plan", "catalog", "layout", "animate"}
    assert _complete("pinfeed plan --support-f", tmp_path) == ["--support-family"]
    assert _complete("pinfeed catalog q", tmp_path) == ["query"]


def test_completion_marker_is_where_argcomplete_looks():
    # Global completion reads the entry point's module head for the marker.
    assert "PYTHON_ARGCOMPLETE_OK" in (CLI / "__init__.py").read_text()[:1024]


@pytest.mark.parametrize("arcs, order, text", [
    ([(26.5, 4.5), (111.0, 4.5), (206.5, 4.5), (291.0, 4.5)], 2,
     "26.5-31.0 deg, 111.0-115.5 deg (x2 by symmetry)"),
    ([{"start": 200.0, "width": 10.0}, {"start": 20.0, "width": 10.0}], 2, "20.0-30.0 deg (x2 by symmetry)"),
    ([(5.0, 2.0), (125.0, 2.0), (245.0, 2.0)], 3, "5.0-7.0 deg (x3 by symmetry)"),
    ([(5.0, 2.0), (185.0, 2.0)], 1, "5.0-7.0 deg, 185.0-187.0 deg"),
    ([], 2, "none"),
])
def test_sets_text(arcs, order, text):
    assert sets_text(arcs, order) == text


def test_symmetric_part_plan_lists_one_arc_per_carried_set(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    config = small_config_file(tmp_path)
    out_file = tmp_path / "rect.json"
    code, out, err = run_cli(capsys, ["plan", "--config", str(config), "--vertices", "0,0 40,0 40,20 0,20",
                                      "--name", "rect", "--depth", "1", "--pins=5,15", "--mu-c", "0",
                                      "--dynamic-depth", "0", "--out", str(out_file)])
    assert code == 0, err
    tight = json.loads(out_file.read_text())["tight"][0]
    assert tight["symmetry_order"] == 2
    lines = [ln for ln in out.splitlines() if "beside it: carried sets" in ln]
    claims = [ln for ln in out.splitlines() if ln.strip().startswith("claim:")]
    assert len(lines) == len(claims) == len(tight["plans"]) >= 1
    for line, claim, plan in zip(lines, claims, tight["plans"]):
        # The claim names one arc in [0, 180) and says its copy is the same set.
        assert "or a copy of it every 180 deg, by symmetry" in claim
        assert plan["claim"]["arc"]["start"] % 180 == pytest.approx(
            float(re.search(r"(\d+\.\d)-\d+\.\d deg", claim).group(1)), abs=0.051)
        shown = re.findall(r"(\d+\.\d)-(\d+\.\d) deg", line.split("not the claim): ", 1)[1].split(";")[0])
        assert line.split(";")[0].endswith("(x2 by symmetry)")
        assert len(shown) == plan["n_final_sets"]  # one arc per set, not its copy 180 deg away
        stored = [(s["start"] % 360, s["width"]) for s in plan["final_sets"]]
        assert len(stored) == 2 * len(shown)  # the plan file keeps both copies
        for lo, hi in shown:
            lo = float(lo)
            for copy in (lo, (lo + 180) % 360):
                assert any(abs((copy - s + 180) % 360 - 180) <= 0.05 for s, _ in stored), (copy, stored)
