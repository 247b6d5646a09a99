"""Snakemake script: the force/torque sensor on the first pin for one planned part."""
import sys
from pathlib import Path

# The repository is the workflow: make its pipeline importable under --use-conda too.
sys.path.insert(0, str(Path(snakemake.scriptdir).resolve().parents[1]))  # noqa: F821

from pipeline.catalog import Catalog
from pipeline.logs import log_to
from pipeline.sensor_plan import sense_part
from pipeline.stages import write_json

with log_to(snakemake.log[0]):  # noqa: F821
    cat = Catalog.open(snakemake.config["catalog_dir"])  # noqa: F821
    result = sense_part(cat, snakemake.wildcards.name, snakemake.config)  # noqa: F821
    write_json(result, snakemake.output.sensing)  # noqa: F821
    if result["found"]:
        print(f"sensor on {result['first_pin']} ({result['y_pin']:g} mm), plan {result['plan']['pins']}: "
              f"worst {result['worst_sets']} final set(s) per verdict; groups "
              f"{[g['states'] for g in result['groups']]}")
