"""Snakemake script: compute one shard (thin: the work is in pipeline.maps.sweep)."""
from pipeline.logs import log_to
from pipeline.workflow.sweep import sweep_shard

w = snakemake.wildcards  # noqa: F821 (injected by Snakemake)
with log_to(snakemake.log[0]):  # noqa: F821
    path = sweep_shard(snakemake.config, w.family, w.part, w.model, w.tag,  # noqa: F821
                       out=snakemake.output.shard, threads=snakemake.threads)  # noqa: F821
    print(f"wrote {path}")
