"""Figures, one module per kind. All use the paper's conventions: theta_i on
the x axis, theta_f on the y axis, degrees."""
import matplotlib

matplotlib.use("Agg")  # files only: no display needed


def circle_axes(ax):
    """Both axes 0..360 degrees with ticks every 90: theta_i on x, theta_f on y."""
    ax.set_xlim(0, 360)
    ax.set_ylim(0, 360)
    ax.set_xticks([0, 90, 180, 270, 360])
    ax.set_yticks([0, 90, 180, 270, 360])
    ax.tick_params(labelsize=7)
