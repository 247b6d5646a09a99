"""Shared fixtures and Hypothesis settings for the pinfeed test suite.

Hypothesis profiles
-------------------
Registered here once, selected with ``HYPOTHESIS_PROFILE`` (no test sets
deadline, seeds or health checks of its own):

``ci`` (default): 100 examples, no deadline (the first call of a Numba kernel
compiles, which would trip any per-example deadline), derandomized so that a
CI run is reproducible. ``dev``: 300 examples, random seeds, for local bug
hunting. ``thorough``: 2000 examples, random seeds, for a long run before a
release.

A test whose every example runs full rollouts (seconds each) asks for a
share of the profile's count with :func:`fewer_examples` and says why; the
share keeps the same proportion in every profile.

Nothing here reads ``/work/shared``: reference data the tests need is copied
under ``tests/data``.
"""
from __future__ import annotations

import contextlib
import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, settings

_COMMON = dict(deadline=None, print_blob=True,
               suppress_health_check=[HealthCheck.too_slow, HealthCheck.filter_too_much])
settings.register_profile("ci", max_examples=100, derandomize=True, **_COMMON)
settings.register_profile("dev", max_examples=300, **_COMMON)
settings.register_profile("thorough", max_examples=2000, **_COMMON)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "ci"))


def fewer_examples(share: float) -> settings:
    """Settings for a slow property: ``share`` of the loaded profile's
    ``max_examples`` (at least 2), everything else from the profile. Use it
    only where one example costs full rollouts, and say so at the test."""
    return settings(max_examples=max(2, round(settings.default.max_examples * share)))


DATA_DIR = Path(__file__).parent / "data"

# Outlines (drawing frame, mm) used across test files.
TRIANGLE = [(0.0, 0.0), (60.0, 0.0), (15.0, 35.0)]  # the CLI's default triangle
QUAD = [(0.0, 0.0), (50.0, 0.0), (60.0, 30.0), (10.0, 25.0)]  # irregular convex quad
RECTANGLE = [(0.0, 0.0), (60.0, 0.0), (60.0, 20.0), (0.0, 20.0)]  # 60 x 20
# A 60 x 30 block with a V-notch cut into its +x face (apex 20 mm deep).
V_NOTCH = [(0.0, 0.0), (60.0, 0.0), (40.0, 15.0), (60.0, 30.0), (0.0, 30.0)]


def circular_diff(a, b):
    """Signed difference ``a - b`` of angles in degrees, wrapped to [-180, 180)."""
    return (np.asarray(a, dtype=float) - np.asarray(b, dtype=float) + 180.0) % 360.0 - 180.0


@pytest.fixture(scope="session")
def rollout_vectors():
    """Reference rollouts from the independent brute-force implementation."""
    with open(DATA_DIR / "rollouts.json") as fh:
        return json.load(fh)


def _part_fixture(vertices, name):
    @pytest.fixture(scope="session")
    def part():
        from pipeline.parts.part import Part
        return Part.from_vertices(vertices, name=name)
    return part


triangle = _part_fixture(TRIANGLE, "triangle")
quad = _part_fixture(QUAD, "quad")
rectangle = _part_fixture(RECTANGLE, "rectangle")
v_notch = _part_fixture(V_NOTCH, "v-notch")


@pytest.fixture(scope="session")
def warm_kernels(triangle):
    """Compile (or load from cache) the rollout and grid kernels once, so that
    tests timing a single rollout do not measure the JIT compilation."""
    from pipeline.maps import simulate
    simulate.rollout(triangle, 30.0, 0.3, 0.2, 3.0)
    simulate.rollout(triangle, 30.0, 0.3, 0.2, 3.0, trajectory=True)
    simulate.compute_map(triangle, [0.0], [0.3], 0.2, 3.0)
    return True


# ---------------------------------------------------------------- the manual (tests/docs)
# Kept here, not in a tests/docs/conftest.py: the test folders import helpers
# from this file by the bare name ``conftest``, which a second conftest would shadow.
_DOCS_ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="session")
def built_docs(tmp_path_factory) -> Path:
    """The HTML manual, built with warnings as errors from a copy-free run of
    Sphinx on ``docs/`` (its doctree cache in a temporary folder).

    Built once per test run: the tests that read it share one pytest-xdist
    worker (``--dist loadgroup``), and should two workers ask for it anyway,
    the second waits on a lock and reads the first one's build. Two builds at
    once would race: each starts by removing the gallery the other writes."""
    pytest.importorskip("sphinx")
    # All workers of one run share the parent of their base temp folders.
    base = tmp_path_factory.getbasetemp()
    shared = base.parent if os.environ.get("PYTEST_XDIST_WORKER") else base
    with _exclusive(shared / "docs_build.lock"):
        out, verdict = shared / "docs_html", shared / "docs_build.txt"
        if not verdict.exists():
            verdict.write_text(_build_docs(out, shared / "doctrees"))
    failure = verdict.read_text()
    assert not failure, failure
    return out


@contextlib.contextmanager
def _exclusive(lock: Path):
    """Hold an exclusive lock on ``lock`` (POSIX ``flock``; no lock where the
    platform has none)."""
    try:
        import fcntl
    except ImportError:     # pragma: no cover - Windows runs the suite in one process
        yield
        return
    with open(lock, "w") as handle:
        fcntl.flock(handle, fcntl.LOCK_EX)
        try:
            yield
        finally:
            fcntl.flock(handle, fcntl.LOCK_UN)


def _build_docs(out: Path, doctrees: Path) -> str:
    """Run Sphinx into ``out``; return "" when it succeeded, else why it failed."""
    env = {**os.environ, "PYTHONPATH": f"{_DOCS_ROOT}{os.pathsep}{os.environ.get('PYTHONPATH', '')}",
           "MPLBACKEND": "Agg"}
    run = subprocess.run([sys.executable, "-m", "sphinx", "-b", "html", "-W", "--keep-going", "-q",
                          "-d", str(doctrees), str(_DOCS_ROOT / "docs"), str(out)],
                         cwd=_DOCS_ROOT, env=env, capture_output=True, text=True, timeout=900)
    if run.returncode == 0:
        return ""
    return f"the docs build failed ({_gallery_state()}):\n{run.stdout}\n{run.stderr}"


def _gallery_state() -> str:
    """The free disk space and the gallery's images, for a failed build's message."""
    free = shutil.disk_usage(_DOCS_ROOT).free / 2**30
    images = sorted((_DOCS_ROOT / "docs" / "gallery").rglob("*.png"))
    sizes = ", ".join(f"{p.name} {p.stat().st_size} B" for p in images[:40])
    return f"{free:.1f} GiB free; gallery images: {sizes or 'none'}"


@pytest.hookimpl(tryfirst=True)
def pytest_collection_modifyitems(config, items):
    """Under pytest-xdist (``make test`` runs two workers, ``--dist loadgroup``),
    keep the tests that share a costly fixture on one worker, so it is made
    once: the tests that read the built manual form one group, and the tests
    of a module that use one of its module-scoped fixtures (a small workflow
    run, a design search) another. The other tests spread over the workers.

    ``tryfirst``: pytest-xdist reads the group marks in its own hook of this
    name, so they must be set before it runs. (pytest 9.2 broke the grouping
    again, so the test extra keeps pytest below it; ``test_manual_built_once``
    checks the grouping.)"""
    for item in items:
        group = _costly_fixture_group(item)
        if group:
            item.add_marker(pytest.mark.xdist_group(group))


def _costly_fixture_group(item) -> str | None:
    """The xdist group of ``item``: ``built_docs``, ``module:<path>`` when it
    uses a module-scoped fixture, else None."""
    names = getattr(item, "fixturenames", ())
    if "built_docs" in names:
        return "built_docs"
    defined = getattr(getattr(item, "_fixtureinfo", None), "name2fixturedefs", {})
    if any(defs and defs[-1].scope == "module" for name, defs in defined.items() if name in names):
        return "module:" + item.nodeid.split("::")[0]
    return None
