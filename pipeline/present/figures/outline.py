"""A part's outline as the planner sees it: body frame, centroid, reference length a, resting states."""
from __future__ import annotations

import math
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.patches import Circle, Polygon

from pipeline.present.figures import save_figure


def outline_figure(part, source: str | None = None):
    """The outline (body frame, mm) with its centroid, the circle of radius a
    around it, and the fence line of each resting state (numbered as the
    initial states), drawn where the fence touches the part."""
    fig, ax = plt.subplots(figsize=(5.2, 5.0))
    v = part.vertices
    ax.add_patch(Polygon(v, closed=True, fc="tab:blue", ec="k", alpha=0.45, gid="outline"))
    ax.add_patch(Circle((0, 0), part.a, fill=False, ls="--", lw=0.8, ec="0.5"))
    ax.plot([0], [0], "k+", ms=9)
    for k, (theta, y_c) in enumerate(part.stable_states(), start=1):
        # The fence seen from the body frame: world -y rotated back by theta, y_c away.
        t = math.radians(theta)
        n = np.array([-math.sin(t), -math.cos(t)])
        along = np.array([-n[1], n[0]]) * 0.55 * part.a
        foot = y_c * n
        ax.plot(*np.transpose([foot - along, foot + along]), color="tab:red", lw=1.2, gid=f"fence {k}")
        ax.text(*(foot + 0.2 * part.a * n), f"state {k}", ha="center", va="center", fontsize=7,
                color="tab:red")
    lim = 1.35 * part.a
    ax.set_xlim(-lim, lim)
    ax.set_ylim(-lim, lim)
    ax.set_aspect("equal")
    ax.set_xlabel("body frame $x$ (mm)", fontsize=8)
    ax.set_ylabel("body frame $y$ (mm)", fontsize=8)
    ax.tick_params(labelsize=7)
    ax.grid(True, lw=0.3, alpha=0.5)
    kind = "convex" if part.is_convex else "non-convex"
    origin = f"\nfrom {Path(source).name}" if source else ""
    ax.set_title(f"{part.name}: {part.n_vertices} vertices, {kind}, area {part.area:.1f} mm², "
                 f"$a$ = {part.a:.2f} mm{origin}", fontsize=8)
    fig.tight_layout()
    return fig


def plot_outline(part, out, source: str | None = None) -> Path:
    """Draw the part's outline (and its source, if given) to the image file ``out``."""
    return save_figure(outline_figure(part, source), out)
