"""Snakemake script: the animation of one part's laid-out plan (GIF): pins at the layout's
stations, parts at its pitch; the recommended plan in lanes when there is no layout."""
from pipeline.logs import log_to
from pipeline.workflow.report import animate

with log_to(snakemake.log[0]):  # noqa: F821
    p = snakemake.params  # noqa: F821
    done = animate(snakemake.input.plan, snakemake.config, snakemake.output.animation,  # noqa: F821
                   p.frames, p.fps, layout_path=snakemake.input.layout)  # noqa: F821
    print(f"wrote {done['out']}: {done['frames']} frames of the {done.get('what', 'no plan')}; "
          f"outcomes {done['outcomes']}")
