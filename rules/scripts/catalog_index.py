"""Snakemake script: rebuild the catalog index from the shards on disk."""
import sys
from pathlib import Path

# The repository is the workflow: make its pipeline importable under --use-conda too.
sys.path.insert(0, str(Path(snakemake.scriptdir).resolve().parents[1]))  # noqa: F821

from pipeline.maps.catalog import Catalog
from pipeline.logs import log_to

with log_to(snakemake.log[0]):  # noqa: F821
    cat = Catalog.rebuild(snakemake.config["catalog_dir"])  # noqa: F821
    print(f"indexed {len(cat.entries)} shards")
    for problem in cat.problems:
        print(f"problem: {problem}")
