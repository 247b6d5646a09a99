# Stage 5d: plans against a support family. Per studied part: how far
# the family moves theta_f from uniform pressure over the sweep's map grid,
# whether the recommended plan survives the family, and if not, the plan that
# does (JSON, in the report), with the maps of the family's extremes overlaid.


rule support:
    input:
        plan=rules.plan.output.plan,
    output:
        support=f"{RESULTS}/support/{{name}}.json",
        figure=report(f"{RESULTS}/figures/support_maps_{{name}}.png", caption="report/support_maps.rst",
                      category="Configuration maps"),
    params:
        settings={k: config[k] for k in ("support_study", "sweep", "planner", "verify")},
    log:
        f"{LOGS}/support/{{name}}.log",
    conda:
        "envs/pinfeed.yaml"
    script:
        "scripts/support.py"
