"""Snakemake script: plan one part of the library (its refusal or failure is recorded, not raised)."""
from pipeline.logs import log_to
from pipeline.workflow.library import plan_library_part

with log_to(snakemake.log[0]):  # noqa: F821
    rec = plan_library_part(snakemake.config, snakemake.input.drawing,  # noqa: F821
                            snakemake.params.label, snakemake.params.name,  # noqa: F821
                            snakemake.output.folder)  # noqa: F821
    print(rec["label"], rec["status"], rec["reason"] or "", f"{rec['seconds']} s")
