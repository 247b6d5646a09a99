# Stage 5d, its own target: plans against a support family. Per studied part:
# how far the family moves theta_f from uniform pressure over the sweep's map
# grid, whether the recommended plan survives the family, and if not, the plan
# that does (JSON), with the maps of the family's extremes overlaid; and the
# report with its section (report_support.html). Not part of rule all: on the
# default config it costs about an hour of CPU (docs/howto/support-family.md).
#
#   make support-study        (snakemake --cores all support_study)


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
    benchmark:
        f"{LOGS}/benchmark/support/{{name}}.tsv"
    conda:
        "envs/pinfeed.yaml"
    script:
        "scripts/support.py"


# The report of rule report plus the "Support distributions" section of each
# studied part, beside it (the report of `make run` stays without it).
rule report_support:
    input:
        **REPORT_INPUTS,
        support=expand(rules.support.output.support, name=STUDIED),
        support_figures=expand(rules.support.output.figure, name=STUDIED),
    output:
        report=f"{RESULTS}/report_support.html",
    log:
        f"{LOGS}/report_support.log",
    benchmark:
        f"{LOGS}/benchmark/report_support.tsv"
    conda:
        "envs/pinfeed.yaml"
    script:
        "scripts/report.py"


rule support_study:
    input:
        rules.report_support.output.report,
