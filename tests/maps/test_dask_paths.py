"""A dask sweep whose workers run in another working folder lands its shards
in the client's catalog (issue 27): folders are resolved before tasks go out,
and the client checks that every reported shard is on disk and indexed."""
import os

import pytest

from pipeline.config import validate_config
from pipeline.errors import PinfeedError
from pipeline.maps.catalog import Catalog
from pipeline.maps.sweep import check_landed, run_sweep

TINY = {
    "catalog_dir": "cat",
    "families": {"fam": {"parts": [{"name": "tri", "vertices": [[0, 0], [60, 0], [15, 35]]}]}},
    "sweep": {"models": ["ellipsoid"], "mu_c": [0.0, 0.2], "v_pin": [0.0], "d": [-0.4, 0.3],
              "theta_step": 90, "pin_radius": 3.0},
}


def test_workers_in_another_folder_write_into_the_clients_catalog(tmp_path, monkeypatch):
    distributed = pytest.importorskip("distributed")
    client_dir, worker_dir = tmp_path / "client", tmp_path / "worker"
    client_dir.mkdir()
    worker_dir.mkdir()
    monkeypatch.chdir(worker_dir)  # worker processes start here and keep this folder
    with distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as cluster:
        with distributed.Client(cluster) as client:
            assert set(client.run(os.getcwd).values()) == {str(worker_dir)}
        monkeypatch.chdir(client_dir)
        config = validate_config(dict(TINY))  # relative catalog_dir "cat"
        written = run_sweep(config, scheduler=cluster.scheduler_address, threads=1, progress=False)
    assert len(written) == 2
    assert all(p.is_file() and p.is_relative_to(client_dir / "cat") for p in written)
    assert not (worker_dir / "cat").exists()
    cat = Catalog.open(client_dir / "cat")
    assert sorted(e["mu_c"] for e in cat.entries) == [0.0, 0.2] and not cat.problems


def test_a_shard_outside_the_catalog_is_an_error(tmp_path):
    config = validate_config(dict(TINY, catalog_dir=str(tmp_path / "cat")))
    written = run_sweep(config, threads=1, progress=False)
    cat = Catalog.open(tmp_path / "cat")
    check_landed(cat, written)  # all there: no error
    stray = tmp_path / "elsewhere" / "mu_c=0.h5"
    with pytest.raises(PinfeedError, match=r"1 of 3 shards computed did not land in the catalog"):
        check_landed(cat, [*written, stray])
