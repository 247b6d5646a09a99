# Stage 6: figures, outlines, animations and the page that links every result.
# Figures are marked with report() (captions in rules/report/) for 'snakemake --report'.


rule figures:
    input:
        # the maps drawn: every uniform shard of the planned parts (the plans read fewer)
        shards=figure_shards,
        index=ancient(rules.catalog_index.output.index),
        plans=expand(f"{RESULTS}/plans/{{name}}.json", name=PLANNED),
        verify=expand(f"{RESULTS}/verify/{{name}}.json", name=PLANNED),
    output:
        maps=report(expand(f"{RESULTS}/figures/maps_{{name}}.png", name=PLANNED),
                    caption="report/maps.rst", category="Configuration maps"),
        speeds=report(expand(f"{RESULTS}/figures/speeds_{{name}}.png", name=PLANNED),
                      caption="report/speeds.rst", category="Configuration maps"),
        sequence=report(expand(f"{RESULTS}/figures/sequence_{{name}}.png", name=PLANNED),
                        caption="report/sequence.rst", category="Plans"),
        sequence_dynamic=report(expand(f"{RESULTS}/figures/sequence_dynamic_{{name}}.png", name=PLANNED),
                                caption="report/sequence_dynamic.rst", category="Plans"),
        sequence_tight=report(expand(f"{RESULTS}/figures/sequence_tight_{{name}}.png", name=PLANNED),
                              caption="report/sequence_tight.rst", category="Plans"),
        carried=report(expand(f"{RESULTS}/figures/carried_{{name}}.png", name=PLANNED),
                       caption="report/carried.rst", category="Plans"),
        verification_plans=report(expand(f"{RESULTS}/figures/verification_{{name}}.png", name=PLANNED),
                                  caption="report/verification_plans.rst", category="Verification"),
        verification=report(f"{RESULTS}/figures/verification.png",
                            caption="report/verification.rst", category="Verification"),
        table=f"{RESULTS}/verification.md",
    params:
        settings=config["figures"],
    log:
        f"{LOGS}/figures.log",
    benchmark:
        f"{LOGS}/benchmark/figures.tsv"
    conda:
        "envs/pinfeed.yaml"
    script:
        "scripts/figures.py"


rule outline:
    input:
        plan=rules.plan.output.plan,
    output:
        outline=report(f"{RESULTS}/figures/outline_{{name}}.png", caption="report/outline.rst",
                       category="Parts"),
    log:
        f"{LOGS}/outline/{{name}}.log",
    benchmark:
        f"{LOGS}/benchmark/outline/{{name}}.tsv"
    conda:
        "envs/pinfeed.yaml"
    script:
        "scripts/outline.py"


rule animate:
    input:
        plan=rules.plan.output.plan,
        # the feeder's stations and pitch (rules/layout.smk, which needs only the plan)
        layout=rules.layout.output.layout,
    output:
        animation=report(f"{RESULTS}/animations/{{name}}.gif", caption="report/animation.rst",
                         category="Animations"),
    params:
        frames=config["figures"]["animation_frames"],
        fps=config["figures"]["animation_fps"],
    log:
        f"{LOGS}/animate/{{name}}.log",
    benchmark:
        f"{LOGS}/benchmark/animate/{{name}}.tsv"
    conda:
        "envs/pinfeed.yaml"
    script:
        "scripts/animate.py"


# What the report reads: everything `make run` makes (the default target, rule
# all). The support study (rules/support.smk) is not among it: it has its own
# target and report (rule support_study, `make support-study`).
REPORT_INPUTS = dict(
    figures=rules.figures.output,
    plans=rules.figures.input.plans,
    verify=rules.figures.input.verify,
    outlines=expand(rules.outline.output.outline, name=PLANNED),
    animations=expand(rules.animate.output.animation, name=PLANNED),
    # feeder layouts (rules/layout.smk): stations, pitch, throughput, drawings
    layouts=expand(rules.layout.output.layout, name=PLANNED),
    layout_drawings=expand(rules.layout.output.png, name=PLANNED),
    # sensing (rules/sense.smk): results and figures of the sensed parts
    sensing=expand(rules.sense.output.sensing, name=SENSED),
    sensing_figures=expand(f"{RESULTS}/figures/{{kind}}_{{name}}.png",
                           kind=("profiles", "scores"), name=SENSED),
    # speed limit (rules/speed.smk): JSON and figure of every planned part
    speed=expand(rules.speed.output.speed, name=PLANNED),
    speed_figures=expand(rules.speed.output.figure, name=PLANNED),
    # the feedability atlas (rules/atlas.smk), shown first
    atlas=rules.atlas.output.json,
)


rule report:
    input:
        **REPORT_INPUTS,
    output:
        report=f"{RESULTS}/report.html",
    log:
        f"{LOGS}/report.log",
    benchmark:
        f"{LOGS}/benchmark/report.tsv"
    conda:
        "envs/pinfeed.yaml"
    script:
        "scripts/report.py"
