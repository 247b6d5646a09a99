"""Coarse plans for the gallery: a part's maps on a coarse grid, the paper's
fixed-pins planner on them, and the nominal path of every resting state
through the best plan.

The gallery's pin-sequence examples (Fig. 2, Fig. 9, Table 2) call these and
draw the result (:func:`pipeline.present.coarse_plans.coarse_plan_figure`),
so a downloaded example needs only the installed package. ``make run`` plans
on the full grid with the complete search instead.
"""
from __future__ import annotations

import numpy as np

from pipeline.maps import simulate
from pipeline.planning.core.settings import candidate_pins
from pipeline.planning.paper.planner import Planner, load_maps

MU_C, PIN_RADIUS, THRESHOLD_T, FACTOR_C = 0.15, 3.0, 5.0, 2.0
D_VALUES = [float(d) for d in np.round(np.arange(-0.9, 0.91, 0.1), 1) if d != 0]


def best_coarse_plan(part, depth: int = 3, theta_step: float = 2.0):
    """The paper planner's best fixed-pin plan of ``part`` on maps with
    ``theta_step``-degree steps of theta_i (friction ``MU_C``, pin radius
    ``PIN_RADIUS``): returns ``(planner, candidate pins, plan dict)``."""
    maps = simulate.compute_map(part, theta_i=np.arange(0, 360, theta_step), d=D_VALUES,
                                mu_c=MU_C, pin_radius=PIN_RADIUS)
    pins = candidate_pins(part, "auto")
    planner = Planner(part, load_maps(maps, THRESHOLD_T, FACTOR_C), pins, d_min=0.1, d_max=0.9)
    return planner, pins, planner.search(depth, keep=1)[0].to_dict()


def coarse_plan_paths(part, planner, pins: dict, plan: dict) -> dict:
    """The nominal path of every resting state of ``planner`` through ``plan``
    (label -> :func:`pipeline.maps.simulate.nominal_path`), at friction ``MU_C``
    and pin radius ``PIN_RADIUS``; ``pins``: label -> height (mm)."""
    heights = [pins[pin] for pin in plan["pins"]]
    return {label: simulate.nominal_path(part, state.arc[0], state.y_lo, heights, MU_C, PIN_RADIUS)
            for label, state in planner.initial_states().items()}
