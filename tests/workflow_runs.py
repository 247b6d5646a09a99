"""Run the project's Snakemake workflow in a temporary folder (shared by the
catalog, report and dynamic-pin tests)."""
import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
VENV_BIN = Path(sys.executable).parent


def run_snakemake(workdir, *extra):
    """Run ``snakemake`` on the project's Snakefile in ``workdir`` (2 cores)
    with the extra arguments; return the finished process (output captured)."""
    env = dict(os.environ, PATH=f"{VENV_BIN}{os.pathsep}{os.environ.get('PATH', '')}")
    return subprocess.run([str(VENV_BIN / "snakemake"), "-s", str(ROOT / "Snakefile"),
                           "--cores", "2", "--directory", str(workdir), *extra],
                          capture_output=True, text=True, env=env, timeout=600)
