"""Coarse plans for the gallery, drawn: the paper's pin-sequence figure of the
best plan on coarse maps, one row per resting state.

The plan and its nominal paths come from the planner
(:func:`pipeline.planning.best_coarse_plan`,
:func:`pipeline.planning.coarse_plan_paths`); the gallery's pin-sequence
examples (Fig. 2, Fig. 9) call those and draw the result here, so a
downloaded example needs only the installed package.
"""
from __future__ import annotations

from pipeline.planning import COARSE_MU_C, COARSE_PIN_RADIUS
from pipeline.present.figures.sequence import sequence_figure


def coarse_plan_figure(part, plan: dict, pins: dict, paths: dict, theta_step: float = 2.0):
    """The coarse ``plan`` (:func:`pipeline.planning.best_coarse_plan`, on maps
    with ``theta_step``-degree steps) drawn as the paper's pin-sequence figure,
    one row per resting state: ``pins`` (label -> height, mm) and ``paths``
    (:func:`pipeline.planning.coarse_plan_paths`). Returns the figure."""
    title = f"{part.name}: best fixed-pin plan on a {theta_step:g}-degree grid, mu_c {COARSE_MU_C:g}"
    return sequence_figure(part, plan, pins, paths, COARSE_PIN_RADIUS, title)
