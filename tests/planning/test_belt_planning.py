"""Plans at belt speed (issue 18): ``pinfeed plan --belt-speed``, refinement
shards keyed by the belt, verification with the dynamic model at that speed,
the speed stage's JSON and figure, and bad input."""
from __future__ import annotations

import json

import numpy as np
import pytest
import xarray as xr

from cli_runs import TRI_PLAN_ARGS, small_config_file
from images import assert_png_figure
from pipeline.cli import main
from pipeline.config import load_config
from pipeline.errors import PinfeedError
from pipeline.maps import simulate
from pipeline.parts.part import Part
from pipeline.planning.tight.store import lattice_path, load_lattice
from pipeline.planning.tight.propagate import UNITS
from pipeline.planning.claims.replay import replay

TRI = Part.from_vertices([[0, 0], [60, 0], [15, 35]], name="tri")
BELT = 150.0
ARGS = TRI_PLAN_ARGS


@pytest.fixture(scope="module")
def planned(tmp_path_factory):
    """One quasi-static and one belt-speed plan of the triangle in one catalog."""
    tmp = tmp_path_factory.mktemp("belt")
    cfg = small_config_file(tmp)
    common = ARGS + ["--config", str(cfg), "--catalog", str(tmp / "cat")]
    assert main(["plan", *common, "--out", str(tmp / "res" / "plans" / "tri.json")]) == 0
    assert main(["plan", *common, "--belt-speed", f"{BELT:g}",
                 "--out", str(tmp / "belt" / "plans" / "tri.json")]) == 0
    return tmp, cfg


def test_belt_speed_shards_are_apart_from_quasi_static_ones(planned):
    tmp, _ = planned
    quasi = lattice_path(tmp / "cat", TRI, "minpower", 0.0)
    belt = lattice_path(tmp / "cat", TRI, "minpower", 0.0, BELT, 0.5)
    assert quasi.is_file() and belt.is_file() and quasi != belt
    with xr.open_dataset(belt, engine="h5netcdf") as ds:
        assert ds.attrs["model"] == "dynamic"
        assert ds.attrs["belt_speed"] == BELT and ds.attrs["mu_s"] == 0.5
        assert "git_commit" in ds.attrs or "pinfeed_version" in ds.attrs
    # Each planner reads only its own outcomes: another belt speed starts empty.
    assert load_lattice(tmp / "cat", TRI, "minpower", 0.0, 3.0, belt_speed=BELT).known
    assert not load_lattice(tmp / "cat", TRI, "minpower", 0.0, 3.0, belt_speed=200.0).known
    quasi_keys = set(load_lattice(tmp / "cat", TRI, "minpower", 0.0, 3.0).known)
    assert quasi_keys
    # The catalog index lists both refinement files.
    from pipeline.maps.catalog import Catalog
    Catalog.rebuild(tmp / "cat")
    listed = {r["file"]: r for r in json.loads((tmp / "cat" / "index.json").read_text())["refinements"]}
    quasi_entry = listed[quasi.relative_to(tmp / "cat").as_posix()]
    belt_entry = listed[belt.relative_to(tmp / "cat").as_posix()]
    assert (quasi_entry["model"], quasi_entry["belt_speed"]) == ("minpower", None)
    assert (belt_entry["model"], belt_entry["belt_speed"], belt_entry["mu_s"]) == ("dynamic", BELT, 0.5)
    assert belt_entry["part_id"] == TRI.id and belt_entry["v_pin"] == 0.0


def test_belt_speed_outcomes_are_dynamic_rollouts_at_that_speed(planned):
    tmp, _ = planned
    lattice = load_lattice(tmp / "cat", TRI, "minpower", 0.0, 3.0, belt_speed=BELT)
    keys = sorted(k for k, v in lattice.known.items() if v[0] == 0)[::97][:6]
    assert keys
    differs = 0
    for key in keys:
        theta, d, mu = key[0] * UNITS[0], key[1] * UNITS[1], key[2] * UNITS[2]
        one = simulate.dynamic_rollout(TRI, theta, d, mu, 3.0, BELT, 0.5)  # the scalar public API
        assert float(one.theta_f) == pytest.approx(lattice.known[key][1], abs=1e-6)
        assert float(one.dy) == pytest.approx(lattice.known[key][2], abs=1e-6)
        quasi = simulate.rollout(TRI, theta, d, mu, 3.0)
        differs += abs(((float(quasi.theta_f) - lattice.known[key][1] + 180) % 360) - 180) > 1e-3
    assert differs  # at 150 mm/s inertia moves some outcomes: the model really changed


def test_belt_speed_plan_is_verified_with_the_dynamic_model(planned):
    tmp, _ = planned
    result = json.loads((tmp / "belt" / "plans" / "tri.json").read_text())
    assert result["belt_speed"] == BELT and result["mu_s"] == 0.5
    entry = result["tight"][0]
    assert entry["belt_speed"] == BELT and entry["mechanics"].startswith("dynamic at 150")
    assert entry["plans"], entry["warning"]
    for plan in entry["plans"] + entry["rejected"]:
        v = plan["verification"]
        assert v["model"] == "dynamic" and v["belt_speed"] == BELT
        assert v["trials"] == 3 * (20 + 2 ** (3 + len(plan["pins"])))
    quasi = json.loads((tmp / "res" / "plans" / "tri.json").read_text())
    assert "belt_speed" not in quasi and quasi["tight"][0]["belt_speed"] is None
    assert quasi["tight"][0]["plans"][0]["verification"]["model"] == "minpower"


def _one_by_one(theta, y_c, mu, heights, belt_speed):
    """Passages past each pin in turn with the scalar public API: ``(theta, y_c, ok)``,
    ``ok`` False once a passage jams or is truncated."""
    for h in heights:
        one = simulate.dynamic_rollout(TRI, theta, (h - y_c) / TRI.a, mu, 3.0, belt_speed, 0.5)
        if str(one.status.values) in ("jammed", "truncated"):
            return theta, y_c, False
        theta, y_c = float(one.theta_f), y_c + float(one.dy)
    return theta, y_c, True


def test_replay_at_belt_speed_equals_passages_one_by_one():
    rng = np.random.default_rng(3)
    theta, y_c = rng.uniform(0, 360, 4), rng.uniform(10, 14, 4)
    mu, heights, offsets = rng.uniform(0, 0.3, 4), [27.5, 7.5], np.zeros((4, 2))
    tf, yf, jam, _ = replay(TRI, heights, [0.0, 0.0], theta, y_c, mu, offsets, 3.0, "minpower",
                            belt_speed=BELT, mu_s=0.5)
    for j in range(4):
        th, y, ok = _one_by_one(theta[j], y_c[j], mu[j], heights, BELT)
        assert ok == (not jam[j])
        if ok:
            assert tf[j] == pytest.approx(th % 360.0, abs=1e-6) and yf[j] == pytest.approx(y, abs=1e-6)


def test_speed_stage_json_and_figure(planned, tmp_path):
    from pipeline.maps.io import read_json
    from pipeline.workflow.speed import speed_figure, speed_part
    tmp, cfg = planned
    config = load_config(cfg)
    from pipeline.planning import PlannerSettings
    result = speed_part(read_json(tmp / "res" / "plans" / "tri.json"), PlannerSettings.from_config(config))
    assert set(result) >= {"pin_labels", "pin_heights_mm", "final_set", "mu_c", "mu_s",
                           "speed_limit_mm_s", "curve", "git_commit"}
    fractions = dict((v, f) for v, f in result["curve"])
    limit = result["speed_limit_mm_s"]
    assert limit == 0.0 or fractions[limit] >= 0.99  # the replay holds at the stated limit
    above = [f for v, f in result["curve"] if v > limit]
    assert not above or above[0] < 0.99  # and fails at the next speed tried
    out = speed_figure(result, tmp_path / "speed.png")
    assert_png_figure(out)  # decoded: a plot with axes and a curve, not just bytes


def test_speed_figure_has_labelled_axes_legend_and_marked_limit():
    from pipeline.present.figures import text_problems
    from pipeline.present.figures.speed import speed_curve_figure
    result = {"part": "tri", "pin_labels": ["P1", "P2"], "friction": "0.2", "mu_s": 0.5,
              "required": 0.99, "speed_limit_mm_s": 215.0, "trials_per_speed": 64,
              "curve": [[10.0, 1.0], [200.0, 1.0], [215.0, 0.995], [220.0, 0.97], [300.0, 0.8]]}
    fig = speed_curve_figure(result)
    ax = fig.axes[0]
    assert "mm/s" in ax.get_xlabel() and "final set" in ax.get_ylabel()
    verticals = [line for line in ax.get_lines()
                 if len(set(line.get_xdata())) == 1 and line.get_xdata()[0] == 215.0]
    assert verticals, "the speed limit is marked by a vertical line"
    legend = [t.get_text() for t in ax.get_legend().get_texts()]
    assert any("215" in t for t in legend) and any("99" in t for t in legend)
    assert text_problems(fig) == []


@pytest.mark.parametrize("extra, words", [
    (["--belt-speed", "0"], "belt speed must be"),
    (["--belt-speed", "-20"], "belt speed must be"),
    (["--belt-speed", "nan"], "belt speed must be"),
    (["--belt-speed", "150", "--mu-s", "0"], "mu_s must be in"),
    (["--belt-speed", "150", "--mu-s", "80"], "mu_s must be in"),
    (["--belt-speed", "3000"], "throws the part"),
    (["--mu-s", "0.4"], "give --belt-speed too"),
    (["--belt-speed", "150", "--mode", "paper"], "--mode tight"),
])
def test_bad_belt_input_is_a_one_line_error(tmp_path, capsys, extra, words):
    assert main(["plan", *ARGS, "--catalog", str(tmp_path / "cat"), *extra]) == 2
    err = capsys.readouterr().err.strip()
    assert words in err and "\n" not in err and "Traceback" not in err
    assert not (tmp_path / "cat").exists()  # refused before any work


def test_config_belt_speed_where_the_part_is_thrown_is_refused():
    from pipeline.config import validate_config
    cfg = load_config(None)
    cfg["planner"]["belt_speed"] = 3000.0
    with pytest.raises(PinfeedError, match="planner/belt_speed .*throws the part"):
        validate_config(cfg)
    cfg["planner"]["belt_speed"] = 0
    with pytest.raises(PinfeedError, match="planner/belt_speed"):
        validate_config(cfg)


def test_batched_success_fraction_equals_passages_one_at_a_time():
    from pipeline.planning.core.settings import SpeedPerturbation
    from pipeline.planning.plans.speed_limit import _draws, success_fraction
    heights, arcs = [27.5, 7.5], [(0.0, 40.0), (120.0, 30.0)]
    draws = _draws(TRI, heights, [(0.0, 11.67), (217.9, 12.28)], (0.1, 0.3),
                   SpeedPerturbation(theta_deg=2.0, y_mm=0.5, pin_mm=0.3), 3, seed=5)
    good = total = 0
    for th, yc, mu, pins in draws:
        for i in range(th.size):
            theta, _, ok = _one_by_one(th[i], yc[i], mu[i], pins[i], 200.0)
            good += ok and any((theta - s) % 360.0 <= w for s, w in arcs)
            total += 1
    assert 0 < good < total  # the arcs catch some trials and miss others: a real comparison
    assert success_fraction(TRI, heights, [0.0, 0.0], draws, arcs, 200.0, r_pin=3.0) == good / total
