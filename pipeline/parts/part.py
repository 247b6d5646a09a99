"""Parts: validated, normalised polygons with a stable identity.

A :class:`Part` is built from an outline in its drawing frame, in either
winding. It keeps the outline counter-clockwise with the area centroid (the
centre of mass for uniform density) at the origin, as spec section 1 asks;
body axes are the drawing axes. ``Part.id`` is the name plus a hash of the
normalised geometry, so a changed outline never matches stale stored maps.

The id is canonical: the same outline gives the same id whichever vertex it
starts from, in either winding, wherever it is drawn (outlines are centred
before any arithmetic, so a triangle 1e6 mm from the origin is checked and
normalised as precisely as one at the origin). Ids made before this rule
(pinfeed <= the hardening change) hashed the vertex list as given; a catalog
written then stays readable, and new shards of such a part get the new id.

Limits (why: a rollout's time grows with each): at most ``MAX_VERTICES``
vertices (a 100-vertex outline takes about 0.025 s a rollout, a 500-vertex
one 0.35 s to 0.8 s), and a size ``a`` of at least ``MIN_SIZE`` (1 micrometre
in millimetres).
"""
from __future__ import annotations

import hashlib
import math
from dataclasses import dataclass, field

import numpy as np

from kernels import geometry as _geo
from kernels.rollout import _prepare

from pipeline.errors import PinfeedError


class PolygonError(PinfeedError):
    """The outline is not a simple polygon with non-zero area."""


MAX_VERTICES = 500  # with the kernel's step budget a 500-vertex rollout stays under ~1.5 s
MIN_SIZE = 1e-3  # smallest centroid-to-vertex distance a, in the length unit (mm)
ID_QUANTUM = 1e-6  # the id hashes vertices rounded to this (1 nm in mm)


_PROBLEMS = {
    _geo.POLY_TOO_FEW: "a polygon needs at least 3 vertices, got {j}",
    _geo.POLY_NOT_FINITE: "vertex {j} is not a finite number",
    _geo.POLY_REPEATED: "vertices {j} and {k} are the same point",
    _geo.POLY_SELF_INTERSECTING: "edges {j} and {k} cross: the polygon is self-intersecting",
    _geo.POLY_ZERO_AREA: "the polygon has zero area",
}


def parse_vertices(text: str) -> np.ndarray:
    """Parse ``"x0,y0 x1,y1 ..."`` (the CLI's ``--vertices``) into an ``(n, 2)`` array."""
    rows = []
    for token in text.replace(";", " ").split():
        parts = token.split(",")
        if len(parts) != 2:
            raise PolygonError(f"vertex {token!r} is not 'x,y'; write vertices as \"0,0 60,0 15,35\"")
        try:
            rows.append((float(parts[0]), float(parts[1])))
        except ValueError:
            raise PolygonError(f"vertex {token!r} is not two numbers 'x,y'") from None
    return check_outline(rows)


def check_outline(vertices) -> np.ndarray:
    """Return ``vertices`` as a float64 ``(n, 2)`` array or raise :class:`PolygonError`."""
    try:
        xy = np.asarray(vertices, dtype=np.float64)
    except (TypeError, ValueError):
        raise PolygonError("vertices must be a list of (x, y) number pairs") from None
    if xy.ndim != 2 or xy.shape[1] != 2:
        raise PolygonError(f"vertices must have shape (n, 2), got {xy.shape}")
    if xy.shape[0] > MAX_VERTICES:
        raise PolygonError(f"the outline has {xy.shape[0]} vertices, more than the limit of "
                           f"{MAX_VERTICES} (a rollout's time grows with the count); simplify it")
    code, j, k = _geo._polygon_problem(_centred(xy))
    if code != _geo.POLY_OK:
        raise PolygonError(_PROBLEMS[code].format(j=j, k=k) + "; give a simple polygon's vertices in order")
    return xy


def _centred(xy: np.ndarray) -> np.ndarray:
    """``xy`` shifted by its bounding-box centre, so the area and collinearity
    tests see the part's own size, not its distance from the origin (the
    differences are exact for a far-away part: Sterbenz's lemma)."""
    if not np.all(np.isfinite(xy)):
        return np.ascontiguousarray(xy)  # let the kernel name the bad vertex
    centre = 0.5 * (xy.min(axis=0) + xy.max(axis=0))
    return np.ascontiguousarray(xy - centre)


@dataclass(frozen=True)
class Part:
    """A flat part: a simple polygon, counter-clockwise, centroid at the origin.

    Attributes
    ----------
    name : label used in catalogs and figures.
    vertices : ``(n, 2)`` body-frame outline (counter-clockwise, centred).
    area : polygon area.
    a : largest centroid-to-vertex distance (the paper's reference length).
    """

    name: str
    vertices: np.ndarray = field(repr=False)
    area: float
    a: float

    @classmethod
    def from_vertices(cls, vertices, name: str = "part") -> "Part":
        """Validate and normalise an outline given in its drawing frame."""
        xy = check_outline(vertices)
        verts, area, a = _geo._normalise(_centred(xy))
        if not a >= MIN_SIZE:
            raise PolygonError(f"the part is {a:.3g} across (centroid to farthest vertex), smaller "
                               f"than the limit of {MIN_SIZE:g} mm; give its outline in millimetres")
        verts.setflags(write=False)
        return cls(name=str(name), vertices=verts, area=float(area), a=float(a))

    @property
    def id(self) -> str:
        """``name-<hash>``: stable across runs, changes with the geometry."""
        return f"{self.name}-{self.geometry_hash}"

    @property
    def geometry_hash(self) -> str:
        """Hash of the canonical outline: counter-clockwise, centred (so winding
        and position do not matter), vertices rounded to ``ID_QUANTUM`` to drop
        float noise, started at the rotation that sorts first (so the first
        vertex does not matter)."""
        q = np.round(self.vertices / ID_QUANTUM).astype(np.int64)
        start = min(range(len(q)), key=lambda k: np.roll(q, -k, axis=0).ravel().tolist())
        return hashlib.sha256(np.roll(q, -start, axis=0).tobytes()).hexdigest()[:10]

    @property
    def n_vertices(self) -> int:
        """Number of vertices of the outline."""
        return self.vertices.shape[0]

    @property
    def is_convex(self) -> bool:
        """Whether the outline is convex."""
        return bool(_geo._is_convex(self.vertices))

    def prepared(self):
        """Arrays the rollout kernels take (see ``kernels.rollout._prepare``)."""
        return _prepare(np.ascontiguousarray(self.vertices))

    def mirrored(self) -> "Part":
        """Mirror image: ``y -> -y`` in the body frame."""
        return Part.from_vertices(self.vertices * np.array([1.0, -1.0]), self.name + "-mirror")

    def scaled(self, k: float) -> "Part":
        """The same part scaled by ``k`` (about the origin of its vertices)."""
        return Part.from_vertices(self.vertices * float(k), self.name)

    def rotated(self, phi_deg: float) -> "Part":
        """The same part drawn rotated by ``phi_deg`` (counter-clockwise)."""
        c, s = math.cos(math.radians(phi_deg)), math.sin(math.radians(phi_deg))
        rot = np.array([[c, -s], [s, c]])
        return Part.from_vertices(self.vertices @ rot.T, self.name)

    def stable_states(self) -> np.ndarray:
        """Resting states against a fence along the belt (spec section 6).

        Returns rows ``(theta_deg, y_c)``: the orientation that puts a stable
        hull edge on the fence with the part on its ``+y`` side, and the
        centroid's distance from the fence.
        """
        rows = _geo._stable_edges(np.ascontiguousarray(self.vertices))
        return np.column_stack([np.degrees(rows[:, 2]) % 360.0, rows[:, 3]])

    def symmetry_order(self, tol: float = 1e-6) -> int:
        """Order k of the part's rotational symmetry about its centroid (1: none):
        orientations 360/k apart are the same physical orientation."""
        v = np.asarray(self.vertices)
        scale = tol * self.a
        for k in range(v.shape[0], 1, -1):
            if v.shape[0] % k:
                continue
            c, s = math.cos(2 * math.pi / k), math.sin(2 * math.pi / k)
            turned = v @ np.array([[c, s], [-s, c]])
            gaps = np.min(np.hypot(*(turned[:, None, :] - v[None, :, :]).transpose(2, 0, 1)), axis=1)
            if np.all(gaps < scale):
                return k
        return 1

    def to_dict(self) -> dict:
        """Name, id, vertices, area and radius ``a`` (the part's length unit) as a JSON-ready dict."""
        return {"name": self.name, "id": self.id, "vertices": self.vertices.tolist(),
                "area": self.area, "a": self.a}
