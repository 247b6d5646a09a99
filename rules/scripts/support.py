"""Snakemake script: one part's plans against the support family."""
from pipeline.logs import log_to
from pipeline.workflow.supports import support_part, support_summary_text

with log_to(snakemake.log[0]):  # noqa: F821
    result = support_part(snakemake.input.plan, snakemake.config,  # noqa: F821
                          snakemake.output.support, snakemake.output.figure)  # noqa: F821
    print(support_summary_text(result))
