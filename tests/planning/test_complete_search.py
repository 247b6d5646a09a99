"""The complete fixed-pin search (issue 23) against a brute-force oracle that
shares none of its arithmetic (tests/oracle.py: its own trials, replay and
judgement), on hypothesis-drawn triangles and quadrilaterals and on fixed
parts beyond the default triangles; the orientation verdict against brute
force; the evidence when no fixed-pin plan exists."""
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from oracle import box_trials, most_in_arc, orienting_sequences, replay_box
from strategies import convex_polygons, triangles

from pipeline.parts.part import Part
from pipeline.planning.claims import orient
from pipeline.planning.core.settings import ClaimSettings, PlannerSettings, SearchSettings, VerifySettings
from pipeline.planning.tight.complete import FixedPinSearch

MU = (0.1, 0.2)
VERIFY = VerifySettings(trials=20, seed=3)  # few trials: the point rule
RADIUS = 3.0


def _search(part, pins, tolerance, depth):
    search = FixedPinSearch(part, pins, MU, ClaimSettings(tolerance, 0.995, rule="point"), VERIFY,
                            SearchSettings(RADIUS))
    return search.run(depth, candidates=4, keep=5)


def _grid(part, n):
    """``n`` pins evenly across the resting states' heights (labels Q1..Qn)."""
    top = max(y for _, y in part.stable_states()) * 1.8
    return {f"Q{k}": float(y) for k, y in enumerate(np.linspace(-0.1 * part.a, top, n), start=1)}


def _check(part, pins, tolerance, depth):
    """Completeness: whenever the oracle finds a sequence whose every trial ends
    within half the tolerance, the planner returns a plan with no more pins.
    Soundness: every returned plan keeps 95 % of the oracle's own trials within
    the tolerance (+1 deg: the two sample the box differently)."""
    order = part.symmetry_order()
    oracle = orienting_sequences(part, pins, depth, tolerance / 2,
                                 lambda n: box_trials(part, n, 12, 7, MU), order)
    result = _search(part, pins, tolerance, depth)
    if oracle:
        assert result.plans, f"oracle found {oracle[0]}, the planner none: {result.evidence()}"
        assert len(result.plans[0].labels) <= min(len(s) for s in oracle)
    for plan in result.plans:
        finals = replay_box(part, plan.heights, box_trials(part, len(plan.heights), 40, 11, MU),
                            strict=False)
        assert most_in_arc(finals, tolerance + 1.0, order) >= 0.95 * finals.size, plan.labels
    return oracle, result


@settings(max_examples=3, deadline=None)
@given(triangles(), st.floats(30.0, 60.0))
def test_complete_and_sound_on_random_triangles(tri, size):
    part = Part.from_vertices(tri * size)
    _check(part, _grid(part, 5), 12.0, 2)


@settings(max_examples=2, deadline=None)
@given(convex_polygons(min_n=4, max_n=4), st.floats(30.0, 60.0))
def test_complete_and_sound_on_random_quadrilaterals(quad, size):
    part = Part.from_vertices(quad * size)
    _check(part, _grid(part, 5), 12.0, 2)


@pytest.mark.parametrize("vertices, pins, tolerance", [
    ([[0, 0], [50, 0], [0, 30]], {"A": -7.5, "B": 7.5, "C": 15.0, "D": 27.5}, 12.0),  # right triangle
    ([[0, 0], [60, 0], [15, 35]], {"A": -10.0, "B": 10.0, "C": 27.5}, 16.0),  # the default asym triangle
])
def test_three_pin_plans_found_where_the_oracle_finds_them(vertices, pins, tolerance):
    """The oracle finds 3-pin sequences whose every trial ends within half the
    tolerance on these grids (checked here, so the completeness check is not
    vacuous); the planner's plan has at most 3 pins and is sound."""
    part = Part.from_vertices(vertices)
    oracle, result = _check(part, pins, tolerance, 3)
    assert oracle and min(len(s) for s in oracle) == 3
    assert len(result.plans[0].labels) <= 3


def test_no_fixed_plan_evidence_on_a_part_the_oracle_cannot_orient():
    """Two pins far above a flat bar touch nothing useful: the oracle finds no
    sequence, the planner returns none and says so with its evidence."""
    part = Part.from_vertices([[0, 0], [60, 0], [60, 12], [0, 12]])
    pins = {"A": 3.0, "B": 9.0}
    order = part.symmetry_order()
    assert not orienting_sequences(part, pins, 2, 10.0, lambda n: box_trials(part, n, 8, 5, MU), order)
    result = _search(part, pins, 10.0, 2)
    assert not result.plans
    assert result.evidence().startswith("no fixed-pin sequence of up to 2 pins orients this part within 10 deg")
    assert [lv["pins"] for lv in result.levels] == [1, 2]
    assert sum(lv["sequences"] for lv in result.levels) > 0


@given(st.lists(st.floats(0.0, 359.99), min_size=1, max_size=40), st.floats(0.5, 90.0),
       st.sampled_from([1, 2, 3]))
def test_best_arc_matches_brute_force(thetas, width, order):
    count, _ = orient.best_arc(thetas, width, order)
    assert count == most_in_arc(thetas, width, order)


@given(st.lists(st.floats(0.0, 359.99), min_size=2, max_size=30), st.integers(1, 30))
def test_narrowest_arc_holds_k_and_none_narrower(thetas, k):
    arc = orient.narrowest_arc(thetas, k)
    if k > len(thetas):
        assert arc is None
        return
    start, width = arc
    assert most_in_arc(thetas, width) >= k
    assert most_in_arc(thetas, max(0.0, width - 1e-6)) < k or width < 1e-6


def test_judge_counts_jams_as_failures():
    finals = [10.0] * 990  # 1000 trials, 10 jammed: 99.0 % < 99.5 %
    verdict = orient.judge(finals, 1000, 5.0)
    assert not verdict["orients"] and verdict["in_tolerance"] == 990 and verdict["width_deg"] is None
    assert orient.judge(finals + [12.0] * 5, 995, 5.0)["orients"]


def test_judge_works_modulo_symmetry():
    """Two sets 180 deg apart are one orientation of a 2-fold symmetric part."""
    finals = [10.0] * 50 + [190.5] * 50
    assert not orient.judge(finals, 100, 5.0, order=1)["orients"]
    verdict = orient.judge(finals, 100, 5.0, order=2, rule="point")  # 100 trials: the point rule
    assert verdict["orients"] and verdict["width_deg"] == pytest.approx(0.5)


@pytest.mark.parametrize("bad", [0, -3, 360, 400, float("nan"), "ten"])
def test_bad_tolerance_is_one_line(bad):
    with pytest.raises(Exception) as exc:
        orient.check_tolerance(bad)
    assert "\n" not in str(exc.value) and "tolerance" in str(exc.value)


def test_sampled_claim_splits_outliers_and_holds_in_an_independent_replay():
    """A sequence the propagation cannot follow gets sampled carried sets: one
    branch per cluster of final orientations (outliers are their own branch,
    not a 160-degree hull), and the verification's own trials (another seed)
    end in the claimed sets."""
    from pipeline.config import load_config
    from pipeline.planning.tight.certify import CLUSTER_GAP_DEG, sampled_plan
    from pipeline.planning.plans.planner import planner_for
    from pipeline.planning.claims.verify import verify_plan
    part = Part.from_vertices([[0, 0], [60, 0], [15, 35]])
    config = load_config()
    planner = planner_for(part, PlannerSettings.from_config(config).at(0.3))
    labels = [k for k, p in planner.pins.items() if p.y in (10.0, 27.5, 47.5)]
    labels = sorted(labels, key=lambda k: [10.0, 27.5, 47.5].index(planner.pins[k].y))
    plan = sampled_plan(planner, labels, 0.0, VerifySettings(trials=100))
    assert plan.carried == "sampled"
    for label, branches in plan.branches.items():
        finals = sorted(br[-1].band.start for br in branches)
        assert all(br[-1].band.width < 20.0 for br in branches), (label, finals)
        assert len(branches) == 1 or min(np.diff(finals)) > CLUSTER_GAP_DEG - 1.0
    states = {k: (float(t), float(y)) for k, (t, y) in zip(planner.initial_states(), part.stable_states())}
    res = verify_plan(part, plan.to_dict(), {k: p.y for k, p in planner.pins.items()}, states, 0.3, 3.0,
                      settings=VerifySettings(trials=100))
    assert res["successes"] >= 0.98 * res["trials"]


def test_moving_pins_only_when_fixed_pins_cannot_and_their_plan_holds():
    """A trapezoid that one fixed pin cannot orient: the plan entry says so,
    moving pins after it (same enumeration) do orient it, and the recommended
    moving-pin plan holds in the oracle's own replay with the pins moving."""
    from pipeline.config import load_config
    from pipeline.planning.plans.plan import plan_tight
    config = load_config()
    config["planner"].update(pins="auto", depth=1, tolerance_deg=10.0)
    config["verify"].update(trials=30, rule="point")  # few trials: the point rule
    part = Part.from_vertices([[0, 0], [70, 0], [50, 25], [10, 25]], name="trapezoid")
    entry = plan_tight(part, PlannerSettings.from_config(config).at((0.1, 0.3))).to_dict()
    assert not entry["fixed_pin_search"]["orients"]
    assert entry["fixed_pin_search"]["evidence"].startswith("no fixed-pin sequence of up to 1 pins")
    assert entry["moving_pin_search"]["orients"] and entry["orients"]
    rec = entry["recommended"]
    assert rec["n_dynamic_pins"] >= 1 and rec["verification"]["orientation"]["orients"]
    finals = replay_box(part, rec["pin_heights_mm"], box_trials(part, len(rec["pins"]), 40, 13, (0.1, 0.3)),
                        strict=False, speeds=rec["pin_speeds"])
    assert most_in_arc(finals, 11.0) >= 0.95 * finals.size


def test_no_plan_recommends_fixed_pins_for_a_sensor():
    """When neither fixed nor moving pins orient the part, the recommended plan
    is a several-set plan of fixed pins and the warning names the sensor."""
    from pipeline.config import load_config
    from pipeline.planning.plans.plan import plan_tight
    config = load_config()
    config["planner"].update(pins=[0.0, 5.0, 10.0, 15.0, 20.0, 25.0, 30.0], depth=1, tolerance_deg=12.0)
    config["planner"]["dynamic"].update(speeds=[-2.0, 2.0], depth=1)
    config["verify"].update(trials=30, rule="point")  # few trials: the point rule
    part = Part.from_vertices([[0, 0], [70, 0], [50, 25], [10, 25]], name="trapezoid")
    entry = plan_tight(part, PlannerSettings.from_config(config).at(0.15)).to_dict()
    assert not entry["orients"] and not entry["moving_pin_search"]["orients"]
    assert entry["recommended"]["n_dynamic_pins"] == 0
    assert "nor do up to 1 moving pins" in entry["warning"] and "a sensor must tell them apart" in entry["warning"]


def test_a_square_needs_no_pin_and_the_oracle_agrees():
    """A square's four resting states are one orientation (4-fold symmetry): with
    no pin at all, the oracle's own trials already end within the tolerance, and
    the search says that no pin is needed."""
    part = Part.from_vertices([[0, 0], [40, 0], [40, 40], [0, 40]])
    finals = np.concatenate([t[0] for t in box_trials(part, 0, 30, 3, MU)])
    assert most_in_arc(finals, 8.0, part.symmetry_order()) == finals.size  # the oracle: oriented already
    result = _search(part, {"A": 10.0, "B": 30.0}, 8.0, 1)
    assert result.needs_no_pin and result.evidence().startswith("no pin is needed")
    triangle = _search(Part.from_vertices([[0, 0], [60, 0], [15, 35]]), {"A": 10.0}, 8.0, 1)
    assert not triangle.needs_no_pin


def _thin_triangle_entry(depth: int, prune: bool, monkeypatch):
    """The tight plan of a 60 x 20 mm right triangle that no fixed pin of up to
    ``depth`` orients, with (or, ``prune`` False, without) the moving search's
    pruning of prefixes that cannot beat a plan already found."""
    import pipeline.planning.plans.candidates as candidates
    import pipeline.planning.plans.plan as plan_module
    from pipeline.config import load_config
    config = load_config()
    config["planner"].update(pins="auto", depth=depth, tolerance_deg=10.0)
    config["planner"]["dynamic"].update(speeds=[-2.0, -1.0, 1.0, 2.0], depth=2)
    config["verify"].update(trials=30, rule="point")  # few trials: the point rule
    part = Part.from_vertices([[0, 0], [60, 0], [0, 20]], name="thin_triangle")
    with monkeypatch.context() as patch:
        if not prune:
            patch.setattr(candidates, "moving_room", lambda found, n_prefix, depth, **kw: depth)
        return plan_module.plan_tight(part, PlannerSettings.from_config(config).at(0.15)).to_dict()


def test_moving_prefixes_that_cannot_beat_a_found_plan_change_nothing(monkeypatch):
    """Two moving pins with no fixed pin before them orient the thin triangle;
    searching the fixed-pin prefixes only for plans of at most two pins gives
    the same recommended plan as searching them to the full moving depth (which
    finds longer plans too), and a prefix of two fixed pins is skipped with its
    reason."""
    pruned = _thin_triangle_entry(1, True, monkeypatch)
    full = _thin_triangle_entry(1, False, monkeypatch)
    assert pruned["recommended"]["pins"] == full["recommended"]["pins"]
    assert len(pruned["recommended"]["pins"]) == 2 and pruned["orients"]
    assert max(lv["pins"] for lv in full["moving_pin_search"]["levels"]) == 3
    assert max(lv["pins"] for lv in pruned["moving_pin_search"]["levels"]) == 2
    assert any(lv["pins"] == 3 and lv["orienting"] for lv in full["moving_pin_search"]["levels"])
    two_fixed = _thin_triangle_entry(2, True, monkeypatch)
    assert two_fixed["recommended"]["pins"] == pruned["recommended"]["pins"]
    skipped = two_fixed["moving_pin_search"]["skipped"]
    assert skipped and all(len(s["after"]) == 2 for s in skipped)
    assert skipped[0]["why"] == "a plan of 2 pins already orients the part"


def test_best_fixed_pin_results_name_each_sequence_once():
    """The evidence's best fixed-pin results (and so the prefixes moving pins
    follow) list a sequence once, though it may be both judged and among the
    fewest-cluster sequences of its level."""
    from pipeline.config import load_config
    from pipeline.planning.plans.plan import plan_tight
    config = load_config()
    config["planner"].update(pins="auto", depth=3, tolerance_deg=10.0)
    config["planner"]["dynamic"].update(depth=0)
    config["verify"].update(trials=30, rule="point")
    part = Part.from_vertices([[0, 0], [60, 0], [45, 50]], name="leaning_triangle")
    best = plan_tight(part, PlannerSettings.from_config(config).at(0.15)).to_dict()["fixed_pin_search"]["best_effort"]
    assert len(best) == 5 and all(len(b["pins"]) == 3 for b in best[:2])
    assert len({tuple(b["pins"]) for b in best}) == len(best)


def test_with_a_family_later_prefixes_look_only_for_fewer_pins():
    """moving_room: without a family a later prefix may tie the shortest plan
    found (same pins, maybe narrower); with one it must beat it."""
    from types import SimpleNamespace
    from pipeline.planning.plans.candidates import moving_room
    found = [SimpleNamespace(labels=("P1", "P2", "P3v-1"))]
    assert moving_room([], 2, 2) == 2
    assert moving_room(found, 2, 2) == 1 and moving_room(found, 2, 2, fewer=True) == 0
    assert moving_room(found, 1, 2, fewer=True) == 1
