"""Force/torque sensing figures: the profiles per initial state (the paper's
Table 3) and the score matrix (the paper's Table 4)."""
from __future__ import annotations

from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

from pipeline.present.figures import save_figure
from pipeline.sensing.profiles import Sensor, processed, sign_matrix

_ROWS = (("fx", r"$F_x$ ($\mu_s m g$)"), ("fy", r"$F_y$ ($\mu_s m g$)"),
         ("dfx", r"$dF_x/dt$ ($\mu_s m g$/s)"), ("dfy", r"$dF_y/dt$ ($\mu_s m g$/s)"))
_SIGN = {1: "+", -1: "−", 0: "0"}


def plot_profiles(simulated: dict, measured: dict, sensor: Sensor, title, out) -> Path:
    """``simulated``/``measured``: initial-state label -> ``sensing.Profile`` (noise-free
    simulation; one synthetic measurement). Columns: initial states; rows: F_x,
    F_y (raw measurement, smoothed, simulation) and their gradients (smoothed
    measurement, simulation), with the regions and the measured sign matrix."""
    labels = list(simulated)
    fig, axes = plt.subplots(4, len(labels), figsize=(3.6 * len(labels) + 0.8, 9.0), squeeze=False,
                             sharex="col")
    for c, label in enumerate(labels):
        sim, meas = simulated[label], measured[label]
        ps, pm = processed(sim, sensor), processed(meas, sensor)
        signs = sign_matrix(meas, sensor)
        n = pm["t"].size
        edges = np.linspace(0, n, sensor.regions + 1).round().astype(int)
        bounds = [pm["t"][min(e, n - 1)] for e in edges]
        for r, (key, ylabel) in enumerate(_ROWS):
            ax = axes[r][c]
            if r < 2:
                ax.plot(meas.t, getattr(meas, key), color="0.75", lw=0.6, label="measured (raw)")
            ax.plot(pm["t"], pm[key], color="tab:blue", lw=1.2,
                    label="measured, smoothed")
            ax.plot(ps["t"], ps[key], color="tab:red", lw=1.0, ls="--", label="simulated (no noise)")
            ax.axhline(0.0, color="k", lw=0.5)
            if n >= sensor.regions:
                for b in bounds[1:-1]:
                    ax.axvline(b, color="0.85", lw=0.5, zorder=0)
                for k in range(sensor.regions):
                    ax.text(0.5 * (bounds[k] + bounds[k + 1]), 1.0, _SIGN[int(signs[r, k])],
                            transform=ax.get_xaxis_transform(), ha="center", va="bottom", fontsize=7)
            if c == 0:
                ax.set_ylabel(ylabel, fontsize=8)
            ax.tick_params(labelsize=7)
            if r == 0:
                ax.set_title(label, fontsize=9, pad=12)  # room for the signs above the panel
        axes[-1][c].set_xlabel("time since first contact t (s)", fontsize=8)
    handles, names = [], []
    for r in (0, 2):
        for h, nm in zip(*axes[r][0].get_legend_handles_labels()):
            if nm not in names:
                handles.append(h)
                names.append(nm)
    fig.legend(handles, names, loc="lower center", ncol=4, fontsize=8, frameon=False)
    fig.suptitle(f"{title}\nsigns above each panel: the measured sign matrix over "
                 f"{sensor.regions} regions (+, −, 0 within the dead zone)", fontsize=9)
    fig.tight_layout(rect=(0, 0.04, 1, 0.96))
    return save_figure(fig, out)


def plot_scores(table: dict, title, out) -> Path:
    """The score matrix: simulated initial states (rows) x measured ones (columns),
    mean scores out of ``elements``, accuracy in the title."""
    labels = table["labels"]
    m = np.array([[table["mean_scores"][s][k] for k in labels] for s in labels])
    n = table["elements"]
    fig, ax = plt.subplots(figsize=(1.6 * len(labels) + 2.4, 1.2 * len(labels) + 1.8))
    im = ax.imshow(m, cmap="Blues", vmin=0.5 * n, vmax=n)
    for i in range(len(labels)):
        for j in range(len(labels)):
            ax.text(j, i, f"{m[i, j]:.1f}/{n}", ha="center", va="center", fontsize=9,
                    color="white" if m[i, j] > 0.85 * n else "black")
    ax.set_xticks(range(len(labels)), labels, fontsize=8)
    ax.set_yticks(range(len(labels)), labels, fontsize=8)
    ax.set_xlabel("measured (synthetic) initial state", fontsize=8)
    ax.set_ylabel("simulated initial state", fontsize=8)
    fig.colorbar(im, ax=ax, fraction=0.046, pad=0.04, label="mean score (equal elements)")
    groups = " ".join("{" + ", ".join(g) + "}" for g in table["groups"])
    ax.set_title(f"{title}\naccuracy {100 * table['accuracy']:.0f} %, wrong "
                 f"{100 * table['wrong']:.0f} % ({table['trials']} trials per state)\n"
                 f"states the sensor cannot tell apart: {groups}", fontsize=8)
    fig.tight_layout()
    return save_figure(fig, out)


def sensing_figures(result: dict, out_profiles, out_scores) -> tuple[Path, Path]:
    """Both figures for a stored sensing result (``RESULTS/sensing/NAME.json``)."""
    from pipeline.parts.part import Part
    from pipeline.sensing.profiles import PERTURB_DEFAULTS, reference_profiles, synthetic_measurement
    part = Part.from_dict(result["part"])
    name = part.name
    if not result.get("found"):
        from pipeline.present.figures import placeholder
        for path in (out_profiles, out_scores):
            placeholder(path, f"{name}: no allowed plan within depth {result['depth']}: no sensor plan")
        return Path(out_profiles), Path(out_scores)
    sensor = Sensor.from_config(result["sensor"])
    table = result["score_table"]
    states = result["initial_states"]
    common = (result["pin_radius"], result["model"], sensor)
    # References at the one friction of the profiles; measurements over the planned friction.
    sim = reference_profiles(part, states, result["y_pin"], result["mu_c_profiles"], *common)
    rng = np.random.default_rng(table["seed"])
    perturb = dict(PERTURB_DEFAULTS, **table["perturb"])
    meas = {k: synthetic_measurement(part, s, result["y_pin"], result["mu_c"], *common, perturb, rng)
            for k, s in states.items()}
    where = f"sensor on {result['first_pin']} at y = {result['y_pin']:g} mm"
    friction = f"mu_c {result['friction']} (simulated profiles at {result['mu_c_profiles']:g})"
    plot_profiles(sim, meas, sensor, f"{name}: force on the pin, {where}; belt "
                  f"{sensor.belt_speed:g} mm/s, {sensor.rate_hz:g} Hz, moving average of "
                  f"{sensor.window} samples", out_profiles)
    plot_scores(table, f"{name}: sign-matrix scores, {where}\n{friction}", out_scores)
    return Path(out_profiles), Path(out_scores)

