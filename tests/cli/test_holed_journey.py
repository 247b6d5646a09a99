"""A holed bracket drawn in CAD, from the drawing to the animation: rollout,
plan, speed, layout and animate all run on it, every stored file keeps the
holes, and the part's physics is the holed one (its rollouts are those of
the same part given as vertices with finely drawn holes)."""
import json
import math
import shlex

import numpy as np
import pytest
import yaml
from cli_runs import run_cli
from test_journey import hints, run_hint, tiny_config

from pipeline.parts.part import Part

ezdxf = pytest.importorskip("ezdxf")

OUTLINE = [(0, 0), (50, 0), (50, 25), (35, 40), (0, 40)]  # 50 x 40 mm, one corner chamfered


def _holed_bracket_dxf(path):
    """Outline as an LWPOLYLINE, two mounting holes as CIRCLEs, a slot as an
    LWPOLYLINE with bulges (two half-circle ends): as a CAD tool writes it."""
    doc = ezdxf.new("R2010")
    doc.header["$INSUNITS"] = 4
    msp = doc.modelspace()
    msp.add_lwpolyline(OUTLINE, close=True, dxfattribs={"layer": "PART"})
    for x in (8, 42):
        msp.add_circle((x, 8), 3.25, dxfattribs={"layer": "PART"})
    # Slot 12..28 along y = 28, 6.5 mm wide: (x, y, start_width, end_width, bulge).
    msp.add_lwpolyline([(12, 24.75, 0, 0, 0), (28, 24.75, 0, 0, 1), (28, 31.25, 0, 0, 0),
                        (12, 31.25, 0, 0, 1)], format="xyseb", close=True, dxfattribs={"layer": "PART"})
    doc.saveas(path)


def _slot(n=64):
    right = [(28 + 3.25 * math.cos(t), 28 + 3.25 * math.sin(t)) for t in np.linspace(-math.pi / 2, math.pi / 2, n)]
    left = [(12 + 3.25 * math.cos(t), 28 + 3.25 * math.sin(t)) for t in np.linspace(math.pi / 2, 1.5 * math.pi, n)]
    return right + left


def _circle(x, y, r=3.25, n=96):
    return [(x + r * math.cos(t), y + r * math.sin(t)) for t in np.linspace(0, 2 * math.pi, n, endpoint=False)]


@pytest.fixture
def fresh(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    _holed_bracket_dxf(tmp_path / "holed.dxf")
    config = tiny_config(pins=(10.0, 30.0))
    (tmp_path / "tiny.yaml").write_text(yaml.safe_dump(config))
    return tmp_path


def test_holed_dxf_from_rollout_to_animation(fresh, capsys):
    code, out, err = run_cli(capsys, ["rollout", "--outline", "holed.dxf", "--theta-i", "0,90", "--d", "0.3",
                                      "--mu-c", "0.2", "--pin-radius", "3", "--json"])
    assert code == 0, err
    assert "3 holes" in err  # the outline line says what was read
    rows = json.loads(out)
    # The same part given as vertices with fine holes rolls the same way; the
    # solid outline does not.
    fine = Part.from_vertices(OUTLINE, "holed", holes=[_circle(8, 8), _circle(42, 8), _slot()])
    from pipeline.maps.simulate import rollout
    for row, theta in zip(rows, (0.0, 90.0)):
        want = float(rollout(fine, theta, 0.3, 0.2, 3.0).theta_f)
        assert abs((row["theta_f"] - want + 180) % 360 - 180) < 0.5

    code, out, err = run_cli(capsys, ["plan", "--config", "tiny.yaml", "--outline", "holed.dxf",
                                      "--name", "holed"])
    assert code == 0, err
    plan_file = fresh / "res" / "tiny" / "plans" / "holed.json"
    stored = json.loads(plan_file.read_text())
    assert len(stored["part"]["holes"]) == 3
    part = Part.from_dict(stored["part"])
    assert part.id == stored["part"]["id"] and part.has_holes
    assert part.area == pytest.approx(fine.area, rel=2e-3)  # the flattened holes are a little smaller
    steps = hints(out) if "next: " in out else []
    commands = {shlex.split(h)[1]: h for h in steps}
    for verb in ("speed", "layout"):
        cmd = commands.get(verb, f"pinfeed {verb} --part holed --config tiny.yaml")
        code, out, err = run_hint(capsys, cmd)
        assert code == 0, err
    laid = json.loads((fresh / "res" / "tiny" / "layout_holed.json").read_text())
    assert "holes" in json.dumps(laid)  # the drawn parts carry their holes
    cmd = commands.get("animate", "pinfeed animate --part holed --config tiny.yaml")
    code, out, err = run_hint(capsys, cmd + " --frames 3")
    assert code == 0, err
    assert (fresh / "res" / "tiny" / "animations" / "holed.gif").is_file()
