"""Snakemake script: the animation of one part's recommended plan (GIF)."""
import sys
from pathlib import Path

# The repository is the workflow: make its pipeline importable under --use-conda too.
sys.path.insert(0, str(Path(snakemake.scriptdir).resolve().parents[1]))  # noqa: F821

from pipeline.logs import log_to
from pipeline.workflow.stages import animate_part, read_json

with log_to(snakemake.log[0]):  # noqa: F821
    p = snakemake.params  # noqa: F821
    done = animate_part(read_json(snakemake.input.plan), snakemake.config,  # noqa: F821
                        snakemake.output.animation, p.frames, p.fps)  # noqa: F821
    print(f"wrote {done['out']}: {done['frames']} frames of the {done.get('what', 'no plan')}; "
          f"outcomes {done['outcomes']}")
