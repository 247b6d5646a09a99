"""Write the CAD corpus of tests/data/cad (and docs/tutorials/holed_bracket.dxf, its gusset bracket).

The files are committed; this script rewrites them byte for byte (ezdxf's fixed
metadata for testing: no time stamps or GUIDs; a fixed hash seed, as ezdxf
writes some objects in set order), so anyone can see how each was
made and make it again::

    .venv/bin/python tests/data/cad/make_corpus.py            # rewrite in place
    .venv/bin/python tests/data/cad/make_corpus.py OUT_DIR    # write elsewhere (the test compares)

Each builder draws a part the way a CAD tool writes it; the geometry is
stated in its docstring and checked in tests/parts/test_cad_data.py, which
works out the expected area, centroid and ``a`` on its own. SOURCES.md says
where each file came from.
"""
from __future__ import annotations

import os
import shutil
import sys
from pathlib import Path

import ezdxf
from ezdxf.math import rational_bspline_from_arc

HERE = Path(__file__).resolve().parent
TUTORIAL = HERE.parents[2] / "docs" / "tutorials" / "holed_bracket.dxf"  # the gusset bracket


def _new(version, insunits=4, linetypes=False):
    doc = ezdxf.new(version, setup=["linetypes"] if linetypes else False)
    if version != "R12":  # R12 has no $INSUNITS: unitless, read as mm
        doc.header["$INSUNITS"] = insunits
    return doc


def _layer(doc, name, linetype="Continuous", color=7):
    if not doc.layers.has_entry(name):
        doc.layers.add(name, color=color, linetype=linetype)
    return {"layer": name}


def holed_bracket():
    """A 50 x 40 mm bracket, drawn as loose entities (as LibreCAD does), DXF 2007.

    Layer OUTLINE: the rectangle (0, 0)-(50, 40) as four LINEs, and a slot
    (centres (18, 14) and (32, 14), radius 3.5) of two LINEs and two ARCs.
    Layer HOLES: two mounting holes, CIRCLEs of diameter 6.5 at (8, 32) and (42, 32).
    """
    doc = _new("R2007")
    msp = doc.modelspace()
    o, h = _layer(doc, "OUTLINE"), _layer(doc, "HOLES", color=1)
    corners = [(0, 0), (50, 0), (50, 40), (0, 40)]
    for k in range(4):
        msp.add_line(corners[k], corners[(k + 1) % 4], dxfattribs=o)
    msp.add_line((18, 10.5), (32, 10.5), dxfattribs=o)
    msp.add_arc((32, 14), 3.5, -90, 90, dxfattribs=o)
    msp.add_line((32, 17.5), (18, 17.5), dxfattribs=o)
    msp.add_arc((18, 14), 3.5, 90, 270, dxfattribs=o)
    msp.add_circle((8, 32), 3.25, dxfattribs=h)
    msp.add_circle((42, 32), 3.25, dxfattribs=h)
    return doc


def gusset_bracket():
    """A 50 x 40 mm gusset bracket, the own-part tutorial's holed part (drawn
    as AutoCAD 2000+ writes it), DXF 2010, all on layer PART.

    The outline a closed LWPOLYLINE (0, 0), (50, 0), (50, 6), (6, 40), (0, 40):
    a right triangle with its two sharp tips cut. Two mounting holes, CIRCLEs
    of diameter 6.5 at (8, 8) and (8, 30); a slot, a closed LWPOLYLINE with
    two half-circle bulges, centres (20, 10) and (32, 10), radius 3.25.
    """
    doc = _new("R2010")
    msp = doc.modelspace()
    part = _layer(doc, "PART")
    msp.add_lwpolyline([(0, 0), (50, 0), (50, 6), (6, 40), (0, 40)], close=True, dxfattribs=part)
    msp.add_circle((8, 8), 3.25, dxfattribs=part)
    msp.add_circle((8, 30), 3.25, dxfattribs=part)
    msp.add_lwpolyline([(20, 6.75, 0, 0, 0), (32, 6.75, 0, 0, 1), (32, 13.25, 0, 0, 0),
                        (20, 13.25, 0, 0, 1)], format="xyseb", close=True, dxfattribs=part)
    return doc


def plate_offcentre_r12():
    """An 80 x 50 plate, (0, 0)-(80, 50), with a hole of radius 15 at (55, 25): AutoCAD R12
    (a closed POLYLINE, no LWPOLYLINE; no $INSUNITS), all on layer 0."""
    doc = _new("R12")
    msp = doc.modelspace()
    msp.add_polyline2d([(0, 0), (80, 0), (80, 50), (0, 50)], close=True)
    msp.add_circle((55, 25), 15)
    return doc


def lever_r2000():
    """A lever, DXF R2000 with a centre line and dimensions.

    Layer CONTOUR: a closed LWPOLYLINE with two half-circle bulges: a 120 mm
    bar between end centres (0, 0) and (120, 0), radius 12; holes: CIRCLEs
    of radius 6 at (0, 0), 4 at (120, 0) and 3 at (40, 0); and a hole of
    radius 5 at (80, 0) as a rational SPLINE (CAD programs export circles so).
    Layer CENTER (linetype CENTER): the centre line (-20, 0)-(140, 0).
    Layer DIM: two linear DIMENSIONs (their blocks hold LINEs: never outline).
    """
    doc = _new("R2000", linetypes=True)
    msp = doc.modelspace()
    c = _layer(doc, "CONTOUR")
    msp.add_lwpolyline([(0, -12, 0, 0, 0), (120, -12, 0, 0, 1), (120, 12, 0, 0, 0), (0, 12, 0, 0, 1)],
                       format="xyseb", close=True, dxfattribs=c)
    for x, r in ((0, 6), (120, 4), (40, 3)):
        msp.add_circle((x, 0), r, dxfattribs=c)
    spline = msp.add_spline(dxfattribs=c)
    spline.apply_construction_tool(rational_bspline_from_arc(center=(80, 0), radius=5, start_angle=0,
                                                             end_angle=360))
    msp.add_line((-20, 0), (140, 0), dxfattribs=_layer(doc, "CENTER", linetype="CENTER", color=3))
    d = _layer(doc, "DIM", color=2)
    msp.add_linear_dim(base=(0, -25), p1=(0, 0), p2=(120, 0), dxfattribs=d).render()
    msp.add_linear_dim(base=(-25, 0), p1=(0, -12), p2=(0, 12), angle=90, dxfattribs=d).render()
    return doc


def construction_r2010():
    """A plate with a rounded end on layer "vector", construction lines on "construction", R2010.

    Layer vector: LINEs (0, 0)-(40, 0), (40, 30)-(0, 30), (0, 30)-(0, 0) and the
    ARC centre (40, 15), radius 15, -90..90 deg; a hole: CIRCLE radius 5 at (40, 15).
    Layer construction: the ARC's two radii, LINEs (40, 15)-(40, 0) and (40, 15)-(40, 30)
    (with the ARC they close a half disc), and the axis (-10, 15)-(70, 15).
    """
    doc = _new("R2010")
    msp = doc.modelspace()
    v, k = _layer(doc, "vector"), _layer(doc, "construction", color=8)
    msp.add_line((0, 0), (40, 0), dxfattribs=v)
    msp.add_arc((40, 15), 15, -90, 90, dxfattribs=v)
    msp.add_line((40, 30), (0, 30), dxfattribs=v)
    msp.add_line((0, 30), (0, 0), dxfattribs=v)
    msp.add_circle((40, 15), 5, dxfattribs=v)
    msp.add_line((40, 15), (40, 0), dxfattribs=k)
    msp.add_line((40, 15), (40, 30), dxfattribs=k)
    msp.add_line((-10, 15), (70, 15), dxfattribs=k)
    return doc


def arc_bridged_r2010():
    """Only an ARC on layer "vector" (centre (0, 0), radius 20, -90..90 deg), its
    ends bridged by two LINEs through the centre on layer "construction": no layer
    closes on its own, and construction lines are never joined into an outline."""
    doc = _new("R2010")
    msp = doc.modelspace()
    msp.add_arc((0, 0), 20, -90, 90, dxfattribs=_layer(doc, "vector"))
    k = _layer(doc, "construction", color=8)
    msp.add_line((0, -20), (0, 0), dxfattribs=k)
    msp.add_line((0, 0), (0, 20), dxfattribs=k)
    return doc


def title_block_r2000():
    """A part on an A4 sheet with a border and a title block, R2000.

    Layer PART: the L-bracket (50, 60), (110, 60), (110, 70), (60, 70), (60, 100),
    (50, 100) as a closed LWPOLYLINE, and a hole CIRCLE radius 3 at (55, 65).
    Layer TITLE: the border, an LWPOLYLINE rectangle (0, 0)-(297, 210), and a block
    TITLEBLOCK (its entities on layer 0: they take the INSERT's layer TITLE) of two
    LINEs boxing (207, 0)-(297, 40) and two TEXTs, inserted at the origin.
    Layer DIM: a DIMENSION of the part's width.
    """
    doc = _new("R2000")
    msp = doc.modelspace()
    p, t = _layer(doc, "PART"), _layer(doc, "TITLE", color=5)
    msp.add_lwpolyline([(50, 60), (110, 60), (110, 70), (60, 70), (60, 100), (50, 100)], close=True,
                       dxfattribs=p)
    msp.add_circle((55, 65), 3, dxfattribs=p)
    msp.add_lwpolyline([(0, 0), (297, 0), (297, 210), (0, 210)], close=True, dxfattribs=t)
    block = doc.blocks.new("TITLEBLOCK")
    block.add_line((207, 0), (207, 40))
    block.add_line((207, 40), (297, 40))
    block.add_text("BRACKET 60 x 40", dxfattribs={"height": 5, "insert": (212, 25)})
    block.add_text("pinfeed test sheet, scale 1:1", dxfattribs={"height": 3, "insert": (212, 10)})
    msp.add_blockref("TITLEBLOCK", (0, 0), dxfattribs=t)
    msp.add_linear_dim(base=(50, 45), p1=(50, 60), p2=(110, 60), dxfattribs=_layer(doc, "DIM")).render()
    return doc


def insert_blocks_r2000():
    """A plate drawn as a block reference holding block references, R2000.

    Block HOLE: a CIRCLE radius 2.5 at its origin (layer 0). Block PLATE: an
    LWPOLYLINE rectangle (0, 0)-(40, 25) (layer 0) and INSERTs of HOLE at
    (8, 8), (32, 8) and (20, 17) (layer 0). Modelspace: an INSERT of PLATE at
    (100, 50), turned 30 deg, on layer PARTS (so all of it is on PARTS), and a
    loose CIRCLE radius 1 at (0, 0) on layer 0 (a locating mark, outside).
    """
    doc = _new("R2000")
    hole = doc.blocks.new("HOLE")
    hole.add_circle((0, 0), 2.5)
    plate = doc.blocks.new("PLATE")
    plate.add_lwpolyline([(0, 0), (40, 0), (40, 25), (0, 25)], close=True)
    for at in ((8, 8), (32, 8), (20, 17)):
        plate.add_blockref("HOLE", at)
    msp = doc.modelspace()
    _layer(doc, "PARTS")
    msp.add_blockref("PLATE", (100, 50), dxfattribs={"layer": "PARTS", "rotation": 30})
    msp.add_circle((0, 0), 1)
    return doc


def island_r2010():
    """A washer with a disc in its hole, all on layer 0: CIRCLEs radius 20, 10 and 5 at (0, 0)."""
    doc = _new("R2010")
    msp = doc.modelspace()
    for r in (20, 10, 5):
        msp.add_circle((0, 0), r)
    return doc


def notch_r12():
    """A 40 x 30 plate (closed POLYLINE) with a rectangular "hole" (10, 0)-(20, 8) that
    opens onto its bottom edge: a notch drawn as a hole, R12."""
    doc = _new("R12")
    msp = doc.modelspace()
    msp.add_polyline2d([(0, 0), (40, 0), (40, 30), (0, 30)], close=True)
    msp.add_polyline2d([(10, 0), (20, 0), (20, 8), (10, 8)], close=True)
    return doc


def lever_washer_r2010():
    """A lever with a washer drawn in its bore, all on layer STANDARD, R2010 (as a CAD
    program exports a drawing of an assembly: the washer's circles in the part's bore).

    The lever's outline, loose LINEs and ARCs (drawn out of order): the ARC centre (0, 0),
    radius 20, 90..270 deg; the LINE (0, -20)-(80, -10); the ARC centre (80, 0), radius
    10, -90..90 deg; the LINE (80, 10)-(0, 20). Its holes: the bore, a CIRCLE radius 11 at
    (0, 0), and a CIRCLE radius 4 at (80, 0). The washer in the bore: CIRCLEs radius 9
    (its outline) and 5.5 (its hole) at (0, 0).
    """
    doc = _new("R2010")
    msp = doc.modelspace()
    s = _layer(doc, "STANDARD")
    msp.add_line((0, -20), (80, -10), dxfattribs=s)
    msp.add_arc((80, 0), 10, -90, 90, dxfattribs=s)
    msp.add_arc((0, 0), 20, 90, 270, dxfattribs=s)
    msp.add_line((80, 10), (0, 20), dxfattribs=s)
    for r in (11, 9, 5.5):
        msp.add_circle((0, 0), r, dxfattribs=s)
    msp.add_circle((80, 0), 4, dxfattribs=s)
    return doc


def sheet_three_parts_r2000():
    """Three parts side by side on layer 0, R2000 (a sheet of parts to cut).

    A square 20 x 20 from (100, 0) (drawn first), a plate 40 x 30 from (0, 0) with a
    hole, a CIRCLE radius 5 at (20, 15), and a square 20 x 20 from (60, 0): closed
    LWPOLYLINEs. By the reader's rule the plate is #0 (largest), then the squares
    (equal areas) left to right: (60, 0) is #1, (100, 0) is #2.
    """
    doc = _new("R2000")
    msp = doc.modelspace()
    for x0 in (100, 60):
        if x0 == 60:
            msp.add_lwpolyline([(0, 0), (40, 0), (40, 30), (0, 30)], close=True)
            msp.add_circle((20, 15), 5)
        msp.add_lwpolyline([(x0, 0), (x0 + 20, 0), (x0 + 20, 20), (x0, 20)], close=True)
    return doc


def frame_same_layer_r2000():
    """A part in a drawing frame with a title block, all on layer 0, R2000 (as a drawing
    is often drawn: frame and part on one layer).

    The frame: four LINEs boxing (0, 0)-(250, 180) (no standard sheet size). The title
    block: LINEs (170, 0)-(170, 30), (170, 30)-(250, 30) and (170, 15)-(250, 15), and a
    TEXT at (175, 20). The part: the L-bracket (50, 60), (110, 60), (110, 70), (60, 70),
    (60, 100), (50, 100), a closed LWPOLYLINE, with a hole, a CIRCLE radius 3 at (55, 65).
    """
    doc = _new("R2000")
    msp = doc.modelspace()
    corners = [(0, 0), (250, 0), (250, 180), (0, 180)]
    for k in range(4):
        msp.add_line(corners[k], corners[(k + 1) % 4])
    msp.add_line((170, 0), (170, 30))
    msp.add_line((170, 30), (250, 30))
    msp.add_line((170, 15), (250, 15))
    msp.add_text("L-BRACKET 60 x 40", dxfattribs={"height": 4, "insert": (175, 20)})
    msp.add_lwpolyline([(50, 60), (110, 60), (110, 70), (60, 70), (60, 100), (50, 100)], close=True)
    msp.add_circle((55, 65), 3)
    return doc


DXF = {
    "holed_bracket.dxf": holed_bracket,
    "gusset_bracket.dxf": gusset_bracket,
    "plate_offcentre_r12.dxf": plate_offcentre_r12,
    "lever_r2000.dxf": lever_r2000,
    "construction_r2010.dxf": construction_r2010,
    "arc_bridged_r2010.dxf": arc_bridged_r2010,
    "title_block_r2000.dxf": title_block_r2000,
    "insert_blocks_r2000.dxf": insert_blocks_r2000,
    "island_r2010.dxf": island_r2010,
    "notch_r12.dxf": notch_r12,
    "lever_washer_r2010.dxf": lever_washer_r2010,
    "sheet_three_parts_r2000.dxf": sheet_three_parts_r2000,
    "frame_same_layer_r2000.dxf": frame_same_layer_r2000,
}


def _circle_path(cx, cy, r):
    """A circle as Inkscape writes one: two arcs, closed."""
    return f"M {cx + r:g},{cy:g} A {r:g},{r:g} 0 1 1 {cx - r:g},{cy:g} A {r:g},{r:g} 0 1 1 {cx + r:g},{cy:g} z"


def inkscape048_svg():
    """Inkscape 0.48 (90 px per inch): an A4 page of unitless width and height, no viewBox.

    A plate of 180 x 90 px (2 x 1 in: 50.8 x 25.4 mm), drawn from (100, 200) in a layer
    moved by translate(0, -20), its path back at its start without a closing z; a hole
    of diameter 36 px (10.16 mm) at (145, 245) in page pixels, drawn at the origin and
    placed by a matrix transform: 45 px (0.5 in) from the plate's left edge, half way
    down its height.
    """
    hole = _circle_path(0, 0, 18)
    return f"""<?xml version="1.0" encoding="UTF-8" standalone="no"?>
<!-- Created with Inkscape (http://www.inkscape.org/) -->
<svg
   xmlns:dc="http://purl.org/dc/elements/1.1/"
   xmlns:svg="http://www.w3.org/2000/svg"
   xmlns="http://www.w3.org/2000/svg"
   xmlns:sodipodi="http://sodipodi.sourceforge.net/DTD/sodipodi-0.dtd"
   xmlns:inkscape="http://www.inkscape.org/namespaces/inkscape"
   width="744.09448819"
   height="1052.3622047"
   id="svg2"
   version="1.1"
   inkscape:version="0.48.4 r9939"
   sodipodi:docname="plate.svg">
  <sodipodi:namedview id="base" inkscape:document-units="px" showgrid="false" />
  <g
     inkscape:label="Layer 1"
     inkscape:groupmode="layer"
     id="layer1"
     transform="translate(0,-20)">
    <path
       style="fill:none;stroke:#000000;stroke-width:1px"
       d="M 100,220 L 280,220 L 280,310 L 100,310 L 100,220"
       id="plate"
       inkscape:connector-curvature="0" />
    <path
       sodipodi:type="arc"
       style="fill:none;stroke:#000000;stroke-width:1px"
       id="hole"
       d="{hole}"
       transform="matrix(1,0,0,1,145,265)" />
  </g>
</svg>
"""


def inkscape1_svg():
    """Inkscape 1.2 (mm document: width 100mm over viewBox 0 0 100 80): the 50 x 40 mm
    bracket of holed_bracket.dxf, y down, its top-left corner at (10, 20) on the page,
    by a layer transform translate(10, 20); the outline a path without a closing z;
    the mounting holes two <circle> of radius 3.25 at (8, 8) and (42, 8) (layer units);
    the slot a path of two lines and two arcs, centres (18, 26) and (32, 26), radius 3.5."""
    return """<?xml version="1.0" encoding="UTF-8" standalone="no"?>
<!-- Created with Inkscape (http://www.inkscape.org/) -->

<svg
   width="100mm"
   height="80mm"
   viewBox="0 0 100 80"
   version="1.1"
   id="svg5"
   inkscape:version="1.2.2 (b0a8486541, 2022-12-01)"
   sodipodi:docname="bracket.svg"
   xmlns:inkscape="http://www.inkscape.org/namespaces/inkscape"
   xmlns:sodipodi="http://sodipodi.sourceforge.net/DTD/sodipodi-0.dtd"
   xmlns="http://www.w3.org/2000/svg"
   xmlns:svg="http://www.w3.org/2000/svg">
  <sodipodi:namedview id="namedview7" inkscape:document-units="mm" />
  <g
     inkscape:label="Layer 1"
     inkscape:groupmode="layer"
     id="layer1"
     transform="translate(10,20)">
    <path
       style="fill:none;stroke:#000000;stroke-width:0.264583"
       d="M 0,0 H 50 V 40 H 0 V 0"
       id="outline" />
    <circle style="fill:none;stroke:#000000;stroke-width:0.264583" id="hole-left" cx="8" cy="8" r="3.25" />
    <circle style="fill:none;stroke:#000000;stroke-width:0.264583" id="hole-right" cx="42" cy="8" r="3.25" />
    <path
       style="fill:none;stroke:#000000;stroke-width:0.264583"
       d="m 18,22.5 h 14 a 3.5,3.5 0 0 1 3.5,3.5 3.5,3.5 0 0 1 -3.5,3.5 h -14 \
a 3.5,3.5 0 0 1 -3.5,-3.5 3.5,3.5 0 0 1 3.5,-3.5 z"
       id="slot" />
  </g>
</svg>
"""


def open_path_svg():
    """A path that is not closed (its end 2 mm short of its start) beside a closed circle, plain SVG in mm."""
    return ('<svg xmlns="http://www.w3.org/2000/svg" width="100mm" height="50mm" viewBox="0 0 100 50">\n'
            '  <path id="outline" d="M 10,10 L 60,10 L 60,40 L 10,40 L 10,12" />\n'
            '  <circle id="washer" cx="80" cy="25" r="8" />\n'
            '</svg>\n')


def inkscape_layers_svg():
    """Inkscape 1.3 (mm page over a viewBox, y down), two layers. Layer "Part": a plate
    60 x 40 mm, (10, 10)-(70, 50) on the page, as a path of two open subpaths
    meeting at the corners (10, 10) and (70, 50), and a hole, a <circle> radius 6 at
    (40, 30). Layer "Dimensions": a box around the plate, (5, 5)-(75, 55) (larger than
    the plate: without layers it would be the outline), and two dimension lines whose
    ends touch the plate's corners (they would join its outline on one layer)."""
    return """<?xml version="1.0" encoding="UTF-8" standalone="no"?>
<!-- Created with Inkscape (http://www.inkscape.org/) -->
<svg
   width="80mm"
   height="60mm"
   viewBox="0 0 80 60"
   version="1.1"
   id="svg1"
   inkscape:version="1.3.2 (091e20e, 2023-11-25)"
   xmlns:inkscape="http://www.inkscape.org/namespaces/inkscape"
   xmlns:sodipodi="http://sodipodi.sourceforge.net/DTD/sodipodi-0.dtd"
   xmlns="http://www.w3.org/2000/svg"
   xmlns:svg="http://www.w3.org/2000/svg">
  <sodipodi:namedview id="namedview1" inkscape:document-units="mm" />
  <g inkscape:label="Part" inkscape:groupmode="layer" id="layer1">
    <path style="fill:none;stroke:#000000;stroke-width:0.26" d="M 10,10 H 70 V 50 M 10,10 V 50 H 70" id="plate" />
    <circle style="fill:none;stroke:#000000;stroke-width:0.26" id="bore" cx="40" cy="30" r="6" />
  </g>
  <g inkscape:label="Dimensions" inkscape:groupmode="layer" id="layer2">
    <rect style="fill:none;stroke:#0000ff;stroke-width:0.1" id="box" x="5" y="5" width="70" height="50" />
    <path style="fill:none;stroke:#0000ff;stroke-width:0.1" d="M 10,50 V 57 H 70 V 50" id="dim-width" />
    <path style="fill:none;stroke:#0000ff;stroke-width:0.1" d="M 70,10 H 77 V 50 H 70" id="dim-height" />
  </g>
</svg>
"""


def inkscape_two_parts_svg():
    """Inkscape 1.3 (mm page, y down), a part on each of two layers. Layer "Bracket": a
    50 x 40 mm plate, (5, 5)-(55, 45) on the page (a <rect>), with a hole, a <circle>
    radius 4 at (15, 15). Layer "Washer": a washer, <circle>s radius 9 (id washer) and
    5.5 (id washer-hole) at (80, 25)."""
    return """<?xml version="1.0" encoding="UTF-8" standalone="no"?>
<!-- Created with Inkscape (http://www.inkscape.org/) -->
<svg
   width="100mm"
   height="50mm"
   viewBox="0 0 100 50"
   version="1.1"
   id="svg1"
   inkscape:version="1.3.2 (091e20e, 2023-11-25)"
   xmlns:inkscape="http://www.inkscape.org/namespaces/inkscape"
   xmlns:sodipodi="http://sodipodi.sourceforge.net/DTD/sodipodi-0.dtd"
   xmlns="http://www.w3.org/2000/svg"
   xmlns:svg="http://www.w3.org/2000/svg">
  <sodipodi:namedview id="namedview1" inkscape:document-units="mm" />
  <g inkscape:label="Bracket" inkscape:groupmode="layer" id="layer1">
    <rect style="fill:none;stroke:#000000;stroke-width:0.26" id="bracket" x="5" y="5" width="50" height="40" />
    <circle style="fill:none;stroke:#000000;stroke-width:0.26" id="bracket-hole" cx="15" cy="15" r="4" />
  </g>
  <g inkscape:label="Washer" inkscape:groupmode="layer" id="layer2">
    <circle style="fill:none;stroke:#000000;stroke-width:0.26" id="washer" cx="80" cy="25" r="9" />
    <circle style="fill:none;stroke:#000000;stroke-width:0.26" id="washer-hole" cx="80" cy="25" r="5.5" />
  </g>
</svg>
"""


SVG = {
    "inkscape048_plate.svg": inkscape048_svg,
    "inkscape1_bracket.svg": inkscape1_svg,
    "open_path.svg": open_path_svg,
    "inkscape_layers.svg": inkscape_layers_svg,
    "inkscape_two_parts.svg": inkscape_two_parts_svg,
}


def write(out: Path = HERE, tutorial: bool = True) -> list[Path]:
    """Write every corpus file into ``out`` (and the tutorial's copy of the gusset bracket); the paths."""
    ezdxf.options.write_fixed_meta_data_for_testing = True  # no time stamps, no GUIDs: reproducible
    out.mkdir(parents=True, exist_ok=True)
    paths = []
    for name, build in DXF.items():
        build().saveas(out / name)
        paths.append(out / name)
    for name, build in SVG.items():
        (out / name).write_text(build())
        paths.append(out / name)
    if tutorial:
        shutil.copyfile(out / "gusset_bracket.dxf", TUTORIAL)
    return paths


if __name__ == "__main__":
    if os.environ.get("PYTHONHASHSEED") != "0":  # ezdxf writes some objects in set order: fix the hash seed
        os.execve(sys.executable, [sys.executable, __file__, *sys.argv[1:]], dict(os.environ, PYTHONHASHSEED="0"))
    target = Path(sys.argv[1]) if len(sys.argv) > 1 else HERE
    for p in write(target, tutorial=len(sys.argv) == 1):
        print(p)
