"""Snakemake script: the HTML page linking every result."""
from pipeline.logs import log_to
from pipeline.workflow.report import make_report

with log_to(snakemake.log[0]):  # noqa: F821
    make_report(snakemake.config, snakemake.input.plans, snakemake.input.verify,  # noqa: F821
                snakemake.output.report,  # noqa: F821
                sensing_paths=snakemake.input.get("sensing", []),  # noqa: F821
                speed_paths=snakemake.input.get("speed", []),  # noqa: F821
                support_paths=snakemake.input.get("support", []),  # noqa: F821
                atlas_path=snakemake.input.get("atlas"))  # noqa: F821
