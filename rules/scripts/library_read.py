"""Snakemake script: the parts of one drawing of the library, or why it cannot be read."""
from pipeline.logs import log_to
from pipeline.workflow.library import write_read_record

with log_to(snakemake.log[0]):  # noqa: F821
    rec = write_read_record(snakemake.wildcards.drawing, snakemake.input.drawing,  # noqa: F821
                            snakemake.config["library"], snakemake.output.record)  # noqa: F821
    print(rec["error"] or f"{len(rec['parts'])} part(s), {len(rec['refused'])} refused")
