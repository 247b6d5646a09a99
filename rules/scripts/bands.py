"""Snakemake script: bands, kernels, COM intervals, adjusted bands of one shard."""
from pipeline.logs import log_to
from pipeline.workflow.plan import bands

with log_to(snakemake.log[0]):  # noqa: F821
    result = bands(snakemake.input.shard, snakemake.params.bands, snakemake.output.bands)  # noqa: F821
    print(f"bands of {len(result['maps'])} maps")
