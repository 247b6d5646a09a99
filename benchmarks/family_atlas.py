"""Time a whole family's feedability atlas end to end: sweep, plans, speed
limits, layouts, atlas, through the Snakemake workflow, and say what each
stage and each job cost.

    .venv/bin/python benchmarks/family_atlas.py [--config config/workstation.yaml]
        [--cores 2] [--sweep planner|config] [--profile profiles/slurm] [--workdir DIR]

It runs ``snakemake`` on the atlas target (``results/NAME/atlas.json``) in a
fresh working folder, then reads the per-job ``benchmark:`` files every rule
writes (wall ``s``, ``cpu_time``, ``max_rss``) and prints, per stage: jobs,
wall and CPU time, the peak memory of one job and the slowest job; the whole
run's wall and CPU time; and a projection to N cores made from the measured
per-job CPU times (each job's CPU time over its threads as its duration, each
stage's jobs packed longest-first onto N cores, stages one after another).

The atlas target needs only the shards the plans read (each part's planner
model at the sweep friction nearest the planner's, a static pin and each
moving-pin speed: ``pipeline.workflow.plan.planner_shards``), so
``--sweep config`` (the default) runs the config as written and sweeps those
alone. ``--sweep planner`` also cuts the config's sweep to the planner's
model, its nominal friction exactly and its speeds (a catalog of those maps
only). ``--shards-only`` stops after the sweep (``catalog/index.json``: every
shard the config lists), to time the whole sweep alone.

``--profile profiles/slurm`` submits every job through SLURM (a cluster or
the one-node test cluster of ``tests/cluster/slurm_up.sh``); per-job numbers
then come from the same benchmark files, written on the nodes.

``--json FILE`` also writes the numbers as JSON. Numbers quoted in the docs'
performance pages come from this script.
"""
from __future__ import annotations

import argparse
import copy
import csv
import json
import os
import platform
import resource
import shlex
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import yaml

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from pipeline.config import config_name, load_config  # noqa: E402
from pipeline.planning import PlannerSettings  # noqa: E402

# Stage of each rule on the way to the atlas that writes a benchmark file, in the order they run.
STAGES = ["sweep_shard", "plan", "speed", "layout", "atlas"]


def planner_sweep(config: dict) -> dict:
    """The config with its sweep cut to the maps the planner reads."""
    config = copy.deepcopy(config)
    pc = config["planner"]
    # every listed speed, even at dynamic depth 0: the paper-mode planner loads them all
    speeds = [float(v) for v in (pc.get("dynamic") or {}).get("speeds", [])]
    config["sweep"].update(models=[pc["model"]], mu_c=[PlannerSettings.from_config(config).friction.nominal],
                           v_pin=[0.0] + speeds)
    config["sweep"].pop("supports", None)
    return config


def run_workflow(workdir: Path, config_path: Path, name: str, cores: int, profile: str | None,
                 shards_only: bool, extra: list[str] = ()) -> tuple[float, float, int]:
    """Run Snakemake to the atlas (or the catalog index); (wall s, children's CPU s, exit status)."""
    target = "catalog/index.json" if shards_only else f"results/{name}/atlas.json"
    cmd = [sys.executable, "-m", "snakemake", "--snakefile", str(ROOT / "Snakefile"),
           "--directory", str(workdir), "--configfile", str(config_path), "--cores", str(cores),
           "--rerun-incomplete", *extra, target]
    if profile:
        cmd[cmd.index("--cores"):cmd.index("--cores") + 2] = ["--profile", str(ROOT / profile)]
    env = {**os.environ, "PYTHONPATH": str(ROOT), "PATH": f"{Path(sys.executable).parent}:{os.environ['PATH']}"}
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    status = subprocess.call(cmd, cwd=workdir, env=env)
    wall = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return wall, cpu, status


def read_jobs(workdir: Path, name: str) -> list[dict]:
    """One row per job from the rules' benchmark files: rule, job, wall s, CPU s, peak RSS MB."""
    rows = []
    for rule, pattern in (("sweep_shard", "logs/benchmark/sweep/**/*.tsv"),
                          ("plan", f"logs/{name}/benchmark/plan/*.tsv"),
                          ("speed", f"logs/{name}/benchmark/speed/*.tsv"),
                          ("layout", f"logs/{name}/benchmark/layout/*.tsv"),
                          ("atlas", f"logs/{name}/benchmark/atlas.tsv")):
        for path in sorted(workdir.glob(pattern)):
            with open(path) as fh:
                row = next(csv.DictReader(fh, delimiter="\t"))
            job = str(path.relative_to(workdir / "logs")).removesuffix(".tsv").replace("benchmark/", "")
            rows.append({"rule": rule, "job": job,
                         "wall_s": float(row["s"]), "cpu_s": _number(row.get("cpu_time")),
                         "max_rss_mb": _number(row.get("max_rss"))})
    return rows


def _number(text) -> float:
    try:
        return float(text)
    except (TypeError, ValueError):
        return float("nan")


def stage_table(jobs: list[dict]) -> list[dict]:
    """Per stage: jobs, wall and CPU sums, peak RSS of one job, the slowest job."""
    table = []
    for rule in STAGES:
        rows = [j for j in jobs if j["rule"] == rule]
        if not rows:
            continue
        slowest = max(rows, key=lambda j: j["wall_s"])
        table.append({"stage": rule, "jobs": len(rows), "wall_sum_s": round(sum(j["wall_s"] for j in rows), 1),
                      "cpu_sum_s": round(sum(j["cpu_s"] for j in rows), 1),
                      "peak_rss_mb": round(max(j["max_rss_mb"] for j in rows), 1),
                      "slowest_job": slowest["job"], "slowest_wall_s": round(slowest["wall_s"], 1),
                      "slowest_cpu_s": round(slowest["cpu_s"], 1)})
    return table


def job_seconds(job: dict) -> float:
    """A job's duration on one core of its own: its CPU time (robust on a loaded
    machine, where wall time is not; a job of 2 threads holds 2 cores for
    about half as long); its wall time where no CPU time was recorded."""
    cpu = job["cpu_s"]
    return cpu if cpu == cpu and cpu > 0 else job["wall_s"]


def projection(jobs: list[dict], cores: int) -> float:
    """Seconds to run these jobs on ``cores`` cores: per stage, jobs of
    :func:`job_seconds` packed longest-first onto the cores, stages one after
    another. It ignores Snakemake's own overhead and any slow-down from jobs
    sharing memory bandwidth."""
    total = 0.0
    for rule in STAGES:
        durations = sorted((job_seconds(j) for j in jobs if j["rule"] == rule), reverse=True)
        slots = [0.0] * max(1, cores)
        for d in durations:
            i = slots.index(min(slots))
            slots[i] += d
        total += max(slots) if durations else 0.0
    return total


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--config", default=str(ROOT / "config" / "workstation.yaml"))
    ap.add_argument("--cores", type=int, default=2)
    ap.add_argument("--sweep", choices=["planner", "config"], default="config")
    ap.add_argument("--shards-only", action="store_true")
    ap.add_argument("--profile", default=None, help="a Snakemake profile, e.g. profiles/slurm")
    ap.add_argument("--snakemake-args", default="",
                    help="more Snakemake options, e.g. \"--slurm-status-command squeue\" for a cluster "
                         "without accounting")
    ap.add_argument("--workdir", default=None, help="working folder (default: a fresh temporary one)")
    ap.add_argument("--project", default="2,4,8,16,32,64", help="core counts to project to")
    ap.add_argument("--no-run", action="store_true",
                    help="only read the benchmark files of an earlier run in --workdir")
    ap.add_argument("--json", default=None, help="also write the numbers to this JSON file")
    args = ap.parse_args()

    name = config_name(args.config)
    config = load_config(args.config)
    if args.sweep == "planner":
        config = planner_sweep(config)
    config["name"] = name
    workdir = Path(args.workdir or tempfile.mkdtemp(prefix="family_atlas_"))
    workdir.mkdir(parents=True, exist_ok=True)
    config_path = workdir / f"{name}.yaml"
    config_path.write_text(yaml.safe_dump(config, sort_keys=False))
    parts = config["planner"]["parts"]
    print(f"family atlas: {args.config} ({len(parts)} planned parts), sweep {args.sweep}, "
          f"{'profile ' + args.profile if args.profile else f'{args.cores} cores'}, in {workdir}", flush=True)

    if args.no_run:  # an earlier run's benchmark files only
        wall, cpu, status = float("nan"), float("nan"), 0
    else:
        wall, cpu, status = run_workflow(workdir, config_path, name, args.cores, args.profile,
                                         args.shards_only, shlex.split(args.snakemake_args))
    jobs = read_jobs(workdir, name)
    table = stage_table(jobs)
    result = {"config": args.config, "sweep": args.sweep, "parts": len(parts), "cores": args.cores,
              "profile": args.profile, "exit_status": status, "wall_s": round(wall, 1),
              "cpu_s_children": round(cpu, 1), "machine": f"{platform.machine()}, {os.cpu_count()} CPUs",
              "date": time.strftime("%Y-%m-%d"), "stages": table,
              "projection_s": {int(n): round(projection(jobs, int(n)), 1) for n in args.project.split(",")},
              "jobs": jobs}
    print(f"exit status {status}; wall {wall / 60:.1f} min, CPU {cpu / 60:.1f} min (all child processes)")
    print(f"{'stage':<13}{'jobs':>5}{'wall s':>10}{'CPU s':>10}{'peak MB':>9}  slowest job (wall s, CPU s)")
    for s in table:
        print(f"{s['stage']:<13}{s['jobs']:>5}{s['wall_sum_s']:>10.1f}{s['cpu_sum_s']:>10.1f}{s['peak_rss_mb']:>9.0f}"
              f"  {s['slowest_job']} ({s['slowest_wall_s']:.1f}, {s['slowest_cpu_s']:.1f})")
    print("projection from per-job CPU times: "
          + ", ".join(f"{n} cores {v / 60:.1f} min" for n, v in result["projection_s"].items()))
    if args.json:
        Path(args.json).write_text(json.dumps(result, indent=1))
    if status != 0:
        sys.exit(status)


if __name__ == "__main__":
    main()
