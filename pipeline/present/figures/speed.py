"""How fast may a plan run: its success against belt speed, the limit marked."""
from __future__ import annotations

from pathlib import Path

import matplotlib.pyplot as plt

from pipeline.present.figures import save_figure

LIMIT_COLOUR = "#b2182b"


def plot_speed_curve(result: dict, out, title: str | None = None) -> Path:
    """Draw a speed result (``speed_limit.stored_plan_speed``) to ``out``
    (see :func:`speed_curve_figure`)."""
    return save_figure(speed_curve_figure(result, title), out)


def speed_curve_figure(result: dict, title: str | None = None):
    """The figure of a speed result (``speed_limit.stored_plan_speed``).

    x: belt speed in mm/s; y: fraction of the trials that end in the plan's
    final set. The required fraction is a dashed horizontal line, the speed
    limit a vertical line (labelled with its value), the belt speed the plan
    was planned at (if any) a dotted one; all are in the legend.
    """
    speeds = [row[0] for row in result["curve"]]
    fractions = [row[1] for row in result["curve"]]
    required = float(result.get("required", 0.99))
    limit = float(result["speed_limit_mm_s"])
    fig, ax = plt.subplots(figsize=(6.4, 3.8))
    ax.plot(speeds, fractions, "o-", color="#2166ac", ms=4,
            label=f"replays ({result.get('trials_per_speed', '?')} trials per speed)")
    ax.axhline(required, color="0.4", ls="--", lw=1, label=f"required: {100 * required:g} %")
    if limit > 0:
        ax.axvline(limit, color=LIMIT_COLOUR, lw=1.5, label=f"speed limit: {limit:g} mm/s")
    else:
        ax.plot([], [], color=LIMIT_COLOUR, lw=1.5, label="speed limit: none (fails at every speed)")
    planned = result.get("planned_belt_speed")
    if planned:
        ax.axvline(planned, color="0.2", ls=":", lw=1.2, label=f"planned at {planned:g} mm/s")
    ax.set_xlabel("belt speed (mm/s)")
    ax.set_ylabel("fraction of trials in the final set")
    ax.set_xlim(0, max(speeds + [limit, planned or 0.0]) * 1.05)
    low = min(fractions + [required])
    ax.set_ylim(max(0.0, low - 0.05), 1.02)
    ax.grid(alpha=0.3)
    ax.legend(loc="lower left", fontsize=8)
    pins = " ".join(result.get("pin_labels", []))
    ax.set_title(title or f"{result.get('part', '')}: plan {pins}, mu_c {result.get('friction', '')}, "
                          f"mu_s {result.get('mu_s', 0.5):g}", fontsize=9)
    fig.tight_layout()
    return fig
