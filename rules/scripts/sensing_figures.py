"""Snakemake script: F/T profiles (paper's Table 3) and score matrix (Table 4) of one part."""
import sys
from pathlib import Path

# The repository is the workflow: make its pipeline importable under --use-conda too.
sys.path.insert(0, str(Path(snakemake.scriptdir).resolve().parents[1]))  # noqa: F821

from pipeline.present.figures.sensing import sensing_figures
from pipeline.logs import log_to
from pipeline.workflow.stages import read_json

with log_to(snakemake.log[0]):  # noqa: F821
    out = snakemake.output  # noqa: F821
    sensing_figures(read_json(snakemake.input.sensing), out.profiles, out.scores)  # noqa: F821
    print(f"wrote {out.profiles} and {out.scores}")
