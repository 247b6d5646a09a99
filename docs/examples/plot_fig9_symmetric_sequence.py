"""
Pin sequence for the symmetric triangle (Fig. 9)
================================================

The paper's Fig. 9: the symmetric triangle's three resting states taken by
fixed pins to two final orientations, which fixed pins alone cannot merge
(a force/torque sensor on the first pin, or a moving pin, can). Coarse maps
(2-degree grid) keep this to seconds.
"""
import matplotlib.pyplot as plt
from _sequence import best_plan_figure

from pipeline.parts.part import Part

part = Part.from_vertices([(0, 0), (40, 0), (20, 60)], name="sym_triangle")
fig, plan = best_plan_figure(part)
print("pins", " -> ".join(plan["pins"]), "final sets", plan["final_sets"])
plt.show()
