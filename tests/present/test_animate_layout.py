"""The plan animation of a laid-out feeder (issue 19): one belt, the pins at the
layout's stations, parts arriving at its pitch, each replaying its passage."""
import json

import numpy as np
import pytest

from pipeline.maps import simulate
from pipeline.planning import station_scene
from pipeline.planning.feeder.lanes import gap as point_gap, rotated
from pipeline.present.animate import animate_layout, station_figure
from pipeline.errors import PinfeedError
from pipeline.parts.part import Part

PART = Part.from_vertices([[0, 0], [60, 0], [15, 35]], name="tri")
STATES = {f"state {k}": (float(th), float(y)) for k, (th, y) in enumerate(PART.stable_states(), 1)}
MU = 0.15


def _layout(pitch=130.0, model="minpower", speed=None):
    """A layout as 'pinfeed layout' writes it (the keys the animation reads), by hand;
    stations deliberately not at round numbers and not starting at 0."""
    return {"part": "tri", "pins": ["P1", "P2"],
            "stations": [{"label": "P1", "x_mm": 12.5, "y_mm": 10.0, "radius_mm": 3.0},
                         {"label": "P2", "x_mm": 83.25, "y_mm": 25.0, "radius_mm": 3.0}],
            "fence_y_mm": 0.0, "fence_end_x_mm": -30.0, "belt_y_mm": [-5.0, 70.0],
            "pitch_mm": pitch, "belt_speed_mm_s": speed, "mu_s": 0.5 if speed else None, "mu_c": MU,
            "plan": {"number": 1, "friction": "0.15", "pins": ["P1", "P2"], "pin_heights_mm": [10.0, 25.0]},
            "method": {"model": model, "margins_mm": {"station_margin_mm": 5.0}}}


def _centroid(poly):
    """Area centroid of a drawn outline (the part's vertices are centred on it)."""
    x, y = poly[:, 0], poly[:, 1]
    xn, yn = np.roll(x, -1), np.roll(y, -1)
    cross = x * yn - xn * y
    area = cross.sum() / 2.0
    return np.array([((x + xn) * cross).sum(), ((y + yn) * cross).sum()]) / (6.0 * area)


@pytest.fixture(scope="module")
def scene():
    return station_scene(PART, _layout(), STATES, MU)


def test_pins_drawn_at_the_stations_and_parts_enter_a_pitch_apart(scene):
    import matplotlib.pyplot as plt
    layout = _layout()
    fig = station_figure(scene, "test")
    try:
        assert scene.n_parts == 3 and len(fig["parts"]) == 3
        for pin, row in zip(fig["pins"], layout["stations"], strict=True):
            assert pin.center == pytest.approx((row["x_mm"], row["y_mm"]))
            assert pin.radius == pytest.approx(row["radius_mm"])
            assert pin in fig["ax"].patches
        entry_x = -scene.entry
        first_pin = layout["stations"][0]["x_mm"]
        assert entry_x < first_pin - PART.a
        # Before any contact every part rides the belt: consecutive centroids are one pitch apart.
        for b in (0.0, 10.0):
            fig["draw"](b)
            c = np.array([_centroid(np.asarray(p.get_xy())[:-1]) for p in fig["parts"]])
            assert c[0, 0] == pytest.approx(entry_x + b, abs=1e-6)
            assert np.diff(c[:, 0]) == pytest.approx([-layout["pitch_mm"]] * 2, abs=1e-6)
            assert c[:, 1] == pytest.approx([y for _, y in STATES.values()], abs=1e-6)  # states cycle
        # Each part crosses the entry one pitch of belt travel after the one before.
        for k in range(scene.n_parts):
            fig["draw"](k * layout["pitch_mm"])
            assert _centroid(np.asarray(fig["parts"][k].get_xy())[:-1])[0] == pytest.approx(entry_x, abs=1e-6)
        fig["draw"](scene.b_end)  # the pins never move
        assert [p.center for p in fig["pins"]] == [pytest.approx((r["x_mm"], r["y_mm"])) for r in layout["stations"]]
    finally:
        plt.close(fig["fig"])


def test_each_part_replays_its_passage_past_the_stations(scene):
    """Parts are pushed by the pins where the layout puts them: at some belt
    travel each pin touches each part it turns (gap = radius), no pin sinks into
    a part, and each part ends in its state's chain of nominal rollouts."""
    stations = _layout()["stations"]
    touched = set()
    for b in np.linspace(0.0, scene.b_end, 1500):
        for k, label, x, y, th in scene.part_poses(b):
            poly = rotated(PART.vertices, th) + [x, y]
            for j, row in enumerate(stations):
                gap = point_gap(np.array([row["x_mm"], row["y_mm"]]), poly)
                assert gap > row["radius_mm"] - 0.3, (k, j, b, gap)
                if gap < row["radius_mm"] + 0.05:
                    touched.add((k, j))
    assert (0, 0) in touched and {j for _, j in touched} == {0, 1}
    for k, label, x, y, th in scene.part_poses(scene.b_end + 1e4):
        theta, yc = STATES[label]
        for row in stations:
            r = simulate.rollout(PART, theta, (row["y_mm"] - yc) / PART.a, MU, 3.0)
            theta, yc = float(r.theta_f), yc + float(r.dy)
        assert th % 360 == pytest.approx(theta, abs=1e-6) and y == pytest.approx(yc, abs=1e-6)
        assert x > stations[-1]["x_mm"]  # past the last pin, riding on


def test_gif_frames_title_and_model(tmp_path, monkeypatch):
    from PIL import Image
    out = tmp_path / "feeder.gif"
    res = animate_layout(station_scene(PART, _layout(), STATES, MU), out, frames=4, fps=4)
    assert res["frames"] == 4 and res["pitch_mm"] == 130.0 and res["model"] == "minpower"
    with Image.open(out) as im:
        assert im.format == "GIF" and im.n_frames == 4
    # A dynamic layout is replayed with the dynamic model at its belt speed and mu_s.
    seen = {}

    def spy(part, heights, states, mu_c, pin_radius, model, **kw):
        seen.update(kw, heights=list(heights), model=model)
        raise RuntimeError("stop")

    monkeypatch.setattr("pipeline.planning.feeder.passages.run_trials", spy)
    with pytest.raises(RuntimeError, match="stop"):
        station_scene(PART, _layout(model="dynamic", speed=150.0), STATES, MU)
    assert seen["belt_speed"] == 150.0 and seen["mu_s"] == 0.5 and seen["nominal"]
    assert seen["heights"] == [10.0, 25.0]
    with pytest.raises(PinfeedError, match="no pin stations"):
        station_scene(PART, {"part": "tri", "plan": None, "note": "no plan", "stations": []}, STATES, MU)


def test_title_says_how_the_passages_were_replayed():
    from pipeline.planning import StationScene
    from pipeline.present.animate import station_title
    sc = StationScene(PART, [], [], 130.0, 40.0, 3, 0.0, -30.0, (0.0, 50.0), 150.0, "dynamic")
    assert station_title("tri", sc) == "tri; belt 150 mm/s (dynamic model); pitch 130.0 mm"
    sc.model, sc.belt_speed = "minpower", None
    assert "no belt speed: quasi-static replay (minpower)" in station_title("tri", sc)


def _stored_plan():
    plan = {"pins": ["P1", "P2"], "pin_heights_mm": [10.0, 25.0], "pin_speeds": [0.0, 0.0],
            "final_sets": []}
    return {"part": PART.to_dict(), "mu_c": MU, "model": "minpower", "plans": [],
            "tight": [{"friction": "0.15", "mu_c": MU, "plans": [plan], "recommended": plan,
                       "initial_states": {k: {"theta": t, "y_c": y} for k, (t, y) in STATES.items()}}]}


def test_cli_animate_with_the_stored_layout(tmp_path, capsys):
    from PIL import Image

    from pipeline.cli import main
    (tmp_path / "plans").mkdir()
    (tmp_path / "plans" / "tri.json").write_text(json.dumps(_stored_plan()))
    out = tmp_path / "tri.gif"
    base = ["animate", "--part", "tri", "--results", str(tmp_path), "--out", str(out), "--frames", "3"]
    assert main(base + ["--layout"]) == 2  # none stored yet
    assert "no layout at" in capsys.readouterr().err
    (tmp_path / "layout_tri.json").write_text(json.dumps(_layout()))
    assert main(base + ["--layout"]) == 0
    text = capsys.readouterr().out
    assert "P2 at x 83.2, y 25 mm" in text and "pitch 130.0 mm" in text and "wrote" in text
    with Image.open(out) as im:
        assert im.n_frames == 3
    assert main(base + ["--layout", "--plan", "1"]) == 2
    assert "leave out --plan" in capsys.readouterr().err
    other = dict(_layout(), stations=[dict(r, label="P7") for r in _layout()["stations"]])
    (tmp_path / "other.json").write_text(json.dumps(other))
    assert main(base + ["--layout", str(tmp_path / "other.json")]) == 2
    assert "are not tight plan 1's" in capsys.readouterr().err
