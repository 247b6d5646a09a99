"""
Pin sequence for the symmetric triangle (Fig. 9)
================================================

The paper's Fig. 9: the symmetric triangle's three resting states taken by
fixed pins to two final orientations, which fixed pins alone cannot merge
(a force/torque sensor on the first pin, or a moving pin, can). Coarse maps
(2-degree grid) keep it short.

Its run time on the machine that built this manual is on the
:ref:`computation times <sphx_glr_sg_execution_times>` page.
"""
import os

import matplotlib.pyplot as plt

from pipeline.parts.part import Part
from pipeline.planning import best_coarse_plan, coarse_plan_paths
from pipeline.present.coarse_plans import coarse_plan_figure

# A coarser grid (e.g. PINFEED_EXAMPLE_THETA_STEP=6) runs faster; the tests use it.
THETA_STEP = float(os.environ.get("PINFEED_EXAMPLE_THETA_STEP", "2"))

part = Part.from_vertices([(0, 0), (40, 0), (20, 60)], name="sym_triangle")
planner, pins, plan = best_coarse_plan(part, theta_step=THETA_STEP)
fig = coarse_plan_figure(part, plan, pins, coarse_plan_paths(part, planner, pins, plan), THETA_STEP)
sets = ", ".join(f"{s['start']:.1f} deg + {s['width']:.1f}" for s in plan["final_sets"])
print("pins", " -> ".join(plan["pins"]), "| final sets (start + width):", sets)
plt.show()
