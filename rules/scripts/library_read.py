"""Snakemake script: the parts of one drawing of the library, or why it cannot be read."""
from pipeline.logs import log_to
from pipeline.maps.io import write_json
from pipeline.workflow.library import read_record

with log_to(snakemake.log[0]):  # noqa: F821
    rec = read_record(snakemake.wildcards.drawing, snakemake.input.drawing,  # noqa: F821
                      snakemake.config["library"])  # noqa: F821
    write_json(rec, snakemake.output.record)  # noqa: F821
    print(rec["error"] or f"{len(rec['parts'])} part(s), {len(rec['refused'])} refused")
