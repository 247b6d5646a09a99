"""Snakemake script: replay the best plans of one part with perturbed full rollouts."""
import sys
from pathlib import Path

# The repository is the workflow: make its pipeline importable under --use-conda too.
sys.path.insert(0, str(Path(snakemake.scriptdir).resolve().parents[1]))  # noqa: F821

from pipeline.logs import log_to
from pipeline.workflow.stages import read_json, verify_part, write_json

with log_to(snakemake.log[0]):  # noqa: F821
    result = verify_part(read_json(snakemake.input.plan), snakemake.config)  # noqa: F821
    write_json(result, snakemake.output.verify)  # noqa: F821
    for check in result["checks"]:
        for row in check["rows"]:
            print(check["kind"], check["plan"], row)
