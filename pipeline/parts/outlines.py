"""Part outlines from CAD files: DXF (ezdxf) and SVG (svgelements).

A drawing may hold loose LINE/ARC pieces in any order and direction,
polylines with bulges, circles, ellipses, splines, paths, polygons and rects.
Every curve is flattened to a polygon whose chords stay within a chordal
tolerance of the curve: ``flatten_tol`` mm when given, else 0.05 mm or a
fixed fraction (:data:`FLATTEN_FRACTION`) of the drawing's diagonal, whichever
is larger, so that a large drawing (or one in the wrong units) still gets a
modest vertex count; duplicate pieces are dropped; pieces whose
ends lie within ``join_tol`` (drawing units; default 1e-4 of the drawing's
size) are joined end to end into closed loops. The largest closed loop is the
part (or the loop picked by ``layer`` / ``id``); the loops and open chains
left out are reported. A loop inside the outline is a hole: refused, because
no pressure acts under a hole, which moves the centroid and changes the
support integrals (spec section 2) that the kernels compute for a solid
polygon.

Units are said out loud (:meth:`Outline.describe`): a DXF's ``$INSUNITS``
(unitless: mm), an SVG's width/height over its viewBox (no physical size: CSS
pixels, 96 per inch), or ``units`` given by the user. Conversion factors are
exact (25.4 mm per inch), so one shape gives one part id from DXF and SVG.
SVG's y axis points down; it is flipped so the part looks as it does in the
viewer (a mirrored part would be a different part).
"""
from __future__ import annotations

import math
import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from pipeline.errors import PinfeedError
from pipeline.parts.part import PolygonError, check_outline

DEFAULT_FLATTEN_TOL = 0.05  # mm: the default chordal tolerance of a drawing up to 100 mm across
FLATTEN_FRACTION = 5e-4  # of the drawing's diagonal: the default chordal tolerance of a larger one
JOIN_TOL_FRACTION = 1e-4  # default join tolerance, as a fraction of the drawing's size
# Exact millimetres per unit: the same shape must hash to the same part id
# whichever file it came from (ezdxf's inch factor is 25.4000000001,
# svgelements' mm is 1.00000054 of the CSS one).
MM_PER_UNIT = {"mm": 1.0, "cm": 10.0, "m": 1000.0, "in": 25.4}
_SVG_MM = dict(MM_PER_UNIT, pt=25.4 / 72, pc=25.4 / 6, px=25.4 / 96, q=0.25)
_DXF_UNITS = {1: "in", 2: "ft", 4: "mm", 5: "cm", 6: "m", 9: "mil", 10: "yd", 13: "um", 14: "dm"}
_DXF_MM = dict(MM_PER_UNIT, ft=304.8, mil=0.0254, yd=914.4, um=1e-3, dm=100.0)
SIZE_WARN_MM = (2.0, 2000.0)  # a part outside this many mm across gets a units warning


class OutlineError(PinfeedError):
    """The CAD file does not give one closed, simple outline without holes."""


@dataclass
class Units:
    """How drawing coordinates became millimetres."""

    name: str  # e.g. "mm", "in", "px"
    source: str  # e.g. "$INSUNITS=1", "SVG width/viewBox", "default (unitless DXF)", "--units"
    scale: float  # mm per drawing unit


@dataclass
class Outline:
    """A part outline read from a CAD file (vertices in mm, drawing frame, y up)."""

    vertices: np.ndarray
    source: str  # the file
    name: str  # which loop: layer/handle (DXF) or element id (SVG)
    flatten_tol: float
    units: Units = field(default_factory=lambda: Units("mm", "default", 1.0))
    left_out: list = field(default_factory=list)  # loops and open chains not used, described

    @property
    def n_vertices(self) -> int:
        """Number of vertices after flattening."""
        return int(self.vertices.shape[0])

    @property
    def size_mm(self) -> tuple:
        """Bounding box width and height, and ``a`` (area centroid to farthest vertex), in mm."""
        w, h = np.ptp(self.vertices, axis=0)
        return float(w), float(h), float(np.max(np.hypot(*(self.vertices - _centroid(self.vertices)).T)))

    def describe(self) -> str:
        """One line: the loop, its vertex count, units (whence, scale) and size in mm."""
        w, h, a = self.size_mm
        u = self.units
        return (f"{self.source}: {self.name}, flattened to {self.n_vertices} vertices "
                f"(chordal tolerance {self.flatten_tol:g} mm); units {u.name} from {u.source}, "
                f"{u.scale:g} mm per unit; size {w:.4g} x {h:.4g} mm, a = {a:.4g} mm")

    def warnings(self) -> list[str]:
        """Lines worth a warning: loops left out, and a size that suggests wrong units."""
        out = [f"{self.source}: left out {item}" for item in self.left_out]
        across = max(self.size_mm[:2])
        if not SIZE_WARN_MM[0] <= across <= SIZE_WARN_MM[1]:
            out.append(f"{self.source}: the part is {across:.4g} mm across (units {self.units.name} from "
                       f"{self.units.source}); if the drawing is in other units, give --units mm|cm|m|in")
        return out


@dataclass
class _Piece:
    """A flattened, possibly open, polyline from one drawing entity (drawing units)."""

    points: np.ndarray  # (n, 2)
    name: str
    closed: bool


def read_outline(path, layer: str | None = None, id: str | None = None,  # noqa: A002 (CLI's --id)
                 flatten_tol: float | None = None, units: str | None = None,
                 join_tol: float | None = None) -> Outline:
    """The part outline in ``path`` (.dxf or .svg).

    Parameters
    ----------
    layer, id : pick the outline by DXF layer, or by SVG element id / DXF
        entity handle; otherwise the largest closed loop is the outline.
    flatten_tol : chordal tolerance for curves, mm (``None``: :data:`DEFAULT_FLATTEN_TOL`
        or :data:`FLATTEN_FRACTION` of the drawing's diagonal, whichever is larger,
        which keeps the vertex count of a large drawing modest).
    units : ``"mm"``, ``"cm"``, ``"m"`` or ``"in"``: overrides the file's units.
    join_tol : largest gap between piece ends that are joined, in drawing
        units (``None``: 1e-4 of the drawing's size).

    Raises
    ------
    OutlineError
        No closed loop, a hole, loops that cross, a self-intersection, or a
        file that cannot be read: one line naming the problem and the way out.
    """
    path = Path(path)
    _check_options(flatten_tol, units, join_tol)
    if not path.is_file():
        raise OutlineError(f"no outline file at {path}")
    suffix = path.suffix.lower()
    if suffix == ".dxf":
        pieces, unit, tol_mm = _dxf_pieces(path, layer, id, flatten_tol, units)
    elif suffix == ".svg":
        if layer is not None:
            raise OutlineError(f"{path}: --layer picks a DXF layer; pick an SVG element with --id")
        pieces, unit, tol_mm = _svg_pieces(path, id, flatten_tol, units)
    else:
        raise OutlineError(f"{path}: unknown outline format {suffix or '(none)'}; give a .dxf or .svg file")
    if not pieces:
        which = f" on layer {layer!r}" if layer else (f" with id {id!r}" if id else "")
        raise OutlineError(f"{path}: no lines, arcs, polylines or shapes{which}")
    tol = join_tol if join_tol is not None else JOIN_TOL_FRACTION * _extent(pieces)
    loops, chains = _join(_unique(pieces, tol), tol)
    loop, left_out = _choose(loops, chains, path, unit)
    try:
        xy = check_outline(loop.points * unit.scale)
    except PolygonError as exc:
        raise OutlineError(f"{path}: outline {loop.name}: {exc}") from None
    return Outline(vertices=xy, source=str(path), name=loop.name, flatten_tol=float(tol_mm),
                   units=unit, left_out=left_out)


def _check_options(flatten_tol, units, join_tol) -> None:
    def positive(x):
        return isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x) and x > 0
    if flatten_tol is not None and not positive(flatten_tol):
        raise OutlineError(f"--flatten-tol must be a length in mm > 0, got {flatten_tol!r}")
    if join_tol is not None and not positive(join_tol):
        raise OutlineError(f"--join-tol must be a length in drawing units > 0, got {join_tol!r}")
    if units is not None and units not in MM_PER_UNIT:
        raise OutlineError(f"--units must be one of {', '.join(MM_PER_UNIT)}, got {units!r}")


def _chordal_tolerance(flatten_tol, diagonal: float, scale: float) -> float:
    """The chordal tolerance in drawing units: ``flatten_tol`` mm when given, else
    :data:`DEFAULT_FLATTEN_TOL` mm or :data:`FLATTEN_FRACTION` of the drawing's
    ``diagonal`` (drawing units), whichever is larger; ``scale`` is mm per drawing unit."""
    if flatten_tol is not None:
        return flatten_tol / scale
    relative = FLATTEN_FRACTION * diagonal if math.isfinite(diagonal) else 0.0
    return max(DEFAULT_FLATTEN_TOL / scale, relative)


def _extent(pieces) -> float:
    allpts = np.vstack([p.points for p in pieces])
    return float(np.max(np.ptp(allpts, axis=0))) if len(allpts) else 0.0


# ---------------------------------------------------------------------- DXF


def _dxf_units(doc, override) -> Units:
    if override is not None:
        return Units(override, "--units", MM_PER_UNIT[override])
    code = int(doc.header.get("$INSUNITS", 0) or 0)
    if code == 0:
        return Units("mm", "the default (unitless DXF, $INSUNITS=0)", 1.0)
    name = _DXF_UNITS.get(code)
    if name is not None:
        return Units(name, f"$INSUNITS={code}", _DXF_MM[name])
    from ezdxf import units
    return Units(units.unit_name(code) or f"code {code}", f"$INSUNITS={code}",
                 units.conversion_factor(code, units.MM))


def _dxf_pieces(path: Path, layer, handle, flatten_tol, override) -> tuple[list[_Piece], Units, float]:
    """The flattened pieces of a DXF's chosen entities, their units and the chordal tolerance (mm)."""
    import ezdxf
    from ezdxf import path as ezpath
    try:
        doc = ezdxf.readfile(str(path))
    except (OSError, ezdxf.DXFStructureError, UnicodeDecodeError) as exc:
        raise OutlineError(f"{path} is not a readable DXF file: {exc}".splitlines()[0]) from None
    unit = _dxf_units(doc, override)
    kinds = {"LINE", "ARC", "CIRCLE", "ELLIPSE", "SPLINE", "LWPOLYLINE", "POLYLINE"}
    chosen = [(e, ezpath.make_path(e)) for e in _dxf_entities(doc.modelspace())
              if e.dxftype() in kinds and (layer is None or e.dxf.layer == layer)
              and (handle is None or e.dxf.handle.upper() == str(handle).upper())]
    box = ezpath.bbox([p for _, p in chosen], fast=True) if chosen else None
    diagonal = float(np.hypot(box.size.x, box.size.y)) if box is not None and box.has_data else 0.0
    tol = _chordal_tolerance(flatten_tol, diagonal, unit.scale)
    pieces = []
    for e, curve in chosen:
        # ezdxf flattens with a maximum chord-to-curve distance: the chordal tolerance.
        pts = np.array([(v.x, v.y) for v in curve.flattening(distance=tol)], dtype=float)
        if len(pts) < 2:
            continue
        kind = e.dxftype()
        closed = bool(getattr(e, "closed", False) or getattr(e, "is_closed", False)) or kind == "CIRCLE"
        pieces.append(_Piece(pts, f"{kind} {e.dxf.handle} on layer {e.dxf.layer}", closed))
    return pieces, unit, tol * unit.scale


def _dxf_entities(space):
    """The entities of a layout, with block references (INSERT) exploded in place."""
    for e in space:
        if e.dxftype() == "INSERT":
            yield from e.virtual_entities()
        else:
            yield e


# ---------------------------------------------------------------------- SVG


def _svg_length_mm(text) -> float | None:
    """An SVG width/height in mm, or None when it is missing, relative or unitless."""
    m = re.fullmatch(r"\s*([0-9.eE+-]+)\s*([a-zA-Z]*)\s*", str(text or ""))
    if not m or m.group(2).lower() not in _SVG_MM:
        return None
    try:
        return float(m.group(1)) * _SVG_MM[m.group(2).lower()]
    except ValueError:
        return None


def _svg_units(svg, override) -> tuple[Units, float]:
    """The units, and the factor from svgelements' pixels to drawing units.

    svgelements has already scaled user units by the viewBox and its own
    (inexact) unit factors; the factor undoes that so the drawing units are
    the viewBox's user units, which are then scaled exactly."""
    vb = svg.viewbox
    if vb is None or not vb.width or not vb.height:
        px_per_user, user_mm = 1.0, None  # user units are CSS pixels
    else:
        # preserveAspectRatio "meet" (the default): the smaller scale wins.
        px_per_user = min(svg.width / vb.width, svg.height / vb.height)
        w, h = _svg_length_mm(svg.values.get("width")), _svg_length_mm(svg.values.get("height"))
        sizes = [s for s in (w and w / vb.width, h and h / vb.height) if s]
        user_mm = min(sizes) if sizes else None
    if override is not None:
        return Units(override, "--units", MM_PER_UNIT[override]), 1.0 / px_per_user
    if user_mm is None:
        return Units("px", "SVG user units (no physical width over a viewBox: CSS pixels, 96 per inch)",
                     _SVG_MM["px"]), 1.0 / px_per_user
    name = next((n for n, f in MM_PER_UNIT.items() if math.isclose(f, user_mm, rel_tol=1e-12)),
                f"user units of {user_mm:g} mm")
    return Units(name, f"SVG width/viewBox ({svg.values.get('width')} over {vb.width:g} user units)",
                 user_mm), 1.0 / px_per_user


def _svg_pieces(path: Path, want_id, flatten_tol, override) -> tuple[list[_Piece], Units, float]:
    """The flattened pieces of an SVG's chosen shapes, their units and the chordal tolerance (mm)."""
    import svgelements as se
    try:
        svg = se.SVG.parse(str(path), ppi=96.0)  # transforms and viewBox applied
    except Exception as exc:  # svgelements raises many kinds on bad XML
        raise OutlineError(f"{path} is not a readable SVG file: {exc}".splitlines()[0]) from None
    unit, user_per_px = _svg_units(svg, override)
    flip = np.array([user_per_px, -user_per_px])
    chosen = []
    for k, el in enumerate(svg.elements()):
        if not isinstance(el, se.Shape) or isinstance(el, se.Group):
            continue
        eid = el.values.get("id") or el.id
        if want_id is not None and eid != want_id:
            continue
        label = f"<{type(el).__name__.lower()} id={eid!r}>" if eid else f"{type(el).__name__.lower()} #{k}"
        shape = se.Path(el)
        shape.reify()  # bake the transform into the coordinates
        chosen.append((label, shape))
    tol_px = _chordal_tolerance(flatten_tol, _svg_diagonal(s for _, s in chosen) * user_per_px,
                                unit.scale) / user_per_px
    pieces = []
    for label, shape in chosen:
        subs = [(sub, closed) for sub, closed in _subpaths(shape, tol_px) if len(sub) >= 2]
        for i, (sub, closed) in enumerate(subs, start=1):
            pts = np.array(sub, dtype=float) * flip
            pieces.append(_Piece(pts, label + (f" subpath {i}" if len(subs) > 1 else ""), closed))
    return pieces, unit, tol_px * user_per_px * unit.scale


def _svg_diagonal(shapes) -> float:
    """The diagonal of the shapes' joint bounding box (svgelements' pixels; 0 for none)."""
    boxes = [b for b in (shape.bbox() for shape in shapes) if b is not None]
    if not boxes:
        return 0.0
    lo = np.min([b[:2] for b in boxes], axis=0)
    hi = np.max([b[2:] for b in boxes], axis=0)
    return float(np.hypot(*(hi - lo)))


def _subpaths(shape, tol_px):
    """Flattened subpaths of an svgelements Path: [(points, closed)]."""
    import svgelements as se
    out, cur, closed = [], [], False
    for seg in shape.segments():
        if isinstance(seg, se.Move):
            if cur:
                out.append((cur, closed))
            cur, closed = [(seg.end.x, seg.end.y)], False
        elif isinstance(seg, se.Close):
            closed = True
        elif isinstance(seg, se.Line):
            cur.append((seg.end.x, seg.end.y))
        else:  # Arc, CubicBezier, QuadraticBezier: anything with point(t)
            cur.extend(_flatten_curve(lambda t, s=seg: s.point(t), tol_px)[1:])
    if cur:
        out.append((cur, closed))
    return out


def _flatten_curve(point, tol, t0=0.0, t1=1.0, depth=0):
    """Points at parameters along ``point(t)`` so that each chord stays within
    ``tol`` of the curve (checked at the chord's quarter points)."""
    a, b = np.array(point(t0), float), np.array(point(t1), float)
    worst = max(_dist_to_segment(np.array(point(t0 + f * (t1 - t0)), float), a, b) for f in (0.25, 0.5, 0.75))
    if worst <= tol or depth >= 18:
        return [tuple(a), tuple(b)]
    tm = 0.5 * (t0 + t1)
    left = _flatten_curve(point, tol, t0, tm, depth + 1)
    return left + _flatten_curve(point, tol, tm, t1, depth + 1)[1:]


def _dist_to_segment(p, a, b) -> float:
    ab = b - a
    L2 = float(ab @ ab)
    t = 0.0 if L2 == 0 else min(1.0, max(0.0, float((p - a) @ ab) / L2))
    return float(np.hypot(*(p - a - t * ab)))


# ---------------------------------------------------------------------- loops


def _dedupe(points: np.ndarray, tol: float) -> np.ndarray:
    """Drop consecutive repeated points and a closing copy of the first point."""
    keep = [points[0]]
    for p in points[1:]:
        if np.hypot(*(p - keep[-1])) > tol:
            keep.append(p)
    if len(keep) > 1 and np.hypot(*(keep[-1] - keep[0])) <= tol:
        keep.pop()
    return np.array(keep)


def _unique(pieces: list[_Piece], tol: float) -> list[_Piece]:
    """The pieces without duplicates (the same points, in either direction),
    which CAD exports repeat and which would otherwise branch the chains."""
    out = []
    for p in pieces:
        if not any(_same(p.points, q.points, tol) for q in out):
            out.append(p)
    return out


def _same(a: np.ndarray, b: np.ndarray, tol: float) -> bool:
    if a.shape != b.shape:
        return False
    return bool(np.all(np.hypot(*(a - b).T) <= tol) or np.all(np.hypot(*(a - b[::-1]).T) <= tol))


def _join(pieces: list[_Piece], tol: float) -> tuple[list[_Piece], list[_Piece]]:
    """Closed loops and open chains from the pieces: closed ones as they are,
    open ones chained end to end (either direction, any order) wherever an end
    lies within ``tol`` of another (the nearest one first)."""
    loops, open_ = [], []
    for p in pieces:
        gap = np.hypot(*(p.points[-1] - p.points[0]))
        if p.closed or (len(p.points) > 2 and gap <= tol):
            loops.append(_Piece(_dedupe(p.points, tol), p.name, True))
        elif np.max(np.ptp(p.points, axis=0)) > tol:  # a zero-length LINE joins nothing
            open_.append(p)
    chains = []
    while open_:
        first = open_.pop(0)
        pts, names = first.points, [first.name]
        pts = _grow(pts, names, open_, tol)
        if np.hypot(*(pts[-1] - pts[0])) > tol:  # a dead end: grow the start too
            pts = _grow(pts[::-1], names, open_, tol)[::-1]
        name = names[0] if len(names) == 1 else f"chain of {len(names)} pieces from {names[0]}"
        closed = np.hypot(*(pts[-1] - pts[0])) <= tol and len(pts) > 2
        (loops if closed else chains).append(_Piece(_dedupe(pts, tol) if closed else pts, name, closed))
    return loops, chains


def _grow(pts, names, open_, tol):
    """``pts`` extended at its end by the pieces of ``open_`` that chain on
    (taken out of ``open_``, their names appended to ``names``)."""
    while np.hypot(*(pts[-1] - pts[0])) > tol:
        k, reverse = _next_piece(open_, pts[-1], tol)
        if k is None:
            break
        piece = open_.pop(k)  # by index: pieces hold arrays, so list.remove would compare them
        more = piece.points[::-1] if reverse else piece.points
        pts = np.vstack([pts, more[1:]])
        names.append(piece.name)
    return pts


def _next_piece(candidates, end, tol):
    """Index of the candidate with an end nearest ``end`` (within ``tol``), and
    whether it runs backwards; ``(None, False)`` when none is that near."""
    if not candidates:
        return None, False
    starts = np.array([c.points[0] for c in candidates])
    ends = np.array([c.points[-1] for c in candidates])
    gaps = np.concatenate([np.hypot(*(starts - end).T), np.hypot(*(ends - end).T)])
    j = int(np.argmin(gaps))
    if gaps[j] > tol:
        return None, False
    return j % len(candidates), j >= len(candidates)


def _signed_area(xy) -> float:
    x, y = xy[:, 0], xy[:, 1]
    return 0.5 * float(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1)))


def _centroid(xy) -> np.ndarray:
    """Area centroid of a simple polygon (after centring, for precision)."""
    c0 = xy.mean(axis=0)
    x, y = (xy - c0).T
    xn, yn = np.roll(x, -1), np.roll(y, -1)
    cross = x * yn - xn * y
    area = 0.5 * cross.sum()
    return c0 + np.array([((x + xn) * cross).sum(), ((y + yn) * cross).sum()]) / (6.0 * area)


def _inside(pt, poly) -> bool:
    """Even-odd point in polygon."""
    x, y = pt
    xs, ys = poly[:, 0], poly[:, 1]
    xj, yj = np.roll(xs, 1), np.roll(ys, 1)
    crosses = ((ys > y) != (yj > y)) & (x < (xj - xs) * (y - ys) / np.where(yj == ys, 1e-300, yj - ys) + xs)
    return bool(np.count_nonzero(crosses) % 2)


def _diagonal(xy) -> float:
    return float(np.hypot(*np.ptp(xy, axis=0)))


def _choose(loops: list[_Piece], chains: list[_Piece], path: Path, unit: Units) -> tuple[_Piece, list]:
    """The largest closed loop and descriptions of what was left out; an error
    for holes, crossing loops, or an open chain that looks like the outline."""
    loops = sorted((lp for lp in loops if len(lp.points) >= 3),
                   key=lambda lp: -abs(_signed_area(lp.points)))
    chains = sorted(chains, key=lambda c: -_diagonal(c.points))
    # A lone straight line (a centre line, a dimension) is never an outline left open.
    could_be_outlines = [c for c in chains if len(c.points) > 2]
    if could_be_outlines and (not loops or _diagonal(could_be_outlines[0].points) > _diagonal(loops[0].points)):
        raise _open_error(could_be_outlines[0], path, unit)
    if chains and not loops:
        raise _open_error(chains[0], path, unit)
    if not loops:
        raise OutlineError(f"{path}: no closed outline with an area")
    outer = loops[0]
    inside = {id(lp): [_inside(pt, outer.points) for pt in lp.points] for lp in loops[1:]}
    crossing = [lp for lp in loops[1:] if any(inside[id(lp)]) and not all(inside[id(lp)])]
    if crossing:
        raise OutlineError(f"{path}: outlines {outer.name} and {crossing[0].name} cross each other; "
                           f"draw the part as one closed outline, or pick one with --layer/--id")
    holes = [lp for lp in loops[1:] if all(inside[id(lp)])]
    if holes:
        raise OutlineError(
            f"{path}: outline {outer.name} has {len(holes)} hole(s) ({', '.join(h.name for h in holes[:3])}"
            f"{' ...' if len(holes) > 3 else ''}); parts with holes are not supported (no pressure acts "
            f"under a hole, which moves the centroid and the support integrals): put the holes on another "
            f"layer and pick the outline with --layer, or delete them to plan the part as if solid")
    left = [f"closed loop {lp.name} (area {abs(_signed_area(lp.points)) * unit.scale ** 2:.4g} mm^2)"
            for lp in loops[1:]]
    left += [f"open chain {c.name} (ends {np.hypot(*(c.points[-1] - c.points[0])) * unit.scale:.4g} mm "
             f"apart)" for c in chains]
    return outer, left


def _open_error(chain: _Piece, path: Path, unit: Units) -> OutlineError:
    end = chain.points[-1] * unit.scale
    gap = np.hypot(*(chain.points[-1] - chain.points[0])) * unit.scale
    return OutlineError(
        f"{path}: open outline: {chain.name} ends at ({end[0]:.3f}, {end[1]:.3f}) mm, {gap:.3f} mm from "
        f"its start; close the outline in the drawing, raise --join-tol (drawing units) over the gaps, "
        f"or pick the outline with --layer/--id")
