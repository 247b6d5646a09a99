"""Snakemake script: band maps, sequence diagrams and the verification table."""
from pipeline.logs import log_to
from pipeline.workflow.report import make_figures

with log_to(snakemake.log[0]):  # noqa: F821
    out = snakemake.output  # noqa: F821
    make_figures(snakemake.config, snakemake.input.plans, snakemake.input.verify,  # noqa: F821
                 {key: getattr(out, key) for key in
                  ("maps", "speeds", "sequence", "sequence_dynamic", "sequence_tight", "carried",
                   "verification_plans",
                   "verification", "table")})
