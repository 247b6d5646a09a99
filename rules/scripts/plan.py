"""Snakemake script: the fixed-pins planner for one part."""
import sys
from pathlib import Path

# The repository is the workflow: make its pipeline importable under --use-conda too.
sys.path.insert(0, str(Path(snakemake.scriptdir).resolve().parents[1]))  # noqa: F821

from pipeline.maps.catalog import Catalog
from pipeline.logs import log_to
from pipeline.workflow.stages import plan_part, write_json

with log_to(snakemake.log[0]):  # noqa: F821
    cat = Catalog.open(snakemake.config["catalog_dir"])  # noqa: F821
    result = plan_part(cat, snakemake.wildcards.name, snakemake.config)  # noqa: F821
    write_json(result, snakemake.output.plan)  # noqa: F821
    for plan in result["plans"]:
        print(plan["pins"], plan["n_final_sets"], plan["final_sets"], plan["margin"])
