"""Figures, one module per kind. All use the paper's conventions: theta_i on
the x axis, theta_f on the y axis, degrees."""
from pathlib import Path

import matplotlib

matplotlib.use("Agg")  # files only: no display needed
import matplotlib.pyplot as plt  # noqa: E402 (after choosing the backend)


def save_figure(fig, out, dpi=130, **kwargs) -> Path:
    """Write ``fig`` to ``out`` (making its folder) and free it."""
    out = Path(out)
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out, dpi=dpi, **kwargs)
    plt.close(fig)
    return out


def circle_axes(ax):
    """Both axes 0..360 degrees with ticks every 90: theta_i on x, theta_f on y."""
    ax.set_xlim(0, 360)
    ax.set_ylim(0, 360)
    ax.set_xticks([0, 90, 180, 270, 360])
    ax.set_yticks([0, 90, 180, 270, 360])
    ax.tick_params(labelsize=7)
