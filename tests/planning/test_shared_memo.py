"""One memo of trial states from the search to the final verification.

The complete search's trial bench keeps each trial's state after each prefix
of pins (a ``ReplayMemo``); the final verification and the nearest "yes"
replay the same held-out trials through the same plans and read those
states instead of rolling them out again. On the 70 x 25 mm trapezoid (two
pins, the point rule on 30 trials per state): the answer is the same, field
for field, with the memo shared and with each step rolling out on its own,
and the shared steps roll out nothing the search had rolled out. A memo
kept for other rollout settings is never read.
"""
import numpy as np
import pytest

from rollout_counter import count_rollouts

from pipeline.config import load_config
from pipeline.parts.part import Part
from pipeline.planning import PlannerSettings
from pipeline.planning.claims.replay import ReplayMemo, kernel_kw, replay
from pipeline.planning.tight.judge import TrialBench
from pipeline.planning.plans import nearest_part
from pipeline.planning.plans import plan as plan_module
from pipeline.planning.plans.plan import plan_tight

TRAPEZOID = Part.from_vertices([[0.0, 0.0], [70.0, 0.0], [50.0, 25.0], [10.0, 25.0]], "trapezoid")


def _settings(tmp_path, tolerance):
    config = load_config()
    config["catalog_dir"] = str(tmp_path)
    config["planner"].update(pins="auto", depth=2, tolerance_deg=tolerance, mu_c=0.2, frictions=[])
    config["planner"]["dynamic"].update(depth=0, speeds=[])
    config["verify"].update(trials=30, rule="point")
    return PlannerSettings.from_config(config).at(0.2)


def _without_seconds(x):
    if isinstance(x, dict):
        return {k: _without_seconds(v) for k, v in x.items() if k != "seconds"}
    if isinstance(x, list):
        return [_without_seconds(v) for v in x]
    return x


def _planned(tmp_path, tolerance, shared: bool, monkeypatch) -> tuple:
    """The plan's dict and the rows rolled out by its verification and by the
    nearest "yes"'s replays of the kept plans (``shared`` False: each with a
    memo of its own, as before the memo was shared)."""
    counted = {"verification": 0, "kept plans": 0}

    def measured(step, fn, drop):
        def wrapper(*args, **kwargs):
            if not shared:
                args = args[:drop]
                kwargs.pop("memo", None), kwargs.pop("reuse", None)
            before = sum(rows)
            out = fn(*args, **kwargs)
            counted[step] += sum(rows) - before
            return out
        return wrapper

    rows = count_rollouts(monkeypatch)
    monkeypatch.setattr(plan_module, "_verify_candidates", measured("verification", plan_module._verify_candidates, 8))
    monkeypatch.setattr(nearest_part, "_kept_tolerance", measured("kept plans", nearest_part._kept_tolerance, 4))
    entry = plan_tight(TRAPEZOID, _settings(tmp_path, tolerance))
    monkeypatch.undo()
    return _without_seconds(entry.to_dict()), counted


def test_the_verification_reads_the_held_out_trials_that_certified_the_plans(tmp_path, monkeypatch):
    alone, rolled_alone = _planned(tmp_path / "alone", 30.0, False, monkeypatch)
    shared, rolled_shared = _planned(tmp_path / "shared", 30.0, True, monkeypatch)
    assert alone["orients"] and shared == alone
    assert rolled_alone["verification"] > 0 and rolled_shared["verification"] == 0


def test_the_nearest_yes_reads_the_verifications_replays(tmp_path, monkeypatch):
    alone, rolled_alone = _planned(tmp_path / "alone", 6.0, False, monkeypatch)
    shared, rolled_shared = _planned(tmp_path / "shared", 6.0, True, monkeypatch)
    assert not alone["orients"] and shared == alone and alone["nearest_yes"]["plans_tried"]
    assert rolled_alone["kept plans"] > 0 and rolled_shared["kept plans"] == 0


def _trials(n=12, pins=2, seed=3):
    rng = np.random.default_rng(seed)
    return (rng.uniform(0, 360, n), np.full(n, 12.0), np.full(n, 0.2), rng.uniform(-0.3, 0.3, (n, pins)))


@pytest.mark.parametrize("other", ["pin radius", "model", "kernel step", "part", "supports"])
def test_a_memo_kept_for_other_rollout_settings_is_not_read(other):
    kw = kernel_kw(0.05, 1e-6, None, 0.5)
    memo = ReplayMemo()
    assert memo.serves(TRAPEZOID, 3.0, "minpower", kw, None)
    assert memo.serves(TRAPEZOID, 3, "minpower", dict(kw), None)  # the same settings, written otherwise
    changed = {"pin radius": (TRAPEZOID, 2.0, "minpower", kw, None),
               "model": (TRAPEZOID, 3.0, "ellipsoid", kw, None),
               "kernel step": (TRAPEZOID, 3.0, "minpower", kernel_kw(0.1, 1e-6, None, 0.5), None),
               "part": (Part.from_vertices(TRAPEZOID.vertices, "copy"), 3.0, "minpower", kw, None),
               "supports": (TRAPEZOID, 3.0, "minpower", kw, [None])}[other]
    assert not memo.serves(*changed)


def test_a_replay_with_a_memo_of_other_settings_gives_its_own_numbers():
    heights, speeds = [14.0, 6.0], [0.0, 0.0]
    theta, y_c, mu, offsets = _trials()
    memo = ReplayMemo()
    first = replay(TRAPEZOID, heights, speeds, theta, y_c, mu, offsets, 3.0, "minpower", memo=memo)
    kept = len(memo)
    other = replay(TRAPEZOID, heights, speeds, theta, y_c, mu, offsets, 1.0, "minpower", memo=memo)
    alone = replay(TRAPEZOID, heights, speeds, theta, y_c, mu, offsets, 1.0, "minpower")
    assert kept > 0 and len(memo) == kept  # the other radius neither read nor wrote it
    for a, b in zip(other, alone):
        assert np.array_equal(a, b)
    assert not np.array_equal(first[0], other[0])  # the radius matters here, so a wrong read would show
    again = replay(TRAPEZOID, heights, speeds, theta, y_c, mu, offsets, 3.0, "minpower", memo=memo)
    for a, b in zip(again, first):
        assert np.array_equal(a, b)


def test_a_bench_memo_gives_replay_its_misses_and_jams(tmp_path, monkeypatch):
    """States the trial bench kept (a pin that misses the part, another that
    meets it) serve ``replay`` whole: its finals, heights, jam reasons and
    misses are those of a replay on its own, with no rollout."""
    s = _settings(tmp_path, 10.0)
    bench = TrialBench(TRAPEZOID, s.friction, s.claims, s.verify, s.search)
    rows = bench.held_out(3)
    heights, speeds = np.array([[14.0, 400.0, 6.0]]), np.zeros((1, 3))  # the second pin is far above the part
    bench.replay(heights, speeds, rows)
    th, yc, mu, offsets, sup = rows
    args = (TRAPEZOID, heights[0], speeds[0], th, yc, mu, offsets, bench.pin_radius, bench.model,
            bench.step.ds_max, bench.step.tol)
    alone = replay(*args)
    counted = count_rollouts(monkeypatch)
    shared = replay(*args, memo=bench.kept)
    assert sum(counted) == 0
    assert alone[3][:, 1].all() and not alone[3][:, 0].all()  # every trial misses pin 2, not every one pin 1
    for a, b in zip(alone, shared):
        assert np.array_equal(a, b)


def test_a_full_memo_keeps_what_fits():
    memo = ReplayMemo(max_kept=5)
    memo.serves(TRAPEZOID, 3.0, "minpower", kernel_kw(0.05, 1e-6, None, 0.5), None)
    nodes, trials = np.ones(8, dtype=np.int64), np.arange(8, dtype=np.int64)
    memo.add(nodes, trials, np.arange(8.0), np.zeros(8), np.array([""] * 8, dtype=object), np.zeros(8, bool))
    assert len(memo) == 5 and memo.half_full
    assert (memo.lookup(nodes, trials) >= 0).tolist() == [True] * 5 + [False] * 3
    assert memo.get(memo.lookup(nodes[:5], trials[:5]))[0].tolist() == [0.0, 1.0, 2.0, 3.0, 4.0]


def test_equal_trials_in_one_replay_do_not_displace_the_next_replays_states(tmp_path):
    """With no friction spread (``mu_sigma`` 0) the box's corners come in
    equal pairs, one trial number each, so a replay keeps some (prefix,
    trial) states twice. The memo once placed states by its count of
    distinct keys, so the next replay's states overwrote kept ones: every
    replay through the bench must still give the numbers of a replay alone."""
    config = load_config()
    config["catalog_dir"] = str(tmp_path)
    config["planner"].update(pins="auto", depth=2, tolerance_deg=10.0, mu_c=0.2, frictions=[])
    config["verify"].update(trials=30, rule="point", mu_sigma=0.0)
    s = PlannerSettings.from_config(config).at(0.2)
    bench = TrialBench(TRAPEZOID, s.friction, s.claims, s.verify, s.search)
    rows = bench.held_out(2)
    th, yc, mu, offsets, sup = rows
    ids = ReplayMemo().trial_ids(th, yc, mu, offsets, sup)
    assert np.unique(ids).size < ids.size  # equal trials are there
    for block in ([[14.0, 6.0], [14.0, 10.0]], [[20.0, 6.0], [14.0, 6.0], [6.0, 14.0], [14.0, 10.0]]):
        heights = np.array(block)
        finals, jammed = bench.replay(heights, np.zeros(heights.shape), rows)
        for k, h in enumerate(heights):
            alone = replay(TRAPEZOID, h, [0.0, 0.0], th, yc, mu, offsets, bench.pin_radius, bench.model,
                           bench.step.ds_max, bench.step.tol)
            assert np.array_equal(finals[k], alone[0] % 360.0) and np.array_equal(jammed[k], alone[2] != "")
