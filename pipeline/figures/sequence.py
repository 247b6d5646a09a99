"""Pin sequence diagrams (the paper's Figs. 2 and 9): each initial state's poses along the belt."""
from __future__ import annotations

import math
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.patches import Circle, Polygon

from . import save_figure


def _pose(vertices, theta_deg, x, y):
    c, s = math.cos(math.radians(theta_deg)), math.sin(math.radians(theta_deg))
    return vertices @ np.array([[c, s], [-s, c]]) + np.array([x, y])


def plot_sequence(part, plan_dict, pins: dict, paths: dict, pin_radius, title, out,
                  spacing=None, speeds: dict | None = None) -> Path:
    """``paths``: initial-state label -> [(theta_deg, y_c)] before and after each pin
    (nominal rollouts). Pins are drawn at their heights, one station per pin.
    A dynamic pin (``speeds``: label -> v_pin / v_b) is drawn at its height when
    the centroid reaches its station, with an arrow along its path while the
    belt carries the part over ``+- a/2`` around that station."""
    speeds = speeds or {}
    labels = list(paths)
    n_pins = len(plan_dict["pins"])
    spacing = spacing or 3.2 * part.a
    fig, axes = plt.subplots(len(labels), 1, figsize=(2.2 + 1.9 * (n_pins + 1), 2.3 * len(labels) + 0.6),
                             squeeze=False)
    ys = [y for p in paths.values() for _, y in p] + [pins[p] for p in plan_dict["pins"]]
    ys += [pins[p] + sgn * 0.5 * speeds[p] * part.a for p in plan_dict["pins"] if p in speeds
           for sgn in (-1, 1)]
    lo, hi = min(ys + [0.0]) - 1.2 * part.a, max(ys) + 1.2 * part.a
    for ax, label in zip(axes[:, 0], labels):
        ax.axhline(0.0, xmin=0.0, xmax=0.12, color="k", lw=2)
        ax.text(0.0, -0.15 * part.a, "fence", fontsize=7, va="top")
        for k, (theta, y) in enumerate(paths[label]):
            x = k * spacing
            ax.add_patch(Polygon(_pose(part.vertices, theta, x, y), closed=True, fc="tab:blue" if k else "0.8",
                                 ec="k", alpha=0.6 if k else 0.9))
            ax.plot([x], [y], "k+", ms=5)
            ax.text(x, y - 1.05 * part.a, f"{theta:.0f}°", ha="center", fontsize=7)
        for k, pin in enumerate(plan_dict["pins"]):
            x = (k + 0.5) * spacing
            color = "tab:purple" if pin in speeds else "tab:red"
            if pin in speeds:
                half = 0.5 * speeds[pin] * part.a
                ax.annotate("", xy=(x, pins[pin] + half), xytext=(x, pins[pin] - half),
                            arrowprops=dict(arrowstyle="->", color=color, ls="--", lw=1.2))
            ax.add_patch(Circle((x, pins[pin]), max(pin_radius, 0.04 * part.a), color=color))
            text = pin if pin not in speeds else f"{pin}\n(v = {speeds[pin]:+g} v_b)"
            ax.text(x + 0.08 * part.a, pins[pin] + 0.12 * part.a, text, color=color, ha="left",
                    fontsize=7)
        ax.annotate("", xy=(n_pins * spacing + 0.8 * part.a, lo + 0.1 * part.a),
                    xytext=(n_pins * spacing - 0.8 * part.a, lo + 0.1 * part.a),
                    arrowprops=dict(arrowstyle="->"))
        ax.text(n_pins * spacing, lo + 0.2 * part.a, "belt", fontsize=7, ha="center")
        ax.set_xlim(-1.3 * part.a, n_pins * spacing + 1.3 * part.a)
        ax.set_ylim(lo, hi)
        ax.set_aspect("equal")
        ax.set_ylabel(f"{label}\ny (mm)", fontsize=8)
        ax.tick_params(labelsize=7)
    axes[-1, 0].set_xlabel("stations along the belt (x not to scale between pins)", fontsize=8)
    sets = ", ".join(f"[{s['start']:.0f}°, {s['start'] + s['width']:.0f}°]" for s in plan_dict["final_sets"])
    fig.suptitle(f"{title}\npins {' → '.join(plan_dict['pins'])}; final orientation set(s): {sets}",
                 fontsize=9)
    fig.tight_layout()
    return save_figure(fig, out)
