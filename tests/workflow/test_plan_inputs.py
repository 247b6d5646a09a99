"""The plan job reads exactly the shards it declares: the atlas needs those alone."""
from __future__ import annotations

import re

import yaml

from pipeline.config import validate_config
from pipeline.maps.sweep import shard_jobs
from pipeline.parts.part import Part
from pipeline.workflow.plan import planner_shards
from workflow_runs import run_snakemake

VERTS = [[0, 0], [40, 0], [10, 25]]
TRI = Part.from_vertices(VERTS, name="tri")
SQUARE = Part.from_vertices([[0, 0], [30, 0], [30, 30], [0, 30]], name="square")

CONFIG = {
    "catalog_dir": "cat", "results_dir": "res",
    "families": {"fam": {"parts": [{"name": "tri", "vertices": VERTS},
                                   {"name": "square", "vertices": SQUARE.vertices.tolist()}]}},
    "sweep": {"models": ["minpower", "tip"], "mu_c": [0.1, 0.2, 0.3], "v_pin": [0.0, -1.0, 1.0, 2.0],
              "d": [-0.4, 0.3], "theta_step": 10.0, "pin_radius": 3.0, "supports": ["uniform", "tripod"]},
    "planner": {"parts": ["tri"], "model": "minpower", "mu_c": "0.2:0.3", "depth": 1,
                "dynamic": {"speeds": [-1.0, 1.0], "depth": 1}},
}


def _config():
    return validate_config(yaml.safe_load(yaml.safe_dump(CONFIG)), name="inputs")


def test_the_plan_reads_its_model_friction_and_speeds_only():
    """Of 2 parts x 2 models x 3 frictions x 4 pin speeds (+ tripod shards), the
    plan of the triangle reads its minpower shards at the sweep friction
    nearest the planner's (0.25 -> 0.2, the lower on a tie, as the catalog
    query picks) with a static pin and the two planner speeds: three shards."""
    config = _config()
    jobs = {str(job.path(config["catalog_dir"])): job for job in shard_jobs(config)}
    want = [f"cat/fam/{TRI.id}/minpower/{tag}.h5" for tag in ("mu_c=0.2", "mu_c=0.2_v_pin=-1.0", "mu_c=0.2_v_pin=1.0")]
    assert sorted(want) == planner_shards(config, jobs, "tri")
    assert all(path in jobs for path in want)
    config["planner"]["mu_c"] = 0.29  # nearest is 0.3
    assert all("mu_c=0.3" in p for p in planner_shards(config, jobs, "tri"))
    assert planner_shards(config, jobs, "no_such_part") == []


def test_the_atlas_target_builds_the_planner_shards_only(tmp_path):
    """A dry run to the atlas schedules the three shards the plan reads and no
    other shard, and no catalog index."""
    (tmp_path / "inputs.yaml").write_text(yaml.safe_dump(CONFIG))
    dry = run_snakemake(tmp_path, "--configfile", str(tmp_path / "inputs.yaml"), "--dry-run",
                        "res/inputs/atlas.json")
    assert dry.returncode == 0, dry.stderr[-3000:]
    text = dry.stdout + dry.stderr
    shards = sorted(set(re.findall(r"cat/fam/[^\s,]+\.h5", text)))
    assert shards == sorted(f"cat/fam/{TRI.id}/minpower/{tag}.h5"
                            for tag in ("mu_c=0.2", "mu_c=0.2_v_pin=-1.0", "mu_c=0.2_v_pin=1.0"))
    assert "catalog_index" not in text


def test_a_plan_with_no_maps_to_read_says_which_model_is_missing(tmp_path):
    """A sweep without the planner's model gives the plan no shard: the job
    fails with one line naming the model to add, and writes no plan file."""
    import pytest

    from pipeline.errors import PinfeedError
    from pipeline.workflow.plan import plan
    config = _config()
    config["sweep"]["models"] = ["tip"]
    jobs = {str(job.path(config["catalog_dir"])): job for job in shard_jobs(config)}
    shards = planner_shards(config, jobs, "tri")
    assert shards == []
    with pytest.raises(PinfeedError, match="add minpower to sweep.models"):
        plan(config, "tri", tmp_path / "tri.json", shards=shards)
    assert not (tmp_path / "tri.json").exists()


def test_the_figures_take_every_uniform_shard_of_the_planned_parts(tmp_path):
    """The figures draw every model and pin speed of a planned part, so their job
    takes all its uniform shards (2 models x 3 frictions x 4 speeds), not the
    tripod shards nor those of the part that is not planned."""
    (tmp_path / "inputs.yaml").write_text(yaml.safe_dump(CONFIG))
    dry = run_snakemake(tmp_path, "--dry-run", "res/inputs/verification.md",
                        "--configfile", str(tmp_path / "inputs.yaml"))
    assert dry.returncode == 0, dry.stderr[-3000:]
    text = (dry.stdout + dry.stderr).split("rule figures:", 1)[1]
    inputs = next(line for line in text.splitlines() if line.strip().startswith("input:"))
    shards = set(re.findall(r"cat/fam/[^\s,]+\.h5", inputs))
    assert len(shards) == 2 * 3 * 4
    assert all(f"/{TRI.id}/" in s and "support" not in s for s in shards)
