"""Snakemake script: the feeder layout of one part's first fixed-pin tight plan."""
from pipeline.logs import log_to
from pipeline.workflow.layout import layout

with log_to(snakemake.log[0]):  # noqa: F821
    out = snakemake.output  # noqa: F821
    done = layout(snakemake.input.plan, snakemake.config,  # noqa: F821
                  {"json": out.layout, "dxf": out.dxf, "svg": out.svg, "png": out.png})
    print(done)
