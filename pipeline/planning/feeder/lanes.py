"""Parts on the belt's clock: the passages of a plan placed in the world frame.

Shared by the feeder layout (:mod:`pipeline.planning.feeder.layout`) and the
animations' passages (:mod:`pipeline.planning.feeder.passages`), so that the
drawings (:mod:`pipeline.present.layout`, :mod:`pipeline.present.animate`)
show the same course:

- a :class:`Lane` is one part's centroid and orientation against the belt
  travel B (mm), built from the rollout kernel's own trajectories
  (:func:`build_lane`);
- :func:`pin_reach` and :func:`contact_offset` say exactly where a pin first
  touches an outline;
- :func:`run_trials` replays perturbed parts past the pins (the verification's
  perturbation box) and :func:`trial_lanes` puts each on the common clock.

World frame of the spec: x downstream, the fence at y = 0.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from pipeline.maps import simulate
from pipeline.parts.contact import contact_parameter
from pipeline.parts.part import Part
from pipeline.planning.claims.trials import corner_inputs, perturbed_batch
from pipeline.planning.core.settings import Perturbation, nominal_friction
from pipeline.progress import Heartbeat


@dataclass
class Lane:
    """One initial state's motion: centroid and orientation against belt travel B."""

    label: str
    B: np.ndarray  # belt travel (mm), non-decreasing
    x: np.ndarray  # centroid, world (mm)
    y: np.ndarray
    theta: np.ndarray  # degrees, unwrapped
    outcome: str = "ok"  # ok, or "jammed at P3 (reason)"
    contacts: list = field(default_factory=list)  # (pin index, B at first contact)
    lead: list = field(default_factory=list)  # per pin: x_world - B before that pin's contact

    def poses(self, b):
        """Centroid x, y and theta (deg) at the belt travels ``b`` (an array):
        before the first sample and after the last the part rides the belt
        (a jammed part stays at its pin)."""
        b = np.asarray(b, float)
        x = np.interp(b, self.B, self.x)
        before, after = b < self.B[0], b > self.B[-1]
        x = np.where(before, self.x[0] + (b - self.B[0]), x)
        if self.outcome == "ok":
            x = np.where(after, self.x[-1] + (b - self.B[-1]), x)
        return x, np.interp(b, self.B, self.y), np.interp(b, self.B, self.theta)

    def pose(self, b: float):
        """Centroid (x, y) and theta (deg) at belt travel ``b``."""
        if b >= self.B[-1] and self.outcome != "ok":
            return self.x[-1], self.y[-1], self.theta[-1]  # jammed: held at the pin
        if b >= self.B[-1]:  # past the last pin: rides the belt
            return self.x[-1] + (b - self.B[-1]), self.y[-1], self.theta[-1]
        return (float(np.interp(b, self.B, self.x)), float(np.interp(b, self.B, self.y)),
                float(np.interp(b, self.B, self.theta)))


def rotated(vertices, theta_deg):
    """``vertices`` (n, 2) turned by ``theta_deg`` degrees counter-clockwise about the origin."""
    c, s = math.cos(math.radians(theta_deg)), math.sin(math.radians(theta_deg))
    return vertices @ np.array([[c, s], [-s, c]])


def gap(point, poly) -> float:
    """Distance from ``point`` to polygon ``poly`` (0 inside)."""
    a, b = poly, np.roll(poly, -1, axis=0)
    ab = b - a
    t = np.clip(np.einsum("ij,ij->i", point - a, ab) / np.einsum("ij,ij->i", ab, ab), 0.0, 1.0)
    d = np.hypot(*(a + t[:, None] * ab - point).T).min()
    x, y = point
    cross = ((a[:, 1] > y) != (b[:, 1] > y)) & (
        x < (b[:, 0] - a[:, 0]) * (y - a[:, 1]) / np.where(b[:, 1] == a[:, 1], 1e-300, b[:, 1] - a[:, 1]) + a[:, 0])
    return 0.0 if np.count_nonzero(cross) % 2 else float(d)


def pin_reach(polygons, height, r_pin) -> np.ndarray:
    """How far downstream a pin of radius ``r_pin`` on the line ``y = height`` can
    stand and still touch each polygon: the largest pin-centre x with the disc
    meeting the polygon (exact: the rightmost point of the polygon grown by the
    disc on that line), ``-inf`` where the line passes by.

    Parameters
    ----------
    polygons : array ``(..., n, 2)`` of outlines (world frame, mm).
    height : the pin's y, mm.
    r_pin : the pin radius, mm.

    Returns
    -------
    array of shape ``polygons.shape[:-2]``.
    """
    a = np.asarray(polygons, float)
    b = np.roll(a, -1, axis=-2)
    # The polygon grown by the disc is the union of the polygon and a capsule
    # per edge; on a horizontal line its rightmost point lies on an end circle
    # or on a side of a capsule.
    dy = height - a[..., 1]
    best = np.where(np.abs(dy) <= r_pin, a[..., 0] + np.sqrt(np.clip(r_pin ** 2 - dy ** 2, 0.0, None)),
                    -np.inf).max(axis=-1)
    edge = b - a
    length = np.hypot(edge[..., 0], edge[..., 1])
    normal = np.stack([-edge[..., 1], edge[..., 0]], axis=-1) / np.where(length > 0, length, 1.0)[..., None]
    for side in (1.0, -1.0):
        p, q = a + side * r_pin * normal, b + side * r_pin * normal
        flat = p[..., 1] == q[..., 1]
        t = (height - p[..., 1]) / np.where(flat, 1.0, q[..., 1] - p[..., 1])
        x = p[..., 0] + t * (q[..., 0] - p[..., 0])
        crossing = ~flat & (t >= 0.0) & (t <= 1.0)
        best = np.maximum(best, np.where(crossing, x, -np.inf).max(axis=-1))
    return best


def contact_offset(vertices, theta_deg, dh, v_pin, r_pin, a) -> float:
    """The centroid's station relative to the pin, u = x_free - X_k, at first touch:
    the pin sits at (-u, dh + v_pin u) from the centroid (``dh`` = pin height at the
    station minus y_c). A fixed pin: exact (:func:`pin_reach`); a moving one:
    scanned upstream to downstream, then bisected."""
    poly = rotated(vertices, theta_deg)
    if v_pin == 0.0:
        reach = float(pin_reach(poly, dh, r_pin))
        return -reach if math.isfinite(reach) else math.nan
    reach = (2.0 * a + r_pin + abs(dh)) * (1.0 + abs(v_pin))
    us = np.linspace(-reach, reach, 4001)
    touching = [gap(np.array([-u, dh + v_pin * u]), poly) <= r_pin for u in us]
    if not any(touching):
        return math.nan
    k = touching.index(True)
    lo, hi = (us[k - 1], us[k]) if k else (us[0], us[0])
    for _ in range(40):
        mid = 0.5 * (lo + hi)
        if gap(np.array([-mid, dh + v_pin * mid]), poly) <= r_pin:
            hi = mid
        else:
            lo = mid
    return hi


def build_lane(part, label, steps, stations, heights, speeds, pin_radius) -> Lane:
    """Place one state's kernel trajectories on the world clock."""
    B, X, Y, T = [0.0], [0.0], [steps[0][1]], [steps[0][0]]
    shift = 0.0  # centroid's lead over the belt from earlier contacts (x_world = B + shift)
    lane = Lane(label, *(np.zeros(0),) * 4)
    for k, (theta, y_c, r) in enumerate(steps):
        lane.lead.append(shift)
        status = str(r.status.item())
        if status == "miss":
            continue
        u = contact_offset(part.vertices, theta, heights[k] - y_c, speeds[k], pin_radius, part.a)
        if not math.isfinite(u):
            continue
        b0 = stations[k] + u - shift  # belt travel when x_free reaches X_k + u
        s = np.asarray(r.traj_s, float)
        # The kernel records the absolute orientation, starting from theta.
        t_unwrapped = T[-1] + (np.asarray(r.traj_theta, float) - theta)
        B += list(b0 + s)
        X += list(stations[k] + u + s + np.asarray(r.traj_x, float))
        Y += list(y_c + np.asarray(r.traj_y, float))
        T += list(t_unwrapped)
        lane.contacts.append((k, b0))
        shift = X[-1] - B[-1]
        if status == "jammed":
            lane.outcome = f"jammed at pin {k + 1} ({r.jam_reason.item()})"
            break
    lane.lead += [shift] * (len(stations) - len(lane.lead))
    lane.B, lane.x, lane.y, lane.theta = (np.array(v, float) for v in (B, X, Y, T))
    # Stations are spaced beyond the longest contact, so a contact starts after the ride before it.
    lane.B = np.maximum.accumulate(lane.B)
    return lane


def pin_height(lane: Lane, k: int, b: float, h: float, v: float, station: float) -> float:
    """Pin k's height at belt travel ``b`` as seen in ``lane``: it passes ``h`` when the
    centroid's belt-carried station (with the lead from earlier contacts, not pin
    k's own) reaches the pin's station."""
    return h + v * (b + lane.lead[k] - station)


@dataclass
class Trial:
    """One replayed part: its perturbed start, friction and pins, and every passage."""

    state: str
    theta: float  # initial orientation, degrees
    y_c: float  # initial centroid height, mm
    mu_c: float
    heights: np.ndarray  # the pins' perturbed heights, mm
    steps: list = field(default_factory=list)  # (theta_deg, y_c, rollout Dataset) per pin
    jam: str = ""  # why the part stopped, or ""


def run_trials(part: Part, heights, states: dict, mu_c, pin_radius: float, model: str,
               belt_speed: float | None = None, mu_s: float = 0.5, perturb: Perturbation | None = None,
               trials: int = 20, corners: bool = False, seed: int = 1,
               nominal: bool = False) -> list[Trial]:
    """Replay ``trials`` perturbed parts per initial state past the pins.

    Parameters
    ----------
    heights : pin heights in passage order, mm.
    states : label -> ``(theta_deg, y_c_mm)``.
    mu_c : a value, or a range ``(lo, hi)`` drawn uniformly.
    model : the quasi-static model (``belt_speed`` None) or ignored: with a
        ``belt_speed`` (mm/s) the dynamic model runs with belt friction ``mu_s``.
    perturb : the verification's perturbation sizes (``None``: the schema's).
    corners : also replay every corner of the perturbation box.
    nominal : one unperturbed trial per state instead (nominal friction).

    Returns
    -------
    list of :class:`Trial`, state by state.

    How far the trials have got goes to the progress report of
    :func:`pipeline.progress.reporting`, if any.
    """
    sizes = perturb or Perturbation()
    rng = np.random.default_rng(seed)
    heights = np.asarray(heights, float)
    n_pins = heights.size
    belt = {"model": "dynamic", "belt_speed": float(belt_speed), "mu_s": float(mu_s)} \
        if belt_speed is not None else {"model": model}
    out = []
    beat = Heartbeat("nominal passages" if nominal else "layout trials", len(states), "initial state").start()
    for i, (label, (theta0, yc0)) in enumerate(states.items()):
        if nominal:
            th, yc = np.array([theta0], float), np.array([yc0], float)
            mu, offs = np.array([nominal_friction(mu_c)]), np.zeros((1, n_pins))
        else:
            th, yc, mu, offs = perturbed_batch(theta0, yc0, mu_c, n_pins, sizes, rng, int(trials))
            if corners:
                extra = corner_inputs(theta0, yc0, mu_c, n_pins, sizes)
                th, yc, mu = (np.concatenate([x, c]) for x, c in zip((th, yc, mu), extra[:3]))
                offs = np.concatenate([offs, extra[3]])
        for j in range(th.size):
            trial = Trial(label, float(th[j]) % 360.0, float(yc[j]), float(mu[j]), heights + offs[j])
            out.append(_roll_trial(part, trial, pin_radius, belt))
            beat.tick(i + (j + 1) / th.size)
    beat.finish()
    return out


def _roll_trial(part: Part, trial: Trial, pin_radius: float, belt: dict) -> Trial:
    """``trial`` rolled past its pins in turn (with trajectories), up to a jam."""
    theta, y = trial.theta, trial.y_c
    for k, h in enumerate(trial.heights):
        ds = simulate.rollout(part, theta, contact_parameter(h, y, part.a), trial.mu_c, pin_radius,
                              trajectory=True, **belt)
        trial.steps.append((theta, y, ds))
        status = str(ds.status.item())
        if status in ("jammed", "truncated"):
            trial.jam = f"{status} at pin {k + 1} ({ds.jam_reason.item()})"
            break
        theta, y = float(ds.theta_f), y + float(ds.dy)
    return trial


def outlines(vertices, x, y, theta_deg) -> np.ndarray:
    """The part's outline at each pose: array ``(n_poses, n_vertices, 2)``, mm."""
    t = np.radians(np.asarray(theta_deg, float))
    c, s = np.cos(t)[:, None], np.sin(t)[:, None]
    vx, vy = vertices[:, 0][None, :], vertices[:, 1][None, :]
    return np.stack([np.asarray(x, float)[:, None] + c * vx - s * vy,
                     np.asarray(y, float)[:, None] + s * vx + c * vy], axis=-1)


def passage_poses(part: Part, theta: float, y_c: float, ds, height: float, pin_radius: float):
    """The part's poses over one passage, centroid x relative to the pin's station:
    the pose at first touch, then every recorded pose until the part rests
    (``None`` for a miss). Returns ``(x, y, theta_deg)`` arrays."""
    if str(ds.status.item()) == "miss" or ds.traj_s.size == 0:
        return None
    reach = float(pin_reach(rotated(part.vertices, theta), height - y_c, pin_radius))
    u = -reach  # the centroid's x at first touch, the pin at x = 0
    s = np.asarray(ds.traj_s, float)
    return (np.concatenate([[u], u + s + np.asarray(ds.traj_x, float)]),
            np.concatenate([[y_c], y_c + np.asarray(ds.traj_y, float)]),
            np.concatenate([[theta], np.asarray(ds.traj_theta, float)]))


def trial_lanes(part: Part, trials: list[Trial], stations, pin_radius: float, entry: float):
    """Each trial on the common clock (belt travel B, mm): at B = 0 its centroid
    is at x = -``entry``; returns a :class:`Lane` per trial in
    world coordinates (first pin at x = 0)."""
    shifted = [x + entry for x in stations]
    lanes = []
    for t in trials:
        lane = build_lane(part, t.state, t.steps, shifted, list(t.heights), [0.0] * len(shifted),
                     pin_radius)
        lane.x = lane.x - entry
        lanes.append(lane)
    return lanes
