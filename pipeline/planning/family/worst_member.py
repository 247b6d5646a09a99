"""The worst member of a support family for one plan: a search, not a sample.

A plan for a support family is verified on trials that rest on the members the
family text draws (``tripods:12`` draws 12 tripods). A finite sample does not
contain the family's edge, and the edge is where a plan breaks. This module
searches the family's *parameter space* for the member whose final
orientations lie farthest outside the plan's set:

* ``tripods:N[:inset=F]``: three leg positions (6 numbers) anywhere in the
  outline at least ``F a`` from its edge, weights by statics (the centroid's
  barycentric coordinates), every leg carrying at least 5 %; for a part with
  holes, on the material and at least ``F a`` from every rim, holes' too
  (as ``sample_tripods``): a start whose leg falls in a hole is dropped;
* ``warp:AMP``: the three quadratic coefficients ``c`` of the pressure
  ``1 + AMP q``, ``q = c . modes`` kept within ``max |q| <= 1``;
* any other item (``tripod``, ``rim:N``, ``points:...``, ``uniform``): every
  member as given.

The *objective* of a member is the largest signed angular distance (degrees)
of its final orientations outside the plan's set, over the resting states'
nominal rollouts and every corner of the verification's perturbation box
(positive outside the set, negative inside: a member deep inside scores the
depth of its nearest final, so the optimiser is not lost on a plateau). A
jam scores ``JAM_SCORE``. Physics goes through the public rollout API
(``verify.replay``) only.

The search is a seeded multi-start Nelder-Mead (``scipy.optimize``) on the
raw parameters with a penalty outside the feasible set, started from the
family's geometric corners (legs at the inset outline's corners, every
triple of them for an outline with more than 3 corners; the smallest leg
triangle about the centroid; the warp modes at full amplitude, both signs)
and from seeded random members. It stops as soon as a member breaks the plan
or the budget (rollout evaluations of one member) is spent. A plan of many
pins has many corners (``2**(3 + pins)`` per resting state); the search
then scores members on at most ``SEARCH_CORNERS`` of them per state
(:func:`coarse_rows`: the pins' diagonal, then seeded random ones) and the
member it ends with on all of them. A member that breaks a plan on that
subset breaks it on the full probe too; one that only breaks it on corners
left out is found only if it is the member the search ends with.

:func:`check_plan_for_family` judges a plan again with the worst members
found joining the verification; :class:`FamilyChecker` is what the complete
search calls on each plan that passed its sampled verification.
"""
from __future__ import annotations

import dataclasses
import itertools
import math
from dataclasses import dataclass, field
from types import SimpleNamespace

import numpy as np
from scipy.optimize import minimize

from pipeline.errors import PinfeedError
from pipeline.parts.support import (Support, barycentric, filled_support, material_distance,
                                    point_support, signed_material_distance)
from pipeline.parts.support_family import (DEFAULT_INSET, MIN_LEG_WEIGHT, WARP_FILL, SupportFamily,
                                           parse_support_family, warp_modes)
from pipeline.planning.claims import orient
from pipeline.planning.claims.confidence import DEFAULT_CONFIDENCE
from pipeline.planning.core.resting import resting_states
from pipeline.config import schema_default
from pipeline.planning.core.settings import PlannerSettings, nominal_friction
from pipeline.planning.claims.verify import corner_inputs, replay, replay_shared, trial_inputs, verify_dict
from pipeline.progress import Heartbeat

DEFAULT_BUDGET = schema_default("planner", "worst_member_budget")  # member evaluations per search
JAM_SCORE = 180.0  # deg: a jam is as far outside the set as anything can be
RANDOM_STARTS = 6  # seeded random members besides the geometric corners
RANDOM_SHARE = 0.5  # of the budget spent on the starts (corners, then seeded random members)
LARGEST_STARTS = 8  # largest leg triangles on the inset outline among the starts
EDGE_POINTS = 5  # points per inset edge (besides its corner) the largest triangles' legs take
MAX_ROUNDS = 3  # worst member found -> joins the verification -> searched again
_PENALTY = 1.0e3
_POOL = 20_000
PRESCREEN_ROWS = 200_000  # rollouts per batch of the kept breakers' prescreen
SEARCH_CORNERS = 64  # corners per resting state a member is scored on during the search
PRESCREEN_CORNERS = 16  # corners per resting state in the kept members' middle prescreen stage


# --------------------------------------------------------------------------- parameter spaces

@dataclass
class TripodSpace:
    """Three legs on the material at least ``inset a`` from its edges (the
    outline, and the holes' rims of a part with holes) that hold the centroid."""

    part: object
    inset: float

    kind = "tripods"
    size = 6

    def violation(self, x: np.ndarray) -> float:
        """0 for a feasible tripod, else how far it is from one (mm-ish)."""
        legs = np.asarray(x, float).reshape(3, 2)
        signed = signed_material_distance(self.part, legs)  # negative outside or in a hole
        bad = np.maximum(0.0, self.inset * self.part.a * (1 - 1e-9) - signed).sum()
        lam = _weights(legs, self.part.a)
        if lam is None:
            return bad + 1.0
        return bad + np.maximum(0.0, MIN_LEG_WEIGHT - lam).sum() * self.part.a

    def member(self, x, label: str) -> Support:
        """The tripod with legs ``x`` (6 numbers, mm) and weights by statics."""
        legs = np.asarray(x, float).reshape(3, 2)
        return point_support(self.part, legs, _weights(legs, self.part.a), kind="points", label=label)

    def params(self, x) -> dict:
        """Legs (mm) and weights of ``x`` for outputs."""
        legs = np.asarray(x, float).reshape(3, 2)
        lam = _weights(legs, self.part.a)
        return {"legs_mm": np.round(legs, 4).tolist(),
                "weights": None if lam is None else np.round(lam, 4).tolist()}

    def corners(self) -> list[np.ndarray]:
        """The starts of :meth:`_corners`, found once per space (copies)."""
        if "_starts" not in self.__dict__:
            self.__dict__["_starts"] = self._corners()
        return [x.copy() for x in self.__dict__["_starts"]]

    def _corners(self) -> list[np.ndarray]:
        """Legs at the inset outline's corners (every triple that holds the
        centroid), the ``LARGEST_STARTS`` largest leg triangles with legs on
        the inset outline (corners and ``EDGE_POINTS`` points along each
        edge: where no corner triple holds the centroid, as on a rectangle,
        these are the extreme tripods), and the smallest leg triangles about
        the centroid (three turns). Starts with a leg off the material (in
        a hole, or nearer its rim than the inset) are dropped."""
        pts = inset_corners(np.asarray(self.part.vertices, float), self.inset * self.part.a,
                            getattr(self.part, "holes", ()))
        out = [np.array(t).ravel() for t in itertools.combinations(pts, 3)]
        out = [x for x in out if self.violation(x) == 0.0]
        rim = [p + (q - p) * t for p, q in zip(pts, np.roll(pts, -1, axis=0))
               for t in np.linspace(0.0, 1.0, EDGE_POINTS + 1, endpoint=False)]
        big = [np.array(t) for t in itertools.combinations(rim, 3)]
        big = [t.ravel() for t in big if self.violation(t.ravel()) == 0.0]
        big.sort(key=_area, reverse=True)
        out += [x for x in big if not any(np.allclose(x, y) for y in out)][:LARGEST_STARTS]
        r = max(0.05, 1.0 - self.inset) * 0.1 * self.part.a
        for turn in (0.0, 40.0, 80.0):
            ang = np.radians(turn + np.array([90.0, 210.0, 330.0]))
            out.append(np.column_stack([r * np.cos(ang), r * np.sin(ang)]).ravel())
        return [x for x in out if self.violation(x) == 0.0]

    def random(self, rng, n: int) -> list[np.ndarray]:
        """Up to ``n`` feasible tripods with legs uniform in the inset material."""
        verts = np.asarray(self.part.vertices, float)
        lo, hi = verts.min(axis=0), verts.max(axis=0)
        xy = rng.uniform(lo, hi, (_POOL, 2))
        on, dist = material_distance(self.part, xy)
        pool = xy[on & (dist >= self.inset * self.part.a)]
        out = []
        for _ in range(200 * n if pool.shape[0] >= 3 else 0):
            x = pool[rng.choice(pool.shape[0], 3, replace=False)].ravel()
            if _may_hold_centroid(x, self.part.a) and self.violation(x) == 0.0:
                out.append(x)
                if len(out) == n:
                    break
        return out

    def sample(self, rng, n: int) -> list[Support]:
        """``n`` random members (a fresh sample for the certificate)."""
        return [self.member(x, f"fresh tripod {k + 1}") for k, x in enumerate(self.random(rng, n))]

    def describe(self) -> str:
        """The space in words."""
        return f"tripods {self.inset:g} a inside the {_where(self.part)}"


@dataclass
class WarpSpace:
    """Pressures ``1 + amplitude q``, ``q`` a mix of the three quadratic modes with ``max |q| <= 1``."""

    part: object
    amplitude: float
    base: Support = field(init=False)
    modes: np.ndarray = field(init=False)

    kind = "warp"
    size = 3

    def __post_init__(self):
        self.base = filled_support(self.part, WARP_FILL)
        self.modes = warp_modes(self.base.points, self.base.weights, self.part.a)

    def _q(self, x) -> np.ndarray:
        q = np.asarray(x, float) @ self.modes
        return q / max(1.0, float(np.max(np.abs(q))))

    def violation(self, x) -> float:
        """Always 0: every coefficient vector is rescaled into the bound."""
        return 0.0

    def member(self, x, label: str) -> Support:
        """The warped pressure of coefficients ``x`` (3 numbers)."""
        w = self.base.weights * (1.0 + self.amplitude * self._q(x))
        return point_support(self.part, self.base.points, w, kind="points", label=label)

    def params(self, x) -> dict:
        """The coefficients of ``x`` as used (within the bound) and the amplitude."""
        q = np.asarray(x, float) @ self.modes
        scale = 1.0 / max(1.0, float(np.max(np.abs(q))))
        return {"coefficients": np.round(np.asarray(x, float) * scale, 4).tolist(),
                "amplitude": self.amplitude}

    def corners(self) -> list[np.ndarray]:
        """Each mode at full amplitude, both signs (the dome and dish among them)."""
        return [s * e for e in np.eye(3) for s in (-1.0, 1.0)]

    def random(self, rng, n: int) -> list[np.ndarray]:
        """``n`` seeded random coefficient vectors inside the bound."""
        c = rng.normal(size=(n, 3))
        return list(c / np.linalg.norm(c, axis=1, keepdims=True) * rng.uniform(0.3, 1.0, (n, 1)))

    def sample(self, rng, n: int) -> list[Support]:
        """``n`` random members (a fresh sample for the certificate)."""
        return [self.member(x, f"fresh warp {k + 1}") for k, x in enumerate(self.random(rng, n))]

    def describe(self) -> str:
        """The space in words."""
        return f"warps of amplitude up to {self.amplitude:g}"


def _where(part) -> str:
    """What a tripod's legs stand in, in words: the outline, or the material of a part with holes."""
    return "material" if getattr(part, "holes", ()) else "outline"


def _area(x: np.ndarray) -> float:
    """Twice the area of the leg triangle ``x`` (6 numbers)."""
    (ux, uy), (vx, vy) = x[2:4] - x[0:2], x[4:6] - x[0:2]
    return abs(ux * vy - uy * vx)


def _weights(legs: np.ndarray, a: float) -> np.ndarray | None:
    """Statics' leg weights (the centroid's barycentric coordinates), or None
    for three legs in a line."""
    (ux, uy), (vx, vy) = legs[1] - legs[0], legs[2] - legs[0]
    if abs(ux * vy - uy * vx) < 1e-9 * a * a:
        return None
    return barycentric(*legs)


def _may_hold_centroid(x, a: float) -> bool:
    """A quick necessary test of :meth:`TripodSpace.violation`'s weights: legs
    ``x`` (6 numbers) not in a line whose centroid weights (barycentric, in
    plain floats) are all at least ``MIN_LEG_WEIGHT`` less a rounding slack.
    Most random triples fail it, at a fraction of the full test's cost."""
    x0, y0, x1, y1, x2, y2 = (float(v) for v in x)
    det = (x1 - x0) * (y2 - y0) - (x2 - x0) * (y1 - y0)
    if abs(det) < 1e-9 * a * a:
        return False
    l1 = (-x0 * (y2 - y0) + (x2 - x0) * y0) / det
    l2 = (-(x1 - x0) * y0 + x0 * (y1 - y0)) / det
    return min(l1, l2, 1.0 - l1 - l2) >= MIN_LEG_WEIGHT - 1e-6


def inset_corners(verts: np.ndarray, distance: float, holes=()) -> np.ndarray:
    """The corners of the outline moved inwards by ``distance`` along each
    corner's bisector (exact for a convex outline; a reflex corner's point is
    kept only if it lies at least ``distance`` from every edge).

    ``holes``: the part's holes (part frame); a point in a hole or nearer a
    hole's rim than ``distance`` is dropped as well (the legs stand on the
    material, as far from a hole's rim as from the outline)."""
    n = verts.shape[0]
    out = []
    for i in range(n):
        p, prev, nxt = verts[i], verts[i - 1], verts[(i + 1) % n]
        u1, u2 = (prev - p) / np.linalg.norm(prev - p), (nxt - p) / np.linalg.norm(nxt - p)
        bis = u1 + u2
        if np.linalg.norm(bis) < 1e-12:
            continue
        half = math.acos(float(np.clip(u1 @ u2, -1.0, 1.0))) / 2.0
        out.append(p + bis / np.linalg.norm(bis) * distance / math.sin(half))
    pts = np.array(out).reshape(-1, 2)
    on, dist = material_distance(SimpleNamespace(vertices=verts, holes=tuple(holes)), pts)
    return pts[on & (dist >= distance * (1 - 1e-9))]


@dataclass
class MemberSpace:
    """A family's parameter space: continuous parts (tripods, warps) and fixed members."""

    label: str
    spaces: list
    fixed: list

    def describe(self) -> str:
        """The space in words (for the plan file)."""
        parts = [s.describe() for s in self.spaces] + [f"{len(self.fixed)} listed member(s)"] * bool(self.fixed)
        return "; ".join(parts)


def member_space(part, family) -> MemberSpace:
    """The parameter space of ``family`` (its text or a :class:`SupportFamily`).

    Raises
    ------
    PinfeedError
        One line when a tripod space holds no tripod (the inset leaves no
        three points that hold the centroid with every leg >= 5 %).
    """
    label = family.label if isinstance(family, SupportFamily) else str(family)
    key = (getattr(part, "id", id(part)), label)
    if key not in _SPACES:
        _SPACES[key] = _member_space(part, label)
    return _SPACES[key]


_SPACES: dict = {}  # (part id, family text) -> MemberSpace: its starts are found once


def _member_space(part, label: str) -> MemberSpace:
    """The parameter space of the family text ``label`` (see :func:`member_space`)."""
    spaces, fixed = [], []
    for item in label.split(";"):
        item = item.strip()
        kind, _, rest = item.partition(":")
        fields = dict(f.split("=", 1) for f in rest.split(":") if "=" in f)
        if kind.strip() == "tripods":
            space = TripodSpace(part, float(fields.get("inset", DEFAULT_INSET)))
            if not (space.corners() or space.random(np.random.default_rng([0, 33]), 1)):
                raise PinfeedError(
                    f"support family {item!r} has no member: no three points {space.inset:g} a "
                    f"({space.inset * part.a:.3g} mm) inside the {_where(part)} hold the centroid with every "
                    f"leg carrying >= {MIN_LEG_WEIGHT:.0%}; lower the inset (tripods:N:inset=F)")
            spaces.append(space)
        elif kind.strip() == "warp":
            spaces.append(WarpSpace(part, float([f for f in rest.split(":") if "=" not in f][0])))
        elif item:
            fixed.extend(parse_support_family(item, part).members)
    return MemberSpace(label, spaces, fixed)


# --------------------------------------------------------------------------- the objective

def probe_inputs(part, mu_c, n_pins: int, cfg: dict) -> tuple[tuple, np.ndarray]:
    """The probe's starts for plans of ``n_pins`` pins: every resting state of
    ``part`` at the middle friction, then at every corner of the perturbation
    box (``cfg``); ``((theta, y_c, mu, offsets), each state's nominal row)``."""
    rows = []
    for theta, y_c in resting_states(part).values():
        rows.append((np.array([theta]), np.array([y_c]), np.array([nominal_friction(mu_c)]),
                     np.zeros((1, n_pins))))
        rows.append(corner_inputs(theta, y_c, mu_c, n_pins, cfg))
    inputs = tuple(np.concatenate([r[k] for r in rows]) for k in range(4))
    sizes = np.array([r[0].size for r in rows])
    return inputs, np.concatenate([[0], np.cumsum(sizes)[:-1]])[0::2]


def coarse_rows(offsets: np.ndarray, nominal: np.ndarray, corners: int = SEARCH_CORNERS) -> np.ndarray:
    """The probe rows a search scores members on: per resting state its
    nominal row and at most ``corners`` of its corners, namely every corner
    whose pins are all offset the same way (the box's diagonal in the pins'
    offsets) and then seeded random ones; all rows when a state has no more.

    A member's objective on these rows is at most its objective on the full
    probe (a maximum over a subset), so a member that breaks a plan here
    breaks it on the full probe too."""
    rng = np.random.default_rng(17)
    ends = [*nominal[1:], offsets.shape[0]]
    picked = []
    for start, end in zip(nominal, ends):
        corner = np.arange(start + 1, end)
        picked.append([start])
        if corner.size <= corners:
            picked.append(corner)
            continue
        offs = offsets[corner]
        diagonal = corner[offs.min(axis=1) == offs.max(axis=1)][:corners]
        rest = np.setdiff1d(corner, diagonal)
        extra = rng.choice(rest, size=max(0, corners - diagonal.size), replace=False)
        picked.append(np.sort(np.concatenate([diagonal, extra])))
    return np.concatenate(picked).astype(int)


@dataclass
class PlanProbe:
    """What a member is scored on: a plan's pins and the trials that probe it."""

    part: object
    heights: tuple
    mu_c: object
    settings: dict
    pin_radius: float = 3.0
    model: str = "minpower"
    kernel: dict = field(default_factory=dict)
    speeds: tuple = ()
    inputs: tuple = field(init=False)
    nominal: np.ndarray = field(init=False)
    coarse: tuple | None = field(init=False)

    def __post_init__(self):
        self.inputs, self.nominal = probe_inputs(self.part, self.mu_c, len(self.heights), verify_dict(self.settings))
        rows = coarse_rows(self.inputs[3], self.nominal, SEARCH_CORNERS)
        self.coarse = None if rows.size == self.inputs[0].size else tuple(x[rows] for x in self.inputs)

    def finals(self, support: Support | None, inputs=None) -> tuple[np.ndarray, np.ndarray]:
        """``(theta_f, jammed)`` of every probe trial resting on ``support``."""
        th, yc, mu, offs = self.inputs if inputs is None else inputs
        kw = {k: self.kernel[k] for k in ("ds_max", "tol") if k in self.kernel}
        speeds = list(self.speeds) or [0.0] * len(self.heights)
        tf, _, jam, _ = replay(self.part, list(self.heights), speeds, th, yc, mu, offs, self.pin_radius, self.model, **kw,
                               support=np.zeros(th.size, int), supports=[support])
        return tf, jam != ""


def outside(theta, arc: tuple, period: float = 360.0) -> np.ndarray:
    """Signed angular distance (deg) of each ``theta`` outside the arc
    ``(start, width)``: positive outside, minus the distance to the nearer
    end inside."""
    start, width = arc
    rel = np.mod(np.asarray(theta, float) - start, period)
    inside = rel <= width
    beyond = np.minimum(rel - width, period - rel)
    return np.where(inside, -np.minimum(rel, width - rel), beyond)


def score(probe: PlanProbe, support, arc, period: float, coarse: bool = False) -> tuple[float, np.ndarray]:
    """``(objective, finals)`` of one member (see the module docstring), on the
    full probe or (``coarse``) on its :func:`coarse_rows`."""
    rows = getattr(probe, "coarse", None) if coarse else None  # a probe without a subset: all rows
    tf, jam = probe.finals(support) if rows is None else probe.finals(support, rows)
    dist = np.where(jam, JAM_SCORE, outside(tf, arc, period))
    return float(dist.max()), tf


# --------------------------------------------------------------------------- the search

@dataclass
class WorstMember:
    """The member a search found farthest outside the set."""

    support: Support
    params: dict
    objective: float
    finals: np.ndarray
    evaluations: int
    source: str
    nominal: np.ndarray = field(default_factory=lambda: np.zeros(0, int))

    @property
    def breaks(self) -> bool:
        """True when some final lies outside the set."""
        return self.objective > 0.0

    def to_dict(self) -> dict:
        """JSON-ready: the member, its parameters, how far outside, its nominal finals."""
        return {"member": self.support.to_dict(), "parameters": self.params,
                "outside_deg": round(self.objective, 4), "breaks": self.breaks,
                "nominal_finals_deg": np.round(self.finals[self.nominal], 3).tolist(),
                "probe_finals": int(self.finals.size), "evaluations": self.evaluations,
                "found_by": self.source}


class _Stop(Exception):
    pass


def check_budget(budget) -> int:
    """The search budget as an int >= 1, or a one-line :class:`PinfeedError`."""
    try:
        n = int(budget)
    except (TypeError, ValueError):
        n = 0
    if n < 1:
        raise PinfeedError(f"a search with no budget: planner.worst_member_budget is {budget!r}; "
                           f"give the number of member evaluations, at least 1 (e.g. {DEFAULT_BUDGET})")
    return n


def search_worst_member(probe: PlanProbe, space: MemberSpace, arc: tuple, period: float = 360.0,
                        budget: int = DEFAULT_BUDGET, seed: int = 0,
                        stop_when_broken: bool = True, beat: Heartbeat | None = None) -> WorstMember:
    """The member of ``space`` whose probe finals lie farthest outside ``arc``
    (``(start, width)`` degrees) within ``budget`` member evaluations.

    Every fixed member is scored; then, for each continuous space, its
    geometric corners and ``RANDOM_STARTS`` seeded random members are scored
    and Nelder-Mead runs from the highest-scoring starts until the budget is
    spent (the budget is shared between the spaces). ``beat`` (a
    :class:`~pipeline.progress.Heartbeat` counting evaluations) is ticked
    after each one."""
    budget = check_budget(budget)
    best = {"obj": -np.inf}
    used = [0]
    beat = (beat or Heartbeat("", budget)).start()

    def keep(obj, tf, support, params, source):
        beat.tick(used[0])
        if obj > best["obj"]:
            best.update(obj=obj, tf=tf, support=support, params=params, source=source)

    for m in space.fixed:
        obj, tf = score(probe, None if m.is_uniform else m, arc, period, coarse=True)
        used[0] += 1
        keep(obj, tf, m, {"member": m.label}, "listed member")
    rng = np.random.default_rng([int(seed), 33])
    share = max(1, (budget - used[0]) // max(1, len(space.spaces)))
    for space_k in space.spaces:
        _search_space(probe, space_k, arc, period, share, rng, keep, used, stop_when_broken, best)
        if stop_when_broken and best["obj"] > 0:
            break
    if best["obj"] == -np.inf:
        raise PinfeedError(f"support family {space.label!r} has no member to search")
    if getattr(probe, "coarse", None) is not None:  # the member found, on the full probe (only higher)
        member = None if getattr(best["support"], "is_uniform", False) else best["support"]
        best["obj"], best["tf"] = score(probe, member, arc, period)
    beat.finish(used[0], "a member breaks the plan" if best["obj"] > 0 else "")
    return WorstMember(best["support"], best["params"], float(best["obj"]), best["tf"], used[0],
                       best["source"], probe.nominal)


def _search_space(probe, space, arc, period, budget, rng, keep, used, stop_when_broken, best):
    """Multi-start Nelder-Mead over one continuous space (see :func:`search_worst_member`)."""
    spent = [0]

    def f(x, source):
        bad = space.violation(x)
        if bad > 0:
            return _PENALTY + bad
        if spent[0] >= budget:
            raise _Stop
        spent[0] += 1
        used[0] += 1
        support = space.member(x, f"worst {space.kind} member")
        obj, tf = score(probe, support, arc, period, coarse=True)
        keep(obj, tf, support, space.params(x), source)
        if stop_when_broken and obj > 0:
            raise _Stop
        return -obj

    starts = [(x, "geometric corner") for x in space.corners()]
    n_random = max(RANDOM_STARTS, int(RANDOM_SHARE * budget) - len(starts))
    starts += [(x, "random start") for x in space.random(rng, n_random)]
    try:
        values = [f(x, src) for x, src in starts]
        for i in np.argsort(values):
            x0, src = starts[i]
            step = 0.05 * probe.part.a if space.kind == "tripods" else 0.2
            simplex = np.vstack([x0, x0 + step * np.eye(space.size)])
            minimize(f, x0, args=(f"Nelder-Mead from a {src}",), method="Nelder-Mead",
                     options={"initial_simplex": simplex, "maxfev": max(10, budget // 4),
                              "xatol": 1e-3, "fatol": 1e-3})
    except _Stop:
        pass


# --------------------------------------------------------------------------- judged again

@dataclass
class FamilyCheckSettings:
    """How a plan is checked for a family: the planner's verification settings and the search's."""

    mu_c: object
    tolerance: float
    required: float
    verify: dict
    pin_radius: float = 3.0
    model: str = "minpower"
    kernel: dict = field(default_factory=dict)
    budget: int = DEFAULT_BUDGET
    seed: int = 0

    @classmethod
    def from_settings(cls, settings: PlannerSettings) -> "FamilyCheckSettings":
        """The planner's settings at its friction: its claim, its trials (with
        the claim's confidence and rule), its mechanics and its budget."""
        search, claims = settings.search, settings.claims
        verify = dict(settings.verify.as_dict(), confidence=claims.confidence, rule=claims.rule)
        return cls(settings.friction.value, claims.tolerance_deg, claims.required, verify,
                   search.pin_radius, search.model, search.kernel_settings,
                   check_budget(search.worst_member_budget), settings.verify.seed)


def claimed_arc(verdict: dict, tolerance: float) -> tuple | None:
    """The set a family plan claims: its verified set widened about its middle
    to the tolerance (the widest arc the claim "one arc of at most T" allows
    around the trials); ``None`` when the verdict has no set."""
    s = verdict.get("set")
    if not s:
        return None
    grow = max(0.0, tolerance - s["width"]) / 2.0
    return (s["start"] - grow, max(s["width"], tolerance))


def verify_members(part, heights, family: SupportFamily, st: FamilyCheckSettings, speeds=(),
                   progress=None, what: str = "verification on the family's members") -> dict:
    """The verification's trials of a plan (``verify.trial_inputs``) on ``family``,
    judged; ``progress`` hears how far the trials have got (stage ``what``)."""
    inputs = trial_inputs(resting_states(part), st.mu_c, len(heights), st.verify, family)
    th, yc, mu, offs, sup = (np.concatenate([r[k] for r in inputs]) for k in range(5))
    kw = {k: st.kernel[k] for k in ("ds_max", "tol") if k in st.kernel}
    with Heartbeat(what, th.size, "trial", progress) as beat:
        tf, _, jam, _ = replay(part, list(heights), list(speeds) or [0.0] * len(heights), th, yc, mu, offs,
                               st.pin_radius, st.model, **kw, support=sup, supports=family.kernel_supports,
                               stretch=beat.stretch(0, th.size))
    return orient.judge(tf[jam == ""], th.size, st.tolerance, part.symmetry_order(), st.required,
                        st.verify.get("confidence", DEFAULT_CONFIDENCE), rule=st.verify.get("rule", "bound"))


def known_member(probe: PlanProbe, members, arc: tuple, period: float, params=()) -> WorstMember | None:
    """The first of ``members`` (worst members kept from earlier plans) whose
    probe finals leave ``arc``, as a :class:`WorstMember` with its search
    parameters from ``params`` (one dict per member, when known); else None."""
    for k, support in enumerate(members):
        obj, tf = score(probe, support, arc, period)
        if obj > 0:
            found = params[k] if k < len(params) else {"member": support.label}
            return WorstMember(support, found, obj, tf, 1,
                               f"worst member kept from an earlier plan ({k + 1} of {len(members)})",
                               probe.nominal)
    return None


def check_plan_for_family(part, heights, family: SupportFamily, st: FamilyCheckSettings,
                          verdict: dict | None = None, speeds=(), progress=None, name: str = "the plan",
                          known=(), known_params=()) -> dict:
    """Search the worst member of ``family`` for the plan of pins at ``heights``
    (mm); when it breaks the plan, the member joins the verification's members
    and the plan is judged again, up to ``MAX_ROUNDS`` times.

    Returns a JSON-ready dict: ``holds`` (the last search found no member
    outside the re-judged set and the re-judged verification orients),
    ``worst_member`` (:meth:`WorstMember.to_dict`), ``members`` and ``trials``
    of the last verification, ``rounds`` (what each search found), the
    ``verdict`` and ``set_deg`` the claim rests on, ``space``. ``progress``
    hears how far each search and verification has got (the plan called ``name``).
    ``known``: members kept from earlier checks; the first round tries them
    first and searches only when none leaves the plan's set."""
    space = member_space(part, family)
    probe = PlanProbe(part, tuple(float(h) for h in heights), st.mu_c, st.verify, st.pin_radius,
                      st.model, st.kernel, tuple(float(v) for v in speeds))
    period = 360.0 / part.symmetry_order()
    what = f"worst member of {family.label} for {name}"
    verdict = verdict or verify_members(part, heights, family, st, speeds, progress, f"{what}: verification")
    sampled = verdict  # the verdict on the family's sampled members, before any worst member joined
    joined, rounds, worst = family, [], None
    for k in range(MAX_ROUNDS):
        arc = claimed_arc(verdict, st.tolerance)
        if not verdict["orients"] or arc is None:
            break
        worst = known_member(probe, known, arc, period, known_params) if k == 0 and known else None
        if worst is None:
            beat = Heartbeat(f"{what}: search {k + 1}", st.budget, "member evaluation", progress)
            worst = search_worst_member(probe, space, arc, period, st.budget, st.seed + k, beat=beat)
        rounds.append({"set_deg": [round(arc[0] % period, 3), round(arc[1], 3)], **worst.to_dict()})
        if not worst.breaks:
            break
        extra = dataclasses.replace(worst.support, label=f"worst member {k + 1}")
        joined = SupportFamily(f"{joined.label} + worst member {k + 1}", joined.members + (extra,),
                               tuple(joined.representatives) + (len(joined.members),))
        verdict = verify_members(part, heights, joined, st, speeds, progress,
                                 f"{what}: verification with worst member {k + 1}")
    holds = bool(verdict["orients"] and worst is not None and not worst.breaks)
    arc = claimed_arc(verdict, st.tolerance)
    return {"holds": holds, "space": space.describe(), "budget": st.budget,
            "members": len(joined.members), "trials": verdict["trials"],
            "verdict": verdict, "sampled_verdict": {k: sampled.get(k) for k in ("orients", "in_tolerance", "trials")},
            "set_deg": None if arc is None else [round(arc[0] % period, 3), round(arc[1], 3)],
            "worst_member": None if worst is None else worst.to_dict(), "rounds": rounds,
            "_family": joined, "_worst": worst}


def arc_holds(must, tolerance: float, order: int = 1, others=None, allowed: int = 0) -> bool:
    """Whether one arc of ``tolerance`` degrees (modulo ``360 / order``) holds
    every angle of ``must`` and all but ``allowed`` of ``others`` (``(angles,
    jammed)``; a jammed one is never held)."""
    period = 360.0 / order
    x = np.sort(np.mod(np.asarray(must, float), period))
    if x.size == 0:
        return True
    gaps = np.diff(np.concatenate([x, [x[0] + period]]))
    k = int(np.argmax(gaps))
    first, span = x[(k + 1) % x.size], period - gaps[k]  # the smallest arc holding ``must``
    if span > tolerance + 1e-9:
        return False
    if others is None:
        return True
    theta, jammed = np.asarray(others[0], float)[~np.asarray(others[1], bool)], others[1]
    need = len(jammed) - int(allowed)
    if need <= 0:
        return True
    # Arcs that hold ``must`` start in [first - slack, first]; the count of
    # ``others`` held changes only where an arc's end reaches one of them or its
    # start passes one, so those starts and the range's ends are enough.
    slack = tolerance - span
    rel = np.mod(theta - (first - slack), period)
    ends = rel - tolerance
    starts = np.concatenate([[0.0, slack], rel[rel <= slack], ends[(ends >= 0.0) & (ends <= slack)]])
    held = ((np.mod(rel[None, :] - starts[:, None], period) <= tolerance + 1e-9).sum(axis=1))
    return bool(held.max() >= need)


class FamilyChecker:
    """What the complete search asks of a plan that passed its sampled
    verification: does the worst member of the family break it?
    Results are kept per pin sequence (``results``); each search tells
    ``progress`` (a function of one line) how far it has got.

    The worst members that broke a plan are kept (``breakers``): a member
    that breaks one plan often breaks its neighbours. A new plan's check
    tries the kept members first, in the first round of
    :func:`check_plan_for_family` (one that leaves the set joins the
    verification as a found one would, so the claim is the same), and
    searches only when none does. :meth:`prescreen` asks of many sequences
    at once, before they are judged, whether the kept members break them
    whatever their sets: when the kept members' probe finals and the screen
    trials leave no arc of the tolerance that could be claimed, no plan of
    the sequence holds for the family. That is exact for the members it
    replays (a family member shown by rollouts to end outside every possible
    set), and a member that breaks every candidate of a level ends that
    level before its sequences are judged.
    """

    def __init__(self, part, family: SupportFamily, settings: FamilyCheckSettings, progress=None):
        self.part, self.family, self.settings, self.progress = part, family, settings, progress
        self.space = member_space(part, family).describe()  # an empty space is an error before any search
        self.results: dict = {}
        self.breakers: list = []
        self.breaker_params: list = []  # each kept member's parameters (legs, coefficients)
        self.spared = {"searches": 0, "sequences": 0}

    def __call__(self, labels, heights, verdict: dict | None = None, speeds=()) -> bool:
        key = self.key(labels, heights)
        if key not in self.results:
            self.results[key] = check_plan_for_family(self.part, heights, self.family, self.settings,
                                                      verdict, speeds, self.progress, " ".join(labels),
                                                      known=tuple(self.breakers),
                                                      known_params=tuple(self.breaker_params))
            rounds = self.results[key]["rounds"]
            if rounds and rounds[0]["found_by"].startswith("worst member kept"):
                self.spared["searches"] += 1
            worst = self.results[key]["_worst"]
            if worst is not None and worst.breaks and not any(worst.support is b for b in self.breakers):
                self.breakers.append(worst.support)
                self.breaker_params.append(worst.params)
            self.results[key]["_speeds"] = tuple(float(v) for v in speeds)
        return self.results[key]["holds"]

    def prescreen(self, heights: np.ndarray, speeds: np.ndarray, tolerance: float, screened=None,
                  allowed: int = 0) -> np.ndarray:
        """True for each sequence (rows of ``heights``, ``speeds``) that the kept
        breakers break whatever the sequence's set.

        A plan for the family claims one arc of ``tolerance`` degrees that holds
        every kept member's probe finals (the resting states' nominal rollouts
        and the perturbation box's corners) and all but ``allowed`` of its
        verification trials. ``screened``, ``(finals, jammed)`` arrays
        ``(sequences, k)`` of some of those trials, makes the test sharper: no
        arc may then leave out more than ``allowed`` of them. A sequence is
        broken when a kept member's probe rollout jams or no such arc exists.

        In stages, each exact: the nominal rollouts first (if no arc holds
        them, none holds the whole probe), then ``PRESCREEN_CORNERS`` corners
        a state (the pins' diagonal), then, for the sequences left, the whole
        probe, or for a plan of many pins the rows the worst-member search
        scores on (:func:`coarse_rows`): a subset rejects less, never
        wrongly, at a fraction of the whole probe's cost."""
        heights, speeds = np.atleast_2d(heights), np.atleast_2d(speeds)
        broken = np.zeros(heights.shape[0], bool)
        if not self.breakers or heights.size == 0:
            return broken
        st = self.settings
        probe = PlanProbe(self.part, (0.0,) * heights.shape[1], st.mu_c, st.verify, st.pin_radius, st.model,
                          st.kernel)
        nominal = tuple(x[probe.nominal] for x in probe.inputs)
        last = probe.inputs if probe.coarse is None else probe.coarse
        few = tuple(x[coarse_rows(probe.inputs[3], probe.nominal, PRESCREEN_CORNERS)] for x in probe.inputs)
        stages = [nominal, few, last] if few[0].size < last[0].size else [nominal, last]
        for rows in stages:
            left = np.flatnonzero(~broken)
            if left.size == 0:
                break
            tf, jam = self._probe_finals(heights[left], speeds[left], rows)
            for j, i in enumerate(left):
                others = None if screened is None else (screened[0][i], screened[1][i])
                broken[i] = jam[j].any() or not arc_holds(tf[j], tolerance, self.part.symmetry_order(),
                                                          others, allowed)
        self.spared["sequences"] += int(broken.sum())
        return broken

    def _probe_finals(self, heights, speeds, rows) -> tuple[np.ndarray, np.ndarray]:
        """Finals and jam flags ``(sequences, members * rows)`` of every kept
        breaker on ``rows`` (``theta, y_c, mu, offsets``) past each sequence."""
        st, members = self.settings, len(self.breakers)
        th, yc, mu, offs = rows
        per = members * th.size  # rollouts per sequence
        kw = {k: st.kernel[k] for k in ("ds_max", "tol") if k in st.kernel}
        tfs, jams = [], []
        step = max(1, PRESCREEN_ROWS // per)
        for start in range(0, heights.shape[0], step):
            tf, jam = replay_shared(self.part, heights[start:start + step], speeds[start:start + step],
                                    np.tile(th, members), np.tile(yc, members), np.tile(mu, members),
                                    np.tile(offs, (members, 1)), st.pin_radius, st.model, **kw,
                                    support=np.repeat(np.arange(members), th.size), supports=list(self.breakers))
            tfs.append(tf)
            jams.append(jam)
        return np.concatenate(tfs), np.concatenate(jams)

    @staticmethod
    def key(labels, heights) -> tuple:
        """The cache key of a plan: its labels and heights."""
        return tuple(labels), tuple(round(float(h), 9) for h in heights)

    def result(self, labels, heights) -> dict | None:
        """The check of a plan already checked (else None)."""
        return self.results.get(self.key(labels, heights))
