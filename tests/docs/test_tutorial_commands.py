"""Every shell command in the tutorials (a ``$ `` line in a console block) runs
and prints the lines shown under it.

How a page's output lines are read:

- a line that is only ``...`` stands for lines left out; ``...`` inside a
  line stands for any text (a path that differs from machine to machine);
- lines a block highlights (``{code-block} console`` with ``:emphasize-lines:``)
  are what the full ``make run`` prints and depend on its grid and trials:
  they are shown, not checked;
- every other line must appear in what the command prints (stdout and stderr,
  runs of spaces squeezed).

Where the commands run: ``own-part`` in an empty folder holding the
tutorial's drawings; ``paper-feeder`` in an empty folder holding a small
config (``tests/data/paper_feeder_small.yaml``: the default config's parts
and planner settings on a 4 x 36 grid of one model, friction and pin speed,
with few trials), because ``make run`` on the default config takes many
minutes. Its ``make run`` is replaced by what ``make run`` runs,
``python -m pipeline.workflow run --cores all --rerun-incomplete``, with
that config and 2 cores; the page's other commands then run as written. The
lines they print that do not depend on the grid (the catalog's part ids and
vertices, the rollouts a query returns, the atlas's header and columns, the
files made) must equal those of the full run that the page shows.

Stored outputs: the own-part page shows a drawing and figures of plans of
parts that are not in the default config, whose planning takes too long to
repeat in every docs build. So it shows files its own commands write, kept
beside the page (:data:`STORED`): the holed bracket's feeder drawing (a PNG
that records its plan in the ``pinfeed-plan`` text field) and the wedge's
layout file (from which the docs build draws the plan's pin sequence, the
feeder drawing and a frame of the animation, ``docs/_ext/tutorial_figures.py``).
After the page's commands ran, each kept copy must show what the commands
wrote: the same plan, which the commands print, and for the layout file the
same stations, pitch, belt speed and drawn poses.
"""
from __future__ import annotations

import json
import math
import os
import re
import shlex
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
from workflow_runs import VENV_BIN

ROOT = Path(__file__).resolve().parents[2]
TUTORIALS = ROOT / "docs" / "tutorials"
SMALL_CONFIG = ROOT / "tests" / "data" / "paper_feeder_small.yaml"
BLOCK = re.compile(r"^```(?:console|\{code-block\} console)\n((?::[\w-]+:[^\n]*\n)*)\n?(.*?)^```", re.S | re.M)
FENCE = re.compile(r"^```([^\n]*)\n(.*?)^```", re.S | re.M)
MAKE_RUN = [sys.executable, "-m", "pipeline.workflow", "run", "--cores", "2", "--rerun-incomplete",
            "--snakefile", str(ROOT / "Snakefile"), "--configfile", "config.yaml"]


#: Files a page shows that its own commands write, kept beside the page: page ->
#: {kept copy in docs/tutorials/: the file the commands write, relative to their folder}.
STORED = {"own-part": {"holed_bracket_feeder.png": "feeder_holed_bracket.png",
                       "layout_wedge.json": "results/config/layout_wedge.json"}}
#: Layout keys that say when and by which build a file was made, not what it holds.
PROVENANCE = {"created", "git_commit", "pinfeed_version"}


def line_numbers(spec: str) -> set[int]:
    """The lines ``:emphasize-lines:`` names: ``3,5-7`` -> {3, 5, 6, 7}."""
    out = set()
    for part in filter(None, (p.strip() for p in spec.split(","))):
        lo, _, hi = part.partition("-")
        out.update(range(int(lo), int(hi or lo) + 1))
    return out


def console_steps(markdown: str) -> list[tuple[str, list[str]]]:
    """(command, output lines to check) for every ``$ `` line of every console block."""
    steps = []
    for options, body in BLOCK.findall(markdown):
        shown_only = line_numbers(dict(re.findall(r"^:([\w-]+):\s*(.*)$", options, re.M))
                                  .get("emphasize-lines", ""))
        for number, line in enumerate(body.splitlines(), start=1):
            if line.startswith("$ "):
                assert number not in shown_only, f"a command is highlighted: {line}"
                steps.append((line[2:], []))
            elif line.strip() and line.strip() != "..." and number not in shown_only:
                steps[-1][1].append(line)
    return steps


def squeeze(text: str) -> str:
    return " ".join(text.split())


def printed(expected: str, output: str) -> bool:
    """Whether ``expected`` (``...`` for any text) appears in the squeezed ``output``."""
    pattern = ".*?".join(re.escape(part) for part in squeeze(expected).split("..."))
    return re.search(pattern, output) is not None


def test_console_steps_are_read_as_written():
    text = ("x\n```console\n$ pinfeed a --b 1\nout 1\n...\n\n$ pinfeed c\n```\n```text\n$ not me\n```\n"
            "```{code-block} console\n:emphasize-lines: 3,5-6\n\n$ ls x\nkept\nfrom the full run\nkept too\n"
            "full 1\nfull 2\n```\n")
    assert console_steps(text) == [("pinfeed a --b 1", ["out 1"]), ("pinfeed c", []),
                                   ("ls x", ["kept", "kept too"])]


def test_output_lines_match_with_ellipses():
    out = squeeze("report: /home/me/pinfeed/results/config/report.html\n  mu_c   0.15")
    assert printed("report: .../results/config/report.html", out)
    assert printed("mu_c 0.15", out)
    assert not printed("report: .../results/other/report.html", out)
    assert not printed("mu_c 0.3", out)


PAGES = sorted(TUTORIALS.glob("*.md"))


@pytest.mark.parametrize("page", PAGES, ids=lambda p: p.stem)
def test_every_shell_command_of_a_tutorial_is_in_a_console_block(page):
    """No command hides in a block the tests do not run."""
    for info, body in FENCE.findall(page.read_text()):
        if "console" in info:
            continue
        commands = [line for line in body.splitlines()
                    if re.match(r"\s*(\$ |pinfeed |make |open |snakemake |python )", line)]
        assert commands == [], f"{page.name}: commands outside a console block: {commands}"


def test_the_tutorials_have_commands():
    for name, least in (("own-part", 8), ("paper-feeder", 7)):
        assert len(console_steps((TUTORIALS / f"{name}.md").read_text())) >= least, name


def test_make_run_stand_in_runs_what_make_run_runs():
    """The paper-feeder test runs the workflow command of the Makefile's
    ``run`` target, only with the small config, 2 cores and the Snakefile
    named; the target compiles the kernels first (silent when cached)."""
    warm, recipe = re.search(r"^run:.*\n\t(.*)\n\t(.*)$", (ROOT / "Makefile").read_text(), re.M).groups()
    assert warm == "@$(BIN)/python -m pipeline.maps.warm"
    assert recipe.split("$(BIN)/python ", 1)[1].split() == [
        "-m", "pipeline.workflow", "run", "--cores", "all", "--rerun-incomplete"]
    assert MAKE_RUN[1:7] == ["-m", "pipeline.workflow", "run", "--cores", "2", "--rerun-incomplete"]


def shown(path: Path):
    """What a kept output shows: a drawing's plan (its PNG's ``pinfeed-plan``
    field), or a layout file without its provenance."""
    if path.suffix == ".png":
        from PIL import Image
        with Image.open(path) as image:
            image.load()
            return {"plan": image.text.get("pinfeed-plan")}
    return {k: v for k, v in json.loads(path.read_text()).items() if k not in PROVENANCE}


def differences(kept, fresh, where="") -> list[str]:
    """Where ``kept`` and ``fresh`` (JSON values) differ; numbers within 0.05."""
    if isinstance(kept, dict) and isinstance(fresh, dict):
        return [d for k in sorted(set(kept) | set(fresh), key=str)
                for d in differences(kept.get(k), fresh.get(k), f"{where}.{k}")]
    if isinstance(kept, list) and isinstance(fresh, list) and len(kept) == len(fresh):
        return [d for k, (a, b) in enumerate(zip(kept, fresh)) for d in differences(a, b, f"{where}[{k}]")]
    numbers = (int, float)
    if (isinstance(kept, numbers) and isinstance(fresh, numbers) and not isinstance(kept, bool)
            and math.isclose(kept, fresh, rel_tol=0.0, abs_tol=0.05)):
        return []
    return [] if kept == fresh else [f"{where or 'value'}: kept {kept!r}, written now {fresh!r}"]


def test_differences_of_kept_outputs():
    assert differences({"a": [1.0, {"b": "P1 P2"}]}, {"a": [1.04, {"b": "P1 P2"}]}) == []
    assert differences({"a": [1.0]}, {"a": [1.2]}) == [".a[0]: kept 1.0, written now 1.2"]
    assert differences({"plan": "P1"}, {"plan": "P2", "x": 1}) == [
        ".plan: kept 'P1', written now 'P2'", ".x: kept None, written now 1"]


def check_kept_outputs(page: Path, folder: Path, printed_text: str) -> None:
    """Each output the page keeps shows what its commands wrote in ``folder``
    (see the module docstring); ``printed_text``: all they printed, squeezed."""
    for kept, written in STORED.get(page.stem, {}).items():
        fresh = shown(folder / written)
        plan = fresh["plan"] if isinstance(fresh["plan"], str) else " ".join(fresh["plan"]["pins"])
        assert plan and f"plan 1: {plan} (" in printed_text, (written, plan)
        assert differences(shown(TUTORIALS / kept), fresh) == [], (
            f"docs/tutorials/{kept} no longer shows what the {page.stem} tutorial's commands write: "
            f"copy their {written} there")


def setup_folder(page: Path, folder: Path) -> None:
    """What a page's commands start from (see the module docstring)."""
    if page.stem == "paper-feeder":
        shutil.copy(SMALL_CONFIG, folder / "config.yaml")
    else:
        for data in TUTORIALS.glob("*.dxf"):
            shutil.copy(data, folder)


def command_line(command: str) -> list[str]:
    """The process a page's command runs as (only pinfeed, ls and make run are run)."""
    argv = shlex.split(command)
    if argv[0] == "pinfeed":
        return [sys.executable, "-c", "from pipeline.cli import main; main()", *argv[1:]]
    if argv == ["make", "run"]:
        return MAKE_RUN
    assert argv[0] == "ls", f"only pinfeed, ls and make run are run from tutorials: {command}"
    return argv


@pytest.mark.parametrize("page", [p for p in PAGES if console_steps(p.read_text())], ids=lambda p: p.stem)
def test_tutorial_commands_run_and_print_what_the_page_shows(page, tmp_path):
    setup_folder(page, tmp_path)
    env = {**os.environ, "PYTHONPATH": str(ROOT), "MPLBACKEND": "Agg",
           "PATH": f"{VENV_BIN}{os.pathsep}{os.environ.get('PATH', '')}"}  # snakemake for make run
    everything = []
    for command, expected in console_steps(page.read_text()):
        run = subprocess.run(command_line(command), cwd=tmp_path, env=env, capture_output=True, text=True,
                             timeout=600)
        output = squeeze(run.stdout + run.stderr)
        everything.append(output)
        assert run.returncode == 0, f"{command}\n{run.stdout[-3000:]}\n{run.stderr[-3000:]}"
        assert [line for line in expected if not printed(line, output)] == [], f"{command}\n{output[-5000:]}"
    check_kept_outputs(page, tmp_path, " ".join(everything))
