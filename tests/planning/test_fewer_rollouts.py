"""The nominal enumeration rolls out fewer rollouts and finds exactly the
same levels: a candidate is rolled out one column (resting state) at a time
and dropped at the first column that jams or passes a touched centroid
within the pins' tolerance (the rule drops it whatever its other columns
do), and an outcome already rolled out for the same key (rounded pose, pin
offset, speed, support) is reused (a rollout starts from the rounded pose,
so its outcome is a function of the key alone)."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from pipeline.parts.outlines import read_outline
from pipeline.parts.part import Part
from pipeline.planning.tight.enumerate import NominalTree

CAD = Path(__file__).resolve().parents[1] / "data" / "cad"
PARTS = {
    "triangle": lambda: Part.from_vertices([[0, 0], [60, 0], [15, 35]], name="tri"),
    "t_bracket": lambda: Part.from_vertices([[0, 0], [60, 0], [60, 10], [35, 10], [35, 40], [25, 40], [25, 10],
                                             [0, 10]], name="t"),
    "l_bracket": lambda: Part.from_vertices([[0, 0], [60, 0], [60, 15], [15, 15], [15, 40], [0, 40]], name="l"),
    "holed_bracket": lambda: (lambda o: Part.from_vertices(o.vertices, name="holed", holes=o.holes))(
        read_outline(CAD / "holed_bracket.dxf")),
}


class EagerTree(NominalTree):
    """The enumeration as it was: every column of every candidate rolled out
    at once, each distinct key once per batch, nothing reused."""

    def _columns(self, theta, dy_pin, v_pin, stretch, span=None, orders=None, keys=None):
        self._outcomes.codes = self._outcomes.codes[:0]  # forget: roll out every key of the batch
        self._outcomes.status, self._outcomes.theta_f, self._outcomes.dy = (
            self._outcomes.status[:0], self._outcomes.theta_f[:0], self._outcomes.dy[:0])
        out = self._rollouts(theta, dy_pin, v_pin, stretch)
        self._outcomes.codes = self._outcomes.codes[:0]
        self._outcomes.status, self._outcomes.theta_f, self._outcomes.dy = (
            self._outcomes.status[:0], self._outcomes.theta_f[:0], self._outcomes.dy[:0])
        return (*out, None)


def _pins(part: Part, n: int) -> np.ndarray:
    top = float(part.stable_states()[:, 1].max()) * 2.0
    return np.linspace(-0.2 * top, 1.1 * top, n)


@pytest.mark.parametrize("name", list(PARTS))
def test_the_lazy_enumeration_finds_the_same_levels_with_no_more_rollouts(name):
    part = PARTS[name]()
    pins = _pins(part, 9)
    lazy, eager = NominalTree(part, pins, 0.2, 3.0), EagerTree(part, pins, 0.2, 3.0)
    for a, b in zip(lazy.levels(3), eager.levels(3)):
        np.testing.assert_array_equal(a.seq, b.seq)
        np.testing.assert_array_equal(a.theta, b.theta)
        np.testing.assert_array_equal(a.y, b.y)
        np.testing.assert_array_equal(a.margin, b.margin)
        assert a.size > 0
    assert lazy.rollouts < eager.rollouts


def test_chunks_and_reuse_do_not_change_a_level():
    part = PARTS["t_bracket"]()
    pins = _pins(part, 9)
    tree = NominalTree(part, pins, 0.2, 3.0)
    two = tree.extend(tree.extend(tree.root()))
    whole = tree.extend(two)
    fresh = NominalTree(part, pins, 0.2, 3.0)
    parts = [fresh.extend(two.rows(i, i + 7)) for i in range(0, two.size, 7)]
    for k in ("seq", "theta", "y", "margin"):
        np.testing.assert_array_equal(np.concatenate([getattr(p, k) for p in parts]), getattr(whole, k))


def test_moving_pins_enumerate_the_same_levels():
    part = PARTS["triangle"]()
    pins = _pins(part, 6)
    speeds = np.where(np.arange(pins.size) % 2, 0.3, -0.3)
    lazy, eager = NominalTree(part, pins, 0.2, 3.0, speeds=speeds), EagerTree(part, pins, 0.2, 3.0, speeds=speeds)
    for a, b in zip(lazy.levels(2), eager.levels(2)):
        for k in ("seq", "theta", "y", "margin"):
            np.testing.assert_array_equal(getattr(a, k), getattr(b, k))
    assert lazy.rollouts <= eager.rollouts


def test_replays_reuse_the_states_of_earlier_calls_and_give_the_same_numbers():
    from pipeline.planning.claims.replay import replay_shared
    from pipeline.planning.core.settings import ClaimSettings, SearchSettings, VerifySettings
    from pipeline.planning.tight.complete import FixedPinSearch
    from pipeline.planning.tight.judge import stack

    part = PARTS["l_bracket"]()
    pins = {f"P{k}": float(y) for k, y in enumerate(_pins(part, 6))}
    search = FixedPinSearch(part, pins, (0.1, 0.3), ClaimSettings(10.0, 0.995), VerifySettings(trials=20),
                            SearchSettings(3.0))
    bench = search.bench
    inputs = bench.trials(3)
    full, screen, probe = stack(inputs), bench.screen_rows(inputs, 12, 8), bench.screen_rows(inputs, 6, 2)
    rng = np.random.default_rng(1)
    heights = search.pins.heights[rng.integers(0, 6, size=(40, 3))]
    speeds = np.zeros_like(heights)
    for rows, lo, hi in ((probe, 0, 40), (screen, 0, 15), (screen, 10, 40), (full, 5, 12), (full, 0, 40)):
        before = len(bench.kept)
        tf, jam = bench.replay(heights[lo:hi], speeds[lo:hi], rows)
        th, yc, mu, offs, sup = rows
        ref_tf, ref_jam = replay_shared(part, heights[lo:hi], speeds[lo:hi], th, yc, mu, offs, bench.pin_radius,
                                        bench.model, bench.step.ds_max, bench.step.tol,
                                        belt_speed=bench.belt_speed, mu_s=bench.mu_s,
                                        support=sup, supports=bench.supports)
        np.testing.assert_array_equal(tf, ref_tf)
        np.testing.assert_array_equal(jam, ref_jam)
        assert len(bench.kept) > before or rows is full


def test_verifying_plans_with_a_memo_gives_the_same_records():
    from pipeline.planning.claims import replay as replay_module
    from pipeline.planning.claims.replay import ReplayMemo
    from pipeline.planning.claims.verify import verify_plan
    from pipeline.planning.core.resting import resting_states
    from pipeline.planning.core.settings import VerifySettings

    part = PARTS["l_bracket"]()
    heights = _pins(part, 6)
    pins = {f"P{k}": float(y) for k, y in enumerate(heights)}
    states = resting_states(part)
    trials = VerifySettings(trials=12, seed=5)
    plans = [["P1", "P3", "P2"], ["P1", "P3", "P4"], ["P1", "P3", "P2"], ["P2", "P3", "P4"], ["P1", "P3"]]
    memo, counted = ReplayMemo(), []
    original = replay_module.pin_step
    try:
        replay_module.pin_step = lambda *a, **k: counted.append(np.size(a[1])) or original(*a, **k)
        with_memo = [verify_plan(part, {"pins": p, "initial_states": {k: [] for k in states}}, pins, states, (0.1, 0.3), 3.0, settings=trials, memo=memo)
                     for p in plans]
        used = sum(counted)
        counted.clear()
        without = [verify_plan(part, {"pins": p, "initial_states": {k: [] for k in states}}, pins, states, (0.1, 0.3), 3.0, settings=trials) for p in plans]
    finally:
        replay_module.pin_step = original
    assert with_memo == without
    assert used < sum(counted)


def test_sampled_carried_sets_with_a_memo_are_the_same():
    from pipeline.config import load_config
    from pipeline.planning.claims.replay import ReplayMemo
    from pipeline.planning.core.settings import PlannerSettings, VerifySettings
    from pipeline.planning.plans.planner import planner_for
    from pipeline.planning.tight.certify import sampled_plan

    part = PARTS["triangle"]()
    planner = planner_for(part, PlannerSettings.from_config(load_config()).at(0.3))
    by_height = {p.y: k for k, p in planner.pins.items()}
    first = [by_height[10.0], by_height[27.5]]
    sequences = [first + [by_height[47.5]], first + [by_height[10.0]], first + [by_height[47.5]]]
    memo = ReplayMemo()
    for labels in sequences:
        kept, plain = sampled_plan(planner, labels, 0.0, VerifySettings(trials=30), memo=memo), \
            sampled_plan(planner, labels, 0.0, VerifySettings(trials=30))
        assert kept.to_dict() == plain.to_dict()
    assert len(memo) < 3 * 3 * len(memo.trials)  # the shared first pins were kept once
