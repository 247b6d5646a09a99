"""Plans you can watch: kernel trajectories placed on the belt clock, GIFs written."""
import json

import numpy as np
import pytest

from pipeline.errors import PinfeedError
from pipeline.parts.part import Part
from pipeline.planning import plan_inputs, roll_plan
from pipeline.planning.feeder.lanes import gap as point_gap, rotated
from pipeline.present.animate import animate_plan

PART = Part.from_vertices([[0, 0], [60, 0], [15, 35]], name="tri")
STATES = {f"state {k}": (float(th), float(y)) for k, (th, y) in enumerate(PART.stable_states(), 1)}
HEIGHTS, SPEEDS = [10.0, 25.0], [0.0, 0.0]


def test_lanes_follow_the_kernel_and_touch_the_pins():
    from pipeline.maps import simulate
    lanes, stations, b_end = roll_plan(PART, HEIGHTS, SPEEDS, STATES, 0.15, "minpower", 3.0)
    assert len(lanes) == len(STATES) and b_end > stations[-1]
    for lane in lanes:
        theta, y = STATES[lane.label]
        for h in HEIGHTS:  # the chain of nominal rollouts the lane must end in
            r = simulate.rollout(PART, theta, (h - y) / PART.a, 0.15, 3.0)
            theta, y = float(r.theta_f), y + float(r.dy)
        x_end, y_end, th_end = lane.pose(b_end)
        assert th_end % 360 == pytest.approx(theta, abs=1e-6) and y_end == pytest.approx(y, abs=1e-9)
        assert lane.contacts
        for k, b0 in lane.contacts:
            # At first contact the pin touches the outline; a little earlier it is clear of it.
            x, yy, th = lane.pose(b0)
            poly = rotated(PART.vertices, th) + [x, yy]
            assert point_gap(np.array([stations[k], HEIGHTS[k]]), poly) == pytest.approx(3.0, abs=1e-3)
            x, yy, th = lane.pose(b0 - 0.5)
            assert point_gap(np.array([stations[k], HEIGHTS[k]]), rotated(PART.vertices, th) + [x, yy]) > 3.0


def test_gif_has_the_frames_asked_for(tmp_path):
    from PIL import Image
    out = tmp_path / "plan.gif"
    lanes, stations, b_end = roll_plan(PART, [10.0], [0.0], STATES, 0.15, "minpower", 3.0)
    res = animate_plan(PART, lanes, stations, b_end, [10.0], [0.0], 3.0, out, frames=4, fps=5)
    assert res["frames"] == 4
    with Image.open(out) as im:
        assert im.format == "GIF" and im.n_frames == 4


def test_mp4_without_ffmpeg_and_bad_outputs(tmp_path):
    from matplotlib import animation

    from pipeline.workflow.commands import animate_stored
    lanes, stations, b_end = roll_plan(PART, [10.0], [0.0], STATES, 0.15, "minpower", 3.0)
    if not animation.writers.is_available("ffmpeg"):
        with pytest.raises(PinfeedError, match="MP4 needs ffmpeg"):
            animate_plan(PART, lanes, stations, b_end, [10.0], [0.0], 3.0, tmp_path / "p.mp4")
    with pytest.raises(PinfeedError, match="gif or an .mp4"):
        animate_plan(PART, lanes, stations, b_end, [10.0], [0.0], 3.0, tmp_path / "p.avi")
    with pytest.raises(PinfeedError, match="gif or an .mp4"):  # before any rollout
        animate_stored(_stored(True), {"sweep": {"pin_radius": 3.0}}, tmp_path / "p.avi", 1)


def _stored(with_heights=False):
    plan = {"pins": ["P2", "P5v+2"], "final_sets": []}
    if with_heights:
        plan["pin_heights_mm"] = [7.0, 11.0]
    return {"part": PART.to_dict(), "mu_c": 0.15, "model": "minpower", "plans": [plan],
            "initial_states": {k: {"theta": t, "y_c": y} for k, (t, y) in STATES.items()}}


def _planner(pins):
    """The planner's settings with these configured pin heights and a 3 mm pin."""
    from pipeline.planning import PlannerSettings, SearchSettings
    return PlannerSettings(SearchSettings(3.0, pins=tuple(pins)))


def test_plan_inputs_heights_from_plan_or_config():
    config = _planner([0.0, 5.0, 10.0, 15.0, 20.0])
    got = plan_inputs(_stored(), 1, config)
    assert got["heights"] == [5.0, 20.0] and got["speeds"] == [0.0, 2.0] and got["pin_radius"] == 3.0
    assert plan_inputs(_stored(True), 1, config)["heights"] == [7.0, 11.0]
    with pytest.raises(PinfeedError, match="--plan 2: tri has plans 1 to 1"):
        plan_inputs(_stored(), 2, config)
    assert plan_inputs(_stored(), None, config)["what"] == "plan 1"  # no tight plan: paper mode's best
    with pytest.raises(PinfeedError, match="tri: the stored result has no recommended tight plan"):
        plan_inputs(_stored(), "tight", config)


def test_plan_inputs_prefers_the_tight_recommended_plan():
    """The recommended plan is the tight planner's (first friction): its own
    heights, speeds and the friction range's middle."""
    from pipeline.planning import recommended_index
    config = _planner([0.0, 5.0, 10.0, 15.0, 20.0])
    stored = _stored()
    stored["tight"] = [{"friction": "0.1:0.3", "mu_c": [0.1, 0.3], "plans": [],
                        "recommended": {"pins": ["P7", "P9"], "pin_heights_mm": [12.5, 30.0],
                                        "pin_speeds": [0.0, -1.0], "final_sets": []}}]
    assert recommended_index(stored) == "tight"
    got = plan_inputs(stored, None, config)
    assert got["labels"] == ["P7", "P9"] and got["heights"] == [12.5, 30.0] and got["speeds"] == [0.0, -1.0]
    assert got["mu_c"] == pytest.approx(0.2) and got["what"] == "tight plan at mu_c 0.1:0.3"
    assert plan_inputs(stored, 1, config)["labels"] == ["P2", "P5v+2"]  # paper mode on request
    stored["tight"][0]["recommended"] = None
    assert recommended_index(stored) == 1 and recommended_index({"part": PART.to_dict(), "plans": []}) is None


def test_cli_animate(tmp_path, capsys):
    from PIL import Image

    from pipeline.cli import main
    (tmp_path / "plans").mkdir()
    stored = _stored(True)
    stored["plans"][0]["pins"] = ["P1"]
    stored["plans"][0]["pin_heights_mm"] = [10.0]
    (tmp_path / "plans" / "tri.json").write_text(json.dumps(stored))
    out = tmp_path / "tri.gif"
    assert main(["animate", "--part", "tri", "--results", str(tmp_path), "--out", str(out),
                 "--frames", "3"]) == 0
    assert "wrote" in capsys.readouterr().out
    with Image.open(out) as im:
        assert im.n_frames == 3
    assert main(["animate", "--part", "nope", "--results", str(tmp_path), "--out", str(out)]) == 2
    assert "no stored plan for nope" in capsys.readouterr().err
    with pytest.raises(SystemExit) as exc:  # argparse: one line, status 2
        main(["animate", "--part", "tri", "--results", str(tmp_path), "--plan", "best", "--out", str(out)])
    assert exc.value.code == 2 and "expected 'tight' or a plan number" in capsys.readouterr().err


def test_moving_pin_touches_at_its_height_on_the_clock():
    from pipeline.planning import pin_height
    speeds = [0.0, 1.0]
    lanes, stations, _ = roll_plan(PART, HEIGHTS, speeds, STATES, 0.15, "minpower", 3.0)
    touched = 0
    for lane in lanes:
        for k, b0 in lane.contacts:
            x, y, th = lane.pose(b0)
            pin = np.array([stations[k], pin_height(lane, k, b0, HEIGHTS[k], speeds[k], stations[k])])
            assert point_gap(pin, rotated(PART.vertices, th) + [x, y]) == pytest.approx(3.0, abs=1e-3)
            touched += k == 1
    assert touched  # the moving pin met some state
