"""
A configuration map (Fig. 4)
============================

The paper's Fig. 4: one configuration map, the final orientation theta_f of
the asymmetric triangle after one pin against its initial orientation
theta_i, at one contact parameter d, with its bands. A coarse 3-degree grid
keeps it to seconds.
"""
import matplotlib.pyplot as plt
import numpy as np

from pipeline.maps import simulate
from pipeline.parts.part import Part
from pipeline.present.figures.maps import map_figure

part = Part.from_vertices([(0, 0), (60, 0), (15, 35)], name="asym_triangle")
one_map = simulate.compute_map(part, theta_i=np.arange(0, 360, 3), d=[0.3], mu_c=0.15, pin_radius=3)
print(f"theta_f from {float(one_map['theta_f'].min()):.1f} to {float(one_map['theta_f'].max()):.1f} deg")
fig = map_figure(one_map, ncols=1, bands=(5, 2))
plt.show()
