"""Snakemake script: the speed curve and speed limit of one part's recommended plan."""
from pipeline.logs import log_to
from pipeline.workflow.speed import speed

with log_to(snakemake.log[0]):  # noqa: F821
    result = speed(snakemake.input.plan, snakemake.config, snakemake.output.speed,  # noqa: F821
                   snakemake.output.figure)  # noqa: F821
    print(result["part"], "speed limit (mm/s):", result["speed_limit_mm_s"],
          "in", result.get("seconds"), "s;", result.get("note", ""))
    for v, fraction in result["curve"]:
        print(f"  {v:g} mm/s: {fraction:.4f}")
