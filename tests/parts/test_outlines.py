"""CAD outlines: DXF and SVG files written here, read back as parts."""
import json
import math

import numpy as np
import pytest

ezdxf = pytest.importorskip("ezdxf")
pytest.importorskip("svgelements")

from pipeline.parts.outlines import OutlineError, read_outline  # noqa: E402
from pipeline.parts.part import Part  # noqa: E402
from cad_files import dxf_file

L, R = 40.0, 10.0  # rounded slot: centre distance, end radius
SLOT_AREA = 2 * R * L + math.pi * R * R


def _area(xy):
    x, y = xy[:, 0], xy[:, 1]
    return 0.5 * abs(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1)))


def _slot_pieces(msp, dx=0.0, layer="0"):
    a = {"layer": layer}
    msp.add_line((dx, -R), (dx + L, -R), dxfattribs=a)
    msp.add_arc((dx + L, 0), R, -90, 90, dxfattribs=a)
    msp.add_line((dx, R), (dx + L, R), dxfattribs=a)  # drawn backwards: the chain must reverse it
    msp.add_arc((dx, 0), R, 90, 270, dxfattribs=a)


def _bracket(msp, w=60.0, h=40.0, t=10.0, layer="0"):
    msp.add_lwpolyline([(0, 0), (w, 0), (w, t), (t, t), (t, h), (0, h)], close=True,
                       dxfattribs={"layer": layer})


def _svg(path, body, size='width="100mm" height="60mm" viewBox="0 0 100 60"'):
    path.write_text(f'<svg xmlns="http://www.w3.org/2000/svg" {size}>{body}</svg>')
    return path


SLOT_D = "M 0,-10 L 40,-10 A 10 10 0 0 1 40 10 L 0 10 A 10 10 0 0 1 0 -10 Z"


@pytest.mark.parametrize("tol", [0.05, 0.01])
def test_dxf_rounded_slot_from_lines_and_arcs(tmp_path, tol):
    out = read_outline(dxf_file(tmp_path / "slot.dxf", _slot_pieces), flatten_tol=tol)
    area = _area(out.vertices)
    # Chords lie inside the arcs: the polygon's area is short of the true one by
    # less than the arcs' length times the tolerance.
    assert 0 < SLOT_AREA - area <= 2 * math.pi * R * tol
    assert out.n_vertices > 4 and "4 pieces" in out.name
    part = Part.from_vertices(out.vertices, name="slot")
    assert part.is_convex and part.a == pytest.approx(L / 2 + R, abs=tol)


def test_dxf_units_are_converted_to_mm(tmp_path):
    out = read_outline(dxf_file(tmp_path / "in.dxf", _bracket, insunits=1))  # inches
    assert _area(out.vertices) == pytest.approx((60 * 10 + 30 * 10) * 25.4 ** 2)


def test_dxf_bulged_polyline_is_flattened(tmp_path):
    # A slot as one closed LWPOLYLINE with two half-circle bulges (bulge 1 = 180 deg).
    def build(msp):
        msp.add_lwpolyline([(0, -R, 0, 0, 0), (L, -R, 0, 0, 1), (L, R, 0, 0, 0), (0, R, 0, 0, 1)],
                           format="xyseb", close=True)
    out = read_outline(dxf_file(tmp_path / "bulge.dxf", build), flatten_tol=0.05)
    assert 0 < SLOT_AREA - _area(out.vertices) <= 2 * math.pi * R * 0.05


def test_dxf_l_bracket_non_convex(tmp_path):
    out = read_outline(dxf_file(tmp_path / "l.dxf", _bracket))
    assert out.n_vertices == 6
    part = Part.from_vertices(out.vertices, name="bracket")
    assert not part.is_convex and part.area == pytest.approx(900.0)


def test_svg_slot_with_transform_and_units(tmp_path):
    body = f'<g transform="translate(20,20)"><path id="slot" d="{SLOT_D}"/></g>'
    out = read_outline(_svg(tmp_path / "slot.svg", body), flatten_tol=0.05)
    assert 0 < SLOT_AREA - _area(out.vertices) <= 2 * math.pi * R * 0.05
    # translate(20,20) then y flipped: x in [10, 70], y in [-30, -10] (mm).
    assert out.vertices.min(0) == pytest.approx([10, -30], abs=1e-3)
    assert out.vertices.max(0) == pytest.approx([70, -10], abs=1e-3)


def test_svg_scaled_document_units(tmp_path):
    # viewBox 0..50 spread over 100 mm: one user unit is 2 mm.
    body = '<rect id="r" x="0" y="0" width="10" height="5"/>'
    out = read_outline(_svg(tmp_path / "r.svg", body, 'width="100mm" height="100mm" viewBox="0 0 50 50"'))
    assert _area(out.vertices) == pytest.approx(20 * 10, rel=1e-4)


def test_svg_l_bracket_polygon(tmp_path):
    body = '<polygon id="L" points="0,0 60,0 60,10 10,10 10,40 0,40"/>'
    part = Part.from_vertices(read_outline(_svg(tmp_path / "l.svg", body)).vertices)
    assert not part.is_convex and part.area == pytest.approx(900.0, rel=1e-4)


def test_open_outline(tmp_path):
    def build(msp):
        msp.add_line((0, 0), (10, 0))
        msp.add_line((10, 0), (10, 10))
    with pytest.raises(OutlineError, match=r"open outline.*ends at \(10\.000, 10\.000\)"):
        read_outline(dxf_file(tmp_path / "open.dxf", build))


def test_disjoint_outlines_largest_by_default_others_reported(tmp_path):
    def build(msp):
        _slot_pieces(msp, dx=100.0, layer="SLOT")  # area 1114 mm^2
        _bracket(msp, layer="BRACKET")  # area 900 mm^2
    path = dxf_file(tmp_path / "two.dxf", build)
    out = read_outline(path)
    assert _area(out.vertices) == pytest.approx(SLOT_AREA, rel=1e-2) and "layer SLOT" in out.name
    assert len(out.left_out) == 1 and "layer BRACKET" in out.left_out[0] and "900 mm^2" in out.left_out[0]
    assert any("left out 1 other part of this drawing: two.dxf#1" in w for w in out.warnings())
    assert read_outline(path, layer="BRACKET").n_vertices == 6
    svg = _svg(tmp_path / "two.svg", f'<path id="slot" d="{SLOT_D}"/>'
               '<rect id="plate" x="80" y="0" width="10" height="10"/>')
    out = read_outline(svg)
    assert "id='slot'" in out.name and "id='plate'" in out.left_out[0]
    assert _area(read_outline(svg, id="plate").vertices) == pytest.approx(100.0, rel=1e-4)


def test_self_intersection(tmp_path):
    def build(msp):
        msp.add_lwpolyline([(0, 0), (10, 10), (10, 0), (0, 10)], close=True)
    with pytest.raises(OutlineError, match="self-intersecting"):
        read_outline(dxf_file(tmp_path / "bow.dxf", build))


def test_hole_reads_as_a_hole(tmp_path):
    def build(msp):
        _bracket(msp)
        msp.add_circle((5, 5), 2)
    out = read_outline(dxf_file(tmp_path / "hole.dxf", build), flatten_tol=0.01)
    (hole,) = out.holes
    assert out.n_vertices == 6 and out.hole_names[0].startswith("CIRCLE") and "1 hole (" in out.describe()
    # The flattened circle is inscribed: short of the true area by under its length times the tolerance.
    assert 0 < math.pi * 4 - _area(hole) <= 2 * math.pi * 2 * 0.01
    part = out.part("bracket")
    assert part.area == pytest.approx(900 - _area(hole)) and part.has_holes
    # The material's centroid: the L's (65/3, 35/3) less the hole's (5, 5), weighted by area.
    c = (np.array([65 / 3, 35 / 3]) * 900 - np.array([5.0, 5.0]) * _area(hole)) / part.area
    corners = np.array([(0, 0), (60, 0), (60, 10), (10, 10), (10, 40), (0, 40)])
    assert out.a == part.a == pytest.approx(np.max(np.hypot(*(corners - c).T)), rel=1e-12)


def test_bad_inputs(tmp_path):
    with pytest.raises(OutlineError, match="no outline file"):
        read_outline(tmp_path / "missing.dxf")
    (tmp_path / "x.stl").write_text("solid")
    with pytest.raises(OutlineError, match="give a .dxf or .svg"):
        read_outline(tmp_path / "x.stl")
    with pytest.raises(OutlineError, match="flatten-tol"):
        read_outline(dxf_file(tmp_path / "l.dxf", _bracket), flatten_tol=0)


def test_config_family_outline_relative_to_config_file(tmp_path, monkeypatch):
    import yaml

    from pipeline.config import DEFAULT_CONFIG, load_config
    from pipeline.errors import PinfeedError
    from pipeline.parts.families import family_parts
    (tmp_path / "cad").mkdir()
    dxf_file(tmp_path / "cad" / "l.dxf", _bracket)
    cfg = yaml.safe_load(DEFAULT_CONFIG.read_text())
    cfg["families"] = {"cad": {"parts": [{"name": "bracket", "outline": "cad/l.dxf"}]}}
    cfg["planner"]["parts"] = ["bracket"]
    (tmp_path / "c.yaml").write_text(yaml.safe_dump(cfg))
    monkeypatch.chdir("/")  # the working directory must not matter
    loaded = load_config(tmp_path / "c.yaml")
    (part,) = family_parts("cad", loaded["families"]["cad"])
    assert part.name == "bracket" and part.area == pytest.approx(900.0) and not part.is_convex
    cfg["families"]["cad"]["parts"][0]["outline"] = "cad/missing.dxf"
    (tmp_path / "c.yaml").write_text(yaml.safe_dump(cfg))
    with pytest.raises(PinfeedError, match="family cad, part bracket: no outline file at .*missing.dxf"):
        load_config(tmp_path / "c.yaml")


def test_cli_rollout_from_outline(tmp_path, capsys):
    from pipeline.cli import main
    path = dxf_file(tmp_path / "slot.dxf", _slot_pieces)
    assert main(["rollout", "--outline", str(path), "--mu-c", "0.2", "--pin-radius", "3",
                 "--theta-i", "30", "--d", "0.3", "--json"]) == 0
    cap = capsys.readouterr()
    assert "vertices (chordal tolerance 0.05 mm)" in cap.err
    assert json.loads(cap.out)[0]["theta_i"] == 30.0
    assert main(["rollout", "--outline", str(tmp_path / "nope.svg"), "--mu-c", "0.2",
                 "--pin-radius", "3", "--theta-i", "30", "--d", "0.3"]) == 2
    assert capsys.readouterr().err.startswith("pinfeed: error: no outline file")


def test_svg_hole_reads_and_is_named(tmp_path):
    body = '<path id="ring" fill-rule="evenodd" d="M0,0 H40 V40 H0 Z M10,10 H20 V20 H10 Z"/>'
    out = read_outline(_svg(tmp_path / "ring.svg", body))
    assert out.name == "<path id='ring'> subpath 1" and out.hole_names == ["<path id='ring'> subpath 2"]
    assert "1 hole (4 vertices)" in out.describe()
    # Material: the 40 x 40 square less the 10 x 10 one, centroid (20.333, 20.333) in SVG's frame
    # (y down); the farthest corner is the square's (0, 0), flipped or not.
    c = (1600 * 20 - 100 * 15) / 1500
    assert out.part().area == pytest.approx(1500) and out.a == pytest.approx(c * math.sqrt(2), rel=1e-12)


@pytest.mark.parametrize("part, message", [
    ({"name": "x", "vertices": [[0, 0], [1, 0], [0, 1]], "outline": "x.dxf"}, "not both"),
    ({"name": "x"}, "give either vertices or outline"),
    ({"name": "x", "vertices": [[0, 0], [1, 0], [0, 1]], "layer": "A"}, "layer only apply to an outline"),
])
def test_config_part_needs_vertices_or_outline(part, message):
    import yaml

    from pipeline.config import DEFAULT_CONFIG, validate_config
    from pipeline.errors import PinfeedError
    cfg = yaml.safe_load(DEFAULT_CONFIG.read_text())
    cfg["families"] = {"cad": {"parts": [part]}}
    cfg["planner"]["parts"] = []
    with pytest.raises(PinfeedError, match=f"families/cad/parts/0: .*{message}"):
        validate_config(cfg)


def test_validated_config_validates_again(tmp_path):
    import yaml

    from pipeline.config import DEFAULT_CONFIG, validate_config
    dxf_file(tmp_path / "l.dxf", _bracket)
    cfg = yaml.safe_load(DEFAULT_CONFIG.read_text())
    cfg["families"]["cad"] = {"parts": [{"name": "bracket", "outline": str(tmp_path / "l.dxf")}]}
    once = validate_config(cfg)
    assert validate_config(once) == once  # the Snakefile and rule scripts validate again


def test_crossing_outlines_and_block_references(tmp_path):
    def crossing(msp):
        _bracket(msp)
        msp.add_lwpolyline([(5, 5), (80, 5), (80, 8), (5, 8)], close=True)
    with pytest.raises(OutlineError, match="cross each other"):
        read_outline(dxf_file(tmp_path / "cross.dxf", crossing))
    doc = ezdxf.new()
    doc.header["$INSUNITS"] = 4  # mm (ezdxf's new documents default to metres)
    block = doc.blocks.new(name="BRACKET")
    _bracket(block)
    doc.modelspace().add_blockref("BRACKET", (100, 50))
    doc.saveas(tmp_path / "block.dxf")
    out = read_outline(tmp_path / "block.dxf")
    assert out.vertices.min(0) == pytest.approx([100, 50]) and _area(out.vertices) == pytest.approx(900)
