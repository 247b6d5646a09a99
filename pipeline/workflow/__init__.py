"""The workflow: one function per Snakemake rule (the modules named after the
stages: ``bands``, ``plan``, ``verify``, ``speed``, ``figures``, ``report``),
called by the thin scripts in ``rules/scripts/`` and by the CLI, and the
runner behind ``make run`` (``runner``; ``python -m pipeline.workflow run``).
The top of the house below the CLI: it may import every layer.
"""
