"""The nearest "yes" for one part that no plan orients (uniform pressure).

The tolerance answer against brute force (the smallest half-degree step
whose best arc, counted angle by angle, holds the claim's count); and on the
70 x 25 mm trapezoid at a 6 deg tolerance with two pins (no plan), the
answer's plan replayed through the public rollout API on the oracle's own
trials (tests/oracle.py) ends in one set of the answered tolerance (+1 deg:
the two sample the box differently).
"""
import dataclasses
import math
from types import SimpleNamespace

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from oracle import box_trials, most_in_arc, replay_box

from pipeline.config import load_config
from pipeline.parts.part import Part
from pipeline.planning import PlannerSettings, nearest_yes_lines
from pipeline.planning.claims import orient
from pipeline.planning.plans.nearest_part import (LADDER, MAX_TOLERANCE, loosest_needed, part_moving_axis,
                                                 part_nearest_yes, part_tolerance_axis)
from pipeline.planning.core.plan_records import Plan
from pipeline.planning.core.types import TightEntry
from pipeline.planning.plans.plan import plan_tight
from pipeline.progress import Deadline

TRAPEZOID = Part.from_vertices([[0.0, 0.0], [70.0, 0.0], [50.0, 25.0], [10.0, 25.0]], "trapezoid")


@settings(max_examples=40, deadline=None)
@given(st.lists(st.floats(0.0, 360.0), min_size=20, max_size=80), st.integers(0, 6),
       st.sampled_from([1, 2]))
def test_the_tolerance_is_the_smallest_step_whose_arc_holds_the_count(thetas, n_jammed, order):
    finals = np.array(thetas + [0.0] * n_jammed)
    jammed = np.array([False] * len(thetas) + [True] * n_jammed)
    n = finals.size
    allowed = orient.max_failures(n, 0.9, rule="point")
    answer = loosest_needed(finals, jammed, n, order, 0.9, 0.95, "point")
    ladder = np.arange(LADDER, MAX_TOLERANCE + LADDER / 2, LADDER)
    brute = next((float(t) for t in ladder if most_in_arc(finals[~jammed], t, order) >= n - allowed), None)
    assert answer == brute


@pytest.fixture(scope="module")
def no_plan_entry(tmp_path_factory):
    config = load_config()
    config["catalog_dir"] = str(tmp_path_factory.mktemp("catalog"))
    config["planner"].update(pins="auto", depth=2, tolerance_deg=6.0, mu_c=0.2, frictions=[])
    config["planner"]["dynamic"].update(depth=0, speeds=[])
    config["verify"].update(trials=30, rule="point")  # few trials: the point rule
    settings_ = PlannerSettings.from_config(config)
    return plan_tight(TRAPEZOID, settings_.at(0.2)), settings_


@pytest.fixture(scope="module")
def no_plan(no_plan_entry):
    """The entry as its plan file has it, and the settings."""
    entry, settings_ = no_plan_entry
    return entry.to_dict(), settings_


def _search_record(time_limit=None, complete=True, complete_to=0, orients=False, unsearched=(), found=()):
    """A stand-in for a search's record (``tight.records.FixedSearch``): what the nearest "yes" reads."""
    return SimpleNamespace(time_limit=time_limit, complete=complete, complete_to=complete_to, orients=orients,
                           unsearched=list(unsearched), plans=[SimpleNamespace(labels=tuple(f)) for f in found])


def _entry(recommended=None, rejected=()):
    """A tight entry with only the plans the moving-pin axis reads."""
    rec = Plan.from_dict(recommended) if recommended else None
    return TightEntry(0.2, "0.2", (), recommended=rec, rejected=tuple(Plan.from_dict(r) for r in rejected))


def test_a_part_without_a_plan_gets_its_nearest_yes(no_plan):
    result, _ = no_plan
    assert not result["orients"]
    axes = {a["axis"]: a for a in result["nearest_yes"]["axes"]}
    assert set(axes) == {"tolerance", "moving pins", "sensor", "more pins"}
    tol = axes["tolerance"]
    assert tol["found"] and 6.0 < tol["value"] <= MAX_TOLERANCE
    assert tol["verdict"]["orients"] and tol["verdict"]["tolerance_deg"] == tol["value"]
    assert tol["verdict"]["trials"] >= 180  # the held-out trials (fresh seed), not the 30 per state
    assert not axes["moving pins"]["found"] and "not searched" in axes["moving pins"]["statement"]
    assert not axes["more pins"]["found"] and "--depth 3" in axes["more pins"]["statement"]
    assert result["nearest_yes"]["subject"] == "part"  # the answer says what it is about
    lines = nearest_yes_lines(result["nearest_yes"])
    assert lines[0].startswith("the nearest \"yes\"") and any(f"{tol['value']:g} deg" in x for x in lines)


def test_the_answer_is_its_plans_own_tolerance(no_plan):
    """The searched answer is the narrowest tolerance its plan's held-out
    trials allow: replayed afresh as a kept plan, it answers the same."""
    result, settings_ = no_plan
    tol = next(a for a in result["nearest_yes"]["axes"] if a["axis"] == "tolerance")
    fresh = part_tolerance_axis(TRAPEZOID, settings_.at(0.2), [(tol["plan"], tol["pin_heights_mm"], ())])
    searched = {k: v for k, v in tol["verdict"].items() if k != "width_interval_deg"}  # kept plans give none
    assert fresh["value"] == tol["value"] and fresh["verdict"] == searched


class _Bench:
    """A trial bench whose held-out replay gives the finals ``finals`` (none jammed)."""
    order = 1

    def __init__(self, finals):
        self.finals = np.asarray(finals, float)

    def held_out(self, n_pins):
        return (self.finals,)

    def replay(self, heights, speeds, rows):
        return self.finals[None, :], np.zeros((1, self.finals.size), bool)


@pytest.mark.parametrize("spread, expected", [(0.2, 6.5), (20.0, 20.0)])
def test_a_found_plan_answers_at_its_own_tolerance_above_the_asked_one(spread, expected):
    """A plan a search certified at 45 deg answers at the narrowest tolerance
    its held-out trials allow, never at or below the asked one (here 6 deg:
    held-out trials easier than those that rejected it give the next step)."""
    from pipeline.planning.plans.nearest_part import _own_tolerance
    finals = np.linspace(100.0, 100.0 + spread, 200)
    claims = SimpleNamespace(required=0.99, confidence=0.95, rule="point")
    plan = SimpleNamespace(heights=(5.0, 9.0), speeds=(), verdict={"tolerance_deg": 45.0})
    plan = dataclasses.make_dataclass("P", ["heights", "speeds", "verdict"])(**vars(plan))
    tol, answered = _own_tolerance(plan, _Bench(finals), claims, 6.0)
    assert tol == expected and answered.verdict["tolerance_deg"] == expected and answered.verdict["orients"]
    assert most_in_arc(finals, tol, 1) >= 0.99 * finals.size


def test_half_a_degree_tighter_the_complete_search_finds_no_plan(no_plan):
    import dataclasses
    from pipeline.planning.tight.complete import FixedPinSearch
    result, settings_ = no_plan
    tol = next(a for a in result["nearest_yes"]["axes"] if a["axis"] == "tolerance")
    s = settings_.at(0.2)
    claims = dataclasses.replace(s.claims, tolerance_deg=tol["value"] - 0.5)
    pins = {k: v for k, v in result["pins_used"].items()}
    assert not FixedPinSearch(TRAPEZOID, pins, s.friction, claims, s.verify, s.search).run(2, keep=1).plans


def test_the_first_step_below_the_plan_found_answers_as_the_plain_bisection(no_plan, monkeypatch):
    """Searching half a step below the widest search's plan first, then
    bisecting, gives the plain bisection's answer (the same tolerance and
    plan) and the planner's."""
    from pipeline.planning.plans import nearest_part
    result, settings_ = no_plan
    pins = dict(result["pins_used"])
    tried = []
    at = nearest_part._at

    def noted(progress, tolerance):
        tried.append(tolerance)
        return at(progress, tolerance)

    monkeypatch.setattr(nearest_part, "_at", noted)
    stepped = nearest_part.searched_tolerance(TRAPEZOID, settings_.at(0.2), pins, 2, 12)
    first_tries = list(tried)
    tried.clear()
    monkeypatch.setattr(nearest_part, "_next_tolerance",
                        lambda lo, hi, tries: math.floor((lo + hi) / 2 / LADDER) * LADDER)
    plain = nearest_part.searched_tolerance(TRAPEZOID, settings_.at(0.2), pins, 2, 12)
    assert stepped[0] == plain[0] and stepped[1].labels == plain[1].labels and stepped[2] and plain[2]
    assert first_tries[0] == MAX_TOLERANCE and 1 < len(first_tries) < len(tried)  # fewer searches
    assert first_tries[1] == stepped[0] - LADDER  # half a step below the answer: its "no" settles it
    tol_first = next(a for a in result["nearest_yes"]["axes"] if a["axis"] == "tolerance")
    assert stepped[0] == tol_first["value"]


def test_the_answer_holds_in_an_independent_replay(no_plan):
    result, _ = no_plan
    tol = next(a for a in result["nearest_yes"]["axes"] if a["axis"] == "tolerance")
    heights = tol["pin_heights_mm"]
    finals = replay_box(TRAPEZOID, heights, box_trials(TRAPEZOID, len(heights), 60, 29, (0.18, 0.22)),
                        strict=False)
    order = TRAPEZOID.symmetry_order()
    assert most_in_arc(finals, tol["value"] + 1.0, order) >= 0.95 * finals.size
    # and the asked tolerance is not enough for it (the reason there was no plan)
    assert most_in_arc(finals, 6.0, order) < 0.95 * finals.size


class _SearchCut(Deadline):
    """A time limit whose search time ends after ``reads`` reads of it, with
    time left for verification ever after (a search cut part way)."""

    def __init__(self, reads: int):
        super().__init__(600.0)
        self.reads = reads

    def search_over(self) -> bool:
        self.reads -= 1
        return self.reads < 0

    def over(self) -> bool:
        return False


def test_a_search_cut_by_its_time_limit_still_answers_from_the_kept_plans(no_plan):
    """A cut search (here its evidence: both levels were searched in full)
    gets the kept plans' tolerance answer, marked as kept plans only, with no
    search at looser tolerances, the cut named in ``unsearched`` and only the
    plans replayed listed."""
    full, settings_ = no_plan
    cut = plan_tight(TRAPEZOID, settings_.at(0.2), deadline=_SearchCut(reads=3)).to_dict()
    assert cut["complete"] is False and not cut["orients"]
    assert cut["fixed_pin_search"]["complete"] is False
    assert any("kept plans only" in u for u in cut["unsearched"])
    nearest = cut["nearest_yes"]
    axis = next(a for a in nearest["axes"] if a["axis"] == "tolerance")
    assert axis["kept_plans_only"] is True and axis["replayed"] == len(nearest["plans_tried"]) > 0
    kept = [p["pins"] for p in cut["plans"] + cut["rejected"]]
    assert all(p in kept for p in nearest["plans_tried"])
    more = next(a for a in nearest["axes"] if a["axis"] == "more pins")
    searched = cut["fixed_pin_search"]
    assert searched["complete_to_pins"] == 2 and any("fewest-set" in u for u in searched["unsearched"])
    assert "--depth 3" in more["statement"]  # both levels searched in full: only the evidence was cut
    # the plans kept here end far apart: none orients within the widest tolerance (checked by the
    # oracle's replays), so there is no answer, and the statement says the search was not run
    heights = {tuple(p["pins"]): p["pin_heights_mm"] for p in cut["plans"] + cut["rejected"]}
    for pins in nearest["plans_tried"]:
        h = heights[tuple(pins)]
        finals = replay_box(TRAPEZOID, h, box_trials(TRAPEZOID, len(h), 60, 29, (0.18, 0.22)), strict=False)
        assert most_in_arc(finals, MAX_TOLERANCE - 1.0, TRAPEZOID.symmetry_order()) < 0.99 * finals.size
    assert not axis["found"] and "was not run" in axis["statement"]


class _NoTimeLeft(_SearchCut):
    """:class:`_SearchCut` whose time runs out (``over``) once ``expired`` is set."""
    expired = False

    def over(self) -> bool:
        return self.expired


def test_with_no_time_left_the_nearest_yes_still_gives_the_axes_that_need_no_rollout(no_plan, monkeypatch):
    """The limit has passed when the nearest "yes" begins: its sensor and
    moving-pin axes (read from the search, no rollout) answer as with time
    left, the tolerance axis replays nothing and says so, and ``unsearched``
    names what was left out."""
    from pipeline.planning.plans import plan as plan_module
    _, settings_ = no_plan
    with_time = plan_tight(TRAPEZOID, settings_.at(0.2), deadline=_SearchCut(reads=3)).to_dict()
    deadline, original = _NoTimeLeft(reads=3), plan_module._with_certificate_or_nearest_yes

    def expire(*args, **kwargs):
        deadline.expired = True
        return original(*args, **kwargs)

    monkeypatch.setattr(plan_module, "_with_certificate_or_nearest_yes", expire)
    cut = plan_tight(TRAPEZOID, settings_.at(0.2), deadline=deadline).to_dict()
    assert deadline.expired and [p["pins"] for p in cut["plans"]] == [p["pins"] for p in with_time["plans"]]
    axes = {a["axis"]: a for a in cut["nearest_yes"]["axes"]}
    before = {a["axis"]: a for a in with_time["nearest_yes"]["axes"]}
    assert axes["sensor"] == before["sensor"] and axes["moving pins"] == before["moving pins"]
    assert axes["tolerance"]["replayed"] == 0 and "no time was left" in axes["tolerance"]["statement"]
    assert cut["nearest_yes"]["plans_tried"] == []
    assert any(u.startswith('the nearest "yes": only the axes that need no rollout') for u in cut["unsearched"])


def _carried_as_the_limit_passes(settings_, monkeypatch) -> tuple:
    """The trapezoid planned with time left (``with_time``) and with the limit
    passing as the carried sets of the chosen plans begin (``cut``)."""
    from pipeline.planning.plans import plan as plan_module
    with_time = plan_tight(TRAPEZOID, settings_.at(0.2), deadline=_SearchCut(reads=10 ** 6)).to_dict()
    deadline, original = _NoTimeLeft(reads=10 ** 6), plan_module.carried_sets

    def expire(*args, **kwargs):
        deadline.expired = True
        return original(*args, **kwargs)

    monkeypatch.setattr(plan_module, "carried_sets", expire)
    cut = plan_tight(TRAPEZOID, settings_.at(0.2), deadline=deadline).to_dict()
    assert deadline.expired
    skipped = [u for u in cut["unsearched"] if u.startswith("carried sets and held-out verification")]
    return with_time, cut, skipped


def test_a_limit_passing_as_certified_plans_are_carried_keeps_the_first(monkeypatch):
    """At 40 deg the search certifies plans for the trapezoid. When the limit
    passes as their carried sets begin, the first (the search's best) is
    still carried and verified, with the numbers it has with time left, and
    the others are named as skipped (dropping them all would leave no plan
    where the search certified one)."""
    config = load_config()
    config["planner"].update(pins="auto", depth=2, tolerance_deg=40.0, mu_c=0.2, frictions=[])
    config["planner"]["dynamic"].update(depth=0, speeds=[])
    config["verify"].update(trials=30, rule="point")
    with_time, cut, skipped = _carried_as_the_limit_passes(PlannerSettings.from_config(config), monkeypatch)
    kept = cut["plans"] + cut["rejected"]
    before = {tuple(p["pins"]): p for p in with_time["plans"] + with_time["rejected"]}
    assert with_time["orients"] and cut["orients"] and len(kept) == 1 and len(before) > 1
    plan = kept[0]
    same = before[tuple(plan["pins"])]["verification"]
    assert plan["verification"] == {k: v for k, v in same.items() if k != "untruncated"}  # skipped: no time
    assert len(skipped) == 1 and skipped[0].startswith(f"carried sets and held-out verification of "
                                                       f"{len(before) - 1} chosen plan(s): skipped")
    assert " ".join(plan["pins"]) not in skipped[0].split(": skipped")[1]


def test_a_limit_passing_as_best_efforts_are_carried_keeps_the_first(no_plan, monkeypatch):
    """Where nothing orients, the chosen plans are the search's best efforts:
    past the limit the first is still carried and verified on its held-out
    trials, with the numbers it has with time left (an answer, not "no
    plan"), and the others are named as skipped."""
    _, settings_ = no_plan
    with_time, cut, skipped = _carried_as_the_limit_passes(settings_, monkeypatch)
    kept = cut["plans"] + cut["rejected"]
    before = {tuple(p["pins"]): p for p in with_time["plans"] + with_time["rejected"]}
    assert not with_time["orients"] and len(kept) == 1 and len(before) > 1
    plan = kept[0]
    same = before[tuple(plan["pins"])]["verification"]
    assert plan["verification"] == {k: v for k, v in same.items() if k != "untruncated"}
    assert len(skipped) == 1 and skipped[0].startswith(f"carried sets and held-out verification of "
                                                       f"{len(before) - 1} chosen plan(s): skipped")


def test_moving_pins_the_limit_came_before_are_named_so(no_plan):
    """With moving pins configured, a limit that ends the search before them
    says so on the moving-pin axis (never "no pin speeds given")."""
    _, settings_ = no_plan
    s = dataclasses.replace(settings_.at(0.2), search=dataclasses.replace(
        settings_.at(0.2).search, dynamic_speeds=(-1.0, 1.0), dynamic_depth=1))
    cut = plan_tight(TRAPEZOID, s, deadline=_SearchCut(reads=3)).to_dict()
    assert any(u.startswith("moving pins: not reached") for u in cut["unsearched"])
    axis = next(a for a in cut["nearest_yes"]["axes"] if a["axis"] == "moving pins")
    assert not axis["found"] and "time limit ended the search before the moving pins" in axis["statement"]


def test_the_kept_plans_answer_needs_no_search(no_plan_entry):
    """Kept plans only: none of the search's kept plans answers here (the
    complete answer came from the searches at looser tolerances), and it says
    so; given the complete answer's plan as a kept plan, it answers with that
    plan at no looser a tolerance (the same held-out trials)."""
    entry, settings_ = no_plan_entry
    full = entry.to_dict()
    kept = [(p["pins"], p["pin_heights_mm"], p.get("pin_speeds") or ()) for p in full["plans"]]
    complete = next(a for a in full["nearest_yes"]["axes"] if a["axis"] == "tolerance")
    assert complete["kept_plans_only"] is False and complete["plan"] not in [k[0] for k in kept]

    def tolerance(plans):
        return next(a for a in part_nearest_yes(TRAPEZOID, settings_.at(0.2), entry, _search_record(), None,
                                                plans)["axes"] if a["axis"] == "tolerance")

    none = tolerance(kept)
    assert not none["found"] and none["kept_plans_only"] and "was not run" in none["statement"]
    given = tolerance(kept + [(complete["plan"], complete["pin_heights_mm"], ())])
    assert given["found"] and given["kept_plans_only"] and given["plan"] == complete["plan"]
    assert 6.0 < given["value"] <= complete["value"] and given["verdict"]["orients"]


def test_moving_pins_cut_by_the_limit_are_not_called_unconfigured():
    axis = part_moving_axis(_entry(), None, cut=True)
    assert not axis["found"] and "time limit" in axis["statement"]
    assert "no pin speeds given" in part_moving_axis(_entry(), None)["statement"]
    stage = _search_record(time_limit=5.0, complete=False, unsearched=["2 moving pin(s) after P1: not reached"])
    part_way = part_moving_axis(_entry(), stage)
    assert not part_way["found"] and part_way["statement"].startswith("searched in part")
    assert "2 moving pin(s) after P1: not reached" in part_way["statement"]
    assert part_moving_axis(_entry(), _search_record())["statement"].startswith("searched after the fixed pins")


def test_searches_that_reuse_rollouts_find_what_they_find_alone(no_plan):
    """The bisection's searches share one search's nominal outcomes and trial
    states: a search at another tolerance that reuses them finds the same
    plans, verdicts, evidence and level counts as alone; as the bisection runs
    them (no evidence), with fewer nominal rollouts."""
    from pipeline.planning.tight.complete import FixedPinSearch
    full, settings_ = no_plan
    s = settings_.at(0.2)
    pins = dict(full["pins_used"])

    def search(tolerance, reuse=None, evidence=True):
        claims = dataclasses.replace(s.claims, tolerance_deg=tolerance)
        out = FixedPinSearch(TRAPEZOID, pins, s.friction, claims, s.verify, s.search)
        if reuse is not None:
            out.reuse_rollouts(reuse)
        out.evidence = evidence
        return out

    first = search(MAX_TOLERANCE)
    first.run(2, keep=1)
    alone, reusing = search(20.0).run(2, keep=3), search(20.0, reuse=first).run(2, keep=3)
    assert [(p.labels, p.verdict) for p in alone.plans] == [(p.labels, p.verdict) for p in reusing.plans]
    assert [(p.labels, p.verdict) for p in alone.best_effort] == [(p.labels, p.verdict) for p in reusing.best_effort]
    # the deepest level's count of sequences depends on the order of the states, which follows
    # what the shared tree rolled out before; every other count is the search's own
    def counts(levels):
        return [{k: v for k, v in lv.items() if not (lv is levels[-1] and k in ("sequences", "spread_out"))}
                for lv in levels]
    assert counts(alone.levels) == counts(reusing.levels)
    # (with the evidence the deepest level's stopped sequences may be rolled out in another
    # order, so only the bisection's own searches are compared for their rollouts)
    alone, reusing = search(20.0, evidence=False).run(2, keep=1), search(20.0, first, False).run(2, keep=1)
    assert [p.labels for p in alone.plans] == [p.labels for p in reusing.plans]
    assert reusing.rollouts < alone.rollouts


def test_a_bisection_the_limit_cuts_keeps_its_certified_bound(no_plan, monkeypatch):
    """When the limit cuts the bisection after its first search (at the widest
    tolerance) found a plan, the answer is that plan's own tolerance (the
    narrowest its held-out trials allow: the same as replaying it afresh as a
    kept plan), said to be an upper bound, not nothing."""
    from pipeline.planning.tight import complete
    full, settings_ = no_plan
    real_run, calls = complete.FixedPinSearch.run, []

    def run(self, *args, **kwargs):
        result = real_run(self, *args, **kwargs)
        calls.append(self.bench.tolerance)
        if len(calls) > 1:  # every search after the first is cut
            result.unsearched.append("cut by the test's time limit")
        return result

    monkeypatch.setattr(complete.FixedPinSearch, "run", run)
    axis = part_tolerance_axis(TRAPEZOID, settings_.at(0.2), [], dict(full["pins_used"]), 2)
    assert calls[0] == MAX_TOLERANCE and len(calls) == 2
    monkeypatch.setattr(complete.FixedPinSearch, "run", real_run)
    fresh = part_tolerance_axis(TRAPEZOID, settings_.at(0.2), [(axis["plan"], axis["pin_heights_mm"], ())])
    assert fresh["found"] and fresh["kept_plans_only"]
    assert axis["found"] and axis["value"] == fresh["value"] < MAX_TOLERANCE and axis["searches_cut"]
    assert {k: v for k, v in axis["verdict"].items() if k != "width_interval_deg"} == fresh["verdict"]
    assert not axis["kept_plans_only"] and f"at most {axis['value']:g} deg" in axis["statement"]
    assert "upper bound" in axis["statement"] and axis["verdict"]["orients"]


def test_more_pins_asks_for_a_longer_limit_only_when_the_depth_was_not_searched(no_plan_entry):
    entry, settings_ = no_plan_entry
    kept = [(p.pins, p.pin_heights_mm, ()) for p in entry.plans][:1]

    def more(complete_to):
        cut = _search_record(time_limit=5.0, complete=False, complete_to=complete_to)
        return next(a for a in part_nearest_yes(TRAPEZOID, settings_.at(0.2), entry, cut, None, kept)["axes"]
                    if a["axis"] == "more pins")["statement"]

    assert "--time-limit" in more(1)
    assert "--depth 3" in more(2)  # depth 2 searched in full: only the evidence was cut


def test_a_moving_plan_found_but_not_recommended_is_never_called_none():
    stage = _search_record(time_limit=5.0, complete=False, orients=True, found=[["P1", "P2v+1"]])
    fixed_rec = {"pins": ["P1"], "pin_speeds": [0.0], "final_sets": []}
    unverified = part_moving_axis(_entry(recommended=fixed_rec), stage)
    assert not unverified["found"] and unverified["partial"] and "not verified" in unverified["statement"]
    failed = part_moving_axis(_entry(rejected=[{"pins": ["P1", "P2v+1"], "final_sets": []}]), stage)
    assert not failed["found"] and "fails the final verification" in failed["statement"]
