"""Make the example parts library: drawings/ holds 36 drawings (DXF and SVG),
drawn here from numbers, of flat parts from 10 to 150 mm: plates, triangles,
brackets, wedges, polygons, parts with holes, sheets of several parts, a lever
with a washer in its bore, a drawing frame with a title block, Inkscape layers,
and a few drawings pinfeed cannot read (an open outline, a hole crossing the
outline, a file that is no drawing). Run it from anywhere:

    python examples/library/make_library.py

then plan the whole library: ``pinfeed library examples/library/drawings``.
"""
from __future__ import annotations

import math
from pathlib import Path

import ezdxf

OUT = Path(__file__).resolve().parent / "drawings"


def circle_pts(cx, cy, r, n=12):
    return [(cx + r * math.cos(2 * math.pi * k / n), cy + r * math.sin(2 * math.pi * k / n)) for k in range(n)]


def dxf(name, loops, circles=(), layer="0", extra=None):
    """A DXF (R2010, millimetres) of closed polylines ``loops`` and ``circles`` (cx, cy, r)."""
    doc = ezdxf.new("R2010")
    doc.header["$INSUNITS"] = 4
    msp = doc.modelspace()
    for loop in loops:
        msp.add_lwpolyline(loop, close=True, dxfattribs={"layer": layer})
    for cx, cy, r in circles:
        msp.add_circle((cx, cy), r, dxfattribs={"layer": layer})
    if extra:
        extra(doc, msp)
    doc.saveas(OUT / name)


def svg(name, body, size=(200, 200), inkscape=False):
    ns = (' xmlns:inkscape="http://www.inkscape.org/namespaces/inkscape"' if inkscape else "")
    w, h = size
    (OUT / name).write_text(f'<?xml version="1.0" encoding="UTF-8"?>\n<svg xmlns="http://www.w3.org/2000/svg"{ns} '
                            f'width="{w}mm" height="{h}mm" viewBox="0 0 {w} {h}">\n{body}\n</svg>\n')


def poly(points, **attrs):
    pts = " ".join(f"{x:g},{y:g}" for x, y in points)
    extra = "".join(f' {k.replace("_", "-")}="{v}"' for k, v in attrs.items())
    return f'<polygon points="{pts}" fill="none" stroke="black"{extra}/>'


def rect(x, y, w, h):
    return [(x, y), (x + w, y), (x + w, y + h), (x, y + h)]


def main() -> None:
    OUT.mkdir(parents=True, exist_ok=True)
    for old in OUT.iterdir():
        old.unlink()
    # Plates and bars, 10 to 150 mm.
    dxf("tab_10x6.dxf", [rect(0, 0, 10, 6)])
    dxf("shim_24x14.dxf", [[(0, 0), (24, 0), (24, 9), (19, 14), (0, 14)]])
    dxf("bar_90x12.dxf", [rect(0, 0, 90, 12)])
    dxf("plate_40x25_hole.dxf", [rect(0, 0, 40, 25), rect(8, 8, 8, 8)])
    dxf("plate_150x60_holes.dxf", [rect(0, 0, 150, 60)], circles=[(20, 30, 6), (120, 20, 8)])
    dxf("plate_chamfer_50x30.dxf", [[(0, 0), (44, 0), (50, 6), (50, 30), (0, 30)]])
    dxf("plate_notch_60x40.dxf", [[(0, 0), (60, 0), (60, 40), (34, 40), (34, 32), (26, 32), (26, 40), (0, 40)]])
    # Triangles and wedges.
    dxf("triangle_asym_60.dxf", [[(0, 0), (60, 0), (15, 35)]])
    dxf("triangle_right_50x30.dxf", [[(0, 0), (50, 0), (0, 30)]])
    dxf("triangle_obtuse_80.dxf", [[(0, 0), (80, 0), (65, 18)]])
    dxf("wedge_70x25.dxf", [[(0, 0), (70, 0), (70, 25), (0, 8)]])
    dxf("trapezoid_70x25.dxf", [[(0, 0), (70, 0), (52, 25), (10, 25)]])
    dxf("gusset_holed_50x40.dxf", [[(0, 0), (50, 0), (50, 6), (6, 40), (0, 40)], rect(5, 5, 6, 6)])
    # Brackets.
    dxf("l_bracket_60x45.dxf", [[(0, 0), (60, 0), (60, 12), (12, 12), (12, 45), (0, 45)]])
    dxf("t_bracket_80x50.dxf", [[(0, 38), (0, 50), (80, 50), (80, 38), (46, 38), (46, 0), (34, 0), (34, 38)]])
    dxf("z_bracket_70x40.dxf", [[(0, 0), (40, 0), (40, 28), (70, 28), (70, 40), (28, 40), (28, 12), (0, 12)]])
    dxf("u_channel_60x30.dxf", [[(0, 0), (60, 0), (60, 30), (50, 30), (50, 10), (10, 10), (10, 30), (0, 30)]])
    # Regular and near-regular polygons.
    dxf("hexagon_30.dxf", [circle_pts(0, 0, 15, 6)])
    dxf("pentagon_off_hole.dxf", [circle_pts(0, 0, 20, 5)], circles=[(6, 3, 3)])
    a0 = math.asin(3 / 20)  # a disk with a keyway: the arc from the key's top edge round to its bottom edge
    arc = [(20 * math.cos(a0 + (2 * math.pi - 2 * a0) * k / 22), 20 * math.sin(a0 + (2 * math.pi - 2 * a0) * k / 22))
           for k in range(23)]
    dxf("disk_keyway_40.dxf", [arc + [(15, -3), (15, 3)]])
    # Sheets of several parts (each gets its own row: FILE#0, FILE#1, ...).
    dxf("sheet_three_parts.dxf", [rect(0, 0, 40, 30), rect(60, 0, 20, 20), [(100, 0), (130, 0), (100, 20)]])
    dxf("sheet_two_brackets.dxf", [[(0, 0), (50, 0), (50, 10), (10, 10), (10, 35), (0, 35)],
                                   [(70, 0), (130, 0), (130, 14), (70, 6)]])
    # A lever with a washer lying in its bore: two parts (a loop in a hole is a part of its own).
    dxf("lever_washer.dxf", [[(0, 0), (110, 10), (110, 30), (0, 40)]],
        circles=[(20, 20, 12), (20, 20, 8), (20, 20, 3), (90, 20, 4)])
    # A part inside a drawing frame with a title block (the frame is left out).
    def frame(doc, msp):
        doc.layers.add("TITLE")
        msp.add_lwpolyline(rect(-20, -20, 297, 210), close=True, dxfattribs={"layer": "TITLE"})
        msp.add_lwpolyline(rect(177, -20, 100, 30), close=True, dxfattribs={"layer": "TITLE"})
        msp.add_text("BRACKET 12-A", dxfattribs={"layer": "TITLE", "height": 5}).set_placement((180, -10))
    dxf("framed_bracket_a4.dxf", [[(0, 0), (70, 0), (70, 15), (20, 15), (20, 50), (0, 50)]], extra=frame)
    # Construction lines on their own layer (never part of the outline).
    def construction(doc, msp):
        doc.layers.add("CONSTRUCTION")
        msp.add_line((-10, 15), (90, 15), dxfattribs={"layer": "CONSTRUCTION"})
        msp.add_line((40, -10), (40, 40), dxfattribs={"layer": "CONSTRUCTION"})
    dxf("slotted_plate_80x30.dxf", [rect(0, 0, 80, 30), rect(20, 12, 40, 6)], extra=construction)
    # SVG drawings (y flipped to look as in a viewer).
    svg("svg_triangle_45.svg", poly([(10, 60), (55, 60), (20, 25)]))
    svg("svg_kite_60.svg", poly([(10, 40), (40, 20), (70, 40), (40, 110)]), size=(120, 120))
    svg("svg_plate_holes_100x50.svg", poly(rect(10, 10, 100, 50)) + poly(rect(20, 20, 10, 10))
        + '<circle cx="90" cy="35" r="8" fill="none" stroke="black"/>', size=(130, 80))
    svg("svg_two_parts.svg", poly(rect(10, 10, 50, 30)) + poly([(80, 40), (120, 40), (90, 10)]), size=(140, 60))
    svg("inkscape_layers_bracket.svg",
        '<g inkscape:groupmode="layer" inkscape:label="part">'
        + poly([(10, 70), (70, 70), (70, 58), (22, 58), (22, 10), (10, 10)]) + "</g>"
        + '<g inkscape:groupmode="layer" inkscape:label="construction">'
        '<path d="M 0,40 L 90,40" fill="none" stroke="blue" stroke-dasharray="4,2"/></g>',
        size=(100, 100), inkscape=True)
    svg("svg_big_lever_140.svg", poly([(5, 30), (145, 22), (145, 38), (5, 50)])
        + '<circle cx="20" cy="40" r="5" fill="none" stroke="black"/>', size=(150, 60))
    # Drawings pinfeed cannot read, each for its own reason.
    def open_outline(doc, msp):
        msp.add_lwpolyline([(0, 0), (50, 0), (50, 30), (0, 30), (0, 5)], close=False)
    dxf("broken_open_outline.dxf", [], extra=open_outline)
    dxf("broken_hole_crosses.dxf", [rect(0, 0, 40, 30), rect(30, 10, 20, 10)])
    (OUT / "broken_not_a_drawing.dxf").write_text("this file was saved as text, not as a DXF drawing\n")
    svg("broken_empty.svg", "<!-- nothing drawn -->")
    # A sheet with one good part and one refused (its hole touches the outline).
    dxf("sheet_one_refused.dxf", [rect(0, 0, 30, 20), rect(60, 0, 40, 30), rect(90, 10, 10, 10)])
    print(f"{len(list(OUT.iterdir()))} drawings in {OUT}")


if __name__ == "__main__":
    main()
