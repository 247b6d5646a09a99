"""The SLURM profile on a real (one-node, local) SLURM cluster: every job goes
through sbatch, the results equal a local run's, and a job cancelled with
scancel mid-run is resubmitted by a rerun with nothing half-written left.

The cluster is tests/cluster/slurm_up.sh (munged, slurmctld, slurmd as the
current user). It has no accounting database, so the executor reads job
states with squeue (--slurm-status-command squeue) and the cluster's
jobcomp.log is the record of every job that ran.
"""
import os
import re
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
import yaml

from shards import RUN_STAMPS, assert_same_shard

ROOT = Path(__file__).resolve().parents[2]
VENV_BIN = Path(sys.executable).parent
SLURM_UP = ROOT / "tests" / "cluster" / "slurm_up.sh"

pytestmark = [
    pytest.mark.cluster,
    # Opt-in: it links /etc/slurm/slurm.conf while the cluster is up (see slurm_up.sh).
    pytest.mark.skipif(os.environ.get("PINFEED_CLUSTER_TESTS") != "1",
                       reason="SLURM cluster test: set PINFEED_CLUSTER_TESTS=1 to run it"),
    pytest.mark.skipif(shutil.which("slurmctld") is None and not Path("/usr/sbin/slurmctld").exists(),
                       reason="slurm-wlm not installed (apt-get install -y slurm-wlm munge)"),
    pytest.mark.skipif(shutil.which("snakemake-executor-plugin-slurm") is None
                       and not (VENV_BIN.parent / "lib").glob("python*/site-packages/snakemake_executor_plugin_slurm"),
                       reason="snakemake-executor-plugin-slurm not installed (pip install 'pinfeed[slurm]')"),
]

ONE_PART = {
    "catalog_dir": "catalog", "results_dir": "results",
    "families": {"plates": {"parts": [{"name": "scalene_triangle",
                                       "vertices": [[0, 0], [70, 0], [20, 30]]}]}},
    "sweep": {"models": ["minpower"], "mu_c": [0.2], "v_pin": [0.0],
              "d": [-0.7, -0.5, -0.3, -0.1, 0.1, 0.3, 0.5, 0.7], "theta_step": 4.0,
              "pin_radius": 3.0, "kernel": {"ds_max": 0.1, "tol": 1.0e-7}},
    "bands": {"threshold_T": 5.0, "factor_c": 2.0},
    "planner": {"parts": ["all"], "pins": "auto", "tolerance_deg": 10, "depth": 3,
                "d_min": 0.1, "d_max": 0.9, "mu_c": "0.1:0.3", "frictions": [],
                "model": "minpower", "coverage": "bracket", "dynamic": {"speeds": [], "depth": 0}},
    "speed": {"trials": 5, "speeds": [50, 100]},
    "verify": {"trials": 20},
    "sensing": {"parts": []},
    "figures": {"d": [-0.5, 0.3]},
}
TARGET = "results/one_part/atlas.json"


@pytest.fixture(scope="module")
def slurm_cluster(tmp_path_factory):
    """A running one-node cluster; yields its folder (slurm.conf, jobcomp.log)."""
    folder = tmp_path_factory.mktemp("slurm")
    daemon = subprocess.Popen(["bash", str(SLURM_UP), str(folder)], env=dict(os.environ, SLURM_UP_SYSTEM_CONF="1"), stdout=subprocess.PIPE,
                              stderr=subprocess.STDOUT, text=True, start_new_session=True)
    line = daemon.stdout.readline()
    if "slurm ready" not in line:
        daemon.kill()
        pytest.fail(f"slurm_up.sh did not start the cluster: {line}{daemon.stdout.read()}")
    yield folder
    daemon.send_signal(signal.SIGTERM)
    daemon.wait(timeout=60)


def _env(cluster):
    return dict(os.environ, SLURM_CONF=str(cluster / "slurm.conf"), PINFEED_SLURM_ACCOUNT="pinfeed",
                PINFEED_SLURM_PARTITION="debug", PINFEED_SLURM_RUNTIME="20",
                PATH=f"{VENV_BIN}{os.pathsep}{os.environ.get('PATH', '')}{os.pathsep}/usr/sbin")


def _snakemake(workdir, *extra, env=None, wait=True):
    command = [str(VENV_BIN / "snakemake"), "-s", str(ROOT / "Snakefile"), "--directory", str(workdir),
               TARGET, *extra, "--configfile", str(workdir / "one_part.yaml")]
    if not wait:
        return subprocess.Popen(command, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                                text=True)
    return subprocess.run(command, env=env, capture_output=True, text=True, timeout=600)


def _slurm_args():
    return ("--profile", str(ROOT / "profiles" / "slurm"), "--slurm-status-command", "squeue",
            "--slurm-init-seconds-before-status-checks", "2", "--latency-wait", "5")


def _workdir(tmp_path, name):
    workdir = tmp_path / name
    workdir.mkdir()
    (workdir / "one_part.yaml").write_text(yaml.safe_dump(ONE_PART))
    return workdir


def _running_plan_job(env, timeout=400):
    """The SLURM id of the plan job once it runs (squeue shows it R)."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        out = subprocess.run(["squeue", "-h", "-t", "R", "-o", "%i %k"], env=env, capture_output=True,
                             text=True).stdout
        for line in out.splitlines():
            job_id, _, comment = line.partition(" ")
            if "plan" in comment:
                return job_id
        time.sleep(1)
    pytest.fail("no plan job ran within the time limit")


def _atlas_without_timings(workdir):
    """The atlas JSON less its run stamps and the measured planning time."""
    import json
    atlas = json.loads((workdir / "results/one_part/atlas.json").read_text())
    for stamp in RUN_STAMPS:
        atlas.pop(stamp, None)
    timing = atlas["columns"].index("planning_seconds") if "planning_seconds" in atlas["columns"] else None
    rows = [dict(row) if isinstance(row, dict) else list(row) for row in atlas["rows"]]
    for row in rows:
        if isinstance(row, dict):
            row.pop("planning_seconds", None)
        elif timing is not None:
            row.pop(timing)
    atlas["rows"] = rows
    return atlas


def test_slurm_profile_matches_local_and_survives_scancel(slurm_cluster, tmp_path):
    env = _env(slurm_cluster)
    local, remote = _workdir(tmp_path, "local"), _workdir(tmp_path, "slurm")
    done = _snakemake(local, "--cores", "2", env=env)
    assert done.returncode == 0, done.stderr[-3000:]

    first = _snakemake(remote, *_slurm_args(), env=env, wait=False)
    cancelled = _running_plan_job(env)
    subprocess.run(["scancel", cancelled], env=env, check=True)
    first_log, _ = first.communicate(timeout=600)
    assert first.returncode != 0, first_log[-3000:]
    assert not (remote / "results/one_part/plans/scalene_triangle.json").exists()

    rerun = _snakemake(remote, *_slurm_args(), env=env)
    log = first_log + rerun.stdout + rerun.stderr
    assert rerun.returncode == 0, log[-3000:]

    submitted = re.findall(r"has been submitted with SLURM jobid (\d+)", log)
    finished = re.findall(r"Finished jobid: \d+ \(Rule: (\w+)\)", log)
    assert cancelled in submitted
    jobcomp = (slurm_cluster / "jobcomp.log").read_text()
    completed = set(re.findall(r"JobId=(\d+) .*JobState=COMPLETED", jobcomp))
    assert re.search(rf"JobId={cancelled} .*JobState=CANCELLED", jobcomp)
    # every job that finished ran as a SLURM job, the plan twice (cancelled, then rerun)
    assert len(set(submitted) & completed) == len(finished) == len(set(submitted)) - 1
    assert finished.count("plan") == 1 and "sweep_shard" in finished

    shards = sorted(p.relative_to(local) for p in (local / "catalog").rglob("*.h5"))
    assert shards and shards == sorted(p.relative_to(remote) for p in (remote / "catalog").rglob("*.h5"))
    for shard in shards:
        assert_same_shard(remote / shard, local / shard)
    assert _atlas_without_timings(local) == _atlas_without_timings(remote)
    assert not list(remote.rglob("*.tmp")) and not list(remote.rglob("*.partial"))
