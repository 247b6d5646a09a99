"""``python -m pipeline.workflow run|unlock [SNAKEMAKE ARGS...]`` (what ``make run`` calls)."""
import sys

from pipeline.workflow.runner import main

sys.exit(main())
