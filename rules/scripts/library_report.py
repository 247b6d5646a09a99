"""Snakemake script: the library's page, JSON and CSV, one row per part."""
from pathlib import Path

from pipeline.logs import log_to
from pipeline.workflow.library import library_report

with log_to(snakemake.log[0]):  # noqa: F821
    parts = {Path(p).name: p for p in snakemake.input.parts}  # noqa: F821
    logs = {key: Path(snakemake.log[0]).parent / "part" / f"{key}.log" for key in parts}  # noqa: F821
    doc = library_report(snakemake.config, snakemake.input.records, parts,  # noqa: F821
                         {k: getattr(snakemake.output, k) for k in ("html", "json", "csv")},  # noqa: F821
                         logs)
    print(doc["summary"])
