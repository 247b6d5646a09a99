"""Snakemake script: rebuild the catalog index from the shards on disk."""
from pipeline.logs import log_to
from pipeline.workflow.catalog import catalog_index

with log_to(snakemake.log[0]):  # noqa: F821
    cat = catalog_index(snakemake.config)  # noqa: F821
    print(f"indexed {len(cat.entries)} shards")
    for problem in cat.problems:
        print(f"problem: {problem}")
