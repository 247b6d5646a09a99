"""A dask sweep on a cluster started the way a user starts one: ``dask scheduler``
and two ``dask worker`` commands, each its own process group in its own working
folder. One worker (nanny and worker process) is killed with SIGKILL while the
sweep runs, as when a machine dies; the sweep must still finish, with every
shard in place, an index that matches the disk, no temporary file left, and
shards equal to those of a run without dask."""
from __future__ import annotations

import hashlib
import importlib.util
import os
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
import yaml

from pipeline.config import load_config, validate_config
from pipeline.maps.catalog import Catalog
from pipeline.maps.sweep import run_sweep
from shards import assert_same_shard

REPO = Path(__file__).resolve().parents[2]
MU_C = [0.0, 0.05, 0.1, 0.15, 0.2, 0.25]  # one shard each
# 360 x 30 rollouts a shard: about half a second on one core, so the sweep is
# still running when the first shard lands.
SLOW_ENOUGH = {
    "catalog_dir": "cat",
    "families": {"fam": {"parts": [{"name": "tri", "vertices": [[0, 0], [60, 0], [15, 35]]}]}},
    "sweep": {"models": ["ellipsoid"], "mu_c": MU_C, "v_pin": [0.0],
              "d": [round(float(x), 3) for x in np.linspace(-0.45, 0.45, 30)],
              "theta_step": 1, "pin_radius": 3.0},
}
STARTUP_S = 60  # scheduler file, two workers
SWEEP_S = 120


def _dask_cli() -> str:
    """The ``dask`` command of this Python's environment (its ``scheduler`` and
    ``worker`` subcommands come with distributed)."""
    if importlib.util.find_spec("distributed") is None:
        pytest.skip("distributed is not installed: no 'dask scheduler' / 'dask worker' commands")
    beside = Path(sys.executable).with_name("dask")
    cli = str(beside) if beside.is_file() else shutil.which("dask")
    if cli is None:
        pytest.skip("no 'dask' command beside this Python or on PATH")
    return cli


def _child_env() -> dict:
    """This environment, with the code under test first on the path of every child."""
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join(p for p in (str(REPO), env.get("PYTHONPATH")) if p)
    return env


class Processes:
    """Commands started as their own process groups, each logging to a file;
    :meth:`stop_all` kills whatever is still running."""

    def __init__(self, log_dir: Path):
        self.log_dir = log_dir
        self.running: dict[str, subprocess.Popen] = {}

    def start(self, name, cmd, cwd) -> subprocess.Popen:
        log = open(self.log_dir / f"{name}.log", "wb")
        try:
            proc = subprocess.Popen(cmd, cwd=cwd, env=_child_env(), stdout=log, stderr=subprocess.STDOUT,
                                    stdin=subprocess.DEVNULL, start_new_session=True)
        finally:
            log.close()  # the child holds its own copy
        self.running[name] = proc
        return proc

    def kill(self, name) -> None:
        """SIGKILL to the whole group (a worker's nanny and its worker process)."""
        proc = self.running[name]
        try:
            os.killpg(proc.pid, signal.SIGKILL)
        except ProcessLookupError:
            pass
        proc.wait(timeout=10)

    def log(self, name) -> str:
        return (self.log_dir / f"{name}.log").read_text(errors="replace")[-3000:]

    def stop_all(self) -> None:
        for name, proc in reversed(list(self.running.items())):
            if proc.poll() is None:
                try:
                    os.killpg(proc.pid, signal.SIGTERM)
                    proc.wait(timeout=10)
                except subprocess.TimeoutExpired:
                    os.killpg(proc.pid, signal.SIGKILL)
                    proc.wait(timeout=10)
                except ProcessLookupError:
                    pass
            # a worker's process group may outlive its leader
            try:
                os.killpg(proc.pid, signal.SIGKILL)
            except (ProcessLookupError, PermissionError):
                pass


@pytest.fixture
def processes(tmp_path):
    procs = Processes(tmp_path)
    yield procs
    procs.stop_all()


def _wait_for_file(path: Path, proc: subprocess.Popen, timeout: float) -> None:
    deadline = time.monotonic() + timeout
    while not path.is_file():
        assert proc.poll() is None, f"exited with {proc.returncode} before writing {path}"
        assert time.monotonic() < deadline, f"no {path} after {timeout} s"
        time.sleep(0.1)


def start_cluster(processes, tmp_path, names=("w0", "w1")):
    """``dask scheduler`` and one ``dask worker`` per name, each worker in a folder of
    its own; returns the scheduler file and the workers' folders by name."""
    cli = _dask_cli()
    sched_file = tmp_path / "scheduler.json"
    sched = processes.start("scheduler", [cli, "scheduler", "--host", "127.0.0.1", "--port", "0",
                                          "--no-dashboard", "--scheduler-file", str(sched_file),
                                          "--idle-timeout", "300"], cwd=tmp_path)
    folders = {}
    for name in names:
        folders[name] = tmp_path / f"machine-{name}"
        folders[name].mkdir()
        processes.start(name, [cli, "worker", "--scheduler-file", str(sched_file), "--name", name,
                               "--nthreads", "1", "--nworkers", "1", "--no-dashboard",
                               "--local-directory", str(folders[name] / "scratch"),
                               "--death-timeout", "60"], cwd=folders[name])
    _wait_for_file(sched_file, sched, STARTUP_S)
    return sched_file, folders


def _shards(catalog: Path) -> set[str]:
    return {p.relative_to(catalog).as_posix() for p in catalog.rglob("*.h5") if not p.name.startswith(".")}


def _all_files(catalog: Path) -> set[str]:
    return {p.relative_to(catalog).as_posix() for p in catalog.rglob("*") if p.is_file()}


def _sha256(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def test_sweep_survives_a_worker_killed_mid_sweep(tmp_path, processes, monkeypatch):
    from distributed import Client

    # The user's side: a config with a relative catalog folder, in a folder of its own.
    user = tmp_path / "user"
    user.mkdir()
    (user / "sweep.yaml").write_text(yaml.safe_dump(SLOW_ENOUGH))
    catalog = user / "cat"
    # The same shards without dask, then moved aside: the same config (its hash, an
    # attribute, covers the catalog folder). This also puts the compiled kernels
    # in Numba's cache for the workers.
    monkeypatch.chdir(user)  # a relative catalog folder is taken from the working folder
    run_sweep(load_config("sweep.yaml"), threads=1, progress=False)
    local = catalog.rename(tmp_path / "local")
    assert len(_shards(local)) == len(MU_C)

    sched_file, folders = start_cluster(processes, tmp_path)
    with Client(scheduler_file=str(sched_file), timeout=30) as client:
        client.wait_for_workers(2, timeout=STARTUP_S)
        assert sorted(client.run(os.getcwd).values()) == sorted(str(f) for f in folders.values())
        sweep = processes.start("sweep", [sys.executable, "-m", "pipeline.cli", "sweep", "--config",
                                          "sweep.yaml", "--scheduler", client.scheduler.address,
                                          "--threads", "1", "--quiet"], cwd=user)

        # Kill a busy worker as soon as the first shard lands.
        deadline = time.monotonic() + SWEEP_S
        while not (catalog.is_dir() and _shards(catalog)):
            assert sweep.poll() is None, f"the sweep ended before any shard landed:\n{processes.log('sweep')}"
            assert time.monotonic() < deadline, f"no shard after {SWEEP_S} s:\n{processes.log('sweep')}"
            time.sleep(0.02)
        busy = {client.scheduler_info()["workers"][addr]["name"]: keys
                for addr, keys in client.processing().items() if keys}
        landed = _shards(catalog)
        assert busy, "no worker had a task when the first shard landed"
        assert sweep.poll() is None and len(landed) < len(MU_C), \
            f"the kill would come too late: {len(landed)} of {len(MU_C)} shards had landed"
        victim = sorted(busy)[0]
        processes.kill(victim)

        try:
            rc = sweep.wait(timeout=SWEEP_S)
        except subprocess.TimeoutExpired:
            pytest.fail(f"the sweep did not finish within {SWEEP_S} s after the kill:\n{processes.log('sweep')}")
        assert rc == 0, processes.log("sweep")
        assert f"computed {len(MU_C)} shards" in processes.log("sweep")
        # the killed worker stayed dead: its tasks ran on the other one
        assert [w["name"] for w in client.scheduler_info()["workers"].values()] == \
            [n for n in folders if n != victim]

    # Every shard landed, nothing else is in the catalog (no temporary file of the killed write)...
    shards = _shards(catalog)
    assert shards == _shards(local)
    assert _all_files(catalog) == shards | {"index.json"}
    # ...and nothing landed where the workers run.
    assert not any(_shards(f) for f in folders.values())
    # The index lists exactly the files on disk, with their checksums.
    cat = Catalog.open(catalog)
    assert not cat.problems
    assert {e["file"]: e["sha256"] for e in cat.entries} == {s: _sha256(catalog / s) for s in shards}
    assert sorted(e["mu_c"] for e in cat.entries) == MU_C
    for shard in sorted(shards):
        assert_same_shard(catalog / shard, local / shard)


def test_a_sweep_removes_the_temporary_file_a_killed_writer_left(tmp_path):
    """What a worker killed mid-write leaves (the atomic write's temporary file
    beside the shard) is gone once the shard is in place; other files stay."""
    config = validate_config(dict(SLOW_ENOUGH, catalog_dir=str(tmp_path / "cat"),
                                  sweep=dict(SLOW_ENOUGH["sweep"], mu_c=[0.1], d=[0.0], theta_step=90)))
    folder = tmp_path / "cat" / "fam"
    run_sweep(config, threads=1, progress=False)
    (shard,) = [p for p in folder.rglob("*.h5")]
    shard.unlink()
    killed = shard.parent / f".{shard.name}.k1ll3d.tmp"  # the name atomic writes use
    killed.write_bytes(b"half an HDF5 file")
    other = shard.parent / ".mu_c=0.3.h5.k1ll3d.tmp"  # not a shard of this sweep
    other.write_bytes(b"")
    run_sweep(config, threads=1, progress=False)
    assert shard.is_file() and not killed.exists() and other.exists()
