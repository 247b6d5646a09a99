"""A support family's parameter space: the members a worst-member search moves through.

A plan for a support family is verified on trials that rest on the members
the family text draws (``tripods:12`` draws 12 tripods); the worst-member
search (:mod:`pipeline.planning.family.member_search`) looks instead
through the family's *parameter space*, which this module builds from the
family text:

* ``tripods:N[:inset=F]``: three leg positions (6 numbers) anywhere in the
  outline at least ``F a`` from its edge, weights by statics (the centroid's
  barycentric coordinates), every leg carrying at least 5 %; for a part with
  holes, on the material and at least ``F a`` from every rim, holes' too
  (as ``sample_tripods``): a start whose leg falls in a hole is dropped;
* ``warp:AMP``: the three quadratic coefficients ``c`` of the pressure
  ``1 + AMP q``, ``q = c . modes`` kept within ``max |q| <= 1``;
* any other item (``tripod``, ``rim:N``, ``points:...``, ``uniform``): every
  member as given.

Each continuous space gives the search its geometric corners (legs at the
inset outline's corners, every triple of them for an outline with more than
3 corners; the largest leg triangles on the inset outline; the smallest leg
triangle about the centroid; the warp modes at full amplitude, both signs),
seeded random members, and a penalty (:meth:`TripodSpace.violation`) outside
the feasible set.
"""
from __future__ import annotations

import itertools
import math
from dataclasses import dataclass, field
from types import SimpleNamespace

import numpy as np

from pipeline.errors import PinfeedError
from pipeline.parts.support import (Support, barycentric, filled_support, material_distance,
                                    point_support, signed_material_distance)
from pipeline.parts.support_family import (DEFAULT_INSET, MIN_LEG_WEIGHT, WARP_FILL, SupportFamily,
                                           parse_support_family, warp_modes)

LARGEST_STARTS = 8  # largest leg triangles on the inset outline among the starts
EDGE_POINTS = 5  # points per inset edge (besides its corner) the largest triangles' legs take
_POOL = 20_000


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
