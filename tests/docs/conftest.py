"""One build of the manual per test session, shared by the docs tests."""
from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="session")
def built_docs(tmp_path_factory) -> Path:
    """The HTML manual, built with warnings as errors from a copy-free run of
    Sphinx on ``docs/`` (its doctree cache in a temporary folder)."""
    pytest.importorskip("sphinx")
    out = tmp_path_factory.mktemp("docs_html")
    doctrees = tmp_path_factory.mktemp("doctrees")
    env = {**os.environ, "PYTHONPATH": f"{ROOT}{os.pathsep}{os.environ.get('PYTHONPATH', '')}",
           "MPLBACKEND": "Agg"}
    run = subprocess.run([sys.executable, "-m", "sphinx", "-b", "html", "-W", "--keep-going", "-q",
                          "-d", str(doctrees), str(ROOT / "docs"), str(out)],
                         cwd=ROOT, env=env, capture_output=True, text=True, timeout=600)
    assert run.returncode == 0, f"the docs build failed:\n{run.stdout}\n{run.stderr}"
    return out
