"""The last wrong answers of the catalog (issue 26): a negative friction in a
query, and a damaged shard named (with the way to recompute it) by every
command that would have used it, never 'unknown part'."""
from __future__ import annotations

import json
import os
from pathlib import Path

import pytest

from cli_runs import run_cli
from pipeline.config import validate_config
from pipeline.errors import PinfeedError
from pipeline.maps.catalog import Catalog
from pipeline.maps.sweep import run_sweep, shard_jobs

TINY = {
    "families": {"fam": {"parts": [{"name": "tri", "vertices": [[0, 0], [60, 0], [15, 35]]}]}},
    "sweep": {"models": ["ellipsoid"], "mu_c": [0.0, 0.2], "d": [-0.4, 0.3],
              "theta_step": 45, "pin_radius": 3.0},
}


@pytest.fixture
def swept(tmp_path):
    cfg = validate_config(dict(json.loads(json.dumps(TINY)), catalog_dir=str(tmp_path / "cat")))
    run_sweep(cfg, progress=False, threads=1)
    return cfg


def _error(capsys, argv, *needles):
    """Exit 2, the last stderr line a 'pinfeed: error:' line holding ``needles``
    (lines before it may be warnings about the catalog), no traceback."""
    code, out, err = run_cli(capsys, argv)
    lines = err.strip().splitlines()
    assert code == 2 and lines[-1].startswith("pinfeed: error: "), err
    assert all(line.startswith("pinfeed: ") for line in lines) and "Traceback" not in err
    for needle in needles:
        assert needle in lines[-1], lines[-1]
    return lines[-1]


def _base(cfg, command="query"):
    return ["catalog", command, "--catalog", cfg["catalog_dir"], "--part", "tri", "--model", "ellipsoid"]


@pytest.mark.parametrize("mu", ["-1", "nan", "inf", "-0.01"])
def test_bad_friction_in_query_and_plot(swept, capsys, tmp_path, mu):
    _error(capsys, _base(swept) + ["--mu-c", mu], "mu_c must be a finite number")
    _error(capsys, _base(swept, "plot") + ["--mu-c", mu, "--out", str(tmp_path / "m.png")],
           "mu_c must be a finite number")
    assert not (tmp_path / "m.png").exists()
    with pytest.raises(PinfeedError, match=">= 0|finite"):
        Catalog.open(swept["catalog_dir"]).query("tri", model="ellipsoid", mu_c=float(mu))


def _damage(cfg, which):
    shard = shard_jobs(cfg)[which].path(cfg["catalog_dir"])
    shard.write_bytes(os.urandom(shard.stat().st_size))
    return shard


def test_damaged_shard_is_named_where_it_would_be_used(swept, capsys, tmp_path):
    zero, point2 = (j.path(swept["catalog_dir"]) for j in shard_jobs(swept))
    assert "mu_c=0.2" in point2.name
    _damage(swept, 1)
    for mu in ("0.2", "0.15"):  # exactly, and as the nearest stored friction
        _error(capsys, _base(swept) + ["--mu-c", mu], point2.name, "changed since it was indexed",
               "pinfeed sweep", "make run")
    _error(capsys, _base(swept), point2.name)  # every friction asked
    _error(capsys, _base(swept, "plot") + ["--mu-c", "0.2", "--out", str(tmp_path / "m.png")], point2.name)
    code, out, err = run_cli(capsys, _base(swept) + ["--mu-c", "0.05", "--json"])  # mu 0 is whole
    assert code == 0 and {r["mu_c"] for r in json.loads(out)["rows"]} == {0.0}
    assert point2.name in err and "pinfeed sweep" in err  # still warned about
    _damage(swept, 0)
    show = ["catalog", "show", "tri", "--catalog", swept["catalog_dir"]]
    line = _error(capsys, show, "tri: a shard it needs is damaged", "pinfeed sweep")
    assert "unknown part" not in line


def test_unreadable_shard_after_reindex_is_named(swept, capsys):
    shards = [_damage(swept, k) for k in (0, 1)]
    code, _, err = run_cli(capsys, ["catalog", "index", "--catalog", swept["catalog_dir"]])
    assert code == 0 and "cannot read as HDF5" in err
    line = _error(capsys, ["catalog", "show", "tri", "--catalog", swept["catalog_dir"]],
                  "cannot read as HDF5", "pinfeed sweep")
    assert any(s.name in line for s in shards) and "unknown part" not in line
    _error(capsys, _base(swept) + ["--mu-c", "0.2"], shards[1].name)
    with pytest.raises(PinfeedError, match="family fam: a shard it needs is damaged"):
        Catalog.open(swept["catalog_dir"]).cube("fam")
    # Another part is still unknown, with the usual message.
    _error(capsys, ["catalog", "show", "nope", "--catalog", swept["catalog_dir"]], "unknown part 'nope'")
    assert Path(swept["catalog_dir"], "index.json").is_file()
