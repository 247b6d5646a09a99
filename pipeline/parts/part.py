"""Parts: validated, normalised polygons, with or without holes, and a stable identity.

A :class:`Part` is built from an outline in its drawing frame, in either
winding, and zero or more holes. It keeps the outline counter-clockwise
and each hole clockwise (the material on the left of every edge), all
moved so that the area centroid of the material (outline minus holes: the
centre of mass for uniform density) is at the origin; body axes are the
drawing axes.

What a part may be: the outline is a simple polygon; each hole is a simple
polygon strictly inside it; holes do not touch the outline or each other.
Refused, with the reason: loops that cross or touch (an opening to the
outline is a notch: draw it as part of the outline), a hole outside the
outline, and a loop inside a hole (an island, a separate part). Pins touch
the outline only (an overhead pin comes from the belt's edge side and can
never enter a closed hole); the belt presses on the material only, so the
area, centroid, ``a``, the support integrals and the inertia leave the
holes out. ``Part.id`` is the name plus a hash of the
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
from kernels.rollout import _prepare, _prepare_loops

from pipeline.errors import PinfeedError


class PolygonError(PinfeedError):
    """The outline is not a simple polygon with non-zero area, or a hole is
    not a simple polygon strictly inside it and apart from the others."""


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


def parse_holes(texts) -> list[np.ndarray]:
    """Parse the CLI's repeated ``--hole "x,y x,y ..."`` into ``(m, 2)`` arrays."""
    out = []
    for k, text in enumerate(texts or (), start=1):
        try:
            out.append(parse_vertices(text))
        except PolygonError as exc:
            raise PolygonError(f"hole {k}: {exc}") from None
    return out


_LOOP_PROBLEMS = {
    _geo.LOOPS_MEET: "{what_k} and {what_l} cross or touch",
    _geo.HOLE_OUTSIDE: "{what_k} is not inside the outline",
    _geo.HOLE_IN_HOLE: "{what_k} lies inside {what_l} (an island: a separate part)",
}
_LOOP_ADVICE = {
    _geo.LOOPS_MEET: ("; a hole must lie strictly inside the outline, apart from the others "
                      "(an opening to the outline is a notch: draw it as part of the outline)"),
    _geo.HOLE_OUTSIDE: "; give holes strictly inside the outline, in the same frame",
    _geo.HOLE_IN_HOLE: "; plan the island as a part of its own, or leave it out",
}


def check_holes(outline: np.ndarray, holes) -> list[np.ndarray]:
    """Each hole as a checked float64 ``(m, 2)`` array, or :class:`PolygonError`
    naming the hole and the way out (``outline`` already checked)."""
    out = []
    for k, hole in enumerate(holes, start=1):
        try:
            out.append(check_outline(hole))
        except PolygonError as exc:
            raise PolygonError(f"hole {k}: {exc}") from None
    if out:
        xy, starts = _stack(outline, out)
        code, k, l = _geo._loops_problem(_centred(xy, outline), starts)
        if code != _geo.LOOPS_OK:
            def what(i):
                return "the outline" if i == 0 else f"hole {i}"
            raise PolygonError(_LOOP_PROBLEMS[code].format(what_k=what(k), what_l=what(l))
                               + _LOOP_ADVICE[code])
    return out


def _stack(outline, holes):
    """The loops as one vertex array and their int64 offsets (``kernels.geometry._keyhole``)."""
    loops = [np.asarray(outline, dtype=np.float64)] + [np.asarray(h, dtype=np.float64) for h in holes]
    starts = np.concatenate([[0], np.cumsum([len(lp) for lp in loops])]).astype(np.int64)
    return np.ascontiguousarray(np.vstack(loops)), starts


def _canonical(loop: np.ndarray) -> np.ndarray:
    """A loop's vertices rounded to ``ID_QUANTUM``, started at the rotation that sorts first."""
    q = np.round(loop / ID_QUANTUM).astype(np.int64)
    start = min(range(len(q)), key=lambda k: np.roll(q, -k, axis=0).ravel().tolist())
    return np.roll(q, -start, axis=0)


def _centred(xy: np.ndarray, frame: np.ndarray | None = None) -> np.ndarray:
    """``xy`` shifted by the bounding-box centre of ``frame`` (default
    ``xy``), so the area and collinearity tests see the part's own size, not
    its distance from the origin (the differences are exact for a far-away
    part: Sterbenz's lemma)."""
    if not np.all(np.isfinite(xy)):
        return np.ascontiguousarray(xy)  # let the kernel name the bad vertex
    frame = xy if frame is None else frame
    centre = 0.5 * (frame.min(axis=0) + frame.max(axis=0))
    return np.ascontiguousarray(xy - centre)


@dataclass(frozen=True)
class Part:
    """A flat part: a simple polygon, counter-clockwise, with zero or more
    holes (clockwise), the material's centroid at the origin.

    Attributes
    ----------
    name : label used in catalogs and figures.
    vertices : ``(n, 2)`` body-frame outline (counter-clockwise, centred).
    area : area of the material (the outline's less the holes').
    a : largest centroid-to-vertex distance (the paper's reference length).
    holes : ``(m_k, 2)`` body-frame holes, each clockwise (empty for a solid part).
    """

    name: str
    vertices: np.ndarray = field(repr=False)
    area: float
    a: float
    holes: tuple = field(default=(), repr=False)

    @classmethod
    def from_vertices(cls, vertices, name: str = "part", holes=()) -> "Part":
        """Validate and normalise an outline (and its holes) given in the drawing frame."""
        xy = check_outline(vertices)
        hole_list = check_holes(xy, holes)
        if len(xy) + sum(len(h) for h in hole_list) > MAX_VERTICES:
            raise PolygonError(f"the outline and holes have {len(xy) + sum(len(h) for h in hole_list)} "
                               f"vertices, more than the limit of {MAX_VERTICES} (a rollout's time grows "
                               f"with the count); simplify them")
        if not hole_list:
            verts, area, a = _geo._normalise(_centred(xy))
            loops = []
        else:
            stacked, starts = _stack(xy, hole_list)
            allv, area, a = _geo._normalise_loops(_centred(stacked, xy), starts)
            verts = allv[:starts[1]].copy()
            loops = [allv[starts[k]:starts[k + 1]].copy() for k in range(1, len(starts) - 1)]
        if not a >= MIN_SIZE:
            raise PolygonError(f"the part is {a:.3g} across (centroid to farthest vertex), smaller "
                               f"than the limit of {MIN_SIZE:g} mm; give its outline in millimetres")
        for arr in [verts, *loops]:
            arr.setflags(write=False)
        return cls(name=str(name), vertices=verts, area=float(area), a=float(a), holes=tuple(loops))

    @classmethod
    def from_dict(cls, data: dict, name: str | None = None) -> "Part":
        """The part a :meth:`to_dict` (or a plan file's ``part``) describes."""
        return cls.from_vertices(data["vertices"], name=name or data.get("name", "part"),
                                 holes=data.get("holes") or ())

    @property
    def id(self) -> str:
        """``name-<hash>``: stable across runs, changes with the geometry."""
        return f"{self.name}-{self.geometry_hash}"

    @property
    def geometry_hash(self) -> str:
        """Hash of the canonical outline: counter-clockwise, centred (so winding
        and position do not matter), vertices rounded to ``ID_QUANTUM`` to drop
        float noise, started at the rotation that sorts first (so the first
        vertex does not matter); then the holes likewise, in sorted order (so
        their order does not matter). A solid part hashes its outline alone."""
        h = hashlib.sha256(_canonical(self.vertices).tobytes())
        for hole in sorted((_canonical(hole) for hole in self.holes), key=lambda q: q.ravel().tolist()):
            h.update(b"hole")
            h.update(hole.tobytes())
        return h.hexdigest()[:10]

    @property
    def has_holes(self) -> bool:
        """Whether the part has holes."""
        return bool(self.holes)

    def hole_attrs(self) -> dict:
        """File attributes of the holes (none for a solid part, whose stored
        files stay as they were): ``part_holes``, every hole's vertices one
        after the other, flattened, and ``part_hole_sizes``, their counts."""
        if not self.holes:
            return {}
        return {"part_holes": np.vstack(self.holes).ravel(),
                "part_hole_sizes": np.array([len(h) for h in self.holes], dtype=np.int64)}

    @staticmethod
    def holes_from_attrs(attrs) -> list[np.ndarray]:
        """The holes that :meth:`hole_attrs` stored (``[]`` when none)."""
        if "part_holes" not in attrs:
            return []
        flat = np.asarray(attrs["part_holes"], dtype=np.float64).reshape(-1, 2)
        ends = np.cumsum(np.atleast_1d(np.asarray(attrs["part_hole_sizes"], dtype=np.int64)))
        return np.split(flat, ends[:-1])

    def loops(self) -> tuple[np.ndarray, np.ndarray]:
        """The outline and holes as one ``(N, 2)`` array and the int64 loop
        offsets the kernels take (``kernels.rollout._prepare_loops``)."""
        return _stack(self.vertices, self.holes)

    @property
    def n_vertices(self) -> int:
        """Number of vertices of the outline."""
        return self.vertices.shape[0]

    @property
    def is_convex(self) -> bool:
        """Whether the outline is convex."""
        return bool(_geo._is_convex(self.vertices))

    def prepared(self):
        """Arrays the rollout kernels take (see ``kernels.rollout._prepare``),
        made once per part and kept: a part with many edges carries a support
        table (``kernels.support_table``) that takes about a second to build.
        The kernels only read them."""
        kept = self.__dict__.get("_prepared")
        if kept is None:
            if not self.holes:
                kept = _prepare(np.ascontiguousarray(self.vertices))
            else:
                kept = _prepare_loops(*self.loops())
            object.__setattr__(self, "_prepared", kept)  # a cache, not a field
        return kept

    def __getstate__(self):
        """Pickle the fields only: the kept kernel arrays are made again where needed."""
        return {k: v for k, v in self.__dict__.items() if k != "_prepared"}

    def mirrored(self) -> "Part":
        """Mirror image: ``y -> -y`` in the body frame."""
        flip = np.array([1.0, -1.0])
        return Part.from_vertices(self.vertices * flip, self.name + "-mirror",
                                  holes=[h * flip for h in self.holes])

    def scaled(self, k: float) -> "Part":
        """The same part scaled by ``k`` (about the origin of its vertices)."""
        return Part.from_vertices(self.vertices * float(k), self.name,
                                  holes=[h * float(k) for h in self.holes])

    def rotated(self, phi_deg: float) -> "Part":
        """The same part drawn rotated by ``phi_deg`` (counter-clockwise)."""
        c, s = math.cos(math.radians(phi_deg)), math.sin(math.radians(phi_deg))
        rot = np.array([[c, -s], [s, c]])
        return Part.from_vertices(self.vertices @ rot.T, self.name,
                                  holes=[h @ rot.T for h in self.holes])

    def stable_states(self) -> np.ndarray:
        """Resting states against a fence along the belt (see the manual's mechanics page, section 6).

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
        inner = np.vstack(self.holes) if self.holes else np.zeros((0, 2))
        scale = tol * self.a

        def maps_onto_itself(pts, c, s):
            if not len(pts):
                return True
            turned = pts @ np.array([[c, s], [-s, c]])
            gaps = np.min(np.hypot(*(turned[:, None, :] - pts[None, :, :]).transpose(2, 0, 1)), axis=1)
            return bool(np.all(gaps < scale))

        for k in range(v.shape[0], 1, -1):
            if v.shape[0] % k:
                continue
            c, s = math.cos(2 * math.pi / k), math.sin(2 * math.pi / k)
            if maps_onto_itself(v, c, s) and maps_onto_itself(inner, c, s):
                return k
        return 1

    def to_dict(self) -> dict:
        """Name, id, vertices, area and radius ``a`` (the part's length unit),
        and ``holes`` for a part with holes, as a JSON-ready dict."""
        out = {"name": self.name, "id": self.id, "vertices": self.vertices.tolist(),
               "area": self.area, "a": self.a}
        if self.holes:
            out["holes"] = [h.tolist() for h in self.holes]
        return out
