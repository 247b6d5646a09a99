"""
Verifying a plan by perturbed rollouts (Table 2)
================================================

The paper's Table 2 counts, per initial state, the trials of a pin sequence
that ended in the planned orientation. pinfeed does the same by simulation:
every trial replays the whole sequence with perturbed inputs (initial
orientation, position across the belt, friction, pin positions). Here the
asymmetric triangle's best plan on coarse maps (as in Fig. 2) gets 30 trials
per state plus the corners of the perturbation box; ``make run`` runs 300.
The table is printed as text and drawn; rows with failures are shaded red.
"""
import os

import matplotlib.pyplot as plt

from pipeline.parts.part import Part
from pipeline.planning import COARSE_MU_C as MU_C, COARSE_PIN_RADIUS as PIN_RADIUS
from pipeline.planning import VerifySettings, best_coarse_plan, verify_plan
from pipeline.present.figures.tables import FAIL_COLOUR, HEADER, verification_rows

# A coarser grid (e.g. PINFEED_EXAMPLE_THETA_STEP=6) runs faster; the tests use it.
THETA_STEP = float(os.environ.get("PINFEED_EXAMPLE_THETA_STEP", "2"))

part = Part.from_vertices([(0, 0), (60, 0), (15, 35)], name="asym_triangle")
planner, pins, plan = best_coarse_plan(part, theta_step=THETA_STEP)
states = {label: (s.arc[0], s.y_lo) for label, s in planner.initial_states().items()}
result = verify_plan(part, plan, pins, states, MU_C, PIN_RADIUS, settings=VerifySettings(trials=30))
rows = verification_rows({part.name: {"checks": [{"plan": plan["pins"], "kind": "fixed pins",
                                                  "rows": result["rows"]}]}})

# %%
# The table as text
widths = [max(len(str(r[c])) for r in [HEADER, *rows]) for c in range(len(HEADER))]
for row in [HEADER, ["-" * w for w in widths], *rows]:
    print("  ".join(str(cell).ljust(w) for cell, w in zip(row, widths)))

# %%
# The same table as a figure, one row per initial state
fig, ax = plt.subplots(figsize=(10, 0.5 * (len(rows) + 2) + 0.6))
ax.axis("off")
ax.set_title(f"{part.name}: perturbed rollouts of the best coarse plan")
table = ax.table(cellText=rows, colLabels=HEADER, loc="center", cellLoc="left")
table.auto_set_font_size(False)
table.set_fontsize(10)
table.scale(1, 1.6)
table.auto_set_column_width(list(range(len(HEADER))))
failures = HEADER.index("failures")
for r, row in enumerate(rows, start=1):
    if row[failures] != "0":
        for c in range(len(HEADER)):
            table[r, c].set_facecolor(FAIL_COLOUR)
fig.tight_layout()
plt.show()
