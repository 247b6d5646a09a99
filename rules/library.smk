# A parts library (config key library): one job reads each drawing, one job
# plans each part (its only input: its own drawing), then the library's page,
# JSON and CSV (pipeline/workflow/library.py says how and why).
from pipeline.workflow.library import library_plan

LIBRARY = library_plan(config)
LIB = f"{RESULTS}/library"
LIBRARY_TARGETS = [f"{RESULTS}/library.html"] if LIBRARY["drawings"] else []


def library_drawing(wildcards):
    """The drawing file a library job reads: the drawing itself, or a part's drawing."""
    if "key" in wildcards.keys():
        return LIBRARY["drawings"][LIBRARY["parts"][wildcards.key]["drawing"]]
    return LIBRARY["drawings"][wildcards.drawing]


def library_runtime(wildcards, attempt):
    """Minutes a part's job may run: its time limit, the steps after it, and Python's start."""
    limit = config.get("library", {}).get("time_limit_s")
    return 120 if limit is None else int(3 + 3 * float(limit) / 60) * attempt


rule library_read:
    input:
        drawing=library_drawing,
    output:
        record=f"{LIB}/drawings/{{drawing}}.json",
    params:
        library=config.get("library"),
    wildcard_constraints:
        drawing="[A-Za-z0-9_][A-Za-z0-9_.-]*",
    log:
        f"{LOGS}/library/read/{{drawing}}.log",
    benchmark:
        f"{LOGS}/benchmark/library_read/{{drawing}}.tsv"
    resources:
        mem_mb=500,
        runtime=5,
    conda:
        "envs/pinfeed.yaml"
    script:
        "scripts/library_read.py"


rule library_part:
    input:
        drawing=library_drawing,
    output:
        folder=directory(f"{LIB}/parts/{{key}}"),
    params:
        label=lambda wildcards: LIBRARY["parts"][wildcards.key]["label"],
        name=lambda wildcards: LIBRARY["parts"][wildcards.key]["name"],
        settings={k: config[k] for k in ("library", "planner", "verify", "speed", "layout") if k in config},
    wildcard_constraints:
        key="[A-Za-z0-9_][A-Za-z0-9_.-]*-[0-9]+",
    log:
        f"{LOGS}/library/part/{{key}}.log",
    benchmark:
        f"{LOGS}/benchmark/library_part/{{key}}.tsv"
    threads: 1
    resources:
        mem_mb=1500,
        runtime=library_runtime,
    conda:
        "envs/pinfeed.yaml"
    script:
        "scripts/library_part.py"


rule library:
    input:
        records=expand(f"{LIB}/drawings/{{drawing}}.json", drawing=list(LIBRARY["drawings"])),
        parts=expand(f"{LIB}/parts/{{key}}", key=list(LIBRARY["parts"])),
    output:
        html=f"{RESULTS}/library.html",
        json=f"{RESULTS}/library.json",
        csv=f"{RESULTS}/library.csv",
    log:
        f"{LOGS}/library/report.log",
    benchmark:
        f"{LOGS}/benchmark/library.tsv"
    resources:
        mem_mb=500,
        runtime=5,
    conda:
        "envs/pinfeed.yaml"
    script:
        "scripts/library_report.py"
