"""The planner's carried sets against replayed rollouts, for one plan.

One column per initial state. Top row: the orientation sets the tight
planner carries after each pin (bars; several bars where a state branched)
and the orientations of replayed, perturbed full rollouts after each pin
(dots). Bottom row: the same for the centroid height y_c. A sound
propagation has every dot inside a bar; a tight one has bars little wider
than the dots' spread. The replays are computed by the planner
(:func:`pipeline.planning.replayed_paths`); this module draws them.
"""
from __future__ import annotations

from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

from pipeline.present.figures import save_figure


def carried_by_step(plan: dict, label: str) -> list[list[dict]]:
    """For one initial state: the carried sets (``StateSet.to_dict()``) before
    the first pin and after each pin, one list per step (several branches)."""
    steps = [[plan["initial_sets"][label]]]
    for k in range(len(plan["pins"])):
        seen, row = set(), []
        for branch in plan["initial_states"][label]:
            st = branch[k]["carried"]
            key = (st["arc"]["start"], st["arc"]["width"], *st["y_c"])
            if key not in seen:
                seen.add(key)
                row.append(st)
        steps.append(row)
    return steps


def _unwrap_near(values, centre):
    """Angles shifted by multiples of 360 to lie within 180 of ``centre``."""
    return centre + ((np.asarray(values) - centre + 180.0) % 360.0) - 180.0


def plot_carried(plan: dict, replays: dict, title: str, out) -> Path:
    """Draw carried sets (bars) against replayed rollouts (dots); see the module doc."""
    labels = list(replays)
    n_steps = len(plan["pins"]) + 1
    fig, axes = plt.subplots(2, len(labels), figsize=(3.6 * len(labels), 6.4), squeeze=False)
    xt = ["start"] + [f"{p}\n{y:g} mm" for p, y in zip(plan["pins"], plan["pin_heights_mm"])]
    for col, label in enumerate(labels):
        theta, y_c = replays[label]
        steps = carried_by_step(plan, label)
        ax_t, ax_y = axes[0, col], axes[1, col]
        for k in range(n_steps):
            for st in steps[k]:
                s, w = st["arc"]["start"], st["arc"]["width"]
                centre = s + w / 2.0
                ax_t.bar(k, w, bottom=s if k == 0 else centre - w / 2.0, width=0.5, color="#9ecae1",
                         edgecolor="#3182bd", label="carried set" if (k, col) == (0, 0) else None)
                ax_y.bar(k, st["y_c"][1] - st["y_c"][0], bottom=st["y_c"][0], width=0.5, color="#c7e9c0",
                         edgecolor="#31a354", label="carried $y_c$ interval" if (k, col) == (0, 0) else None)
                near = np.isfinite(theta[:, k]) & (np.abs(_unwrap_near(theta[:, k], centre) - centre) <= 180)
                ax_t.plot(np.full(near.sum(), k) + np.random.default_rng(k).uniform(-0.15, 0.15, near.sum()),
                          _unwrap_near(theta[near, k], centre), ".", ms=2, color="#d62728",
                          label="replayed rollouts" if (k, col) == (0, 0) and st is steps[k][0] else None)
            ax_y.plot(np.full(len(y_c), k), y_c[:, k], ".", ms=2, color="#d62728")
        for ax in (ax_t, ax_y):
            ax.set_xticks(range(n_steps))
            ax.set_xticklabels(xt, fontsize=7)
        ax_t.set_title(label, fontsize=9)
        ax_t.set_ylabel(r"orientation $\theta$ (deg)")
        ax_y.set_ylabel(r"centroid height $y_c$ (mm)")
    fig.legend(loc="lower center", ncol=3, fontsize=8)
    fig.suptitle(title, fontsize=10)
    fig.tight_layout(rect=(0, 0.05, 1, 0.95))
    return save_figure(fig, out)
