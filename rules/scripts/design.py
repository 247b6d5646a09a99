"""Snakemake script: design for feeding for one planned part."""
from pipeline.logs import log_to
from pipeline.workflow.design import design_rule

with log_to(snakemake.log[0]):  # noqa: F821
    result = design_rule(snakemake.config, snakemake.wildcards.name, snakemake.input.plan,  # noqa: F821
                         snakemake.output.design)  # noqa: F821
    print(f"{result['part']['name']}: {result['outcome']}")
