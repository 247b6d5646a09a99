"""
Pin sequence for the asymmetric triangle (Fig. 2)
=================================================

The paper's Fig. 2: a sequence of fixed pins across the belt that takes the
asymmetric triangle from each of its three resting states against the fence
towards one final orientation. Here the paper's planner works on coarse maps
(2-degree grid, up to three pins), where the best plan it finds ends in the
sets named in the title; ``make run`` plans on the 1-degree grid with the
complete search and verifies the plan by perturbed rollouts. Each row follows
one initial state through the pins.
"""
import os

import matplotlib.pyplot as plt

from pipeline.parts.part import Part
from pipeline.planning import best_coarse_plan, coarse_plan_paths
from pipeline.present.coarse_plans import coarse_plan_figure

# A coarser grid (e.g. PINFEED_EXAMPLE_THETA_STEP=6) runs faster; the tests use it.
THETA_STEP = float(os.environ.get("PINFEED_EXAMPLE_THETA_STEP", "2"))

part = Part.from_vertices([(0, 0), (60, 0), (15, 35)], name="asym_triangle")
planner, pins, plan = best_coarse_plan(part, theta_step=THETA_STEP)
fig = coarse_plan_figure(part, plan, pins, coarse_plan_paths(part, planner, pins, plan), THETA_STEP)
sets = ", ".join(f"{s['start']:.1f} deg + {s['width']:.1f}" for s in plan["final_sets"])
print("pins", " -> ".join(plan["pins"]), "| final sets (start + width):", sets)
plt.show()
