"""The tests that read the built manual run on one pytest-xdist worker, so
``make test`` builds the manual once: two builds at once would race (each
starts by removing the gallery the other is writing). Likewise the tests of a
module that share a module-scoped fixture (a small workflow run) run on one
worker, so the fixture is made once.

Checked by running the suite's own grouping hook (tests/conftest.py) in a
small pytest session with two workers, as ``make test`` runs them."""
from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import pytest

TESTS = Path(__file__).resolve().parents[1]

CONFTEST = f'''
import importlib.util, os
import pytest
spec = importlib.util.spec_from_file_location("pinfeed_suite_conftest", {str(TESTS / "conftest.py")!r})
suite = importlib.util.module_from_spec(spec)
spec.loader.exec_module(suite)
pytest_collection_modifyitems = suite.pytest_collection_modifyitems

@pytest.fixture(scope="session")
def built_docs():
    return os.environ.get("PYTEST_XDIST_WORKER")
'''

# One module, three kinds of test: reading the manual (its own group), sharing
# the module's fixture (the module's group), and neither (spread).
TESTS_PY = '''
import time

import pytest

@pytest.fixture(scope="module")
def workflow_run():
    return 1

@pytest.mark.parametrize("i", range(12))
def test_reads_the_manual(built_docs, i):
    pass

@pytest.mark.parametrize("i", range(12))
def test_reads_the_run(workflow_run, i):
    pass

@pytest.mark.parametrize("i", range(12))
def test_other(i):
    time.sleep(0.2)  # long enough that one worker cannot take them all while the other starts its group
'''


def test_tests_sharing_a_costly_fixture_share_one_worker(tmp_path):
    pytest.importorskip("xdist")
    (tmp_path / "conftest.py").write_text(CONFTEST)
    (tmp_path / "test_grouping.py").write_text(TESTS_PY)
    run = subprocess.run([sys.executable, "-m", "pytest", "-v", "-p", "no:cacheprovider", "-n", "2",
                          "--dist", "loadgroup", "test_grouping.py"],
                         cwd=tmp_path, capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stdout[-3000:] + run.stderr[-3000:]
    workers = {}
    for worker, name in re.findall(r"\[(gw\d+)\].*?PASSED test_grouping\.py::(\w+)", run.stdout):
        workers.setdefault(name, set()).add(worker)
    assert len(workers.get("test_reads_the_manual", ())) == 1, (
        f"the tests reading the manual ran on {workers.get('test_reads_the_manual')}: "
        "pytest-xdist did not keep their group on one worker")
    assert len(workers.get("test_reads_the_run", ())) == 1, (
        f"the tests sharing a module-scoped fixture ran on {workers.get('test_reads_the_run')}")
    assert len(workers.get("test_other", ())) == 2, (
        "the ungrouped tests did not spread over the workers")
