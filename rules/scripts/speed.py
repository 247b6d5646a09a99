"""Snakemake script: the speed curve and speed limit of one part's recommended plan."""
import sys
from pathlib import Path

# The repository is the workflow: make its pipeline importable under --use-conda too.
sys.path.insert(0, str(Path(snakemake.scriptdir).resolve().parents[1]))  # noqa: F821

from pipeline.logs import log_to
from pipeline.workflow.stages import read_json, speed_figure, speed_part, write_json

with log_to(snakemake.log[0]):  # noqa: F821
    result = speed_part(read_json(snakemake.input.plan), snakemake.config)  # noqa: F821
    write_json(result, snakemake.output.speed)  # noqa: F821
    speed_figure(result, snakemake.output.figure)  # noqa: F821
    print(result["part"], "speed limit (mm/s):", result["speed_limit_mm_s"],
          "in", result.get("seconds"), "s;", result.get("note", ""))
    for speed, fraction in result["curve"]:
        print(f"  {speed:g} mm/s: {fraction:.4f}")
