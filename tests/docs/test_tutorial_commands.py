"""Every shell command in the tutorials (a ``$ `` line in a ```console block) runs,
in an empty folder holding the tutorial's files, and prints the lines shown under it."""
from __future__ import annotations

import os
import re
import shlex
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
TUTORIALS = ROOT / "docs" / "tutorials"
BLOCK = re.compile(r"^```console\n(.*?)^```", re.S | re.M)


def console_steps(markdown: str) -> list[tuple[str, list[str]]]:
    """(command, expected output lines) for every ``$ `` line of every console block."""
    steps = []
    for block in BLOCK.findall(markdown):
        for line in block.splitlines():
            if line.startswith("$ "):
                steps.append((line[2:], []))
            elif line.strip():
                steps[-1][1].append(line)
    return steps


def test_console_steps_are_read_as_written():
    text = "x\n```console\n$ pinfeed a --b 1\nout 1\n\n$ pinfeed c\n```\n```text\n$ not me\n```\n"
    assert console_steps(text) == [("pinfeed a --b 1", ["out 1"]), ("pinfeed c", [])]


def squeeze(text: str) -> str:
    return " ".join(text.split())


PAGES = sorted(TUTORIALS.glob("*.md"))


def test_the_own_part_tutorial_has_commands():
    assert len(console_steps((TUTORIALS / "own-part.md").read_text())) >= 3


@pytest.mark.parametrize("page", [p for p in PAGES if console_steps(p.read_text())], ids=lambda p: p.stem)
def test_tutorial_commands_run_and_print_what_the_page_shows(page, tmp_path):
    for data in TUTORIALS.glob("*.dxf"):
        shutil.copy(data, tmp_path)
    env = {**os.environ, "PYTHONPATH": str(ROOT), "MPLBACKEND": "Agg"}
    for command, expected in console_steps(page.read_text()):
        argv = shlex.split(command)
        assert argv[0] == "pinfeed", f"only pinfeed commands are run from tutorials: {command}"
        run = subprocess.run([sys.executable, "-c", "from pipeline.cli import main; main()", *argv[1:]],
                             cwd=tmp_path, env=env, capture_output=True, text=True, timeout=600)
        output = squeeze(run.stdout + run.stderr)
        assert run.returncode == 0, f"{command}\n{run.stdout}\n{run.stderr}"
        assert [line for line in expected if squeeze(line) not in output] == [], f"{command}\n{output}"
