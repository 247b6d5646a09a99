"""Configuration maps with their bands, as in the paper's Table 1 and Fig. 4.

Each band is drawn as its rectangle(s) B_j x K_j: theta_f in the band B_j
(y) over the initial orientations K_j that land in it (x; K_j may be several
arcs). The adjusted band m_j +- c sigma_j is drawn over the same K_j as a
hatched outline, so both stay visible where they overlap. Rectangles that
wrap through 0/360 are split; every rectangle is at least ``MIN_THICKNESS``
degrees thick so that a band of identical theta_f (zero width) still shows.
"""
from __future__ import annotations

import math
import textwrap
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.lines import Line2D
from matplotlib.patches import Patch, Rectangle

from kernels.rollout import JAMMED, MISS, OK, TRUNCATED

from pipeline.planning import extract_bands
from pipeline.present.figures import circle_axes, save_figure

MIN_THICKNESS = 3.0  # degrees: the thinnest band B_j or kernel K_j drawn
BAND_STYLE = dict(facecolor="tab:blue", edgecolor="tab:blue", alpha=0.25, lw=0.6)
ADJ_STYLE = dict(facecolor="none", edgecolor="tab:orange", hatch="////", lw=1.0)
POINTS = {
    OK: dict(marker=".", s=3, color="navy", label=r"$\theta_f$ (contact, ok)"),
    MISS: dict(marker=".", s=3, color="0.65", label="miss (no contact)"),
    JAMMED: dict(marker="x", s=9, color="tab:red", label="jammed"),
    TRUNCATED: dict(marker="+", s=9, color="tab:purple", label="truncated"),
}


def arc_segments(start: float, width: float, min_width: float = 0.0) -> list[tuple[float, float]]:
    """The arc ``start + [0, width]`` (degrees) as ``(lo, hi)`` pieces inside
    [0, 360], widened about its middle to at least ``min_width``."""
    if width >= 360.0:
        return [(0.0, 360.0)]
    if width < min_width:
        start, width = start - 0.5 * (min_width - width), min_width
    lo = start % 360.0
    hi = lo + width
    if hi <= 360.0:
        return [(lo, hi)]
    return [(lo, 360.0), (0.0, hi - 360.0)]


def kernel_arc_segments(kernel_arcs, step: float) -> list[tuple[float, float]]:
    """K_j's arcs of grid points (degrees), each point standing for ``+- step/2``."""
    out = []
    for start, width in kernel_arcs:
        out += arc_segments(start - 0.5 * step, min(width + step, 360.0), MIN_THICKNESS)
    return out


def band_rectangles(band, step: float, adjusted: bool = False) -> list[tuple[float, float, float, float]]:
    """``(x, y, width, height)`` of the rectangles B_j x K_j (or the adjusted band x K_j)."""
    ys = (arc_segments(band.adj_start, band.adj_width, MIN_THICKNESS) if adjusted
          else arc_segments(band.start, band.width, MIN_THICKNESS))
    return [(x0, y0, x1 - x0, y1 - y0) for x0, x1 in kernel_arc_segments(band.kernel_arcs, step) for y0, y1 in ys]


def draw_map_panel(ax, theta_i, theta_f, dy, status, threshold_T, factor_c) -> list:
    """One map (one d): band and adjusted-band rectangles, then the points.
    Returns the bands drawn. Rectangles carry gid ``band j`` / ``adjusted j``."""
    step = float(np.median(np.diff(theta_i))) if len(theta_i) > 1 else 1.0
    bands = extract_bands(theta_i, theta_f, dy, status, threshold_T, factor_c)
    for j, b in enumerate(bands):
        for x, y, w, h in band_rectangles(b, step):
            ax.add_patch(Rectangle((x, y), w, h, gid=f"band {j}", zorder=1, **BAND_STYLE))
        for x, y, w, h in band_rectangles(b, step, adjusted=True):
            ax.add_patch(Rectangle((x, y), w, h, gid=f"adjusted {j}", zorder=2, **ADJ_STYLE))
    for code, style in POINTS.items():
        sel = status == code
        if sel.any():
            # Misses and jams keep theta_f = theta_i; draw them where they start.
            ax.scatter(theta_i[sel], theta_f[sel], zorder=3, linewidths=0.7,
                       **{k: v for k, v in style.items() if k != "label"})
    circle_axes(ax)
    ax.set_aspect("equal")
    return bands


def legend_handles(factor_c: float, statuses) -> list:
    """Legend entries: the band, the adjusted band, and each status present."""
    handles = [Patch(label=r"band $B_j \times K_j$", **BAND_STYLE),
               Patch(label=rf"adjusted band $m_j \pm {factor_c:g}\sigma_j$", **ADJ_STYLE)]
    for code, style in POINTS.items():
        if code in statuses:
            handles.append(Line2D([], [], ls="", marker=style["marker"], color=style["color"],
                                  markersize=6, label=style["label"]))
    return handles


def bottom_legend(fig, handles) -> float:
    """A legend under the panels, wrapped into as many rows as the figure's width
    needs; returns the fraction of the height it takes (for ``tight_layout``'s rect)."""
    width, height = fig.get_size_inches()
    per_row = max(1, min(len(handles), int(width // 2.3)))
    rows = math.ceil(len(handles) / per_row)
    legend = fig.legend(handles=handles, loc="lower center", ncol=per_row, fontsize=8, frameon=False)
    # Measured, not estimated: a row of mathtext labels is taller than plain text.
    measured = legend.get_window_extent(fig.canvas.get_renderer()).height / fig.dpi
    return (max(measured, 0.28 * rows) + 0.1) / height


def plot_band_maps(maps_by_model: dict, d_values, threshold_T, factor_c, title, out) -> Path:
    """``maps_by_model``: row label (a model, or a pin speed; mathtext allowed) ->
    Dataset with dims (d, theta_i). Rows: those labels; columns: d."""
    return save_figure(band_maps_figure(maps_by_model, d_values, threshold_T, factor_c, title), out)


def band_maps_figure(maps_by_model: dict, d_values, threshold_T, factor_c, title):
    """The figure of :func:`plot_band_maps`, unsaved."""
    rows = list(maps_by_model)
    fig, axes = plt.subplots(len(rows), len(d_values), figsize=(max(2.5 * len(d_values) + 0.8, 7.0),
                             2.6 * len(rows) + 1.5), sharex=True, sharey=True, squeeze=False)
    seen = set()
    for r, label in enumerate(rows):
        ds = maps_by_model[label]
        for c, d in enumerate(d_values):
            ax = axes[r][c]
            sub = ds.sel(d=d, method="nearest")
            st = sub["status"].values
            seen.update(np.unique(st).tolist())
            draw_map_panel(ax, ds["theta_i"].values, sub["theta_f"].values, sub["dy"].values, st,
                           threshold_T, factor_c)
            ax.set_title(f"{label}, $d$ = {float(sub['d']):+.2f}", fontsize=8)
            ax.tick_params(labelbottom=True, labelleft=True)  # tick labels on every panel
            ax.set_xlabel(r"$\theta_i$ (deg)", fontsize=8)
            if c == 0:
                ax.set_ylabel(r"$\theta_f$ (deg)", fontsize=8)
    bottom = bottom_legend(fig, legend_handles(factor_c, seen))
    width, height = fig.get_size_inches()
    # The title wrapped to the figure's width, and the panels kept below it.
    title = textwrap.fill(title, int(11 * width), break_on_hyphens=False)
    fig.suptitle(title, fontsize=10)
    fig.tight_layout(rect=(0, bottom, 1, 1 - (0.12 + 0.2 * title.count("\n") + 0.2) / height))
    return fig
