"""Snakemake script: compute one shard (thin: the work is in pipeline.maps.sweep)."""
import sys
from pathlib import Path

# The repository is the workflow: make its pipeline importable under --use-conda too.
sys.path.insert(0, str(Path(snakemake.scriptdir).resolve().parents[1]))  # noqa: F821

from pipeline.logs import log_to
from pipeline.maps.sweep import find_job, write_shard

w = snakemake.wildcards  # noqa: F821 (injected by Snakemake)
with log_to(snakemake.log[0]):  # noqa: F821
    job = find_job(snakemake.config, w.family, w.part, w.model, w.tag)  # noqa: F821
    path = write_shard(snakemake.config, job, out=snakemake.output.shard,  # noqa: F821
                       threads=snakemake.threads)  # noqa: F821
    print(f"wrote {path}")
