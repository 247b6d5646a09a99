"""Planning against a read-only catalog (issue 26): the refinement rollouts go
to the user cache folder ($PINFEED_CACHE), said in one line, and are reused
on the next run; the catalog's files stay byte-identical."""
from __future__ import annotations

import json
import os
from pathlib import Path

import pytest

from cli_runs import TRI_PLAN_ARGS, run_cli, small_config_file
from pipeline.planning.tight import store as lattice_store

ARGS = TRI_PLAN_ARGS


def _snapshot(root: Path) -> dict:
    return {p.relative_to(root).as_posix(): (p.read_bytes() if p.is_file() else None)
            for p in sorted(root.rglob("*"))}


@pytest.fixture
def computed(monkeypatch):
    """A list that collects how many lattice rollouts each batch computed (not
    the plan's own count, which also holds unstored verification replays)."""
    from pipeline.planning.tight.propagate import OutcomeLattice
    counts, ensure = [], OutcomeLattice.ensure

    def counting(self, keys):
        before = self.n_computed
        ensure(self, keys)
        counts.append(self.n_computed - before)
    monkeypatch.setattr(OutcomeLattice, "ensure", counting)
    return counts


@pytest.fixture
def read_only(tmp_path, monkeypatch):
    """A catalog the process may not write (simulated: tests may run as root,
    whom chmod does not stop), and a cache folder of its own."""
    cat = tmp_path / "shared" / "cat"
    (cat / "fam").mkdir(parents=True)
    (cat / "index.json").write_text('{"index_version": 1, "entries": []}\n')
    real_access, real_mkstemp = os.access, __import__("tempfile").mkstemp

    def access(path, mode, *a, **k):
        if Path(path).resolve().is_relative_to(cat.resolve()) and mode & os.W_OK:
            return False
        return real_access(path, mode, *a, **k)

    def mkstemp(*a, dir=None, **k):
        if dir is not None and Path(dir).resolve().is_relative_to(cat.resolve()):
            raise PermissionError(13, "Permission denied")
        return real_mkstemp(*a, dir=dir, **k)
    monkeypatch.setattr(lattice_store.os, "access", access)
    monkeypatch.setattr("tempfile.mkstemp", mkstemp)
    monkeypatch.setenv("PINFEED_CACHE", str(tmp_path / "cache"))
    monkeypatch.setattr(lattice_store, "_announced", set())
    return cat


def test_plan_twice_on_a_read_only_catalog(tmp_path, capsys, read_only, computed):
    before = _snapshot(read_only)
    common = ARGS + ["--config", str(small_config_file(tmp_path)), "--catalog", str(read_only)]
    code, _, err = run_cli(capsys, ["plan", *common, "--out", str(tmp_path / "one.json")])
    said = [line for line in err.splitlines() if "cannot be written" in line]
    assert code == 0 and len(said) == 1 and str(tmp_path / "cache") in said[0], err
    cached = list((tmp_path / "cache").rglob("*.h5"))
    assert len(cached) == 1 and "refine" in cached[0].parts
    assert sum(computed) > 0
    computed.clear()
    lattice_store._announced.clear()  # a new run says it again
    code, _, err = run_cli(capsys, ["plan", *common, "--out", str(tmp_path / "two.json")])
    assert code == 0 and "cannot be written" in err
    assert sum(computed) == 0  # every lattice rollout came from the cache
    assert json.loads((tmp_path / "two.json").read_text())["tight"][0]["plans"] == \
        json.loads((tmp_path / "one.json").read_text())["tight"][0]["plans"]
    assert _snapshot(read_only) == before  # nothing written into the catalog


def test_writable_catalog_keeps_its_refinements(tmp_path, monkeypatch):
    from pipeline.parts.part import Part
    from pipeline.planning.tight.propagate import OutcomeLattice
    monkeypatch.setenv("PINFEED_CACHE", str(tmp_path / "cache"))
    part = Part.from_vertices([[0, 0], [60, 0], [15, 35]], name="tri")
    lattice = OutcomeLattice(part, "minpower", 3.0)
    lattice.add([[1, 2, 3]], [0], [10.0], [0.5])
    path = lattice_store.save_lattice(tmp_path / "cat", lattice)
    assert path.is_relative_to(tmp_path / "cat") and not (tmp_path / "cache").exists()
    assert lattice_store.load_lattice(tmp_path / "cat", part, "minpower", 0.0, 3.0).known == lattice.known
    # Two catalogs never share a cache folder.
    assert lattice_store.cache_root(tmp_path / "a") != lattice_store.cache_root(tmp_path / "b")
