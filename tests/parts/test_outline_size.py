"""CAD outlines whose size gives their units away: arcs are flattened by a
tolerance that grows with a large drawing, so a millimetre drawing declared in
metres reads as a modest polygon and the user is told the size and ``--units``
(not that the outline has too many vertices)."""
import math

import numpy as np
import pytest

pytest.importorskip("ezdxf")

from cad_files import dxf_file  # noqa: E402
from cli_runs import run_cli  # noqa: E402
from pipeline.parts.outlines import read_outline  # noqa: E402
from pipeline.parts.part import Part  # noqa: E402

LENGTH, WIDTH = 40.0, 20.0  # the slot overall: two half discs of radius WIDTH/2 on a square
R = WIDTH / 2
SLOT_AREA = (LENGTH - WIDTH) * WIDTH + math.pi * R * R  # closed form
MAX_SLOT_VERTICES = 100


def _slot(scale=1.0):
    """A 40 x 20 slot (times ``scale``) of two LINEs and two ARCs, the top line drawn backwards."""
    c, r = (LENGTH - WIDTH) / 2 * scale, R * scale

    def build(msp):
        msp.add_line((-c, -r), (c, -r))
        msp.add_arc((c, 0), r, -90, 90)
        msp.add_line((c, r), (-c, r))
        msp.add_arc((-c, 0), r, 90, 270)
    return build


def _area(xy):
    x, y = xy[:, 0], xy[:, 1]
    return 0.5 * abs(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1)))


def test_millimetre_slot_has_modest_vertices_and_its_area(tmp_path):
    out = read_outline(dxf_file(tmp_path / "slot.dxf", _slot(), insunits=4))
    assert 16 <= out.n_vertices <= MAX_SLOT_VERTICES
    assert _area(out.vertices) == pytest.approx(SLOT_AREA, rel=5e-3)
    assert _area(out.vertices) < SLOT_AREA  # chords lie inside the arcs
    w, h, _ = out.size_mm
    assert (w, h) == (pytest.approx(LENGTH, abs=1e-9), pytest.approx(WIDTH, abs=1e-9))
    assert not out.warnings()


@pytest.mark.parametrize("scale", [10.0, 1e3, 1e5])
def test_large_drawings_keep_a_modest_vertex_count(tmp_path, scale):
    # A fixed 0.05 mm tolerance gave a 40 m slot 1226 vertices (over the limit of 500).
    out = read_outline(dxf_file(tmp_path / "slot.dxf", _slot(scale), insunits=4))
    assert out.n_vertices <= MAX_SLOT_VERTICES
    assert _area(out.vertices) == pytest.approx(SLOT_AREA * scale ** 2, rel=5e-3)


def test_an_explicit_flatten_tol_is_kept(tmp_path):
    path = dxf_file(tmp_path / "slot.dxf", _slot(10.0), insunits=4)
    fine = read_outline(path, flatten_tol=0.05)
    assert fine.flatten_tol == 0.05 and fine.n_vertices > read_outline(path).n_vertices


def test_millimetre_slot_declared_in_metres_names_the_size_and_units(tmp_path, capsys):
    path = dxf_file(tmp_path / "slot_m.dxf", _slot(), insunits=6)  # $INSUNITS = 6: metres
    base = ["rollout", "--outline", str(path), "--mu-c", "0.2", "--pin-radius", "3", "--theta-i", "30",
            "--d", "0.3"]
    code, out, err = run_cli(capsys, base)
    assert code == 0 and "more than the limit" not in err
    said = [line for line in err.splitlines() if line.startswith("pinfeed:")]
    assert len(said) == 1 and "4e+04 mm across" in said[0] and "--units" in said[0], err
    assert "size 4e+04 x 2e+04 mm" in err
    code, out, err = run_cli(capsys, base + ["--units", "mm"])
    assert code == 0 and "pinfeed:" not in err
    mm = read_outline(dxf_file(tmp_path / "slot_mm.dxf", _slot(), insunits=4))
    assert f"part {Part.from_vertices(mm.vertices, name='slot_m').id} " in out
