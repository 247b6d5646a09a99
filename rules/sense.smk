# Stage 5b: a force/torque sensor on the first pin (spec section 7): score
# table, sensor plan with the final set per verdict, and its two figures.
SENSED = config["sensing"]["parts"]


rule sense:
    input:
        index=rules.catalog_index.output.index,
        plan=f"{CATALOG}/plans/{{name}}.json",
    output:
        sensing=f"{CATALOG}/sensing/{{name}}.json",
    params:
        settings={k: config[k] for k in ("sensing", "planner", "bands", "verify")},
    log:
        "logs/sense/{name}.log",
    conda:
        "envs/pinfeed.yaml"
    script:
        "scripts/sense.py"


rule sensing_figures:
    input:
        sensing=rules.sense.output.sensing,
    output:
        profiles=f"{RESULTS}/figures/profiles_{{name}}.png",
        scores=f"{RESULTS}/figures/scores_{{name}}.png",
    log:
        "logs/sense/figures_{name}.log",
    conda:
        "envs/pinfeed.yaml"
    script:
        "scripts/sensing_figures.py"
