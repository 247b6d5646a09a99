"""The cascade of growing trial subsets before a full judgement rejects only
what the full judgement rejects: failures on a subset never exceed failures
on the whole set, a sequence the cascade drops does not orient on the full
trials, and a search with the cascade finds the same plans as one without."""
import numpy as np
import pytest

from pipeline.parts.part import Part
from pipeline.planning.claims import orient
from pipeline.planning.core.settings import ClaimSettings, Friction, SearchSettings, VerifySettings
from pipeline.planning.tight import screen
from pipeline.planning.tight.complete import FixedPinSearch
from pipeline.planning.tight.screen import CASCADE
from pipeline.planning.tight.judge import TrialBench, stack

MU = (0.1, 0.3)
CLAIMS = ClaimSettings(10.0, 0.99, rule="point")
VERIFY = VerifySettings(trials=400, seed=5)
SEARCH = SearchSettings(3.0)


def _bench(part):
    return TrialBench(part, Friction.parse(MU), CLAIMS, VERIFY, SEARCH)


def _random_sequences(part, n_pins, n, seed):
    rng = np.random.default_rng(seed)
    top = max(y for _, y in part.stable_states()) * 1.6
    heights = rng.uniform(0.05 * part.a, top, size=(n, n_pins))
    return heights, np.zeros_like(heights)


@pytest.mark.parametrize("vertices", [[[0, 0], [60, 0], [45, 50]], [[0, 0], [70, 0], [50, 25], [10, 25]]])
def test_a_subset_never_fails_more_than_the_whole(vertices):
    part = Part.from_vertices(vertices)
    bench = _bench(part)
    heights, speeds = _random_sequences(part, 3, 12, seed=len(vertices))
    inputs = bench.trials(3)
    full = stack(inputs)
    full_fails = bench.failures(heights, speeds, full)
    allowed = bench.allowed_failures(full[0].size)
    verdicts = list(bench.judge(heights, speeds, full))
    for sizes in ((12, 8), *CASCADE):
        sub = bench.screen_rows(inputs, *sizes)
        assert sub[0].size < full[0].size
        sub_fails = bench.failures(heights, speeds, sub)
        assert np.all(sub_fails <= full_fails)
        # what a stage rejects, the full judgement rejects
        for f, v in zip(sub_fails, verdicts):
            if f > allowed:
                assert not v["orients"]


def _thin_search(part, pins):
    # a narrow tolerance and one candidate judged in full: the rest meet the cascade
    search = FixedPinSearch(part, pins, MU, ClaimSettings(5.0, 0.99, rule="point"), VERIFY, SEARCH)
    return search.run(3, candidates=1, keep=5)


def test_the_cascade_changes_no_plan_and_no_count(monkeypatch):
    """The same plans, verdicts and level counts of orienting sequences with
    and without the cascade; only the full replays saved differ."""
    part = Part.from_vertices([[0, 0], [50, 0], [10, 30]], name="sharp_triangle")
    top = max(y for _, y in part.stable_states()) * 1.8
    pins = {f"Q{k}": float(y) for k, y in enumerate(np.linspace(0.05 * part.a, top, 9), start=1)}
    with_cascade = _thin_search(part, pins)
    monkeypatch.setattr(screen, "CASCADE", ())
    without = _thin_search(part, pins)
    assert [p.labels for p in with_cascade.plans] == [p.labels for p in without.plans]
    for a, b in zip(with_cascade.plans, without.plans):
        assert a.verdict == b.verdict
    for a, b in zip(with_cascade.levels, without.levels):
        assert a["orienting"] == b["orienting"] and a["certified"] == b["certified"]
        assert a["judged"] <= b["judged"]
        assert a["judged"] + a.get("cascade_out", 0) == b["judged"]
    assert sum(lv.get("cascade_out", 0) for lv in with_cascade.levels) > 0  # the cascade was used


@pytest.mark.parametrize("tolerance", [5.0, 8.0])
def test_hard_trials_learned_from_judged_sequences_change_no_plan(tolerance):
    """A search that keeps no evidence (the moving-pin stage's) screens with
    the trials its judged sequences failed most: the same plans, verdicts and
    counts of orienting sequences as the search without it (at 8 deg a plan
    of three pins; at 5 deg none, where the hard trials reject a sequence
    that the full judgement rejects too), and no evidence gathered."""
    part = Part.from_vertices([[0, 0], [50, 0], [10, 30]], name="sharp_triangle")
    top = max(y for _, y in part.stable_states()) * 1.8
    pins = {f"Q{k}": float(y) for k, y in enumerate(np.linspace(0.05 * part.a, top, 9), start=1)}

    def search(evidence):
        s = FixedPinSearch(part, pins, MU, ClaimSettings(tolerance, 0.99, rule="point"), VERIFY, SEARCH)
        s.evidence = evidence
        return s.run(3, candidates=1, keep=5)

    learned, plain = search(False), search(True)
    assert [p.labels for p in learned.plans] == [p.labels for p in plain.plans]
    assert bool(learned.plans) == (tolerance == 8.0)
    for a, b in zip(learned.plans, plain.plans):
        assert a.verdict == b.verdict
    for a, b in zip(learned.levels, plain.levels):
        assert a["orienting"] == b["orienting"] and a["certified"] == b["certified"]
        assert (a["judged"] + a.get("cascade_out", 0) + a.get("hard_trials_out", 0)
                == b["judged"] + b.get("cascade_out", 0))
    if tolerance == 5.0:
        assert sum(lv.get("hard_trials_out", 0) for lv in learned.levels) > 0  # the hard trials were used
    assert learned.best_effort == [] and (plain.plans or plain.best_effort)


def test_the_hardest_trials_first_change_no_count_and_replay_less(monkeypatch):
    """The hard trials in two steps (the ``HARD_FIRST`` hardest, then all
    ``HARD_TRIALS``) reject exactly what all of them at once reject: the same
    plans, verdicts and every level count, with fewer sequence-trial pairs
    replayed (rolled out, or read from the bench's memo)."""
    from pipeline.planning.tight.judge import TrialBench
    part = Part.from_vertices([[0, 0], [50, 0], [10, 30]], name="sharp_triangle")
    top = max(y for _, y in part.stable_states()) * 1.8
    pins = {f"Q{k}": float(y) for k, y in enumerate(np.linspace(0.05 * part.a, top, 9), start=1)}
    replay = TrialBench.replay

    def search(hard_first):
        monkeypatch.setattr(screen, "HARD_FIRST", hard_first)
        pairs = []

        def counted(self, heights, speeds, rows, *args, **kwargs):
            pairs.append(np.atleast_2d(heights).shape[0] * np.size(rows[0]))
            return replay(self, heights, speeds, rows, *args, **kwargs)

        monkeypatch.setattr(TrialBench, "replay", counted)
        # a strict claim (at most one failure allowed): few of the hardest trials already reject
        s = FixedPinSearch(part, pins, MU, ClaimSettings(5.0, 0.999, rule="point"), VERIFY, SEARCH)
        s.evidence = False
        return s.run(3, candidates=1, keep=5), sum(pairs)

    (staged, staged_pairs), (at_once, at_once_pairs) = search(16), search(screen.HARD_TRIALS)
    assert [p.labels for p in staged.plans] == [p.labels for p in at_once.plans]
    assert staged.levels == at_once.levels
    assert sum(lv.get("hard_trials_out", 0) for lv in staged.levels) > 0  # the hard trials were used
    assert staged_pairs < at_once_pairs


def test_the_failing_trials_are_those_outside_the_best_arc():
    part = Part.from_vertices([[0, 0], [70, 0], [50, 25], [10, 25]])
    bench = _bench(part)
    rng = np.random.default_rng(3)
    finals = np.concatenate([rng.normal(40.0, 4.0, (5, 30)), rng.uniform(0, 360, (5, 10))], axis=1) % 360
    jammed = rng.random(finals.shape) < 0.05
    failing = bench.failing(finals, jammed)
    for k in range(finals.shape[0]):
        held, _ = orient.best_arc(finals[k][~jammed[k]], bench.tolerance, bench.order)
        assert (~failing[k]).sum() == held and not (~failing[k] & jammed[k]).any()
