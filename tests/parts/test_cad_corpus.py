"""CAD outlines as CAD tools write them (issue 26): a corpus of DXF and SVG
files built here with ezdxf (no binary files checked in), each compared with
the same part given as vertices, by its rollouts at a few (theta_i, d)."""
import functools
import math
import random

import numpy as np
import pytest

ezdxf = pytest.importorskip("ezdxf")
pytest.importorskip("svgelements")

from cli_runs import run_cli  # noqa: E402
from pipeline.maps.simulate import rollout  # noqa: E402
from pipeline.parts.outlines import read_outline  # noqa: E402
from pipeline.parts.part import Part  # noqa: E402
from cad_files import dxf_file

L_XY = [(0, 0), (60, 0), (60, 10), (10, 10), (10, 40), (0, 40)]  # L-bracket, mm
SL, R = 40.0, 10.0  # slot: centre distance and end radius, mm
POINTS = [(30.0, 0.3), (100.0, -0.3), (200.0, 0.6), (310.0, -0.1)]  # (theta_i deg, d)


def _states(part):
    """(status, theta_f) of the rollouts at POINTS (minpower, mu_c 0.2, pin radius 3 mm)."""
    out = []
    for theta_i, d in POINTS:
        r = rollout(part, theta_i, d, 0.2, 3.0)
        out.append((str(r["status"].values), float(r["theta_f"])))
    return out


def _assert_same_rollouts(part, reference, tol_deg):
    for (s1, t1), (s2, t2) in zip(_states(part), _states(reference)):
        assert s1 == s2 and abs((t1 - t2 + 180.0) % 360.0 - 180.0) <= tol_deg, (s1, t1, s2, t2)


def _fine_slot(sagitta=1e-3):
    """The slot's true outline, flattened much finer than any test tolerance."""
    n = int(math.ceil(math.pi / (2 * math.acos(1 - sagitta / R))))
    right = [(SL + R * math.cos(t), R * math.sin(t)) for t in np.linspace(-math.pi / 2, math.pi / 2, n + 1)]
    left = [(R * math.cos(t), R * math.sin(t)) for t in np.linspace(math.pi / 2, 3 * math.pi / 2, n + 1)]
    return Part.from_vertices(right + left, name="slot")


@functools.lru_cache(maxsize=1)
def _fine():
    return _fine_slot()


def _shuffled_lines(msp, xy=L_XY, seed=3, scale=1.0):
    """The polygon's edges as loose LINEs: shuffled, about half drawn backwards."""
    rng = random.Random(seed)
    edges = [(xy[k], xy[(k + 1) % len(xy)]) for k in range(len(xy))]
    rng.shuffle(edges)
    for a, b in edges:
        a, b = (b, a) if rng.random() < 0.5 else (a, b)
        msp.add_line(np.multiply(a, scale).tolist(), np.multiply(b, scale).tolist())


# ---------------------------------------------------------------- exact polygons: 1e-6 deg


def _l_lines(msp):
    _shuffled_lines(msp)


def _l_lines_duplicated(msp):
    _shuffled_lines(msp)
    msp.add_line(L_XY[3], L_XY[2])  # a duplicate, drawn backwards
    msp.add_line(L_XY[0], L_XY[1])  # and one as drawn


def _l_polyline2d(msp):
    msp.add_polyline2d(L_XY[::-1], close=True)  # old-style POLYLINE, clockwise


def _l_two_open_lwpolylines(msp):
    msp.add_lwpolyline(L_XY[:4])
    msp.add_lwpolyline([L_XY[0], L_XY[5], L_XY[4], L_XY[3]])  # the rest, from the other end


@pytest.mark.parametrize("build", [_l_lines, _l_lines_duplicated, _l_polyline2d, _l_two_open_lwpolylines])
def test_exact_polygon_from_dxf_is_the_vertices_part(tmp_path, build):
    out = read_outline(dxf_file(tmp_path / "l.dxf", build))
    part = Part.from_vertices(out.vertices, name="l")
    reference = Part.from_vertices(L_XY, name="l")
    assert part.id == reference.id and out.n_vertices == 6 and not out.left_out
    _assert_same_rollouts(part, reference, 1e-6)


def test_issue_l_bracket_of_six_shuffled_lines_reads(tmp_path):
    # The issue's crash: six LINEs out of order (list.remove compared numpy arrays).
    for seed in range(5):
        out = read_outline(dxf_file(tmp_path / f"l{seed}.dxf", lambda m, s=seed: _shuffled_lines(m, seed=s)))
        assert Part.from_vertices(out.vertices, name="l").id == Part.from_vertices(L_XY, name="l").id


def test_svg_polygon_with_transform_has_the_dxf_part_id(tmp_path):
    # svgelements' mm is 1.00000054 CSS mm: unfixed, the SVG part got another id.
    flipped = " ".join(f"{x},{40 - y}" for x, y in L_XY)  # y down in SVG
    path = tmp_path / "l.svg"
    path.write_text('<svg xmlns="http://www.w3.org/2000/svg" width="200mm" height="100mm" '
                    f'viewBox="0 0 200 100"><g transform="translate(17,5)"><polygon points="{flipped}"/>'
                    '</g></svg>')
    svg_part = Part.from_vertices(read_outline(path).vertices, name="l")
    dxf_part = Part.from_vertices(read_outline(dxf_file(tmp_path / "l.dxf", _l_lines)).vertices, name="l")
    assert svg_part.id == dxf_part.id == Part.from_vertices(L_XY, name="l").id
    _assert_same_rollouts(svg_part, dxf_part, 1e-6)


# ---------------------------------------------------------------- arcs: 0.5 deg of a fine flattening


def _slot_issue(msp):
    # The issue's slot: one arc -90..90, the other 90..270; shuffled, a line reversed.
    msp.add_arc((0, 0), R, 90, 270)
    msp.add_line((SL, R), (0, R))
    msp.add_arc((SL, 0), R, -90, 90)
    msp.add_line((0, -R), (SL, -R))


def _slot_crossing_zero_negative_start(msp):
    msp.add_line((SL, R), (0, R))
    msp.add_arc((0, 0), R, -270, -90)  # negative start angle
    msp.add_line((SL, -R), (0, -R))
    msp.add_arc((SL, 0), R, 270, 90)  # runs through 0 deg


def _slot_gaps_and_duplicates(msp):
    gap = 2e-4  # mm: under the default join tolerance (1e-4 of 60 mm = 6e-3)
    msp.add_line((0, -R), (SL - gap, -R))
    msp.add_arc((SL, 0), R, -90, 90)
    msp.add_arc((SL, 0), R, -90, 90)  # exported twice
    msp.add_line((SL, R + gap), (gap, R))
    msp.add_arc((0, 0), R, 90, 270)


def _slot_bulged_open_lwpolylines(msp):
    # Each half: a straight edge then a half circle (bulge 1 = 180 deg); the second drawn backwards.
    msp.add_lwpolyline([(0, -R, 0, 0, 0), (SL, -R, 0, 0, 1), (SL, R)], format="xyseb")
    msp.add_lwpolyline([(0, -R, 0, 0, -1), (0, R, 0, 0, 0), (SL, R)], format="xyseb")


def _slot_closed_bulges(msp):
    msp.add_lwpolyline([(0, -R, 0, 0, 0), (SL, -R, 0, 0, 1), (SL, R, 0, 0, 0), (0, R, 0, 0, 1)],
                       format="xyseb", close=True)


@pytest.mark.parametrize("build", [_slot_issue, _slot_crossing_zero_negative_start,
                                   _slot_gaps_and_duplicates, _slot_bulged_open_lwpolylines,
                                   _slot_closed_bulges])
def test_slot_with_arcs_rolls_like_the_fine_slot(tmp_path, build):
    out = read_outline(dxf_file(tmp_path / "slot.dxf", build), flatten_tol=0.05)
    assert not out.left_out
    part = Part.from_vertices(out.vertices, name="slot")
    assert part.a == pytest.approx(SL / 2 + R, abs=0.05)
    _assert_same_rollouts(part, _fine(), 0.5)


SLOT_D = f"M 0,-{R} L {SL},-{R} A {R} {R} 0 0 1 {SL} {R} L 0 {R} A {R} {R} 0 0 1 0 -{R} Z"


@pytest.mark.parametrize("transform, turn", [("translate(30,40) scale(0.5)", 0.0),
                                             ("translate(50,50) rotate(30)", -30.0)])
def test_svg_slot_with_transforms_and_arcs(tmp_path, transform, turn):
    d = SLOT_D if "scale" not in transform else SLOT_D.replace(f"{R}", f"{2 * R}").replace(f"{SL}", f"{2 * SL}")
    path = tmp_path / "slot.svg"
    path.write_text('<svg xmlns="http://www.w3.org/2000/svg" width="100mm" height="100mm" '
                    f'viewBox="0 0 100 100"><g transform="{transform}"><path d="{d}"/></g></svg>')
    part = Part.from_vertices(read_outline(path, flatten_tol=0.05).vertices, name="slot")
    # SVG's y points down: a turn of +30 deg on screen is -30 deg in the y-up drawing frame.
    reference = _fine().rotated(turn) if turn else _fine()
    _assert_same_rollouts(part, reference, 0.5)


def test_centre_line_longer_than_the_part_is_left_out(tmp_path):
    def build(msp):
        _slot_issue(msp)
        msp.add_line((-20, 0), (SL + 20, 0), dxfattribs={"layer": "CENTER"})  # 80 mm, across the slot
    out = read_outline(dxf_file(tmp_path / "c.dxf", build))
    assert "chain of 4 pieces" in out.name
    assert len(out.left_out) == 1 and "open chain LINE" in out.left_out[0] and "80 mm apart" in out.left_out[0]


def test_ellipse_and_spline_pieces_join(tmp_path):
    def build(msp):
        # A D shape: the right half of an ellipse (semi-axes 20, 10) closed by a SPLINE through
        # the left side, drawn from the other end.
        msp.add_ellipse((0, 0), major_axis=(20, 0), ratio=0.5, start_param=-math.pi / 2,
                        end_param=math.pi / 2)
        msp.add_spline([(0, 10), (-5, 5), (-6, 0), (-5, -5), (0, -10)])
    out = read_outline(dxf_file(tmp_path / "d.dxf", build), flatten_tol=0.01)
    w, h, _ = out.size_mm
    assert "2 pieces" in out.name and w == pytest.approx(26, abs=0.5) and h == pytest.approx(20, abs=0.01)


# ---------------------------------------------------------------- units


def _l_scaled(factor):
    return lambda msp: _shuffled_lines(msp, scale=factor)


@pytest.mark.parametrize("insunits, factor, said", [(6, 1e-3, "units m from $INSUNITS=6, 1000 mm per unit"),
                                                    (1, 1 / 25.4, "units in from $INSUNITS=1, 25.4 mm"),
                                                    (0, 1.0, "units mm from the default (unitless DXF"),
                                                    (5, 0.1, "units cm from $INSUNITS=5")])
def test_declared_units_give_the_same_part(tmp_path, insunits, factor, said):
    out = read_outline(dxf_file(tmp_path / "l.dxf", _l_scaled(factor), insunits=insunits))
    assert Part.from_vertices(out.vertices, name="l").id == Part.from_vertices(L_XY, name="l").id
    assert said in out.describe() and "size 60 x 40 mm, a = 40.07 mm" in out.describe()
    assert not out.warnings()


def test_mm_drawing_declared_in_metres_warns_and_units_fixes_it(tmp_path, capsys):
    # ezdxf's new drawings default to metres: a drawing made in mm comes out 1000 times larger.
    path = dxf_file(tmp_path / "l.dxf", _l_lines, insunits=6)
    base = ["rollout", "--outline", str(path), "--mu-c", "0.2", "--pin-radius", "3", "--theta-i", "30",
            "--d", "0.3"]
    code, out, err = run_cli(capsys, base)
    assert code == 0 and "size 6e+04 x 4e+04 mm" in err
    warning = [line for line in err.splitlines() if line.startswith("pinfeed: warning:")]
    assert len(warning) == 1 and "6e+04 mm across" in warning[0] and "--units" in warning[0]
    code, out, err = run_cli(capsys, base + ["--units", "mm"])
    assert code == 0 and "units mm from --units" in err and "warning" not in err
    assert f"part {Part.from_vertices(L_XY, name='l').id}" in out


def test_tiny_part_warns(tmp_path):
    out = read_outline(dxf_file(tmp_path / "l.dxf", _l_scaled(1 / 100), insunits=4))
    assert any("0.6 mm across" in w and "--units" in w for w in out.warnings())


def test_svg_units_inch_and_override(tmp_path):
    path = tmp_path / "r.svg"
    path.write_text('<svg xmlns="http://www.w3.org/2000/svg" width="2in" height="1in" viewBox="0 0 200 100">'
                    '<rect x="0" y="0" width="50" height="20"/></svg>')
    out = read_outline(path)  # one user unit = 0.01 in = 0.254 mm
    assert out.size_mm[:2] == pytest.approx((12.7, 5.08), rel=1e-12)
    assert "SVG width/viewBox" in out.describe()
    over = read_outline(path, units="mm")  # user units taken as mm
    assert over.size_mm[:2] == pytest.approx((50, 20), rel=1e-12) and "from --units" in over.describe()


# ---------------------------------------------------------------- bad input: one line, exit 2


def _one_line_error(capsys, argv, *needles):
    code, _, err = run_cli(capsys, argv)
    lines = err.strip().splitlines()
    assert code == 2 and len(lines) == 1 and lines[0].startswith("pinfeed: error: "), err
    for needle in needles:
        assert needle in lines[0], lines[0]


def _rollout_args(path, *extra):
    return ["rollout", "--outline", str(path), "--mu-c", "0.2", "--pin-radius", "3", "--theta-i", "30",
            "--d", "0.3", *extra]


def test_bad_outlines_are_one_line_errors(tmp_path, capsys):
    def washer(msp):
        _slot_issue(msp)
        msp.add_circle((SL / 2, 0), 3, dxfattribs={"layer": "HOLES"})
    path = dxf_file(tmp_path / "washer.dxf", washer)
    out = read_outline(path)  # a hole on another layer is a hole (issue: parts with holes)
    assert len(out.holes) == 1 and out.hole_names[0].startswith("CIRCLE") and "1 on layer HOLES" in out.describe()
    assert not read_outline(path, layer="0").holes  # --layer reads one layer alone

    def island(msp):  # a disc in the hole: a separate part, named in a warning
        washer(msp)
        msp.add_circle((SL / 2, 0), 1, dxfattribs={"layer": "HOLES"})
    island_path = dxf_file(tmp_path / "island.dxf", island)
    code, _, err = run_cli(capsys, _rollout_args(island_path))
    warning = [line for line in err.splitlines() if "other part" in line]
    assert code == 0 and "chain of 4 pieces" in err and "1 hole" in err and len(warning) == 1
    assert "island.dxf#1 (CIRCLE" in warning[0] and "--id island.dxf#1" in warning[0]
    code, _, err = run_cli(capsys, _rollout_args(island_path, "--id", "island.dxf#1"))  # the disc alone
    assert code == 0 and "outline " + str(island_path) + ": CIRCLE" in err

    def gapped(msp):  # the L in two open polylines, 0.05 mm apart at (0, 0)
        msp.add_lwpolyline(L_XY[:4])
        msp.add_lwpolyline([(0, 0.05)] + L_XY[5:2:-1])
    gap_path = dxf_file(tmp_path / "gap.dxf", gapped)
    _one_line_error(capsys, _rollout_args(gap_path), "open outline", "0.050 mm from its start", "--join-tol")
    code, _, err = run_cli(capsys, _rollout_args(gap_path, "--join-tol", "0.1"))
    assert code == 0 and "6 vertices" in err
    _one_line_error(capsys, _rollout_args(gap_path, "--join-tol", "-1"), "--join-tol must be")
    _one_line_error(capsys, ["rollout", "--vertices", "0,0 60,0 15,35", "--units", "in", "--mu-c", "0.2",
                             "--pin-radius", "3", "--theta-i", "30", "--d", "0.3"], "--units", "--outline")


def test_zero_length_line_is_ignored(tmp_path):
    def build(msp):
        _shuffled_lines(msp)
        msp.add_line((0, 0), (0, 0))
    out = read_outline(dxf_file(tmp_path / "z.dxf", build))
    assert out.n_vertices == 6 and not out.left_out


def test_help_says_join_tol_units_and_holes(capsys):
    code, out, _ = run_cli(capsys, ["rollout", "--help"])
    text = " ".join(out.split())
    assert code == 0 and "in the drawing's units" in text and "the loops directly inside it its holes" in text
    assert "the largest part is read, the others are named in a warning" in text and "FILE#N" in text
    assert "--units {mm,cm,m,in}" in text


def test_config_part_takes_units_and_join_tol(tmp_path):
    import yaml

    from pipeline.config import DEFAULT_CONFIG, validate_config
    from pipeline.errors import PinfeedError
    from pipeline.parts.families import family_parts

    def gapped(msp):  # the L drawn in inches, read as mm unless told, 0.002 in apart at (0, 0)
        msp.add_lwpolyline(np.divide(L_XY[:4], 25.4).tolist())
        msp.add_lwpolyline((np.array([(0, 0.05)] + L_XY[5:2:-1]) / 25.4).tolist())
    path = dxf_file(tmp_path / "l.dxf", gapped, insunits=0)
    cfg = yaml.safe_load(DEFAULT_CONFIG.read_text())
    cfg["planner"]["parts"] = []
    cfg["families"] = {"cad": {"parts": [{"name": "l", "outline": str(path), "units": "in", "join_tol": 0.01}]}}
    (part,) = family_parts("cad", validate_config(cfg)["families"]["cad"])
    assert part.area == pytest.approx(900.0, rel=1e-3)
    cfg["families"]["cad"]["parts"][0]["units"] = "furlong"
    with pytest.raises(PinfeedError, match="units"):
        validate_config(cfg)
