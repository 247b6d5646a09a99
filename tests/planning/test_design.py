"""Design for feeding: the search returns the smallest change that orients, and says so.

The exhaustive reference plans every chamfer of a small grid on a trapezoid
that no fixed-pin plan of up to two pins orients, with the planner called
here directly on chamfered outlines built in this test (own geometry, own
areas), and checks that the search chose the smallest-area one among those
that orient. Settings are small (two pins, 30 trials per state, the point
rule) so that the module runs in well under a minute on two cores.
"""
from __future__ import annotations

import math

import numpy as np
import pytest

from pipeline.config import load_config
from pipeline.parts.part import Part
from pipeline.planning import DesignGrid, DesignLimits, DesignSettings, PlannerSettings, design_part
from pipeline.planning.plans.plan import plan_tight_all

TRAPEZOID = [[0.0, 0.0], [70.0, 0.0], [50.0, 25.0], [10.0, 25.0]]
SIZES = (0.2, 0.3)  # chamfer legs, fractions of a


def small_config(catalog) -> dict:
    config = load_config()
    config["catalog_dir"] = str(catalog)
    config["planner"].update(pins="auto", depth=2, tolerance_deg=14.0, mu_c=0.2, frictions=[])
    config["planner"]["dynamic"].update(depth=0, speeds=[])
    config["verify"].update(trials=30, rule="point")  # few trials: the point rule
    config["design"].update(kinds=["chamfer"], chamfer=list(SIZES), max_change=0.2)
    return config


@pytest.fixture(scope="module")
def trapezoid_design(tmp_path_factory):
    catalog = tmp_path_factory.mktemp("catalog")
    config = small_config(catalog)
    settings = PlannerSettings.from_config(config)
    lines = []
    result = design_part(TRAPEZOID, (), "trapezoid", settings, DesignSettings.from_section(config["design"]),
                         catalog, progress=lines.append)
    return result, lines, settings, catalog


def chamfered(xy, corner, leg):
    """The outline with corner ``corner`` cut by legs ``leg`` (this test's own geometry)."""
    xy = np.asarray(xy, dtype=float)
    n = len(xy)
    p, q, r = xy[corner - 1], xy[corner], xy[(corner + 1) % n]
    a = q + (p - q) / np.linalg.norm(p - q) * leg
    b = q + (r - q) / np.linalg.norm(r - q) * leg
    out = [v for k, v in enumerate(xy) if k != corner]
    out[corner:corner] = [a, b]
    angle = math.acos(np.dot(p - q, r - q) / np.linalg.norm(p - q) / np.linalg.norm(r - q))
    return np.array(out), 0.5 * leg * leg * math.sin(angle)


def test_the_search_returns_the_smallest_change_that_orients(trapezoid_design):
    result, lines, settings, catalog = trapezoid_design
    original = Part.from_vertices(TRAPEZOID, name="trapezoid")
    assert not result["original"]["orients"]
    orienting = []
    for corner in range(4):
        for size in SIZES:
            xy, area = chamfered(TRAPEZOID, corner, size * original.a)
            entries = plan_tight_all(Part.from_vertices(xy, name="trapezoid"), settings.without_moving_pins(),
                                     catalog)
            if all(e.orients for e in entries):
                orienting.append((area, corner, size))
    assert orienting, "the reference grid must hold a change that orients the trapezoid"
    area, corner, size = min(orienting)
    chosen = result["chosen"]
    assert result["outcome"] == "changed"
    assert chosen["kind"] == "chamfer" and chosen["corner"] == corner
    assert chosen["legs_mm"][0] == pytest.approx(size * original.a)
    assert chosen["area_mm2"] == pytest.approx(area)
    assert chosen["share"] == pytest.approx(area / original.area)
    # tried in order of area share, every one before the chosen does not orient
    shares = [t["share"] for t in result["tried"]]
    assert shares == sorted(shares) and result["tried"][-1]["orients"]
    assert not any(t["orients"] for t in result["tried"][:-1])
    # the chosen change is certified on held-out rollouts
    rec = chosen["plan"][0]["recommended"]
    assert rec["verification"]["held_out"] and rec["verification"]["orientation"]["orients"]
    assert rec["verification"]["trials"] > 0
    # one progress line per change tried, and one for the original
    assert len([line for line in lines if line.startswith("[")]) == len(result["tried"])


def test_the_chosen_outline_is_the_changed_trapezoid(trapezoid_design):
    result = trapezoid_design[0]
    xy = np.array(result["chosen"]["vertices"])
    assert len(xy) == 5
    area = Part.from_vertices(TRAPEZOID).area - result["chosen"]["area_mm2"]
    assert Part.from_vertices(xy).area == pytest.approx(area)


def test_an_orienting_part_stops_at_once(tmp_path):
    config = small_config(tmp_path)
    settings = PlannerSettings.from_config(config)
    rectangle = [[0, 0], [60, 0], [60, 20], [0, 20]]
    result = design_part(rectangle, (), "rectangle", settings, DesignSettings.from_section(config["design"]),
                         tmp_path)
    assert result["outcome"] == "already orients" and result["tried"] == [] and result["chosen"] is None


def test_no_change_within_the_limits(tmp_path):
    config = small_config(tmp_path)
    settings = PlannerSettings.from_config(config)
    design = DesignSettings(grid=DesignGrid(kinds=("chamfer",), chamfer=(0.2,)),
                            limits=DesignLimits(max_change=0.001))
    result = design_part(TRAPEZOID, (), "trapezoid", settings, design, tmp_path)
    assert result["outcome"] == "no change helps" and result["chosen"] is None and result["tried"] == []
    assert len(result["refused"]) == 4 and all("max-change" in r["why"] for r in result["refused"])


def test_the_dxf_reads_back_to_the_changed_outline(trapezoid_design, tmp_path):
    from pipeline.parts.outlines import read_outline
    from pipeline.workflow.design import store_design
    result = trapezoid_design[0]
    config = small_config(tmp_path)
    paths = {"json": tmp_path / "t.json", "dxf": tmp_path / "t.dxf", "figure": tmp_path / "t.png"}
    stored = store_design(result, config, paths)
    back = read_outline(paths["dxf"], layer="MODIFIED")
    want = np.array(result["chosen"]["vertices"])
    assert back.vertices.shape == want.shape
    shift = int(np.argmin(np.linalg.norm(want - back.vertices[0], axis=1)))
    assert np.allclose(np.roll(want, -shift, axis=0), back.vertices, atol=1e-6)
    original = read_outline(paths["dxf"], layer="ORIGINAL")
    assert len(original.vertices) == 4
    assert paths["figure"].stat().st_size > 0
    for key in ("git_commit", "config_hash", "pinfeed_version", "parameters", "files"):
        assert key in stored


def test_the_bracket_chamfer_and_its_four_pin_plan_replay_in_one_set():
    """The tutorial bracket's design answer (design for feeding, measured with
    ``pinfeed design --depth 4``): a 6.5 mm chamfer (0.2 a) at corner 2 and
    the plan P19 P16 P1 P4 at 26, 20, -10, -4 mm. Replayed here by the tests'
    oracle alone (public rollout API, its own uniform box with every corner,
    mu_c 0.16 to 0.24), every trial of the chamfered bracket ends in one arc
    of 10 deg; the bracket as drawn, through the same pins, does not."""
    from oracle import box_trials, most_in_arc, replay_box
    from pipeline.planning.design.edits import OutlineChange, apply_change, ccw_outline
    bracket = ccw_outline(np.array([[0, 0], [50, 0], [50, 12], [18, 12], [18, 30], [0, 30]], float))
    a = Part.from_vertices(bracket.tolist()).a
    chamfered = apply_change(bracket, OutlineChange("chamfer", 2, (0.2 * a, 0.2 * a)))
    heights = [26.0, 20.0, -10.0, -4.0]
    for vertices, orients in ((chamfered, True), (bracket, False)):
        part = Part.from_vertices(vertices.tolist())
        finals = replay_box(part, heights, box_trials(part, 4, 60, 11, (0.16, 0.24)), strict=False)
        assert (most_in_arc(finals, 10.0) == finals.size) == orients
    assert len(Part.from_vertices(chamfered.tolist()).stable_states()) == 3  # the end-face state is gone
