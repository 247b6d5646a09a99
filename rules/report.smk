# Stage 6: figures and the page that links every result.


rule figures:
    input:
        index=rules.catalog_index.output.index,
        plans=expand(f"{CATALOG}/plans/{{name}}.json", name=PLANNED),
        verify=expand(f"{CATALOG}/verify/{{name}}.json", name=PLANNED),
    output:
        maps=expand(f"{RESULTS}/figures/maps_{{name}}.png", name=PLANNED),
        speeds=expand(f"{RESULTS}/figures/speeds_{{name}}.png", name=PLANNED),
        sequence=expand(f"{RESULTS}/figures/sequence_{{name}}.png", name=PLANNED),
        sequence_dynamic=expand(f"{RESULTS}/figures/sequence_dynamic_{{name}}.png", name=PLANNED),
        carried=expand(f"{RESULTS}/figures/carried_{{name}}.png", name=PLANNED),
        verification=f"{RESULTS}/figures/verification.png",
        table=f"{RESULTS}/verification.md",
    params:
        settings=config["figures"],
    log:
        "logs/figures.log",
    conda:
        "envs/pinfeed.yaml"
    script:
        "scripts/figures.py"


rule report:
    input:
        rules.figures.output,
        plans=rules.figures.input.plans,
        verify=rules.figures.input.verify,
        # sensing (rules/sense.smk): results and figures of the sensed parts
        sensing=expand(f"{CATALOG}/sensing/{{name}}.json", name=SENSED),
        sensing_figures=expand(f"{RESULTS}/figures/{{kind}}_{{name}}.png",
                               kind=("profiles", "scores"), name=SENSED),
    output:
        report=f"{RESULTS}/report.html",
    log:
        "logs/report.log",
    conda:
        "envs/pinfeed.yaml"
    script:
        "scripts/report.py"
