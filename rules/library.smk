# A parts library (config key library): one job reads each drawing, one job
# plans each part (its only input: its own drawing), then the library's page,
# JSON and CSV (pipeline/workflow/library.py says how and why).
from pipeline.workflow.library import drawing_lookup, library_plan, part_runtime

LIBRARY = library_plan(config)
LIB = f"{RESULTS}/library"
LIBRARY_TARGETS = [f"{RESULTS}/library.html"] if LIBRARY["drawings"] else []


# input functions and runtimes (pipeline/workflow/library.py)
library_drawing = drawing_lookup(LIBRARY)
library_runtime = part_runtime(config)


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
