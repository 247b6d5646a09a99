"""
Force profiles on the pin (Table 3)
===================================

The paper's Table 3 shows the force on a pin over one contact, F_x and F_y,
for the asymmetric triangle at theta_i = 0 deg and d = -0.2. This example
simulates that force history (in units of mu_s m g, against the belt's travel
since first contact) together with two other initial orientations: the
differences between such profiles are what a force/torque sensor on the first
pin uses to tell initial states apart.
"""
import matplotlib.pyplot as plt

from pipeline.maps import simulate
from pipeline.parts.part import Part

part = Part.from_vertices([(0, 0), (60, 0), (15, 35)], name="asym_triangle")
fig, (ax_x, ax_y) = plt.subplots(2, 1, figsize=(6, 5), sharex=True)
for theta_i in (0, 120, 240):
    one = simulate.rollout(part, theta_i=theta_i, d=-0.2, mu_c=0.15, pin_radius=3, trajectory=True)
    s, fx, fy = (one[k].values for k in ("force_s", "force_x", "force_y"))
    print(f"theta_i {theta_i}: contact over {s[-1]:.1f} mm, peak |F| {float(one['peak_force']):.2f}")
    ax_x.plot(s, fx, label=f"theta_i = {theta_i} deg")
    ax_y.plot(s, fy)
ax_x.set_ylabel("F_x on the pin (mu_s m g)")
ax_y.set_ylabel("F_y on the pin (mu_s m g)")
ax_y.set_xlabel("belt travel since first contact (mm)")
ax_x.legend(fontsize=8)
fig.tight_layout()
plt.show()
