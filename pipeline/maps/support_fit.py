"""Fit a point support to measured pushes (``pinfeed support fit``).

A *push* is one passage of a part past one pin: its initial orientation
``theta_i`` (deg), its contact parameter ``d`` and the measured final
orientation ``theta_f`` (deg), optionally its own pin friction ``mu_c``. The
fit finds the ``K`` support points (part frame) whose quasi-static rollouts
(model minpower) reproduce the measured ``theta_f`` best.

Method
------
- *Weights by statics.* A rigid part at rest presses with its centre of
  pressure at its centroid, so the weights are not free: for given points
  they are the non-negative solution of ``sum w_k p_k = 0``, ``sum w_k = 1``
  nearest to equal weights (``scipy.optimize.nnls`` on the equations, and a
  pull towards ``1/K`` weighted ``PULL`` times less); for ``K = 3`` that is
  the centroid's barycentric coordinates. Points whose hull does not hold the centroid
  cannot balance the part and are rejected.
- *Loss.* The residual of a push is ``wrap(theta_f_model - theta_f_measured)``
  in (-180, 180] deg. A push the model misses keeps its orientation (the
  residual compares ``theta_i`` with the measurement); a push the model jams
  or truncates has no final orientation and counts ``OUTCOME_PENALTY_DEG``,
  in the loss and in the reported residuals and statistics. The loss is the
  sum of ``HUBER_DEG^2 * 2 (sqrt(1 + (r / HUBER_DEG)^2) - 1)`` (soft L1:
  quadratic for small residuals, linear for outliers, so one bad
  measurement does not drag the fit).
- *Search.* ``starts`` random tripods (or ``K`` points) in the outline
  (:func:`~pipeline.parts.support_family.sample_tripods` for ``K = 3``) are
  scored; from each of the ``refine`` best, a trust-region least-squares solver
  (``scipy.optimize.least_squares``, method ``trf``, the same soft-L1 loss,
  finite-difference Jacobian) moves the ``2K`` coordinates. While it
  searches, a point off the material (outside the outline, or in a hole of
  a part with holes) is moved to the nearest point of the material's edge
  (the outline, or that hole's rim) and a layout that cannot balance the
  part keeps its nearest weights; both pay a penalty residual of
  ``PENALTY_DEG_PER_MM`` per mm of the violation, so the solver sees a
  continuous loss and walks back. One more
  run starts from the best feasible layout so far with a fresh trust
  region; the answer is the best *feasible* layout any evaluation saw
  (points on the material, centre of pressure at the centroid).
  Gauss-Newton steps use the residuals' structure that a simplex search
  (Nelder-Mead, the first version) ignores: four to seven times fewer
  rollouts, and it converges where the simplex stalled short of the light
  legs. The light legs are weakly determined even so (README: measured
  recovery); fits from two ``seed`` values that agree are the check.

The result reports per-push residuals and their RMS, median and 90th
percentile of ``|r|``, next to those of uniform pressure on the same pushes,
so a user sees whether the support explains the data better.
"""
from __future__ import annotations

import csv
import math
from dataclasses import dataclass
from pathlib import Path
from types import SimpleNamespace

import numpy as np
from scipy import optimize

from pipeline.errors import PinfeedError
from pipeline.maps import simulate
from pipeline.parts.part import Part
from pipeline.parts.support import (Support, format_mm, material_distance, on_print_grid,
                                    point_support)
from pipeline.progress import Heartbeat

COLUMNS = ("theta_i_deg", "d", "theta_f_deg")
OPTIONAL = ("mu_c",)
OUTCOME_PENALTY_DEG = 90.0  # residual of a push the model misses or jams
HUBER_DEG = 2.0  # residuals beyond this count linearly in the loss
PULL = 1e-4  # weight of the pull towards equal weights against the statics equations
MAX_PUSHES = 100_000
PENALTY_DEG_PER_MM = 100.0  # residual per mm a layout lies outside the outline or off statics
MAX_NFEV = 60  # least-squares residual evaluations per start (each 2K + 1 for a Jacobian)


@dataclass
class Pushes:
    """Measured pushes: arrays of equal length (degrees; ``mu_c`` may be NaN: use the default)."""
    theta_i: np.ndarray
    d: np.ndarray
    theta_f: np.ndarray
    mu_c: np.ndarray

    def __len__(self) -> int:
        return int(self.theta_i.size)


def read_pushes(path) -> Pushes:
    """Read a pushes CSV: a header naming ``theta_i_deg``, ``d``, ``theta_f_deg``
    (and optionally ``mu_c``), one push per row. Any problem is a one-line
    :class:`PinfeedError`."""
    path = Path(path)
    if not path.is_file():
        raise PinfeedError(f"pushes file {path} not found; give a CSV with the header "
                           f"{','.join(COLUMNS)}[,mu_c]")
    try:
        with path.open(newline="") as fh:
            rows = list(csv.reader(line for line in fh if line.strip() and not line.startswith("#")))
    except (OSError, UnicodeDecodeError, csv.Error) as err:
        raise PinfeedError(f"cannot read pushes file {path}: {err}") from None
    if not rows:
        raise PinfeedError(f"pushes file {path} is empty; give the header {','.join(COLUMNS)}[,mu_c] "
                           f"and one push per row")
    header = [h.strip() for h in rows[0]]
    missing = [c for c in COLUMNS if c not in header]
    if missing:
        raise PinfeedError(f"pushes file {path} has no column {', '.join(missing)} (header: "
                           f"{','.join(header)}); the columns are {','.join(COLUMNS)}[,mu_c]")
    cols = [c for c in COLUMNS + OPTIONAL if c in header]
    data = {c: [] for c in cols}
    for n, row in enumerate(rows[1:], start=2):
        if len(row) != len(header):
            raise PinfeedError(f"pushes file {path}, line {n}: {len(row)} fields, the header has "
                               f"{len(header)}")
        for c in cols:
            text = row[header.index(c)].strip()
            try:
                value = float(text)
            except ValueError:
                raise PinfeedError(f"pushes file {path}, line {n}: {c} = {text!r} is not a "
                                   f"number") from None
            if not math.isfinite(value):
                raise PinfeedError(f"pushes file {path}, line {n}: {c} = {text} is not finite")
            data[c].append(value)
    if not data[COLUMNS[0]]:
        raise PinfeedError(f"pushes file {path} has a header but no pushes")
    if len(data[COLUMNS[0]]) > MAX_PUSHES:
        raise PinfeedError(f"pushes file {path} has more than {MAX_PUSHES} pushes")
    mu = np.array(data["mu_c"]) if "mu_c" in data else np.full(len(data["d"]), np.nan)
    if np.any(mu < 0):
        raise PinfeedError(f"pushes file {path}: a mu_c is negative; friction coefficients are >= 0")
    return Pushes(np.array(data["theta_i_deg"]), np.array(data["d"]), np.array(data["theta_f_deg"]), mu)


@dataclass
class SupportFit:
    """What :func:`fit_support` found."""
    support: Support
    residuals_deg: np.ndarray
    uniform_residuals_deg: np.ndarray
    pushes: int
    evaluations: int

    @staticmethod
    def _stats(r) -> dict:
        a = np.abs(r)
        return {"rms_deg": float(np.sqrt(np.mean(a * a))), "median_deg": float(np.median(a)),
                "p90_deg": float(np.percentile(a, 90)), "max_deg": float(a.max())}

    @property
    def spec(self) -> str:
        """The fitted support as ``--support`` text (``points:x,y,w ...``, mm, part frame)."""
        return _points_text(self.support)

    def to_dict(self) -> dict:
        """The JSON ``pinfeed support fit --json`` prints."""
        fit, uni = self._stats(self.residuals_deg), self._stats(self.uniform_residuals_deg)
        return {"support": self.spec, "points": self.support.points.tolist(),
                "weights": self.support.weights.tolist(), "pushes": self.pushes,
                "residuals_deg": [round(float(r), 4) for r in self.residuals_deg],
                **fit, **{f"uniform_{k}": v for k, v in uni.items()},
                "uniform_residuals_deg": [round(float(r), 4) for r in self.uniform_residuals_deg],
                "evaluations": self.evaluations}


def statics_weights(points: np.ndarray) -> np.ndarray | None:
    """Non-negative weights that put the centre of pressure of ``points`` at the
    origin, nearest equal weights; ``None`` if no such weights exist."""
    w = _nearest_weights(points)
    scale = max(1e-12, float(np.abs(points).max()))
    if np.hypot(*(w @ points)) > 1e-7 * scale:  # the centroid is outside the points' hull
        return None
    return w


def _soft_l1(r: np.ndarray) -> float:
    """The fit's loss of residuals ``r`` (deg): soft L1 with scale ``HUBER_DEG``."""
    z = np.asarray(r) / HUBER_DEG
    return float(np.sum(2.0 * (np.sqrt(1.0 + z * z) - 1.0)))


def _into_outline(verts: np.ndarray, pts: np.ndarray, holes=()) -> tuple[np.ndarray, np.ndarray]:
    """``pts`` with each point off the material (outside the polygon
    ``verts``, or inside one of ``holes``) moved to the nearest point of the
    material's edge, and how far each moved. The nearest edge point over
    every loop is the right one: a point outside the outline is nearer the
    outline than any hole inside it, a point in a hole nearer that hole's
    rim than any other loop."""
    on, dist = material_distance(SimpleNamespace(vertices=verts, holes=tuple(holes)), pts)
    out = ~on
    moved = np.where(out, dist, 0.0)
    if not out.any():
        return pts, moved
    loops = [np.asarray(verts, dtype=float)] + [np.asarray(h, dtype=float) for h in holes]
    p0 = np.vstack(loops)[None, :, :]
    e = np.vstack([np.roll(lp, -1, axis=0) - lp for lp in loops])[None, :, :]
    rel = pts[:, None, :] - p0
    t = np.clip(np.sum(rel * e, axis=2) / np.sum(e * e, axis=2), 0.0, 1.0)
    near = p0 + t[:, :, None] * e
    gap = np.hypot(*(pts[:, None, :] - near).transpose(2, 0, 1))
    nearest = near[np.arange(pts.shape[0]), np.argmin(gap, axis=1)]
    return np.where(out[:, None], nearest, pts), moved


def _nearest_weights(points: np.ndarray) -> np.ndarray:
    """Non-negative weights summing to 1 nearest to putting the centre of
    pressure of ``points`` at the origin (then nearest equal weights); the
    search's penalty measures how far they miss."""
    k = points.shape[0]
    scale = max(1e-12, float(np.abs(points).max()))
    # The two statics equations and sum w = 1 weigh 1/PULL times the pull, so
    # they hold to rounding whenever they can hold at all.
    a = np.vstack([np.vstack([points.T / scale, np.ones(k)]) / PULL, np.eye(k)])
    b = np.concatenate([[0.0, 0.0, 1.0 / PULL], np.full(k, 1.0 / k)])
    w, _ = optimize.nnls(a, b)
    return w / w.sum() if w.sum() > 0 else np.full(k, 1.0 / k)


class _Objective:
    """The loss of a point layout on the pushes; counts its evaluations (each
    one rollout per push) and keeps the best feasible layout it has seen."""

    def __init__(self, part, pushes, mu_default, pin_radius):
        self.part, self.pushes, self.pin_radius = part, pushes, float(pin_radius)
        self.mu = np.where(np.isnan(pushes.mu_c), mu_default, pushes.mu_c)
        self.verts = np.asarray(part.vertices, dtype=float)
        self.holes = tuple(getattr(part, "holes", ()))
        self.evaluations = 0
        self.best_loss, self.best_flat = math.inf, None
        self.beat = Heartbeat("", 0)  # the search stage to tick after each evaluation (none: silent)

    def residuals(self, support) -> np.ndarray:
        self.beat.tick()
        res = simulate.rollout_points(self.part, self.pushes.theta_i, self.pushes.d, self.mu,
                                      self.pin_radius, "minpower", support=support)
        r = (res["theta_f"] - self.pushes.theta_f + 180.0) % 360.0 - 180.0
        pushed = res["status"] == 0
        return np.where(pushed | (res["status"] == 1), r, OUTCOME_PENALTY_DEG)

    def support_of(self, flat) -> Support | None:
        pts = np.asarray(flat, dtype=float).reshape(-1, 2)
        on, dist = material_distance(self.part, pts)
        if not np.all(on | (dist < 1e-9)):
            return None
        w = statics_weights(pts)
        if w is None:
            return None
        return point_support(self.part, pts, w, kind="points", label="fitted")

    def _keep(self, flat, r) -> float:
        loss = _soft_l1(r)
        if loss < self.best_loss:
            self.best_loss, self.best_flat = loss, np.array(flat, dtype=float)
        return loss

    def loss(self, flat) -> float:
        """The soft-L1 loss of a layout, infinite if it is not feasible."""
        support = self.support_of(flat)
        if support is None:
            return math.inf
        self.evaluations += 1
        return self._keep(flat, self.residuals(support))

    def residual_vector(self, flat) -> np.ndarray:
        """The residuals of a layout and its penalty residuals, continuous across
        the feasible region's edge (see the module notes)."""
        pts, moved = _into_outline(self.verts, np.asarray(flat, dtype=float).reshape(-1, 2), self.holes)
        w = _nearest_weights(pts)
        off = w @ pts  # the centre of pressure's distance from the centroid
        support = point_support(self.part, pts, np.maximum(w, 0.0), kind="points", label="search")
        self.evaluations += 1
        r = self.residuals(support)
        if not moved.any() and statics_weights(pts) is not None:
            self._keep(pts.ravel(), r)
        return np.concatenate([r, PENALTY_DEG_PER_MM * moved, PENALTY_DEG_PER_MM * off])


def _random_layouts(part, k, n, seed) -> list[np.ndarray]:
    """``n`` random layouts of ``k`` points on the material that hold the centroid."""
    from pipeline.parts.support_family import sample_tripods
    if k == 3:
        return [m.points.ravel() for m in sample_tripods(part, n, 0.0, seed)]
    rng = np.random.default_rng([seed, 27])
    verts = np.asarray(part.vertices, dtype=float)
    lo, hi = verts.min(axis=0), verts.max(axis=0)
    out = []
    for _ in range(200 * n):
        pts = rng.uniform(lo, hi, (k, 2))
        if np.all(material_distance(part, pts)[0]) and statics_weights(pts) is not None:
            out.append(pts.ravel())
            if len(out) == n:
                break
    return out


def _search(objective: _Objective, layouts, refine: int, a: float, again_from_best: bool = False) -> None:
    """Score ``layouts``, then least squares from the ``refine`` best (and, with
    ``again_from_best``, once more from the best layout found), telling the
    progress report of :func:`pipeline.progress.reporting` how far it has got."""
    with Heartbeat("support fit: scoring starting layouts", len(layouts), "layout") as beat:
        def loss(flat):
            value = objective.loss(flat)
            beat.tick(beat.done + 1)
            return value
        scored = sorted(layouts, key=loss)[:max(1, int(refine))]
    with Heartbeat("support fit: least squares", len(scored) + again_from_best, "start") as beat:
        objective.beat = beat
        for k, start in enumerate(scored):
            _least_squares(objective, start, a)
            beat.tick(k + 1)
        if again_from_best:
            _least_squares(objective, objective.best_flat, a)  # a fresh trust region
    objective.beat = Heartbeat("", 0)


def _least_squares(objective: _Objective, start, a: float):
    """Trust-region least squares (soft L1) from ``start``; finite-difference
    steps of 0.1 % and variables scaled by 10 % of ``a``."""
    return optimize.least_squares(objective.residual_vector, np.asarray(start, dtype=float),
                                  method="trf", loss="soft_l1", f_scale=HUBER_DEG, diff_step=1e-3,
                                  x_scale=0.1 * a, max_nfev=MAX_NFEV)


def fit_support(part: Part, pushes: Pushes, mu_c: float | None, pin_radius: float, n_points: int = 3,
                starts: int = 48, refine: int = 8, seed: int = 0) -> SupportFit:
    """The ``n_points``-point support (statics weights) that best explains
    ``pushes`` (see the module notes); ``mu_c`` is used where a push gives none."""
    if not 3 <= int(n_points) <= 12:
        raise PinfeedError(f"--points must be 3 to 12 (a support that holds the centroid needs 3), "
                           f"got {n_points}")
    if int(starts) < 1 or int(refine) < 1:
        raise PinfeedError(f"--starts and --refine must be at least 1, got {starts} and {refine}")
    if mu_c is None and np.any(np.isnan(pushes.mu_c)):
        raise PinfeedError("give --mu-c or a mu_c column in the pushes file")
    if mu_c is not None and not (math.isfinite(mu_c) and mu_c >= 0):
        raise PinfeedError(f"--mu-c must be a number >= 0, got {mu_c}")
    if len(pushes) < 2 * n_points:
        raise PinfeedError(f"{len(pushes)} pushes cannot fix {n_points} support points "
                           f"({2 * n_points} unknowns); measure at least {2 * n_points} pushes")
    objective = _Objective(part, pushes, mu_c if mu_c is not None else 0.0, pin_radius)
    layouts = _random_layouts(part, int(n_points), int(starts), seed)
    if not layouts:
        raise PinfeedError(f"no {n_points} points inside the outline hold the centroid; try --points 3")
    _search(objective, layouts, refine, part.a, again_from_best=True)
    support = _as_printed(part, objective.support_of(objective.best_flat))
    return SupportFit(support, objective.residuals(support), objective.residuals(None), len(pushes),
                      objective.evaluations)


def _points_text(support: Support) -> str:
    """``--support`` text of a point support (mm, part frame)."""
    return "points:" + " ".join(f"{format_mm(x)},{format_mm(y)},{w:.4f}"
                                for (x, y), w in zip(support.points, support.weights))


def _as_printed(part, support: Support) -> Support:
    """``support`` with its points where their printed text puts them (within
    1.5 um, on the material) and their weights balancing the part
    there: what the fit reports is what the printed text reads back as."""
    pts = on_print_grid(part, support.points)
    w = statics_weights(pts)
    return point_support(part, pts, support.weights if w is None else w, kind=support.kind,
                         label=support.label)


# --------------------------------------------------------------------------- a family of fits

MAX_FAMILY = 8  # members a fitted family lists at most
FAMILY_CONFIDENCE = 0.95  # chi-square quantile a consistent support's residuals stay within


class _RecordingObjective(_Objective):
    """An :class:`_Objective` that also keeps every feasible layout it scored,
    with its sum of squared residuals (deg^2)."""

    def __init__(self, *args):
        super().__init__(*args)
        self.seen: list[tuple[np.ndarray, float]] = []

    def _keep(self, flat, r) -> float:
        self.seen.append((np.array(flat, dtype=float), float(np.sum(np.square(r)))))
        return super()._keep(flat, r)


@dataclass
class FamilyFit:
    """What :func:`fit_support_family` found: the supports consistent with the pushes."""
    members: list  # Support, best fit first
    chi2: list  # sum of (residual / noise)^2 of each member
    threshold: float  # the chi-square quantile they stay within
    noise_deg: float
    noise_estimated: bool
    pushes: int
    evaluations: int
    consistent: int  # layouts within the threshold among all scored

    @property
    def spec(self) -> str:
        """The family as ``--support-family`` text: ``points:x,y,w x,y,w ...; points:...``."""
        return "; ".join(_points_text(m) for m in self.members)

    def to_dict(self) -> dict:
        """The JSON ``pinfeed support fit --family --json`` prints."""
        return {"support_family": self.spec, "members": len(self.members),
                "chi2": [round(c, 3) for c in self.chi2], "chi2_threshold": round(self.threshold, 3),
                "confidence": FAMILY_CONFIDENCE, "noise_deg": round(self.noise_deg, 4),
                "noise_estimated": self.noise_estimated, "pushes": self.pushes,
                "consistent_layouts": self.consistent, "evaluations": self.evaluations}

    def line(self) -> str:
        """One line for the terminal."""
        how = "estimated from the best fit" if self.noise_estimated else "given"
        return (f"{len(self.members)} supports explain the {self.pushes} pushes within their noise "
                f"({self.noise_deg:.3g} deg, {how}; chi-square <= {self.threshold:.1f} at "
                f"{FAMILY_CONFIDENCE:.0%}): --support-family \"{self.spec}\"")


def _spread_pick(flats: np.ndarray, n: int) -> list[int]:
    """Up to ``n`` indices of ``flats`` far apart (greedy farthest points from the first)."""
    chosen = [0]
    dist = np.linalg.norm(flats - flats[0], axis=1)
    while len(chosen) < min(n, len(flats)):
        i = int(np.argmax(dist))
        if dist[i] <= 1e-6:
            break
        chosen.append(i)
        dist = np.minimum(dist, np.linalg.norm(flats - flats[i], axis=1))
    return chosen


def fit_support_family(part: Part, pushes: Pushes, mu_c: float | None, pin_radius: float,
                       noise_deg: float | None = None, n_points: int = 3, starts: int = 48,
                       refine: int = 8, seed: int = 0, max_members: int = MAX_FAMILY) -> FamilyFit:
    """The ``n_points``-point supports consistent with ``pushes`` within their noise.

    The fit of :func:`fit_support` is run, keeping every feasible layout it
    scores; a layout is *consistent* when ``sum (r / noise)^2`` of its
    residuals stays within the ``FAMILY_CONFIDENCE`` quantile of the
    chi-square distribution with one degree of freedom per push (what the
    true support's residuals do with that probability when the measurement
    noise is normal with sigma ``noise_deg``). ``noise_deg`` ``None``
    estimates it from the best fit (``RMS * sqrt(n / (n - 2K))``). Up to
    ``max_members`` consistent layouts far apart (the best fit first) form the
    family.

    Raises
    ------
    PinfeedError
        One line: fewer pushes than the family's parameters (``2 n_points``,
        and one more when the noise is estimated), a noise level that is not
        a positive number.
    """
    from scipy.stats import chi2 as chi2_dist

    k = int(n_points)
    need = 2 * k + (1 if noise_deg is None else 0)
    if len(pushes) < need:
        raise PinfeedError(f"a support family from {len(pushes)} pushes: {k}-point supports have {2 * k} "
                           f"parameters{' and the noise is estimated' if noise_deg is None else ''}; "
                           f"measure at least {need} pushes")
    if noise_deg is not None and not (math.isfinite(float(noise_deg)) and float(noise_deg) > 0):
        raise PinfeedError(f"--noise-deg must be a number of degrees > 0, got {noise_deg}")
    best = fit_support(part, pushes, mu_c, pin_radius, k, starts, refine, seed)
    recorder = _RecordingObjective(part, pushes, mu_c if mu_c is not None else 0.0, pin_radius)
    layouts = _random_layouts(part, k, int(starts), seed + 1) + [best.support.points.ravel()]
    _search(recorder, layouts, refine, part.a)
    n = len(pushes)
    estimated = noise_deg is None
    sigma = (float(np.sqrt(np.mean(np.square(best.residuals_deg)) * n / (n - 2 * k)))
             if estimated else float(noise_deg))
    sigma = max(sigma, 1e-6)
    threshold = float(chi2_dist.ppf(FAMILY_CONFIDENCE, n))
    seen = [(best.support.points.ravel(), float(np.sum(np.square(best.residuals_deg))))] + recorder.seen
    ok = [(f, s / sigma ** 2) for f, s in seen if s / sigma ** 2 <= threshold]
    if not ok:
        raise PinfeedError(f"no {k}-point support explains the {n} pushes within a noise of {sigma:.3g} deg "
                           f"(the best fit's RMS residual is "
                           f"{np.sqrt(np.mean(np.square(best.residuals_deg))):.3g} deg); give a larger "
                           f"--noise-deg or check the pushes")
    flats = np.array([f for f, _ in ok])
    pick = _spread_pick(flats, int(max_members))
    members, chi = [], []
    for i in pick:
        pts = flats[i].reshape(-1, 2)
        members.append(_as_printed(part, point_support(part, pts, statics_weights(pts), kind="points",
                                                       label=f"fitted {len(members) + 1}")))
        chi.append(ok[i][1])
    return FamilyFit(members, chi, threshold, sigma, estimated, n, best.evaluations + recorder.evaluations,
                     len(ok))
