# Stage 8: the feedability atlas: one row per planned part from its
# plan, speed limit and layout files, as JSON and CSV; the report opens with it.


rule atlas:
    input:
        plans=expand(f"{RESULTS}/plans/{{name}}.json", name=PLANNED),
        speed=expand(f"{RESULTS}/speed/{{name}}.json", name=PLANNED),
        layouts=expand(f"{RESULTS}/layout_{{name}}.json", name=PLANNED),
    output:
        json=f"{RESULTS}/atlas.json",
        csv=f"{RESULTS}/atlas.csv",
    log:
        f"{LOGS}/atlas.log",
    benchmark:
        f"{LOGS}/benchmark/atlas.tsv"
    conda:
        "envs/pinfeed.yaml"
    script:
        "scripts/atlas.py"
