"""Part outlines from CAD files: DXF (ezdxf) and SVG (svgelements).

A drawing may hold loose LINE/ARC pieces, polylines with bulges, circles,
paths, polygons and rects. Every curve is flattened to a polygon whose chords
stay within ``flatten_tol`` mm of the curve, pieces are joined end to end into
closed loops, and exactly one simple loop must remain: the part. Holes are
refused, because the support integrals (spec section 2) assume the pressure
spreads over a simple polygon.

Units: a DXF's ``$INSUNITS`` is honoured (unitless files are read as mm); an
SVG's document units are honoured through its width/height and viewBox (user
units without a physical size are CSS pixels, 96 per inch). SVG's y axis
points down; it is flipped so the part looks as it does in the viewer (a
mirrored part would be a different part).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from pipeline.errors import PinfeedError
from pipeline.parts.part import PolygonError, check_outline

DEFAULT_FLATTEN_TOL = 0.05  # mm
_JOIN_TOL = 1e-3  # mm: pieces whose ends are closer than this are joined


class OutlineError(PinfeedError):
    """The CAD file does not hold exactly one closed, simple outline."""


@dataclass
class Outline:
    """A part outline read from a CAD file (vertices in mm, drawing frame, y up)."""

    vertices: np.ndarray
    source: str  # the file
    name: str  # which loop: layer/handle (DXF) or element id (SVG)
    flatten_tol: float

    @property
    def n_vertices(self) -> int:
        """Number of vertices after flattening."""
        return int(self.vertices.shape[0])

    def describe(self) -> str:
        """One line saying where the outline came from and how it was flattened."""
        return (f"{self.source}: {self.name}, flattened to {self.n_vertices} vertices "
                f"(chordal tolerance {self.flatten_tol:g} mm)")


@dataclass
class _Piece:
    """A flattened, possibly open, polyline from one drawing entity."""

    points: np.ndarray  # (n, 2), mm
    name: str
    closed: bool


def read_outline(path, layer: str | None = None, id: str | None = None,  # noqa: A002 (CLI's --id)
                 flatten_tol: float = DEFAULT_FLATTEN_TOL) -> Outline:
    """The one closed outline in ``path`` (.dxf or .svg), optionally chosen by
    DXF ``layer`` or element ``id`` (SVG id, DXF entity handle)."""
    path = Path(path)
    if not (isinstance(flatten_tol, (int, float)) and math.isfinite(flatten_tol) and flatten_tol > 0):
        raise OutlineError(f"--flatten-tol must be a length in mm > 0, got {flatten_tol!r}")
    if not path.is_file():
        raise OutlineError(f"no outline file at {path}")
    suffix = path.suffix.lower()
    if suffix == ".dxf":
        pieces = _dxf_pieces(path, layer, id, flatten_tol)
    elif suffix == ".svg":
        if layer is not None:
            raise OutlineError(f"{path}: --layer picks a DXF layer; pick an SVG element with --id")
        pieces = _svg_pieces(path, id, flatten_tol)
    else:
        raise OutlineError(f"{path}: unknown outline format {suffix or '(none)'}; give a .dxf or .svg file")
    if not pieces:
        which = f" on layer {layer!r}" if layer else (f" with id {id!r}" if id else "")
        raise OutlineError(f"{path}: no lines, arcs, polylines or shapes{which}")
    loops = _join(pieces, path)
    loop = _choose(loops, path)
    try:
        xy = check_outline(loop.points)
    except PolygonError as exc:
        raise OutlineError(f"{path}: outline {loop.name}: {exc}") from None
    return Outline(vertices=xy, source=str(path), name=loop.name, flatten_tol=float(flatten_tol))


# ---------------------------------------------------------------------- DXF


def _dxf_pieces(path: Path, layer, handle, tol) -> list[_Piece]:
    import ezdxf
    from ezdxf import path as ezpath
    from ezdxf import units
    try:
        doc = ezdxf.readfile(str(path))
    except (OSError, ezdxf.DXFStructureError) as exc:
        raise OutlineError(f"{path} is not a readable DXF file: {exc}".splitlines()[0]) from None
    code = doc.header.get("$INSUNITS", 0)
    scale = units.conversion_factor(code, units.MM) if code else 1.0
    kinds = {"LINE", "ARC", "CIRCLE", "ELLIPSE", "SPLINE", "LWPOLYLINE", "POLYLINE"}
    pieces = []
    for e in _dxf_entities(doc.modelspace()):
        kind = e.dxftype()
        if kind not in kinds:
            continue
        if layer is not None and e.dxf.layer != layer:
            continue
        if handle is not None and e.dxf.handle.upper() != str(handle).upper():
            continue
        p = ezpath.make_path(e)
        # ezdxf flattens with a maximum chord-to-curve distance: the chordal tolerance.
        pts = np.array([(v.x, v.y) for v in p.flattening(distance=tol / scale)], dtype=float) * scale
        closed = bool(getattr(e, "closed", False) or getattr(e, "is_closed", False)) or kind == "CIRCLE"
        pieces.append(_Piece(pts, f"{kind} {e.dxf.handle} on layer {e.dxf.layer}", closed))
    return pieces


def _dxf_entities(space):
    """The entities of a layout, with block references (INSERT) exploded in place."""
    for e in space:
        if e.dxftype() == "INSERT":
            yield from e.virtual_entities()
        else:
            yield e


# ---------------------------------------------------------------------- SVG


def _svg_pieces(path: Path, want_id, tol) -> list[_Piece]:
    import svgelements as se
    try:
        svg = se.SVG.parse(str(path), ppi=96.0)  # transforms and viewBox applied
    except Exception as exc:  # svgelements raises many kinds on bad XML
        raise OutlineError(f"{path} is not a readable SVG file: {exc}".splitlines()[0]) from None
    mm_per_px = 25.4 / 96.0
    pieces = []
    for k, el in enumerate(svg.elements()):
        if not isinstance(el, se.Shape) or isinstance(el, se.Group):
            continue
        eid = el.values.get("id") or el.id
        if want_id is not None and eid != want_id:
            continue
        label = f"<{type(el).__name__.lower()} id={eid!r}>" if eid else f"{type(el).__name__.lower()} #{k}"
        shape = se.Path(el)
        shape.reify()  # bake the transform into the coordinates
        subs = [(sub, closed) for sub, closed in _subpaths(shape, tol / mm_per_px) if len(sub) >= 2]
        for i, (sub, closed) in enumerate(subs, start=1):
            pts = np.array(sub, dtype=float) * mm_per_px * np.array([1.0, -1.0])
            pieces.append(_Piece(pts, label + (f" subpath {i}" if len(subs) > 1 else ""), closed))
    return pieces


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


def _dedupe(points: np.ndarray) -> np.ndarray:
    """Drop consecutive repeated points and a closing copy of the first point."""
    keep = [points[0]]
    for p in points[1:]:
        if np.hypot(*(p - keep[-1])) > _JOIN_TOL:
            keep.append(p)
    if len(keep) > 1 and np.hypot(*(keep[-1] - keep[0])) <= _JOIN_TOL:
        keep.pop()
    return np.array(keep)


def _join(pieces: list[_Piece], path: Path) -> list[_Piece]:
    """Closed loops from the pieces: closed ones as they are, open ones chained
    end to end (either direction). An open chain left over is an error."""
    loops = []
    open_ = []
    for p in pieces:
        gap = np.hypot(*(p.points[-1] - p.points[0]))
        if p.closed or (len(p.points) > 2 and gap <= _JOIN_TOL):
            loops.append(_Piece(_dedupe(p.points), p.name, True))
        else:
            open_.append(p)
    while open_:
        chain = [open_.pop(0)]
        pts = chain[0].points
        while np.hypot(*(pts[-1] - pts[0])) > _JOIN_TOL:
            nxt = _next_piece(open_, pts[-1])
            if nxt is None:
                names = ", ".join(c.name for c in chain[:3]) + (" ..." if len(chain) > 3 else "")
                raise OutlineError(
                    f"{path}: open outline: the chain of {len(chain)} piece(s) ({names}) ends at "
                    f"({pts[-1][0]:.3f}, {pts[-1][1]:.3f}) mm, {np.hypot(*(pts[-1] - pts[0])):.3f} mm "
                    f"from its start; close the outline in the drawing")
            piece, reverse = nxt
            open_.remove(piece)
            more = piece.points[::-1] if reverse else piece.points
            pts = np.vstack([pts, more[1:]])
            chain.append(piece)
        name = chain[0].name if len(chain) == 1 else f"chain of {len(chain)} pieces from {chain[0].name}"
        loops.append(_Piece(_dedupe(pts), name, True))
    return loops


def _next_piece(candidates, end):
    for piece in candidates:
        if np.hypot(*(piece.points[0] - end)) <= _JOIN_TOL:
            return piece, False
        if np.hypot(*(piece.points[-1] - end)) <= _JOIN_TOL:
            return piece, True
    return None


def _signed_area(xy) -> float:
    x, y = xy[:, 0], xy[:, 1]
    return 0.5 * float(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1)))


def _inside(pt, poly) -> bool:
    """Even-odd point in polygon."""
    x, y = pt
    xs, ys = poly[:, 0], poly[:, 1]
    xj, yj = np.roll(xs, 1), np.roll(ys, 1)
    crosses = ((ys > y) != (yj > y)) & (x < (xj - xs) * (y - ys) / np.where(yj == ys, 1e-300, yj - ys) + xs)
    return bool(np.count_nonzero(crosses) % 2)


def _choose(loops: list[_Piece], path: Path) -> _Piece:
    """The single outline, or a clear error: holes, or several disjoint loops."""
    loops = [lp for lp in loops if len(lp.points) >= 3]
    if not loops:
        raise OutlineError(f"{path}: no closed outline with an area")
    if len(loops) == 1:
        return loops[0]
    loops.sort(key=lambda lp: -abs(_signed_area(lp.points)))
    outer = loops[0]
    inside = {id(lp): [_inside(pt, outer.points) for pt in lp.points] for lp in loops[1:]}
    crossing = [lp for lp in loops[1:] if any(inside[id(lp)]) and not all(inside[id(lp)])]
    if crossing:
        raise OutlineError(f"{path}: outlines {outer.name} and {crossing[0].name} cross each other; "
                           f"draw the part as one closed outline")
    holes = [lp for lp in loops[1:] if all(inside[id(lp)])]
    if holes:
        raise OutlineError(
            f"{path}: outline {outer.name} has {len(holes)} hole(s) ({', '.join(h.name for h in holes)}); "
            f"parts with holes are not supported (the support integrals assume a simple polygon): "
            f"remove the inner loops or pick another outline with --layer/--id")
    raise OutlineError(f"{path}: {len(loops)} disjoint outlines: {'; '.join(lp.name for lp in loops)}; "
                       f"choose one with --layer NAME (DXF) or --id ID (SVG id or DXF handle)")
