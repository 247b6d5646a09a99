"""Snakemake script: the outline figure of one planned part."""
from pipeline.logs import log_to
from pipeline.workflow.report import outline

with log_to(snakemake.log[0]):  # noqa: F821
    path = outline(snakemake.input.plan, snakemake.config, snakemake.output.outline)  # noqa: F821
    print(f"wrote {path}")
