"""The ``pinfeed`` command line: output contracts and error handling.

Most calls run ``pipeline.cli.main`` in-process (fast, output via capsys);
a few run the installed ``pinfeed`` script to check real exit codes and what
a user sees on stderr.
"""
from __future__ import annotations

import json
import math
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

from cli_runs import run_cli as run
from conftest import TRIANGLE, circular_diff
from images import assert_png_figure
from pipeline.maps import simulate
from pipeline.parts.part import Part

VERTS = "0,0 60,0 15,35"
BASE = ["rollout", "--vertices", VERTS, "--d", "0.3", "--mu-c", "0.2", "--pin-radius", "3"]
CONTRACT_KEYS = {"theta_i", "status", "theta_f", "dy", "contact_travel", "feature_changes",
                 "peak_force"}
PINFEED = Path(sys.executable).with_name("pinfeed")


def with_options(pairs):
    """BASE plus ``--theta-i 0`` with ``pairs`` (flag, value, ...) replacing or adding options."""
    argv = list(BASE) + ["--theta-i", "0"]
    for flag, value in zip(pairs[::2], pairs[1::2]):
        if flag in argv:
            argv[argv.index(flag) + 1] = value
        else:
            argv += [flag, value]
    return argv


def run_script(args, cwd):
    # PYTHONPATH: the script runs this checkout's package even where the
    # editable install points at another checkout (a git worktree).
    env = {k: v for k, v in os.environ.items() if k != "PYTHONWARNINGS"}
    env["PYTHONPATH"] = os.pathsep.join([str(Path(__file__).resolve().parents[2]),
                                         *filter(None, [env.get("PYTHONPATH")])])
    return subprocess.run([str(PINFEED), *args], capture_output=True, text=True, cwd=cwd,
                          timeout=300, env=env)


def assert_one_line_error(code, err):
    assert code == 2, (code, err)
    lines = err.strip("\n").splitlines()
    assert len(lines) == 1, err
    assert lines[0].startswith("pinfeed: error:"), err
    assert len(lines[0]) > len("pinfeed: error: ") + 5


# --------------------------------------------------------------------------- rollout

def test_rollout_json_contract(capsys):
    code, out, err = run(capsys, BASE + ["--theta-i", "0,15,30", "--json"])
    assert code == 0, err
    rows = json.loads(out)
    assert isinstance(rows, list) and len(rows) == 3
    part = Part.from_vertices(TRIANGLE)
    for row, theta_i in zip(rows, (0.0, 15.0, 30.0)):
        assert CONTRACT_KEYS <= set(row), row
        assert "trajectory" not in row and "force" not in row
        assert row["theta_i"] == theta_i
        assert row["status"] in simulate.STATUSES
        assert isinstance(row["feature_changes"], int)
        for key in ("theta_f", "dy", "contact_travel", "peak_force"):
            assert isinstance(row[key], float) and math.isfinite(row[key])
        # Same numbers as the Python API.
        ds = simulate.rollout(part, theta_i, 0.3, 0.2, 3.0)
        assert row["status"] == ds.status.item()
        assert row["theta_f"] == pytest.approx(float(ds.theta_f), abs=1e-12)
        assert row["dy"] == pytest.approx(float(ds.dy), abs=1e-12)
        assert row["contact_travel"] == pytest.approx(float(ds.contact_travel), abs=1e-12)
        assert row["feature_changes"] == int(ds.feature_changes)
        assert row["peak_force"] == pytest.approx(float(ds.peak_force), abs=1e-12)


def test_rollout_theta_range_and_model(capsys):
    code, out, err = run(capsys, BASE + ["--theta-i", "0:90:45", "--model", "ellipsoid", "--json"])
    assert code == 0, err
    rows = json.loads(out)
    assert [r["theta_i"] for r in rows] == [0.0, 45.0, 90.0]
    part = Part.from_vertices(TRIANGLE)
    ds = simulate.rollout(part, 45.0, 0.3, 0.2, 3.0, model="ellipsoid")
    assert rows[1]["theta_f"] == pytest.approx(float(ds.theta_f), abs=1e-12)
    other = simulate.rollout(part, 45.0, 0.3, 0.2, 3.0, model="minpower")
    assert abs(circular_diff(float(other.theta_f), rows[1]["theta_f"])) > 1e-6


def test_rollout_trajectory_rows(capsys):
    code, out, err = run(capsys, BASE + ["--theta-i", "30", "--trajectory", "--json"])
    assert code == 0, err
    (row,) = json.loads(out)
    assert CONTRACT_KEYS <= set(row)
    traj = np.array(row["trajectory"], dtype=float)
    force = np.array(row["force"], dtype=float)
    assert traj.ndim == 2 and traj.shape[1] == 4 and traj.shape[0] >= 2
    assert force.ndim == 2 and force.shape[1] == 3 and force.shape[0] >= 2
    np.testing.assert_allclose(traj[0], [0.0, 0.0, 0.0, 30.0], atol=1e-12)
    assert abs(circular_diff(traj[-1, 3], row["theta_f"])) < 1e-9
    assert traj[-1, 2] == pytest.approx(row["dy"], abs=1e-12)
    assert np.all(np.diff(traj[:, 0]) >= 0)
    np.testing.assert_array_equal(force[-1, 1:], [0.0, 0.0])
    assert np.hypot(force[:, 1], force[:, 2]).max() == pytest.approx(row["peak_force"], rel=1e-12)


def test_rollout_max_travel_truncates(capsys):
    code, out, err = run(capsys, BASE + ["--theta-i", "0,30", "--max-travel", "2", "--json"])
    assert code == 0, err
    rows = json.loads(out)
    assert [r["status"] for r in rows] == ["truncated", "truncated"]
    assert all(r["contact_travel"] == pytest.approx(2.0) for r in rows)
    # Without the cap the contact lasts much longer than 2 mm.
    code, out, _ = run(capsys, BASE + ["--theta-i", "0,30", "--json"])
    assert all(r["status"] == "ok" and r["contact_travel"] > 10.0 for r in json.loads(out))


def test_rollout_table(capsys):
    code, out, err = run(capsys, BASE + ["--theta-i", "0,15,30"])
    assert code == 0, err
    with pytest.raises(json.JSONDecodeError):
        json.loads(out)
    lines = [ln for ln in out.splitlines() if ln.strip()]
    rows = [ln.split() for ln in lines if ln.split() and ln.split()[0] in ("0.00", "15.00", "30.00")]
    assert len(rows) == 3
    part = Part.from_vertices(TRIANGLE)
    for fields, theta_i in zip(rows, (0.0, 15.0, 30.0)):
        ds = simulate.rollout(part, theta_i, 0.3, 0.2, 3.0)
        assert ds.status.item() in fields
        assert float(fields[2]) == pytest.approx(float(ds.theta_f), abs=0.001)
        assert float(fields[3]) == pytest.approx(float(ds.dy), abs=0.001)


def test_rollout_table_shows_jams(capsys):
    code, out, err = run(capsys, ["rollout", "--vertices", "0,0 60,0 60,20 0,20", "--d", "0",
                                  "--mu-c", "0.2", "--pin-radius", "3", "--theta-i", "0"])
    assert code == 0, err
    assert "jammed" in out


# --------------------------------------------------------------------------- errors

@pytest.mark.parametrize("args, words", [
    (["--vertices", "0,0 1,1"], ["3 vertices"]),
    (["--vertices", "0,0 60,0 a,b"], ["a,b"]),
    (["--vertices", "0,0 10,10 10,0 0,10"], ["self-intersecting"]),
    (["--mu-c", "-0.2"], ["mu_c"]),
    (["--mu-c", "nan"], ["mu_c"]),
    (["--pin-radius", "0"], ["radius"]),
    (["--pin-radius", "-1"], ["radius"]),
    (["--d", "nan"], ["d"]),
    (["--theta-i", "zero"], ["theta"]),
    (["--max-travel", "0"], ["travel"]),
])
def test_rollout_bad_input_one_line_exit_2(capsys, args, words):
    code, out, err = run(capsys, with_options(args))
    assert_one_line_error(code, err)
    assert out == ""
    for w in words:
        assert w in err, err


def test_unknown_model_exits_2(capsys):
    code, out, err = run(capsys, BASE + ["--theta-i", "0", "--model", "nonsense"])
    assert code == 2
    assert out == ""
    assert "nonsense" in err and "error" in err


@pytest.mark.parametrize("extra", [["--model", "nonsense"], ["--mu-c", "abc"]],
                         ids=["unknown-model", "mu-c-not-a-number"])
def test_argparse_errors_follow_the_one_line_contract(capsys, extra):
    # cli.py promises: every error a user can cause prints one line
    # "pinfeed: error: ..." on stderr and exits with status 2.
    code, out, err = run(capsys, with_options(extra))
    assert_one_line_error(code, err)


def test_script_exit_codes(tmp_path):
    ok = run_script(["rollout", "--vertices", VERTS, "--theta-i", "30", "--d", "0.3", "--mu-c",
                     "0.2", "--pin-radius", "3", "--json"], tmp_path)
    assert ok.returncode == 0, ok.stderr
    assert json.loads(ok.stdout)[0]["status"] == "ok"
    bad = run_script(["rollout", "--vertices", "0,0 1,1", "--theta-i", "30", "--d", "0.3",
                      "--mu-c", "0.2", "--pin-radius", "3", "--json"], tmp_path)
    assert_one_line_error(bad.returncode, bad.stderr)
    assert bad.stdout == ""


# --------------------------------------------------------------------------- map files

def test_map_and_plot_round_trip(tmp_path, capsys):
    out = tmp_path / "maps" / "map.h5"
    code, stdout, err = run(capsys, ["map", "--vertices", VERTS, "--mu-c", "0.2", "--pin-radius",
                                     "3", "--d", "0.3,0.5", "--theta-step", "30", "--threads", "1",
                                     "--out", str(out)])
    assert code == 0, err
    assert out.is_file()
    assert str(out) in stdout
    with xr.open_dataset(out, engine="h5netcdf") as ds:
        ds.load()
    np.testing.assert_allclose(ds.d.values, [0.3, 0.5])
    np.testing.assert_allclose(ds.theta_i.values, np.arange(0.0, 360.0, 30.0))
    assert ds.theta_f.dims == ("d", "theta_i")
    want = simulate.compute_map(Part.from_vertices(TRIANGLE), np.arange(0.0, 360.0, 30.0), [0.3, 0.5],
                                0.2, 3.0)
    np.testing.assert_array_equal(ds.theta_f.values, want.theta_f.values)
    np.testing.assert_array_equal(ds.dy.values, want.dy.values)
    np.testing.assert_array_equal(ds.status.values, want.status.values)
    assert ds.attrs["mu_c"] == 0.2 and ds.attrs["pin_radius"] == 3.0
    # No temporary files left next to the map.
    assert sorted(p.name for p in out.parent.iterdir()) == ["map.h5"]

    png = tmp_path / "map.png"
    code, stdout, err = run(capsys, ["plot-map", str(out), "--out", str(png)])
    assert code == 0, err
    assert_png_figure(png)


def test_map_range_syntax(tmp_path, capsys):
    out = tmp_path / "r.h5"
    code, _, err = run(capsys, ["map", "--vertices", VERTS, "--mu-c", "0.2", "--pin-radius", "3",
                                "--d", "0.1:0.9:0.4", "--theta-step", "90", "--out", str(out)])
    assert code == 0, err
    with xr.open_dataset(out, engine="h5netcdf") as ds:
        np.testing.assert_allclose(ds.d.values, [0.1, 0.5, 0.9], atol=1e-12)
        np.testing.assert_allclose(ds.theta_i.values, [0.0, 90.0, 180.0, 270.0])


@pytest.mark.parametrize("d_arg, want", [
    ("-0.9:0.9:0.6", [-0.9, -0.3, 0.3, 0.9]),  # the README's form: --d -0.9:0.9:0.1
    ("-0.3,0.3", [-0.3, 0.3]),
])
def test_map_negative_d_values(tmp_path, capsys, d_arg, want):
    # Negative d (the pin below the centroid) is half of every map; the README
    # documents "--d -0.9:0.9:0.1" with a space, so that form must work.
    out = tmp_path / "neg.h5"
    code, _, err = run(capsys, ["map", "--vertices", VERTS, "--mu-c", "0.2", "--pin-radius", "3",
                                "--d", d_arg, "--theta-step", "90", "--out", str(out)])
    assert code == 0, err
    with xr.open_dataset(out, engine="h5netcdf") as ds:
        np.testing.assert_allclose(ds.d.values, want, atol=1e-12)


def test_map_negative_d_values_with_equals_sign(tmp_path, capsys):
    out = tmp_path / "neg.h5"
    code, _, err = run(capsys, ["map", "--vertices", VERTS, "--mu-c", "0.2", "--pin-radius", "3",
                                "--d=-0.9:0.9:0.6", "--theta-step", "90", "--out", str(out)])
    assert code == 0, err
    with xr.open_dataset(out, engine="h5netcdf") as ds:
        np.testing.assert_allclose(ds.d.values, [-0.9, -0.3, 0.3, 0.9], atol=1e-12)


def test_rollout_negative_theta_list(capsys):
    # Like --d above: a list starting with a negative number is a value.
    code, out, err = run(capsys, BASE + ["--theta-i", "-30,0,30", "--json"])
    assert code == 0, err
    assert [r["theta_i"] for r in json.loads(out)] == [-30.0, 0.0, 30.0]


@pytest.mark.parametrize("args", [["--theta-step", "0"], ["--theta-step", "-5"],
                                  ["--d", "0.9:-0.9:0.1"], ["--d", "a,b"], ["--mu-c", "-1"]])
def test_map_bad_input(tmp_path, capsys, args):
    out = tmp_path / "m.h5"
    argv = ["map", "--vertices", VERTS, "--mu-c", "0.2", "--pin-radius", "3", "--d", "0.3",
            "--theta-step", "90", "--out", str(out)]
    argv[argv.index(args[0]) + 1] = args[1]
    code, _, err = run(capsys, argv)
    assert_one_line_error(code, err)
    assert not out.exists()


def test_plot_map_missing_file(tmp_path, capsys):
    code, _, err = run(capsys, ["plot-map", str(tmp_path / "nothere.h5"), "--out",
                                str(tmp_path / "x.png")])
    assert_one_line_error(code, err)
    assert "nothere.h5" in err
    assert not (tmp_path / "x.png").exists()


def test_plot_map_corrupt_file(tmp_path, capsys):
    bad = tmp_path / "bad.h5"
    bad.write_bytes(bytes(range(256)) * 8)
    code, _, err = run(capsys, ["plot-map", str(bad), "--out", str(tmp_path / "x.png")])
    assert_one_line_error(code, err)
    assert "bad.h5" in err
    assert not (tmp_path / "x.png").exists()


def test_plot_map_corrupt_file_script(tmp_path):
    bad = tmp_path / "bad.h5"
    bad.write_bytes(b"\x00garbage, not HDF5\xff" * 50)
    res = run_script(["plot-map", str(bad), "--out", str(tmp_path / "x.png")], tmp_path)
    assert_one_line_error(res.returncode, res.stderr)


def test_plot_map_hdf5_that_is_not_a_map(tmp_path):
    # A valid HDF5 file without the map variables: still one clean error line
    # (run as a script so that library warnings reach stderr as a user sees them).
    import h5py
    path = tmp_path / "other.h5"
    with h5py.File(path, "w") as fh:
        fh["x"] = np.arange(3)
    res = run_script(["plot-map", str(path), "--out", str(tmp_path / "x.png")], tmp_path)
    assert_one_line_error(res.returncode, res.stderr)
    assert "not a pinfeed map" in res.stderr
