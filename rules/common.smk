# Shared helpers: the shard list and per-shard parameters, from the config.
from snakemake.exceptions import WorkflowError

from pipeline.maps.sweep import shard_jobs
from pipeline.parts.support import support_key
from pipeline.workflow.plan import planner_shards as planner_shard_paths
from pipeline.workflow.supports import studied_parts

CATALOG = config["catalog_dir"]
JOBS = {str(job.path(CATALOG)): job for job in shard_jobs(config)}


wildcard_constraints:
    family="[A-Za-z0-9_]+",
    part="[A-Za-z0-9_]+-[0-9a-f]{10}",
    model="minpower|tip|ellipsoid|dynamic",
    tag="mu_c=[0-9.eE+-]+(_v_pin=[0-9.eE+-]+)?(_belt=[0-9.eE+-]+_mu_s=[0-9.eE+-]+)?(_support=[A-Za-z0-9-]+)?",


def shard_threads() -> int:
    """Threads of a shard job: 2 where the run has 4 cores or more (a shard's
    theta rows run in parallel), else 1, so that two shards run side by side
    on 2 cores (a shard's few CPU seconds are mostly its start)."""
    try:
        cores = workflow.cores
    except WorkflowError:  # no --cores (a cluster executor): the profile's set-threads decides
        return 2
    return 2 if cores >= 4 else 1


def figure_shards(wildcards):
    """The uniform-pressure shards of the planned parts (the figures draw every
    model and pin speed of the sweep at a plan's friction): a recomputed shard
    re-draws them."""
    planned = set(PLANNED)
    return [path for path, job in JOBS.items() if job.part.name in planned and not support_key(job.support)]


def planner_shards(wildcards):
    """The shard files the plan of the part named ``wildcards.name`` reads: its
    planner model at the planner's friction, static and moving pins, uniform
    pressure (adding a support or another model to the sweep re-plans nothing)."""
    return planner_shard_paths(config, JOBS, wildcards.name)


def shard_params(wildcards):
    """Everything a shard's content depends on: changing any of it reruns the shard."""
    path = f"{CATALOG}/{wildcards.family}/{wildcards.part}/{wildcards.model}/{wildcards.tag}.h5"
    job = JOBS[path]
    sweep = config["sweep"]
    return {
        "vertices": job.part.vertices.round(12).tolist(),
        "d": sweep["d"],
        "theta_step": sweep["theta_step"],
        "pin_radius": sweep["pin_radius"],
        "kernel": sweep["kernel"],
        **({"support": job.support} if job.support != "uniform" else {}),
    }


# This config's results (plans, verification, sensing, bands, figures, report):
# results_dir/NAME, so two configs never overwrite each other's. The catalog is shared.
RESULTS = f"{config['results_dir']}/{config['name']}"
LOGS = f"logs/{config['name']}"
PLANNED = config["planner"]["parts"]
BAND_FILES = [
    p.replace(f"{CATALOG}/", f"{RESULTS}/bands/", 1).replace(".h5", ".json") for p in JOBS
]
# Parts whose plans are replayed against the support family (support_study).
STUDIED = studied_parts(config)
