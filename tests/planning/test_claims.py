"""What "orients" claims: the held-out step against the winner's curse, the
confidence bound, and the ranking (near misses, robustness before width)."""
import math
from dataclasses import replace

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from pipeline.errors import PinfeedError
from pipeline.planning.claims import orient
from pipeline.planning.tight.records import FixedPlan, margin_text, orientation_rank, robust_order
from pipeline.planning.claims.confidence import share_lower_bound
from pipeline.planning.claims.trials import holdout_settings, trial_inputs
from pipeline.planning.core.settings import VerifySettings

N, REQUIRED = 1092, 0.995  # the default triangle's trials: 3 states x (300 + 64 corners)


def _synthetic_finals(k, n):
    """k trials in one set (at 0 deg), the rest half a turn away."""
    return np.r_[np.zeros(k), np.full(n - k, 180.0)]


def test_held_out_bound_rejects_lucky_winners_at_the_promised_rate():
    """Fifty candidate plans whose true share (99.3 %) sits just below the rule:
    the point rule on selection trials nearly always finds a lucky 'winner';
    the held-out check with the bound certifies it at most 5 % of the time (the
    bound's promise), while the point rule on fresh trials alone would pass it
    far more often."""
    rng = np.random.default_rng(2026)
    p_true, runs = 0.993, 600
    winners = certified = point_only = 0
    for _ in range(runs):
        selection = rng.binomial(N, p_true, size=50)
        if not (selection >= orient.needed(N, REQUIRED)).any():
            continue
        winners += 1
        k = rng.binomial(N, p_true)  # the winner's held-out trials
        verdict = orient.judge(_synthetic_finals(k, N), N, 10.0, required=REQUIRED)
        certified += verdict["orients"]
        point_only += verdict["point_rule"]
    assert winners > 0.9 * runs
    rate = certified / winners
    assert rate <= 0.05 + 3.0 * math.sqrt(0.05 * 0.95 / winners)
    assert point_only / winners > 2.0 * rate + 0.05


def test_held_out_bound_certifies_a_plan_that_truly_orients():
    """Power: a plan whose true share is 99.9 % is certified most of the time."""
    rng = np.random.default_rng(7)
    ks = rng.binomial(N, 0.999, size=400)
    passed = [orient.judge(_synthetic_finals(k, N), N, 10.0, required=REQUIRED)["orients"] for k in ks]
    assert np.mean(passed) > 0.5


@pytest.mark.parametrize("n", [300, 598, 1092, 2000])
def test_max_failures_is_the_largest_allowance_the_bound_accepts(n):
    f = orient.max_failures(n, REQUIRED)
    brute = max([g for g in range(n + 1) if share_lower_bound(n - g, n) >= REQUIRED], default=-1)
    assert f == brute
    assert orient.max_failures(n, REQUIRED, rule="point") == n - orient.needed(n, REQUIRED)


def test_bound_needs_about_600_clean_trials_for_995():
    assert orient.max_failures(597, REQUIRED) == -1 and orient.max_failures(598, REQUIRED) == 0


def test_judge_reports_share_bound_and_interval():
    v = orient.judge(_synthetic_finals(N - 1, N), N, 10.0, required=REQUIRED, interval=True)
    assert v["orients"] and v["point_rule"]
    assert v["share"] == pytest.approx((N - 1) / N, abs=1e-6)
    assert v["share_lower_bound"] == pytest.approx(share_lower_bound(N - 1, N), abs=1e-6)
    lo, hi = v["width_interval_deg"]
    assert lo <= v["width_deg"] <= hi
    near = orient.judge(_synthetic_finals(N - 5, N), N, 10.0, required=REQUIRED)
    assert near["point_rule"] and not near["orients"]  # the 1087 of 1092
    assert "near miss" in orient.describe_claim(near)
    assert orient.judge(_synthetic_finals(N - 5, N), N, 10.0, required=REQUIRED, rule="point")["orients"]


def test_held_out_trials_are_fresh_and_not_fewer():
    chosen = VerifySettings(trials=40, seed=1)
    held = chosen.held_out()
    assert held.trials == 40 and held.seed != 1 and held.holdout
    assert chosen.held_out() == held  # reproducible
    assert VerifySettings(trials=40, seed=1, holdout_trials=80).held_out().trials == 80
    states = {"s": (10.0, 5.0)}
    a = trial_inputs(states, 0.15, 2, replace(chosen, corners=False))[0][0]
    b = trial_inputs(states, 0.15, 2, replace(held, corners=False))[0][0]
    assert not np.intersect1d(a, b).size  # no selection trial is reused
    with pytest.raises(PinfeedError) as err:
        VerifySettings(trials=40, seed=1, holdout_trials=10).held_out()
    assert "\n" not in str(err.value) and "holdout_trials" in str(err.value)


def test_the_flat_dicts_not_yet_switched_callers_pass_give_the_same_trials():
    # plans/plan.py and family/* still pass the flat dicts of VerifySettings.as_dict();
    # read back, they are the same settings and draw the same trials.
    chosen = VerifySettings(trials=40, seed=1)
    held = chosen.held_out()
    assert holdout_settings(chosen) == held.as_dict() == dict(chosen.as_dict(), trials=40, seed=held.seed,
                                                              holdout=True)
    assert list(held.as_dict()) == list(chosen.as_dict()) + ["holdout"]  # the record's key order
    assert list(chosen.untruncated(12).as_dict()) == list(chosen.as_dict()) + ["truncate_sigma", "holdout"]
    assert VerifySettings.from_section(held.as_dict()) == held
    assert VerifySettings.from_section({"trials": 40, "seed": 1}) == chosen
    states = {"s": (10.0, 5.0), "t": (200.0, 7.0)}
    for typed in (chosen, held, chosen.untruncated(12)):
        a, b = trial_inputs(states, 0.15, 2, typed), trial_inputs(states, 0.15, 2, typed.as_dict())
        for x, y in zip(a, b):
            for u, v in zip(x, y):
                np.testing.assert_array_equal(u, v)


@pytest.mark.parametrize("bad", [0.0, 1.0, -0.5, 2])
def test_confidence_outside_unit_interval_is_refused_by_the_planner(bad):
    with pytest.raises(PinfeedError) as err:
        orient.judge([0.0], 1, 10.0, confidence=bad)
    assert "\n" not in str(err.value) and "confidence" in str(err.value)


def test_bad_rule_is_one_line():
    with pytest.raises(PinfeedError) as err:
        orient.check_rule("loose")
    assert "\n" not in str(err.value) and "verify.rule" in str(err.value)


def _plan(name, width, margin, orients=True, point=True):
    v = {"orients": orients, "point_rule": point, "width_deg": width, "trials": 100, "in_tolerance": 100,
         "needed": 100, "sets_within_tolerance": 1}
    return FixedPlan((name,), (0.0,), width, margin, v)


def test_near_misses_rank_after_plans_that_clear_the_bound():
    clear = _plan("clear", 9.0, 0.1)
    near = _plan("near", 3.0, 0.1, orients=False, point=True)
    miss = _plan("miss", 2.0, 0.1, orients=False, point=False)
    assert sorted([miss, near, clear], key=FixedPlan.rank_key) == [clear, near, miss]


def test_a_negative_margin_yields_to_a_safe_plan_within_the_slack():
    """The slot's case: P20 P16 (3.6 deg, margin -0.015) against P20 P15 (3.6 deg, +0.026)."""
    risky = _plan("risky", 3.55, -0.015)
    safe = _plan("safe", 3.6, 0.026)
    far = _plan("far", 5.0, 0.2)
    key, width, margin = FixedPlan.rank_key, FixedPlan.width, lambda p: p.margin
    assert sorted([risky, safe], key=key)[0] is risky  # width alone would pick the risky one
    assert robust_order([risky, safe, far], key, width, margin, 1.0) == [safe, risky, far]
    assert robust_order([risky, far], key, width, margin, 1.0) == [risky, far]  # 1.45 deg wider: no
    assert robust_order([risky, far], key, width, margin, 2.0) == [far, risky]
    assert robust_order([risky, safe], key, width, margin, 0.0) == [risky, safe]


def test_margin_is_said_in_words():
    assert "outside the safe band" in margin_text(-0.015)
    assert "inside the safe band" in margin_text(0.026)
    assert "no pin touches" in margin_text(float("inf"))
    assert orientation_rank({"orients": True, "point_rule": True, "width_deg": 3.0}, 2, 0.1)[:2] == (0, 0)


def _default_raw_config():
    import yaml

    from pipeline.config import DEFAULT_CONFIG
    with open(DEFAULT_CONFIG) as fh:
        return yaml.safe_load(fh)


@pytest.mark.parametrize("bad", [0.0, 1.0, -0.5, 1.5])
def test_confidence_outside_unit_interval_is_refused_by_config_validation(bad):
    from pipeline.config import validate_config
    raw = _default_raw_config()
    raw["verify"]["confidence"] = bad
    with pytest.raises(PinfeedError) as err:
        validate_config(raw)
    assert "\n" not in str(err.value) and "verify/confidence" in str(err.value)


@pytest.mark.parametrize("bad", [0.0, 1.0, 1.5])
def test_confidence_outside_unit_interval_is_refused_by_the_planner_settings(bad):
    from pipeline.planning.core.settings import ClaimSettings
    with pytest.raises(PinfeedError) as err:
        ClaimSettings(confidence=bad)
    assert "\n" not in str(err.value) and "verify.confidence" in str(err.value)


def test_fewer_held_out_than_selection_trials_is_refused_by_config_validation():
    from pipeline.config import validate_config
    raw = _default_raw_config()
    raw["verify"]["holdout_trials"] = raw["verify"]["trials"] - 1
    with pytest.raises(PinfeedError) as err:
        validate_config(raw)
    assert "\n" not in str(err.value) and "verify/holdout_trials" in str(err.value)
    raw["verify"]["holdout_trials"] = raw["verify"]["trials"]
    assert validate_config(raw)["verify"]["holdout_trials"] == raw["verify"]["trials"]


def test_describe_claim_says_share_bound_width_and_verdict_in_one_line():
    clean = orient.judge(np.linspace(0.0, 5.0, N), N, 10.0, required=REQUIRED, interval=True)
    text = orient.describe_claim(clean)
    assert "\n" not in text and text.endswith(": orients the part")
    assert f"{N}/{N} trials" in text and "at least 99.73 % with 95 % confidence" in text
    assert "bootstrap interval" in text
    # 5 failures in 1092: the point rule holds (99.54 %) but its lower bound (about 99.0 %) does not
    near = orient.judge(_synthetic_finals(N - 5, N), N, 10.0, required=REQUIRED)
    assert near["point_rule"] and not near["orients"]
    assert orient.describe_claim(near).endswith("a near miss)")
    worse = orient.judge(_synthetic_finals(N - 20, N), N, 10.0, required=REQUIRED)
    assert orient.describe_claim(worse).endswith(": does not orient the part")


def test_claim_settings_at_their_defaults_leave_the_config_hash():
    """A config that does not touch the claim's settings keeps its hash (and the
    hash its map shards record); changing one changes it."""
    from pipeline.config import config_hash, load_config
    config = load_config()
    before = config_hash(config)
    for section, key in [("verify", "confidence"), ("verify", "rule"), ("verify", "holdout_trials"),
                         ("planner", "width_slack_deg"), ("planner", "worst_member_budget")]:
        assert key in config[section]
        del config[section][key]
    assert config_hash(config) == before
    changed = load_config()
    changed["verify"]["confidence"] = 0.9
    assert config_hash(changed) != before


@pytest.mark.parametrize("required, confidence", [(0.995, 0.95), (0.99, 0.9), (0.95, 0.99), (0.999, 0.95)])
def test_min_trials_is_the_smallest_count_whose_clean_run_clears_the_bound(required, confidence):
    """Against the zero-failure Clopper-Pearson bound in closed form, (1 - c) ** (1 / n)."""
    brute = next(n for n in range(1, 100_000) if (1.0 - confidence) ** (1.0 / n) >= required)
    assert orient.min_trials(required, confidence) == brute
    assert orient.max_failures(brute, required, confidence) == 0
    assert orient.max_failures(brute - 1, required, confidence) == -1


def test_too_few_trials_for_the_claim_is_said_with_the_way_out():
    """A search whose trials cannot support the bound at all says so, with the
    number needed, instead of only 'no plan orients'."""
    from pipeline.parts.part import Part
    from pipeline.planning.tight.complete import FixedPinSearch

    part = Part.from_vertices([(0, 0), (50, 0), (0, 30)], "right_triangle")
    from pipeline.planning.core.settings import ClaimSettings, SearchSettings, VerifySettings
    search = FixedPinSearch(part, {"P1": 0.0, "P2": 8.0, "P3": 16.0}, (0.1, 0.2), ClaimSettings(10.0, 0.995),
                            VerifySettings(trials=10, seed=3), SearchSettings(3.0))
    result = search.run(1, candidates=2, keep=2)
    evidence = result.evidence()
    assert not result.orients
    assert all(lv.get("too_few_trials") for lv in result.levels)
    assert "cannot show 99.5 % at 95 % confidence" in evidence and "at least 598 are needed" in evidence
    assert "verify.trials" in evidence


def _fewest_arcs_by_enumeration(theta, width, order):
    """Fewest arcs of ``width`` covering ``theta`` (mod 360/order), by trying
    every set of start points (an optimal cover's arcs may start at points)."""
    import itertools
    period = 360.0 / order
    x = np.mod(np.asarray(theta, float), period)
    for k in range(1, x.size + 1):
        for starts in itertools.combinations(x, k):
            if all(any(np.mod(t - s, period) <= width + 1e-9 for s in starts) for t in x):
                return k
    return 0


@settings(max_examples=150, deadline=None)
@given(st.lists(st.sampled_from(np.arange(0.0, 360.0, 2.5).tolist()), min_size=1, max_size=7),
       st.sampled_from([2.5, 5.0, 10.0, 45.0, 200.0]), st.sampled_from([1, 2, 3]))
def test_the_fewest_sets_are_those_of_exhaustive_enumeration(theta, width, order):
    assert orient.arcs_to_cover(theta, width, order) == _fewest_arcs_by_enumeration(theta, width, order)
