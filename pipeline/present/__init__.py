"""Presentation: figures (``figures/``), animations (``animate``), the feeder
layout and its drawing (``layout``) and the HTML report (``report``). Reads
results (plans, verification, sensing) and the catalog; never the workflow.
"""
