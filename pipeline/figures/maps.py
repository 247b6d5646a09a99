"""Configuration maps as in the paper's Table 1: theta_f against theta_i, one panel per d."""
from __future__ import annotations

import math
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
import xarray as xr

from kernels.rollout import JAMMED, MISS, OK, TRUNCATED

from . import circle_axes, save_figure

_STYLE = {
    OK: dict(marker=".", s=4, color="tab:blue", label="ok"),
    MISS: dict(marker=".", s=4, color="0.7", label="miss (no contact)"),
    JAMMED: dict(marker="x", s=10, color="tab:red", label="jammed"),
    TRUNCATED: dict(marker="+", s=10, color="tab:orange", label="truncated"),
}


def plot_map(ds: xr.Dataset, out, ncols: int = 6) -> Path:
    """Draw every ``d`` of a map set and save to ``out`` (PNG, PDF, SVG...)."""
    d_values = np.atleast_1d(ds["d"].values)
    n = d_values.size
    ncols = min(ncols, n)
    nrows = math.ceil(n / ncols)
    fig, axes = plt.subplots(nrows, ncols, figsize=(2.4 * ncols + 0.6, 2.4 * nrows + 0.9),
                             sharex=True, sharey=True, squeeze=False)
    theta_i = ds["theta_i"].values
    seen = set()
    for k, d in enumerate(d_values):
        ax = axes[k // ncols][k % ncols]
        sub = ds.sel(d=d)
        status = sub["status"].values
        for code, style in _STYLE.items():
            sel = status == code
            if sel.any():
                label = style["label"] if code not in seen else None
                seen.add(code)
                ax.scatter(theta_i[sel], sub["theta_f"].values[sel], marker=style["marker"],
                           s=style["s"], color=style["color"], label=label, linewidths=0.8)
        ax.set_title(f"d = {d:+.2f}", fontsize=9)
        circle_axes(ax)
        ax.set_aspect("equal")
        ax.grid(True, lw=0.3, alpha=0.5)
    for k in range(n, nrows * ncols):
        axes[k // ncols][k % ncols].set_visible(False)
    for ax in axes[-1]:
        ax.set_xlabel(r"$\theta_i$ (deg)", fontsize=8)
    for row in axes:
        row[0].set_ylabel(r"$\theta_f$ (deg)", fontsize=8)
    attrs = ds.attrs
    unit = attrs.get("length_unit", "")
    fig.suptitle(f"Configuration maps: {attrs.get('part_name', 'part')}, model {attrs.get('model', '?')}, "
                 f"$\\mu_c$ = {attrs.get('mu_c', float('nan')):g}, pin radius "
                 f"{attrs.get('pin_radius', float('nan')):g} {unit}", fontsize=10)
    fig.legend(loc="upper right", fontsize=7, markerscale=2, frameon=False)
    fig.tight_layout(rect=(0, 0.02, 1, 0.95))
    return save_figure(fig, out)
