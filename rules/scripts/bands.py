"""Snakemake script: bands, kernels, COM intervals, adjusted bands of one shard."""
import sys
from pathlib import Path

# The repository is the workflow: make its pipeline importable under --use-conda too.
sys.path.insert(0, str(Path(snakemake.scriptdir).resolve().parents[1]))  # noqa: F821

from pipeline.logs import log_to
from pipeline.workflow.stages import shard_bands, write_json

with log_to(snakemake.log[0]):  # noqa: F821
    b = snakemake.params.bands  # noqa: F821
    result = shard_bands(snakemake.input.shard, b["threshold_T"], b["factor_c"])  # noqa: F821
    write_json(result, snakemake.output.bands)  # noqa: F821
    print(f"bands of {len(result['maps'])} maps")
