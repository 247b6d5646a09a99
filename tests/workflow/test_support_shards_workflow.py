"""Shards with a support through Snakemake (issue 25, ``sweep.supports``): a
uniform-only catalog built by the workflow, then ``tripod`` added to the
config: only the new shard and the index run, the uniform shard keeps its
bytes, and the tripod shard the workflow wrote is queried back equal to
``compute_map(..., support="tripod")`` on the same grid. Tiny grid: two
shards, about 25 s."""
from __future__ import annotations

import hashlib

import numpy as np
import pytest
import yaml

from workflow_runs import run_snakemake

from pipeline.config import config_hash, validate_config
from pipeline.maps import simulate
from pipeline.maps.catalog import Catalog
from pipeline.parts.part import Part

VERTS = [[0, 0], [60, 0], [15, 35]]
TRI = Part.from_vertices(VERTS, name="tri")
BASE = {
    "catalog_dir": "cat", "results_dir": "res",
    "families": {"fam": {"parts": [{"name": "tri", "vertices": VERTS}]}},
    "sweep": {"models": ["minpower"], "mu_c": [0.2], "v_pin": [0.0], "d": [-0.4, 0.3],
              "theta_step": 45, "pin_radius": 3.0},
    "planner": {"parts": [], "mu_c": 0.2, "pins": [0.0, 10.0]},
}
UNIFORM = f"cat/fam/{TRI.id}/minpower/mu_c=0.2.h5"
TRIPOD = f"cat/fam/{TRI.id}/minpower/mu_c=0.2_support=tripod.h5"


def _config(tmp_path, name, supports=None):
    cfg = yaml.safe_load(yaml.safe_dump(BASE))
    if supports is not None:
        cfg["sweep"]["supports"] = supports
    path = tmp_path / f"{name}.yaml"
    path.write_text(yaml.safe_dump(cfg))
    return path


def _sha(path):
    return hashlib.sha256(path.read_bytes()).hexdigest()


@pytest.fixture(scope="module")
def built(tmp_path_factory):
    """The workflow run twice in one folder: uniform only, then with tripod."""
    work = tmp_path_factory.mktemp("wf")
    plain = _config(work, "plain")
    run = run_snakemake(work, "cat/index.json", "--configfile", str(plain))
    assert run.returncode == 0, run.stderr[-3000:]
    before = {"sha": _sha(work / UNIFORM), "mtime": (work / UNIFORM).stat().st_mtime_ns,
              "index": Catalog.open(work / "cat").entries}
    tripod = _config(work, "tripod", ["uniform", "tripod"])
    dry = run_snakemake(work, "cat/index.json", "--configfile", str(tripod), "--dry-run")
    assert dry.returncode == 0, dry.stderr[-3000:]
    run = run_snakemake(work, "cat/index.json", "--configfile", str(tripod))
    assert run.returncode == 0, run.stderr[-3000:]
    return work, before, dry.stdout + dry.stderr


def test_adding_a_support_runs_only_its_shard(built):
    work, before, dry = built
    outputs = [line.split(":", 1)[1].strip() for line in dry.splitlines()
               if line.strip().startswith("output:")]
    assert TRIPOD in outputs and UNIFORM not in outputs  # the uniform shard is not rerun
    assert "catalog_index" in dry
    assert _sha(work / UNIFORM) == before["sha"]
    assert (work / UNIFORM).stat().st_mtime_ns == before["mtime"]


def test_workflow_tripod_shard_equals_compute_map(built):
    work, _, _ = built
    cat = Catalog.open(work / "cat")
    assert not cat.problems and len(cat.entries) == 2
    entry = next(e for e in cat.entries if e["support_key"] == "tripod")
    assert entry["support"] == "tripod" and entry["file"] == TRIPOD.removeprefix("cat/")
    q = cat.query("tri", mu_c=0.2, support="tripod").load()
    direct = simulate.compute_map(TRI, np.arange(0, 360, 45.0), [-0.4, 0.3], 0.2, 3.0, support="tripod")
    for name in ("theta_f", "dy", "status"):
        np.testing.assert_array_equal(q[name].values[0], direct[name].values)
    for name in ("support_kind", "support_points", "support_weights"):
        np.testing.assert_array_equal(np.asarray(q.attrs[name]), np.asarray(direct.attrs[name]))
    # the uniform maps are served as before, and differ from the tripod's
    uni = cat.query("tri", mu_c=0.2).load()
    assert str(uni["support"].values) == "uniform"
    assert np.nanmax(np.abs(uni["theta_f"].values - q["theta_f"].values)) > 1.0


def test_uniform_shard_records_the_hash_of_a_config_without_the_key(built):
    """The uniform shard written before ``supports`` was set records the hash
    of the config without the key, which is that of ``supports: [uniform]``."""
    work, before, _ = built
    text = yaml.safe_load((work / "plain.yaml").read_text())
    plain = validate_config(text, name="plain")  # as the Snakefile does: the file's stem names it
    explicit = validate_config(dict(text, sweep=dict(BASE["sweep"], supports=["uniform"])), name="plain")
    entry = next(e for e in before["index"] if e["support_key"] == "")
    assert entry["config_hash"] == config_hash(plain) == config_hash(explicit)


def test_plan_reads_the_uniform_shards_only(tmp_path):
    """The planner queries uniform maps, so a part's plan job takes its uniform
    shards as input and not its support shards (adding a support re-plans nothing);
    the support shards still get their bands."""
    cfg = yaml.safe_load(yaml.safe_dump(BASE))
    cfg["sweep"]["supports"] = ["uniform", "tripod"]
    cfg["planner"]["parts"] = ["tri"]
    (tmp_path / "p.yaml").write_text(yaml.safe_dump(cfg))
    dry = run_snakemake(tmp_path, "--configfile", str(tmp_path / "p.yaml"), "--dry-run")
    assert dry.returncode == 0, dry.stderr[-3000:]
    jobs, rule = {}, None
    for line in (dry.stdout + dry.stderr).splitlines():
        if line.startswith("rule "):
            rule = line.split()[1].rstrip(":")
        elif rule and line.strip().startswith(("input:", "output:")):
            key, files = line.strip().split(":", 1)
            jobs.setdefault(rule, []).append((key, [f.strip() for f in files.split(",")]))
    plan_inputs = [files for key, files in jobs["plan"] if key == "input"][0]
    assert UNIFORM in plan_inputs and TRIPOD not in plan_inputs
    band_outputs = [f for key, files in jobs["bands"] if key == "output" for f in files]
    assert any(f.endswith("mu_c=0.2_support=tripod.json") for f in band_outputs)
