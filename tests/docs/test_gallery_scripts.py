"""Every gallery example runs on its own, as a user runs it after downloading
it: copied alone into an empty folder and run with the environment's python,
the installed package its only import; it draws a figure."""
from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
EXAMPLES = sorted((ROOT / "docs" / "examples").glob("plot_*.py"))
# The pin-sequence examples honour this (documented in each): a coarser grid
# keeps each run well under a minute here; the manual builds them at 2 degrees.
FAST = {"PINFEED_EXAMPLE_THETA_STEP": "6"}


def test_there_are_examples():
    assert len(EXAMPLES) >= 8


def test_no_shared_helpers_beside_the_examples():
    """A downloaded example comes alone: nothing it needs may sit beside it."""
    assert sorted(p.name for p in (ROOT / "docs" / "examples").glob("_*.py")) == []


@pytest.mark.parametrize("script", EXAMPLES, ids=lambda p: p.stem)
def test_downloaded_example_runs_and_draws(script, tmp_path):
    folder = tmp_path / "download"
    folder.mkdir()
    (folder / script.name).write_text(script.read_text())
    saver = tmp_path / "run.py"
    saver.write_text(
        "import runpy, sys, matplotlib\nmatplotlib.use('Agg')\nimport matplotlib.pyplot as plt\n"
        "plt.show = lambda *a, **k: None\n"
        f"runpy.run_path({script.name!r}, run_name='__main__')\n"
        "figs = [plt.figure(n) for n in plt.get_fignums()]\nassert figs, 'no figure drawn'\n"
        "for k, f in enumerate(figs):\n    f.savefig(sys.argv[1] + f'/{k}.png')\n")
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    env.update(MPLBACKEND="Agg", **FAST)
    run = subprocess.run([sys.executable, str(saver), str(tmp_path)], cwd=folder, env=env,
                         capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stderr[-2000:]
    pngs = list(tmp_path.glob("*.png"))
    assert pngs and all(p.stat().st_size > 5000 for p in pngs)
