"""CAD outlines as engineers draw them: holes, layers, construction lines,
drawing frames, blocks, old Inkscape files and the advice of one-line errors.
Files are built here (ezdxf, SVG text); tests/parts/test_cad_data.py reads the
committed corpus."""
import math

import numpy as np
import pytest

ezdxf = pytest.importorskip("ezdxf")
pytest.importorskip("svgelements")

from cad_files import dxf_file  # noqa: E402
from pipeline.parts.outlines import OutlineError, read_outline  # noqa: E402


def _area(xy):
    x, y = xy[:, 0], xy[:, 1]
    return 0.5 * abs(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1)))


def _rect(msp, x0, y0, x1, y1, layer="0", **attribs):
    return msp.add_lwpolyline([(x0, y0), (x1, y0), (x1, y1), (x0, y1)], close=True,
                              dxfattribs={"layer": layer, **attribs})


def _one_line(exc_info, *needles):
    text = str(exc_info.value)
    assert "\n" not in text, text
    for needle in needles:
        assert needle in text, text
    return text


# ---------------------------------------------------------------- holes


def test_rectangle_holes_exact_material(tmp_path):
    # A 60 x 40 plate with two square holes: no flattening, so area and a are exact.
    def build(msp):
        _rect(msp, 0, 0, 60, 40)
        _rect(msp, 5, 5, 15, 15)  # area 100, centroid (10, 10)
        _rect(msp, 40, 20, 50, 35, layer="HOLES")  # area 150, centroid (45, 27.5)
    out = read_outline(dxf_file(tmp_path / "p.dxf", build))
    area = 2400 - 100 - 150
    c = (np.array([30, 20]) * 2400 - np.array([10, 10]) * 100 - np.array([45, 27.5]) * 150) / area
    corners = np.array([(0, 0), (60, 0), (60, 40), (0, 40)])
    assert out.part().area == pytest.approx(area, rel=1e-12)
    assert out.a == pytest.approx(np.max(np.hypot(*(corners - c).T)), rel=1e-12)
    assert len(out.holes) == 2 and out.hole_layers == ["HOLES", "0"]
    assert "2 holes (8 vertices; 1 on layer HOLES)" in out.describe()
    w, h, a = out.size_mm
    assert (w, h) == (60, 40) and a == out.a


def test_hole_touching_the_outline_is_a_notch(tmp_path):
    def build(msp):
        _rect(msp, 0, 0, 40, 30)
        _rect(msp, 10, 5, 40, 10)  # its right edge on the outline's
    with pytest.raises(OutlineError) as exc:
        read_outline(dxf_file(tmp_path / "n.dxf", build))
    _one_line(exc, "touch", "notch: draw it as part of the outline")


def test_holes_that_cross_each_other_are_named(tmp_path):
    def build(msp):
        _rect(msp, 0, 0, 40, 30)
        h1 = _rect(msp, 5, 5, 20, 20)
        h2 = _rect(msp, 15, 15, 30, 25)
        build.handles = (h1.dxf.handle, h2.dxf.handle)
    with pytest.raises(OutlineError) as exc:
        read_outline(dxf_file(tmp_path / "x.dxf", build))
    _one_line(exc, f"LWPOLYLINE {build.handles[0]}", f"LWPOLYLINE {build.handles[1]}", "cross or touch")


def test_island_is_a_part_of_its_own(tmp_path):
    def build(msp):
        build.ring = msp.add_circle((0, 0), 20).dxf.handle
        msp.add_circle((0, 0), 10)
        build.island = msp.add_circle((0, 0), 4).dxf.handle
    path = dxf_file(tmp_path / "i.dxf", build)
    ring = read_outline(path)  # the largest part: the ring; the disc in its hole is named
    assert ring.name.startswith(f"CIRCLE {build.ring}") and len(ring.holes) == 1 and ring.label == "i.dxf#0"
    (other,) = ring.left_out
    assert other.startswith("1 other part of this drawing: i.dxf#1 (CIRCLE") and f"--id {build.island}" in other
    island = read_outline(path, id=build.island)  # picked by its handle, or by its index
    assert not island.holes and island.label == "i.dxf#1" and "i.dxf#0" in island.left_out[0]
    assert read_outline(path, id="i.dxf#1").name == island.name == read_outline(path, id="#1").name


def test_loop_outside_is_left_out_and_pickable(tmp_path):
    def build(msp):
        _rect(msp, 0, 0, 40, 30)
        msp.add_circle((10, 10), 3)
        build.far = msp.add_circle((100, 0), 5).dxf.handle
    out = read_outline(dxf_file(tmp_path / "o.dxf", build))
    assert len(out.holes) == 1
    (left,) = out.left_out
    assert f"CIRCLE {build.far}" in left and f"--id {build.far}" in left


def test_dashed_pitch_circle_is_never_a_hole(tmp_path):
    # A bolt circle in linetype CENTER through the holes' centres: construction, not a hole
    # (as a hole it would cross the real ones).
    def build(msp):
        msp.doc.linetypes.add("CENTER", pattern=[2.0, 1.25, -0.25, 0.25, -0.25])
        msp.add_circle((0, 0), 30)
        for k in range(4):
            t = k * math.pi / 2
            msp.add_circle((20 * math.cos(t), 20 * math.sin(t)), 3)
        msp.add_circle((0, 0), 20, dxfattribs={"linetype": "CENTER"})
    out = read_outline(dxf_file(tmp_path / "b.dxf", build))
    assert len(out.holes) == 4
    assert any("linetype CENTER" in item and "never a hole" in item for item in out.left_out)


def test_svg_holes_from_circles_and_the_material_centroid(tmp_path):
    path = tmp_path / "p.svg"
    path.write_text('<svg xmlns="http://www.w3.org/2000/svg" width="100mm" height="100mm" viewBox="0 0 100 100">'
                    '<rect id="plate" x="0" y="0" width="60" height="40"/>'
                    '<rect id="sq" x="10" y="10" width="10" height="10"/>'
                    '<circle id="c" cx="45" cy="20" r="5"/></svg>')
    out = read_outline(path, flatten_tol=0.01)
    assert out.hole_names == ["<circle id='c'>", "<rect id='sq'>"] or \
        sorted(out.hole_names) == ["<circle id='c'>", "<rect id='sq'>"]
    circle = next(h for h, n in zip(out.holes, out.hole_names) if "circle" in n)
    assert 0 < math.pi * 25 - _area(circle) <= 2 * math.pi * 5 * 0.01
    # y down in SVG: flipped, the plate spans y -40..0; the square hole is at (15, -15), the circle (45, -20).
    area = 2400 - 100 - _area(circle)
    c = (np.array([30, -20]) * 2400 - np.array([15, -15]) * 100 - np.array([45, -20]) * _area(circle)) / area
    corners = np.array([(0, 0), (60, 0), (60, -40), (0, -40)])
    assert out.a == pytest.approx(np.max(np.hypot(*(corners - c).T)), rel=1e-9)


# ---------------------------------------------------------------- layers


def _rounded_plate(msp, layer):
    """A 40 x 30 plate with a half-disc end (centre (40, 15), radius 15) of LINEs and an ARC."""
    a = {"layer": layer}
    msp.add_line((0, 0), (40, 0), dxfattribs=a)
    msp.add_arc((40, 15), 15, -90, 90, dxfattribs=a)
    msp.add_line((40, 30), (0, 30), dxfattribs=a)
    msp.add_line((0, 30), (0, 0), dxfattribs=a)


ROUNDED_AREA = 1200 + math.pi * 15 ** 2 / 2


@pytest.mark.parametrize("aux", ["aux", "construction"])
def test_construction_lines_on_another_layer_never_join_the_outline(tmp_path, aux):
    def build(msp):
        _rounded_plate(msp, "vector")
        msp.add_line((40, 15), (40, 0), dxfattribs={"layer": aux})  # radii: with the ARC, a half disc
        msp.add_line((40, 15), (40, 30), dxfattribs={"layer": aux})
    out = read_outline(dxf_file(tmp_path / "c.dxf", build), flatten_tol=0.01)
    assert "chain of 4 pieces" in out.name and out.layer == "vector" and not out.joined_layers
    assert 0 < ROUNDED_AREA - _area(out.vertices) <= math.pi * 15 * 0.01
    assert len(out.left_out) == 1 and f"on layer {aux}" in out.left_out[0]


def test_no_layer_closes_layers_are_joined_and_said(tmp_path):
    def build(msp):
        msp.add_arc((0, 0), 20, -90, 90, dxfattribs={"layer": "vector"})
        msp.add_line((0, -20), (0, 0), dxfattribs={"layer": "lines"})
        msp.add_line((0, 0), (0, 20), dxfattribs={"layer": "lines"})
    out = read_outline(dxf_file(tmp_path / "j.dxf", build))
    assert out.joined_layers == ["lines", "vector"] and out.layer is None
    assert "joined across layers lines, vector" in out.describe()
    (warning,) = [w for w in out.warnings() if "joins pieces" in w]
    assert "lines, vector" in warning and "--layer NAME" in warning


def test_construction_named_layer_never_closes_the_outline(tmp_path):
    def build(msp):
        msp.add_arc((0, 0), 20, -90, 90, dxfattribs={"layer": "vector"})
        msp.add_line((0, -20), (0, 0), dxfattribs={"layer": "construction"})
        msp.add_line((0, 0), (0, 20), dxfattribs={"layer": "construction"})
    with pytest.raises(OutlineError) as exc:
        read_outline(dxf_file(tmp_path / "a.dxf", build))
    _one_line(exc, "open outline: ARC", "on layer construction", "never joined", "--layer",
              "layers construction, vector")


def test_chain_of_the_parts_layer_closing_through_another_layer_is_said(tmp_path):
    def build(msp):
        _rect(msp, 0, 0, 60, 40, layer="vector")
        msp.add_arc((100, 0), 10, -90, 90, dxfattribs={"layer": "vector"})  # away from the plate
        msp.add_line((100, -10), (100, 10), dxfattribs={"layer": "sketch"})
    out = read_outline(dxf_file(tmp_path / "b.dxf", build))
    assert out.layer == "vector" and _area(out.vertices) == pytest.approx(2400)
    (arc,) = [item for item in out.left_out if "open chain ARC" in item]
    assert "closes only through LINE" in arc and "layer sketch" in arc and "--layer vector" in arc


def test_open_outline_on_the_parts_layer_names_the_bridging_layer(tmp_path):
    # The outline's layer has a hole that closes, the outline itself only closes through another layer.
    def build(msp):
        msp.add_lwpolyline([(0, 0), (60, 0), (60, 40), (0, 40)], dxfattribs={"layer": "vector"})  # open
        msp.add_line((0, 40), (0, 0), dxfattribs={"layer": "sketch"})
        build.hole = msp.add_circle((30, 20), 5, dxfattribs={"layer": "vector"}).dxf.handle
    with pytest.raises(OutlineError) as exc:
        read_outline(dxf_file(tmp_path / "o.dxf", build))
    # The closed loop on the same layer is picked by its handle (--layer would not tell them apart).
    _one_line(exc, "open outline", "closes only through LINE", "layer sketch",
              "layers are joined only when none closes", "draw it closed on layer vector", f"--id {build.hole}")


def test_layer_restricts_everything(tmp_path):
    def build(msp):
        _rect(msp, 0, 0, 60, 40, layer="PLATE")
        msp.add_circle((30, 20), 5, dxfattribs={"layer": "HOLES"})
    path = dxf_file(tmp_path / "l.dxf", build)
    assert len(read_outline(path).holes) == 1
    assert not read_outline(path, layer="PLATE").holes
    assert read_outline(path, layer="HOLES").n_vertices > 8  # the circle alone, as a part


# ---------------------------------------------------------------- drawing frames


def _sheet(msp, frame_layer, text=True, part_layer="PART"):
    _rect(msp, 20, 20, 80, 60, layer=part_layer)
    msp.add_circle((40, 40), 5, dxfattribs={"layer": part_layer})
    _rect(msp, 0, 0, 297, 210, layer=frame_layer)
    if text:
        msp.add_text("DRAWING No. 1", dxfattribs={"layer": frame_layer, "insert": (220, 10), "height": 5})


@pytest.mark.parametrize("frame_layer, text", [("Rahmen", False), ("SHEET_A4", False), ("L1", True)])
def test_drawing_frame_is_left_out(tmp_path, frame_layer, text):
    out = read_outline(dxf_file(tmp_path / "s.dxf", lambda m: _sheet(m, frame_layer, text)))
    assert out.layer == "PART" and _area(out.vertices) == pytest.approx(2400) and len(out.holes) == 1
    (frame,) = [item for item in out.left_out if item.startswith("drawing frame")]
    assert f"on layer {frame_layer}" in frame and "297 x 210 mm" in frame and f"--layer {frame_layer}" in frame
    assert ("text" in frame) == (not FRAME_NAMED(frame_layer))


def FRAME_NAMED(name):
    from pipeline.parts.outlines import FRAME_LAYER
    return bool(FRAME_LAYER.search(name))


def test_rectangular_plate_with_holes_on_another_layer_is_no_frame(tmp_path):
    # The same rectangle, no text and a plain layer name: a plate with holes, not a sheet.
    def build(msp):
        _rect(msp, 0, 0, 100, 60, layer="PLATE")
        msp.add_circle((20, 20), 4, dxfattribs={"layer": "HOLES"})
        msp.add_circle((80, 40), 4, dxfattribs={"layer": "HOLES"})
        msp.add_text("PN 4711", dxfattribs={"layer": "PLATE", "insert": (40, 25), "height": 5})  # engraved
    out = read_outline(dxf_file(tmp_path / "p.dxf", build))
    assert out.layer == "PLATE" and len(out.holes) == 2 and not out.left_out


def test_a4_frame_on_the_parts_layer_is_left_out(tmp_path):
    # Frame and part on one layer: the 297 x 210 rectangle is an A4 sheet, around everything else.
    out = read_outline(dxf_file(tmp_path / "f.dxf", lambda m: _sheet(m, "0", part_layer="0")))
    assert _area(out.vertices) == pytest.approx(2400) and len(out.holes) == 1
    (frame,) = [item for item in out.left_out if item.startswith("drawing frame")]
    assert "297 x 210 mm" in frame and "sheet size A4" in frame


def test_rectangular_part_on_its_own_layer_is_no_frame(tmp_path):
    # A plate with one small central hole and a bend line from edge to edge, all on one layer: a
    # rectangle around everything else, much larger than what it holds, lines touching it, but no
    # title block in a corner and no sheet size: the part, not a frame.
    def build(msp):
        _rect(msp, 0, 0, 120, 80)
        msp.add_circle((60, 40), 5)
        msp.add_line((90, 0), (90, 80))
    out = read_outline(dxf_file(tmp_path / "p.dxf", build))
    assert out.n_vertices == 4 and _area(out.vertices) == pytest.approx(9600) and len(out.holes) == 1
    assert not any(item.startswith("drawing frame") for item in out.left_out)


def test_frame_with_inner_border_and_title_block_on_the_parts_layer(tmp_path):
    def build(msp):
        _rect(msp, 0, 0, 300, 200)  # the sheet's edge (no standard size)
        _rect(msp, 20, 10, 290, 190)  # the inner border, the title block touching it
        msp.add_line((200, 10), (200, 40))
        msp.add_line((200, 40), (290, 40))
        _rect(msp, 60, 60, 120, 100)  # the part, with a hole
        msp.add_circle((90, 80), 5)
    out = read_outline(dxf_file(tmp_path / "f.dxf", build))
    assert _area(out.vertices) == pytest.approx(2400) and len(out.holes) == 1 and out.n_parts == 1
    (frame,) = out.left_out
    assert "with its inner border" in frame and "300 x 200 mm" in frame and "title block of 2 piece(s)" in frame


def test_id_inside_a_frame_not_recognised_leaves_the_frame_out(tmp_path):
    # An SVG frame (no title block, no sheet size) around a plate: the frame reads as the part, with
    # a warning; --id of the plate leaves the frame out and picks the plate with its hole.
    svg = tmp_path / "plate.svg"
    svg.write_text('<svg xmlns="http://www.w3.org/2000/svg" width="100mm" height="100mm" viewBox="0 0 100 100">'
                   '<rect id="frame" x="2" y="2" width="98" height="68"/>'
                   '<path id="plate" d="M 10,10 H 90 V 60 H 10 Z"/><circle id="hole" cx="30" cy="30" r="5"/></svg>')
    out = read_outline(svg)
    assert out.name == "<rect id='frame'>" and any("if it is a drawing frame" in w for w in out.warnings())
    plate = read_outline(svg, id="plate")
    assert plate.name == "<path id='plate'>" and len(plate.holes) == 1
    (frame,) = plate.left_out
    assert frame.startswith("drawing frame <rect id='frame'>") and "--id frame" in frame


# ---------------------------------------------------------------- blocks


def test_block_entities_are_named_by_block_and_insert_and_take_its_layer(tmp_path):
    doc = ezdxf.new("R2010")
    doc.header["$INSUNITS"] = 4
    hole = doc.blocks.new("HOLE")
    hole.add_circle((0, 0), 2)  # layer 0: takes the INSERT's
    hole.add_circle((0, 0), 0.5, dxfattribs={"layer": "MARKS"})  # its own layer stays
    bracket = doc.blocks.new("BRACKET")
    bracket.add_lwpolyline([(0, 0), (30, 0), (30, 20), (0, 20)], close=True)
    bracket.add_blockref("HOLE", (10, 10))
    bracket.add_blockref("HOLE", (20, 10))
    msp = doc.modelspace()
    insert = msp.add_blockref("BRACKET", (50, 50), dxfattribs={"layer": "PART"})
    doc.saveas(tmp_path / "b.dxf")
    h = insert.dxf.handle
    out = read_outline(tmp_path / "b.dxf", layer="PART")
    assert out.name == f"LWPOLYLINE in block BRACKET (INSERT {h}) on layer PART"
    assert out.hole_names == [f"CIRCLE in block HOLE in block BRACKET (INSERT {h}) on layer PART"] * 2


def test_block_marks_inside_holes_are_parts_of_their_own(tmp_path):
    doc = ezdxf.new("R2010")
    hole = doc.blocks.new("HOLE")
    hole.add_circle((0, 0), 2)
    hole.add_circle((0, 0), 0.5, dxfattribs={"layer": "MARKS"})
    doc.modelspace().add_lwpolyline([(0, 0), (30, 0), (30, 20), (0, 20)], close=True)
    insert = doc.modelspace().add_blockref("HOLE", (10, 10), dxfattribs={"layer": "PART"})
    doc.saveas(tmp_path / "m.dxf")
    out = read_outline(tmp_path / "m.dxf")
    assert len(out.holes) == 1 and out.n_vertices == 4
    (mark,) = out.left_out
    assert f"m.dxf#1 (CIRCLE in block HOLE (INSERT {insert.dxf.handle}) on layer MARKS" in mark
    assert "--layer MARKS" in mark


def test_id_of_an_insert_picks_its_block(tmp_path):
    doc = ezdxf.new("R2010")
    doc.header["$INSUNITS"] = 4
    block = doc.blocks.new("WASHER")
    block.add_circle((0, 0), 10)
    block.add_circle((0, 0), 4)
    msp = doc.modelspace()
    big = msp.add_circle((100, 0), 30)
    washer = msp.add_blockref("WASHER", (0, 0))
    doc.saveas(tmp_path / "w.dxf")
    assert read_outline(tmp_path / "w.dxf").name.startswith(f"CIRCLE {big.dxf.handle}")
    out = read_outline(tmp_path / "w.dxf", id=washer.dxf.handle.lower())  # handles in any case
    assert out.name.startswith(f"CIRCLE in block WASHER (INSERT {washer.dxf.handle})") and len(out.holes) == 1
    with pytest.raises(OutlineError, match="no lines, arcs, polylines or shapes with id 'FFFF'"):
        read_outline(tmp_path / "w.dxf", id="FFFF")


# ---------------------------------------------------------------- advice: --id or --layer, as fits the file


def test_crossing_loops_advice_fits_the_file(tmp_path):
    def one_layer(msp):
        build.outer = _rect(msp, 0, 0, 60, 40).dxf.handle
        _rect(msp, 50, 10, 80, 20)
    build = one_layer
    with pytest.raises(OutlineError) as exc:
        read_outline(dxf_file(tmp_path / "one.dxf", one_layer))
    _one_line(exc, "cross each other", f"--id {build.outer}")

    def two_layers(msp):
        _rect(msp, 0, 0, 60, 40, layer="A")
        _rect(msp, 50, 10, 80, 20, layer="B")
    with pytest.raises(OutlineError) as exc:
        read_outline(dxf_file(tmp_path / "two.dxf", two_layers))
    text = _one_line(exc, "cross each other", "--layer A")
    assert "--id" not in text

    svg = tmp_path / "x.svg"
    svg.write_text('<svg xmlns="http://www.w3.org/2000/svg" width="100mm" height="100mm" viewBox="0 0 100 100">'
                   '<rect id="plate" width="60" height="40"/>'
                   '<rect id="bar" x="50" y="10" width="30" height="10"/>'
                   '</svg>')
    with pytest.raises(OutlineError) as exc:
        read_outline(svg)
    text = _one_line(exc, "cross each other", "--id plate")
    assert "--layer" not in text
    assert read_outline(svg, id="bar").left_out[0].startswith("closed loop <rect id='plate'>")


def test_open_outline_advice_fits_the_file(tmp_path):
    def build(msp):
        msp.add_lwpolyline([(0, 0), (60, 0), (60, 40), (0, 40)])  # open, larger than the washer
        build.washer = msp.add_circle((100, 0), 5).dxf.handle
    with pytest.raises(OutlineError) as exc:
        read_outline(dxf_file(tmp_path / "o.dxf", build))
    _one_line(exc, "open outline", "--join-tol", f"--id {build.washer}")


# ---------------------------------------------------------------- Inkscape's pixels


def _inkscape(path, version, size):
    version_attr = f' inkscape:version="{version}"' if version else ""
    path.write_text('<svg xmlns="http://www.w3.org/2000/svg" xmlns:inkscape="http://www.inkscape.org/namespaces/'
                    f'inkscape"{version_attr} {size}><rect x="0" y="0" width="180" height="90"/></svg>')
    return path


@pytest.mark.parametrize("version, size, mm, said", [
    ("0.48.4 r9939", 'width="744.09448819" height="1052.3622047"', 25.4 / 90,
     "Inkscape 0.48 file: 90 px per inch"),
    ("0.91 r13725", 'width="744.09448819" height="1052.3622047" viewBox="0 0 744.09448819 1052.3622047"',
     25.4 / 90, "Inkscape 0.91 file: 90 px per inch"),
    ("0.48.4 r9939", 'width="360px" height="180px" viewBox="0 0 180 90"', 2 * 25.4 / 90, "Inkscape 0.48 file"),
    ("0.92.3 (2405546, 2018-03-11)", 'width="793.7" height="1122.5"', 25.4 / 96, "CSS pixels, 96 per inch"),
    ("1.2.2 (b0a8486541, 2022-12-01)", 'width="793.7" height="1122.5"', 25.4 / 96, "CSS pixels, 96 per inch"),
    (None, 'width="793.7" height="1122.5"', 25.4 / 96, "CSS pixels, 96 per inch"),
    ("0.48.4 r9939", 'width="210mm" height="297mm" viewBox="0 0 210 297"', 1.0, "SVG width/viewBox (210mm"),
])
def test_inkscape_pixels(tmp_path, version, size, mm, said):
    out = read_outline(_inkscape(tmp_path / "i.svg", version, size))
    assert out.size_mm[:2] == pytest.approx((180 * mm, 90 * mm), rel=1e-9)
    assert said in out.describe()
    over = read_outline(tmp_path / "i.svg", units="mm")  # --units keeps overriding
    assert over.size_mm[:2] == pytest.approx((180, 90), rel=1e-9) and "from --units" in over.describe()
