"""Bands, the fixed-pins planner and verification (issue: bands, planner, verification)."""
import json
import math

import numpy as np
import pytest
import xarray as xr

from kernels.rollout import JAMMED, MISS, OK
from oracle import n_clusters, replay_sequence, trial_inputs
from pipeline.errors import PinfeedError
from pipeline.maps import simulate
from pipeline.parts.part import Part
from pipeline.planning.paper.bands import circular_mean_std, extract_bands, in_arc
from pipeline.planning.paper.planner import Planner, State, load_maps, merge_arcs
from pipeline.planning.claims.verify import verify_plan
from pipeline.planning.core.settings import VerifySettings

GRID = np.arange(0.0, 360.0, 1.0)


def _bands(theta_f, status=None, dy=None, T=5.0, c=2.0):
    status = np.full(GRID.size, OK) if status is None else status
    dy = np.zeros(GRID.size) if dy is None else dy
    return extract_bands(GRID, theta_f, dy, status, T, c)


def test_band_wrapping_through_360():
    theta_f = np.where(GRID < 180, 355.0 + GRID / 18.0, 100.0)  # 355 .. 365 -> wraps
    bands = _bands(theta_f % 360.0)
    wrap = [b for b in bands if b.start > 300][0]
    assert wrap.start == pytest.approx(355.0) and wrap.width == pytest.approx(179 / 18.0)
    assert wrap.wraps
    assert circ_close(wrap.mean, 355.0 + 179 / 36.0)
    assert wrap.kernel_arcs == [(0.0, 179.0)]


def circ_close(a, b, tol=1e-6):
    return abs((a - b + 180.0) % 360.0 - 180.0) < tol


def test_kernel_made_of_several_arcs_and_com_interval():
    theta_f = np.full(GRID.size, 200.0)
    first = (GRID <= 30) | ((GRID >= 180) & (GRID <= 210)) | (GRID >= 350)
    theta_f[first] = 45.0 + 0.01 * GRID[first]
    dy = np.where(first, GRID / 10.0, -1.0)
    bands = _bands(theta_f, dy=dy)
    b = [b for b in bands if b.start < 50][0]
    # [350, 359] and [0, 30] join across 0/360; [180, 210] is separate.
    assert sorted(b.kernel_arcs) == [(180.0, 30.0), (350.0, 40.0)]
    assert b.com_min == pytest.approx(0.0) and b.com_max == pytest.approx(35.9)
    other = [b for b in bands if b.start >= 190][0]
    assert other.com_min == other.com_max == -1.0


def test_single_sample_band_and_all_miss_map():
    theta_f = np.where(GRID < 180, 10.0, 250.0)
    theta_f[90] = 120.0  # an isolated outcome, e.g. at a band jump
    bands = _bands(theta_f)
    single = [b for b in bands if b.n == 1]
    assert len(single) == 1 and single[0].width == 0.0 and single[0].sigma == 0.0
    assert single[0].kernel_arcs == [(90.0, 0.0)]
    assert _bands(GRID.copy(), status=np.full(GRID.size, MISS)) == []


def test_band_covering_the_whole_circle():
    bands = _bands(GRID.copy(), T=5.0)  # identity map: every gap is 1 degree
    assert len(bands) == 1 and bands[0].width == 360.0 and bands[0].kernel_arcs == [(0.0, 360.0)]


def test_adjusted_band_is_mean_plus_minus_c_sigma():
    rng = np.random.default_rng(0)
    theta_f = np.where(GRID < 180, 80.0 + rng.normal(0, 2.0, GRID.size), 300.0 + rng.normal(0, 1.0, GRID.size))
    bands = _bands(theta_f, T=10.0, c=1.5)
    assert len(bands) == 2
    b = bands[0]
    vals = theta_f[:180]
    assert b.mean == pytest.approx(vals.mean(), abs=0.01)
    assert b.sigma == pytest.approx(vals.std(), rel=0.01)  # small spread: circular ~ linear
    assert b.adj_width == pytest.approx(3.0 * b.sigma)
    assert circ_close(b.adj_start + b.adj_width / 2.0, b.mean)
    assert b.adj_width < b.width  # the paper's point: adjusted bands are narrower


def test_circular_statistics_across_zero():
    mean, sigma = circular_mean_std([358.0, 2.0])
    assert circ_close(mean, 0.0) and sigma == pytest.approx(2.0, rel=1e-3)


def test_merge_arcs_on_the_circle():
    assert merge_arcs([(350, 20), (5, 10), (100, 5)]) == [(100.0, 5.0), (350.0, 25.0)]
    assert merge_arcs([(0, 200), (190, 200)]) == [(0.0, 360.0)]
    assert in_arc(5.0, 350.0, 20.0) and not in_arc(15.0, 350.0, 20.0)


# ---------------------------------------------------------------- planner on synthetic maps

RECT = Part.from_vertices([(0, 0), (40, 0), (40, 20), (0, 20)], name="rect")  # a = 22.36


def _synthetic_maps(rule):
    """A map set whose outcome ``rule(theta_i, d) -> (theta_f, dy, status)`` is set by hand."""
    d = np.round(np.concatenate([np.arange(-0.9, -0.05, 0.1), np.arange(0.1, 0.95, 0.1)]), 3)
    tf = np.empty((d.size, GRID.size))
    dy = np.empty_like(tf)
    st = np.empty(tf.shape, dtype=np.int8)
    for i, dd in enumerate(d):
        for j, th in enumerate(GRID):
            tf[i, j], dy[i, j], st[i, j] = rule(th, dd)
    return xr.Dataset({"theta_f": (("d", "theta_i"), tf), "dy": (("d", "theta_i"), dy),
                       "status": (("d", "theta_i"), st)}, coords={"d": d, "theta_i": GRID})


def test_planner_finds_the_hand_known_best_plan():
    # Pins above the centroid (d > 0) send every orientation to 45 deg and push the
    # part down 2 mm; pins below send it to 45 or 225 deg by half-turns: one pin above
    # is the unique single-set plan with the widest margin.
    def rule(th, d):
        if d > 0:
            return 45.0, -2.0, OK
        return (45.0 if th < 180 else 225.0), 2.0, OK
    maps = load_maps(_synthetic_maps(rule), 5.0, 2.0)
    a = RECT.a
    states = {k: s.y_lo for k, s in Planner(RECT, maps, {}, 0.1, 0.9).initial_states().items()}
    assert sorted(states.values()) == pytest.approx([10, 10, 20, 20])
    pins = {"low": 20 - 0.5 * a, "high": 20 + 0.5 * a, "too_close": 20 + 0.05 * a,
            "best": 15 + 0.5 * a}
    plans = Planner(RECT, maps, pins, 0.1, 0.9).search(2)
    best = plans[0]
    assert best.pins == ("best",) and best.n_sets == 1
    assert best.final_sets == [(45.0, 0.0)]
    # d = (y_pin - y_c)/a = 0.5 + 5/a for y_c = 10 and 0.5 - 5/a for y_c = 20.
    assert best.margin == pytest.approx(min(0.5 - 5 / a - 0.1, 0.9 - (0.5 + 5 / a)), abs=1e-12)
    # Metastable (|d| = 0.05) for the y_c = 20 states as they arrive; allowed only
    # after a first pin has moved every part 2 mm down (d = 0.14 then).
    assert Planner(RECT, maps, pins, 0.1, 0.9).transition(State((90.0, 0.0), 20.0, 20.0), "too_close") is None
    assert all(p.pins[0] != "too_close" for p in plans)
    assert any(p.pins[1:] == ("too_close",) for p in plans)
    branches = best.branches
    assert set(branches) == {"state 1", "state 2", "state 3", "state 4"}
    step = branches["state 1"][0][0]
    assert step.band.pair == (45.0, 0.0) and step.com_interval[0] == pytest.approx(step.com_interval[1])
    assert step.carried is None  # a paper step carries no state set


def test_planner_forbids_jamming_pins_and_keeps_misses():
    def rule(th, d):
        if d > 0.5:
            return th, 0.0, MISS
        if d < 0:
            return 0.0, 0.0, JAMMED
        return 90.0, -1.0, OK
    maps = load_maps(_synthetic_maps(rule), 5.0, 2.0)
    a = RECT.a
    pl = Planner(RECT, maps, {"jam": 10 - 0.3 * a, "miss": 10 + 0.7 * a, "turn": 10 + 0.3 * a}, 0.1, 0.9)
    st = State((0.0, 0.0), 10.0, 10.0)
    assert pl.transition(st, "jam") is None
    children, _ = pl.transition(st, "miss")
    assert [c.arc for c in children] == [(0.0, 0.0)] and children[0].y_lo == 10.0
    children, _ = pl.transition(st, "turn")
    assert [c.arc for c in children] == [(90.0, 0.0)] and children[0].y_lo == pytest.approx(9.0)


def test_uncertain_state_branches_into_every_band_it_covers():
    def rule(th, d):
        return (30.0 if th < 100 else 200.0), 0.0, OK
    maps = load_maps(_synthetic_maps(rule), 5.0, 2.0)
    pl = Planner(RECT, maps, {"p": 25.0}, 0.1, 0.9)
    children, _ = pl.transition(State((90.0, 20.0), 10.0, 10.0), "p")
    assert sorted(c.arc for c in children) == [pytest.approx((30.0, 0.0)), pytest.approx((200.0, 0.0))]
    # the bracketing grid step: an arc ending 1 degree before the jump still branches
    children, _ = pl.transition(State((90.0, 9.0), 10.0, 10.0), "p")
    assert len(children) == 2
    children, _ = Planner(RECT, maps, {"p": 25.0}, 0.1, 0.9, coverage="nearest").transition(
        State((90.0, 8.0), 10.0, 10.0), "p")
    assert len(children) == 1


# ---------------------------------------------------------------- real triangles

TRIANGLE = Part.from_vertices([(0, 0), (60, 0), (15, 35)], name="asym_triangle")


@pytest.fixture(scope="module")
def triangle_plan():
    d = [-0.9, -0.8, -0.7, -0.6, -0.5, -0.4, -0.3, -0.2, -0.1, 0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9]
    ds = simulate.compute_map(TRIANGLE, GRID, d, 0.15, 3.0)
    pl = Planner(TRIANGLE, load_maps(ds, 5.0, 2.0), {"A": 42.5, "B": 2.5, "C": 35.0}, 0.1, 0.9)
    plans = pl.search(2)
    return pl, plans


def test_triangle_plan_is_confirmed_by_full_rollouts(triangle_plan):
    pl, plans = triangle_plan
    best = plans[0]
    # The number of final sets the plan claims is the number an independent
    # replay sees: every initial state, perturbed (random draws plus the
    # corners of the box), pushed by plain rollouts through the plan's pins;
    # the final orientations of all states fall into that many clusters.
    trials = trial_inputs(TRIANGLE, len(best.pins), 4, seed=21, mu=(0.15, 0.15))
    finals = replay_sequence(TRIANGLE, [pl.pins[p] for p in best.pins], trials)
    assert finals is not None, "a trial jams or a pin passes a state's centroid on both sides"
    thetas = [t for rows in finals for t, _ in rows]
    assert best.n_sets == n_clusters(thetas, TRIANGLE.symmetry_order()), (best.final_sets, sorted(thetas))
    res = verify_plan(TRIANGLE, best.to_dict(), pl.pins, pl.initial_states(), 0.15, 3.0,
                      settings=VerifySettings(trials=30, seed=3, corners=False))
    for row in res["rows"]:
        assert row["trials"] == 30 and row["successes"] >= 29, row


def test_verification_counts_a_plan_that_fails_for_one_state(triangle_plan):
    pl, plans = triangle_plan
    plan = json.loads(json.dumps(plans[0].to_dict()))
    # Claim state 1 ends 90 degrees away from where it really goes.
    for branch in plan["initial_states"]["state 1"]:
        branch[-1]["band"]["start"] = (branch[-1]["band"]["start"] + 90.0) % 360.0
    plan["final_sets"] = []
    res = verify_plan(TRIANGLE, plan, pl.pins, pl.initial_states(), 0.15, 3.0,
                      settings=VerifySettings(trials=30, seed=3))
    rows = {r["state"]: r for r in res["rows"]}
    n = 30 + 2 ** (3 + len(plan["pins"]))  # random trials plus the corners of the box
    assert rows["state 1"]["failures"] == n and rows["state 1"]["reasons"] == {"other band": n}
    assert rows["state 2"]["successes"] >= n - 1 and rows["state 3"]["successes"] >= n - 1
    assert len(res["trials_detail"]) == 3 * n and res["trials"] == 3 * n


def test_verification_is_reproducible(triangle_plan):
    pl, plans = triangle_plan
    a = verify_plan(TRIANGLE, plans[0].to_dict(), pl.pins, pl.initial_states(), 0.15, 3.0,
                    settings=VerifySettings(trials=5, seed=7))
    b = verify_plan(TRIANGLE, plans[0].to_dict(), pl.pins, pl.initial_states(), 0.15, 3.0,
                    settings=VerifySettings(trials=5, seed=7))
    assert [t["final_theta"] for t in a["trials_detail"]] == [t["final_theta"] for t in b["trials_detail"]]


def test_cli_plan_for_new_outline(tmp_path, capsys):
    from pipeline.cli import main
    out = tmp_path / "plan.json"
    assert main(["plan", "--vertices", "0,0 40,0 40,20 0,20", "--name", "rect", "--catalog",
                 str(tmp_path / "cat"), "--depth", "1", "--pins=-5,5,15,25,35", "--out", str(out),
                 "--mode", "paper"]) == 0
    text = capsys.readouterr().out
    assert "state 4" in text and "#1:" in text
    res = json.loads(out.read_text())
    assert res["part"]["name"] == "rect" and res["plans"]
    # The maps it needed are now stored and indexed.
    from pipeline.maps.catalog import Catalog
    assert any(e["part_name"] == "rect" for e in Catalog.open(tmp_path / "cat").entries)
    assert main(["plan", "--catalog", str(tmp_path / "cat"), "--part", "nope"]) == 2


def test_moving_pin_limits_apply_to_the_offset_of_its_path():
    # Same maps for a static pin and one moving at 2 v_b: every orientation goes to
    # 45 deg. At station offset d = 0.2 the moving pin's path passes the centroid at
    # 0.2 / sqrt(5) = 0.089 < d_min (metastable: forbidden); at d = 0.5 it is 0.224,
    # allowed, with that margin; a plan may then end with it after static pins.
    def rule(th, d):
        return 45.0, 0.0, OK
    maps = load_maps(_synthetic_maps(rule), 5.0, 2.0)
    a = RECT.a
    dynamic = {"near": (20 + 0.2 * a, 2.0), "far": (20 + 0.5 * a, 2.0)}
    pl = Planner(RECT, maps, {"static": 20 + 0.2 * a}, 0.1, 0.9, dynamic=dynamic,
                 dynamic_maps={2.0: maps})
    state = State((90.0, 0.0), 20.0, 20.0)
    assert pl.transition(state, "static") is not None
    assert pl.transition(state, "near") is None
    children, margin = pl.transition(state, "far")
    assert margin == pytest.approx(0.5 / math.sqrt(5.0) - 0.1, abs=1e-12)
    assert children[0].history[-1].v_pin == 2.0
    with pytest.raises(PinfeedError, match="no maps are stored at that speed"):
        Planner(RECT, maps, {}, 0.1, 0.9, dynamic={"x": (10.0, -1.0)}, dynamic_maps={2.0: maps})
