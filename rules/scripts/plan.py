"""Snakemake script: the fixed-pins planner for one part."""
from pipeline.logs import log_to
from pipeline.workflow.plan import plan

with log_to(snakemake.log[0]):  # noqa: F821
    result = plan(snakemake.config, snakemake.wildcards.name, snakemake.output.plan,  # noqa: F821
                  shards=list(snakemake.input.shards))  # noqa: F821
    for p in result["plans"]:
        print(p["pins"], p["n_final_sets"], p["final_sets"], p["margin"])
