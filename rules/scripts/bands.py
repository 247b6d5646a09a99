"""Snakemake script: bands, kernels, COM intervals, adjusted bands of every
shard (input ``shards``, output ``bands`` in the same order), in one process."""
from pipeline.logs import log_to
from pipeline.workflow.plan import bands

with log_to(snakemake.log[0]):  # noqa: F821
    for shard, out in zip(snakemake.input.shards, snakemake.output.bands, strict=True):  # noqa: F821
        result = bands(shard, snakemake.params.bands, out)  # noqa: F821
        print(f"{out}: bands of {len(result['maps'])} maps")
