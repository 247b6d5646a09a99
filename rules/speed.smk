# Stage 5c: how fast may each plan run? The recommended tight plan
# of every planned part replayed with the dynamic model at belt speeds: its
# success against speed (a figure) and its speed limit (JSON, in the report).


rule speed:
    input:
        plan=rules.plan.output.plan,
    output:
        speed=f"{RESULTS}/speed/{{name}}.json",
        figure=report(f"{RESULTS}/figures/speed_limit_{{name}}.png", caption="report/speed_limit.rst",
                      category="Plans"),
    params:
        settings={k: config[k] for k in ("speed", "verify")},
        pin_radius=config["sweep"]["pin_radius"],
    log:
        f"{LOGS}/speed/{{name}}.log",
    benchmark:
        f"{LOGS}/benchmark/speed/{{name}}.tsv"
    conda:
        "envs/pinfeed.yaml"
    script:
        "scripts/speed.py"
