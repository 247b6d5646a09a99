"""Configuration maps as in the paper's Table 1: theta_f against theta_i, one panel per d."""
from __future__ import annotations

import math
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
import xarray as xr

from pipeline.present.figures import circle_axes, save_figure
from pipeline.present.figures.bands import POINTS, bottom_legend, draw_map_panel, legend_handles


def plot_map(ds: xr.Dataset, out, ncols: int = 6, bands: tuple[float, float] | None = None) -> Path:
    """Draw every ``d`` of a map set and save to ``out`` (PNG, PDF, SVG...).
    ``bands``: ``(threshold_T, factor_c)`` also draws the bands B_j x K_j."""
    return save_figure(map_figure(ds, ncols, bands), out)


def map_figure(ds: xr.Dataset, ncols: int = 6, bands: tuple[float, float] | None = None):
    """The figure of :func:`plot_map`, unsaved."""
    d_values = np.atleast_1d(ds["d"].values)
    n = d_values.size
    ncols = min(ncols, n)
    nrows = math.ceil(n / ncols)
    fig, axes = plt.subplots(nrows, ncols, figsize=(max(2.5 * ncols + 0.7, 7.0), 2.6 * nrows + 1.4),
                             sharex=True, sharey=True, squeeze=False)
    theta_i = ds["theta_i"].values
    seen = set()
    for k, d in enumerate(d_values):
        ax = axes[k // ncols][k % ncols]
        sub = ds.sel(d=d)
        status = sub["status"].values
        seen.update(np.unique(status).tolist())
        if bands is not None:
            draw_map_panel(ax, theta_i, sub["theta_f"].values, sub["dy"].values, status, *bands)
        else:
            for code, style in POINTS.items():
                sel = status == code
                if sel.any():
                    ax.scatter(theta_i[sel], sub["theta_f"].values[sel], linewidths=0.8,
                               **{k: v for k, v in style.items() if k != "label"})
            circle_axes(ax)
            ax.set_aspect("equal")
        ax.set_title(f"$d$ = {d:+.2f}", fontsize=9)
        ax.tick_params(labelbottom=True, labelleft=True)  # tick labels on every panel row
        ax.grid(True, lw=0.3, alpha=0.5)
    for k in range(n, nrows * ncols):
        axes[k // ncols][k % ncols].set_visible(False)
    for ax in axes.ravel():
        ax.set_xlabel(r"$\theta_i$ (deg)", fontsize=8)
    for row in axes:
        row[0].set_ylabel(r"$\theta_f$ (deg)", fontsize=8)
    attrs = ds.attrs
    unit = attrs.get("length_unit", "")
    handles = legend_handles(bands[1], seen) if bands else legend_handles(0, seen)[2:]
    fig.suptitle(f"Configuration maps: {attrs.get('part_name', 'part')}\nmodel {attrs.get('model', '?')}, "
                 f"$\\mu_c$ = {attrs.get('mu_c', float('nan')):g}, pin radius "
                 f"{attrs.get('pin_radius', float('nan')):g} {unit}", fontsize=10)
    bottom = bottom_legend(fig, handles)
    # Twice: the first pass sizes the equal-aspect panels, the second fits their
    # labels above the legend (one pass can leave the x labels on it).
    fig.tight_layout(rect=(0, bottom, 1, 1))
    fig.tight_layout(rect=(0, bottom, 1, 1))
    return fig
