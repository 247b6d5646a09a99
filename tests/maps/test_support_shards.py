"""Shards with a support (issue 25, ``sweep.supports``): written, indexed and
queried back equal to a direct kernel call on the same support; uniform
shards keep their names; the cube's ``support`` dimension; an unknown or a
damaged support shard named in one line; the CLI; the workflow's jobs."""
from __future__ import annotations

import json
import os

import numpy as np
import pytest

from cli_runs import run_cli
from workflow_runs import run_snakemake

from pipeline.config import load_config, validate_config
from pipeline.errors import PinfeedError
from pipeline.maps import simulate
from pipeline.maps.catalog import Catalog
from pipeline.maps.sweep import run_sweep, shard_jobs
from pipeline.parts.part import Part
from pipeline.parts.support import support_key

POINTS = "points:-5,-3,1 5,-3,1 0,6,1"
TINY = {
    "families": {"fam": {"parts": [{"name": "tri", "vertices": [[0, 0], [60, 0], [15, 35]]}]}},
    "sweep": {"models": ["minpower", "ellipsoid"], "mu_c": [0.2], "d": [-0.4, 0.3],
              "theta_step": 45, "pin_radius": 3.0, "supports": ["uniform", "tripod", POINTS]},
}
TRI = Part.from_vertices(TINY["families"]["fam"]["parts"][0]["vertices"], name="tri")


@pytest.fixture(scope="module")
def swept(tmp_path_factory):
    cfg = validate_config(dict(json.loads(json.dumps(TINY)),
                               catalog_dir=str(tmp_path_factory.mktemp("cat") / "catalog")))
    run_sweep(cfg, progress=False, threads=1)
    return cfg


@pytest.mark.parametrize("support", ["tripod", POINTS, "uniform"])
def test_query_equals_a_direct_kernel_call(swept, support):
    cat = Catalog.open(swept["catalog_dir"])
    assert not cat.problems and len(cat.entries) == 2 + 2  # uniform x 2 models, 2 supports x minpower
    q = cat.query("tri", mu_c=0.2, support=support).load()
    direct = simulate.compute_map(TRI, np.arange(0, 360, 45.0), [-0.4, 0.3], 0.2, 3.0,
                                  support=None if support == "uniform" else support)
    for name in ("theta_f", "dy", "status"):
        np.testing.assert_array_equal(q[name].values[0], direct[name].values)
    assert str(q["support"].values) == support
    by_key = cat.query("tri", mu_c=0.2, support=support_key(support) or "uniform").load()
    np.testing.assert_array_equal(by_key["theta_f"].values, q["theta_f"].values)


def test_supports_change_the_maps_and_name_their_files(swept):
    paths = [j.path(swept["catalog_dir"]) for j in shard_jobs(swept)]
    names = sorted(p.name for p in paths)
    assert names == sorted(["mu_c=0.2.h5", "mu_c=0.2.h5", "mu_c=0.2_support=tripod.h5",
                            f"mu_c=0.2_support={support_key(POINTS)}.h5"])
    assert support_key(POINTS).startswith("points-") and len(support_key(POINTS)) == 17
    cat = Catalog.open(swept["catalog_dir"])
    uni = cat.query("tri", mu_c=0.2).load()["theta_f"].values
    tri = cat.query("tri", mu_c=0.2, support="tripod").load()["theta_f"].values
    assert np.nanmax(np.abs(tri - uni)) > 1.0


def test_default_config_keeps_its_shard_names():
    """Uniform pressure alone (the default) adds nothing to any name."""
    cfg = load_config()
    assert cfg["sweep"]["supports"] == ["uniform"]
    jobs = shard_jobs(cfg)
    assert all("support" not in j.path("cat").name for j in jobs)
    explicit = dict(cfg, sweep=dict(cfg["sweep"], supports=["uniform"]))
    assert [j.path("c") for j in shard_jobs(explicit)] == [j.path("c") for j in jobs]


def test_cube_has_a_support_dimension(swept):
    cube = Catalog.open(swept["catalog_dir"]).cube("fam")
    assert "support" in cube.dims and set(cube["support"].values) == {"uniform", "tripod", POINTS}
    tip = cube["theta_f"].sel(model="ellipsoid", support="tripod").load().values
    assert np.all(np.isnan(tip))  # not stored: a support is swept with minpower only


def test_unknown_support_is_one_line(swept):
    with pytest.raises(PinfeedError, match="no minpower maps on support 'rim:8'; stored supports: "
                                           "uniform, points:.*, tripod"):
        Catalog.open(swept["catalog_dir"]).query("tri", mu_c=0.2, support="rim:8")


def test_damaged_support_shard_is_named_only_where_it_is_used(swept, capsys, tmp_path):
    import shutil
    root = tmp_path / "copy"
    shutil.copytree(swept["catalog_dir"], root)
    shard = root / "fam" / TRI.id / "minpower" / "mu_c=0.2_support=tripod.h5"
    shard.write_bytes(os.urandom(shard.stat().st_size))
    cat = Catalog.open(root)
    with pytest.raises(PinfeedError, match="support=tripod.h5"):
        cat.query("tri", mu_c=0.2, support="tripod")
    assert cat.query("tri", mu_c=0.2, support=POINTS).load()["theta_f"].size  # the others still served
    code, out, err = run_cli(capsys, ["catalog", "query", "--catalog", str(root), "--part", "tri", "--mu-c", "0.2",
                                      "--support", "tripod"])
    assert code == 2 and err.strip().splitlines()[-1].startswith("pinfeed: error:")


def test_cli_lists_and_queries_supports(swept, capsys):
    code, out, _ = run_cli(capsys, ["catalog", "list", "--catalog", swept["catalog_dir"], "--json"])
    assert code == 0 and json.loads(out)[0]["supports"] == ["uniform", POINTS, "tripod"]
    code, out, err = run_cli(capsys, ["catalog", "query", "--catalog", swept["catalog_dir"], "--part", "tri",
                                      "--mu-c", "0.2", "--d", "0.3", "--support", "tripod", "--json"])
    assert code == 0, err
    res = json.loads(out)
    assert res["support"] == "tripod" and "support tripod" in res["selection"]
    direct = simulate.compute_map(TRI, np.arange(0, 360, 45.0), [0.3], 0.2, 3.0, support="tripod")
    assert [r["theta_f"] for r in res["rows"]] == pytest.approx(direct["theta_f"].values[0].tolist())


def test_bad_support_in_the_config_is_one_line():
    cfg = dict(json.loads(json.dumps(TINY)), catalog_dir="cat")
    cfg["sweep"]["supports"] = ["uniform", "points:500,0,1"]
    with pytest.raises(PinfeedError, match="outside the outline"):
        shard_jobs(validate_config(cfg))


def test_workflow_plans_the_support_shards(tmp_path):
    import yaml
    cfg = dict(json.loads(json.dumps(TINY)), catalog_dir="cat", results_dir="res",
               planner={"parts": [], "mu_c": 0.2, "pins": [0.0, 10.0]})
    (tmp_path / "s.yaml").write_text(yaml.safe_dump(cfg))
    run = run_snakemake(tmp_path, "--configfile", str(tmp_path / "s.yaml"), "--dry-run", "--quiet", "all")
    assert run.returncode == 0, run.stderr[-2000:]
    text = run.stdout + run.stderr
    assert "sweep_shard" in text
    dry = run_snakemake(tmp_path, "--configfile", str(tmp_path / "s.yaml"), "--dry-run", "--summary")
    assert "mu_c=0.2_support=tripod.h5" in dry.stdout and f"_support={support_key(POINTS)}.h5" in dry.stdout


def _copy(swept, tmp_path):
    import shutil
    root = tmp_path / "copy"
    shutil.copytree(swept["catalog_dir"], root)
    return root


@pytest.mark.parametrize("attrs", [{"support": "rim:8"}, {"support": "uniform"},
                                   {"support_weights": [1.0, float("nan"), 1.0]},
                                   {"support_points": [0.0, 1.0, 2.0]}],
                         ids=["other-support", "says-uniform", "nan-weight", "short-points"])
def test_corrupt_support_attribute_is_a_damaged_shard(swept, tmp_path, attrs):
    """A tripod shard whose support attributes no longer say tripod (or hold
    bad points) is indexed as damaged: queries that would use it name it in
    one line, the others are served."""
    import h5py
    root = _copy(swept, tmp_path)
    shard = root / "fam" / TRI.id / "minpower" / "mu_c=0.2_support=tripod.h5"
    with h5py.File(shard, "r+") as fh:
        for k, v in attrs.items():
            fh.attrs[k] = v
    cat = Catalog.rebuild(root)
    assert len(cat.problems) == 1 and "support=tripod.h5: damaged support attribute" in cat.problems[0]
    assert "\n" not in cat.problems[0]
    cat = Catalog.open(root)
    with pytest.raises(PinfeedError, match="support=tripod.h5") as exc:
        cat.query("tri", mu_c=0.2, support="tripod")
    assert "\n" not in str(exc.value)
    assert cat.query("tri", mu_c=0.2, support=POINTS).load()["theta_f"].size
    assert cat.query("tri", mu_c=0.2).load()["theta_f"].size  # uniform untouched


def test_uniform_shard_claiming_a_support_is_damaged(swept, tmp_path):
    import h5py
    root = _copy(swept, tmp_path)
    shard = root / "fam" / TRI.id / "minpower" / "mu_c=0.2.h5"
    with h5py.File(shard, "r+") as fh:
        fh.attrs["support"] = "tripod"
    cat = Catalog.rebuild(root)
    assert len(cat.problems) == 1 and "the file name says uniform" in cat.problems[0]
    with pytest.raises(PinfeedError, match=r"mu_c=0\.2\.h5"):
        Catalog.open(root).query("tri", mu_c=0.2)
    assert Catalog.open(root).query("tri", mu_c=0.2, support="tripod").load()["theta_f"].size


def test_index_of_support_shards_is_checked_against_disk(swept, tmp_path):
    """The index records each shard's support; a support shard changed after
    indexing is caught by the size/checksum check like any other."""
    root = _copy(swept, tmp_path)
    index = json.loads((root / "index.json").read_text())
    rows = {(e["model"], e["support"], e["support_key"]) for e in index["entries"]}
    assert rows == {("minpower", "uniform", ""), ("ellipsoid", "uniform", ""),
                    ("minpower", "tripod", "tripod"), ("minpower", POINTS, support_key(POINTS))}
    shard = root / "fam" / TRI.id / "minpower" / "mu_c=0.2_support=tripod.h5"
    with open(shard, "ab") as fh:
        fh.write(b"\0")
    cat = Catalog.open(root)
    assert any("support=tripod.h5: changed since it was indexed" in p for p in cat.problems)
    with pytest.raises(PinfeedError, match="support=tripod.h5"):
        cat.query("tri", mu_c=0.2, support="tripod")


def test_other_models_on_a_support_say_minpower_only(swept):
    with pytest.raises(PinfeedError, match="no ellipsoid maps on support 'tripod'.*minpower only"):
        Catalog.open(swept["catalog_dir"]).query("tri", model="ellipsoid", mu_c=0.2, support="tripod")


def test_config_hash_ignores_the_default_supports():
    """sweep.supports at its default (absent or [uniform]) leaves the config hash
    (a shard attribute) as it was before the key existed; a support changes it."""
    from pipeline.config import config_hash
    base = dict(json.loads(json.dumps(TINY)), catalog_dir="cat")
    del base["sweep"]["supports"]
    cfg = validate_config(base)
    assert cfg["sweep"]["supports"] == ["uniform"]
    # The support keys and the claim's settings, at their defaults, are left out too.
    planner_neutral = {"support_family", "width_slack_deg", "worst_member_budget", "shape_tolerance_mm"}
    verify_neutral = {"confidence", "rule", "holdout_trials"}
    without = dict(cfg, sweep={k: v for k, v in cfg["sweep"].items() if k != "supports"},
                   planner={k: v for k, v in cfg["planner"].items() if k not in planner_neutral},
                   verify={k: v for k, v in cfg["verify"].items() if k not in verify_neutral})
    without.pop("support_study")
    without.pop("design")  # the design search's settings, at their defaults, are left out too
    blob = json.dumps(without, sort_keys=True, separators=(",", ":"), default=float)
    import hashlib
    assert config_hash(cfg) == hashlib.sha256(blob.encode()).hexdigest()[:16]
    explicit = validate_config(dict(base, sweep=dict(base["sweep"], supports=["uniform"])))
    assert config_hash(explicit) == config_hash(cfg)
    tripod = validate_config(dict(base, sweep=dict(base["sweep"], supports=["uniform", "tripod"])))
    assert config_hash(tripod) != config_hash(cfg)
    studied = validate_config(dict(base, support_study={"family": "tripods:3"}))
    assert config_hash(studied) != config_hash(cfg)


def test_default_config_shards_hard_coded():
    """The default config's shards, written out: 2 parts x 2 models x 3 mu_c x 5 v_pin."""
    cfg = load_config()
    got = sorted(j.path("catalog").as_posix() for j in shard_jobs(cfg))
    want = sorted(f"catalog/paper_triangles/{pid}/{model}/mu_c={mu}{'' if v == '0.0' else '_v_pin=' + v}.h5"
                  for pid in ("asym_triangle-e6ce061196", "sym_triangle-1264dca961")
                  for model in ("minpower", "tip")
                  for mu in ("0.0", "0.15", "0.3") for v in ("0.0", "-2.0", "-1.0", "1.0", "2.0"))
    assert got == want and len(got) == 60


@pytest.mark.parametrize("supports, models, match", [
    (["uniform", "tripod"], ["tip"], "tripod needs minpower in sweep/models"),
    (["tripod", "tripod "], ["minpower"], "the same support"),
    (["rim:8", "rim 8"], ["minpower"], "the same support"),
])
def test_bad_supports_list_is_one_line(supports, models, match):
    cfg = dict(json.loads(json.dumps(TINY)), catalog_dir="cat")
    cfg["sweep"].update(supports=supports, models=models)
    with pytest.raises(PinfeedError, match=match) as exc:
        validate_config(cfg)
    assert "\n" not in str(exc.value) and str(exc.value).startswith("config error at sweep/supports")


def test_shard_missing_an_attribute_is_damaged_not_a_crash(swept, tmp_path):
    """A readable shard missing an attribute the index needs is a problem of the
    rebuilt index (it used to escape as a KeyError)."""
    import h5py
    root = _copy(swept, tmp_path)
    shard = root / "fam" / TRI.id / "minpower" / f"mu_c=0.2_support={support_key(POINTS)}.h5"
    with h5py.File(shard, "r+") as fh:
        del fh.attrs["pin_radius"]
    cat = Catalog.rebuild(root)
    assert len(cat.problems) == 1 and "damaged attributes (KeyError" in cat.problems[0]
    with pytest.raises(PinfeedError, match=support_key(POINTS)):
        Catalog.open(root).query("tri", mu_c=0.2, support=POINTS)


def test_planner_maps_are_not_taken_from_a_support_shard(swept, tmp_path):
    """ensure_maps (pinfeed plan on a part) wants uniform maps: a tripod shard at
    the planner's friction does not stand in for them."""
    from pipeline.workflow.plan import ensure_maps
    root = _copy(swept, tmp_path)
    (root / "fam" / TRI.id / "minpower" / "mu_c=0.2.h5").unlink()
    Catalog.rebuild(root)
    cfg = dict(swept, catalog_dir=str(root), planner=dict(swept["planner"], mu_c=0.2, model="minpower"))
    cfg["planner"]["dynamic"] = dict(cfg["planner"]["dynamic"], speeds=[])
    cat = ensure_maps(cfg, TRI, family="fam")
    assert (root / "fam" / TRI.id / "minpower" / "mu_c=0.2.h5").is_file()
    assert str(cat.query("tri", mu_c=0.2)["support"].values) == "uniform"


def test_cli_show_selects_a_support(swept, capsys):
    code, out, err = run_cli(capsys, ["catalog", "show", "tri", "--catalog", swept["catalog_dir"],
                                      "--support", "tripod", "--json"])
    assert code == 0, err
    assert [(s["model"], s["support"]) for s in json.loads(out)["shards"]] == [("minpower", "tripod")]
    code, out, _ = run_cli(capsys, ["catalog", "show", "tri", "--catalog", swept["catalog_dir"]])
    assert code == 0 and out.count("support ") == 2  # tripod and points named, uniform rows plain
    code, _, err = run_cli(capsys, ["catalog", "show", "tri", "--catalog", swept["catalog_dir"],
                                    "--support", "rim:8"])
    last = err.strip().splitlines()[-1]
    assert code == 2 and len(err.strip().splitlines()) == 1
    assert last.startswith("pinfeed: error: part 'tri' has no maps on support 'rim:8'; stored supports: uniform")
