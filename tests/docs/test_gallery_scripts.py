"""Every gallery example runs on its own, in seconds, and draws a figure."""
# (the examples import their shared helpers, docs/examples/_*.py, from their own folder)
from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
EXAMPLES = sorted((ROOT / "docs" / "examples").glob("plot_*.py"))


def test_there_are_examples():
    assert len(EXAMPLES) >= 8


@pytest.mark.parametrize("script", EXAMPLES, ids=lambda p: p.stem)
def test_example_runs_and_draws(script, tmp_path):
    saver = tmp_path / "run.py"
    saver.write_text(
        "import runpy, sys, matplotlib\nmatplotlib.use('Agg')\nimport matplotlib.pyplot as plt\n"
        "plt.show = lambda *a, **k: None\n"
        f"runpy.run_path({str(script)!r}, run_name='__main__')\n"
        "figs = [plt.figure(n) for n in plt.get_fignums()]\nassert figs, 'no figure drawn'\n"
        "for k, f in enumerate(figs):\n    f.savefig(sys.argv[1] + f'/{k}.png')\n")
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(ROOT), str(script.parent)]), "MPLBACKEND": "Agg"}
    run = subprocess.run([sys.executable, str(saver), str(tmp_path)], cwd=tmp_path, env=env,
                         capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stderr[-2000:]
    pngs = list(tmp_path.glob("*.png"))
    assert pngs and all(p.stat().st_size > 5000 for p in pngs)
