"""A force/torque-sensing pin (spec section 7; the paper's section V).

Profiles. The force on the pin over the contact comes from the rollout's
force history (units of mu_s m g, world frame) against belt travel ``s``; at
belt speed ``v_b`` it is sampled at the sensor rate over time ``t = s / v_b``,
from first contact to the end of contact. A sensor at the top of a pin of
length ``L`` also reads the moments ``M_x = L F_y`` and ``M_y = -L F_x``.

Processing, as in the paper: a moving average (``window`` samples), the time
gradients of the smoothed F_x and F_y, and the sign matrix S: the signs of
F_x, F_y, dF_x/dt and dF_y/dt averaged over each of ``R`` equal regions of
the contact period (4 R elements; R = 10 gives the paper's 40). A sign is 0
where the region's value is within ``dead_zone`` of the profile's largest
magnitude, so the matrix does not depend on the force unit: a measured
profile in newtons scores like one in units of mu_s m g. The score of a
measured profile against a simulated one is the number of equal elements.
The verdict is the best-scoring initial state; states scoring within
``margin`` of the best are reported with it as indistinguishable.
"""
from __future__ import annotations

import csv
import math
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np
from scipy.ndimage import uniform_filter1d

from .errors import PinfeedError
from .parts import Part


@dataclass
class Sensor:
    rate_hz: float = 200.0
    belt_speed: float = 20.0  # mm/s
    pin_length: float = 30.0  # mm, sensor to contact
    noise_sigma: float = 0.05  # mu_s m g, per sample
    bias_x: float = 0.03
    bias_y: float = -0.02
    window: int = 9  # moving-average samples
    regions: int = 10
    dead_zone: float = 0.05
    margin: int = 3

    @classmethod
    def from_config(cls, cfg: dict | None) -> "Sensor":
        return cls(**(cfg or {}))

    def to_dict(self):
        return asdict(self)


@dataclass
class Profile:
    """Force on the pin against time since first contact (units of the source)."""
    t: np.ndarray
    fx: np.ndarray
    fy: np.ndarray

    def moments(self, pin_length):
        return pin_length * self.fy, -pin_length * self.fx


def profile_from_rollout(force_s, force_x, force_y, sensor: Sensor) -> Profile:
    """Sample a rollout's force history at the sensor rate (no noise)."""
    s = np.asarray(force_s, float)
    if s.size < 2 or s[-1] <= 0:
        return Profile(np.zeros(1), np.zeros(1), np.zeros(1))
    t_end = s[-1] / sensor.belt_speed
    n = max(2, int(math.floor(t_end * sensor.rate_hz)) + 1)
    t = np.arange(n) / sensor.rate_hz
    ts = s / sensor.belt_speed
    # The history ends with a drop to zero at separation: sample the force
    # held before it, so the last sample is not an interpolation artefact.
    fx = np.interp(t, ts[:-1], np.asarray(force_x, float)[:-1])
    fy = np.interp(t, ts[:-1], np.asarray(force_y, float)[:-1])
    return Profile(t, fx, fy)


def measure(profile: Profile, sensor: Sensor, rng) -> Profile:
    """A synthetic measurement: the profile plus bias and Gaussian noise."""
    return Profile(profile.t, profile.fx + sensor.bias_x + rng.normal(0, sensor.noise_sigma, profile.t.size),
                   profile.fy + sensor.bias_y + rng.normal(0, sensor.noise_sigma, profile.t.size))


def smooth(values, window: int) -> np.ndarray:
    values = np.asarray(values, float)
    if window <= 1 or values.size < 2:
        return values.copy()
    return uniform_filter1d(values, size=min(window, values.size), mode="nearest")


def processed(profile: Profile, sensor: Sensor) -> dict:
    """Smoothed forces and their time gradients."""
    fx, fy = smooth(profile.fx, sensor.window), smooth(profile.fy, sensor.window)
    dt = 1.0 / sensor.rate_hz
    gx = np.gradient(fx, dt) if fx.size > 1 else np.zeros_like(fx)
    gy = np.gradient(fy, dt) if fy.size > 1 else np.zeros_like(fy)
    return {"t": profile.t, "fx": fx, "fy": fy, "dfx": gx, "dfy": gy}


def sign_matrix(profile: Profile, sensor: Sensor) -> np.ndarray:
    """The ``4 x R`` sign matrix: rows F_x, F_y, dF_x/dt, dF_y/dt; columns regions."""
    p = processed(profile, sensor)
    n = p["t"].size
    out = np.zeros((4, sensor.regions), dtype=np.int8)
    if n < sensor.regions:
        return out  # no contact worth the name: all zeros
    edges = np.linspace(0, n, sensor.regions + 1).round().astype(int)
    for row, key in enumerate(("fx", "fy", "dfx", "dfy")):
        series = p[key]
        means = np.array([series[a:b].mean() for a, b in zip(edges[:-1], edges[1:])])
        scale = np.abs(series).max()
        signs = np.sign(means)
        signs[np.abs(means) <= sensor.dead_zone * scale] = 0
        out[row] = signs
    return out


def score(measured: np.ndarray, simulated: np.ndarray) -> int:
    """Number of equal elements (the paper's 'k/40')."""
    return int((np.asarray(measured) == np.asarray(simulated)).sum())


def classify(measured: np.ndarray, references: dict, margin: int) -> dict:
    """Scores against every reference sign matrix, the best state and the
    states within ``margin`` of it (indistinguishable from the best)."""
    scores = {k: score(measured, s) for k, s in references.items()}
    best = max(scores.values())
    tied = sorted(k for k, v in scores.items() if best - v < margin)
    ranked = sorted(scores, key=lambda k: (-scores[k], k))
    return {"scores": scores, "best": ranked[0], "candidates": tied, "decided": len(tied) == 1}


# ---------------------------------------------------------------- simulation of the first pin


def first_pin_rollout(part: Part, theta, y_c, y_pin, mu_c, pin_radius, model):
    from . import simulate
    return simulate.rollout(part, theta, (y_pin - y_c) / part.a, mu_c, pin_radius, model=model,
                            trajectory=True)


def reference_profiles(part, states: dict, y_pin, mu_c, pin_radius, model, sensor) -> dict:
    """Noise-free simulated profiles of every initial state at the first pin."""
    out = {}
    for label, s in states.items():
        r = first_pin_rollout(part, s["theta"], s["y_c"], y_pin, mu_c, pin_radius, model)
        out[label] = profile_from_rollout(r.force_s.values, r.force_x.values, r.force_y.values, sensor)
    return out


def score_table(part, states: dict, y_pin, mu_c, pin_radius, model, sensor: Sensor,
                trials: int = 20, perturb: dict | None = None, seed: int = 1) -> dict:
    """The paper's Table 4: mean score of simulated rows against measured columns.

    Measured profiles are synthetic: perturbed inputs (theta, y_c, mu_c, pin
    position) rolled out again, then sensor bias and noise. Also returns the
    classification accuracy and which pairs of states the sensor tells apart
    (in at least 90 % of trials from either state the verdict excludes the other).
    """
    perturb = dict({"theta_sigma": 1.0, "y_halfwidth": 0.5, "mu_sigma": 0.02, "pin_halfwidth": 0.3},
                   **(perturb or {}))
    rng = np.random.default_rng(seed)
    refs = reference_profiles(part, states, y_pin, mu_c, pin_radius, model, sensor)
    ref_s = {k: sign_matrix(p, sensor) for k, p in refs.items()}
    labels = list(states)
    sums = {(a, b): 0.0 for a in labels for b in labels}
    correct = 0
    excludes = {(a, b): 0 for a in labels for b in labels}
    verdicts = []
    for truth in labels:
        s = states[truth]
        for _ in range(trials):
            r = first_pin_rollout(part, s["theta"] + rng.normal(0, perturb["theta_sigma"]),
                                  s["y_c"] + rng.uniform(-perturb["y_halfwidth"], perturb["y_halfwidth"]),
                                  y_pin + rng.uniform(-perturb["pin_halfwidth"], perturb["pin_halfwidth"]),
                                  max(0.0, mu_c + rng.normal(0, perturb["mu_sigma"])), pin_radius, model)
            prof = profile_from_rollout(r.force_s.values, r.force_x.values, r.force_y.values, sensor)
            meas = sign_matrix(measure(prof, sensor, rng), sensor)
            v = classify(meas, ref_s, sensor.margin)
            for sim in labels:
                sums[(sim, truth)] += v["scores"][sim]
                if sim not in v["candidates"]:
                    excludes[(truth, sim)] += 1
            correct += int(v["decided"] and v["best"] == truth)
            verdicts.append({"truth": truth, **v})
    mean = {sim: {meas: sums[(sim, meas)] / trials for meas in labels} for sim in labels}
    apart = sorted({tuple(sorted((a, b))) for a in labels for b in labels if a < b
                    and excludes[(a, b)] >= 0.9 * trials and excludes[(b, a)] >= 0.9 * trials})
    return {"labels": labels, "mean_scores": mean, "elements": 4 * sensor.regions,
            "accuracy": correct / (trials * len(labels)), "told_apart": [list(p) for p in apart],
            "groups": sensor_groups(labels, apart), "trials": trials, "verdicts": verdicts,
            "reference_signs": {k: v.tolist() for k, v in ref_s.items()}}


def sensor_groups(labels, apart_pairs) -> list[list[str]]:
    """States the sensor cannot tell apart, grouped (connected by 'not apart')."""
    apart = {tuple(sorted(p)) for p in apart_pairs}
    groups = []
    for lab in labels:
        for g in groups:
            if any(tuple(sorted((lab, m))) not in apart for m in g):
                g.append(lab)
                break
        else:
            groups.append([lab])
    return groups


def read_profile_csv(path) -> Profile:
    """Read a measured profile: CSV with columns time (s), F_x, F_y (any force unit).

    A header row is allowed (it is skipped if not numeric); extra columns are
    ignored; time must increase. Raises :class:`PinfeedError` naming the problem.
    """
    path = Path(path)
    if not path.is_file():
        raise PinfeedError(f"no profile file at {path}; give a CSV with columns time, F_x, F_y")
    rows = []
    with open(path, newline="") as fh:
        for k, rec in enumerate(csv.reader(fh), start=1):
            if not rec or all(not c.strip() for c in rec):
                continue
            try:
                vals = [float(c) for c in rec[:3]]
            except ValueError:
                if not rows and k == 1:
                    continue  # header
                raise PinfeedError(f"{path}, line {k}: not three numbers (time, F_x, F_y): {rec!r}") from None
            if len(vals) < 3:
                raise PinfeedError(f"{path}, line {k}: needs three columns time, F_x, F_y")
            if not all(math.isfinite(v) for v in vals):
                raise PinfeedError(f"{path}, line {k}: values must be finite")
            rows.append(vals)
    if len(rows) < 2:
        raise PinfeedError(f"{path}: needs at least two samples of time, F_x, F_y")
    arr = np.asarray(rows)
    if np.any(np.diff(arr[:, 0]) <= 0):
        raise PinfeedError(f"{path}: time must increase from row to row")
    return Profile(arr[:, 0] - arr[0, 0], arr[:, 1], arr[:, 2])
