"""Part outlines from CAD files: DXF (ezdxf) and SVG (svgelements), with holes.

A drawing may hold loose LINE/ARC pieces in any order and direction,
polylines with bulges (LWPOLYLINE, or R12's POLYLINE), circles, ellipses,
splines, block references (INSERT, nested too), paths, polygons and rects.
Every curve is flattened to a polygon whose chords stay within a chordal
tolerance of the curve: ``flatten_tol`` mm when given, else 0.05 mm or a
fixed fraction (:data:`FLATTEN_FRACTION`) of the drawing's diagonal, whichever
is larger, so that a large drawing (or one in the wrong units) still gets a
modest vertex count; duplicate pieces are dropped; pieces whose ends lie
within ``join_tol`` (drawing units; default 1e-4 of the drawing's size) are
joined end to end into closed loops.

Layers (DXF layers; Inkscape layers of an SVG: groups with
``inkscape:groupmode="layer"``, named by their ``inkscape:label``). Pieces are
joined layer by layer: construction lines on another layer never become part
of an outline. ``layer`` restricts everything to one layer. Only when no layer
closes on its own are the pieces of several layers joined, and the outline
says which layers it joined. An entity of a block on layer 0 takes the layer
of its INSERT (CAD's rule). Pieces in a dashed linetype (CENTER, DASHED, ...;
an SVG's stroke-dasharray) or on a layer named for construction, centre lines
or dimensions are construction geometry: joined only among themselves, never
a hole or a part, and taken as drawn only when nothing else closes.

Parts. The closed loops nest: a loop inside no other is a part's outline; the
loops directly inside an outline are its holes (from any layer); a loop inside
a hole (a washer drawn in a bore, an island) is the outline of a part of its
own, and so on down. Parts are indexed by the area their outlines enclose,
largest first; outlines of equal area (to 6 significant digits) left to right,
then bottom to top (the lower left corner of their bounding box). A part is
labelled ``FILE#index`` (``lever.dxf#0``). :func:`read_sheet` (and
:func:`read_parts`) read them all; :func:`read_outline` reads the largest, or
the one ``id`` picks, and names the others in one line of ``left_out``, each
with the ``--id`` that picks it. ``id`` is a DXF entity handle (an INSERT's
handle for what its block holds) or an SVG element id of any piece of a part,
outline or hole, or the part's index (``FILE#N``, ``#N``, or ``N`` where no
piece has that id).

Holes. The belt presses on the material only, so the area, centroid and ``a``
are those of the outline minus its holes (:class:`pipeline.parts.part.Part`);
pins touch the outline only. Holes are checked by
:func:`pipeline.parts.part.check_holes`. Refused, in one line naming the loops
and the way out: loops that cross each other, and a hole touching the outline
(an opening to the outline is a notch: draw it as part of the outline); with
``id``, loops across the outline it picked are left out instead. Open chains
are left out and reported; one larger than every closed loop is refused as an
open outline.

Drawing frames. A sheet border is usually a drawing's largest loop, and is
left out (and said so) when it is an axis-aligned rectangle around all other
geometry and
- on a layer of its own, holds closed loops of other layers, and its layer is
  named as a frame (TITLE, BORDER, FRAME, SHEET, RAHMEN, ...) or holds TEXT
  outside the other layers' geometry (a title block): left out with its layer;
- or, drawn among the parts' pieces (same layer, or an SVG), touches no closed
  loop, is at least :data:`FRAME_AREA_RATIO` times the area of the box around
  what it holds, and has a title block (lines touching it that close a corner
  region of at most half its area) or a sheet's size (ISO A0-A5, ANSI A-E, to
  1 %): left out with the pieces touching it, and with an inner border (a
  rectangle around everything else, nothing touching the outer one).
A rectangular part with holes has no title block in a corner and is not a
sheet size, so it stays a part. ``id`` naming a loop inside a rectangle around
everything else that was not taken for a frame leaves that rectangle out.

Units are said out loud (:meth:`Outline.describe`): a DXF's ``$INSUNITS``
(unitless, as every R12 file: mm), an SVG's width/height over its viewBox (no
physical size: CSS pixels, 96 per inch; 90 per inch in a file of Inkscape
before 0.92, which its ``inkscape:version`` tells), or ``units`` given by the
user. Conversion factors are exact (25.4 mm per inch), so one shape gives one
part id from DXF and SVG. SVG's y axis points down; it is flipped so the part
looks as it does in the viewer (a mirrored part would be a different part).
"""
from __future__ import annotations

import math
import re
from collections import Counter
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from pipeline.errors import PinfeedError
from pipeline.parts.part import Part, PolygonError, check_holes, check_outline

DEFAULT_FLATTEN_TOL = 0.05  # mm: the default chordal tolerance of a drawing up to 100 mm across
FLATTEN_FRACTION = 5e-4  # of the drawing's diagonal: the default chordal tolerance of a larger one
JOIN_TOL_FRACTION = 1e-4  # default join tolerance, as a fraction of the drawing's size
# Exact millimetres per unit: the same shape must hash to the same part id
# whichever file it came from (ezdxf's inch factor is 25.4000000001,
# svgelements' mm is 1.00000054 of the CSS one).
MM_PER_UNIT = {"mm": 1.0, "cm": 10.0, "m": 1000.0, "in": 25.4}
_SVG_MM = dict(MM_PER_UNIT, pt=25.4 / 72, pc=25.4 / 6, px=25.4 / 96, q=0.25)
OLD_INKSCAPE_PX_PER_IN = 90.0  # Inkscape before 0.92 drew 90 pixels per inch, not CSS's 96
_DXF_UNITS = {1: "in", 2: "ft", 4: "mm", 5: "cm", 6: "m", 9: "mil", 10: "yd", 13: "um", 14: "dm"}
_DXF_MM = dict(MM_PER_UNIT, ft=304.8, mil=0.0254, yd=914.4, um=1e-3, dm=100.0)
SIZE_WARN_MM = (2.0, 2000.0)  # a part outside this many mm across gets a units warning
_DXF_CURVES = {"LINE", "ARC", "CIRCLE", "ELLIPSE", "SPLINE", "LWPOLYLINE", "POLYLINE"}
_DXF_TEXTS = {"TEXT", "MTEXT", "ATTRIB"}
# Layer names that mark a drawing frame (sheet border, title block).
FRAME_LAYER = re.compile(r"title|titel|border|frame|rahmen|sheet|blatt|schriftfeld|cartouche", re.I)
# Layer names that mark construction geometry, centre lines or dimensions.
CONSTRUCTION_LAYER = re.compile(r"constr|hilfs|center|centre|mittel|axis|achse|defpoints|dimension|^dims?$"
                                r"|^dims?[ _-]|bema(ss|ß)|hidden|verdeckt", re.I)
_SOLID_LINETYPES = {"", "CONTINUOUS", "BYLAYER", "BYBLOCK"}


class OutlineError(PinfeedError):
    """The CAD file does not give one closed, simple outline with valid holes."""


@dataclass
class Units:
    """How drawing coordinates became millimetres."""

    name: str  # e.g. "mm", "in", "px"
    source: str  # e.g. "$INSUNITS=1", "SVG width/viewBox", "default (unitless DXF)", "--units"
    scale: float  # mm per drawing unit


@dataclass
class Outline:
    """A part outline read from a CAD file (vertices in mm, drawing frame, y up),
    and its holes (each an ``(m, 2)`` array in mm, same frame)."""

    vertices: np.ndarray
    source: str  # the file
    name: str  # which loop: entity and layer (DXF) or element id (SVG)
    flatten_tol: float
    units: Units = field(default_factory=lambda: Units("mm", "default", 1.0))
    left_out: list = field(default_factory=list)  # loops and open chains not used, described
    holes: list = field(default_factory=list)  # (m, 2) float arrays, mm
    hole_names: list = field(default_factory=list)  # which loop each hole is
    hole_layers: list = field(default_factory=list)  # each hole's DXF layer (None: SVG, or several)
    layer: str | None = None  # the outline's DXF layer (None: SVG, or joined across layers)
    joined_layers: list = field(default_factory=list)  # the layers an outline joined across, if several
    hints: list = field(default_factory=list)  # further warnings (a frame taken for the part?)
    index: int = 0  # the part's index in its drawing (read_sheet's order)
    n_parts: int = 1  # how many parts the drawing holds
    _a: float | None = field(default=None, repr=False, compare=False)

    @property
    def label(self) -> str:
        """``"FILE#index"``: the part's name in its drawing (``--id`` takes it)."""
        return f"{Path(self.source).name}#{self.index}"

    @property
    def n_vertices(self) -> int:
        """Number of vertices of the outline after flattening (holes not counted)."""
        return int(self.vertices.shape[0])

    def part(self, name: str = "part") -> Part:
        """The part: the outline with its holes (``Part.from_vertices``)."""
        return Part.from_vertices(self.vertices, name=name, holes=self.holes)

    @property
    def a(self) -> float:
        """Distance from the material's centroid (outline minus holes) to the farthest vertex, mm."""
        if self._a is None:
            self._a = self.part().a
        return self._a

    @property
    def size_mm(self) -> tuple:
        """Bounding box width and height, and ``a`` (the material's area centroid
        to the farthest vertex of the outline), in mm."""
        w, h = np.ptp(self.vertices, axis=0)
        return float(w), float(h), float(self.a)

    def describe(self) -> str:
        """One line: the loop, its vertex count, units (whence, scale), size in
        mm, and, where there are any, the holes (how many, their vertices, the
        layers other than the outline's they came from) and the layers joined."""
        w, h, a = self.size_mm
        u = self.units
        line = (f"{self.source}: {self.name}, flattened to {self.n_vertices} vertices "
                f"(chordal tolerance {self.flatten_tol:g} mm); units {u.name} from {u.source}, "
                f"{u.scale:g} mm per unit; size {w:.4g} x {h:.4g} mm, a = {a:.4g} mm")
        if self.holes:
            k = len(self.holes)
            elsewhere = Counter(ly for ly in self.hole_layers if ly is not None and ly != self.layer)
            where = "".join(f"; {n} on layer {ly}" for ly, n in sorted(elsewhere.items()))
            line += (f", {k} hole{'s' if k != 1 else ''} "
                     f"({sum(len(hole) for hole in self.holes)} vertices{where})")
        if self.joined_layers:
            line += f"; joined across layers {', '.join(self.joined_layers)}"
        return line

    def warnings(self) -> list[str]:
        """Lines worth a warning: loops left out, an outline joined across layers,
        and a size that suggests wrong units."""
        out = [f"{self.source}: left out {item}" for item in self.left_out] + list(self.hints)
        if self.joined_layers:
            out.append(f"{self.source}: the outline joins pieces of layers {', '.join(self.joined_layers)} "
                       f"(no layer closes on its own); if some are construction lines, draw the outline "
                       f"closed on one layer and pick it with --layer NAME")
        across = max(self.size_mm[:2])
        if not SIZE_WARN_MM[0] <= across <= SIZE_WARN_MM[1]:
            out.append(f"{self.source}: the part is {across:.4g} mm across (units {self.units.name} from "
                       f"{self.units.source}); if the drawing is in other units, give --units mm|cm|m|in")
        return out


@dataclass
class _Piece:
    """A flattened, possibly open, polyline from one drawing entity, or joined
    from several (drawing units)."""

    points: np.ndarray  # (n, 2)
    name: str
    closed: bool
    layer: str | None = None  # DXF layer (None: SVG, or a chain across layers)
    pick: str | None = None  # what --id names: DXF handle (the top INSERT's in a block), SVG element id
    construction: str = ""  # why it is construction geometry ("linetype CENTER"), "" when not
    members: tuple = ()  # the drawn pieces a loop or chain was joined from
    svg: bool = False  # drawn in an SVG (ids are case-sensitive), not a DXF (handles are not)

    @property
    def parts(self) -> tuple:
        """The drawn pieces this one is made of."""
        return self.members or (self,)

    @property
    def layers(self) -> list:
        """The DXF layers of its drawn pieces, sorted."""
        return sorted({m.layer for m in self.parts if m.layer is not None})


@dataclass
class _Drawing:
    """What advice and messages need to know of the file read."""

    path: Path
    unit: Units
    svg: bool
    layers: list  # DXF layers of the pieces read (empty for SVG)
    id: str | None

    def option(self, loop: _Piece, other: _Piece | None = None) -> str:
        """The option that picks ``loop`` as the outline, as fits the file:
        ``--id`` for an SVG (element id) or a DXF on one layer (entity handle),
        ``--layer`` for a DXF of several layers (``--id`` still where ``other``
        is on the same layer, or --id is in use)."""
        if self.svg:
            return f"--id {loop.pick}" if loop.pick else "--id (give the element an id)"
        several = len(self.layers) > 1 and self.id is None
        if several and loop.layer is not None and (other is None or other.layer != loop.layer):
            return f"--layer {loop.layer}"
        return f"--id {loop.pick}"

    def pick(self, loop: _Piece | None, other: _Piece | None = None) -> str:
        """Advice: how to pick ``loop`` (None: an outline not known) as the outline."""
        if loop is None:
            if self.svg:
                return "pick the outline with --id ELEMENT_ID (give it an id in the SVG)"
            if len(self.layers) > 1 and self.id is None:
                return f"pick the outline's layer with --layer NAME (layers {', '.join(self.layers)})"
            return "pick the outline with --id HANDLE (an entity handle of it)"
        option = self.option(loop, other)
        if option.startswith("--layer"):
            return f"pick the outline's layer with {option}"
        return f"pick the outline with {option}"


def _the_part(pieces: list, texts: list, tol: float, drawing: _Drawing, id):  # noqa: A002
    """The drawing's parts and the index of the one :func:`read_outline`
    reads: the largest, or the one ``id`` picks (a loop inside a rectangle
    around everything else, a frame not recognised, is picked without it)."""
    sheet = _layout(pieces, texts, tol, drawing)
    if id is None:
        _check_open(sheet, pieces, tol, drawing)
        return sheet, 0
    k = _picked(sheet, pieces, tol, drawing)
    frame = sheet.parts[k][0]
    if not _named(drawing, frame.parts) and _is_box(frame.points, tol) and _around_all(frame, pieces, tol):
        sheet = _layout(pieces, texts, tol, drawing, drop=frame)
        k = _picked(sheet, pieces, tol, drawing)
    return sheet, k


def read_outline(path, layer: str | None = None, id: str | None = None,  # noqa: A002 (CLI's --id)
                 flatten_tol: float | None = None, units: str | None = None,
                 join_tol: float | None = None) -> Outline:
    """The part in ``path`` (.dxf or .svg): its outline, with its holes.

    A drawing may hold several parts (:func:`read_sheet` reads them all);
    this is the largest one, or the one ``id`` picks, and the others are
    named in one line of ``left_out`` (so in :meth:`Outline.warnings`), each
    with the ``--id`` that picks it. See the module docstring for the rules.

    Parameters
    ----------
    layer : read only this layer (DXF layer, or Inkscape layer of an SVG).
    id : the part holding this SVG element id or DXF entity handle (an
        INSERT's handle for the entities of its block) in its outline or a
        hole, or the part's index: ``"FILE#N"``, ``"#N"`` or ``"N"`` (a bare
        number that is also a piece's id or handle names the piece). Loops
        across the outline it picks are left out, not refused (the user chose).
    flatten_tol : chordal tolerance for curves, mm (``None``: :data:`DEFAULT_FLATTEN_TOL`
        or :data:`FLATTEN_FRACTION` of the drawing's diagonal, whichever is larger,
        which keeps the vertex count of a large drawing modest).
    units : ``"mm"``, ``"cm"``, ``"m"`` or ``"in"``: overrides the file's units.
    join_tol : largest gap between piece ends that are joined, in drawing
        units (``None``: 1e-4 of the drawing's size).

    Raises
    ------
    OutlineError
        No closed loop, loops that cross or touch, a self-intersection, too
        many vertices, or a file that cannot be read: one line naming the
        problem and the way out.
    """
    drawing, pieces, texts, tol, tol_mm = _read(path, layer, id, flatten_tol, units, join_tol)
    sheet, k = _the_part(pieces, texts, tol, drawing, id)
    outer, holes = sheet.parts[k]
    left, across = [], set()
    for a, b in sheet.conflicts.get(k, []):
        if id is None:
            raise OutlineError(
                f"{drawing.path}: outlines {a.name} and {b.name} cross each other or touch; a hole must lie "
                f"strictly inside the outline (an opening to the outline is a notch: draw it as part of the "
                f"outline), else draw the part as one closed outline, or {drawing.pick(a, b)}")
        left.append(f"closed loop {b.name} (area {_area(b) * drawing.unit.scale ** 2:.4g} mm^2; across the "
                    f"outline that --id {id} picked)")
        across.add(_key(b))
    left = sheet.notes + [_construction_note(lp, outer, drawing) for lp in sheet.construction] + left
    others = [j for j in range(len(sheet.parts)) if j != k and _key(sheet.parts[j][0]) not in across]
    if others:
        left.append(_others_note(sheet, others, drawing, outer))
    left += _chain_notes(sheet.chains, outer, pieces, tol, drawing)
    out = _outline(outer, holes, drawing, tol_mm, left, index=k, n_parts=len(sheet.parts))
    if id is None and holes and _is_box(outer.points, tol) and _around_all(outer, pieces, tol):
        out.hints.append(f"{drawing.path}: the part {outer.name} is a rectangle around everything else; if it is "
                         f"a drawing frame, pick the part inside it with --id (the id of a piece of it), and the "
                         f"frame is left out")
    return out


@dataclass
class Sheet:
    """All parts of a drawing (:func:`read_sheet`), in the order of their index."""

    source: str  # the file
    units: Units
    parts: list  # Outline, one per part; ``Outline.label`` is "FILE#index"
    left_out: list = field(default_factory=list)  # frame, construction loops, open chains: described
    refused: list = field(default_factory=list)  # (label, one-line reason) of parts that cannot be read

    def warnings(self) -> list[str]:
        """Lines worth a warning: what was left out, and the parts refused."""
        out = [f"{self.source}: left out {item}" for item in self.left_out]
        out += [f"{reason} (part {label} left out)" for label, reason in self.refused]
        return out


def read_sheet(path, layer: str | None = None, flatten_tol: float | None = None, units: str | None = None,
               join_tol: float | None = None, strict: bool = True) -> Sheet:
    """Every part in the drawing ``path`` (.dxf or .svg), each an :class:`Outline`
    with its holes, indexed by the stable rule of the module docstring (largest
    outline first; equal ones left to right, then bottom to top) and labelled
    ``"FILE#index"`` (``--id`` takes that label). A loop inside a hole is a part
    of its own (an island: a washer in a bore). Parameters as :func:`read_outline`;
    ``strict``: a part that cannot be read (loops that cross, a self-intersection,
    too many vertices) raises :class:`OutlineError`, else it is listed in
    ``refused`` with its one-line reason and the others are returned."""
    drawing, pieces, texts, tol, tol_mm = _read(path, layer, None, flatten_tol, units, join_tol)
    sheet = _layout(pieces, texts, tol, drawing)
    _check_open(sheet, pieces, tol, drawing)
    notes = sheet.notes + [_construction_note(lp, None, drawing) for lp in sheet.construction]
    notes += _chain_notes(sheet.chains, sheet.parts[0][0], pieces, tol, drawing)
    out = Sheet(str(drawing.path), drawing.unit, [], notes)
    for k, (outer, holes) in enumerate(sheet.parts):
        try:
            for a, b in sheet.conflicts.get(k, [])[:1]:
                raise OutlineError(
                    f"{drawing.path}: outlines {a.name} and {b.name} cross each other or touch; a hole must lie "
                    f"strictly inside the outline (an opening to the outline is a notch: draw it as part of "
                    f"the outline), else draw the part as one closed outline")
            out.parts.append(_outline(outer, holes, drawing, tol_mm, [], index=k, n_parts=len(sheet.parts)))
        except OutlineError as exc:
            if strict:
                raise
            out.refused.append((f"{drawing.path.name}#{k}", str(exc)))
    return out


def read_parts(path, layer: str | None = None, flatten_tol: float | None = None, units: str | None = None,
               join_tol: float | None = None) -> list[tuple[str, Outline]]:
    """``[(label, outline), ...]``: every part of the drawing, by index (:func:`read_sheet`,
    strict); ``outline.part(name)`` is the :class:`~pipeline.parts.part.Part`."""
    return [(o.label, o) for o in read_sheet(path, layer, flatten_tol, units, join_tol).parts]


def _key(piece) -> int:
    """Identity of a loop (pieces hold arrays: compare by object)."""
    return id(piece)


def _read(path, layer, id, flatten_tol, units, join_tol):  # noqa: A002
    """The drawing's pieces, read: ``(drawing, pieces, texts, join tolerance, chordal tolerance in mm)``."""
    path = Path(path)
    _check_options(flatten_tol, units, join_tol)
    if not path.is_file():
        raise OutlineError(f"no outline file at {path}")
    suffix = path.suffix.lower()
    pieces, unit, tol_mm, texts, layers = _pieces(path, suffix, layer, flatten_tol, units)
    if not pieces:
        if layer is not None:
            known = f"its layers: {', '.join(layers)}" if layers else "it has no layers"
            raise OutlineError(f"{path}: no lines, arcs, polylines or shapes on layer {layer!r}; "
                               f"give one of the drawing's layers ({known})")
        raise OutlineError(f"{path}: no lines, arcs, polylines or shapes; draw the part with lines, arcs, "
                           f"polylines, circles or splines (text, hatches, points and dimensions are not read)")
    drawing = _Drawing(path, unit, suffix == ".svg", sorted({p.layer for p in pieces if p.layer is not None}), id)
    tol = join_tol if join_tol is not None else JOIN_TOL_FRACTION * _extent(pieces)
    return drawing, pieces, texts, tol, tol_mm


def _outline(outer, holes, drawing, tol_mm, left, index=0, n_parts=1) -> Outline:
    xy, hole_xy = _checked(outer, holes, drawing, tol_mm)
    return Outline(vertices=xy, source=str(drawing.path), name=outer.name, flatten_tol=float(tol_mm),
                   units=drawing.unit, left_out=left, holes=hole_xy, hole_names=[h.name for h in holes],
                   hole_layers=[h.layer for h in holes], layer=outer.layer,
                   joined_layers=outer.layers if len(outer.layers) > 1 else [], index=index, n_parts=n_parts)


def _names_id(piece: _Piece, want) -> bool:
    """Whether ``--id want`` names this drawn piece (DXF handles in any case)."""
    if piece.pick is None:
        return False
    return piece.pick == str(want) or (not piece.svg and piece.pick.upper() == str(want).upper())


def _checked(outer: _Piece, holes: list, drawing: _Drawing, tol_mm: float):
    """The outline and holes in mm, checked as a part's (one-line errors naming the loops)."""
    path, scale = drawing.path, drawing.unit.scale
    try:
        xy = check_outline(outer.points * scale)
    except PolygonError as exc:
        raise OutlineError(f"{path}: outline {outer.name}: {_with_flatten_advice(exc, tol_mm)}") from None
    hole_xy = [h.points * scale for h in holes]
    try:
        hole_xy = check_holes(xy, hole_xy)
    except PolygonError as exc:
        text = str(exc)
        head, sep, tail = text.partition(";")
        head = re.sub(r"\bhole (\d+)", lambda m: f"hole {holes[int(m.group(1)) - 1].name}", head)
        head = head.replace("the outline", f"the outline {outer.name}")
        raise OutlineError(f"{path}: {head}{sep}{_with_flatten_advice(tail, tol_mm)}") from None
    try:
        Part.from_vertices(xy, holes=hole_xy)
    except PolygonError as exc:
        raise OutlineError(f"{path}: outline {outer.name}"
                           f"{f' and {len(holes)} holes' if holes else ''}: "
                           f"{_with_flatten_advice(exc, tol_mm)}") from None
    return xy, hole_xy


def _with_flatten_advice(exc, tol_mm: float) -> str:
    """The message, with the way out of a vertex count over the limit: a coarser flattening."""
    text = str(exc)
    if "more than the limit" in text:
        text += f", or raise --flatten-tol (now {tol_mm:g} mm)"
    return text


def _pieces(path: Path, suffix: str, layer, flatten_tol, units):
    """The drawing's flattened pieces, units, chordal tolerance (mm) and TEXT
    positions (DXF; none for SVG), by file format."""
    if suffix == ".dxf":
        return _dxf_pieces(path, layer, flatten_tol, units)
    if suffix == ".svg":
        pieces, unit, tol_mm, layers = _svg_pieces(path, flatten_tol, units)
        if layer is not None:
            if not layers:
                raise OutlineError(f"{path}: --layer picks a layer, and this SVG has none (an Inkscape layer is "
                                   f"a group with inkscape:groupmode=\"layer\"); pick an element with --id")
            pieces = [p for p in pieces if p.layer == layer]
        return pieces, unit, tol_mm, [], layers
    raise OutlineError(f"{path}: unknown outline format {suffix or '(none)'}; give a .dxf or .svg file")


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


def _dxf_pieces(path: Path, layer, flatten_tol, override):
    """The flattened pieces of a DXF's entities (on ``layer`` when given), their
    units, the chordal tolerance (mm), and the TEXT positions ``(x, y, layer)``."""
    import ezdxf
    from ezdxf import path as ezpath
    try:
        doc = ezdxf.readfile(str(path))
    except (OSError, ezdxf.DXFStructureError, UnicodeDecodeError) as exc:
        raise OutlineError(f"{path} is not a readable DXF file: {exc}".splitlines()[0]) from None
    unit = _dxf_units(doc, override)
    chosen, texts, layers = [], [], set()
    for e, where, on_layer, pick, linetype in _dxf_entities(doc):
        if e.dxftype() in _DXF_CURVES:
            layers.add(on_layer)
        if layer is not None and on_layer != layer:
            continue
        kind = e.dxftype()
        if kind in _DXF_TEXTS:
            at = e.dxf.get("insert")
            if at is not None:
                texts.append((float(at.x), float(at.y), on_layer))
        elif kind in _DXF_CURVES:
            chosen.append((e, ezpath.make_path(e), where, on_layer, pick, linetype))
    box = ezpath.bbox([c[1] for c in chosen], fast=True) if chosen else None
    diagonal = float(np.hypot(box.size.x, box.size.y)) if box is not None and box.has_data else 0.0
    tol = _chordal_tolerance(flatten_tol, diagonal, unit.scale)
    pieces = []
    for e, curve, where, on_layer, pick, linetype in chosen:
        kind = e.dxftype()
        # ezdxf flattens with a maximum chord-to-curve distance: the chordal tolerance. A SPLINE
        # from its own NURBS (a rational one, as CAD writes a circle, becomes hundreds of points
        # through the path's cubic curves).
        flat = e.construction_tool().flattening(tol, segments=4) if kind == "SPLINE" \
            else curve.flattening(distance=tol)
        pts = np.array([(v.x, v.y) for v in flat], dtype=float)
        if len(pts) < 2:
            continue
        closed = bool(getattr(e, "closed", False) or getattr(e, "is_closed", False)) or kind == "CIRCLE"
        pieces.append(_Piece(pts, f"{kind} {where} on layer {on_layer}", closed, layer=on_layer, pick=pick,
                             construction=_construction(on_layer, linetype)))
    return pieces, unit, tol * unit.scale, texts, sorted(layers)


def _dxf_entities(doc):
    """``(entity, where, layer, pick, linetype)`` for the modelspace's entities,
    block references (INSERT) exploded in place, nested ones too: ``where`` is
    the handle, or ``"in block B (INSERT 2F)"`` for a block's entity (which has
    none); ``layer`` the effective layer (an entity of a block on layer 0 takes
    its INSERT's); ``pick`` the handle ``--id`` names (the top INSERT's);
    ``linetype`` the effective linetype (BYLAYER and BYBLOCK resolved)."""
    for e in doc.modelspace():
        yield from _explode(e, doc, (), None, None, None)


def _explode(e, doc, blocks, parent_layer, pick, parent_linetype):
    own = e.dxf.get("layer", "0") or "0"
    layer = parent_layer if parent_layer is not None and own == "0" else own
    linetype = _linetype(e, layer, doc, parent_linetype)
    if not blocks:
        pick, where = str(e.dxf.handle), str(e.dxf.handle)
    else:
        where = "in " + " in ".join(f"block {b}" for b in reversed(blocks)) + f" (INSERT {pick})"
    if e.dxftype() != "INSERT":
        yield e, where, layer, pick, linetype
        return
    name = e.dxf.name
    for attrib in e.attribs:  # a title block's fields: only where they stand matters
        own_attrib = attrib.dxf.get("layer", "0") or "0"
        yield attrib, where, layer if own_attrib == "0" else own_attrib, pick, linetype
    if name in blocks:  # a block that holds itself: drawn once
        return
    for v in e.virtual_entities():
        yield from _explode(v, doc, blocks + (name,), layer, pick, linetype)


def _linetype(e, layer: str, doc, inherited) -> str:
    """The linetype an entity is drawn in: its own, its layer's (BYLAYER) or its INSERT's (BYBLOCK)."""
    lt = str(e.dxf.get("linetype", "BYLAYER") or "BYLAYER")
    if lt.upper() == "BYBLOCK":
        return inherited or "CONTINUOUS"
    if lt.upper() == "BYLAYER":
        return str(doc.layers.get(layer).dxf.linetype) if doc.layers.has_entry(layer) else "CONTINUOUS"
    return lt


def _construction(layer: str, linetype: str) -> str:
    """Why a piece is construction geometry (a dashed linetype, a layer named so), or ""."""
    if linetype.upper() not in _SOLID_LINETYPES:
        return f"linetype {linetype}"
    if CONSTRUCTION_LAYER.search(layer):
        return f"layer {layer}"
    return ""


# ---------------------------------------------------------------------- SVG


def _inkscape_version(svg) -> tuple[str, tuple[int, int]] | None:
    """The ``inkscape:version`` of the root element ("0.48.4 r9939": ("0.48", (0, 48))), or None."""
    text = svg.values.get("{http://www.inkscape.org/namespaces/inkscape}version") \
        or svg.values.get("inkscape:version")
    m = re.match(r"\s*(\d+)\.(\d+)", str(text or ""))
    return (f"{m.group(1)}.{m.group(2)}", (int(m.group(1)), int(m.group(2)))) if m else None


def _svg_length_mm(text, px_mm: float = _SVG_MM["px"]) -> float | None:
    """An SVG width/height in mm (a unitless one in pixels of ``px_mm``), or None
    when it is missing or relative."""
    m = re.fullmatch(r"\s*([0-9.eE+-]+)\s*([a-zA-Z]*)\s*", str(text or ""))
    if not m:
        return None
    unit = m.group(2).lower()
    factor = px_mm if unit in ("", "px") else _SVG_MM.get(unit)
    if factor is None:
        return None
    try:
        return float(m.group(1)) * factor
    except ValueError:
        return None


def _svg_units(svg, override) -> tuple[Units, float]:
    """The units, and the factor from svgelements' pixels to drawing units.

    svgelements has already scaled user units by the viewBox and its own
    (inexact) unit factors; the factor undoes that so the drawing units are
    the viewBox's user units, which are then scaled exactly. A pixel is 1/96
    inch (CSS), or 1/90 in a file of Inkscape before 0.92."""
    inkscape = _inkscape_version(svg)
    if inkscape is not None and inkscape[1] < (0, 92):
        px_mm, px_said = 25.4 / OLD_INKSCAPE_PX_PER_IN, f"Inkscape {inkscape[0]} file: 90 px per inch"
    else:
        px_mm, px_said = _SVG_MM["px"], "CSS pixels, 96 per inch"
    vb = svg.viewbox
    width, height = svg.values.get("width"), svg.values.get("height")
    if vb is None or not vb.width or not vb.height:
        px_per_user, user_mm = 1.0, None  # user units are pixels
    else:
        # preserveAspectRatio "meet" (the default): the smaller scale wins.
        px_per_user = min(svg.width / vb.width, svg.height / vb.height)
        w, h = _svg_length_mm(width, px_mm), _svg_length_mm(height, px_mm)
        sizes = [s for s in (w and w / vb.width, h and h / vb.height) if s]
        user_mm = min(sizes) if sizes else None
    if override is not None:
        return Units(override, "--units", MM_PER_UNIT[override]), 1.0 / px_per_user
    if user_mm is None:
        return Units("px", f"SVG user units ({px_said}; no physical width over a viewBox)", px_mm), \
            1.0 / px_per_user
    in_px = any(re.fullmatch(r"\s*[0-9.eE+-]+\s*(px)?\s*", str(t or ""), re.I) for t in (width, height))
    names = dict(MM_PER_UNIT, px=px_mm)
    name = next((n for n, f in names.items() if math.isclose(f, user_mm, rel_tol=1e-12)),
                f"user units of {user_mm:g} mm")
    return Units(name, f"SVG width/viewBox ({width} over {vb.width:g} user units"
                       f"{'; ' + px_said if in_px else ''})", user_mm), 1.0 / px_per_user


_INKSCAPE = "{http://www.inkscape.org/namespaces/inkscape}"


def _svg_layers(group, layer=None, out=None) -> dict:
    """``{id(element): layer label}``: the Inkscape layer (a group with
    ``inkscape:groupmode="layer"``, named by its ``inkscape:label``, else its id)
    each element lies in, the innermost one for a sublayer."""
    import svgelements as se
    out = {} if out is None else out
    for child in group:
        if not isinstance(child, se.SVGElement):
            continue
        here = layer
        if isinstance(child, se.Group):
            v = child.values
            if (v.get(_INKSCAPE + "groupmode") or v.get("inkscape:groupmode")) == "layer":
                here = str(v.get(_INKSCAPE + "label") or v.get("inkscape:label") or child.id or "layer")
            _svg_layers(child, here, out)
        if here is not None:
            out[id(child)] = here
    return out


def _svg_pieces(path: Path, flatten_tol, override) -> tuple[list[_Piece], Units, float, list]:
    """The flattened pieces of an SVG's shapes, their units, the chordal
    tolerance (mm) and the Inkscape layers' labels."""
    import svgelements as se
    try:
        svg = se.SVG.parse(str(path), ppi=96.0)  # transforms and viewBox applied
    except Exception as exc:  # svgelements raises many kinds on bad XML
        raise OutlineError(f"{path} is not a readable SVG file: {exc}".splitlines()[0]) from None
    unit, user_per_px = _svg_units(svg, override)
    flip = np.array([user_per_px, -user_per_px])
    layer_of = _svg_layers(svg)
    chosen = []
    for k, el in enumerate(svg.elements()):
        if not isinstance(el, se.Shape) or isinstance(el, se.Group):
            continue
        eid = el.values.get("id") or el.id
        label = f"<{type(el).__name__.lower()} id={eid!r}>" if eid else f"{type(el).__name__.lower()} #{k}"
        layer = layer_of.get(id(el))
        dashed = str(el.values.get("stroke-dasharray") or "none").strip().lower() not in ("none", "", "0")
        why = "dashed stroke" if dashed else (_construction(layer, "") if layer is not None else "")
        shape = se.Path(el)
        shape.reify()  # bake the transform into the coordinates
        named = layer is not None and len(set(layer_of.values())) > 1  # name the layer where there are several
        chosen.append((label + (f" on layer {layer}" if named else ""), eid, shape, layer, why))
    tol_px = _chordal_tolerance(flatten_tol, _svg_diagonal(c[2] for c in chosen) * user_per_px,
                                unit.scale) / user_per_px
    pieces = []
    for label, eid, shape, layer, why in chosen:
        subs = [(sub, closed) for sub, closed in _subpaths(shape, tol_px) if len(sub) >= 2]
        for i, (sub, closed) in enumerate(subs, start=1):
            pts = np.array(sub, dtype=float) * flip
            name = label if len(subs) == 1 else label.replace(" on layer ", f" subpath {i} on layer ", 1) \
                if " on layer " in label else label + f" subpath {i}"
            pieces.append(_Piece(pts, name, closed, layer=layer, pick=str(eid) if eid else None,
                                 construction=why, svg=True))
    return pieces, unit, tol_px * user_per_px * unit.scale, sorted(set(layer_of.values()))


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
    ends = (a[0, 0] - b[0, 0]) ** 2 + (a[0, 1] - b[0, 1]) ** 2
    back = (a[0, 0] - b[-1, 0]) ** 2 + (a[0, 1] - b[-1, 1]) ** 2
    if min(ends, back) > tol * tol:  # the first points differ: no need to compare the rest
        return False
    return bool(np.all(np.hypot(*(a - b).T) <= tol) or np.all(np.hypot(*(a - b[::-1]).T) <= tol))


def _joined(points, members: list, closed: bool) -> _Piece:
    """A loop or chain of the drawn pieces ``members``."""
    first = members[0]
    name = first.name if len(members) == 1 else f"chain of {len(members)} pieces from {first.name}"
    layers = {m.layer for m in members}
    return _Piece(points, name, closed, layer=first.layer if len(layers) == 1 else None, pick=first.pick,
                  construction=first.construction if all(m.construction for m in members) else "",
                  members=tuple(members), svg=first.svg)


def _join(pieces: list[_Piece], tol: float) -> tuple[list[_Piece], list[_Piece]]:
    """Closed loops and open chains from the pieces: closed ones as they are,
    open ones chained end to end (either direction, any order) wherever an end
    lies within ``tol`` of another (the nearest one first)."""
    loops, open_ = [], []
    for p in pieces:
        gap = np.hypot(*(p.points[-1] - p.points[0]))
        if p.closed or (len(p.points) > 2 and gap <= tol):
            loops.append(_joined(_dedupe(p.points, tol), [p], True))
        elif np.max(np.ptp(p.points, axis=0)) > tol:  # a zero-length LINE joins nothing
            open_.append(p)
    chains = []
    while open_:
        first = open_.pop(0)
        pts, members = first.points, [first]
        pts = _grow(pts, members, open_, tol)
        if np.hypot(*(pts[-1] - pts[0])) > tol:  # a dead end: grow the start too
            pts = _grow(pts[::-1], members, open_, tol)[::-1]
        closed = np.hypot(*(pts[-1] - pts[0])) <= tol and len(pts) > 2
        (loops if closed else chains).append(_joined(_dedupe(pts, tol) if closed else pts, members, closed))
    return loops, chains


def _grow(pts, members, open_, tol):
    """``pts`` extended at its end by the pieces of ``open_`` that chain on
    (taken out of ``open_``, appended to ``members``)."""
    while np.hypot(*(pts[-1] - pts[0])) > tol:
        k, reverse = _next_piece(open_, pts[-1], tol)
        if k is None:
            break
        piece = open_.pop(k)  # by index: pieces hold arrays, so list.remove would compare them
        more = piece.points[::-1] if reverse else piece.points
        pts = np.vstack([pts, more[1:]])
        members.append(piece)
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


def _area(piece: _Piece) -> float:
    return abs(_signed_area(piece.points))


def _inside(pt, poly) -> bool:
    """Even-odd point in polygon."""
    x, y = pt
    xs, ys = poly[:, 0], poly[:, 1]
    xj, yj = np.roll(xs, 1), np.roll(ys, 1)
    crosses = ((ys > y) != (yj > y)) & (x < (xj - xs) * (y - ys) / np.where(yj == ys, 1e-300, yj - ys) + xs)
    return bool(np.count_nonzero(crosses) % 2)


def _inside_all(points, poly) -> np.ndarray:
    """Whether each of ``points`` lies inside ``poly`` (even-odd; :func:`_inside`, for many points at once)."""
    points = np.asarray(points, float)
    xs, ys = poly[:, 0][None, :], poly[:, 1][None, :]
    xj, yj = np.roll(xs, 1, axis=1), np.roll(ys, 1, axis=1)
    dy = np.where(yj == ys, 1e-300, yj - ys)
    out = np.empty(len(points), bool)
    step = max(1, 2_000_000 // max(1, poly.shape[0]))
    for k in range(0, len(points), step):
        x, y = points[k:k + step, :1], points[k:k + step, 1:]
        crosses = ((ys > y) != (yj > y)) & (x < (xj - xs) * (y - ys) / dy + xs)
        out[k:k + step] = np.count_nonzero(crosses, axis=1) % 2 == 1
    return out


def _diagonal(xy) -> float:
    return float(np.hypot(*np.ptp(xy, axis=0)))


def _groups(pieces: list[_Piece]) -> dict:
    """The pieces by (layer, construction or not), in the order drawn."""
    out = {}
    for p in pieces:
        out.setdefault((p.layer, bool(p.construction)), []).append(p)
    return out


def _loops_and_chains(pieces, tol):
    """The loops (of 3 points or more) and the chains of the pieces, joined
    group by group (a layer's pieces, its construction pieces apart)."""
    loops, chains = [], []
    for group in _groups(pieces).values():
        lp, ch = _join(_unique(group, tol), tol)
        loops += lp
        chains += ch
    return [lp for lp in loops if len(lp.points) >= 3], chains


@dataclass
class _Layout:
    """A drawing's loops sorted out: its parts (outline, holes) by index, the
    loop pairs across each other by part, construction loops, open chains and
    notes (a frame left out)."""

    parts: list  # (outline loop, [hole loops]), by index
    conflicts: dict  # part index -> [(its loop, other loop)] that cross or touch
    construction: list  # closed construction loops (never parts, never holes)
    chains: list  # open chains, largest first
    notes: list  # what was left out, described (a drawing frame)


def _around_all(loop: _Piece, pieces: list, tol: float) -> bool:
    """Whether every piece lies within the box of ``loop``."""
    lo, hi = _box(loop.points)
    allpts = np.vstack([p.points for p in pieces])
    return bool(np.all((allpts >= lo - tol) & (allpts <= hi + tol)))


def _layout(pieces: list[_Piece], texts: list, tol: float, drawing: _Drawing,
            drop: _Piece | None = None) -> _Layout:
    """The drawing's parts: pieces joined into loops layer by layer (across
    layers only when no layer closes on its own), a drawing frame left out,
    and the loops nested into parts: a loop inside no other, or inside a hole,
    is a part's outline; the loops directly inside an outline are its holes."""
    if all(p.construction for p in pieces):  # all dashed, or on a construction layer: take it as drawn
        pieces[:] = [_Piece(p.points, p.name, p.closed, p.layer, p.pick, svg=p.svg) for p in pieces]
    loops, chains = _loops_and_chains(pieces, tol)
    plain = [p for p in pieces if not p.construction]
    if not any(not lp.construction for lp in loops) and len({p.layer for p in plain}) > 1:
        # No layer closes on its own: join the layers' pieces (never construction geometry).
        mixed, mixed_chains = _join(_unique(plain, tol), tol)
        mixed = [lp for lp in mixed if len(lp.points) >= 3]
        if mixed:
            loops = [lp for lp in loops if lp.construction] + mixed
            chains = [c for c in chains if c.construction] + mixed_chains
    loops.sort(key=lambda lp: -_area(lp))
    chains.sort(key=lambda c: -_diagonal(c.points))
    notes = []
    frame = _frame(loops, pieces, texts, tol, drawing)
    if frame is not None and not _named(drawing, [p for p in pieces if p.layer == frame[0]]):
        notes.append(frame[1])
        loops = [lp for lp in loops if lp.layer != frame[0]]
        chains = [c for c in chains if c.layer != frame[0]]
    else:
        inplace = _frame_in_place(loops, chains, pieces, texts, tol, drawing)
        if inplace is not None and not _named(drawing, inplace[0]):
            gone = {_key(m) for m in inplace[0]}
            notes.append(inplace[1])
            loops = [lp for lp in loops if not all(_key(m) in gone for m in lp.parts)]
            chains = [c for c in chains if not all(_key(m) in gone for m in c.parts)]
    if drop is not None:
        w, h = np.ptp(drop.points, axis=0) * drawing.unit.scale
        notes.append(f"drawing frame {drop.name}: a {w:.4g} x {h:.4g} mm rectangle around everything else, "
                     f"taken for a frame since --id {drawing.id} picked a loop inside it; to plan it instead: "
                     f"--id {drop.pick or '(give it an id)'}")
        loops = [lp for lp in loops if not all(any(m is d for d in drop.parts) for m in lp.parts)]
    named = [lp for lp in loops if lp.construction and _named(drawing, lp.parts)]
    solid = [lp for lp in loops if not lp.construction or any(lp is x for x in named)]
    if not solid:  # only construction loops close: take them as parts
        solid = loops
    construction = [lp for lp in loops if not any(lp is s_ for s_ in solid)]
    parts, conflicts = _nest(solid, tol)
    return _Layout(parts, conflicts, construction, chains, notes)


def _named(drawing: _Drawing, members) -> bool:
    """Whether ``--id`` names one of these drawn pieces."""
    return drawing.id is not None and any(_names_id(m, drawing.id) for m in members)


def _box(xy) -> tuple:
    return xy.min(axis=0), xy.max(axis=0)


def _nest(loops: list, tol: float):
    """The parts of ``loops`` (sorted largest first): ``[(outline, [holes])]``
    in index order, and ``{index: [(its loop, other loop)]}`` for loops of
    different parts that cross or touch (crossing holes of one part are left to
    :func:`pipeline.parts.part.check_holes`)."""
    n = len(loops)
    boxes = [_box(lp.points) for lp in loops]
    parent, depth, crossing = [None] * n, [0] * n, []
    for i in range(n):
        lo, hi = boxes[i]
        for j in range(i):  # the larger loops, largest first: the last that holds loop i is the innermost
            jlo, jhi = boxes[j]
            if np.any(lo > jhi + tol) or np.any(hi < jlo - tol):
                continue
            inside = _inside_all(loops[i].points, loops[j].points)
            if inside.all():
                parent[i] = j
            elif inside.any():
                crossing.append((j, i))
        depth[i] = 0 if parent[i] is None else depth[parent[i]] + 1
    outlines = [i for i in range(n) if depth[i] % 2 == 0]
    outlines.sort(key=lambda i: (-float(f"{_area(loops[i]):.6g}"), float(boxes[i][0][0]), float(boxes[i][0][1])))
    index = {i: k for k, i in enumerate(outlines)}
    owner = [index[i] if depth[i] % 2 == 0 else index[parent[i]] for i in range(n)]
    parts = [(loops[i], [loops[h] for h in range(n) if parent[h] == i]) for i in outlines]
    conflicts = {}
    for j, i in crossing:
        if owner[i] != owner[j]:
            conflicts.setdefault(owner[j], []).append((loops[j], loops[i]))
            conflicts.setdefault(owner[i], []).append((loops[i], loops[j]))
    return parts, conflicts


def _check_open(sheet: _Layout, pieces, tol, drawing: _Drawing) -> None:
    """An error when an open chain looks like the outline (larger than every
    closed loop), or when nothing closes."""
    plain_chains = [c for c in sheet.chains if not c.construction]
    # A lone straight line (a centre line, a dimension) is never an outline left open.
    could_be = [c for c in plain_chains if len(c.points) > 2]
    biggest = sheet.parts[0][0] if sheet.parts else None
    if could_be and (biggest is None or _diagonal(could_be[0].points) > _diagonal(biggest.points)):
        raise _open_error(could_be[0], pieces, tol, drawing, biggest)
    if biggest is None:
        if plain_chains or sheet.chains:
            raise _open_error((plain_chains or sheet.chains)[0], pieces, tol, drawing, None)
        raise OutlineError(f"{drawing.path}: no closed outline with an area; draw the part's outline as a "
                           f"closed loop (a closed polyline, or pieces whose ends meet)")


_INDEX = re.compile(r"\s*(?:(.*)#)?(\d+)\s*")


def _picked(sheet: _Layout, pieces, tol, drawing: _Drawing) -> int:
    """The index of the part that ``--id`` picks: the part holding the named
    piece (in its outline or a hole), or the part of that index."""
    want = drawing.id
    for k, (outer, holes) in enumerate(sheet.parts):
        if any(_names_id(m, want) for lp in (outer, *holes) for m in lp.parts):
            return k
    m = _INDEX.fullmatch(str(want))
    if m and not any(_names_id(p, want) for p in pieces):
        k, n = int(m.group(2)), len(sheet.parts)
        if k < n:
            return k
        raise OutlineError(f"{drawing.path}: no part #{k}: the drawing holds {n} part{'s' if n != 1 else ''} "
                           f"(#0{f' to #{n - 1}' if n > 1 else ''}); give --id {drawing.path.name}#N with N "
                           f"from 0 to {n - 1}")
    if not any(_names_id(p, want) for p in pieces):
        what = "element id" if drawing.svg else "entity handle"
        raise OutlineError(f"{drawing.path}: no lines, arcs, polylines or shapes with id {want!r}; give the "
                           f"{what} of a piece of the part, or its index ({drawing.path.name}#N)")
    loop = next((lp for lp in sheet.construction if _named(drawing, lp.parts)), None)
    if loop is not None:
        raise OutlineError(f"{drawing.path}: the piece with id {want!r} is construction geometry ("
                           f"{loop.construction}); give the id of a piece of the part")
    chain = next((c for c in sheet.chains if _named(drawing, c.parts)), None)
    if chain is None:
        raise OutlineError(f"{drawing.path}: the piece with id {want!r} has no length, repeats another piece or "
                           f"belongs to a drawing frame; give the id of another piece of the part")
    raise _open_error(chain, pieces, tol, drawing, None)


def _construction_note(lp: _Piece, outer: _Piece | None, drawing: _Drawing) -> str:
    area = f"area {_area(lp) * drawing.unit.scale ** 2:.4g} mm^2"
    where = ""
    if outer is not None:
        inside = _inside_all(lp.points, outer.points)
        where = " " + ("inside" if inside.all() else ("outside" if not inside.any() else "across")) + " the outline,"
    return f"closed loop {lp.name} ({area}; {lp.construction}: construction geometry,{where} never a hole)"


MAX_NAMED_PARTS = 6  # the warning about other parts names this many, then counts the rest


def _others_note(sheet: _Layout, others: list, drawing: _Drawing, chosen: _Piece) -> str:
    """One line: the other parts of the drawing, each with the ``--id`` that picks it."""
    scale2 = drawing.unit.scale ** 2
    label = drawing.path.name
    named = []
    for j in others[:MAX_NAMED_PARTS]:
        outer, holes = sheet.parts[j]
        area = (_area(outer) - sum(_area(h) for h in holes)) * scale2
        with_holes = f", {len(holes)} hole{'s' if len(holes) != 1 else ''}" if holes else ""
        option = drawing.option(outer, chosen)
        pick = f"--id {label}#{j}" + (f" or {option}" if option.startswith("--") and outer.pick else "")
        named.append(f"{label}#{j} ({outer.name}{with_holes}, area {area:.4g} mm^2; to plan it instead: {pick})")
    more = len(others) - len(named)
    tail = f", and {more} more (#{others[len(named)]} to #{others[-1]})" if more else ""
    n = len(others)
    return f"{n} other part{'s' if n != 1 else ''} of this drawing: " + ", ".join(named) + tail


def _chain_notes(chains: list, outer: _Piece, pieces, tol, drawing: _Drawing) -> list[str]:
    out, scale, joined = [], drawing.unit.scale, None
    for c in chains:
        gap = np.hypot(*(c.points[-1] - c.points[0])) * scale
        note = f"; construction geometry, {c.construction}" if c.construction else ""
        if not c.construction and outer.layer is not None and c.layer == outer.layer and len(drawing.layers) > 1:
            if joined is None:
                joined, _ = _join(_unique(pieces, tol), tol)
            bridge = _bridge(c, pieces, tol, joined)
            if bridge:
                note = (f"; {bridge}: draw it closed on layer {c.layer}, or read layer {c.layer} alone "
                        f"with --layer {c.layer}")
        out.append(f"open chain {c.name} (ends {gap:.4g} mm apart{note})")
    return out


def _is_box(xy: np.ndarray, tol: float) -> bool:
    """Whether the polygon is an axis-aligned rectangle (its edges axis-parallel, its area its box's)."""
    edges = np.roll(xy, -1, axis=0) - xy
    if not np.all(np.min(np.abs(edges), axis=1) <= tol):
        return False
    w, h = np.ptp(xy, axis=0)
    return math.isclose(abs(_signed_area(xy)), w * h, rel_tol=1e-6)


def _frame(loops: list, pieces: list, texts: list, tol: float, drawing: _Drawing):
    """``(layer, description)`` of a drawing frame, or None: the largest loop,
    when it is an axis-aligned rectangle around all other geometry holding
    closed loops of other layers, on a layer named as a frame or holding TEXT
    outside the other layers' geometry (a title block)."""
    if not loops or len(drawing.layers) < 2:
        return None
    big = loops[0]
    layer = big.layer
    if layer is None or not _is_box(big.points, tol):
        return None
    others = [p for p in pieces if p.layer != layer]
    if not others or not any(lp.layer != layer and not lp.construction for lp in loops):
        return None
    lo, hi = big.points.min(axis=0) - tol, big.points.max(axis=0) + tol
    pts = np.vstack([p.points for p in others])
    if not np.all((pts >= lo) & (pts <= hi)):
        return None
    olo, ohi = pts.min(axis=0), pts.max(axis=0)
    title = [t for t in texts if t[2] == layer and lo[0] <= t[0] <= hi[0] and lo[1] <= t[1] <= hi[1]
             and not (olo[0] <= t[0] <= ohi[0] and olo[1] <= t[1] <= ohi[1])]
    named = FRAME_LAYER.search(layer)
    if not (named or title):
        return None
    w, h = np.ptp(big.points, axis=0) * drawing.unit.scale
    n = sum(p.layer == layer for p in pieces)
    why = "a layer named as a frame" if named else f"{len(title)} text(s) outside the part, a title block"
    return layer, (f"drawing frame on layer {layer}: {big.name}, a {w:.4g} x {h:.4g} mm rectangle around "
                   f"everything else ({why}), and the other {n - 1} piece(s) of the layer; if it is the part, "
                   f"read layer {layer} alone with --layer {layer}")


# Sheet sizes (mm): a rectangle of one of these is a drawing's border, not a part.
SHEET_SIZES_MM = {"A0": (841, 1189), "A1": (594, 841), "A2": (420, 594), "A3": (297, 420), "A4": (210, 297),
                  "A5": (148, 210), "ANSI A": (215.9, 279.4), "ANSI B": (279.4, 431.8), "ANSI C": (431.8, 558.8),
                  "ANSI D": (558.8, 863.6), "ANSI E": (863.6, 1117.6)}
FRAME_AREA_RATIO = 4.0  # a frame's area is at least this many times the box around what it holds
INNER_BORDER_AREA = 0.6  # an inner border holds at least this fraction of the sheet's area


def _near(points, line, tol: float, closed: bool = False) -> bool:
    """Whether any of ``points`` lies within ``tol`` of the polyline ``line``."""
    a = line if closed else line[:-1]
    b = np.roll(line, -1, axis=0) if closed else line[1:]
    ab = b - a
    L2 = np.einsum("ij,ij->i", ab, ab)
    for k in range(0, len(points), 4096):
        p = points[k:k + 4096, None, :]
        t = np.clip(np.einsum("pij,ij->pi", p - a, ab) / np.where(L2 == 0, 1.0, L2), 0.0, 1.0)
        d = np.hypot(*np.moveaxis(p - a - t[..., None] * ab, -1, 0))
        if np.any(d <= tol):
            return True
    return False


def _touching(seeds: list, rest: list, tol: float) -> list:
    """Groups of the pieces of ``rest`` connected to ``seeds``, each group grown from
    one seed through pieces whose points lie on one another's lines."""
    left = list(rest)
    groups = []
    for seed in seeds:
        if any(seed is m for g in groups for m in g):
            continue
        left = [q for q in left if q is not seed]
        group, todo = [seed], [seed]
        while todo:
            cur = todo.pop()
            lo, hi = _box(cur.points)
            for p in list(left):
                plo, phi = _box(p.points)
                if np.any(plo > hi + tol) or np.any(phi < lo - tol):
                    continue
                ends = p.points if p.closed else p.points[[0, -1]]
                cur_ends = cur.points if cur.closed else cur.points[[0, -1]]
                if _near(ends, cur.points, tol, cur.closed) or _near(cur_ends, p.points, tol, p.closed):
                    left = [q for q in left if q is not p]
                    group.append(p)
                    todo.append(p)
        groups.append(group)
    return groups


def _sheet_size(w: float, h: float) -> str | None:
    """The name of the sheet size ``w`` x ``h`` mm is (either way round, to 1 %), or None."""
    for name, (a, b) in SHEET_SIZES_MM.items():
        for x, y in ((a, b), (b, a)):
            if abs(w - x) <= 0.01 * x and abs(h - y) <= 0.01 * y:
                return name
    return None


def _peel_borders(plain: list, pieces: list, tol: float):
    """The frame ``plain[0]`` and the inner borders inside it (at most two),
    with what touches the innermost one: ``(gone, borders, title, blocks,
    contents)``, the frames' pieces, the borders outermost first, the pieces
    touching the innermost border (a title block), those pieces grouped by
    contact, and everything else; None when nothing is left inside."""
    gone, borders, frame = [], [], plain[0]
    while True:
        gone += list(frame.parts)
        borders.append(frame)
        rest = [p for p in pieces if not any(p is g for g in gone)]
        seeds = [p for p in rest if _near(p.points, frame.points, tol, closed=True)]
        blocks = _touching(seeds, rest, tol)
        title = [m for g in blocks for m in g]
        contents = [p for p in rest if not any(p is t for t in title)]
        if not contents:
            return None
        clo, chi = _box(np.vstack([p.points for p in contents]))
        nxt = next((lp for lp in plain if all(any(m is c for c in contents) for m in lp.parts)), None)
        inner = (not title and nxt is not None and _is_box(nxt.points, tol) and len(borders) < 3
                 and _area(nxt) >= INNER_BORDER_AREA * _area(frame)
                 and np.allclose(_box(nxt.points)[0], clo, atol=tol)
                 and np.allclose(_box(nxt.points)[1], chi, atol=tol))
        if not inner:
            return gone, borders, title, blocks, contents
        frame = nxt


def _corner_blocks(blocks: list, flo, fhi, tol: float) -> list:
    """The groups of pieces touching the frame ``[flo, fhi]`` that hold one of
    its corners and cover at most half its area: title blocks."""
    corners = [np.array(c) for c in ((flo[0], flo[1]), (fhi[0], flo[1]), (fhi[0], fhi[1]), (flo[0], fhi[1]))]
    area = float(np.prod(fhi - flo))
    out = []
    for g in blocks:
        glo, ghi = _box(np.vstack([p.points for p in g]))
        if float(np.prod(ghi - glo)) <= 0.5 * area and any(np.all((c >= glo - tol) & (c <= ghi + tol))
                                                            for c in corners):
            out.append(g)
    return out


def _frame_in_place(loops: list, chains: list, pieces: list, texts: list, tol: float, drawing: _Drawing):
    """``(drawn pieces, description)`` of a drawing frame drawn among the parts'
    pieces (same layer, or an SVG), or None. The frame is the largest closed
    loop, an axis-aligned rectangle around all other geometry, with no closed
    loop touching it, at least :data:`FRAME_AREA_RATIO` times the area of the
    box around what it holds, and a sheet's mark: a title block (lines touching
    it, which close a corner region of at most half its area) or a sheet size
    (:data:`SHEET_SIZES_MM`). An inner border (a rectangle holding everything
    else and :data:`INNER_BORDER_AREA` of the sheet's area, nothing touching the
    outer one) goes with it, and the rules apply to it."""
    plain = [lp for lp in loops if not lp.construction]
    if len(plain) < 2 or not _is_box(plain[0].points, tol):
        return None
    lo, hi = _box(plain[0].points)
    allpts = np.vstack([p.points for p in pieces])
    if not np.all((allpts >= lo - tol) & (allpts <= hi + tol)):
        return None
    peeled = _peel_borders(plain, pieces, tol)
    if peeled is None:
        return None
    gone, borders, title, blocks, contents = peeled
    clo, chi = _box(np.vstack([p.points for p in contents]))
    frame = borders[-1]
    flo, fhi = _box(frame.points)
    solid = [lp for lp in plain if all(any(m is c for c in contents) for m in lp.parts)]
    if not solid or float(np.prod(fhi - flo)) < FRAME_AREA_RATIO * float(np.prod(chi - clo)):
        return None
    corner_blocks = _corner_blocks(blocks, flo, fhi, tol)
    scale = drawing.unit.scale
    w, h = (hi - lo) * scale
    size = _sheet_size(w, h)
    if not corner_blocks and size is None:
        return None
    why = []
    if corner_blocks:
        why.append(f"a title block of {sum(len(g) for g in corner_blocks)} piece(s) in a corner")
    if size is not None:
        why.append(f"sheet size {size}")
    border = f" with its inner border {', '.join(b.name for b in borders[1:])}" if len(borders) > 1 else ""
    out = borders[0]
    return gone + title, (f"drawing frame {out.name}{border}: a {w:.4g} x {h:.4g} mm rectangle around everything "
                          f"else ({'; '.join(why)}), with the {len(title)} piece(s) touching it; if it is the "
                          f"part, pick it with --id {out.pick or '(give it an id)'}")


def _bridge(chain: _Piece, pieces: list, tol: float, loops: list | None = None) -> str:
    """When ``chain`` would close only through pieces of other layers or
    construction geometry: what closes it and why that is not joined; else ""
    (``loops``: all pieces joined, when already known)."""
    if loops is None:
        loops, _ = _join(_unique(pieces, tol), tol)
    mine = {id(m) for m in chain.parts}
    for lp in loops:
        if not any(id(m) in mine for m in lp.parts):
            continue
        foreign = [m for m in lp.parts if id(m) not in mine and (m.layer != chain.layer or m.construction)]
        if not foreign:
            continue
        names = ", ".join(m.name.split(" on layer ")[0] for m in foreign[:3])
        names += " ..." if len(foreign) > 3 else ""
        layers = ", ".join(sorted({m.layer for m in foreign if m.layer is not None}))
        why = ("construction geometry, never joined into an outline" if all(m.construction for m in foreign)
               else "layers are joined only when none closes on its own")
        return f"it closes only through {names} on layer {layers} ({why})"
    return ""


def _open_error(chain: _Piece, pieces: list, tol: float, drawing: _Drawing,
                closed: _Piece | None) -> OutlineError:
    """The error for an open outline: where it ends, what would close it, and the ways out
    (``closed``: a closed loop the user might pick instead)."""
    scale = drawing.unit.scale
    end = chain.points[-1] * scale
    gap = np.hypot(*(chain.points[-1] - chain.points[0])) * scale
    head = (f"{drawing.path}: open outline: {chain.name} ends at ({end[0]:.3f}, {end[1]:.3f}) mm, {gap:.3f} mm "
            f"from its start")
    if closed is not None:
        pick = f"or take the closed loop {closed.name} instead: {drawing.pick(closed, chain)}"
    elif drawing.id is not None:
        pick = "or give --id of a piece of a closed loop"
    else:
        pick = f"or {drawing.pick(None)}"
    bridge = _bridge(chain, pieces, tol) if chain.layer is not None else ""
    if bridge:
        return OutlineError(f"{head}; {bridge}; draw it closed on layer {chain.layer}, {pick}")
    return OutlineError(f"{head}; close the outline in the drawing, raise --join-tol (drawing units) over the "
                        f"gaps, {pick}")
