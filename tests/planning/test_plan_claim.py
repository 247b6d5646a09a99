"""A plan's one claim: its arc and counts, checked against replays and brute force.

The claim says "the part ends in this arc, with this share and this lower
bound, on these trials". A replay that shares nothing with the planner's
batch replay (``oracle.replay_box``: one ``simulate.rollout_points`` call
per pin) must put the printed number of held-out trials in the printed arc,
and fresh trials drawn uniformly over the same box must mostly land there.
"""
from __future__ import annotations

import json

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from oracle import box_trials, replay_box
from pipeline.config import load_config
from pipeline.parts.part import Part
from pipeline.planning.claims.confidence import share_lower_bound
from pipeline.planning.claims.plan_claim import count_in_arc, promised_arc
from pipeline.planning.claims.trials import trial_inputs
from pipeline.planning.core.claim import Claim
from pipeline.planning.core.settings import VerifySettings

angles = st.lists(st.floats(0.0, 720.0, allow_nan=False), min_size=1, max_size=40)


@settings(max_examples=60, deadline=None)
@given(angles, st.floats(0.0, 359.0), st.floats(0.5, 40.0), st.sampled_from([1, 2, 3]))
def test_count_in_arc_is_the_brute_force_count(finals, start, width, order):
    period = 360.0 / order
    lo = start % period
    ends = [lo, lo + width]
    # An angle within a hair of either end may round either way: not a case worth testing.
    assume(all(min(abs((x - e + period / 2) % period - period / 2) for e in ends) > 1e-3 for x in finals))
    brute = 0
    for x in finals:  # every copy of the angle on the plain line against the arc [lo, lo + width]
        brute += any(lo <= x + k * period <= lo + width for k in range(-4 * order, 4 * order + 1))
    assert count_in_arc(finals, (start, width), order) == brute
    # Finals exactly on an end (as when many trials come to rest on one vertex) are inside.
    assert count_in_arc([lo, lo + width], (lo + 5e-5, width - 1e-4), order) == 2


@settings(max_examples=60, deadline=None)
@given(st.floats(0.0, 359.0), st.floats(0.0, 9.9), st.floats(1.0, 30.0))
def test_the_promised_arc_is_the_set_widened_about_its_middle(start, width, tolerance):
    arc = promised_arc({"set": {"start": start, "width": width}}, tolerance)
    assert arc[1] == pytest.approx(max(width, tolerance), abs=1e-4)
    middle_set = start + width / 2.0
    middle_arc = arc[0] + arc[1] / 2.0
    assert abs(((middle_arc - middle_set) + 180.0) % 360.0 - 180.0) < 1e-3
    assert promised_arc({"set": None}, tolerance) is None


@pytest.fixture(scope="module")
def planned(tmp_path_factory):
    from pipeline.cli import main
    tmp = tmp_path_factory.mktemp("claim")
    out = tmp / "plan.json"
    args = ["plan", "--vertices", "0,0 60,0 15,35", "--name", "tri", "--catalog", str(tmp / "cat"),
            "--depth", "2", "--pins=7.5,15,27.5,42.5", "--mu-c", "0", "--out", str(out)]
    assert main(args) == 0
    return json.loads(out.read_text())


def test_every_plan_has_one_claim_whose_statement_gives_its_numbers(planned):
    entry = planned["tight"][0]
    assert entry["plans"]
    for plan in entry["plans"] + entry["rejected"]:
        claim = plan["claim"]
        c = Claim.from_dict(claim)
        assert Claim.from_dict(c.to_dict()) == c and c.to_dict() == claim
        assert claim["trials"] == plan["verification"]["trials"]
        assert claim["share_lower_bound"] == pytest.approx(
            share_lower_bound(claim["in_arc"], claim["trials"], claim["confidence"]), abs=1e-6)
        assert f"{claim['in_arc']}/{claim['trials']} held-out trials in it" in claim["statement"]
        assert c.arc_text in claim["statement"] and claim["arc"]["width"] == claim["tolerance_deg"]
        assert plan["carried_sets_kind"] in ("propagated", "sampled")


def test_an_independent_replay_puts_the_printed_count_in_the_printed_arc(planned):
    """The held-out trials (the same draws) replayed by the oracle, one
    rollout call per pin: the finals in the claim's arc are the claim's count."""
    entry = planned["tight"][0]
    plan = entry["recommended"]
    claim = plan["claim"]
    part = Part.from_dict(planned["part"])
    states = {k: (v["theta"], v["y_c"]) for k, v in entry["initial_states"].items()}
    inputs = trial_inputs(states, 0.0, len(plan["pins"]), VerifySettings.from_section(load_config(None)["verify"]).held_out())
    trials = [(th, yc, mu, offs) for th, yc, mu, offs, _ in inputs]
    finals = replay_box(part, plan["pin_heights_mm"], trials, strict=False)
    assert finals.size == claim["trials"]
    finals = finals[np.isfinite(finals)]
    inside = count_in_arc(finals, (claim["arc"]["start"], claim["arc"]["width"]), claim["symmetry_order"])
    assert abs(inside - claim["in_arc"]) <= 1  # a final on the arc's edge may round either way


def test_fresh_trials_over_the_box_mostly_end_in_the_arc(planned):
    """Fresh trials drawn uniformly over the perturbation box (the truncated
    normals' support), replayed by the oracle: the recommended plan's claim
    holds for them within sampling error."""
    entry = planned["tight"][0]
    plan, claim = entry["recommended"], entry["recommended"]["claim"]
    part = Part.from_dict(planned["part"])
    p = claim["perturbations"]
    mu = p["mu_c"]
    mu_range = (0.0, 2 * mu["normal_sigma"])  # mu_c 0: the normal is floored at 0
    trials = box_trials(part, len(plan["pins"]), 40, seed=11, mu_range=mu_range,
                        theta_half=2 * p["theta_deg"]["normal_sigma"], y_half=p["y_c_mm"]["uniform_halfwidth"],
                        pin_half=p["pin_offset_mm"]["uniform_halfwidth"])
    finals = replay_box(part, plan["pin_heights_mm"], trials, strict=False)
    inside = count_in_arc(finals[np.isfinite(finals)], (claim["arc"]["start"], claim["arc"]["width"]),
                          claim["symmetry_order"])
    assert inside / finals.size >= 0.97
