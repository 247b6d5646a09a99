"""Support distributions: where, and how hard, a part presses on the belt.

Every model of spec section 3 assumes uniform pressure over the part's area.
A real part rests on a few high points (a burr, a warp, a boss). A
:class:`Support` says which distribution a rollout uses:

``uniform``
    The spec's even pressure over the area (the default; the kernels' closed
    forms).
``points``
    K weighted points ``(x, y, w)`` in the part frame: the outline centred on
    its centroid, drawing axes, the part's length unit (``Part.vertices``'s
    frame). The belt's friction power is ``P = sum_k w_k |v(p_k)| / sum w``.
``rim``
    Pressure on the outline only: ``n`` points along the boundary, at the
    midpoints of equal pieces of it, each weighted by its length.
``tripod``
    Three vertices of the convex hull: the largest triangle that holds the
    centroid, weighted by statics (the centroid's barycentric coordinates,
    so that the centre of pressure is the centre of mass, as it must be for
    a rigid part at rest on three points).

``rim`` and ``tripod`` are point supports built here; the kernels know only
``uniform`` and ``points``. :func:`filled_support` fills the area with
points (equal sub-triangles of a triangulation): as they get finer, the
point support's rollouts converge to the uniform ones (a test).

Parts with holes: the belt presses on the material only, so every support
point must lie on the material: inside the outline (or on it) and not inside
a hole (a hole's rim is material; "on" is within ``INSIDE_TOL a``). A given
point in a hole is a one-line error naming the point and the hole. The
built supports follow: ``tripod`` takes outline hull vertices (material) and
its statics about the origin, which is the material's centroid (the centre
of mass; ``Part`` centres the material, not the outline); ``rim`` is the
outline's rim only, not the holes' (a warped or burred plate rests on its
outer edge, the part of it farthest from the centre of mass: a plate dished
enough to lift its middle off the belt touches with the outer rim, and a
hole's rim lies inside that, off the belt); :func:`filled_support`
triangulates the material, holes left out (:func:`material_triangles`).
A solid part's supports are the same, to the bit, as before holes.

A point support of a rigid part in equilibrium has its centre of pressure
(the weighted mean of its points) at the centre of mass; ``points`` takes
the weights as given and :attr:`Support.pressure_offset` says how far off
they are.
"""
from __future__ import annotations

import hashlib
import math
import re
from dataclasses import dataclass, field

import numpy as np

from pipeline.errors import PinfeedError

SUPPORT_KINDS = ("uniform", "points", "rim", "tripod")
MAX_SUPPORT_POINTS = 4096  # a point support's solve costs O(K) per evaluation
DEFAULT_RIM_POINTS = 64
INSIDE_TOL = 1e-9  # a point this far outside the material (units of a) is on its edge
MAX_CONFORM_ROUNDS = 60  # boundary splits that make a Delaunay triangulation hold the material's edges
_SYNTAX = ('give "uniform", "points:x0,y0,w0 x1,y1,w1 ..." (part frame: centroid at the '
           'origin; w defaults to 1), "rim", "rim:N" or "tripod"')


@dataclass(frozen=True, eq=False)
class Support:
    """A support distribution of one part.

    Attributes
    ----------
    kind : one of :data:`SUPPORT_KINDS`.
    points : ``(K, 2)`` support points in the part frame (the part's length
        unit); empty for ``uniform``.
    weights : ``(K,)`` positive weights summing to 1; empty for ``uniform``.
    label : the text it was given as (``"rim:64"``, ...), for outputs.

    Two supports are equal (and hash alike) when their kind, points and
    weights are; the label is for display only.
    """

    kind: str
    points: np.ndarray = field(repr=False, default_factory=lambda: np.zeros((0, 2)))
    weights: np.ndarray = field(repr=False, default_factory=lambda: np.zeros(0))
    label: str = "uniform"

    @property
    def is_uniform(self) -> bool:
        """True for the spec's even pressure (the kernels' closed forms)."""
        return self.kind == "uniform"

    @property
    def n_points(self) -> int:
        """Number of support points (0 for uniform)."""
        return int(self.points.shape[0])

    @property
    def pressure_offset(self) -> float:
        """Distance from the centroid to the centre of pressure (0 for uniform)."""
        if self.is_uniform:
            return 0.0
        return float(np.hypot(*(self.weights @ self.points)))

    def __eq__(self, other) -> bool:
        return (isinstance(other, Support) and self.kind == other.kind
                and np.array_equal(self.points, other.points)
                and np.array_equal(self.weights, other.weights))

    def __hash__(self) -> int:
        return hash((self.kind, self.points.tobytes(), self.weights.tobytes()))

    def to_dict(self) -> dict:
        """Kind, label, points and weights as a JSON-ready dict."""
        return {"kind": self.kind, "label": self.label, "points": self.points.tolist(),
                "weights": self.weights.tolist()}


UNIFORM = Support("uniform")


def boundary_distance(verts: np.ndarray, xy: np.ndarray) -> np.ndarray:
    """Distance from each point of ``xy`` to the closed polyline ``verts``."""
    p = verts[None, :, :]
    e = np.roll(verts, -1, axis=0)[None, :, :] - p
    rel = xy[:, None, :] - p
    t = np.clip(np.sum(rel * e, axis=2) / np.sum(e * e, axis=2), 0.0, 1.0)
    gap = rel - t[:, :, None] * e
    return np.min(np.hypot(gap[..., 0], gap[..., 1]), axis=1)


def inside_outline(verts: np.ndarray, xy: np.ndarray) -> np.ndarray:
    """Even-odd rule: whether each point of ``xy`` is inside the polygon ``verts``."""
    x0, y0 = verts[:, 0][None, :], verts[:, 1][None, :]
    x1, y1 = np.roll(verts[:, 0], -1)[None, :], np.roll(verts[:, 1], -1)[None, :]
    px, py = xy[:, 0][:, None], xy[:, 1][:, None]
    crosses = (y0 > py) != (y1 > py)
    with np.errstate(divide="ignore", invalid="ignore"):
        xc = x0 + (py - y0) * (x1 - x0) / (y1 - y0)
    return np.sum(crosses & (px < xc), axis=1) % 2 == 1


def material_distance(part, xy: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(on, dist)`` for each point of ``xy`` (part frame): whether it is
    on the material (inside the outline and in no hole, even-odd) and its
    distance to the material's edge (the outline or a hole's rim, the
    nearest). A solid part gives ``inside_outline`` and ``boundary_distance``
    of the outline."""
    verts = np.asarray(part.vertices, dtype=np.float64)
    xy = np.asarray(xy, dtype=np.float64).reshape(-1, 2)
    on = inside_outline(verts, xy)
    dist = boundary_distance(verts, xy)
    for hole in getattr(part, "holes", ()):
        hole = np.asarray(hole, dtype=np.float64)
        on &= ~inside_outline(hole, xy)
        dist = np.minimum(dist, boundary_distance(hole, xy))
    return on, dist


def signed_material_distance(part, xy: np.ndarray) -> np.ndarray:
    """Distance of each point of ``xy`` to the material's edge, positive on
    the material, negative off it (outside the outline or in a hole)."""
    on, dist = material_distance(part, xy)
    return np.where(on, dist, -dist)


def _off_material(part, xy: np.ndarray):
    """The first point of ``xy`` off the material beyond ``INSIDE_TOL a`` as
    ``(k, hole, gap)`` (``hole`` 0 for outside the outline, else the hole's
    number from 1; ``gap`` how far off, mm), or ``None``."""
    verts = np.asarray(part.vertices, dtype=np.float64)
    tol = INSIDE_TOL * part.a
    where = np.where(~inside_outline(verts, xy) & (boundary_distance(verts, xy) > tol), 0, -1)
    for j, hole in enumerate(getattr(part, "holes", ()), start=1):
        hole = np.asarray(hole, dtype=np.float64)
        inside = inside_outline(hole, xy) & (boundary_distance(hole, xy) > tol)
        where = np.where((where < 0) & inside, j, where)
    bad = np.flatnonzero(where >= 0)
    if not bad.size:
        return None
    k = int(bad[0])
    loop = verts if where[k] == 0 else np.asarray(part.holes[where[k] - 1], dtype=np.float64)
    return k, int(where[k]), float(boundary_distance(loop, xy[k:k + 1])[0])


PRINT_DECIMALS = 3  # support points are printed in mm to this many decimals


def on_print_grid(part, xy: np.ndarray, decimals: int = PRINT_DECIMALS) -> np.ndarray:
    """``xy`` (part frame, mm) rounded as ``format_mm`` prints it, each point
    kept on the material, so that printed support text reads back.

    A fitted point on the material's edge may round to just outside it
    (0.3 um off a slanted edge), and the text would then be refused. Such a
    point takes the nearest corner of its rounding cell that is on the
    material, with more decimals where none is (a sharp corner's tip)."""
    xy = np.asarray(xy, dtype=np.float64).reshape(-1, 2)
    out = np.round(xy, decimals)
    for k in range(xy.shape[0]):
        if _off_material(part, out[k:k + 1]) is None:
            continue
        out[k] = xy[k]
        for dec in range(decimals, 10):
            step = 10.0 ** -dec
            lo, hi = np.floor(xy[k] / step) * step, np.ceil(xy[k] / step) * step
            corners = [np.round(np.array([x, y]), dec) for x in (lo[0], hi[0]) for y in (lo[1], hi[1])]
            corners.sort(key=lambda c: float(np.hypot(*(c - xy[k]))))
            good = [c for c in corners if _off_material(part, c[None]) is None]
            if good:
                out[k] = good[0]
                break
    return out


def format_mm(x: float) -> str:
    """A coordinate as support text prints it: 3 decimals, more only where
    ``on_print_grid`` needed them."""
    text = f"{x:.{PRINT_DECIMALS}f}"
    return text if float(text) == x else f"{x:.9f}".rstrip("0")


def point_support(part, points, weights=None, kind: str = "points",
                  label: str | None = None) -> Support:
    """A checked point support of ``part``.

    Parameters
    ----------
    part : the :class:`~pipeline.parts.part.Part`.
    points : ``(K, 2)`` points in the part frame (centroid at the origin,
        the part's length unit) on the material: inside the outline or on
        it, and not inside a hole (on a hole's rim is fine).
    weights : ``(K,)`` pressures >= 0, not all zero (default: all equal).
        They are normalised to sum 1; zero-weight points are dropped and
        points at the same place merged (the result lists the points sorted
        by x, then y).
    kind, label : recorded on the result.

    Raises
    ------
    PinfeedError
        One line naming the problem: no points, a point that is not finite,
        lies outside the outline or in a hole (naming the point and the
        hole), a negative weight, all weights zero, too many points.
    """
    xy = np.asarray(points, dtype=np.float64).reshape(-1, 2) if np.size(points) else np.zeros((0, 2))
    if xy.shape[0] == 0:
        raise PinfeedError(f"support {kind!r} has no points; {_SYNTAX}")
    if xy.shape[0] > MAX_SUPPORT_POINTS:
        raise PinfeedError(f"support {kind!r} has {xy.shape[0]} points, more than the limit of "
                           f"{MAX_SUPPORT_POINTS} (a rollout's time grows with the count)")
    w = np.ones(xy.shape[0]) if weights is None else np.asarray(weights, dtype=np.float64).ravel()
    if w.shape[0] != xy.shape[0]:
        raise PinfeedError(f"support {kind!r}: {xy.shape[0]} points but {w.shape[0]} weights")
    for k in range(xy.shape[0]):
        if not (np.all(np.isfinite(xy[k])) and math.isfinite(w[k])):
            raise PinfeedError(f"support point {k} ({xy[k, 0]:g}, {xy[k, 1]:g}, w={w[k]:g}) is "
                               f"not finite; {_SYNTAX}")
        if w[k] < 0:
            raise PinfeedError(f"support point {k} has weight {w[k]:g} < 0; weights are "
                               f"pressures: give numbers >= 0")
    if not np.any(w > 0):
        raise PinfeedError(f"support {kind!r}: every weight is zero; give at least one "
                           f"positive weight")
    off = _off_material(part, xy)
    if off is not None:
        k, hole, gap = off
        if hole == 0:
            raise PinfeedError(f"support point {k} ({xy[k, 0]:g}, {xy[k, 1]:g}) lies {gap:.3g} mm outside "
                               f"the outline; support points are in the part frame (centroid at the "
                               f"origin, drawing axes): move it inside")
        raise PinfeedError(f"support point {k} ({xy[k, 0]:g}, {xy[k, 1]:g}) lies in hole {hole} of the "
                           f"part ({gap:.3g} mm from its rim); give points on the material (part "
                           f"frame: the material's centroid at the origin)")
    keep = w > 0
    xy, w = xy[keep], w[keep]
    uniq, inverse = np.unique(xy, axis=0, return_inverse=True)
    merged = np.bincount(inverse.ravel(), weights=w, minlength=uniq.shape[0])
    merged = merged / merged.sum()
    uniq.setflags(write=False)
    merged.setflags(write=False)
    return Support(kind, uniq, merged, label or kind)


def rim_support(part, n: int = DEFAULT_RIM_POINTS) -> Support:
    """Pressure on the outline only: ``n`` equal pieces of the boundary, each a
    point at its midpoint weighted by its length (``rim:n``).

    A part with holes: the outline's rim only, the holes' rims left out (a
    plate warped or burred enough to rest on a rim rests on its outer one,
    the edge farthest from its centre of mass; see the module docstring).
    The centre of pressure is then the outline's perimeter centroid, which
    need not be the material's centroid: :attr:`Support.pressure_offset`
    says how far (as for any ``rim`` of an outline without symmetry)."""
    if not (isinstance(n, (int, np.integer)) and 3 <= n <= MAX_SUPPORT_POINTS):
        raise PinfeedError(f"rim support needs 3 to {MAX_SUPPORT_POINTS} points, got {n!r}")
    verts = np.asarray(part.vertices, dtype=np.float64)
    edges = np.roll(verts, -1, axis=0) - verts
    lengths = np.hypot(edges[:, 0], edges[:, 1])
    cum = np.concatenate([[0.0], np.cumsum(lengths)])
    s = (np.arange(n) + 0.5) * cum[-1] / n
    j = np.clip(np.searchsorted(cum, s, side="right") - 1, 0, len(verts) - 1)
    t = (s - cum[j]) / lengths[j]
    pts = verts[j] + t[:, None] * edges[j]
    return point_support(part, pts, np.full(n, cum[-1] / n), kind="rim", label=f"rim:{n}")


def _hull(verts: np.ndarray) -> np.ndarray:
    """Indices of the convex hull's vertices, counter-clockwise (monotone chain)."""
    order = sorted(range(len(verts)), key=lambda k: (verts[k, 0], verts[k, 1]))

    def half(idx):
        out = []
        for k in idx:
            while len(out) >= 2:
                o, a = verts[out[-2]], verts[out[-1]]
                b = verts[k]
                if (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0]) > 0:
                    break
                out.pop()
            out.append(k)
        return out

    lower, upper = half(order), half(order[::-1])
    return np.array(lower[:-1] + upper[:-1])


def tripod_support(part) -> Support:
    """Three convex-hull vertices: the largest triangle that holds the centroid,
    weighted by the centroid's barycentric coordinates (statics).

    The hull is the outline's (its vertices are on the material, holes or
    not); the centroid is the part frame's origin, the material's centroid
    (``Part`` centres the outline minus the holes), which lies in the hull."""
    verts = np.asarray(part.vertices, dtype=np.float64)
    hull = verts[_hull(verts)]
    best, best_area = None, 0.0
    n = len(hull)
    for i in range(n):
        for j in range(i + 1, n):
            for k in range(j + 1, n):
                a, b, c = hull[i], hull[j], hull[k]
                area = 0.5 * ((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]))
                lam = barycentric(a, b, c)
                if area > best_area and np.all(lam >= 0):
                    best, best_area = (np.array([a, b, c]), lam), area
    if best is None:  # pragma: no cover - the centroid lies in some hull triangle
        raise PinfeedError("no three hull vertices hold the centroid; give support points")
    return point_support(part, best[0], best[1], kind="tripod", label="tripod")


def barycentric(a, b, c) -> np.ndarray:
    """Barycentric coordinates of the origin in the triangle ``a, b, c``."""
    m = np.array([[a[0], b[0], c[0]], [a[1], b[1], c[1]], [1.0, 1.0, 1.0]])
    return np.linalg.solve(m, np.array([0.0, 0.0, 1.0]))


def _ears(verts: np.ndarray) -> list:
    """Triangles ``(i, j, k)`` of an ear-clipping triangulation of the
    counter-clockwise simple polygon ``verts``."""
    idx = list(range(len(verts)))
    tris = []

    def cross(o, a, b):
        return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])

    while len(idx) > 3:
        for m in range(len(idx)):
            i, j, k = idx[m - 1], idx[m], idx[(m + 1) % len(idx)]
            a, b, c = verts[i], verts[j], verts[k]
            if cross(a, b, c) <= 0:
                continue
            others = [verts[q] for q in idx if q not in (i, j, k)]
            if any(cross(a, b, p) >= 0 and cross(b, c, p) >= 0 and cross(c, a, p) >= 0
                   for p in others):
                continue
            tris.append((i, j, k))
            idx.pop(m)
            break
        else:  # pragma: no cover - a simple polygon always has an ear
            raise PinfeedError("could not triangulate the outline")
    tris.append(tuple(idx))
    return tris


def material_triangles(part) -> np.ndarray:
    """``(T, 3, 2)`` triangles that tile the material, counter-clockwise.

    A solid part: the ear-clipping triangulation of its outline. A part with
    holes: a Delaunay triangulation (``scipy.spatial.Delaunay``, which has
    no constrained form; nor has ``matplotlib.tri``) of the loops' vertices,
    made to conform to the material's edges by splitting each outline or hole
    edge that is not a union of triangle edges at its midpoint and
    triangulating again (at most ``MAX_CONFORM_ROUNDS`` rounds); then every
    triangle lies wholly on the material or wholly off it, and those whose
    centroid is on the material are kept. Their areas are checked to sum to
    ``Part.area``.
    """
    verts = np.asarray(part.vertices, dtype=np.float64)
    if not getattr(part, "holes", ()):
        return np.array([[verts[i], verts[j], verts[k]] for i, j, k in _ears(verts)])
    from scipy.spatial import Delaunay

    loops = [verts] + [np.asarray(h, dtype=np.float64) for h in part.holes]
    for _ in range(MAX_CONFORM_ROUNDS):
        pts = np.vstack(loops)
        tri = Delaunay(pts)
        simp = np.sort(tri.simplices, axis=1)
        edges = set(map(tuple, np.vstack([simp[:, [0, 1]], simp[:, [1, 2]], simp[:, [0, 2]]]).tolist()))
        split, start = [], 0
        for loop in loops:
            m = len(loop)
            i = np.arange(m) + start
            j = np.roll(i, -1)
            present = np.array([(min(p, q), max(p, q)) in edges for p, q in zip(i.tolist(), j.tolist())])
            split.append(~present)
            start += m
        if not any(s.any() for s in split) and len(tri.coplanar) == 0:
            break
        for k, (loop, miss) in enumerate(zip(loops, split)):
            mid = 0.5 * (loop + np.roll(loop, -1, axis=0))
            rows = np.empty((len(loop) + int(miss.sum()), 2))
            at = np.arange(len(loop)) + np.concatenate([[0], np.cumsum(miss)[:-1]])
            rows[at] = loop
            rows[at[miss] + 1] = mid[miss]
            loops[k] = rows
    else:
        raise PinfeedError(f"could not triangulate the material of part {part.name!r} "
                           f"({MAX_CONFORM_ROUNDS} rounds of edge splits)")
    corners = pts[tri.simplices]
    cross = ((corners[:, 1, 0] - corners[:, 0, 0]) * (corners[:, 2, 1] - corners[:, 0, 1])
             - (corners[:, 1, 1] - corners[:, 0, 1]) * (corners[:, 2, 0] - corners[:, 0, 0]))
    corners = np.where((cross < 0)[:, None, None], corners[:, ::-1], corners)
    on, _ = material_distance(part, corners.mean(axis=1))
    out = corners[on & (np.abs(cross) > 0)]
    area = 0.5 * np.abs(cross[on & (np.abs(cross) > 0)]).sum()
    if not abs(area - part.area) <= 1e-9 * part.area:  # pragma: no cover - conforming means exact
        raise PinfeedError(f"the triangulation of part {part.name!r} covers {area:.6g} mm^2 of its "
                           f"{part.area:.6g} mm^2 of material")
    return out


def filled_support(part, n: int) -> Support:
    """Points filling the material: each triangle of a triangulation
    (:func:`material_triangles`: holes left out) cut into ``n^2`` equal
    sub-triangles, one point at each sub-triangle's centroid weighted by its
    area (the midpoint rule: the point support's integrals approach the
    uniform ones as ``n`` grows)."""
    pts, wts = [], []
    for a, b, c in material_triangles(part):
        area = 0.5 * abs((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]))
        u, v = (b - a) / n, (c - a) / n
        for p in range(n):
            for q in range(n - p):
                pts.append(a + (p + 1 / 3) * u + (q + 1 / 3) * v)  # upright
                if p + q < n - 1:
                    pts.append(a + (p + 2 / 3) * u + (q + 2 / 3) * v)  # upside down
        wts.extend([area / (n * n)] * (n * n))
    return point_support(part, np.array(pts), np.array(wts), label=f"filled:{n}")


def support_key(support: str) -> str:
    """A support's name in a file name: ``tripod``, ``rim-64``, or for explicit
    points ``points-`` and the first 10 hex digits of the SHA-256 of its text;
    empty for uniform."""
    text = " ".join(str(support).split())
    if text in ("", "uniform"):
        return ""
    if text.startswith("points"):
        return "points-" + hashlib.sha256(text.encode()).hexdigest()[:10]
    return re.sub(r"[^A-Za-z0-9]+", "-", text).strip("-")


def parse_support(text: str | None, part) -> Support:
    """Parse the CLI's ``--support`` for ``part``: ``uniform``,
    ``points:"x0,y0,w0 x1,y1,w1 ..."`` (weight optional, default 1; the part
    frame), ``rim``, ``rim:N`` or ``tripod``."""
    if text is None or text.strip() in ("", "uniform"):
        return UNIFORM
    kind, _, rest = text.strip().partition(":")
    kind = kind.strip()
    if kind == "tripod" and not rest.strip():
        return tripod_support(part)
    if kind == "rim":
        try:
            n = int(rest) if rest.strip() else DEFAULT_RIM_POINTS
        except ValueError:
            raise PinfeedError(f"support {text!r}: N in rim:N must be a whole number") from None
        return rim_support(part, n)
    if kind != "points":
        raise PinfeedError(f"unknown support {text!r}; {_SYNTAX}")
    rows = []
    for token in rest.replace(";", " ").split():
        vals = token.split(",")
        try:
            nums = [float(x) for x in vals]
        except ValueError:
            nums = []
        if len(nums) not in (2, 3):
            raise PinfeedError(f"support point {token!r} is not 'x,y' or 'x,y,w'; {_SYNTAX}")
        rows.append(nums + [1.0] * (3 - len(nums)))
    arr = np.array(rows, dtype=np.float64).reshape(-1, 3)
    return point_support(part, arr[:, :2], arr[:, 2], label=text.strip())
