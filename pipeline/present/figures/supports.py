"""Configuration maps under uniform support and under a support family's extremes, overlaid."""
from __future__ import annotations

import math
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

from pipeline.present.figures import circle_axes, save_figure

OK = 0  # the maps' status flag of a passage that pushed the part
EXTREME_COLOURS = ("tab:red", "tab:blue", "tab:orange")


def plot_support_maps(spread, d_values, title: str, out, ncols: int = 4) -> Path:
    """One panel per ``d`` (the nearest stored): theta_f against theta_i under
    uniform pressure (black), every member of the family (grey) and its
    extremes (colours). ``spread``: a ``support_spread.FamilySpread``. Only
    passages that push the part are drawn (a miss leaves theta_f = theta_i)."""
    d_all = spread.uniform["d"].values
    picks = sorted({float(d_all[np.argmin(np.abs(d_all - d))]) for d in d_values})
    n = len(picks)
    ncols = min(ncols, n)
    nrows = math.ceil(n / ncols)
    fig, axes = plt.subplots(nrows, ncols, figsize=(3.0 * ncols + 0.6, 3.0 * nrows + 1.3),
                             squeeze=False, sharex=True, sharey=True)
    theta_i = spread.uniform["theta_i"].values
    labels = [str(x) for x in spread.maps["support"].values]
    for k, d in enumerate(picks):
        ax = axes[k // ncols][k % ncols]
        members = spread.maps.sel(d=d)
        for m in range(len(labels)):
            sel = members["status"].values[m] == OK
            ax.scatter(theta_i[sel], members["theta_f"].values[m][sel], s=1.0, c="0.75", lw=0,
                       label="every member" if m == 0 else None, rasterized=True)
        for colour, m in zip(EXTREME_COLOURS, spread.extremes):
            sel = members["status"].values[m] == OK
            ax.scatter(theta_i[sel], members["theta_f"].values[m][sel], s=2.5, c=colour, lw=0,
                       label=f"extreme: {labels[m]}")
        uni = spread.uniform.sel(d=d)
        sel = uni["status"].values == OK
        ax.scatter(theta_i[sel], uni["theta_f"].values[sel], s=2.5, c="k", lw=0, label="uniform")
        circle_axes(ax)
        ax.set_aspect("equal")
        ax.set_title(f"$d$ = {d:+.2f}", fontsize=9)
        ax.tick_params(labelbottom=True, labelleft=True)
        ax.grid(True, lw=0.3, alpha=0.5)
        ax.set_xlabel(r"$\theta_i$ (deg)", fontsize=8)
        if k % ncols == 0:
            ax.set_ylabel(r"$\theta_f$ (deg)", fontsize=8)
    for k in range(n, nrows * ncols):
        axes[k // ncols][k % ncols].set_visible(False)
    handles, texts = axes[0][0].get_legend_handles_labels()
    fig.legend(handles, texts, loc="lower center", ncol=min(5, len(texts)), fontsize=8, markerscale=4,
               frameon=False)
    fig.suptitle(title, fontsize=10)
    fig.tight_layout(rect=(0, 0.07 if nrows == 1 else 0.04, 1, 1))
    return save_figure(fig, out)
