"""Snakemake script: replay the best plans of one part with perturbed full rollouts."""
from pipeline.logs import log_to
from pipeline.workflow.plan import verify

with log_to(snakemake.log[0]):  # noqa: F821
    result = verify(snakemake.input.plan, snakemake.config, snakemake.output.verify)  # noqa: F821
    for check in result["checks"]:
        for row in check["rows"]:
            print(check["kind"], check["plan"], row)
