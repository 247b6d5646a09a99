"""
Matching scores of the sign matrix (Table 4)
============================================

The paper's Table 4 puts a force/torque sensor on a pin in front of the
symmetric triangle of Fig. 9 and compares the sign matrix [S] of each
measured profile (signs of F_x, F_y and their gradients over 10 regions of
the contact: 40 elements) with that of each simulated initial state. An entry
is the number of equal elements: row = simulated state, column = measured
one. The best-scoring row names the state the part was in; a row less than
3 below the best cannot be told apart from it.

Here the measurements are synthetic: each of 20 trials per state rolls the
part out again with perturbed inputs (orientation, position, friction, pin
position) and adds the sensor's bias and noise (200 Hz, belt at 20 mm/s).
Whether two states can be told apart depends on where the pin meets the
part, so the example scores every pin height from 0 to 40 mm above the fence
(right), and shows the score table at the height that tells them apart best
(middle) next to the paper's experimental table (left). The paper's numbering
of the three states is not given; pinfeed's state 1 rests on the base, states
2 and 3 on the two equal sides (mirror images of each other: at about half
the heights the sensor cannot tell them apart, as it could not tell two of the
paper's states apart).
"""
import matplotlib.pyplot as plt
import numpy as np

from pipeline.parts.part import Part
from pipeline.sensing.profiles import Sensor, score_table

MU_C, PIN_RADIUS, MODEL, TRIALS = 0.15, 3.0, "minpower", 20
# The paper's Table 4 as printed (experiment): rows simulated, columns measured, out of 40.
PAPER = np.array([[35, 37, 32], [35, 37, 32], [28, 30, 33]])

part = Part.from_vertices([(0, 0), (40, 0), (20, 60)], name="sym_triangle")
states = {f"state {k}": {"theta": float(theta), "y_c": float(y_c)}
          for k, (theta, y_c) in enumerate(part.stable_states(), start=1)}
sensor = Sensor()
heights = np.arange(0.0, 40.1, 2.5)
tables = [score_table(part, states, y_pin, MU_C, PIN_RADIUS, MODEL, sensor, trials=TRIALS) for y_pin in heights]
accuracy = np.array([t["accuracy"] for t in tables])
wrong = np.array([t["wrong"] for t in tables])
apart = np.array([len(t["groups"]) == len(states) for t in tables])


def groups_text(groups):
    """The states the sensor cannot tell apart, one brace per group."""
    return " ".join("{" + ", ".join(g) + "}" for g in groups)


print("pin height: verdicts right, wrong; groups of states the sensor cannot tell apart")
for y_pin, t in zip(heights, tables):
    print(f"{y_pin:4.1f} mm: {100 * t['accuracy']:3.0f} % right, {100 * t['wrong']:2.0f} % wrong; "
          f"{groups_text(t['groups'])}")
best = int(np.argmax(accuracy))
table = tables[best]
labels = table["labels"]
scores = np.array([[table["mean_scores"][sim][meas] for meas in labels] for sim in labels])

print(f"pin at {heights[best]:g} mm: mean scores out of {table['elements']} "
      f"(rows simulated, columns measured)")
print("simulated \\ measured " + " ".join(f"{lab:>8}" for lab in labels))
for lab, row in zip(labels, scores):
    print(f"{lab:>20} " + " ".join(f"{v:8.1f}" for v in row))
print(f"accuracy {100 * table['accuracy']:.0f} %, wrong {100 * table['wrong']:.0f} %; "
      f"groups: {groups_text(table['groups'])}")


def score_panel(ax, values, row_labels, col_labels, title, out_of=40):
    """A score table as a shaded grid with 'k/40' in every cell."""
    ax.imshow(values, cmap="Blues", vmin=0.5 * out_of, vmax=out_of)
    for i, j in np.ndindex(values.shape):
        text = f"{values[i, j]:.0f}/{out_of}" if float(values[i, j]).is_integer() else f"{values[i, j]:.1f}/{out_of}"
        ax.text(j, i, text, ha="center", va="center", fontsize=9,
                color="white" if values[i, j] > 0.85 * out_of else "black")
    ax.set_xticks(range(len(col_labels)), col_labels, fontsize=8)
    ax.set_yticks(range(len(row_labels)), row_labels, fontsize=8)
    ax.set_xlabel("measured initial state", fontsize=8)
    ax.set_ylabel("simulated initial state", fontsize=8)
    ax.set_title(title, fontsize=9)


fig, (ax_paper, ax_ours, ax_scan) = plt.subplots(1, 3, figsize=(14, 4.2),
                                                 gridspec_kw={"width_ratios": [1, 1, 1.4]})
paper_labels = [f"Init State {k}" for k in (1, 2, 3)]
score_panel(ax_paper, PAPER, paper_labels, paper_labels, "paper, Table 4 (experiment)")
score_panel(ax_ours, scores, labels, labels,
            f"pinfeed: pin at {heights[best]:g} mm, mean of {TRIALS} synthetic trials\n"
            f"accuracy {100 * table['accuracy']:.0f} %, wrong {100 * table['wrong']:.0f} %")
ax_scan.plot(heights, 100 * accuracy, color="tab:blue", label="decided and right")
ax_scan.plot(heights, 100 * wrong, color="tab:red", label="decided and wrong")
ax_scan.scatter(heights[apart], 100 * accuracy[apart], color="tab:blue", zorder=3,
                label="all three states told apart")
ax_scan.scatter(heights[~apart], 100 * accuracy[~apart], facecolor="white", edgecolor="tab:blue", zorder=3,
                label="two or more states not told apart")
ax_scan.axvline(heights[best], color="0.6", lw=0.8, ls="--")
ax_scan.set_xlabel("pin height above the fence (mm)", fontsize=8)
ax_scan.set_ylabel(f"verdicts, % of {TRIALS} trials x {len(states)} states", fontsize=8)
ax_scan.set_ylim(-5, 105)
ax_scan.set_title(f"{part.name}, mu_c {MU_C:g}: the sensing pin's height", fontsize=9)
ax_scan.legend(fontsize=7, loc="center right")
fig.suptitle("Matching scores from the sign matrix [S] between simulated and measured trials", fontsize=10)
fig.tight_layout()
plt.show()
