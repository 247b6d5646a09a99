"""
A part meeting one pin
======================

Each step of the paper's Fig. 2 is a part turning against an overhead pin until it
leaves it. This example rolls the asymmetric triangle out against one pin at
contact parameter d = 0.3 and plots how far it has turned against the belt's travel
since first contact, for three initial orientations.
"""
import matplotlib.pyplot as plt

from pipeline.maps import simulate
from pipeline.parts.part import Part

part = Part.from_vertices([(0, 0), (60, 0), (15, 35)], name="asym_triangle")
fig, ax = plt.subplots(figsize=(6, 3.5))
for theta_i in (0, 120, 240):
    one = simulate.rollout(part, theta_i=theta_i, d=0.3, mu_c=0.15, pin_radius=3,
                           trajectory=True)
    print(f"{theta_i} -> {float(one['theta_f']):.1f} deg", str(one["status"].values))
    s = one["traj_s"].values
    turn = one["traj_theta"].values - one["traj_theta"].values[0]
    ax.plot(s[: turn.size], turn, marker=".", label=f"theta_i = {theta_i} deg")
ax.set_xlabel("belt travel since first contact (mm)")
ax.set_ylabel("turn since first contact (deg)")
ax.legend(fontsize=8)
fig.tight_layout()
plt.show()
