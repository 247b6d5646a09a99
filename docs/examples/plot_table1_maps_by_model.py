"""
Configuration maps by model (Table 1)
=====================================

The paper's Table 1: configuration maps of the asymmetric triangle for given
contact parameters d, one row per model of the centre of rotation (the tip
of the COR locus, and minimum power), with the bands the planner works with
(blue: the bands B_j x K_j; hatched orange: the adjusted bands). Here on a
coarse grid (5 deg, three values of d, one friction) so that it runs in
seconds; ``make run`` draws the full grid.
"""
import matplotlib.pyplot as plt
import numpy as np

from pipeline.maps import simulate
from pipeline.parts.part import Part
from pipeline.present.figures.bands import band_maps_figure

part = Part.from_vertices([(0, 0), (60, 0), (15, 35)], name="asym_triangle")
d_values = [-0.5, 0.3, 0.7]
maps = {model: simulate.compute_map(part, theta_i=np.arange(0, 360, 5), d=d_values,
                                    mu_c=0.15, pin_radius=3, model=model)
        for model in ("tip", "minpower")}
for model, ds in maps.items():
    print(model, {str(k): int(v) for k, v in zip(*np.unique(ds["status"].values, return_counts=True))})
fig = band_maps_figure(maps, d_values, threshold_T=5.0, factor_c=2.0,
                       title="asym_triangle: configuration maps, $\\mu_c$ = 0.15 (rows: models)")
plt.show()
