"""
Verifying a plan by perturbed rollouts (Table 2)
================================================

The paper's Table 2 counts, per initial state, the trials of a pin sequence
that ended in the planned orientation. pinfeed does the same by simulation:
every trial replays the whole sequence with perturbed inputs (initial
orientation, position across the belt, friction, pin positions). Here the
asymmetric triangle's best plan on coarse maps (as in Fig. 2) gets 30 trials
per state plus the corners of the perturbation box; ``make run`` runs 300.
Rows with failures are shaded red.
"""
import tempfile
from pathlib import Path

import matplotlib.pyplot as plt
from _sequence import MU_C, PIN_RADIUS, best_plan

from pipeline.parts.part import Part
from pipeline.planning.verify import verify_plan
from pipeline.present.figures.tables import plot_table, verification_rows

part = Part.from_vertices([(0, 0), (60, 0), (15, 35)], name="asym_triangle")
planner, pins, plan = best_plan(part)
states = {label: (s.arc[0], s.y_lo) for label, s in planner.initial_states().items()}
result = verify_plan(part, plan, pins, states, MU_C, PIN_RADIUS, settings={"trials": 30})
rows = verification_rows({part.name: {"checks": [{"plan": plan["pins"], "kind": "fixed pins",
                                                  "rows": result["rows"]}]}})
for row in rows:
    print(" | ".join(row))
with tempfile.TemporaryDirectory() as folder:   # the report's table figure, shown here
    table = plot_table(rows, "asym_triangle: perturbed rollouts of the best coarse plan",
                       Path(folder) / "table2.png")
    fig, ax = plt.subplots(figsize=(11, 2.2))
    ax.imshow(plt.imread(table))
    ax.axis("off")
plt.show()
