"""Snakemake script: the feedability atlas of the planned parts (JSON and CSV)."""
from pipeline.logs import log_to
from pipeline.workflow.atlas import atlas

with log_to(snakemake.log[0]):  # noqa: F821
    inp, out = snakemake.input, snakemake.output  # noqa: F821
    result = atlas(snakemake.config, inp.plans, inp.speed, inp.layouts, out.json, out.csv)  # noqa: F821
    for row in result["rows"]:
        print(row["part"], row["outcome"], row["plan"], row["verified_width_deg"])
