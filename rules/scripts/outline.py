"""Snakemake script: the outline figure of one planned part."""
import sys
from pathlib import Path

# The repository is the workflow: make its pipeline importable under --use-conda too.
sys.path.insert(0, str(Path(snakemake.scriptdir).resolve().parents[1]))  # noqa: F821

from pipeline.logs import log_to
from pipeline.workflow.stages import outline_figure, read_json

with log_to(snakemake.log[0]):  # noqa: F821
    path = outline_figure(read_json(snakemake.input.plan), snakemake.config,  # noqa: F821
                          snakemake.output.outline)  # noqa: F821
    print(f"wrote {path}")
