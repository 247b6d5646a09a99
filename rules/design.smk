# Design for feeding, its own target (not part of rule all): per planned part,
# the smallest chamfer, notch or tab that lets fixed pins orient it
# (config key design; pinfeed design does the same for one outline). A part
# whose plan file says that its plan orients it gets a short design file
# saying so, without a search; the others are searched, one job each.
#
#   snakemake --cores all design


rule design_part:
    input:
        plan=rules.plan.output.plan,
    output:
        design=f"{RESULTS}/designs/{{name}}.json",
    params:
        settings={k: config[k] for k in ("design", "planner", "verify")},
    log:
        f"{LOGS}/design/{{name}}.log",
    benchmark:
        f"{LOGS}/benchmark/design/{{name}}.tsv"
    conda:
        "envs/pinfeed.yaml"
    script:
        "scripts/design.py"


rule design:
    input:
        expand(rules.design_part.output.design, name=PLANNED),
