"""
Configuration maps with their bands (Fig. 4, Table 1)
=====================================================

The paper's Fig. 4: for the asymmetric triangle, the final orientation
theta_f after one pin against the initial orientation theta_i, one panel per
contact parameter d, with the bands (Table 1) the planner works with drawn
over each map. Here on a coarse grid (4 deg, two values of d) so that it runs
in seconds; ``make run`` draws the full grid.
"""
import matplotlib.pyplot as plt
import numpy as np

from pipeline.maps import simulate
from pipeline.parts.part import Part
from pipeline.present.figures.maps import map_figure

part = Part.from_vertices([(0, 0), (60, 0), (15, 35)], name="asym_triangle")
maps = simulate.compute_map(part, theta_i=np.arange(0, 360, 4), d=[-0.3, 0.3],
                            mu_c=0.15, pin_radius=3)
print(maps["theta_f"].sizes)
fig = map_figure(maps, ncols=2, bands=(5, 2))
plt.show()
