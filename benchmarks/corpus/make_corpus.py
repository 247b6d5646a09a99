"""Write the corpus of real-looking flat parts that ``benchmarks/real_parts.py`` plans.

Brackets and plates with holes, slotted parts, cams and levers with fillets,
L and T brackets, gussets and a few asymmetric parts, 10 to 150 mm across,
drawn the way CAD tools write them: AutoCAD R12 (a closed POLYLINE with
bulges, no $INSUNITS), AutoCAD 2000 to 2018 (a closed LWPOLYLINE with
bulges, CIRCLE holes), LibreCAD (loose LINE, ARC and CIRCLE entities on an
outline and a holes layer, in no particular order) and Inkscape 1.x (SVG
paths with elliptical arcs, ``<circle>`` holes, a mm page over a viewBox,
y pointing down). Every file was made here: nothing is copied or derived
from a third-party drawing.

The files are committed; this script rewrites them byte for byte (ezdxf's
fixed metadata for testing: no time stamps or GUIDs; a fixed hash seed, as
ezdxf writes some objects in set order; the same recipe as
``tests/data/cad/make_corpus.py``)::

    .venv/bin/python benchmarks/corpus/make_corpus.py            # rewrite in place
    .venv/bin/python benchmarks/corpus/make_corpus.py OUT_DIR    # write elsewhere (to compare)

Geometry. Each part is a polygon, listed counter-clockwise in mm, whose
corners are rounded by fillets (:func:`rounded`), or the outline around a
chain of circles joined by their outer tangents (:func:`belt`: levers and
cams), possibly with concave fillets; either gives vertices ``(x, y, bulge)``
(the DXF bulge of the segment that starts there: ``tan(angle / 4)``). Holes
are circles and slots. The emitters turn the same vertices into each
format's entities. ``SOURCES.md`` lists every part with its vertex count
after flattening at the default tolerance, its holes and its size.
"""
from __future__ import annotations

import math
import os
import sys
from pathlib import Path

import ezdxf

HERE = Path(__file__).resolve().parent


# ---------------------------------------------------------------- geometry

def rounded(points, radii) -> list:
    """Vertices ``(x, y, bulge)`` of the polygon ``points`` (counter-clockwise) with
    corner ``k`` rounded by a fillet of radius ``radii[k]`` (0: a sharp corner).
    A convex corner gets a counter-clockwise arc (positive bulge), a concave one
    a clockwise arc (negative bulge)."""
    if isinstance(radii, (int, float)):
        radii = [radii] * len(points)
    n = len(points)
    cut = [0.0] * n  # how far along each adjacent edge the fillet of corner k starts
    turns = [0.0] * n
    for k in range(n):
        (x0, y0), (x1, y1), (x2, y2) = points[k - 1], points[k], points[(k + 1) % n]
        d1 = (x1 - x0, y1 - y0)
        d2 = (x2 - x1, y2 - y1)
        turn = math.atan2(d1[0] * d2[1] - d1[1] * d2[0], d1[0] * d2[0] + d1[1] * d2[1])
        turns[k] = turn
        cut[k] = radii[k] * math.tan(abs(turn) / 2)
    out = []
    for k in range(n):
        (x0, y0), (x1, y1), (x2, y2) = points[k - 1], points[k], points[(k + 1) % n]
        l1, l2 = math.hypot(x1 - x0, y1 - y0), math.hypot(x2 - x1, y2 - y1)
        if cut[k] + cut[k - 1] > l1 + 1e-9 or cut[k] + cut[(k + 1) % n] > l2 + 1e-9:
            raise ValueError(f"fillet of corner {k} at ({x1}, {y1}) does not fit its edges")
        if cut[k] == 0.0:
            out.append((x1, y1, 0.0))
            continue
        a = (x1 + (x0 - x1) * cut[k] / l1, y1 + (y0 - y1) * cut[k] / l1)
        b = (x1 + (x2 - x1) * cut[k] / l2, y1 + (y2 - y1) * cut[k] / l2)
        out.append((a[0], a[1], math.tan(turns[k] / 4)))
        out.append((b[0], b[1], 0.0))
    return _merged(out)


def belt(circles) -> list:
    """Vertices ``(x, y, bulge)`` of the outline around circles ``(cx, cy, r)``
    listed counter-clockwise, each joined to the next by their outer tangent
    (a lever's or a cam's outline); a circle of negative radius is a concave arc
    (a fillet between its neighbours, material outside it)."""
    n = len(circles)
    normals = []  # the unit normal (pointing out of the material) of the tangent from circle k to k+1
    for k in range(n):
        (x1, y1, r1), (x2, y2, r2) = circles[k], circles[(k + 1) % n]
        dx, dy = x2 - x1, y2 - y1
        length = math.hypot(dx, dy)
        alpha = math.acos(max(-1.0, min(1.0, (r1 - r2) / length)))  # +-1: one circle touches the other inside
        phi = math.atan2(dy, dx) - alpha  # turned clockwise from the centre line: the outside
        normals.append((math.cos(phi), math.sin(phi)))
    out = []
    for k in range(n):
        cx, cy, r = circles[k]
        nin, nout = normals[k - 1], normals[k]
        start = (cx + r * nin[0], cy + r * nin[1])
        sweep = math.atan2(nin[0] * nout[1] - nin[1] * nout[0], nin[0] * nout[0] + nin[1] * nout[1])
        if r > 0 and sweep < 0:
            sweep += 2 * math.pi
        if r < 0 and sweep > 0:
            sweep -= 2 * math.pi
        out.append((start[0], start[1], math.tan(sweep / 4)))
        out.append((cx + r * nout[0], cy + r * nout[1], 0.0))
    return _merged(out)


def _merged(verts) -> list:
    """Drop a vertex that repeats the one before it (a fillet eating a whole edge),
    keeping the bulge of the segment that starts there."""
    out = []
    for v in verts:
        if out and math.hypot(v[0] - out[-1][0], v[1] - out[-1][1]) < 1e-9:
            out[-1] = (out[-1][0], out[-1][1], v[2] or out[-1][2])
            continue
        out.append(v)
    if len(out) > 1 and math.hypot(out[0][0] - out[-1][0], out[0][1] - out[-1][1]) < 1e-9:
        last = out.pop()
        out[0] = (out[0][0], out[0][1], out[0][2] or last[2])
    return [(round(x, 6) + 0.0, round(y, 6) + 0.0, round(b, 9) + 0.0) for x, y, b in out]


def slot(x1, y1, x2, y2, r) -> list:
    """A slot between centres ``(x1, y1)`` and ``(x2, y2)`` of width ``2 r``: two
    straight sides and two half circles (bulge 1), counter-clockwise."""
    return belt([(x1, y1, r), (x2, y2, r)])


def moved(verts, dx=0.0, dy=0.0, angle=0.0) -> list:
    """``verts`` turned by ``angle`` degrees about the origin, then shifted."""
    c, s = math.cos(math.radians(angle)), math.sin(math.radians(angle))
    return [(round(c * x - s * y + dx, 6) + 0.0, round(s * x + c * y + dy, 6) + 0.0, b) for x, y, b in verts]


def _arc(p, q, bulge):
    """Centre, radius, start and end angle (deg, counter-clockwise) of the arc from
    ``p`` to ``q`` with ``bulge`` (a DXF ARC always runs counter-clockwise)."""
    if bulge < 0:
        p, q, bulge = q, p, -bulge
    theta = 4 * math.atan(bulge)
    chord = math.hypot(q[0] - p[0], q[1] - p[1])
    r = chord / (2 * math.sin(theta / 2))
    mx, my = (p[0] + q[0]) / 2, (p[1] + q[1]) / 2
    h = r * math.cos(theta / 2)  # centre's distance from the chord, to the left of p -> q
    ux, uy = (q[0] - p[0]) / chord, (q[1] - p[1]) / chord
    cx, cy = mx - uy * h, my + ux * h
    a0 = math.degrees(math.atan2(p[1] - cy, p[0] - cx))
    a1 = math.degrees(math.atan2(q[1] - cy, q[0] - cx))
    return (round(cx, 6), round(cy, 6)), round(r, 6), round(a0 % 360, 6), round(a1 % 360, 6)


# ---------------------------------------------------------------- DXF emitters

def _new(version, insunits=4):
    doc = ezdxf.new(version, setup=False)
    if version != "R12":  # R12 has no $INSUNITS: unitless, read as mm
        doc.header["$INSUNITS"] = insunits
    return doc


def _layer(doc, name, color=7):
    if not doc.layers.has_entry(name):
        doc.layers.add(name, color=color)
    return {"layer": name}


def lwpolyline(msp, verts, attribs):
    """A closed LWPOLYLINE with bulges (AutoCAD 2000 and later)."""
    msp.add_lwpolyline([(x, y, 0, 0, b) for x, y, b in verts], format="xyseb", close=True, dxfattribs=attribs)


def polyline_r12(msp, verts, attribs=None):
    """A closed POLYLINE of VERTEX entities with bulges (AutoCAD R12)."""
    msp.add_polyline2d([(x, y, b) for x, y, b in verts], format="xyb", close=True, dxfattribs=attribs)


def loose(msp, verts, attribs):
    """The outline as loose LINE and ARC entities, one per segment (as LibreCAD
    and many exporters write it); arcs counter-clockwise, as DXF's ARC has it."""
    n = len(verts)
    for k in range(n):
        x0, y0, b = verts[k]
        x1, y1, _ = verts[(k + 1) % n]
        if b == 0:
            msp.add_line((x0, y0), (x1, y1), dxfattribs=attribs)
        else:
            centre, r, a0, a1 = _arc((x0, y0), (x1, y1), b)
            msp.add_arc(centre, r, a0, a1, dxfattribs=attribs)


# ---------------------------------------------------------------- SVG emitter

def _n(v) -> str:
    return f"{round(v, 4) + 0.0:g}"


def svg_path(verts, height, relative=True) -> str:
    """An Inkscape-style path ``d`` of the closed outline: y flipped (SVG's y points
    down, the page ``height`` mm tall); straight sides as ``l``/``h``/``v``, fillets
    as elliptical arcs ``a r,r 0 large sweep dx,dy``; relative commands as
    Inkscape writes them (``relative``), or absolute ones."""
    pts = [(x, height - y, -b) for x, y, b in verts]  # the mirror turns each arc's sense
    out = [f"{'m' if relative else 'M'} {_n(pts[0][0])},{_n(pts[0][1])}"]
    n = len(pts)
    for k in range(n):
        x0, y0, b = pts[k]
        x1, y1, _ = pts[(k + 1) % n]
        if k == n - 1 and b == 0:
            break  # the closing side: z draws it
        dx, dy = x1 - x0, y1 - y0
        if b == 0:
            if relative and abs(dy) < 1e-9:
                out.append(f"h {_n(dx)}")
            elif relative and abs(dx) < 1e-9:
                out.append(f"v {_n(dy)}")
            else:
                out.append(f"l {_n(dx)},{_n(dy)}" if relative else f"L {_n(x1)},{_n(y1)}")
            continue
        theta = 4 * math.atan(abs(b))
        r = math.hypot(dx, dy) / (2 * math.sin(theta / 2))
        large, sweep = int(theta > math.pi), int(b > 0)  # in y-down numbers, positive angles turn x to y
        end = f"{_n(dx)},{_n(dy)}" if relative else f"{_n(x1)},{_n(y1)}"
        out.append(f"{'a' if relative else 'A'} {_n(r)},{_n(r)} 0 {large} {sweep} {end}")
    return " ".join(out) + " z"


def svg_document(name, width, height, outline_d, circles=(), paths=()) -> str:
    """An Inkscape 1.x document: a mm page over a viewBox of the same numbers, one
    layer, the outline path, ``<circle>`` holes ``(cx, cy, r)`` (y down) and other
    hole paths ``(id, d)``."""
    style = "fill:none;stroke:#000000;stroke-width:0.264583"
    lines = [
        '<?xml version="1.0" encoding="UTF-8" standalone="no"?>',
        "<!-- Created with Inkscape (http://www.inkscape.org/) -->",
        "",
        "<svg",
        f'   width="{_n(width)}mm"',
        f'   height="{_n(height)}mm"',
        f'   viewBox="0 0 {_n(width)} {_n(height)}"',
        '   version="1.1"',
        '   id="svg5"',
        '   inkscape:version="1.3.2 (091e20e, 2023-11-25)"',
        f'   sodipodi:docname="{name}"',
        '   xmlns:inkscape="http://www.inkscape.org/namespaces/inkscape"',
        '   xmlns:sodipodi="http://sodipodi.sourceforge.net/DTD/sodipodi-0.dtd"',
        '   xmlns="http://www.w3.org/2000/svg"',
        '   xmlns:svg="http://www.w3.org/2000/svg">',
        '  <sodipodi:namedview id="namedview7" inkscape:document-units="mm" />',
        "  <g",
        '     inkscape:label="Layer 1"',
        '     inkscape:groupmode="layer"',
        '     id="layer1">',
        "    <path",
        f'       style="{style}"',
        f'       d="{outline_d}"',
        '       id="outline" />',
    ]
    for k, (cx, cy, r) in enumerate(circles, start=1):
        lines.append(f'    <circle style="{style}" id="hole{k}" cx="{_n(cx)}" cy="{_n(cy)}" r="{_n(r)}" />')
    for pid, d in paths:
        lines += ["    <path", f'       style="{style}"', f'       d="{d}"', f'       id="{pid}" />']
    lines += ["  </g>", "</svg>", ""]
    return "\n".join(lines)


# ---------------------------------------------------------------- the parts (mm, y up)
# Each builder returns a DXF document or SVG text; its docstring says what it is.

def l_bracket_r2010():
    """L bracket 60 x 50, legs 14 wide, outer corners r 3 (r 2 by the notch), inside corner r 8, a notch 6 wide and 8 deep
    in the end of the long leg (r 1.5); two holes d 6.5 (R2010 LWPOLYLINE)."""
    doc = _new("R2010")
    msp = doc.modelspace()
    p = _layer(doc, "PART")
    pts = [(0, 0), (60, 0), (60, 4), (52, 4), (52, 10), (60, 10), (60, 14), (14, 14), (14, 50), (0, 50)]
    lwpolyline(msp, rounded(pts, [3, 2, 1.5, 1.5, 1.5, 1.5, 2, 8, 3, 3]), p)
    for c in ((40, 7), (7, 38)):
        msp.add_circle(c, 3.25, dxfattribs=p)
    return doc


def t_bracket_r2000():
    """T bracket 90 x 60: a 90 x 16 flange and a 20 wide stem, fillets r 4 and r 6 (inside);
    three holes d 6.5, one in the stem (R2000 LWPOLYLINE)."""
    doc = _new("R2000")
    msp = doc.modelspace()
    p = _layer(doc, "0")
    lwpolyline(msp, rounded([(35, 0), (55, 0), (55, 44), (90, 44), (90, 60), (0, 60), (0, 44), (35, 44)],
                            [4, 4, 6, 4, 4, 4, 4, 6]), p)
    for c in ((10, 52), (80, 52), (45, 14)):
        msp.add_circle(c, 3.25, dxfattribs=p)
    return doc


def gusset_r12():
    """Gusset 70 x 70: a right triangle with cut tips, a concave hypotenuse (a large clockwise arc) and
    a locating notch 12 x 4 in its base, corners r 3 (notch r 1.5); three holes d 8 (R12 POLYLINE with
    bulges, unitless)."""
    doc = _new("R12")
    msp = doc.modelspace()
    pts = [(0, 0), (28, 0), (28, 4), (40, 4), (40, 0), (70, 0), (70, 10), (10, 70), (0, 70)]
    verts = rounded(pts, [3, 1.5, 1.5, 1.5, 1.5, 3, 3, 3, 3])
    k = _longest(verts)  # bow the long side in
    verts[k] = (verts[k][0], verts[k][1], -0.12)
    polyline_r12(msp, verts)
    for c in ((12, 12), (12, 42), (42, 14)):
        msp.add_circle(c, 4, dxfattribs={})
    return doc


def _longest(verts) -> int:
    """Index of the vertex that starts the longest side."""
    n = len(verts)
    return max(range(n), key=lambda i: math.hypot(verts[(i + 1) % n][0] - verts[i][0],
                                                  verts[(i + 1) % n][1] - verts[i][1]))


def slotted_plate_librecad():
    """Plate 100 x 40, corners r 5, a notch 6 x 12 in each end (r 2), two slots 21 x 7 (centres 14
    apart) and a hole d 8, as LibreCAD draws: loose LINE/ARC/CIRCLE on layers outline and holes (R2007)."""
    doc = _new("R2007")
    msp = doc.modelspace()
    o, h = _layer(doc, "outline"), _layer(doc, "holes", color=1)
    pts = [(0, 0), (100, 0), (100, 14), (94, 14), (94, 26), (100, 26), (100, 40), (0, 40), (0, 26), (6, 26),
           (6, 14), (0, 14)]
    loose(msp, rounded(pts, [5, 5, 2, 2, 2, 2, 5, 5, 2, 2, 2, 2]), o)
    loose(msp, slot(17, 10, 31, 10, 3.5), h)
    loose(msp, slot(69, 30, 83, 30, 3.5), h)
    msp.add_circle((50, 20), 4, dxfattribs=h)
    return doc


def mounting_plate_r2013():
    """Mounting plate 120 x 80, corners r 10, a notch 30 wide and 12 deep in one long side
    (r 4 fillets), four holes d 9 (R2013 LWPOLYLINE)."""
    doc = _new("R2013")
    msp = doc.modelspace()
    p = _layer(doc, "CONTOUR")
    lwpolyline(msp, rounded([(0, 0), (45, 0), (45, 12), (75, 12), (75, 0), (120, 0), (120, 80), (0, 80)],
                            [10, 4, 4, 4, 4, 10, 10, 10]), p)
    for c in ((14, 14), (106, 14), (106, 66), (14, 66)):
        msp.add_circle(c, 4.5, dxfattribs=p)
    return doc


def pear_cam_r2010():
    """Pear cam 53 x 40: a base circle r 20 at the origin and a nose r 7 at (26, 0), joined
    by tangents; a bore d 10 at the base circle's centre with a 3 mm keyway (R2010 LWPOLYLINE)."""
    doc = _new("R2010")
    msp = doc.modelspace()
    p = _layer(doc, "CAM")
    lwpolyline(msp, belt([(0, 0, 20), (26, 0, 7)]), p)
    lwpolyline(msp, _bore_with_key(), p)
    return doc


def _bore_with_key():
    """A bore of radius 5 about the origin with a keyway 3 wide reaching x = -6.5 (vertices, CCW)."""
    y = 1.5
    x = -math.sqrt(25 - y * y)
    theta = 2 * math.pi - 2 * math.atan2(y, -x)  # the arc from (x, -y) round the right to (x, y)
    return [(x, -y, math.tan(theta / 4)), (x, y, 0.0), (-6.5, y, 0.0), (-6.5, -y, 0.0)]


def heart_cam_r2000():
    """Heart-shaped cam 64 x 64: four circles (r 28, 12, 6, 12) around a hub, joined by tangents,
    a hub hole d 12 and a pin hole d 4 (R2000 LWPOLYLINE, layer CAM)."""
    doc = _new("R2000")
    msp = doc.modelspace()
    p = _layer(doc, "CAM")
    lwpolyline(msp, belt([(0, 0, 28), (18, -20, 12), (30, 0, 6), (18, 20, 12)]), p)
    msp.add_circle((0, 0), 6, dxfattribs=p)
    msp.add_circle((18, 0), 2, dxfattribs=p)
    return doc


def lever_tapered_librecad():
    """Tapered lever 116 long: a boss r 14 at the origin and an end r 7 at (95, 0), a waist 10 wide
    between them (concave arcs r 30); holes d 10 and d 5 at the ends and a d 4 hole at (50, 0);
    loose LINE/ARC (R2007, LibreCAD style)."""
    doc = _new("R2007")
    msp = doc.modelspace()
    o, h = _layer(doc, "outline"), _layer(doc, "holes", color=1)
    loose(msp, belt([(0, 0, 14), (48, -35, -30), (95, 0, 7), (48, 35, -30)]), o)
    for c, r in (((0, 0), 5), ((95, 0), 2.5), ((50, 0), 2)):
        msp.add_circle(c, r, dxfattribs=h)
    return doc


def bell_crank_r2010():
    """Bell crank: arms to (60, 0) and (0, 45) from a boss r 12 at the origin, ends r 7, the inner
    corner a concave fillet r 10; three holes d 8, 5, 5 (R2010 LWPOLYLINE), asymmetric."""
    doc = _new("R2010")
    msp = doc.modelspace()
    p = _layer(doc, "PART")
    lwpolyline(msp, belt([(0, 0, 12), (60, 0, 7), (24, 22, -10), (0, 45, 7)]), p)
    for c, r in (((0, 0), 4), ((60, 0), 2.5), ((0, 45), 2.5)):
        msp.add_circle(c, r, dxfattribs=p)
    return doc


def dogbone_link_r12():
    """Link 80 long: ends r 10 at (0, 0) and (60, 0), a waist 10 wide between them made by concave
    arcs r 12; holes d 8 at both ends (R12 POLYLINE with bulges)."""
    doc = _new("R12")
    msp = doc.modelspace()
    polyline_r12(msp, belt([(0, 0, 10), (30, -17, -12), (60, 0, 10), (30, 17, -12)]))
    for c in ((0, 0), (60, 0)):
        msp.add_circle(c, 4)
    return doc


def rocker_arm_r2018():
    """Rocker arm 137 long, asymmetric: a boss r 16 at the origin, a long arm to r 8 at (-80, 18),
    a short arm to r 9 at (40, -8); a concave fillet r 5 in the crotch above and a concave r 20 under
    the long arm, a notch r 2 in its end (fillets r 0.8); holes d 14, 6, 6 (R2018)."""
    doc = _new("R2018")
    msp = doc.modelspace()
    p = _layer(doc, "PART")
    boss, end = (0, 0, 16), (-80, 18, 8)  # the boss listed twice: the outline passes it below and above
    lwpolyline(msp, belt([boss, (40, -8, 9), (20, 12, -5), boss, end, *_notch(end, 180, 2, 0.8, 1.5), end,
                          (-40, -18, -20)]), p)
    for c, r in (((0, 0), 7), ((40, -8), 3), ((-80, 18), 3)):
        msp.add_circle(c, r, dxfattribs=p)
    return doc


def clip_small_r2010():
    """Spring clip 12 x 20, a U of 2.5 mm strips with a lip: fillets r 1 and r 2 (inside), no holes
    (R2010 LWPOLYLINE): the small end of the corpus."""
    doc = _new("R2010")
    msp = doc.modelspace()
    pts = [(0, 0), (12, 0), (12, 20), (8, 20), (8, 17.5), (9.5, 17.5), (9.5, 2.5), (2.5, 2.5), (2.5, 17.5),
           (4, 17.5), (4, 20), (0, 20)]
    lwpolyline(msp, rounded(pts, [1, 1, 0.8, 0.8, 0.4, 0.4, 2, 2, 0.4, 0.4, 0.8, 0.8]), _layer(doc, "PART"))
    return doc


def washer_tab_r2000():
    """Tab washer 38 across, asymmetric: a ring r 12 with a tab 8 wide reaching 24 from the centre and
    a locking tab 6 wide reaching 17 at 140 deg, corners r 1.5 and 1, concave fillets r 2 where the
    tabs meet the ring; a centre hole d 10.5 (R2000 LWPOLYLINE)."""
    doc = _new("R2000")
    msp = doc.modelspace()
    p = _layer(doc, "PART")
    ring = (0, 0, 12)
    lwpolyline(msp, belt([ring, *_tab(0, 4, 24, 1.5, 2, 12), ring, *_tab(140, 3, 17, 1, 2, 12)]), p)
    msp.add_circle((0, 0), 5.25, dxfattribs=p)
    return doc


def _tab(angle, w, reach, rc, rf, ring):
    """The circles (for :func:`belt`) of a straight tab ``2 w`` wide reaching ``reach`` from the centre of a
    ring of radius ``ring``, at ``angle`` deg: corners rounded ``rc``, concave fillets ``rf`` at its roots."""
    xf = math.sqrt((ring + rf) ** 2 - (w + rf) ** 2)  # the fillet touches the ring and the tab's side
    local = [(xf, -(w + rf), -rf), (reach - rc, -(w - rc), rc), (reach - rc, w - rc, rc), (xf, w + rf, -rf)]
    c, s = math.cos(math.radians(angle)), math.sin(math.radians(angle))
    return [(c * x - s * y, s * x + c * y, r) for x, y, r in local]


def z_bracket_r2013():
    """Z bracket 70 x 45, strips 12 wide, fillets r 3 outside and r 6 inside; two holes d 5 (R2013)."""
    doc = _new("R2013")
    msp = doc.modelspace()
    pts = [(0, 0), (40, 0), (40, 33), (70, 33), (70, 45), (28, 45), (28, 12), (0, 12)]
    lwpolyline(msp, rounded(pts, [3, 3, 6, 3, 3, 3, 6, 3]), _layer(doc, "PART"))
    for c in ((8, 6), (62, 39)):
        msp.add_circle(c, 2.5, dxfattribs=_layer(doc, "PART"))
    return doc


def clamp_jaw_r2010():
    """Clamp jaw 80 x 40 with a 90 deg V notch 14 deep in its top and a tongue 20 x 5 under it,
    fillets r 4 (outside) and r 1.5 (the V and the tongue); two holes d 6.5 and a slot 16 x 6.5 (R2010)."""
    doc = _new("R2010")
    msp = doc.modelspace()
    p = _layer(doc, "PART")
    pts = [(0, 0), (30, 0), (30, -5), (50, -5), (50, 0), (80, 0), (80, 35), (54, 35), (40, 21), (26, 35), (0, 35)]
    lwpolyline(msp, rounded(pts, [4, 1.5, 1.5, 1.5, 1.5, 4, 4, 1.5, 1.5, 1.5, 4]), p)
    for c in ((10, 12), (70, 12)):
        msp.add_circle(c, 3.25, dxfattribs=p)
    lwpolyline(msp, slot(32, 8, 48, 8, 3.25), p)
    return doc


def pawl_r2000():
    """Ratchet pawl 67 long, asymmetric: a pivot boss r 10, a body tapering to a hooked tip (r 1.2)
    with a concave r 6 under it, a relief r 8 in its underside, a tail r 4 behind the pivot, a spring
    notch r 1.5 in the boss; a pivot hole d 8 (R2000 LWPOLYLINE)."""
    doc = _new("R2000")
    msp = doc.modelspace()
    boss = (0, 0, 10)
    lwpolyline(msp, belt([boss, *_notch(boss, 240, 1.5, 0.5, 1), boss, (22, -16, -8), (40, -6, 4), (46, 6, 1.2),
                          (34, 4, -6), (-16, 8, 4)]),
               _layer(doc, "PART"))
    msp.add_circle((0, 0), 4, dxfattribs=_layer(doc, "PART"))
    return doc


def sector_plate_librecad():
    """Sector plate 100 across: a 70 deg fan of radius 90 about a hub r 12, its rim's corners rounded r 5
    (circles inside the rim, touching it), an index notch r 4 cut 3 deep in the rim (fillets r 1), two
    mounting lugs r 6 on its sides; a hub hole d 10, lug holes d 4 and an arc slot (r 60, 40 deg, 8 wide)
    as LINE/ARC (R2007, LibreCAD style)."""
    doc = _new("R2007")
    msp = doc.modelspace()
    o, h = _layer(doc, "outline"), _layer(doc, "holes", color=1)
    a = math.radians(35) - math.asin(5 / 85)
    rim = (0, 0, 90)
    loose(msp, belt([(0, 0, 12), (30, -28, 6), (85 * math.cos(a), -85 * math.sin(a), 5), rim,
                     *_notch(rim, 0, 4, 1, 3), rim, (85 * math.cos(a), 85 * math.sin(a), 5), (45, 38, 6)]), o)
    msp.add_circle((0, 0), 5, dxfattribs=h)
    msp.add_circle((30, -28), 2, dxfattribs=h)
    msp.add_circle((45, 38), 2, dxfattribs=h)
    loose(msp, _arc_slot(60, -20, 20, 4), h)
    return doc


def _notch(circle, angle, rn, rf, cut):
    """The circles (for :func:`belt`) of a round notch of radius ``rn`` cut ``cut`` deep into the convex
    arc ``circle`` at ``angle`` deg, its edges rounded by fillets ``rf`` (list the arc's circle again after)."""
    cx, cy, r = circle
    d = r + rn - cut  # the notch's centre from the arc's
    phi = math.acos(((r - rf) ** 2 + d ** 2 - (rn + rf) ** 2) / (2 * (r - rf) * d))
    a = math.radians(angle)
    return [(cx + (r - rf) * math.cos(a - phi), cy + (r - rf) * math.sin(a - phi), rf),
            (cx + d * math.cos(a), cy + d * math.sin(a), -rn),
            (cx + (r - rf) * math.cos(a + phi), cy + (r - rf) * math.sin(a + phi), rf)]


def _arc_slot(r, a0, a1, w):
    """A curved slot, counter-clockwise: the band ``r - w .. r + w`` about the origin between
    angles ``a0`` and ``a1`` (deg), with half-circle ends."""
    b0, b1 = math.radians(a0), math.radians(a1)
    t = math.tan((b1 - b0) / 4)
    return [((r + w) * math.cos(b0), (r + w) * math.sin(b0), t), ((r + w) * math.cos(b1), (r + w) * math.sin(b1), 1.0),
            ((r - w) * math.cos(b1), (r - w) * math.sin(b1), -t), ((r - w) * math.cos(b0), (r - w) * math.sin(b0), 1.0)]


def hook_lever_r2010():
    """Hook lever 93 long, asymmetric: a handle r 6 at (-60, 0), a boss r 11 at the origin, a hook tip r 5
    at (22, 16) with a concave throat r 5 and a concave top r 30; holes d 8 at the boss and d 4 at the
    handle (R2010)."""
    doc = _new("R2010")
    msp = doc.modelspace()
    p = _layer(doc, "PART")
    lwpolyline(msp, belt([(-60, 0, 6), (0, 0, 11), (22, 16, 5), (8, 19, -5), (-28, 33, -30)]), p)
    msp.add_circle((0, 0), 4, dxfattribs=p)
    msp.add_circle((-60, 0), 2, dxfattribs=p)
    return doc


def big_bracket_r2018():
    """Base bracket 150 x 60: a flange with two ears (r 12 ends) and a raised middle, fillets r 6;
    four holes d 10 (R2018 LWPOLYLINE): the large end of the corpus."""
    doc = _new("R2018")
    msp = doc.modelspace()
    p = _layer(doc, "PART")
    pts = [(0, 0), (150, 0), (150, 24), (110, 24), (100, 60), (50, 60), (40, 24), (0, 24)]
    lwpolyline(msp, rounded(pts, [12, 12, 12, 6, 8, 8, 6, 12]), p)
    for c in ((12, 12), (138, 12), (62, 44), (88, 44)):
        msp.add_circle(c, 5, dxfattribs=p)
    return doc


def angle_gusset_r12_lines():
    """Corner plate 45 x 45: a quarter disc r 45 with a 10 x 10 clearance notch at its corner (r 3 and a
    concave r 3), the ends of its rim rounded r 3 (circles inside the rim, touching it and a side);
    a hole d 6 (R12, loose LINE/ARC entities)."""
    doc = _new("R12")
    msp = doc.modelspace()
    x = math.sqrt(42 ** 2 - 3 ** 2)
    loose(msp, belt([(13, 3, 3), (x, 3, 3), (0, 0, 45), (3, x, 3), (3, 13, 3), (7, 7, -3)]), {})
    msp.add_circle((20, 20), 3)
    return doc


def yoke_r2013():
    """Yoke 100 x 56, symmetric: a bar with rounded ends (r 12 ears at x = 0 and 100) and a U cut
    40 wide, 28 deep in the middle, fillets r 5; holes d 8 in the ears (R2013)."""
    doc = _new("R2013")
    msp = doc.modelspace()
    p = _layer(doc, "PART")
    pts = [(0, 0), (100, 0), (100, 56), (70, 56), (70, 28), (30, 28), (30, 56), (0, 56)]
    lwpolyline(msp, rounded(pts, [12, 12, 12, 5, 5, 5, 5, 12]), p)
    for c in ((14, 14), (86, 14)):
        msp.add_circle(c, 4, dxfattribs=p)
    return doc

def star_knob_r2010():
    """Star knob 54 across: five lobes r 6 on a circle r 22, concave flutes r 5 between them (centres on
    r 25); a bore d 8 (R2010 LWPOLYLINE)."""
    doc = _new("R2010")
    msp = doc.modelspace()
    circles = []
    for k in range(5):
        a, b = math.radians(72 * k), math.radians(72 * k + 36)
        circles += [(22 * math.cos(a), 22 * math.sin(a), 6), (25 * math.cos(b), 25 * math.sin(b), -5)]
    lwpolyline(msp, belt(circles), _layer(doc, "KNOB"))
    msp.add_circle((0, 0), 4, dxfattribs=_layer(doc, "KNOB"))
    return doc


def fork_r2000():
    """Fork 70 x 56: a spine 22 wide and four tines 8 wide, tine ends r 2, roots r 2.5, spine corners
    r 4; two holes d 6 in the spine (R2000 LWPOLYLINE)."""
    doc = _new("R2000")
    msp = doc.modelspace()
    p = _layer(doc, "PART")
    pts = [(0, 0), (70, 0)]
    for y in (8, 24, 40):
        pts += [(70, y), (22, y), (22, y + 8), (70, y + 8)]
    pts += [(70, 56), (0, 56)]
    lwpolyline(msp, rounded(pts, [4] + [2, 2, 2.5, 2.5] * 3 + [2, 2, 4]), p)
    for c in ((11, 12), (11, 44)):
        msp.add_circle(c, 3, dxfattribs=p)
    return doc


# ---------------------------------------------------------------- SVG parts (Inkscape 1.x)

def cover_plate_svg():
    """Cover plate 90 x 60 (Inkscape 1.3, mm page 100 x 70): corners r 8, a cut-off corner with r 3
    fillets, cable notches 10 x 6 in the bottom edge and 10 x 4 in the top (r 2 and r 1.5); four
    <circle> holes d 5.5; relative commands."""
    w, h = 100, 70
    pts = [(0, 0), (40, 0), (40, 6), (50, 6), (50, 0), (90, 0), (90, 45), (75, 60), (30, 60), (30, 56), (20, 56),
           (20, 60), (0, 60)]
    verts = moved(rounded(pts, [8, 2, 2, 2, 2, 8, 3, 3, 1.5, 1.5, 1.5, 1.5, 8]), 5, 5)
    holes = [(5 + x, h - (5 + y), 2.75) for x, y in ((8, 8), (82, 8), (8, 52), (68, 52))]
    return svg_document("cover_plate.svg", w, h, svg_path(verts, h), circles=holes)


def cam_lobe_svg():
    """Disc cam 47 x 44 (Inkscape 1.3): a base circle r 22 at the page's (35, 35) and a lobe r 9
    10 mm out, joined by tangents; a <circle> bore d 12; absolute path commands."""
    w, h = 75, 70
    verts = moved(belt([(0, 0, 22), (16, 8, 9)]), 30, 35)
    return svg_document("cam_lobe.svg", w, h, svg_path(verts, h, relative=False), circles=[(30, h - 35, 6)])


def slotted_link_svg():
    """Slotted link 106 long (Inkscape 1.3): ends r 12 and r 9, a waist 16 wide (concave arcs r 32), index
    notches r 2.5 and r 2 in its ends (fillets r 0.8); a slot 40 x 8 as a path and a <circle> hole d 10 at
    the big end; relative commands."""
    w, h = 130, 40
    end, tip = (0, 0, 12), (85, 0, 9)
    verts = moved(belt([end, *_notch(end, 180, 2.5, 0.8, 2), end, (42, -40, -32), tip, *_notch(tip, 0, 2, 0.8, 1.5), tip,
                        (42, 40, -32)]),
                  15, 20)
    sl = moved(slot(26, 0, 58, 0, 4), 15, 20)
    return svg_document("slotted_link.svg", w, h, svg_path(verts, h), circles=[(15, h - 20, 5)],
                        paths=[("slot", svg_path(sl, h))])


def gusset_svg():
    """Gusset 64 x 54 (Inkscape 1.3): a trapezoid with a concave long side and a mounting tab on each
    leg, fillets r 2.5 and r 1.5; two <circle> holes d 5 (relative commands)."""
    w, h = 75, 65
    pts = [(0, 0), (20, 0), (20, -4), (36, -4), (36, 0), (60, 0), (60, 8), (10, 50), (0, 50), (0, 34),
           (-4, 34), (-4, 18), (0, 18)]
    verts = rounded(pts, [2.5, 1.5, 1.5, 1.5, 1.5, 2.5, 2.5, 2.5, 2.5, 1.5, 1.5, 1.5, 1.5])
    k = _longest(verts)
    verts[k] = (verts[k][0], verts[k][1], -0.1)
    verts = moved(verts, 9, 9)
    return svg_document("gusset.svg", w, h, svg_path(verts, h),
                        circles=[(9 + 9, h - 18, 2.5), (9 + 9, h - 41, 2.5)])

DXF = {
    "l_bracket_r2010.dxf": l_bracket_r2010,
    "t_bracket_r2000.dxf": t_bracket_r2000,
    "gusset_r12.dxf": gusset_r12,
    "slotted_plate_librecad.dxf": slotted_plate_librecad,
    "mounting_plate_r2013.dxf": mounting_plate_r2013,
    "pear_cam_r2010.dxf": pear_cam_r2010,
    "heart_cam_r2000.dxf": heart_cam_r2000,
    "lever_tapered_librecad.dxf": lever_tapered_librecad,
    "bell_crank_r2010.dxf": bell_crank_r2010,
    "dogbone_link_r12.dxf": dogbone_link_r12,
    "rocker_arm_r2018.dxf": rocker_arm_r2018,
    "clip_small_r2010.dxf": clip_small_r2010,
    "washer_tab_r2000.dxf": washer_tab_r2000,
    "z_bracket_r2013.dxf": z_bracket_r2013,
    "clamp_jaw_r2010.dxf": clamp_jaw_r2010,
    "pawl_r2000.dxf": pawl_r2000,
    "sector_plate_librecad.dxf": sector_plate_librecad,
    "hook_lever_r2010.dxf": hook_lever_r2010,
    "big_bracket_r2018.dxf": big_bracket_r2018,
    "angle_gusset_r12_lines.dxf": angle_gusset_r12_lines,
    "yoke_r2013.dxf": yoke_r2013,
    "star_knob_r2010.dxf": star_knob_r2010,
    "fork_r2000.dxf": fork_r2000,
}

SVG = {
    "cover_plate.svg": cover_plate_svg,
    "cam_lobe.svg": cam_lobe_svg,
    "slotted_link.svg": slotted_link_svg,
    "gusset.svg": gusset_svg,
}



def write(out: Path = HERE) -> list[Path]:
    """Write every corpus file into ``out``; the paths."""
    ezdxf.options.write_fixed_meta_data_for_testing = True  # no time stamps, no GUIDs: reproducible
    out.mkdir(parents=True, exist_ok=True)
    paths = []
    for name, build in DXF.items():
        build().saveas(out / name)
        paths.append(out / name)
    for name, build in SVG.items():
        (out / name).write_text(build())
        paths.append(out / name)
    return paths


if __name__ == "__main__":
    if os.environ.get("PYTHONHASHSEED") != "0":  # ezdxf writes some objects in set order: fix the hash seed
        os.execve(sys.executable, [sys.executable, __file__, *sys.argv[1:]], dict(os.environ, PYTHONHASHSEED="0"))
    target = Path(sys.argv[1]) if len(sys.argv) > 1 else HERE
    for p in write(target):
        print(p)
