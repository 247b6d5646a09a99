"""A time limit on the complete search: it returns in time, says it is not
complete and what it left unsearched; without one (or with one it never
reaches) the answer is the one the complete search gave before."""
from __future__ import annotations

import time

import numpy as np
import pytest

from pipeline.errors import PinfeedError
from pipeline.parts.part import Part
from pipeline.planning.core.settings import ClaimSettings, SearchSettings, VerifySettings
from pipeline.planning.tight.complete import FixedPinSearch, level_estimate
from pipeline.planning.tight import enumerate as enumerate_module
from pipeline.planning.tight import pacing
from pipeline.planning.tight.enumerate import NominalTree
from pipeline.progress import NO_DEADLINE, Deadline, duration_text

TRIANGLE = [[0, 0], [60, 0], [15, 35]]
PINS = {f"P{k}": float(y) for k, y in enumerate(np.arange(3, 44, 4), start=1)}  # 11 pins, 3 to 43 mm
HANG = 60.0  # seconds beyond the limit that would mean a hang (not a performance bound)


class SteppingClock:
    """A clock that moves ``step`` seconds at every read."""

    def __init__(self, step: float):
        self.now, self.step = 0.0, step

    def __call__(self):
        self.now += self.step
        return self.now


def _search(tolerance: float):
    part = Part.from_vertices(TRIANGLE, name="tri")
    return FixedPinSearch(part, PINS, 0.0, ClaimSettings(tolerance, 0.995, rule="point"), VerifySettings(trials=20),
                          SearchSettings(3.0))


def _answer(result) -> dict:
    return {"plans": [[list(p.labels), p.verdict["in_tolerance"], p.verdict["trials"],
                       round(p.verdict["width_deg"], 4)] for p in result.plans],
            "best": [[list(p.labels), p.verdict["in_tolerance"], p.verdict["trials"]] for p in result.best_effort],
            "levels": [(lv["pins"], lv["sequences"], lv["nominal_within"], lv["judged"], lv["certified"])
                       for lv in result.levels]}


# What the complete search answered before the time limit existed (recorded
# with the code of the commit before it, same part, pins, trials and claim).
BEFORE = {
    10.0: {"plans": [[["P2", "P7"], 156, 156, 4.8935], [["P2", "P6"], 156, 156, 7.9402]], "best": [],
           "levels": [(1, 11, 0, 0, 0), (2, 96, 2, 2, 2)]},
    1.0: {"plans": [], "best": [[["P2", "P4", "P8"], 172, 252], [["P11", "P2", "P7"], 152, 252],
                                [["P2", "P7"], 64, 156], [["P3"], 58, 108], [["P4"], 35, 108]],
          "levels": [(1, 11, 0, 0, 0), (2, 96, 0, 0, 0), (3, 760, 16, 0, 0)]},
}
# The deepest level's count changed since: it now also counts the sequences
# that stopped once their finals spread over the tolerance + 1 deg, whose
# other states might jam (``spread_out``). Rolled out in full, that level
# keeps the sequences recorded before (checked below).
DEEPEST_NOW = {1.0: 1041}


def _expected(tolerance: float) -> dict:
    """``BEFORE`` with the deepest level's count of now."""
    want = dict(BEFORE[tolerance], levels=list(BEFORE[tolerance]["levels"]))
    if tolerance in DEEPEST_NOW:
        pins, _, *rest = want["levels"][-1]
        want["levels"][-1] = (pins, DEEPEST_NOW[tolerance], *rest)
    return want


def test_the_deadline_keeps_a_reserve_for_verification_and_no_limit_never_ends():
    clock = SteppingClock(1.0)
    deadline = Deadline(10.0, clock=clock)  # made at t = 1
    assert deadline.limited and deadline.reserve == pytest.approx(2.0)
    assert not deadline.search_over()  # t = 2: 9 s left
    assert deadline.search_left() == pytest.approx(6.0)  # t = 3: 8 s left, less the 2 s reserve
    clock.now = 8.5  # the next read is t = 9.5: 1.5 s left, inside the reserve
    assert deadline.search_over() and not deadline.over()
    assert deadline.search_left() == 0.0  # inside the reserve: none, never negative
    clock.now = 11.0
    assert deadline.over()
    assert not NO_DEADLINE.limited and not NO_DEADLINE.search_over() and not NO_DEADLINE.over()
    assert NO_DEADLINE.search_left() == float("inf")
    assert Deadline(3600.0).reserve == 60.0  # at most a minute is kept back


def test_durations_and_the_level_estimate_read_as_one_line():
    assert duration_text(12.2) == "12 s"
    assert duration_text(240) == "4 min"
    assert duration_text(7080) == "1 h 58 min"
    line = level_estimate("4 fixed pin(s)", 593_810, 84.0)
    assert line == "4 fixed pin(s): 593,810 candidate sequences, about 1 h 58 min at 84/s (the pace of the level before)"
    assert "\n" not in line
    assert level_estimate("1 fixed pin(s)", 11, None) == "1 fixed pin(s): 11 candidate sequences"


@pytest.mark.parametrize("tolerance", [10.0, 1.0])
def test_without_a_limit_the_answer_is_the_one_before(tolerance):
    """No limit, and a limit the search never reaches, give the complete
    search's answer of before: same plans, verdicts and level counts."""
    unlimited = _search(tolerance).run(3, candidates=3)
    assert _answer(unlimited) == _expected(tolerance)
    assert unlimited.complete and "time_limit_s" not in unlimited.to_dict()
    roomy = _search(tolerance).run(3, candidates=3, deadline=Deadline(3600.0))
    assert _answer(roomy) == _expected(tolerance)
    assert roomy.evidence() == unlimited.evidence()
    record = roomy.to_dict()
    assert record["time_limit_s"] == 3600.0 and record["complete"] is True and record["unsearched"] == []
    if tolerance in DEEPEST_NOW:
        tree = NominalTree(Part.from_vertices(TRIANGLE, name="tri"), list(PINS.values()), 0.0, 3.0)
        *_, deepest = tree.levels(3)  # every state of every sequence rolled out
        assert deepest.size == BEFORE[tolerance]["levels"][-1][1]
        assert unlimited.levels[-1]["spread_out"] > 0


def test_a_tiny_limit_returns_in_time_and_lists_every_level_it_left():
    lines = []
    t0 = time.monotonic()
    # a clock that runs 1 s a read: the limit has passed before the first level
    result = _search(1.0).run(4, candidates=3, progress=lines.append,
                              deadline=Deadline(0.01, clock=SteppingClock(1.0)))
    assert time.monotonic() - t0 < 0.01 + HANG
    assert not result.complete and result.plans == [] and result.levels == []
    assert result.unsearched == ["1 fixed pin(s): not reached (11 candidate sequences)",
                                 "2 fixed pin(s): not reached", "3 fixed pin(s): not reached",
                                 "4 fixed pin(s): not reached"]
    text = result.evidence()
    assert text.startswith("no fixed-pin sequence was searched")
    assert "not searched: 1 fixed pin(s): not reached" in text
    assert "no level searched in full" in text
    record = result.to_dict()
    assert record["complete"] is False and record["complete_to_pins"] == 0


def test_a_limit_reached_mid_search_keeps_the_levels_done_and_says_what_is_left():
    """The limit ends the search part way (a second on a search that takes
    longer): the levels finished are the complete search's, and the rest is
    listed, level by level, never as the complete search's "no"."""
    t0 = time.monotonic()
    result = _search(1.0).run(6, candidates=3, deadline=Deadline(1.0))  # 6 pins: over a million sequences
    took = time.monotonic() - t0
    assert took < 1.0 + HANG
    if result.complete:  # a machine so fast that the whole search fits in a second
        pytest.skip(f"the whole search took {took:.2f} s, within the limit")
    finished = [lv for lv in result.levels if lv.get("complete") is not False][:len(BEFORE[1.0]["levels"])]
    assert [(lv["pins"], lv["sequences"]) for lv in finished] == [(k, n) for k, n, *_ in
                                                                  BEFORE[1.0]["levels"]][:len(finished)]
    assert result.unsearched and any("6 fixed pin(s)" in u for u in result.unsearched)
    text = result.evidence()
    assert "among the sequences searched" in text and "not searched:" in text
    assert (f"complete up to {result.complete_to} pin(s) only" if result.complete_to
            else "no level searched in full") in text


def test_a_cut_enumeration_keeps_exactly_the_sequences_of_the_parents_done(monkeypatch):
    part = Part.from_vertices(TRIANGLE, name="tri")
    tree = NominalTree(part, np.array(list(PINS.values())), 0.0, 3.0)
    two = tree.extend(tree.extend(tree.root()))
    whole = tree.extend(two)
    monkeypatch.setattr(enumerate_module, "FIRST_PARENTS", 8)  # batches of 8 parents, then at most 64
    # a clock that runs 1 s a read: the search time is over at the second read, after two batches
    cut = tree.extend(two, deadline=Deadline(1.5, clock=SteppingClock(1.0)))
    assert cut.cut is not None and 0 < cut.cut[0] < cut.cut[1] == two.size * len(PINS)
    assert cut.size < whole.size
    np.testing.assert_array_equal(cut.seq, whole.seq[:cut.size])
    np.testing.assert_array_equal(cut.theta, whole.theta[:cut.size])


@pytest.mark.parametrize("value", [0, -1, float("nan"), "soon", True])
def test_a_bad_time_limit_is_one_line_with_the_way_out(value):
    with pytest.raises(PinfeedError) as err:
        SearchSettings(3.0, time_limit_s=value)
    text = str(err.value)
    assert "\n" not in text and "time_limit_s" in text and "without a time limit" in text


def test_the_config_key_is_checked_and_read_into_the_settings():
    from pipeline.config import load_config, validate_config
    from pipeline.planning.core.settings import PlannerSettings
    config = load_config(None)
    assert config["planner"]["time_limit_s"] is None
    assert PlannerSettings.from_config(config).search.time_limit_s is None
    config["planner"]["time_limit_s"] = 90
    assert PlannerSettings.from_config(validate_config(config)).search.time_limit_s == 90.0
    config["planner"]["time_limit_s"] = -5
    with pytest.raises(PinfeedError, match=r"^config error at planner/time_limit_s: it must be a number of "
                                           r"seconds above 0, got -5; leave it out"):
        validate_config(config)


def test_a_cut_enumeration_with_time_left_screens_what_it_enumerated(monkeypatch):
    """A level whose enumeration the limit cuts (here after the first 4 of its
    11 parents) is screened and judged on the sequences it has: the plan of
    the complete search (first pin P2, among those parents) is found with the
    complete search's verdict, the levels before are complete, and the
    result says the level was only partly enumerated."""
    monkeypatch.setattr(enumerate_module, "FIRST_PARENTS", 4)
    monkeypatch.setattr(enumerate_module, "ENUMERATION_SHARE", 1e-9)  # stop after the first chunk ...
    monkeypatch.setattr(enumerate_module, "finishes_in_time", lambda *args: False)  # ... as if the rest were slow
    result = _search(10.0).run(2, candidates=3, deadline=Deadline(3600.0))
    assert not result.complete and result.complete_to == 1
    cut = result.levels[-1]
    assert cut["pins"] == 2 and 0 < cut["candidates_enumerated"] < cut["candidates"] == 11 * len(PINS)
    assert cut["judged"] > 0 and "only those screened" in cut["unsearched"]
    best = result.plans[0]
    assert [list(best.labels), best.verdict["in_tolerance"], best.verdict["trials"],
            round(best.verdict["width_deg"], 4)] == BEFORE[10.0]["plans"][0]
    assert result.evidence().startswith("2 fixed pins orient this part")


@pytest.mark.parametrize("now, done, search_end, goes_on", [
    (70.0, 60, 104.0, True),   # 70 s for 60 of 80 parents: the other 20 take 23.3 s, ending at 93.3 s,
                               # with 10.7 s (over a tenth of the 104 s) left to screen: it goes on
    (70.0, 60, 100.0, False),  # ending at 93.3 s leaves under a tenth of 100 s: it stops and screens now
    (70.0, 60, 90.0, False),   # it would not end at all before the search does
    (10.0, 1, 50.0, False),    # one parent in 10 s: 79 more do not fit in 40 s
])
def test_a_level_that_ends_in_time_is_never_cut_for_its_share(now, done, search_end, goes_on):
    assert enumerate_module.finishes_in_time(now, 0.0, done, 80, search_end) is goes_on


def test_a_probe_cut_by_its_share_judges_the_sequences_it_probed(monkeypatch):
    """A level whose first screen the limit cuts (here after its first chunk
    of one sequence, the narrowest nominally) goes on with the sequences it
    probed: the plan found there has the complete search's verdict, and the
    level says how far the first screen got and that only those were judged."""
    monkeypatch.setattr(pacing, "PROBE_CHUNK", 1)
    monkeypatch.setattr(pacing, "PROBE_SHARE", 1e-9)  # past its share after the first chunk ...
    monkeypatch.setattr(pacing, "finishes_in_time", lambda *args, **kw: False)  # ... and slow
    result = _search(10.0).run(2, candidates=3, deadline=Deadline(3600.0))
    level = result.levels[-1]
    assert level["pins"] == 2 and level["nominal_within"] == 2 and level["probed"] == 1
    assert "the first screen reached 1 of the 2 sequences" in level["unsearched"]
    assert "only those screened and judged" in level["unsearched"]
    assert not result.complete and result.complete_to == 1
    assert len(result.plans) == 1
    best = result.plans[0]
    got = [list(best.labels), best.verdict["in_tolerance"], best.verdict["trials"], round(best.verdict["width_deg"], 4)]
    assert got in BEFORE[10.0]["plans"]
    # the one probed is the narrowest nominally (the screen's first), not the other
    whole = _search(10.0).run(2, candidates=3).plans
    assert len(whole) == 2 and best.nominal_span == min(p.nominal_span for p in whole)
    assert best.nominal_span < max(p.nominal_span for p in whole)


def test_a_probe_cut_with_no_search_time_left_judges_none(monkeypatch):
    """With the search time over when the probe stops, nothing is judged and
    the level says so."""
    from pipeline.planning.tight import screen as screen_module
    monkeypatch.setattr(pacing, "PROBE_CHUNK", 1)
    probing = {"started": False}
    original = screen_module.LevelScreen._probe

    def probe(self, *args, **kw):
        probing["started"] = True  # the search time ends once the first screen runs
        return original(self, *args, **kw)

    monkeypatch.setattr(screen_module.LevelScreen, "_probe", probe)
    monkeypatch.setattr(Deadline, "search_over", lambda self: probing["started"])
    result = _search(10.0).run(2, candidates=3, deadline=Deadline(3600.0))
    level = result.levels[-1]
    assert level["pins"] == 2 and level["probed"] == 1 and level["judged"] == 0
    assert level["unsearched"].endswith("none judged") and not result.plans


@pytest.mark.parametrize("now, done, search_end, goes_on", [
    (10.0, 10, 40.0, True),    # within its share (0.3) of the 40 s
    (15.0, 95, 40.0, True),    # past its share, but the other 5 end at 15.8 s, leaving over half of the 40 s to judge
    (15.0, 60, 40.0, False),   # the other 40 end at 25 s, leaving under half: it stops and the level judges
                               # what it probed
])
def test_a_probe_that_ends_in_time_with_room_to_judge_is_never_cut(now, done, search_end, goes_on):
    assert pacing.probe_goes_on(now, 0.0, done, 100, search_end) is goes_on


class _OverOnceCertifying(Deadline):
    """A time limit with search time throughout that passes as soon as the
    first held-out replay of the certification starts."""

    def __init__(self):
        super().__init__(3600.0)
        self.passed = False

    def search_over(self) -> bool:
        return False

    def over(self) -> bool:
        return self.passed


def test_the_limit_passing_during_certification_certifies_the_best_first(monkeypatch):
    """The two orienting sequences of the 2-pin level are certified one at a
    time, best first on the selection trials, under a limit: when the limit
    passes after the first, it is the plan (with the complete search's
    verdict) and the other is an unverified candidate, named as such."""
    from pipeline.planning.tight import screen as screen_module
    from pipeline.planning.tight.judge import TrialBench
    deadline, judge = _OverOnceCertifying(), TrialBench.judge

    def certifying(self, heights, speeds, rows, interval=False, stretch=None, **kw):
        if interval:  # the certification's held-out replay
            deadline.passed = True
        return judge(self, heights, speeds, rows, interval, **({"stretch": stretch} if stretch else {}))

    monkeypatch.setattr(TrialBench, "judge", certifying)
    # the screen finds them in the reverse of their rank: the certification must rank them itself
    screen_and_judge = screen_module.LevelScreen._screen_and_judge

    def reversed_found(self, *args, **kwargs):
        found, found_idx, judged = screen_and_judge(self, *args, **kwargs)
        return found[::-1], found_idx[::-1], judged

    monkeypatch.setattr(screen_module.LevelScreen, "_screen_and_judge", reversed_found)
    result = _search(10.0).run(2, candidates=3, deadline=deadline)
    level = result.levels[-1]
    assert level["orienting"] == 2 and level["certified"] == 1 and level["unverified"] == 1
    assert "not replayed on held-out trials (unverified)" in level["unsearched"] and not result.complete
    best = result.plans[0]
    assert len(result.plans) == 1 and [list(best.labels), best.verdict["in_tolerance"], best.verdict["trials"],
                                       round(best.verdict["width_deg"], 4)] == BEFORE[10.0]["plans"][0]
    assert [list(p.labels) for p in result.unverified] == [BEFORE[10.0]["plans"][1][0]]


def test_the_search_time_ending_inside_a_block_leaves_its_other_survivors_unjudged(monkeypatch):
    """Under a limit a block judges no further chunk once the search time is
    over (what is left is the reserve for verifying): with one sequence a
    chunk, the 2-pin level judges its first survivor only, keeps its plan
    with the complete search's verdict, and names the other as not judged."""
    from pipeline.planning.tight import screen as screen_module
    monkeypatch.setattr(screen_module, "MAX_ROWS", 1)  # one sequence per chunk of the judging
    calls = {"judge": 0}
    judge = screen_module.LevelScreen._judge

    def counted(self, *args, **kwargs):
        calls["judge"] += 1
        return judge(self, *args, **kwargs)

    monkeypatch.setattr(screen_module.LevelScreen, "_judge", counted)
    monkeypatch.setattr(Deadline, "search_over", lambda self: calls["judge"] > 0)  # over once one is judged
    result = _search(10.0).run(2, candidates=3, deadline=Deadline(3600.0))
    level = result.levels[-1]
    assert level["pins"] == 2 and level["judged"] == 1 and level["not_judged"] == 1 and _counts_add_up(level)
    assert "2 fixed pin(s): 1 of the 2 sequences that passed the first screen not screened or judged" \
        in level["unsearched"]
    assert not result.complete and calls["judge"] == 1
    assert [[list(p.labels), p.verdict["in_tolerance"], p.verdict["trials"], round(p.verdict["width_deg"], 4)]
            for p in result.plans] in ([plan] for plan in BEFORE[10.0]["plans"])


@pytest.mark.parametrize("step, left, per_sequence, size", [
    (12, float("inf"), 0.5, 12),  # no limit: the whole chunk
    (12, 100.0, 0.5, 12),         # room for all
    (12, 2.0, 0.5, 4),            # room for four
    (12, 0.1, 0.5, 1),            # room for none: one, so a block started judges
    (12, 2.0, 0.0, 12),           # no pace measured: the whole chunk
])
def test_a_chunk_is_cut_to_what_ends_in_the_search_time_left(step, left, per_sequence, size):
    assert pacing.fitting(step, left, per_sequence) == size


def test_with_little_search_time_left_the_judging_goes_one_sequence_at_a_time(monkeypatch):
    """With almost no search time left (but not none), the 2-pin level
    judges its two survivors one chunk of one each, and finds the complete
    search's plans and verdicts."""
    from pipeline.planning.tight import screen as screen_module
    sizes = []
    judge = screen_module.LevelScreen._judge

    def sized(self, chunk, *args, **kwargs):
        sizes.append(len(chunk))
        return judge(self, chunk, *args, **kwargs)

    monkeypatch.setattr(screen_module.LevelScreen, "_judge", sized)
    monkeypatch.setattr(Deadline, "search_left", lambda self: 1e-9)
    result = _search(10.0).run(2, candidates=3, deadline=Deadline(3600.0))
    assert sizes == [1, 1]
    assert _answer(result)["plans"] == BEFORE[10.0]["plans"]


def _counts_add_up(level) -> bool:
    """Every sequence within the tolerance nominally is screened out, judged,
    not screened or not judged (no cascade at these sizes)."""
    return (level["screened_out"] + level["judged"] + level["not_screened"] + level.get("not_judged", 0)
            == level["nominal_within"])


def test_a_block_whose_screen_ends_past_the_search_time_still_judges_one_chunk(monkeypatch):
    """The search time ends while the block screens (after the probe and the
    block's start): the block still judges its first chunk, so a block
    started always judges, and leaves the other survivor unjudged."""
    from pipeline.planning.tight import screen as screen_module
    from pipeline.planning.tight.judge import TrialBench
    monkeypatch.setattr(screen_module, "MAX_ROWS", 1)  # one sequence per chunk of the judging
    calls = {"failures": 0}
    failures = TrialBench.failures

    def counted(self, *args, **kwargs):
        calls["failures"] += 1  # the probe's, then the block's screen
        return failures(self, *args, **kwargs)

    monkeypatch.setattr(TrialBench, "failures", counted)
    monkeypatch.setattr(Deadline, "search_over", lambda self: calls["failures"] >= 2)
    result = _search(10.0).run(2, candidates=3, deadline=Deadline(3600.0))
    level = result.levels[-1]
    assert level["pins"] == 2 and level["judged"] == 1 and level["not_judged"] == 1 and _counts_add_up(level)
    assert len(result.plans) == 1


@pytest.mark.parametrize("judge_pace, pace", [
    (None, 1.5),  # before a full judgement: the screen's 0.01 s a replay x 50 trials x SCREEN_TO_JUDGE (3)
    (0.2, 1.5),   # a measured 0.6 s a sequence of 3 pins is faster than that: the slower one counts
    (1.0, 3.0),   # 1 s a pin: 3 s a sequence of 3 pins
])
def test_the_judging_pace_is_the_slower_of_the_measured_and_the_screen_estimate(judge_pace, pace):
    assert pacing.judging_pace(judge_pace, 3, 1.0, 100, 50) == pytest.approx(pace)


def test_the_evidence_stops_between_its_judgements_once_the_search_time_is_over(monkeypatch):
    """When nothing orients, the fewest-set sequences are judged one at a
    time: with the search time ending after the first judgement, the 1-pin
    level's other two are named as not judged, the deeper levels' evidence
    as not judged at all, and the one judged keeps the complete search's
    numbers."""
    from pipeline.planning.tight import screen as screen_module
    from pipeline.planning.tight.judge import TrialBench
    calls = {"evidence": False, "judge": 0}
    judge, several_sets = TrialBench.judge, screen_module.LevelScreen.several_sets

    def counted(self, *args, **kwargs):
        calls["judge"] += calls["evidence"]  # the evidence's judgements only
        return judge(self, *args, **kwargs)

    def evidence(self, *args, **kwargs):
        calls["evidence"] = True
        return several_sets(self, *args, **kwargs)

    monkeypatch.setattr(TrialBench, "judge", counted)
    monkeypatch.setattr(screen_module.LevelScreen, "several_sets", evidence)
    monkeypatch.setattr(Deadline, "search_over", lambda self: calls["judge"] >= 1)
    result = _search(1.0).run(3, candidates=3, deadline=Deadline(3600.0))
    assert calls["judge"] == 1 and not result.plans and not result.complete
    assert "the fewest-set sequences of 1 fixed pin(s): 2 not judged (the time limit ended their judging)" \
        in result.unsearched
    assert "the fewest-set sequences of 2 level(s) (the evidence when nothing orients): not judged" \
        in result.unsearched
    one_pin = [[list(p.labels), p.verdict["in_tolerance"], p.verdict["trials"]] for p in result.best_effort
               if len(p.labels) == 1]
    assert len(one_pin) == 1 and one_pin[0] in BEFORE[1.0]["best"]
