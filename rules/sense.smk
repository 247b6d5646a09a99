# Stage 5b: a force/torque sensor on the first pin (spec section 7): score
# table, sensor plan with the final set per verdict, and its two figures. The
# sensor plan is chosen among the stored tight plans (no search of its own).
SENSED = config["sensing"]["parts"]


rule sense:
    input:
        plan=rules.plan.output.plan,
    output:
        sensing=f"{RESULTS}/sensing/{{name}}.json",
    params:
        settings={k: config[k] for k in ("sensing", "verify")},
        sweep={k: config["sweep"][k] for k in ("pin_radius", "kernel")},
    log:
        f"{LOGS}/sense/{{name}}.log",
    benchmark:
        f"{LOGS}/benchmark/sense/{{name}}.tsv"
    conda:
        "envs/pinfeed.yaml"
    script:
        "scripts/sense.py"


rule sensing_figures:
    input:
        sensing=rules.sense.output.sensing,
    output:
        profiles=report(f"{RESULTS}/figures/profiles_{{name}}.png", caption="report/profiles.rst",
                        category="Sensing"),
        scores=report(f"{RESULTS}/figures/scores_{{name}}.png", caption="report/scores.rst",
                      category="Sensing"),
    log:
        f"{LOGS}/sense/figures_{{name}}.log",
    benchmark:
        f"{LOGS}/benchmark/sensing_figures/{{name}}.tsv"
    conda:
        "envs/pinfeed.yaml"
    script:
        "scripts/sensing_figures.py"
