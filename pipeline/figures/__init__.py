"""Figures, one module per kind. All use the paper's conventions: theta_i on
the x axis, theta_f on the y axis, degrees."""
import matplotlib

matplotlib.use("Agg")  # files only: no display needed
