"""Snakemake script: F/T profiles (paper's Table 3) and score matrix (Table 4) of one part."""
from pipeline.logs import log_to
from pipeline.workflow.sense import sensing_figures

with log_to(snakemake.log[0]):  # noqa: F821
    out = snakemake.output  # noqa: F821
    sensing_figures(snakemake.input.sensing, out.profiles, out.scores)  # noqa: F821
    print(f"wrote {out.profiles} and {out.scores}")
