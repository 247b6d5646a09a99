"""Bad input and faults (issue 12): one test per class of the README table
"Bad input and faults: what you get". Each checks the one-line error (or the
recovery) and that nothing stored was lost."""
from __future__ import annotations

import json
import os
import random
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
import yaml

from cli_runs import run_cli
from pipeline.config import validate_config
from pipeline.errors import PinfeedError
from pipeline.maps import simulate
from pipeline.maps.catalog import Catalog
from pipeline.maps.io import read_map
from pipeline.maps.sweep import run_sweep, shard_jobs
from pipeline.parts.part import MAX_VERTICES, Part, PolygonError

ROOT = Path(__file__).resolve().parents[2]
VENV_BIN = Path(sys.executable).parent
TRI = [[0, 0], [60, 0], [15, 35]]
TINY = {
    "families": {"fam": {"parts": [{"name": "tri", "vertices": TRI}]}},
    "sweep": {"models": ["ellipsoid"], "mu_c": [0.0, 0.2], "d": [-0.4, 0.3],
              "theta_step": 45, "pin_radius": 3.0},
}
MAP = ["map", "--vertices", "0,0 60,0 15,35", "--mu-c", "0.2", "--pin-radius", "3",
       "--theta-step", "90"]


def cli(capsys, argv):
    """Run the CLI in-process: (exit code, stdout, stderr lines)."""
    code, out, err = run_cli(capsys, argv)
    return code, out, err.strip().splitlines()


def one_line_error(capsys, argv, *needles):
    code, _, err = cli(capsys, argv)
    assert code == 2 and len(err) == 1 and err[0].startswith("pinfeed: error: "), err
    for needle in needles:
        assert needle in err[0], err[0]
    return err[0]


@pytest.fixture
def swept(tmp_path):
    cfg = validate_config(dict(json.loads(json.dumps(TINY)), catalog_dir=str(tmp_path / "cat")))
    run_sweep(cfg, progress=False, threads=1)
    return cfg


# --------------------------------------------------------------------------- catalog index


@pytest.mark.parametrize("mutate, where", [
    (lambda d: d["entries"], "(top level)"),                              # a list
    (lambda d: {"entries": d["entries"]}, "index_version"),               # missing field
    (lambda d: d["entries"][0].update(mu_c="0.2") or d, "entries/0/mu_c"),  # wrong type
    (lambda d: d["entries"][0].update(file="../../etc/passwd.h5") or d, "entries/0/file"),
    (lambda d: d["entries"][0].pop("sha256") and d, "entries/0"),
])
def test_malformed_index_is_refused_with_the_rebuild_hint(swept, mutate, where):
    index = Path(swept["catalog_dir"]) / "index.json"
    index.write_text(json.dumps(mutate(json.loads(index.read_text()))))
    with pytest.raises(PinfeedError, match="pinfeed catalog index") as info:
        Catalog.open(swept["catalog_dir"])
    assert where in str(info.value) and "\n" not in str(info.value)
    # The way out works: the rebuilt index serves every shard again.
    assert len(Catalog.rebuild(swept["catalog_dir"]).entries) == 2


def test_read_only_catalog_folder_is_a_clear_error(swept, capsys, monkeypatch):
    # Simulated (tests may run as root, whom chmod does not stop).
    def denied(*a, **k):
        raise PermissionError(13, "Permission denied")
    monkeypatch.setattr("tempfile.mkstemp", denied)
    before = (Path(swept["catalog_dir"]) / "index.json").read_bytes()
    one_line_error(capsys, ["catalog", "index", "--catalog", swept["catalog_dir"]],
                   "cannot write", "Permission denied", "writable")
    assert (Path(swept["catalog_dir"]) / "index.json").read_bytes() == before
    code, out, _ = cli(capsys, ["catalog", "list", "--catalog", swept["catalog_dir"]])
    assert code == 0 and "tri-" in out  # reading needs no write access


# --------------------------------------------------------------------------- map --out


def test_map_out_must_be_a_writable_map_file(tmp_path, capsys):
    args = MAP + ["--d", "0.3"]
    one_line_error(capsys, args + ["--out", str(tmp_path)], "is a folder")
    one_line_error(capsys, args + ["--out", str(tmp_path / "m.txt")], "unsupported suffix", ".h5")
    (tmp_path / "file").write_text("x")
    one_line_error(capsys, args + ["--out", str(tmp_path / "file" / "m.h5")], "is a file, not a folder")
    one_line_error(capsys, ["plot-map", str(tmp_path / "none.h5"), "--out", str(tmp_path / "p.gif")],
                   "unsupported suffix")
    # A missing parent folder is made.
    code, _, _ = cli(capsys, args + ["--out", str(tmp_path / "new" / "sub" / "m.h5")])
    assert code == 0 and read_map(tmp_path / "new" / "sub" / "m.h5").sizes["theta_i"] == 4


# --------------------------------------------------------------------------- numbers


@pytest.mark.parametrize("d, needle", [
    (",", "is empty"),
    ("0.3,0.3", "more than once"),
    ("nan", "finite"),
    ("inf", "finite"),
    ("0:1:1e-12", "1,000,000,000,001 values, more than the limit of 100,000"),
    ("0:inf:1", "finite"),
])
def test_bad_number_lists_are_refused(tmp_path, capsys, d, needle):
    one_line_error(capsys, MAP + ["--d", d, "--out", str(tmp_path / "m.h5")], needle)
    assert not (tmp_path / "m.h5").exists()


def test_nan_and_inf_never_reach_the_kernel(capsys):
    base = ["rollout", "--vertices", "0,0 60,0 15,35", "--mu-c", "0.2", "--pin-radius", "3"]
    one_line_error(capsys, base + ["--d", "0.3", "--theta-i", "nan"], "finite")
    one_line_error(capsys, base + ["--d", "inf", "--theta-i", "0"], "finite")
    one_line_error(capsys, MAP + ["--d", "0.3", "--theta-step", "1e-9", "--out", "x.h5"],
                   "360,000,000,000 values")
    one_line_error(capsys, MAP + ["--d", "0:1:0.01", "--theta-step", "0.01", "--out", "x.h5"],
                   "the map (d x theta_i) has 3,636,000 values, more than the limit of 1,000,000")


# --------------------------------------------------------------------------- config


@pytest.mark.parametrize("mutate, needle", [
    (lambda c: c["families"].update(g={"generators": [{"kind": "rectangle", "aspect": "wide"}]}),
     "families/g/generators/0/aspect: 'wide' is not of type 'array'"),
    (lambda c: c["families"].update(g={"generators": [{"kind": "regular_ngon", "n": [4.5]}]}),
     "not of type 'integer'"),
    (lambda c: c["families"].update(g={"generators": [{"kind": "l_shape", "thickness": [5],
                                                        "widht": 3}]}), "'widht' was unexpected"),
    (lambda c: c["families"]["fam"].update(description=["x"]), "is not of type 'string'"),
    (lambda c: c["families"].update(other={"parts": [{"name": "tri", "vertices": [[0, 0], [9, 0], [0, 9]]}]}),
     "part tri is also in family fam"),
    (lambda c: c.update(catalog_dir=""), "catalog_dir: it is empty"),
    (lambda c: c["sweep"]["mu_c"].append(float("nan")), "sweep/mu_c/2: nan is not a finite number"),
    (lambda c: c["sweep"].update(kernel={"ds_max": 1e-9}), "minimum of 0.001"),
    (lambda c: c["sweep"].update(kernel={"tol": 1e-30}), "minimum of 1e-12"),
    (lambda c: c["sweep"].update(pin_radius=1e4), "more than the limit of 10"),
    (lambda c: c["sweep"].update(theta_step=1e-6), "minimum of 0.01"),
    (lambda c: c["sweep"].update(theta_step=0.01, d=[k / 100 for k in range(1, 40)]),
     "one shard (d x theta_i) has 1,404,000 values, more than the limit of 1,000,000"),
])
def test_bad_configs_are_refused(mutate, needle):
    cfg = json.loads(json.dumps(TINY))
    mutate(cfg)
    with pytest.raises(PinfeedError, match="config error") as info:
        validate_config(cfg)
    assert needle in str(info.value)


# --------------------------------------------------------------------------- kernel settings


def test_inputs_that_would_run_without_end_are_refused():
    part = Part.from_vertices(TRI)
    with pytest.raises(PinfeedError, match="more than the limit of 10"):
        simulate.rollout(part, 0, 0.3, 0.2, pin_radius=100 * part.a)
    with pytest.raises(PinfeedError, match=r"ds_max must be in \[0.001, 1\]"):
        simulate.compute_map(part, [0], [0.3], 0.2, 3.0, ds_max=1e-9)
    with pytest.raises(PinfeedError, match=r"tol must be in \[1e-12, 0.001\]"):
        simulate.rollout(part, 0, 0.3, 0.2, 3.0, tol=1e-30)
    with pytest.raises(PolygonError, match="smaller than the limit of 0.001 mm"):
        Part.from_vertices(np.array(TRI) * 1e-9)
    ang = 2 * np.pi * np.arange(MAX_VERTICES + 1) / (MAX_VERTICES + 1)
    with pytest.raises(PolygonError, match=f"{MAX_VERTICES + 1} vertices, more than the limit of {MAX_VERTICES}"):
        Part.from_vertices(np.column_stack([30 * np.cos(ang), 30 * np.sin(ang)]))
    ang = ang[:MAX_VERTICES]  # at the limit: accepted
    Part.from_vertices(np.column_stack([30 * np.cos(ang), 30 * np.sin(ang)]))


# --------------------------------------------------------------------------- parts


def test_far_away_triangle_is_valid_and_keeps_its_id():
    here = Part.from_vertices(TRI, name="t")
    far = Part.from_vertices(np.array(TRI, float) + 1e6, name="t")
    assert far.area == pytest.approx(here.area, rel=1e-12)
    assert far.id == here.id
    with pytest.raises(PolygonError, match="zero area"):  # a true sliver still fails
        Part.from_vertices([[1e6, 1e6], [1e6 + 60, 1e6], [1e6 + 30, 1e6]])


def test_part_id_is_canonical():
    ref = Part.from_vertices([[0, 0], [60, 0], [60, 20], [10, 35]], name="q")
    xy = np.array([[0, 0], [60, 0], [60, 20], [10, 35]], float)
    for k in range(4):
        assert Part.from_vertices(np.roll(xy, k, axis=0), name="q").id == ref.id  # start vertex
        assert Part.from_vertices(np.roll(xy, k, axis=0)[::-1], name="q").id == ref.id  # winding
    assert Part.from_vertices(xy + [-123.25, 4567.5], name="q").id == ref.id  # translation
    # Geometry still counts: the mirror image and a moved vertex are other parts.
    assert ref.mirrored().id.split("-")[1] != ref.id.split("-")[1]
    assert Part.from_vertices(xy + [[0, 0], [0, 0], [0, 0.01], [0, 0]], name="q").id != ref.id


# --------------------------------------------------------------------------- sensing


def test_sensing_inputs_are_bounded(tmp_path):
    from pipeline.sensing.profiles import read_profile_csv, resample
    huge = tmp_path / "huge.csv"
    huge.write_text("t,fx,fy\n0,0,0\n1e12,1,1\n")
    with pytest.raises(PinfeedError, match="more than the limit of 1,000,000"):
        resample(read_profile_csv(huge), 200.0)
    binary = tmp_path / "bin.csv"
    binary.write_bytes(bytes(range(256)) * 10)
    with pytest.raises(PinfeedError, match="not a text CSV file"):
        read_profile_csv(binary)
    nul = tmp_path / "nul.csv"
    nul.write_bytes(b"0,1,2\n\x00\x00,1,1\n")
    with pytest.raises(PinfeedError, match="not a text CSV file|not three numbers"):
        read_profile_csv(nul)


@pytest.mark.parametrize("content, where", [
    ([1, 2, 3], "(top level)"),
    ({"found": True, "part": {}}, "(top level)"),
    ({"found": True, "part": {}, "first_pin": "P1", "y_pin": "high", "sensor": {}, "mu_c": [0.1, 0.3],
      "mu_c_profiles": 0.2, "symmetry_order": 1, "model": "minpower",
      "plan": {"pins": [], "pin_heights_mm": []}, "states": {}}, "y_pin"),
    ({"found": True, "part": {}, "first_pin": "P1", "y_pin": 5.0, "sensor": {}, "mu_c": 0.1,
      "model": "minpower", "plan": {"pins": []}, "states": {}}, "(top level)"),  # before issue 11
])
def test_sensing_json_of_the_wrong_shape_is_refused(tmp_path, content, where):
    from pipeline.sensing.sensor_plan import stored_sensor_plan
    (tmp_path / "sensing").mkdir()
    (tmp_path / "sensing" / "p.json").write_text(json.dumps(content))
    with pytest.raises(PinfeedError, match="not a pinfeed sensing result") as info:
        stored_sensor_plan(tmp_path, "p")
    assert where in str(info.value) and "re-run the workflow" in str(info.value)


def test_all_zero_profile_is_undecided():
    from pipeline.sensing.profiles import Profile, Sensor, classify, sign_matrix
    sensor = Sensor()
    t = np.arange(400) / sensor.rate_hz
    zero = sign_matrix(Profile(t, np.zeros_like(t), np.zeros_like(t)), sensor)
    mostly_zero = np.zeros((4, sensor.regions), np.int8)
    mostly_zero[0, 0] = 1  # the state whose matrix has most zeros would win
    refs = {"state 1": mostly_zero, "state 2": np.ones((4, sensor.regions), np.int8)}
    v = classify(zero, refs, sensor.margin)
    assert not v["decided"] and v["candidates"] == ["state 1", "state 2"]
    assert classify(mostly_zero, refs, sensor.margin)["decided"]  # a real profile still decides
    # If some states miss the pin (all-zero references), the candidates are those,
    # still undecided: a dead sensor reads the same.
    refs["state 3"] = np.zeros((4, sensor.regions), np.int8)
    v = classify(zero, refs, sensor.margin)
    assert not v["decided"] and v["candidates"] == ["state 3"]


# --------------------------------------------------------------------------- environment


def test_unreachable_dask_scheduler_times_out(tiny_cfg, monkeypatch):
    pytest.importorskip("distributed")
    monkeypatch.setattr("pipeline.maps.sweep.SCHEDULER_TIMEOUT", 1)
    t0 = time.monotonic()
    with pytest.raises(PinfeedError, match="cannot reach the dask scheduler at tcp://127.0.0.1:9"):
        run_sweep(tiny_cfg, scheduler="tcp://127.0.0.1:9", progress=False)
    assert time.monotonic() - t0 < 30
    assert not Path(tiny_cfg["catalog_dir"]).exists()


@pytest.fixture
def tiny_cfg(tmp_path):
    return validate_config(dict(json.loads(json.dumps(TINY)), catalog_dir=str(tmp_path / "cat")))


def test_non_numeric_source_date_epoch(capsys, monkeypatch, tmp_path):
    monkeypatch.setenv("SOURCE_DATE_EPOCH", "yesterday")
    one_line_error(capsys, MAP + ["--d", "0.3", "--out", str(tmp_path / "m.h5")],
                   "SOURCE_DATE_EPOCH must be a whole number", "'yesterday'")
    with pytest.raises(PinfeedError, match="SOURCE_DATE_EPOCH"):
        validate_config(json.loads(json.dumps(TINY)))
    monkeypatch.setenv("SOURCE_DATE_EPOCH", "1700000000")
    from pipeline.provenance import creation_time
    assert creation_time() == "2023-11-14T22:13:20Z"


# --------------------------------------------------------------------------- catalog answers


def test_same_size_garbage_is_flagged_by_list_and_show(swept, capsys):
    root = Path(swept["catalog_dir"])
    shard = shard_jobs(swept)[0].path(root)
    shard.write_bytes(os.urandom(shard.stat().st_size))
    code, out, err = cli(capsys, ["catalog", "list", "--catalog", str(root)])
    assert code == 0 and any("changed since it was indexed (checksum)" in e for e in err)
    code, out, err = cli(capsys, ["catalog", "show", "tri", "--catalog", str(root), "--json"])
    assert code == 0 and len(json.loads(out)["shards"]) == 1  # the damaged one is not served


def test_catalog_query_refuses_nan_and_inf(swept, capsys):
    base = ["catalog", "query", "--catalog", swept["catalog_dir"], "--part", "tri"]
    one_line_error(capsys, base + ["--mu-c", "nan"], "mu_c must be a finite number")
    one_line_error(capsys, base + ["--v-pin", "inf"], "v_pin must be a finite number")
    one_line_error(capsys, base + ["--d", "nan"], "finite")
    with pytest.raises(PinfeedError, match="d must be a finite"):
        Catalog.open(swept["catalog_dir"]).query("tri", model="ellipsoid", d=[float("-inf")])


def test_part_in_two_families_is_a_clear_error(swept):
    root = Path(swept["catalog_dir"])
    cat = Catalog.open(root)
    for e in cat.entries[:1]:
        e["family"] = "other"
    with pytest.raises(PinfeedError, match="stored in several families"):
        cat.query("tri", model="ellipsoid")


def test_plan_depth_zero_is_refused(capsys):
    one_line_error(capsys, ["plan", "--vertices", "0,0 60,0 15,35", "--depth", "0"],
                   "--depth must be at least 1")
    one_line_error(capsys, ["plan", "--vertices", "0,0 60,0 15,35", "--mu-c", "nan"],
                   "must be a finite number >= 0")


# --------------------------------------------------------------------------- workflow faults


def test_deleted_or_damaged_shard_drops_the_stale_index(swept):
    from pipeline.workflow.runner import reconcile_catalog
    root = Path(swept["catalog_dir"])
    assert reconcile_catalog(swept) == []  # consistent: nothing done
    gone, damaged = (j.path(root) for j in shard_jobs(swept))
    gone.unlink()
    damaged.write_bytes(os.urandom(damaged.stat().st_size))
    notes = reconcile_catalog(swept)
    assert any("gone from disk" in n for n in notes) and any("moved to" in n for n in notes)
    assert not (root / "index.json").exists() and not damaged.exists()
    assert damaged.with_name(damaged.name + ".corrupt").is_file()  # kept, out of the catalog's way
    assert len(run_sweep(swept, progress=False, threads=1)) == 2  # both recomputed
    assert not Catalog.open(root).problems


def test_stale_lock_and_temp_files_are_cleared_only_when_no_run_is_alive(tmp_path):
    from pipeline.maps.io import remove_stale_temps
    from pipeline.workflow.runner import clear_stale_lock
    locks = tmp_path / ".snakemake" / "locks"
    locks.mkdir(parents=True)
    (locks / "0.input.lock").write_text("x")
    fake = tmp_path / "snakemake_fake.py"  # looks like a live Snakemake in this folder
    fake.write_text("import time\ntime.sleep(60)\n")
    proc = subprocess.Popen([sys.executable, str(fake)], cwd=tmp_path)
    try:
        time.sleep(0.3)
        with pytest.raises(PinfeedError, match=f"pid {proc.pid}"):
            clear_stale_lock(tmp_path)
        assert (locks / "0.input.lock").exists()
    finally:
        proc.kill()
        proc.wait()
    assert "previous run was killed" in clear_stale_lock(tmp_path)
    assert not (locks / "0.input.lock").exists()
    tmp = tmp_path / "cat" / ".mu_c=0.2.h5.abc123.tmp"
    tmp.parent.mkdir()
    tmp.write_text("half")
    assert remove_stale_temps(tmp_path / "cat") == [tmp] and not tmp.exists()


def _run_workflow(workdir):
    env = dict(os.environ, PATH=f"{VENV_BIN}{os.pathsep}{os.environ.get('PATH', '')}",
               PYTHONPATH=str(ROOT))
    return subprocess.Popen([sys.executable, "-m", "pipeline.workflow", "run", "-s", str(ROOT / "Snakefile"),
                             "--cores", "1", "--rerun-incomplete", "--configfile", "tiny.yaml"],
                            cwd=workdir, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                            text=True, start_new_session=True)


def _check_consistent(root: Path):
    """Every shard on disk is whole; an index, if any, lists only whole shards."""
    for path in root.rglob("*.h5"):
        read_map(path)
    if (root / "index.json").is_file():
        cat = Catalog.open(root)
        assert not cat.problems, cat.problems
        for e in cat.entries:
            cat._open_entry(e)


def test_killed_runs_leave_a_consistent_catalog_that_resumes(tmp_path):
    (tmp_path / "tiny.yaml").write_text(yaml.safe_dump(dict(json.loads(json.dumps(TINY)),
                                                            catalog_dir="cat")))
    rng = random.Random(12)
    for _ in range(3):
        proc = _run_workflow(tmp_path)
        time.sleep(rng.uniform(1.0, 7.0))
        os.killpg(proc.pid, signal.SIGKILL)  # the whole run, as kill -9 of make would
        proc.communicate()
        _check_consistent(tmp_path / "cat")
    proc = _run_workflow(tmp_path)
    out = proc.communicate(timeout=600)[0]
    assert proc.returncode == 0, out[-3000:]
    cat = Catalog.open(tmp_path / "cat")
    assert len(cat.entries) == 2 and not cat.problems
    assert not list((tmp_path / "cat").rglob("*.tmp"))
    # Resumed maps equal a straight computation.
    cfg = validate_config(dict(json.loads(json.dumps(TINY)), catalog_dir=str(tmp_path / "ref")))
    run_sweep(cfg, progress=False, threads=1)
    ref = Catalog.open(tmp_path / "ref")
    for mu in (0.0, 0.2):
        a = cat.query("tri", model="ellipsoid", mu_c=mu).load()
        b = ref.query("tri", model="ellipsoid", mu_c=mu).load()
        np.testing.assert_array_equal(a["theta_f"].values, b["theta_f"].values)
