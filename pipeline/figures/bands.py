"""Configuration maps with bands and adjusted bands shaded, models side by side (the paper's Table 1)."""
from __future__ import annotations

from pathlib import Path

import matplotlib.pyplot as plt

from kernels.rollout import OK

from ..bands import extract_bands
from . import circle_axes, save_figure


def _shade(ax, start, width, **kw):
    end = start + width
    ax.axhspan(start, min(end, 360.0), **kw)
    if end > 360.0:  # a band wrapping through 0/360
        ax.axhspan(0.0, end - 360.0, **kw)


def plot_band_maps(maps_by_model: dict, d_values, threshold_T, factor_c, title, out) -> Path:
    """``maps_by_model``: row label (a model, or a pin speed) -> Dataset with dims
    (d, theta_i). Rows: those labels; columns: d."""
    models = list(maps_by_model)
    fig, axes = plt.subplots(len(models), len(d_values), figsize=(2.7 * len(d_values) + 0.5,
                             2.7 * len(models) + 0.8), sharex=True, sharey=True, squeeze=False)
    for r, model in enumerate(models):
        ds = maps_by_model[model]
        for c, d in enumerate(d_values):
            ax = axes[r][c]
            sub = ds.sel(d=d, method="nearest")
            ti, tf, st = ds["theta_i"].values, sub["theta_f"].values, sub["status"].values
            for b in extract_bands(ti, tf, sub["dy"].values, st, threshold_T, factor_c):
                _shade(ax, b.start, b.width, color="tab:blue", alpha=0.12, lw=0)
                _shade(ax, b.adj_start, b.adj_width, color="tab:orange", alpha=0.35, lw=0)
            ok = st == OK
            ax.scatter(ti[ok], tf[ok], s=2, color="tab:blue", label="θ_f (ok)")
            ax.scatter(ti[~ok], tf[~ok], s=2, color="0.6", label="miss / jammed")
            ax.set_title(f"{model}, d = {float(sub['d']):+.1f}", fontsize=9)
            circle_axes(ax)
            if r == len(models) - 1:
                ax.set_xlabel(r"$\theta_i$ (deg)", fontsize=8)
            if c == 0:
                ax.set_ylabel(r"$\theta_f$ (deg)", fontsize=8)
    handles = [plt.Rectangle((0, 0), 1, 1, color="tab:blue", alpha=0.12),
               plt.Rectangle((0, 0), 1, 1, color="tab:orange", alpha=0.35)]
    handles += axes[0][0].get_legend_handles_labels()[0]
    labels = ["band B_j", f"adjusted band m ± {factor_c:g}σ"] + axes[0][0].get_legend_handles_labels()[1]
    fig.legend(handles, labels, loc="lower center", ncol=4, fontsize=8, frameon=False)
    fig.suptitle(title, fontsize=10)
    fig.tight_layout(rect=(0, 0.05, 1, 0.95))
    return save_figure(fig, out)
