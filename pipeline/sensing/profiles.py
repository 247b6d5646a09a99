"""A force/torque-sensing pin (spec section 7; the paper's section V).

Profiles. The force on the pin over the contact comes from the rollout's
force history (units of mu_s m g, world frame) against belt travel ``s``; at
belt speed ``v_b`` it is sampled at the sensor rate over time ``t = s / v_b``,
from first contact to the end of contact. A sensor at the top of a pin of
length ``L`` also reads the moments ``M_x = L F_y`` and ``M_y = -L F_x``.
Synthetic measurements add the sensor's bias and Gaussian noise to a rollout
whose inputs (theta_i, y_c, mu_c, pin position) were perturbed.

Processing, as in the paper: a moving average (``window`` samples), the time
gradients of the smoothed F_x and F_y, and the sign matrix S: rows F_x, F_y,
dF_x/dt, dF_y/dt, columns ``R`` equal regions of the contact period (4 R
elements; R = 10 gives the paper's 40). A force element is the sign of the
region's mean force; a gradient element the sign of the region's mean
gradient, i.e. of the force's change across the region. The score of a
measured profile against a simulated one is the number of equal elements.
The verdict is the best-scoring initial state; states scoring within
``margin`` of the best are reported with it as indistinguishable.

Dead zone and smoothing (deliberate choices; the paper gives neither). An
element is 0 when the region's mean force, or the force's change across the
region, is within ``dead_zone`` times the profile's peak force magnitude
``max |F|``. Both kinds of row use this one force scale, so the matrix does
not depend on the force unit (a profile in newtons scores like one in units
of mu_s m g) and the threshold does not depend on short transients.
Deviation from the first version of this module, which scaled each row by
its own largest magnitude: the gradient rows' largest magnitude is the spike
where the part slips off the pin at the end of contact (5 to 20 times the
gradient elsewhere), and its size depends on where the samples fall on that
spike, so a 0.3 degree change of theta_i or 0.2 mm of y_c moved the
threshold of every gradient element at once and flipped whole rows between
0 and +-1. Measured (30 trials per state, noise-free sensor): the
asymmetric triangle at 25 mm went from 100 % right with exact inputs to 59 %
right and 12 % wrong with theta_i perturbed by 0.3 degrees (60 % / 10 % for
y_c by 0.2 mm); now 100 % in all three. The moving average has a default
window of 25 samples (0.125 s at 200 Hz, against 9 before), capped at one
region's samples (:func:`effective_window`) so a short contact is not
smoothed across the regions its matrix resolves; with the config's noise and
perturbations the same case went from 38 % right and 10 % wrong to 94 % and
0 % (README, Sensing, has the whole table).
"""
from __future__ import annotations

import csv
import math
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np
from scipy.ndimage import uniform_filter1d

from pipeline.errors import PinfeedError
from pipeline.parts.contact import contact_parameter
from pipeline.parts.part import Part
from pipeline.planning import PERTURB_DEFAULTS, Perturbation, perturbed_inputs  # one set of sizes for every check


@dataclass
class Sensor:
    """A force/torque sensor on the first pin.

    Rate in Hz, belt speed in mm/s, pin length (sensor to contact) in mm,
    noise and biases in units of mu_s m g; ``window`` moving-average samples,
    ``regions``, ``dead_zone`` and ``margin`` set the sign-matrix classifier.
    """
    rate_hz: float = 200.0
    belt_speed: float = 20.0  # mm/s
    pin_length: float = 30.0  # mm, sensor to contact
    noise_sigma: float = 0.05  # mu_s m g, per sample
    bias_x: float = 0.03
    bias_y: float = -0.02
    window: int = 25  # moving-average samples
    regions: int = 10
    dead_zone: float = 0.05
    margin: int = 3

    @classmethod
    def from_config(cls, cfg: dict | None) -> "Sensor":
        """The sensor of a config's ``sensor`` section (defaults where missing)."""
        return cls(**(cfg or {}))

    def to_dict(self):
        """The sensor settings as a JSON-ready dict."""
        return asdict(self)


@dataclass
class Profile:
    """Force on the pin against time since first contact (units of the source)."""
    t: np.ndarray
    fx: np.ndarray
    fy: np.ndarray

    def moments(self, pin_length):
        """Moments ``(M_x, M_y)`` at the sensor for a pin of length ``pin_length`` (mm)."""
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
    """Moving average of ``values`` over ``window`` samples (edges repeat the end values)."""
    values = np.asarray(values, float)
    if window <= 1 or values.size < 2:
        return values.copy()
    return uniform_filter1d(values, size=min(window, values.size), mode="nearest")


def effective_window(n: int, sensor: Sensor) -> int:
    """The moving-average window for a profile of ``n`` samples: ``sensor.window``,
    but never wider than one region (``n // regions``), so that a short contact
    is not smoothed across the regions its sign matrix resolves."""
    return max(1, min(sensor.window, n // max(1, sensor.regions)))


def processed(profile: Profile, sensor: Sensor) -> dict:
    """Smoothed forces (window: :func:`effective_window`) and their time gradients."""
    w = effective_window(np.asarray(profile.t).size, sensor)
    fx, fy = smooth(profile.fx, w), smooth(profile.fy, w)
    t = np.asarray(profile.t, float)
    gx = np.gradient(fx, t) if fx.size > 1 else np.zeros_like(fx)
    gy = np.gradient(fy, t) if fy.size > 1 else np.zeros_like(fy)
    return {"t": t, "fx": fx, "fy": fy, "dfx": gx, "dfy": gy}


MAX_SAMPLES = 1_000_000  # a resampled profile (83 minutes at 200 Hz; a contact lasts seconds)
MAX_PROFILE_BYTES = 100 * 2**20  # a measured CSV file


def resample(profile: Profile, rate_hz: float) -> Profile:
    """The profile on a uniform grid at ``rate_hz`` from its first sample (linear
    interpolation), so a measurement at any rate is smoothed over the same time.
    Refuses more than ``MAX_SAMPLES`` samples before allocating them."""
    t = np.asarray(profile.t, float) - float(profile.t[0])
    span = float(t[-1]) * rate_hz
    if not span < MAX_SAMPLES:
        raise PinfeedError(f"the profile spans {t[-1]:.4g} s, {span:.3g} samples at {rate_hz:g} Hz, "
                           f"more than the limit of {MAX_SAMPLES:,}; check the time column is in "
                           f"seconds and give only the contact")
    n = max(2, int(math.floor(span + 1e-9)) + 1)
    grid = np.arange(n) / rate_hz
    return Profile(grid, np.interp(grid, t, profile.fx), np.interp(grid, t, profile.fy))


def sign_matrix(profile: Profile, sensor: Sensor) -> np.ndarray:
    """The ``4 x R`` sign matrix: rows F_x, F_y, dF_x/dt, dF_y/dt; columns regions.

    Force rows: sign of the region's mean smoothed force. Gradient rows: sign
    of the region's mean gradient times the region's duration (the force's
    change across it). Either is 0 within ``dead_zone`` x the peak of |F|.
    """
    p = processed(profile, sensor)
    n = p["t"].size
    out = np.zeros((4, sensor.regions), dtype=np.int8)
    if n < max(2, sensor.regions):
        return out  # no contact worth the name: all zeros
    peak = float(np.hypot(p["fx"], p["fy"]).max())
    if not peak > 0.0:
        return out
    edges = np.linspace(0, n, sensor.regions + 1).round().astype(int)
    dt = (p["t"][-1] - p["t"][0]) / (n - 1)
    span = np.diff(edges) * dt  # duration of each region
    for row, key in enumerate(("fx", "fy", "dfx", "dfy")):
        series = p[key]
        means = np.array([series[a:b].mean() for a, b in zip(edges[:-1], edges[1:])])
        if row >= 2:
            means = means * span  # change of force across the region
        signs = np.sign(means)
        signs[np.abs(means) <= sensor.dead_zone * peak] = 0
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
    if not np.any(measured):
        # No force above the dead zone: no contact, or a dead sensor. The zeros
        # would match whichever state's matrix has most zeros; decide nothing.
        # It may still be one of the states that miss the pin, if any do.
        missing = sorted(k for k, s in references.items() if not np.any(s))
        return {"scores": scores, "best": ranked[0], "candidates": missing or sorted(scores),
                "decided": False, "note": "no force above the dead zone: undecided"}
    return {"scores": scores, "best": ranked[0], "candidates": tied, "decided": len(tied) == 1}


# ---------------------------------------------------------------- simulation of the first pin


def first_pin_rollout(part: Part, theta, y_c, y_pin, mu_c, pin_radius, model):
    """The rollout of one resting state past the first pin, with trajectory and force.

    ``theta`` in degrees; ``y_c`` (centroid) and ``y_pin`` (pin) across the belt
    in mm; ``pin_radius`` in mm.
    """
    from pipeline.maps import simulate
    return simulate.rollout(part, theta, contact_parameter(y_pin, y_c, part.a), mu_c, pin_radius, model=model,
                            trajectory=True)


def reference_profiles(part, states: dict, y_pin, mu_c, pin_radius, model, sensor) -> dict:
    """Noise-free simulated profiles of every initial state at the first pin."""
    out = {}
    for label, s in states.items():
        r = first_pin_rollout(part, s["theta"], s["y_c"], y_pin, mu_c, pin_radius, model)
        out[label] = profile_from_rollout(r.force_s.values, r.force_x.values, r.force_y.values, sensor)
    return out


def synthetic_measurement(part, state: dict, y_pin, mu_c, pin_radius, model, sensor: Sensor,
                          perturb: dict, rng) -> Profile:
    """One synthetic reading of ``state`` at the pin: inputs drawn from the
    verify stage's perturbation box (:func:`pipeline.planning.claims.trials.perturbed_inputs`:
    theta_i and a friction value normal, truncated at 2 sigma, friction
    clipped at 0, a friction range ``(lo, hi)`` uniform; y_c and the pin
    position uniform; sizes from ``perturb``) rolled out again, sampled at the
    sensor rate, then sensor bias and noise."""
    theta, y_c, mu, offsets = perturbed_inputs(state["theta"], state["y_c"], mu_c, 1,
                                               Perturbation.from_section(perturb), rng)
    r = first_pin_rollout(part, theta, y_c, y_pin + float(offsets[0]), mu, pin_radius, model)
    prof = profile_from_rollout(r.force_s.values, r.force_x.values, r.force_y.values, sensor)
    return measure(prof, sensor, rng)


def score_table(part, states: dict, y_pin, mu_c, pin_radius, model, sensor: Sensor,
                trials: int = 20, perturb: dict | None = None, seed: int = 1,
                apart_fraction: float = 0.9, measured_mu=None) -> dict:
    """The paper's Table 4: mean score of simulated rows against measured columns.

    Simulated (reference) profiles are rolled out at the one friction ``mu_c``;
    measured profiles are synthetic (:func:`synthetic_measurement`), ``trials``
    per initial state, at friction ``measured_mu`` (a value or a range ``(lo,
    hi)``; default ``mu_c``). Returns the mean scores, the classification accuracy
    (decided and right), the rate of wrong decisions, and which pairs of
    states the sensor tells apart: in at least ``apart_fraction`` of the
    trials from either state the verdict excludes the other. ``groups`` are
    the states it cannot tell apart (connected through 'not apart').
    """
    perturb = dict(PERTURB_DEFAULTS, **(perturb or {}))
    measured = mu_c if measured_mu is None else measured_mu
    rng = np.random.default_rng(seed)
    refs = reference_profiles(part, states, y_pin, mu_c, pin_radius, model, sensor)
    ref_s = {k: sign_matrix(p, sensor) for k, p in refs.items()}
    labels = list(states)
    sums = {(a, b): 0.0 for a in labels for b in labels}
    correct = wrong = 0
    excludes = {(a, b): 0 for a in labels for b in labels}
    verdicts = []
    for truth in labels:
        for _ in range(trials):
            meas = sign_matrix(synthetic_measurement(part, states[truth], y_pin, measured, pin_radius,
                                                     model, sensor, perturb, rng), sensor)
            v = classify(meas, ref_s, sensor.margin)
            for sim in labels:
                sums[(sim, truth)] += v["scores"][sim]
                if sim not in v["candidates"]:
                    excludes[(truth, sim)] += 1
            correct += int(v["decided"] and v["best"] == truth)
            wrong += int(v["decided"] and v["best"] != truth)
            verdicts.append({"truth": truth, **v})
    mean = {sim: {meas: sums[(sim, meas)] / trials for meas in labels} for sim in labels}
    need = apart_fraction * trials
    apart = sorted({tuple(sorted((a, b))) for a in labels for b in labels if a < b
                    and excludes[(a, b)] >= need and excludes[(b, a)] >= need})
    n = trials * len(labels)
    return {"labels": labels, "mean_scores": mean, "elements": 4 * sensor.regions,
            "accuracy": correct / n, "wrong": wrong / n, "told_apart": [list(p) for p in apart],
            "groups": sensor_groups(labels, apart), "trials": trials, "verdicts": verdicts,
            "perturb": perturb, "seed": seed, "apart_fraction": apart_fraction,
            "reference_signs": {k: v.tolist() for k, v in ref_s.items()}}


def sensor_groups(labels, apart_pairs) -> list[list[str]]:
    """States the sensor cannot tell apart, grouped: the connected components of
    the relation 'not told apart' (conservative where it is not transitive)."""
    apart = {tuple(sorted(p)) for p in apart_pairs}
    parent = {lab: lab for lab in labels}

    def root(x):
        while parent[x] != x:
            parent[x] = parent[parent[x]]
            x = parent[x]
        return x

    for i, a in enumerate(labels):
        for b in labels[i + 1:]:
            if tuple(sorted((a, b))) not in apart:
                parent[root(b)] = root(a)
    groups = {}
    for lab in labels:
        groups.setdefault(root(lab), []).append(lab)
    return sorted(groups.values(), key=lambda g: labels.index(g[0]))


def read_profile_csv(path) -> Profile:
    """Read a measured profile: CSV with columns time (s), F_x, F_y (any force unit).

    A header row is allowed (it is skipped if not numeric); extra columns are
    ignored; time must increase. Raises :class:`PinfeedError` naming the problem.
    """
    path = Path(path)
    if not path.is_file():
        raise PinfeedError(f"no profile file at {path}; give a CSV with columns time, F_x, F_y")
    if path.stat().st_size > MAX_PROFILE_BYTES:
        raise PinfeedError(f"{path} is {path.stat().st_size / 2**20:.0f} MiB, more than the limit of "
                           f"{MAX_PROFILE_BYTES // 2**20} MiB for a profile; give only the contact")
    try:
        rows = _profile_rows(path)
    except (UnicodeDecodeError, csv.Error):
        raise PinfeedError(f"{path} is not a text CSV file (binary data?); give a CSV with columns "
                           f"time, F_x, F_y") from None
    if len(rows) < 2:
        raise PinfeedError(f"{path}: needs at least two samples of time, F_x, F_y")
    arr = np.asarray(rows)
    if np.any(np.diff(arr[:, 0]) <= 0):
        raise PinfeedError(f"{path}: time must increase from row to row")
    return Profile(arr[:, 0] - arr[0, 0], arr[:, 1], arr[:, 2])


def _profile_rows(path: Path) -> list:
    rows = []
    with open(path, newline="", encoding="utf-8") as fh:
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
    return rows
