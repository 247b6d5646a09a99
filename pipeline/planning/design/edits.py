"""Small changes to a part's outline: chamfers, notches and tabs (pure geometry).

Every change works on the outline in its drawing frame, counter-clockwise
(:func:`ccw_outline`), whose edge ``k`` runs from vertex ``k`` to vertex
``k + 1`` and whose corner ``k`` is vertex ``k``:

``chamfer``
    cut the triangle off a convex corner ``k``: a leg of length ``s1`` along
    the edge before it (edge ``k - 1``) and ``s2`` along the edge after it
    (edge ``k``); it removes ``s1 * s2 * sin(angle) / 2``, ``angle`` the
    corner's interior angle.
``notch``
    a rectangular cut of width ``w`` (along edge ``k``) and depth ``h`` (into
    the material), centred at the fraction ``at`` of the edge; it removes
    ``w * h``.
``tab``
    the same rectangle added outside the edge; it adds ``w * h``.

A change is refused (:class:`ChangeRefused`, one line saying why) when the
changed outline is not a simple polygon with positive area, when it leaves
a hole outside the material, when it touches an edge the user keeps, when a
chamfer would use up a whole edge, or when it leaves less than the minimum
wall of material behind a new edge (measured along the new edge's inward
normal, at five points along it).

Holes are kept as they are: changing a hole (a hole to add, or to move) is
left out, because the pins touch the outline only and a hole moves the
centroid alone, which the outline changes here already do.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from pipeline.errors import PinfeedError
from pipeline.planning.core.settings import DESIGN_KINDS as KINDS
from pipeline.planning.core.settings import DesignGrid
WALL_SAMPLES = (0.1, 0.3, 0.5, 0.7, 0.9)  # where along a new edge its wall is measured


class ChangeRefused(PinfeedError):
    """A change that cannot be made to this outline within the user's limits."""


@dataclass(frozen=True)
class OutlineChange:
    """One change of an outline.

    Attributes
    ----------
    kind : ``"chamfer"``, ``"notch"`` or ``"tab"``.
    index : the corner (chamfer) or edge (notch, tab) it changes.
    size : chamfer: its legs ``(s1, s2)`` in mm; notch, tab: ``(width, depth)`` in mm.
    at : notch, tab: where the centre lies along the edge, a fraction of its length.
    """

    kind: str
    index: int
    size: tuple
    at: float = 0.5

    def describe(self) -> str:
        """The change as people read it (``chamfer at corner 2, legs 3.3 mm``)."""
        if self.kind == "chamfer":
            s1, s2 = self.size
            legs = f"legs {s1:.4g} mm" if math.isclose(s1, s2) else f"legs {s1:.4g} and {s2:.4g} mm"
            return f"chamfer at corner {self.index}, {legs}"
        w, h = self.size
        return f"{self.kind} on edge {self.index} at {self.at:g} of its length, {w:.4g} x {h:.4g} mm"

    def to_dict(self) -> dict:
        """JSON-ready: kind, index (``corner`` or ``edge``), sizes in mm, ``at``."""
        if self.kind == "chamfer":
            return {"kind": "chamfer", "corner": self.index, "legs_mm": [float(s) for s in self.size]}
        return {"kind": self.kind, "edge": self.index, "at": float(self.at),
                "width_mm": float(self.size[0]), "depth_mm": float(self.size[1])}


def signed_area(xy) -> float:
    """Shoelace area of a closed polygon, positive counter-clockwise."""
    xy = np.asarray(xy, dtype=float)
    x, y = xy[:, 0], xy[:, 1]
    return 0.5 * float(np.dot(x, np.roll(y, -1)) - np.dot(np.roll(x, -1), y))


def ccw_outline(vertices) -> np.ndarray:
    """The outline as a float ``(n, 2)`` array, counter-clockwise, in its own frame
    (same first vertex; a clockwise outline is read backwards from it)."""
    xy = np.asarray(vertices, dtype=float)
    if signed_area(xy) < 0:
        xy = np.vstack([xy[:1], xy[:0:-1]])
    return xy


def edge_lengths(xy: np.ndarray) -> np.ndarray:
    """Length of each edge ``k`` (vertex ``k`` to ``k + 1``)."""
    return np.linalg.norm(np.roll(xy, -1, axis=0) - xy, axis=1)


def interior_angle(xy: np.ndarray, corner: int) -> float:
    """Interior angle (radians, 0 to 2 pi) at ``corner`` of a counter-clockwise outline."""
    n = len(xy)
    p, q, r = xy[(corner - 1) % n], xy[corner], xy[(corner + 1) % n]
    u, v = p - q, r - q
    turn = math.atan2(u[0] * v[1] - u[1] * v[0], float(np.dot(u, v)))  # from u to v, anticlockwise
    return (-turn) % (2 * math.pi)


def is_convex_corner(xy: np.ndarray, corner: int) -> bool:
    """Whether the interior angle at ``corner`` is under 180 degrees."""
    return interior_angle(xy, corner) < math.pi - 1e-9


def touched_edges(n: int, change: OutlineChange) -> set[int]:
    """The original edges a change alters (a chamfer both edges at its corner)."""
    if change.kind == "chamfer":
        return {(change.index - 1) % n, change.index % n}
    return {change.index % n}


def changed_area(xy: np.ndarray, change: OutlineChange) -> float:
    """Area removed (chamfer, notch) or added (tab) in closed form, mm^2."""
    if change.kind == "chamfer":
        s1, s2 = change.size
        return 0.5 * s1 * s2 * math.sin(interior_angle(xy, change.index))
    w, h = change.size
    return w * h


def apply_change(xy: np.ndarray, change: OutlineChange, holes=(), keep_edges=(), min_wall: float = 0.0):
    """The outline ``xy`` (counter-clockwise, :func:`ccw_outline`) with ``change``
    made: a new ``(m, 2)`` array, checked.

    Raises
    ------
    ChangeRefused
        The change touches a kept edge, does not fit its corner or edge,
        leaves a wall thinner than ``min_wall`` mm, or gives an outline that
        is not a simple polygon with positive area holding the ``holes``.
    """
    if change.kind not in KINDS:
        raise ChangeRefused(f"unknown change {change.kind!r}; use one of {', '.join(KINDS)}")
    n = len(xy)
    kept = sorted(touched_edges(n, change) & {k % n for k in keep_edges})
    if kept:
        raise ChangeRefused(f"{change.describe()} would change edge {kept[0]}, which is kept")
    if change.kind == "chamfer":
        new, fresh = _chamfered(xy, change, min_wall)
    else:
        new, fresh = _rectangle(xy, change, 1.0 if change.kind == "tab" else -1.0)
    _check_polygon(new, holes, change)
    _check_walls(new, fresh, min_wall, change)
    return new


def _chamfered(xy: np.ndarray, change: OutlineChange, min_wall: float):
    """The chamfered outline and the index of its new edge."""
    n, k = len(xy), change.index % len(xy)
    s1, s2 = change.size
    if not is_convex_corner(xy, k):
        raise ChangeRefused(f"{change.describe()}: corner {k} is not convex")
    lengths = edge_lengths(xy)
    for edge, leg in (((k - 1) % n, s1), (k, s2)):
        if not 0 < leg < lengths[edge] - max(min_wall, 1e-9 * lengths[edge]):
            raise ChangeRefused(f"{change.describe()} would leave less than {min_wall:g} mm of edge {edge} "
                                f"({lengths[edge]:.4g} mm long)")
    p, q, r = xy[(k - 1) % n], xy[k], xy[(k + 1) % n]
    a = q + (p - q) * (s1 / np.linalg.norm(p - q))
    b = q + (r - q) * (s2 / np.linalg.norm(r - q))
    new = np.vstack([xy[:k], a, b, xy[k + 1:]])
    return new, [k]  # the new edge runs from a (vertex k) to b


def _rectangle(xy: np.ndarray, change: OutlineChange, outward: float):
    """The outline with a rectangle cut (``outward`` -1) or added (+1) on an
    edge, and the indices of its three new edges."""
    n, k = len(xy), change.index % len(xy)
    w, h = change.size
    p, q = xy[k], xy[(k + 1) % n]
    length = float(np.linalg.norm(q - p))
    if not (w > 0 and h > 0 and 0 < change.at < 1):
        raise ChangeRefused(f"{change.describe()}: width and depth must be > 0 and 'at' inside (0, 1)")
    lo, hi = change.at * length - w / 2, change.at * length + w / 2
    if lo <= 1e-9 * length or hi >= length * (1 - 1e-9):
        raise ChangeRefused(f"{change.describe()} does not fit edge {k} ({length:.4g} mm long)")
    t = (q - p) / length
    normal = np.array([t[1], -t[0]]) * outward  # right of a counter-clockwise edge is outside
    a, b = p + t * lo, p + t * hi
    new = np.vstack([xy[:k + 1], a, a + normal * h, b + normal * h, b, xy[k + 1:]])
    return new, [k + 1, k + 2, k + 3]


def _check_polygon(new: np.ndarray, holes, change: OutlineChange) -> None:
    """A simple polygon of positive area that still holds every hole strictly inside."""
    from pipeline.parts.part import PolygonError, check_holes, check_outline
    try:
        check_outline(new)
        check_holes(new, holes)
    except PolygonError as exc:
        raise ChangeRefused(f"{change.describe()} gives an invalid outline: {exc}") from None
    if not signed_area(new) > 0:
        raise ChangeRefused(f"{change.describe()} gives an outline without area")


def _check_walls(new: np.ndarray, fresh: list, min_wall: float, change: OutlineChange) -> None:
    """Each new edge has at least ``min_wall`` of material behind it (along its inward normal)."""
    if min_wall <= 0:
        return
    for e in fresh:
        wall = wall_behind(new, e)
        if wall < min_wall:
            raise ChangeRefused(f"{change.describe()} leaves a wall of {wall:.3g} mm, under the minimum "
                                f"of {min_wall:g} mm")


def wall_behind(xy: np.ndarray, edge: int) -> float:
    """The thinnest material behind ``edge`` of a counter-clockwise outline: from
    points along it (:data:`WALL_SAMPLES`), the distance along its inward normal
    to the next edge of the outline."""
    n = len(xy)
    p, q = xy[edge], xy[(edge + 1) % n]
    t = (q - p) / np.linalg.norm(q - p)
    inward = np.array([-t[1], t[0]])
    starts = np.roll(xy, -1, axis=0) - xy
    thinnest = math.inf
    for f in WALL_SAMPLES:
        origin = p + (q - p) * f
        for j in range(n):
            if j == edge:
                continue
            hit = _ray_hit(origin, inward, xy[j], starts[j])
            if hit is not None:
                thinnest = min(thinnest, hit)
    return thinnest


def _ray_hit(origin, direction, start, along) -> float | None:
    """Distance along the ray ``origin + s * direction`` (s > 0) to the segment
    ``start + u * along`` (0 <= u <= 1), or None if it misses."""
    det = direction[0] * (-along[1]) + along[0] * direction[1]
    if abs(det) < 1e-12:
        return None
    d = start - origin
    s = (d[0] * (-along[1]) + along[0] * d[1]) / det
    u = (direction[0] * d[1] - direction[1] * d[0]) / det
    if s > 1e-9 and -1e-12 <= u <= 1 + 1e-12:
        return float(s)
    return None


def candidate_changes(xy: np.ndarray, a: float, grid: DesignGrid) -> list[OutlineChange]:
    """Every change of ``grid`` on every corner and edge of ``xy`` (concave corners
    left out: a chamfer cuts a convex corner), sizes in mm from ``a``."""
    n = len(xy)
    out = []
    if "chamfer" in grid.kinds:
        out += [OutlineChange("chamfer", k, (s * a, s * a)) for k in range(n) if is_convex_corner(xy, k)
                for s in grid.chamfer]
    for kind in ("notch", "tab"):
        if kind in grid.kinds:
            out += [OutlineChange(kind, k, (w * a, h * a), at) for k in range(n)
                    for w, h in getattr(grid, kind) for at in grid.positions]
    return out
