"""Pin sequence diagrams (the paper's Figs. 2 and 9): each initial state's poses along the belt.

One row per initial state; the part is drawn at each station (before the
first pin, then after each pin), the pins between stations at their heights.
Pins are labelled with their heights above each row, outside the drawing, so
labels never cover a part; each pose's orientation is written under it.
``figures.text_problems`` checks that no two labels overlap and none is clipped.
"""
from __future__ import annotations

from pathlib import Path

import matplotlib.pyplot as plt
from matplotlib.patches import Circle

from pipeline.planning import format_arcs
from pipeline.present.figures import save_figure
from pipeline.present.figures.outline import PartPatch, posed


def pin_label(label: str, height: float, speed: float | None = None) -> str:
    """``P3: 22.5 mm`` (a moving pin adds its speed, mathtext)."""
    text = f"{label}: {height:g} mm"
    if speed:
        text += f"\n$v_{{pin}}$ = {speed:+g} $v_b$"
    return text


def plot_sequence(part, plan_dict, pins: dict, paths: dict, pin_radius, title, out,
                  spacing=None, speeds: dict | None = None) -> Path:
    """Save the diagram; arguments as :func:`sequence_figure`."""
    fig = sequence_figure(part, plan_dict, pins, paths, pin_radius, title, spacing, speeds)
    return save_figure(fig, out)


def sequence_figure(part, plan_dict, pins: dict, paths: dict, pin_radius, title,
                    spacing=None, speeds: dict | None = None):
    """``paths``: initial-state label -> [(theta_deg, y_c)] before and after each pin
    (nominal rollouts); ``pins``: label -> height (mm). A dynamic pin (``speeds``:
    label -> v_pin / v_b) is drawn at its height when the centroid reaches its
    station, with an arrow along its path while the belt carries the part over
    ``+- a/2`` around that station."""
    speeds = speeds or {}
    labels = list(paths)
    seq = list(plan_dict["pins"])
    n_pins = len(seq)
    a = part.a
    spacing = spacing or 3.2 * a
    width = 2.4 + 2.0 * (n_pins + 1)
    fig, axes = plt.subplots(len(labels), 1, figsize=(width, 2.5 * len(labels) + 1.2), squeeze=False)
    ys = [y for p in paths.values() for _, y in p] + [pins[p] for p in seq]
    ys += [pins[p] + sgn * 0.5 * speeds[p] * a for p in seq if p in speeds for sgn in (-1, 1)]
    lo, hi = min(ys + [0.0]) - 1.35 * a, max(ys) + 1.15 * a
    for ax, label in zip(axes[:, 0], labels):
        _draw_row(ax, part, paths[label], seq, pins, speeds, pin_radius, spacing)
        ax.set_xlim(-1.3 * a, n_pins * spacing + 1.3 * a)
        ax.set_ylim(lo, hi)
        ax.set_aspect("equal")
        ax.set_xticks([])
        ax.set_ylabel(f"{label}\n$y$ (mm)", fontsize=8)
        ax.tick_params(labelsize=7)
    axes[-1, 0].set_xlabel("stations along the belt, belt moving to the right "
                           "(distances between stations not to scale)", fontsize=8)
    sets = format_arcs(plan_dict["final_sets"], digits=0)
    fig.suptitle(f"{title}\npins {' → '.join(seq)}; final orientation set(s): {sets}", fontsize=9)
    fig.tight_layout()
    return fig


def _draw_row(ax, part, path, seq, pins, speeds, pin_radius, spacing):
    """One initial state: the fence, the poses with their orientations, the labelled pins."""
    a = part.a
    ax.axhline(0.0, color="k", lw=2, zorder=0)
    ax.text(-1.25 * a, 0.0, "fence", fontsize=7, va="bottom", ha="left")
    for k, (theta, y) in enumerate(path):
        x = k * spacing
        ax.add_patch(PartPatch(part, theta, x, y, fc="tab:blue" if k else "0.8", ec="k",
                               alpha=0.6 if k else 0.9))
        ax.plot([x], [y], "k+", ms=5)
        # Below the pose and the fence line: never on the part or the fence.
        bottom = min(posed(part.vertices, theta, x, y)[:, 1].min(), 0.0)
        ax.text(x, bottom - 0.08 * a, rf"$\theta$ = {theta % 360:.0f}°", ha="center", va="top",
                fontsize=7, bbox=dict(fc="white", ec="none", pad=0.5, alpha=0.85))
    for k, pin in enumerate(seq):
        x = (k + 0.5) * spacing
        color = "tab:purple" if pin in speeds else "tab:red"
        if pin in speeds:
            half = 0.5 * speeds[pin] * a
            ax.annotate("", xy=(x, pins[pin] + half), xytext=(x, pins[pin] - half),
                        arrowprops=dict(arrowstyle="->", color=color, ls="--", lw=1.2))
        ax.add_patch(Circle((x, pins[pin]), max(pin_radius, 0.04 * a), color=color))
        ax.axvline(x, color=color, lw=0.4, ls=":", zorder=0)
        ax.text(x, 1.02, pin_label(pin, pins[pin], speeds.get(pin)), color=color, ha="center",
                va="bottom", fontsize=7, transform=ax.get_xaxis_transform())
