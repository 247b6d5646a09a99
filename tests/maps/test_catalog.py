"""The map database: sweep, shards, index, queries, workflow (issue: map database)."""
import hashlib
import json
from pathlib import Path

import h5py
import numpy as np
import pytest
import yaml

from images import assert_png_figure
from pipeline.config import load_config, validate_config
from pipeline.errors import PinfeedError
from pipeline.maps import simulate
from pipeline.maps.catalog import Catalog
from pipeline.maps.sweep import run_sweep, shard_jobs, write_shard
from pipeline.parts.part import Part
from workflow_runs import run_snakemake as _snakemake

ROOT = Path(__file__).resolve().parents[2]

TINY = {
    "families": {"fam": {"parts": [{"name": "tri", "vertices": [[0, 0], [60, 0], [15, 35]]}],
                         "generators": [{"kind": "regular_ngon", "n": [4], "radius": 20}]}},
    "sweep": {"models": ["minpower", "ellipsoid"], "mu_c": [0.0, 0.2], "d": [-0.4, 0.3],
              "theta_step": 45, "pin_radius": 3.0},
}


@pytest.fixture
def tiny(tmp_path):
    cfg = validate_config(dict(TINY, catalog_dir=str(tmp_path / "catalog")))
    return cfg


@pytest.fixture
def swept(tiny):
    run_sweep(tiny, progress=False)
    return tiny


def _sha(path):
    return hashlib.sha256(Path(path).read_bytes()).hexdigest()


def test_catalog_answer_equals_direct_kernel_call(swept):
    cat = Catalog.open(swept["catalog_dir"])
    assert not cat.problems
    assert len(cat.entries) == 2 * 2 * 2  # parts x models x mu_c
    q = cat.query("tri", model="minpower", mu_c=0.2, d=0.3).load()
    part = Part.from_vertices(TINY["families"]["fam"]["parts"][0]["vertices"], name="tri")
    direct = simulate.compute_map(part, np.arange(0, 360, 45.0), [0.3], 0.2, 3.0, model="minpower")
    np.testing.assert_array_equal(q["theta_f"].values[0], direct["theta_f"].values)
    np.testing.assert_array_equal(q["dy"].values[0], direct["dy"].values)
    np.testing.assert_array_equal(q["status"].values[0], direct["status"].values)
    assert q.attrs["selection"] == "mu_c 0.2 -> stored exactly; d 0.3 -> stored exactly"


def test_nearest_and_bracketing_selection_is_reported(swept):
    cat = Catalog.open(swept["catalog_dir"])
    q = cat.query("tri", mu_c=0.17, d=0.25)
    assert q["mu_c"].values.tolist() == [0.2] and q["d"].values.tolist() == [0.3]
    assert "nearest stored 0.2" in q.attrs["selection"] and "nearest stored 0.3" in q.attrs["selection"]
    q = cat.query("tri", mu_c=0.05, d=0.0, method="bracket")
    assert q["mu_c"].values.tolist() == [0.0, 0.2] and q["d"].values.tolist() == [-0.4, 0.3]
    assert "bracketed by 0 and 0.2" in q.attrs["selection"]
    q = cat.query("tri", mu_c=0.9, method="bracket")  # beyond the stored range: the end value
    assert q["mu_c"].values.tolist() == [0.2]


def test_a_catalog_of_given_files_sees_those_alone(swept):
    """Catalog.of_files (what a plan job reads): the given shards only, whatever
    else the folder holds and with no index; it answers as the indexed catalog
    does, and a foreign file among them is a problem, not an entry."""
    root = Path(swept["catalog_dir"])
    (root / "index.json").unlink()
    shards = sorted(str(p) for p in root.rglob("*.h5") if "/minpower/" in str(p) and "/tri-" in str(p))
    assert len(shards) == 2
    foreign = root / "foreign.h5"
    with h5py.File(foreign, "w") as f:
        f["x"] = np.arange(3)
    cat = Catalog.of_files(root, [*shards, foreign])
    assert len(cat.entries) == 2 and {e["model"] for e in cat.entries} == {"minpower"}
    assert len(cat.problems) == 1 and "foreign file" in cat.problems[0]
    with pytest.raises(PinfeedError, match="ellipsoid"):
        cat.query("tri", model="ellipsoid", mu_c=0.2)
    got = cat.query("tri", model="minpower", mu_c=0.17, d=0.3).load()
    foreign.unlink()
    full = Catalog.rebuild(root).query("tri", model="minpower", mu_c=0.17, d=0.3).load()
    assert got.attrs["selection"] == full.attrs["selection"]
    np.testing.assert_array_equal(got["theta_f"].values, full["theta_f"].values)


def test_queries_are_lazy_and_cube_has_all_dims(swept):
    cat = Catalog.open(swept["catalog_dir"])
    q = cat.query("tri")
    assert q["theta_f"].chunks is not None  # dask-backed
    cube = cat.cube("fam")
    assert cube["theta_f"].dims == ("part", "model", "mu_c", "v_pin", "d", "theta_i")
    assert cube.sizes == {"part": 2, "model": 2, "mu_c": 2, "v_pin": 1, "d": 2, "theta_i": 8}
    one = cube["theta_f"].sel(model="minpower", mu_c=0.2, d=0.3).isel(part=0).compute()
    assert np.all((one >= 0) & (one < 360))


def test_dynamic_pin_speeds_are_a_catalog_dimension(tmp_path):
    cfg = validate_config(dict(TINY, catalog_dir=str(tmp_path / "catalog"),
                               sweep=dict(TINY["sweep"], models=["ellipsoid"], mu_c=[0.2],
                                          v_pin=[0.0, -1.5])))
    run_sweep(cfg, progress=False)
    cat = Catalog.open(cfg["catalog_dir"])
    names = sorted(Path(e["file"]).name for e in cat.entries if e["part_name"] == "tri")
    assert names == ["mu_c=0.2.h5", "mu_c=0.2_v_pin=-1.5.h5"]  # static shards keep their names
    part = Part.from_vertices(TINY["families"]["fam"]["parts"][0]["vertices"], name="tri")
    moving = cat.query("tri", model="ellipsoid", mu_c=0.2, v_pin=-1.5).load()
    direct = simulate.compute_map(part, np.arange(0, 360, 45.0), [-0.4, 0.3], 0.2, 3.0, model="ellipsoid",
                                  v_pin=-1.5)
    np.testing.assert_array_equal(moving["theta_f"].values[0], direct["theta_f"].values)
    static = cat.query("tri", model="ellipsoid", mu_c=0.2).load()
    assert not np.array_equal(static["theta_f"].values, moving["theta_f"].values)
    with pytest.raises(PinfeedError, match="no ellipsoid maps at v_pin/v_b = 2; stored speeds: -1.5, 0"):
        cat.query("tri", model="ellipsoid", v_pin=2.0)
    cube = cat.cube("fam")
    assert cube.sizes["v_pin"] == 2 and cube["v_pin"].values.tolist() == [-1.5, 0.0]
    assert [r["v_pin"] for r in cat.parts()] == [[-1.5, 0.0]] * 2


def test_catalog_from_before_dynamic_pins_stays_readable(swept):
    """Shards written before v_pin existed have no v_pin attribute: they are static maps."""
    root = Path(swept["catalog_dir"])
    for path in root.rglob("*.h5"):
        with h5py.File(path, "r+") as f:
            del f.attrs["v_pin"]
    cat = Catalog.rebuild(root)
    assert not cat.problems and all(e["v_pin"] == 0.0 for e in cat.entries)
    q = cat.query("tri", model="minpower", mu_c=0.2, d=0.3).load()
    assert q.sizes["theta_i"] == 8 and "v_pin" not in q.attrs["selection"]
    # An index written before v_pin existed (entries without the key) opens and serves.
    index = root / "index.json"
    data = json.loads(index.read_text())
    for e in data["entries"]:
        e.pop("v_pin")
    index.write_text(json.dumps(data))
    cat = Catalog.open(root)
    assert not cat.problems and cat.query("tri", model="minpower", mu_c=0.2, v_pin=0.0).sizes["d"] == 2
    assert [r["v_pin"] for r in cat.parts()] == [[0.0]] * 2


def test_unknown_part_and_model_are_clear_errors(swept):
    cat = Catalog.open(swept["catalog_dir"])
    with pytest.raises(PinfeedError, match="unknown part 'nope'; known parts: ngon4_r20, tri"):
        cat.query("nope")
    with pytest.raises(PinfeedError, match="no tip maps"):
        cat.query("tri", model="tip")
    with pytest.raises(PinfeedError, match="unknown family"):
        cat.cube("nope")


def test_shards_describe_themselves(swept):
    job = shard_jobs(swept)[0]
    with h5py.File(job.path(swept["catalog_dir"]), "r") as f:
        attrs = dict(f.attrs)
        theta_f = f["theta_f"]
        assert theta_f.chunks == (1, 8)  # one map per chunk
        assert theta_f.compression == "gzip"
        assert f["theta_f"].attrs["units"] == b"degree" or f["theta_f"].attrs["units"] == "degree"
    for key in ("pinfeed_version", "git_commit", "config_hash", "created", "part_id", "model",
                "mu_c", "pin_radius", "theta_step", "kernel_tol", "catalog_schema_version"):
        assert key in attrs, key


def test_rerun_does_no_work(swept):
    before = {p: p.stat().st_mtime_ns for p in Path(swept["catalog_dir"]).rglob("*.h5")}
    assert run_sweep(swept, progress=False) == []
    after = {p: p.stat().st_mtime_ns for p in Path(swept["catalog_dir"]).rglob("*.h5")}
    assert before == after


def test_same_config_same_bits(tiny, tmp_path, monkeypatch):
    monkeypatch.setenv("SOURCE_DATE_EPOCH", "1700000000")
    job = shard_jobs(tiny)[1]
    a = write_shard(tiny, job, out=tmp_path / "a.h5", threads=1)
    b = write_shard(tiny, job, out=tmp_path / "b.h5", threads=2)
    assert _sha(a) == _sha(b)


def test_killed_write_leaves_no_broken_entry(tiny, monkeypatch):
    import xarray as xr
    job = shard_jobs(tiny)[0]
    real = xr.Dataset.to_netcdf

    def dies_half_way(self, path, *args, **kwargs):
        real(self, path, *args, **kwargs)
        Path(path).write_bytes(Path(path).read_bytes()[:1000])  # a torn file...
        raise KeyboardInterrupt  # ...and the run is killed

    monkeypatch.setattr(xr.Dataset, "to_netcdf", dies_half_way)
    with pytest.raises(KeyboardInterrupt):
        write_shard(tiny, job)
    monkeypatch.undo()
    root = Path(tiny["catalog_dir"])
    assert not job.path(root).exists()
    assert not list(root.rglob("*.tmp"))  # the temporary was cleaned up
    # A kill -9 would leave the temporary behind: the index ignores it and the next run resumes.
    job.path(root).parent.mkdir(parents=True, exist_ok=True)
    (job.path(root).parent / ".mu_c=0.0.h5.abc.tmp").write_bytes(b"junk")
    written = run_sweep(tiny, progress=False)
    assert job.path(root) in written
    cat = Catalog.open(root)
    assert not cat.problems and len(cat.entries) == 8


def test_gone_changed_and_foreign_files_are_reported_not_served(swept):
    root = Path(swept["catalog_dir"])
    jobs = shard_jobs(swept)
    gone, changed = jobs[0].path(root), jobs[1].path(root)
    gone.unlink()
    with open(changed, "ab") as fh:
        fh.write(b"tampered")
    cat = Catalog.open(root)
    assert len(cat.entries) == 6
    assert any("gone from disk" in p and str(gone) in p for p in cat.problems)
    assert any("changed since it was indexed" in p and str(changed) in p for p in cat.problems)
    # A same-size edit is caught by the checksum when the entry is served.
    e = next(e for e in cat.entries if root / e["file"] == jobs[2].path(root))
    data = bytearray(jobs[2].path(root).read_bytes())
    data[-1] ^= 0xFF
    jobs[2].path(root).write_bytes(bytes(data))
    with pytest.raises(PinfeedError, match="changed since it was indexed"):
        cat._open_entry(e)
    # Foreign and corrupt files are named by the re-index, which drops the gone entry.
    with h5py.File(root / "foreign.h5", "w") as f:
        f["x"] = np.arange(3)
    (root / "corrupt.h5").write_bytes(b"not hdf5 at all")
    cat = Catalog.rebuild(root)
    assert any("foreign.h5: foreign file" in p for p in cat.problems)
    assert any("corrupt.h5: cannot read" in p for p in cat.problems)
    assert not any(e["file"] == gone.relative_to(root).as_posix() for e in cat.entries)


def test_missing_or_corrupt_index_is_a_clear_error(tmp_path):
    with pytest.raises(PinfeedError, match="no catalog index"):
        Catalog.open(tmp_path)
    (tmp_path / "index.json").write_text("{broken")
    with pytest.raises(PinfeedError, match="is corrupt; rebuild it"):
        Catalog.open(tmp_path)


@pytest.mark.parametrize("mutate, message", [
    (lambda c: c.update(colour="red"), "Additional properties are not allowed"),
    (lambda c: c["sweep"].update(mu_c=[-0.1]), "sweep/mu_c/0"),
    (lambda c: c["sweep"].update(theta_step=7), "360 is not a multiple"),
    (lambda c: c["families"]["fam"]["parts"].append(
        {"name": "bow", "vertices": [[0, 0], [10, 10], [10, 0], [0, 10]]}), "part bow: edges"),
    (lambda c: c["sweep"].update(models=["magic"]), "sweep/models/0"),
])
def test_bad_config_fails_with_clear_message(mutate, message):
    cfg = json.loads(json.dumps(TINY))
    mutate(cfg)
    with pytest.raises(PinfeedError, match=message):
        validate_config(cfg)


def test_default_configs_are_valid():
    cfg = load_config()
    assert set(cfg["sweep"]["models"]) == {"minpower", "tip"} and len(cfg["sweep"]["d"]) == 18
    names = [j.part.name for j in shard_jobs(cfg)]
    assert {"asym_triangle", "sym_triangle"} <= set(names)
    big = load_config(ROOT / "config" / "workstation.yaml")
    assert len(shard_jobs(big)) > len(shard_jobs(cfg))


def test_dask_distributed_sweep_matches_local(tiny, tmp_path):
    distributed = pytest.importorskip("distributed")
    remote = dict(tiny, catalog_dir=str(tmp_path / "remote"))
    with distributed.LocalCluster(n_workers=1, threads_per_worker=2, processes=False,
                                  dashboard_address=None) as cluster:
        written = run_sweep(remote, scheduler=cluster.scheduler_address, threads=1, progress=False)
    assert len(written) == 8
    run_sweep(tiny, progress=False, threads=1)
    a, b = Catalog.open(remote["catalog_dir"]), Catalog.open(tiny["catalog_dir"])
    for model in ("minpower", "ellipsoid"):
        qa = a.query("tri", model=model).load()
        qb = b.query("tri", model=model).load()
        np.testing.assert_array_equal(qa["theta_f"].values, qb["theta_f"].values)


def test_workflow_end_to_end_and_rerun_is_a_no_op(tmp_path):
    cfg = dict(json.loads(json.dumps(TINY)), catalog_dir="cat")
    cfg["families"]["fam"].pop("generators")
    cfg["sweep"]["models"] = ["ellipsoid"]
    (tmp_path / "tiny.yaml").write_text(yaml.safe_dump(cfg))
    run = _snakemake(tmp_path, "--configfile", str(tmp_path / "tiny.yaml"))
    assert run.returncode == 0, run.stderr[-3000:]
    cat = Catalog.open(tmp_path / "cat")
    assert len(cat.entries) == 2 and not cat.problems
    assert (tmp_path / "logs" / "catalog" / "index.log").is_file()
    again = _snakemake(tmp_path, "--configfile", str(tmp_path / "tiny.yaml"), "--dry-run")
    assert again.returncode == 0
    assert "Nothing to be done" in again.stdout + again.stderr


def test_workflow_rejects_bad_config_before_any_job(tmp_path):
    cfg = json.loads(json.dumps(TINY))
    cfg["sweep"]["mu_c"] = [-0.5]
    (tmp_path / "bad.yaml").write_text(yaml.safe_dump(cfg))
    run = _snakemake(tmp_path, "--configfile", str(tmp_path / "bad.yaml"))
    assert run.returncode != 0
    assert "config error at sweep/mu_c/0" in run.stdout + run.stderr
    assert not (tmp_path / "catalog").exists() and not (tmp_path / "logs").exists()


def test_cli_catalog_commands(swept, capsys):
    from pipeline.cli import main
    root = swept["catalog_dir"]
    assert main(["catalog", "list", "--catalog", root, "--json"]) == 0
    rows = json.loads(capsys.readouterr().out)
    assert {r["part_name"] for r in rows} == {"tri", "ngon4_r20"}
    assert main(["catalog", "query", "--catalog", root, "--part", "tri", "--mu-c", "0.19",
                 "--d", "0.3", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["selection"].startswith("mu_c 0.19 -> nearest stored 0.2")
    assert len(out["rows"]) == 8
    assert main(["catalog", "show", "tri", "--catalog", root]) == 0
    assert "config" in capsys.readouterr().out
    assert main(["catalog", "query", "--catalog", root, "--part", "nope"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("pinfeed: error: unknown part 'nope'")
    png = Path(root).parent / "m.png"
    assert main(["catalog", "plot", "--catalog", root, "--part", "tri", "--mu-c", "0.2",
                 "--out", str(png)]) == 0
    assert_png_figure(png, min_width=500)


def test_a_part_with_holes_is_stored_and_read_back_with_them(tmp_path):
    """A config part with holes: its shards record the holes, the index lists
    them, the part rebuilt from the catalog is the same part (same id, area),
    and its maps are the holed part's, not the solid outline's."""
    from pipeline.maps.catalog import entry_part
    outline = [[0, 0], [80, 0], [80, 40], [0, 40]]
    holes = [[[45, 6], [75, 6], [75, 34], [45, 34]]]
    fams = {"fam": {"parts": [{"name": "plate", "vertices": outline, "holes": holes}]}}
    cfg = validate_config(dict(TINY, catalog_dir=str(tmp_path / "catalog"), families=fams,
                               sweep=dict(TINY["sweep"], models=["minpower"], mu_c=[0.2])))
    run_sweep(cfg, progress=False)
    cat = Catalog.open(cfg["catalog_dir"])
    entry = cat.entries_for("plate")[0]
    part = Part.from_vertices(outline, name="plate", holes=holes)
    assert entry["part_id"] == part.id and len(entry["part_holes"]) == 1
    back = entry_part(entry)
    assert back.id == part.id and back.area == pytest.approx(80 * 40 - 30 * 28)
    stored = cat.query("plate", model="minpower", mu_c=0.2).load()
    direct = simulate.compute_map(part, np.arange(0, 360, 45.0), [-0.4, 0.3], 0.2, 3.0, model="minpower")
    np.testing.assert_array_equal(stored["theta_f"].values[0], direct["theta_f"].values)
    solid = simulate.compute_map(Part.from_vertices(outline, name="plate"), np.arange(0, 360, 45.0),
                                 [-0.4, 0.3], 0.2, 3.0, model="minpower")
    assert not np.allclose(stored["theta_f"].values[0], solid["theta_f"].values, atol=1.0)
