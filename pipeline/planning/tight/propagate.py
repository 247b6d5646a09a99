"""Tight, sound propagation of an uncertain part state through one pin.

A state is the set of poses a part can really have when it reaches a pin:
an arc of orientations, an interval of centroid heights ``y_c`` above the
fence and an interval of pin friction ``mu_c`` (the feeder's friction is not
known exactly). A pin at height ``y_pin``, itself placed within
``+- pin_halfwidth``, meets the state over the box

    theta_i in arc,   d in [(y_pin - h - y_hi) / a, (y_pin + h - y_lo) / a],   mu in [mu_lo, mu_hi]

and maps it to the image of that box: the ``theta_f`` and ``y_c + dy`` that
rollouts give over it. The image is computed by adaptive refinement of the
box on a fixed dyadic lattice (so that rollouts are shared between states and
stored for reuse, see :class:`OutcomeLattice`):

- the box is covered by lattice cells (2 deg x 0.04 x 0.08 at the coarsest);
- a cell is accepted when it is smooth: no jammed corner, no two
  neighbouring corners more than ``jump_deg`` apart, and the outcome at its
  centre within ``linear_deg`` (``linear_dy``) of the corners' mean (the
  multilinear interpolant there). It contributes the hull of its corners and
  centre, padded by twice the centre's deviation plus ``pad_deg`` (``pad_dy``);
- any other cell is halved along every axis above the finest size
  (1/4 deg x 0.01 x 0.02), keeping only the halves that meet the box;
- a finest cell that is still not smooth but has no jump between neighbouring
  corners is taken as steep but continuous (hull plus pad); otherwise it
  straddles a jump (a band boundary, a miss boundary): the corners on each
  side of it give their hull, padded by ``pad_jump_deg``, and the state
  branches into children.
- a jammed corner inside the box forbids the pin (a jam stops the feeder).

The outcomes are then merged on the circle into child arcs; each child's
``y_c`` interval is ``y_c + dy`` over the cells that reach it, with ``y_c``
restricted to what is consistent with each cell's ``d`` range.

Soundness rests on one assumption, which the refinement makes mild: inside a
smooth cell, outcomes do not stray beyond the hull of its corners and centre
by more than the pad. Jumps narrower than the finest
cell can be missed; verification by full rollouts (``verify.py``) checks every
recommended plan independently of this arithmetic.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from kernels.rollout import JAMMED, MISS, TRUNCATED

from pipeline.parts.contact import contact_parameter
from pipeline.parts.part import Part
from pipeline.planning.core.arcs import arc_within, merge_arcs
from pipeline.planning.core.resting import resting_states
from pipeline.planning.core.settings import TRUNCATE_SIGMA, Perturbation, VerifySettings
from pipeline.progress import SILENT

# Lattice units: theta in 1/64 deg, d in 1/3200, mu in 1/1600.
UNITS = (1.0 / 64.0, 1.0 / 3200.0, 1.0 / 1600.0)
BASE = (128, 128, 128)  # coarsest cell: 2 deg, 0.04, 0.08
FINEST = (16, 32, 32)  # finest cell: 1/4 deg, 0.01, 0.02
MAX_POINTS = 2000  # lattice points one transition may need; beyond: unresolved

SNAP_DEG = 0.5  # carried arcs are snapped outward to this grid (exact merging of states)
SNAP_Y = 0.1  # carried y_c intervals likewise (mm)


_BOX = Perturbation()  # the schema's perturbation sizes


@dataclass(frozen=True)
class Uncertainty:
    """Sizes of the uncertainty the planner must cover (the verify stage's)."""
    theta_halfwidth: float = TRUNCATE_SIGMA * _BOX.theta_sigma  # deg: of the initial orientation
    y_halfwidth: float = _BOX.y_halfwidth  # mm: initial centroid height
    mu_halfwidth: float = TRUNCATE_SIGMA * _BOX.mu_sigma  # of the friction (a single friction value only)
    pin_halfwidth: float = _BOX.pin_halfwidth  # mm: every pin's position

    @classmethod
    def from_verify(cls, verify: VerifySettings) -> "Uncertainty":
        """The box at the verification's sizes: ``TRUNCATE_SIGMA`` sigma for
        normal errors (where the trials' normal draws stop)."""
        p = verify.perturbation
        return cls(TRUNCATE_SIGMA * p.theta_sigma, p.y_halfwidth, TRUNCATE_SIGMA * p.mu_sigma, p.pin_halfwidth)


@dataclass(frozen=True)
class Tolerances:
    """When the refinement accepts a cell, and how much it pads."""
    linear_deg: float = 0.5  # the centre may stray this far from the corners' mean
    linear_dy: float = 0.25  # mm, likewise for dy
    jump_deg: float = 5.0  # neighbouring corners further apart than this straddle a jump
    pad_deg: float = 0.1
    pad_dy: float = 0.05
    pad_jump_deg: float = 1.0  # beside a jump, where outcomes change fast
    pad_jump_dy: float = 0.25


@dataclass(frozen=True, order=True)
class StateSet:
    """An uncertain state: orientation arc ``(start, width)`` in degrees,
    centroid heights ``[y_lo, y_hi]`` in mm, friction ``[mu_lo, mu_hi]``."""
    start: float
    width: float
    y_lo: float
    y_hi: float
    mu_lo: float
    mu_hi: float

    @property
    def arc(self) -> tuple[float, float]:
        """``(start, width)`` of the orientation arc, degrees."""
        return (self.start, self.width)

    def to_dict(self) -> dict:
        """The state set as a JSON-ready dict (arc, y_c and mu_c intervals)."""
        return {"arc": {"start": self.start, "width": self.width},
                "y_c": [self.y_lo, self.y_hi], "mu_c": [self.mu_lo, self.mu_hi]}

    @classmethod
    def from_dict(cls, d: dict) -> "StateSet":
        """The state set stored by :meth:`to_dict`."""
        return cls(float(d["arc"]["start"]), float(d["arc"]["width"]), float(d["y_c"][0]),
                   float(d["y_c"][1]), float(d["mu_c"][0]), float(d["mu_c"][1]))


def snapped_state(start, width, y_lo, y_hi, mu_lo, mu_hi) -> StateSet:
    """A state snapped outward to the carry grid (so equal states compare equal)."""
    if width >= 360.0 - SNAP_DEG:
        s, w = 0.0, 360.0
    else:
        s = math.floor(start / SNAP_DEG) * SNAP_DEG
        w = min(360.0, math.ceil((start + width) / SNAP_DEG) * SNAP_DEG - s)
        s %= 360.0
    return StateSet(round(s, 6), round(w, 6), round(math.floor(y_lo / SNAP_Y) * SNAP_Y, 6),
                    round(math.ceil(y_hi / SNAP_Y) * SNAP_Y, 6), mu_lo, mu_hi)


def friction_interval(mu_c, unc: Uncertainty) -> tuple[float, float]:
    """``mu_c`` as an interval: a range ``(lo, hi)`` is taken as given (it is
    the uncertainty); a single value is widened by the verify stage's 2 sigma."""
    if isinstance(mu_c, (tuple, list)):
        lo, hi = float(mu_c[0]), float(mu_c[1])
        return lo, hi
    mu = float(mu_c)
    return max(0.0, mu - unc.mu_halfwidth), mu + unc.mu_halfwidth


def initial_state_sets(part: Part, mu_c, unc: Uncertainty) -> dict[str, StateSet]:
    """The resting states against the fence, each widened to the uncertainty box."""
    mu_lo, mu_hi = friction_interval(mu_c, unc)
    return {label: snapped_state(theta - unc.theta_halfwidth, 2 * unc.theta_halfwidth,
                                 y_c - unc.y_halfwidth, y_c + unc.y_halfwidth, mu_lo, mu_hi)
            for label, (theta, y_c) in resting_states(part).items()}


class OutcomeLattice:
    """Rollout outcomes at dyadic lattice points ``(theta_i, d, mu_c)`` of one
    part, model, pin speed and belt (speed and friction), computed on demand
    in batches and kept.

    ``belt_speed`` (mm/s) and ``mu_s`` select the dynamic model
    (``kernels.dynamic``) at that belt speed; ``belt_speed=None`` is the
    quasi-static ``model``. ``known`` maps integer lattice keys to
    ``(status, theta_f_deg, dy)``. ``stretch`` (a
    :class:`pipeline.progress.Stretch`, default silent) is ticked while a
    batch is computed, so the stage that asked for it shows it is moving.
    """

    def __init__(self, part: Part, model: str, pin_radius: float, v_pin: float = 0.0,
                 ds_max: float | None = None, tol: float | None = None,
                 belt_speed: float | None = None, mu_s: float = 0.5):
        self.part, self.pin_radius, self.v_pin = part, pin_radius, float(v_pin)
        self.belt_speed = None if belt_speed is None else float(belt_speed)
        self.mu_s = float(mu_s)
        self.model = "dynamic" if self.belt_speed is not None else model
        self.ds_max, self.tol = ds_max, tol
        self.known: dict[tuple[int, int, int], tuple[int, float, float]] = {}
        self.n_computed = 0
        self.n_stored = 0
        self.stretch = SILENT

    def ensure(self, keys) -> None:
        """Compute every key not yet known, in one parallel batch."""
        from pipeline.maps import simulate
        todo = sorted({k for k in keys if k not in self.known})
        if not todo:
            return
        arr = np.asarray(todo, dtype=np.float64)
        kw = {}
        if self.belt_speed is not None:
            kw.update(belt_speed=self.belt_speed, mu_s=self.mu_s)
        if self.ds_max is not None:
            kw["ds_max"] = self.ds_max
        if self.tol is not None:
            kw["tol"] = self.tol
        res = simulate.rollout_points(self.part, arr[:, 0] * UNITS[0], arr[:, 1] * UNITS[1],
                                      arr[:, 2] * UNITS[2], self.pin_radius, self.model,
                                      v_pin=self.v_pin, **kw, stretch=self.stretch)
        for key, st, tf, dy in zip(todo, res["status"], res["theta_f"], res["dy"]):
            self.known[key] = (int(st), float(tf), float(dy))
        self.n_computed += len(todo)

    def add(self, keys, status, theta_f, dy) -> None:
        """Add stored outcomes (from a refinement shard)."""
        for key, st, tf, y in zip(keys, status, theta_f, dy):
            self.known[tuple(int(x) for x in key)] = (int(st), float(tf), float(y))


UNRESOLVED = "unresolved"  # propagate's answer when a box needs more than MAX_POINTS


@dataclass
class Transition:
    """The children of a state at one pin, and how the pin met it."""
    children: list[StateSet]
    d_lo: float
    d_hi: float
    jump: bool  # the box straddles a jump (the state branched or a piece is a corner value)
    touched: bool = True  # some outcome in the box is a contact (not a miss)


def _cells_covering(lo, hi):
    """Base lattice cells ``(lo_int, hi_int)`` per axis covering ``[lo, hi]`` (lattice units)."""
    axes = []
    for axis in range(3):
        step = BASE[axis]
        a0 = math.floor(lo[axis] / step) * step
        a1 = max(a0 + step, math.ceil(hi[axis] / step) * step)
        axes.append([(x, x + step) for x in range(a0, a1, step)])
    return [(tx, dx, mx) for tx in axes[0] for dx in axes[1] for mx in axes[2]]


def _corners(cell):
    (t0, t1), (d0, d1), (m0, m1) = cell
    return [(t, d, m) for t in (t0, t1) for d in (d0, d1) for m in (m0, m1)]


def _centre(cell):
    return tuple((c0 + c1) // 2 for c0, c1 in cell)


# Pairs of corner indices (in ``_corners`` order) joined by a cell edge.
_EDGES = [(i, j) for i in range(8) for j in range(i + 1, 8) if bin(i ^ j).count("1") == 1]
_EDGE_I = np.array([i for i, _ in _EDGES])
_EDGE_J = np.array([j for _, j in _EDGES])


def _split(cell, lo, hi):
    """Halves of ``cell`` along every axis above the finest size that meet the box."""
    per_axis = []
    for axis, (c0, c1) in enumerate(cell):
        if c1 - c0 > FINEST[axis]:
            mid = (c0 + c1) // 2
            per_axis.append([(c0, mid), (mid, c1)])
        else:
            per_axis.append([(c0, c1)])
    out = []
    for t in per_axis[0]:
        for d in per_axis[1]:
            for m in per_axis[2]:
                sub = (t, d, m)
                if all(sub[k][0] <= hi[k] and sub[k][1] >= lo[k] for k in range(3)):
                    out.append(sub)
    return out


def _is_finest(cell) -> bool:
    return all(c1 - c0 <= FINEST[k] for k, (c0, c1) in enumerate(cell))


def propagate(state: StateSet, y_pin: float, part: Part, lattice: OutcomeLattice,
              pin_halfwidth: float, tol: Tolerances = Tolerances()) -> Transition | None:
    """Children of ``state`` at a pin at height ``y_pin`` (mm); ``None`` if a
    jam is reachable; :data:`UNRESOLVED` if the box holds so many jumps that
    resolving them would take more than ``MAX_POINTS`` lattice points (the
    search then forbids the pin). The d range is not checked here."""
    a = part.a
    d_lo = contact_parameter(y_pin - pin_halfwidth, state.y_hi, a)
    d_hi = contact_parameter(y_pin + pin_halfwidth, state.y_lo, a)
    lo = (state.start / UNITS[0], d_lo / UNITS[1], state.mu_lo / UNITS[2])
    hi = ((state.start + state.width) / UNITS[0], d_hi / UNITS[1], state.mu_hi / UNITS[2])
    cells = _cells_covering(lo, hi)
    pieces = []  # (start, width, dy_lo, dy_hi, g_lo, g_hi, d_lo, d_hi)
    jump = touched = False
    used = 0
    while cells:
        used += len(cells) * 9
        if used > MAX_POINTS:
            return UNRESOLVED
        cell_keys = [_corners(c) + [_centre(c)] for c in cells]
        lattice.ensure([k for keys in cell_keys for k in keys])
        refine = []
        for cell, keys in zip(cells, cell_keys):
            vals = np.array([lattice.known[k] for k in keys])  # (9, 3): status, theta_f, dy
            touched = touched or bool((vals[:, 0] != MISS).any())
            outcome = _cell_outcome(cell, keys, vals, tol, a, lo, hi)
            if outcome == "jam":
                if _is_finest(cell):
                    return None
                refine.extend(_split(cell, lo, hi))
            elif outcome == "split":  # only a jump reaches here at the finest size
                if _is_finest(cell):
                    jump = True
                    pieces.extend(_corner_pieces(cell, lattice, tol, a))
                else:
                    refine.extend(_split(cell, lo, hi))
            else:
                pieces.append(outcome + (cell[1][0] * UNITS[1], cell[1][1] * UNITS[1]))
        cells = refine
    children = _children(pieces, state, y_pin, pin_halfwidth, a, d_lo, d_hi)
    return Transition(children, d_lo, d_hi, jump or len(children) > 1, touched)


def _cell_outcome(cell, keys, vals, tol, a, lo, hi):
    """``"jam"``, ``"split"`` or the padded piece ``(start, width, dy_lo, dy_hi,
    g_lo, g_hi)`` with ``g = dy - d a`` (mm): the new centroid height is
    ``y_pin + offset + g``, which varies far less over a cell than ``dy``.
    ``keys``: the cell's 8 corners (``_corners`` order) and centre; ``vals``
    their outcomes as rows ``(status, theta_f, dy)``."""
    status = vals[:, 0]
    if ((status == JAMMED) | (status == TRUNCATED)).any():
        return "jam"
    ref = vals[0, 1]
    rel = ((vals[:, 1] - ref + 180.0) % 360.0) - 180.0
    if np.abs(rel[_EDGE_I] - rel[_EDGE_J]).max() > tol.jump_deg:
        return "split"
    dys = vals[:, 2]
    gs = dys - np.array([k[1] for k in keys]) * (UNITS[1] * a)
    dev = abs(rel[8] - rel[:8].mean())
    dev_y = abs(dys[8] - dys[:8].mean())
    dev_g = abs(gs[8] - gs[:8].mean())
    if (dev > tol.linear_deg or dev_y > tol.linear_dy) and not _is_finest(cell):
        return "split"
    pad = 2.0 * dev + tol.pad_deg
    pad_y = 2.0 * dev_y + tol.pad_dy
    pad_g = 2.0 * dev_g + tol.pad_dy
    # Only the part of the cell inside the box counts: interpolate the corners
    # multilinearly to the box's clipped corners (the pad covers the curvature).
    clipped = _clip_corners(np.stack([rel[:8], dys[:8], gs[:8]]), cell, lo, hi)
    rel_lo, dy_lo, g_lo = clipped.min(axis=1)
    rel_hi, dy_hi, g_hi = clipped.max(axis=1)
    return (float((ref + rel_lo - pad) % 360.0), float(rel_hi - rel_lo + 2 * pad),
            float(dy_lo - pad_y), float(dy_hi + pad_y), float(g_lo - pad_g), float(g_hi + pad_g))


def _clip_corners(values, cell, lo, hi):
    """Multilinear interpolation of corner values to the corners of the cell
    clipped to the box ``[lo, hi]``.

    ``values`` is ``(n, 8)`` in ``_corners`` order (theta, d, mu bits, theta
    the slowest); returns ``(n, 8)``. One linear interpolation per axis in
    turn: the interpolant is separable, so this equals the trilinear formula.
    An axis the box covers whole keeps its corners."""
    v = values.reshape(-1, 2, 2, 2)
    for axis, (c0, c1) in enumerate(cell):
        u0 = min(1.0, max(0.0, (lo[axis] - c0) / (c1 - c0)))
        u1 = min(1.0, max(0.0, (hi[axis] - c0) / (c1 - c0)))
        if u0 == 0.0 and u1 == 1.0:
            continue
        a0 = np.take(v, 0, axis=axis + 1)
        a1 = np.take(v, 1, axis=axis + 1)
        v = np.stack([a0 + (a1 - a0) * u0, a0 + (a1 - a0) * u1], axis=axis + 1)
    return v.reshape(values.shape[0], 8)


def _corner_pieces(cell, lattice, tol, a):
    """A finest cell across a jump: corners that agree (neighbours within
    ``jump_deg``, transitively) form one side of the jump; each side gives
    the hull of its corners, padded by ``pad_jump_deg`` (outcomes change fast
    near a jump)."""
    keys = _corners(cell)
    vals = [lattice.known[k] for k in keys]
    group = list(range(8))
    for i, j in _EDGES:  # union-find over agreeing neighbours
        if abs(((vals[i][1] - vals[j][1] + 180.0) % 360.0) - 180.0) <= tol.jump_deg:
            gi, gj = _root(group, i), _root(group, j)
            group[gi] = gj
    d0, d1 = cell[1][0] * UNITS[1], cell[1][1] * UNITS[1]
    out = []
    for r in {_root(group, i) for i in range(8)}:
        members = [i for i in range(8) if _root(group, i) == r]
        ref = vals[members[0]][1]
        rel = [((vals[i][1] - ref + 180.0) % 360.0) - 180.0 for i in members]
        dys = [vals[i][2] for i in members]
        gs = [vals[i][2] - keys[i][1] * UNITS[1] * a for i in members]
        pad, pad_y = tol.pad_jump_deg, tol.pad_jump_dy
        out.append(((ref + min(rel) - pad) % 360.0, max(rel) - min(rel) + 2 * pad,
                    min(dys) - pad_y, max(dys) + pad_y, min(gs) - pad_y, max(gs) + pad_y, d0, d1))
    return out


def _root(group, i):
    while group[i] != i:
        i = group[i]
    return i


def _children(pieces, state, y_pin, h, a, d_lo, d_hi):
    # Pieces closer than the carry grid are one set (a union is still sound).
    arcs = merge_arcs([(p[0] - 0.5 * SNAP_DEG, p[1] + SNAP_DEG) for p in pieces])
    children = []
    for arc in arcs:
        y_lo, y_hi = math.inf, -math.inf
        for p in pieces:
            if not arc_within((p[0] % 360.0, p[1]), arc):
                continue
            # Two sound bounds on the new y_c, intersected: y_c + dy with y_c
            # consistent with this piece's d range, and y_pin + offset + g.
            c0, c1 = max(p[6], d_lo), min(p[7], d_hi)
            yc_lo = max(state.y_lo, y_pin - h - c1 * a)
            yc_hi = min(state.y_hi, y_pin + h - c0 * a)
            y_lo = min(y_lo, max(yc_lo + p[2], y_pin - h + p[4]))
            y_hi = max(y_hi, min(yc_hi + p[3], y_pin + h + p[5]))
        children.append(snapped_state(arc[0], arc[1], y_lo, y_hi, state.mu_lo, state.mu_hi))
    return children

