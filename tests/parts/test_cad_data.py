"""The committed CAD corpus (tests/data/cad, SOURCES.md): each file and what it
must give. Expected areas, centroids and ``a`` are worked out here from the
geometry each file is said to hold (make_corpus.py's docstrings), not taken
from the reader: the material is the outline less its holes, and a flattened
circle or arc (chords inside the curve) is short of the true area by at most
its length times the chordal tolerance."""
import math
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

ezdxf = pytest.importorskip("ezdxf")
pytest.importorskip("svgelements")

from pipeline.parts.outlines import OutlineError, read_outline, read_parts, read_sheet  # noqa: E402

CAD = Path(__file__).resolve().parents[1] / "data" / "cad"
TUTORIAL = Path(__file__).resolve().parents[2] / "docs" / "tutorials" / "holed_bracket.dxf"
TOL = 0.05  # mm: the chordal tolerance these tests read with


def _area(xy):
    x, y = xy[:, 0], xy[:, 1]
    return 0.5 * abs(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1)))


def _circle(c, r):
    """(area, centroid, length of curve) of a disc."""
    return math.pi * r * r, np.array(c, float), 2 * math.pi * r


def _slot(c1, c2, r):
    """(area, centroid, length of curve) of a rounded slot between centres c1 and c2 (radius r)."""
    c1, c2 = np.array(c1, float), np.array(c2, float)
    return 2 * r * float(np.hypot(*(c2 - c1))) + math.pi * r * r, (c1 + c2) / 2, 2 * math.pi * r


def _rect(x0, y0, x1, y1):
    return (x1 - x0) * (y1 - y0), np.array([(x0 + x1) / 2, (y0 + y1) / 2]), 0.0


def _material(outer, holes, boundary, shrink=0.0):
    """Area and ``a`` of ``outer`` less ``holes`` (each (area, centroid, curve length)),
    ``a`` the largest distance from the centroid to the points ``boundary`` of the
    outline; ``shrink``: the chordal tolerance by which the holes' areas may fall short."""
    area = outer[0] - sum(h[0] - shrink * h[2] for h in holes)
    moment = outer[0] * outer[1] - sum((h[0] - shrink * h[2]) * h[1] for h in holes)
    c = moment / area
    return area, float(np.max(np.hypot(*(np.asarray(boundary, float) - c).T)))


def _check_part(out, outer, holes, boundary, n_holes):
    """The outline's holes, area and ``a`` against the geometry (``a`` to 0.1 %, for
    holes flattened anywhere between exact and the chordal tolerance short)."""
    assert len(out.holes) == n_holes and f"{n_holes} hole" in out.describe()
    part = out.part()
    exact_area, exact_a = _material(outer, holes, boundary)
    curve = outer[2] + sum(h[2] for h in holes)
    assert exact_area - outer[2] * out.flatten_tol - 1e-9 <= part.area <= exact_area + curve * out.flatten_tol
    _, shrunk_a = _material(outer, holes, boundary, shrink=out.flatten_tol)
    assert min(exact_a, shrunk_a) * (1 - 1e-3) <= out.a <= max(exact_a, shrunk_a) * (1 + 1e-3)
    assert out.a == pytest.approx(exact_a, rel=1e-3)
    return part


def _one_line(path, *needles, **kw):
    with pytest.raises(OutlineError) as exc:
        read_outline(path, **kw)
    text = str(exc.value)
    assert "\n" not in text and text.startswith(str(path)), text
    for needle in needles:
        assert needle in text, text
    return text


def _handles(path, query):
    return [e.dxf.handle for e in ezdxf.readfile(str(path)).modelspace().query(query)]


# ---------------------------------------------------------------- parts with holes

BRACKET = _rect(0, 0, 50, 40)
BRACKET_HOLES = [_circle((8, 32), 3.25), _circle((42, 32), 3.25), _slot((18, 14), (32, 14), 3.5)]
BRACKET_CORNERS = [(0, 0), (50, 0), (50, 40), (0, 40)]


def test_holed_bracket():
    path = CAD / "holed_bracket.dxf"
    out = read_outline(path, flatten_tol=TOL)
    assert out.n_vertices == 4 and out.layer == "OUTLINE" and not out.left_out
    assert sorted(out.hole_layers) == ["HOLES", "HOLES", "OUTLINE"] and "2 on layer HOLES" in out.describe()
    assert "units mm from $INSUNITS=4" in out.describe()
    _check_part(out, BRACKET, BRACKET_HOLES, BRACKET_CORNERS, 3)


GUSSET_CORNERS = [(0, 0), (50, 0), (50, 6), (6, 40), (0, 40)]


def _polygon(xy):
    """(area, centroid, 0) of a simple polygon (the shoelace sums)."""
    xy = np.asarray(xy, float)
    x, y = xy[:, 0], xy[:, 1]
    xn, yn = np.roll(x, -1), np.roll(y, -1)
    cross = x * yn - xn * y
    area = 0.5 * cross.sum()
    return abs(area), np.array([((x + xn) * cross).sum(), ((y + yn) * cross).sum()]) / (6 * area), 0.0


@pytest.mark.parametrize("path", [CAD / "gusset_bracket.dxf", TUTORIAL])
def test_gusset_bracket_of_the_tutorial(path):
    out = read_outline(path, flatten_tol=TOL)
    assert out.n_vertices == 5 and out.layer == "PART" and not out.left_out
    holes = [_circle((8, 8), 3.25), _circle((8, 30), 3.25), _slot((20, 10), (32, 10), 3.25)]
    _check_part(out, _polygon(GUSSET_CORNERS), holes, GUSSET_CORNERS, 3)


def test_tutorial_bracket_is_the_corpus_one():
    assert TUTORIAL.read_bytes() == (CAD / "gusset_bracket.dxf").read_bytes()


def test_inkscape1_bracket_is_the_dxf_bracket():
    out = read_outline(CAD / "inkscape1_bracket.svg", flatten_tol=TOL)
    assert "units mm from SVG width/viewBox (100mm over 100 user units)" in out.describe()
    # y down on the page: the layer's (0, 0) at (10, 20) is (10, -20) in the drawing frame, the
    # plate spanning y -60..-20 mm; the same part as the DXF's, moved.
    assert out.vertices.min(axis=0) == pytest.approx([10, -60])
    assert out.vertices.max(axis=0) == pytest.approx([60, -20])
    assert sorted(out.hole_names) == ["<circle id='hole-left'>", "<circle id='hole-right'>", "<path id='slot'>"]
    part = _check_part(out, BRACKET, BRACKET_HOLES, BRACKET_CORNERS, 3)
    dxf = read_outline(CAD / "holed_bracket.dxf", flatten_tol=TOL).part()
    assert part.area == pytest.approx(dxf.area, rel=1e-4) and part.a == pytest.approx(dxf.a, rel=1e-4)


def test_plate_offcentre_r12():
    out = read_outline(CAD / "plate_offcentre_r12.dxf", flatten_tol=TOL)
    assert "POLYLINE" in out.name and out.n_vertices == 4
    assert "units mm from the default (unitless DXF" in out.describe()  # R12 has no $INSUNITS
    _check_part(out, _rect(0, 0, 80, 50), [_circle((55, 25), 15)], [(0, 0), (80, 0), (80, 50), (0, 50)], 1)


def _stadium_boundary(c1, c2, r, n=3600):
    """Points of a slot's true outline, dense."""
    t = np.linspace(0, 2 * np.pi, n, endpoint=False)
    ring = np.column_stack([np.cos(t), np.sin(t)]) * r
    return np.vstack([ring + c1, ring + c2])  # the farthest point lies on an end's circle


def test_lever_r2000():
    out = read_outline(CAD / "lever_r2000.dxf", flatten_tol=TOL)
    assert out.name.startswith("LWPOLYLINE") and out.layer == "CONTOUR"
    # The outline: two half circles of radius 12, each at least the chords of the tolerance's regular
    # polygon (ezdxf halves its curves: up to twice that), and the two corners between.
    least = 2 * math.ceil(math.pi / (2 * math.acos(1 - TOL / 12))) + 2
    assert least <= out.n_vertices <= 2 * least
    spline = [h for h, n in zip(out.holes, out.hole_names) if n.startswith("SPLINE")]
    assert len(spline) == 1 and len(spline[0]) <= 40  # the rational SPLINE circle, not hundreds of points
    assert np.hypot(*(spline[0] - [80, 0]).T) == pytest.approx(5, abs=1e-9)  # on the true circle
    (centre_line,) = out.left_out  # the dimensions' LINEs sit in DIMENSION blocks: never read
    assert "LINE" in centre_line and "linetype CENTER" in centre_line
    outer = _slot((0, 0), (120, 0), 12)
    holes = [_circle((0, 0), 6), _circle((120, 0), 4), _circle((40, 0), 3), _circle((80, 0), 5)]
    _check_part(out, outer, holes, _stadium_boundary((0, 0), (120, 0), 12), 4)


def test_title_block_r2000():
    out = read_outline(CAD / "title_block_r2000.dxf", flatten_tol=TOL)
    assert out.layer == "PART" and out.n_vertices == 6
    (frame,) = [item for item in out.left_out if item.startswith("drawing frame on layer TITLE")]
    assert "297 x 210 mm" in frame and "--layer TITLE" in frame
    # The L: 60 x 10 foot plus a 10 x 30 upright, from (50, 60); a hole of radius 3 at (55, 65).
    foot, upright = _rect(50, 60, 110, 70), _rect(50, 70, 60, 100)
    outer = (900.0, (foot[0] * foot[1] + upright[0] * upright[1]) / 900, 0.0)
    corners = [(50, 60), (110, 60), (110, 70), (60, 70), (60, 100), (50, 100)]
    _check_part(out, outer, [_circle((55, 65), 3)], corners, 1)


def test_insert_blocks_r2000():
    path = CAD / "insert_blocks_r2000.dxf"
    (insert,) = _handles(path, "INSERT")
    out = read_outline(path, flatten_tol=TOL)
    assert out.name == f"LWPOLYLINE in block PLATE (INSERT {insert}) on layer PARTS"
    assert out.hole_names == [f"CIRCLE in block HOLE in block PLATE (INSERT {insert}) on layer PARTS"] * 3
    # The plate turned 30 deg about the insertion point (100, 50).
    c, s = math.cos(math.radians(30)), math.sin(math.radians(30))
    corners = np.array([(0, 0), (40, 0), (40, 25), (0, 25)])
    placed = corners @ np.array([[c, s], [-s, c]]) + [100, 50]
    assert sorted(map(tuple, np.round(out.vertices, 9))) == sorted(map(tuple, np.round(placed, 9)))
    (mark,) = out.left_out
    assert "CIRCLE" in mark and "on layer 0" in mark and "--layer 0" in mark
    holes = [_circle(xy, 2.5) for xy in ((8, 8), (32, 8), (20, 17))]
    _check_part(out, _rect(0, 0, 40, 25), holes, corners, 3)  # a turn changes neither area nor a
    assert read_outline(path, id=insert).name == out.name and len(read_outline(path, layer="PARTS").holes) == 3
    assert read_outline(path, layer="0").n_vertices < 30  # the locating mark alone


def test_construction_r2010():
    out = read_outline(CAD / "construction_r2010.dxf", flatten_tol=TOL)
    assert out.layer == "vector" and "chain of 4 pieces" in out.name and not out.joined_layers
    assert len(out.left_out) == 2 and all("on layer construction" in item for item in out.left_out)
    # A 40 x 30 rectangle and a half disc (radius 15, centre (40, 15): centroid 20/pi further right).
    half = (math.pi * 15 ** 2 / 2, np.array([40 + 4 * 15 / (3 * math.pi), 15]), math.pi * 15)
    rect = _rect(0, 0, 40, 30)
    outer = (rect[0] + half[0], (rect[0] * rect[1] + half[0] * half[1]) / (rect[0] + half[0]), half[2])
    t = np.linspace(-np.pi / 2, np.pi / 2, 1801)
    boundary = np.vstack([[(0, 0), (0, 30)], np.column_stack([40 + 15 * np.cos(t), 15 + 15 * np.sin(t)])])
    _check_part(out, outer, [_circle((40, 15), 5)], boundary, 1)


def test_inkscape048_plate_90_px_per_inch():
    path = CAD / "inkscape048_plate.svg"
    out = read_outline(path, flatten_tol=TOL)
    assert "units px from SVG user units (Inkscape 0.48 file: 90 px per inch" in out.describe()
    assert out.size_mm[:2] == pytest.approx((50.8, 25.4), rel=1e-12)  # 180 x 90 px at 90 per inch
    # The hole: 36 px (10.16 mm) across, 45 px (12.7 mm) from the left edge, half way down.
    _check_part(out, _rect(0, 0, 50.8, 25.4), [_circle((12.7, 12.7), 5.08)],
                [(0, 0), (50.8, 0), (50.8, 25.4), (0, 25.4)], 1)
    over = read_outline(path, units="mm")  # --units keeps overriding
    assert over.size_mm[:2] == pytest.approx((180, 90), rel=1e-12) and "from --units" in over.describe()


def test_island_r2010_is_a_part_of_its_own():
    path = CAD / "island_r2010.dxf"
    island = _handles(path, "CIRCLE[radius<6]")[0]
    out = read_outline(path)  # the washer (radius 20 with its hole of 10); the disc in the hole is named
    assert len(out.holes) == 1 and out.label == "island_r2010.dxf#0"
    (other,) = out.left_out
    assert "island_r2010.dxf#1 (CIRCLE" in other and f"--id {island}" in other
    disc = read_outline(path, id=island)  # the way to plan it
    assert not disc.holes and disc.n_vertices >= 8 and disc.label == "island_r2010.dxf#1"


# ---------------------------------------------------------------- several parts on one sheet


def _half_disc(c, r, side):
    """(area, centroid, length of curve) of the half disc of centre c, radius r, on the ``side`` (+1 right, -1 left)."""
    return math.pi * r * r / 2, np.array(c, float) + [side * 4 * r / (3 * math.pi), 0.0], math.pi * r


def _union(*shapes):
    """(area, centroid, length of curve) of shapes that do not overlap."""
    area = sum(s[0] for s in shapes)
    return area, sum(s[0] * s[1] for s in shapes) / area, sum(s[2] for s in shapes)


LEVER_TRAPEZOID = [(0, -20), (80, -10), (80, 10), (0, 20)]


def _lever_boundary(n=3601):
    """Points of the lever's true outline: the half circles (radius 20 at (0, 0) on the left,
    10 at (80, 0) on the right) and the corners between."""
    t = np.linspace(np.pi / 2, 3 * np.pi / 2, n)
    left = np.column_stack([20 * np.cos(t), 20 * np.sin(t)])
    right = np.column_stack([80 - 10 * np.cos(t), 10 * np.sin(t)])
    return np.vstack([left, right, LEVER_TRAPEZOID])


def test_lever_with_a_washer_in_its_bore():
    path = CAD / "lever_washer_r2010.dxf"
    out = read_outline(path, flatten_tol=TOL)
    assert out.name.startswith("chain of 4 pieces") and out.label == "lever_washer_r2010.dxf#0"
    outer = _union(_polygon(LEVER_TRAPEZOID), _half_disc((0, 0), 20, -1), _half_disc((80, 0), 10, +1))
    _check_part(out, outer, [_circle((0, 0), 11), _circle((80, 0), 4)], _lever_boundary(), 2)
    # The washer, its circles in the bore, is named in one warning with the ways to plan it.
    (washer,) = _handles(path, "CIRCLE[radius==9]")
    (washer_hole,) = _handles(path, "CIRCLE[radius==5.5]")
    (bore,) = _handles(path, "CIRCLE[radius==11]")
    (other,) = out.left_out
    assert other.startswith("1 other part of this drawing: lever_washer_r2010.dxf#1 (CIRCLE")
    assert "1 hole" in other and f"--id {washer}" in other and "--id lever_washer_r2010.dxf#1" in other
    warnings = out.warnings()
    assert len(warnings) == 1 and "left out 1 other part" in warnings[0]
    # --id of any piece of the lever (a LINE of its chain, its bore) picks the lever.
    for piece in _handles(path, "LINE") + [bore]:
        assert read_outline(path, id=piece, flatten_tol=TOL).name == out.name
    # --id of the washer's circles, or its index, picks the washer: a ring.
    for pick in (washer, washer_hole, "lever_washer_r2010.dxf#1", "#1"):
        ring = read_outline(path, id=pick, flatten_tol=TOL)
        assert ring.name == f"CIRCLE {washer} on layer STANDARD" and ring.label == "lever_washer_r2010.dxf#1"
        _check_part(ring, _circle((0, 0), 9), [_circle((0, 0), 5.5)], _stadium_boundary((0, 0), (0, 0), 9), 1)
        assert "lever_washer_r2010.dxf#0 (chain of 4 pieces" in ring.left_out[0]
    with pytest.raises(OutlineError, match=r"no part #2: the drawing holds 2 parts \(#0 to #1\)"):
        read_outline(path, id="lever_washer_r2010.dxf#2")
    assert [label for label, _ in read_parts(path)] == ["lever_washer_r2010.dxf#0", "lever_washer_r2010.dxf#1"]


def test_sheet_of_three_parts_by_index():
    path = CAD / "sheet_three_parts_r2000.dxf"
    parts = read_parts(path, flatten_tol=TOL)
    # Largest first; the two equal squares left to right (the one at x = 100 is drawn first).
    assert [label for label, _ in parts] == [f"sheet_three_parts_r2000.dxf#{k}" for k in range(3)]
    assert [tuple(o.vertices.min(axis=0)) for _, o in parts] == [(0, 0), (60, 0), (100, 0)]
    assert [len(o.holes) for _, o in parts] == [1, 0, 0]
    _check_part(parts[0][1], _rect(0, 0, 40, 30), [_circle((20, 15), 5)], [(0, 0), (40, 0), (40, 30), (0, 30)], 1)
    for _, square in parts[1:]:
        assert square.part().area == pytest.approx(400)
    out = read_outline(path, flatten_tol=TOL)
    (other,) = out.left_out
    assert other.startswith("2 other parts of this drawing: sheet_three_parts_r2000.dxf#1 (LWPOLYLINE")
    assert "sheet_three_parts_r2000.dxf#2 (LWPOLYLINE" in other
    assert tuple(read_outline(path, id="2").vertices.min(axis=0)) == (100, 0)  # no entity has handle 2
    sheet = read_sheet(path)
    assert not sheet.left_out and not sheet.refused and len(sheet.parts) == 3


def test_frame_on_the_parts_layer_with_a_title_block():
    path = CAD / "frame_same_layer_r2000.dxf"
    out = read_outline(path, flatten_tol=TOL)
    assert out.name.startswith("LWPOLYLINE") and out.n_vertices == 6 and out.n_parts == 1
    (frame,) = out.left_out  # the title block's lines go with the frame: no open chains left over
    assert frame.startswith("drawing frame chain of 4 pieces from LINE") and "250 x 180 mm" in frame
    assert "a title block of 3 piece(s) in a corner" in frame and "--id" in frame
    foot, upright = _rect(50, 60, 110, 70), _rect(50, 70, 60, 100)
    corners = [(50, 60), (110, 60), (110, 70), (60, 70), (60, 100), (50, 100)]
    _check_part(out, _union(foot, upright), [_circle((55, 65), 3)], corners, 1)
    first = _handles(path, "LINE")[0]  # the frame's first LINE: --id keeps the frame, as a part
    assert read_outline(path, id=first).size_mm[:2] == pytest.approx((250, 180))


def test_inkscape_layers_part_and_dimensions():
    path = CAD / "inkscape_layers.svg"
    out = read_outline(path, flatten_tol=TOL)
    # The box on layer Dimensions is larger, but a dimensions layer is construction geometry; the
    # dimension lines touch the plate's corners but are never joined into it (another layer).
    assert "on layer Part" in out.name and out.layer == "Part" and out.n_vertices == 4
    assert out.hole_names == ["<circle id='bore'> on layer Part"]
    _check_part(out, _rect(10, -50, 70, -10), [_circle((40, -30), 6)], [(10, -50), (70, -50), (70, -10), (10, -10)], 1)
    assert any("<rect id='box'> on layer Dimensions" in item and "construction" in item for item in out.left_out)
    part = read_outline(path, layer="Part", flatten_tol=TOL)
    assert part.name == out.name and not part.left_out
    assert read_outline(path, layer="Dimensions").size_mm[:2] == pytest.approx((70, 50))
    with pytest.raises(OutlineError, match="on layer 'Nope'; give one of the drawing's layers .*Dimensions, Part"):
        read_outline(path, layer="Nope")


def test_inkscape_two_parts_on_two_layers():
    path = CAD / "inkscape_two_parts.svg"
    out = read_outline(path, flatten_tol=TOL)
    assert out.name == "<rect id='bracket'> on layer Bracket" and len(out.holes) == 1
    (other,) = out.left_out
    assert "inkscape_two_parts.svg#1 (<circle id='washer'> on layer Washer, 1 hole" in other
    assert "--id washer" in other
    for kw in ({"layer": "Washer"}, {"id": "washer-hole"}, {"id": "inkscape_two_parts.svg#1"}):
        ring = read_outline(path, flatten_tol=TOL, **kw)
        assert ring.name == "<circle id='washer'> on layer Washer"
        _check_part(ring, _circle((80, -25), 9), [_circle((80, -25), 5.5)],
                    _stadium_boundary((80, -25), (80, -25), 9), 1)
    assert [o.layer for _, o in read_parts(path)] == ["Bracket", "Washer"]


def test_cli_rollout_of_the_lever_warns_of_the_washer(capsys):
    from pipeline.cli import main
    path = CAD / "lever_washer_r2010.dxf"
    assert main(["rollout", "--outline", str(path), "--theta-i", "0", "--d", "0.3", "--mu-c", "0.2",
                 "--pin-radius", "3"]) == 0
    err = capsys.readouterr().err
    assert "chain of 4 pieces" in err and "2 holes" in err
    (warning,) = [line for line in err.splitlines() if line.startswith("pinfeed: warning:")]
    assert "1 other part of this drawing: lever_washer_r2010.dxf#1" in warning
    assert main(["rollout", "--outline", str(path), "--id", "lever_washer_r2010.dxf#1", "--theta-i", "0",
                 "--d", "0.3", "--mu-c", "0.2", "--pin-radius", "3"]) == 0
    assert "CIRCLE" in capsys.readouterr().err


# ---------------------------------------------------------------- refused: one line, the problem and the way out


def test_arc_bridged_by_construction_lines():
    _one_line(CAD / "arc_bridged_r2010.dxf", "open outline: ARC", "closes only through LINE",
              "on layer construction", "never joined into an outline", "draw it closed on layer vector",
              "--layer NAME (layers construction, vector)")


def test_notch_r12():
    _one_line(CAD / "notch_r12.dxf", "POLYLINE", "cross or touch",
              "an opening to the outline is a notch: draw it as part of the outline")


def test_open_path_svg():
    _one_line(CAD / "open_path.svg", "open outline: <path id='outline'>", "2.000 mm from its start",
              "--join-tol", "--id washer")
    assert read_outline(CAD / "open_path.svg", join_tol=2.5).n_vertices == 4  # the way out


# ---------------------------------------------------------------- the corpus is what make_corpus.py writes


def test_corpus_is_reproducible(tmp_path):
    made = subprocess.run([sys.executable, str(CAD / "make_corpus.py"), str(tmp_path)], capture_output=True,
                          text=True, env=dict(os.environ), timeout=120)
    assert made.returncode == 0, made.stderr
    written = sorted(p.name for p in tmp_path.iterdir())
    assert written == sorted(p.name for p in CAD.iterdir() if p.suffix in (".dxf", ".svg"))
    for name in written:
        assert (tmp_path / name).read_bytes() == (CAD / name).read_bytes(), name
    sources = (CAD / "SOURCES.md").read_text()
    assert all(f"`{name}`" in sources for name in written)
