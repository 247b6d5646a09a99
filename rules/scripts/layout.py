"""Snakemake script: the feeder layout of one part's first fixed-pin tight plan."""
import sys
from pathlib import Path

# The repository is the workflow: make its pipeline importable under --use-conda too.
sys.path.insert(0, str(Path(snakemake.scriptdir).resolve().parents[1]))  # noqa: F821

from pipeline.present.layout import layout_part
from pipeline.logs import log_to
from pipeline.workflow.stages import read_json

with log_to(snakemake.log[0]):  # noqa: F821
    out = snakemake.output  # noqa: F821
    done = layout_part(read_json(snakemake.input.plan), snakemake.config,  # noqa: F821
                       {"json": out.layout, "dxf": out.dxf, "svg": out.svg, "png": out.png})
    print(done)
