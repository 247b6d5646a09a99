"""Kept worst members end a level, and a family claim states epsilon and beta.

The prescreen (``FamilyChecker.prescreen``) rejects a sequence only when
the kept breakers' probe finals together fit in no arc of the tolerance. The
reference here replays the same starts (every resting state nominally and at
every corner of the perturbation box) pin by pin through the public
``simulate.rollout_points`` and fits the arc by sorting: the two must agree
on every sequence, with both answers present. The certificate's epsilon and
beta are checked against the scenario approach's closed form.
"""

import numpy as np
import pytest


from pipeline.parts.part import Part
from pipeline.parts.support_family import parse_support_family
from pipeline.planning.family.certificate import members_needed, scenario_claim
from pipeline.planning.core.settings import ClaimSettings, Perturbation, SearchSettings, VerifySettings
from pipeline.planning.family.member_spaces import member_space
from pipeline.planning.family.worst_member import FamilyChecker, FamilyCheckSettings

from test_worst_member import _corner_finals

TRIANGLE = Part.from_vertices([(0, 0), (60, 0), (15, 35)], "asym_triangle")
BOX = {"theta_sigma": 1.0, "y_halfwidth": 0.5, "mu_sigma": 0.02, "pin_halfwidth": 0.3}
MU = (0.1, 0.3)


def _fits(theta, width):
    """Whether every angle lies in one arc of ``width`` degrees (sorting: the
    largest circular gap is at least 360 - width)."""
    if np.isnan(theta).any():
        return False
    x = np.sort(theta)
    gaps = np.diff(np.concatenate([x, [x[0] + 360.0]]))
    return gaps.max() >= 360.0 - width - 1e-9


def test_the_prescreen_agrees_with_an_independent_replay():
    family = parse_support_family("tripods:12", TRIANGLE)
    st = FamilyCheckSettings(MU, ClaimSettings(10.0, 0.995),
                             VerifySettings(20, True, 3, None, Perturbation(**BOX)),
                             SearchSettings(3.0, model="minpower", worst_member_budget=20), 3)
    checker = FamilyChecker(TRIANGLE, family, st)
    space = member_space(TRIANGLE, family).spaces[0]
    widest = space.member(space.corners()[0], "legs at the inset outline's corners")
    checker.breakers.append(widest)
    sequences = np.array([(15.0, -5.0, 15.0, 35.0), (15.0, -5.0, 15.0, 30.0), (20.0, -5.0, 10.0, 35.0),
                          (5.0, 10.0, 20.0, 35.0), (-5.0, 15.0, -5.0, 15.0), (35.0, 15.0, -5.0, 15.0),
                          (10.0, 25.0, 0.0, 20.0), (25.0, 5.0, 30.0, -5.0)])
    broken = checker.prescreen(sequences, np.zeros_like(sequences), 10.0)
    reference = np.array([not _fits(_corner_finals(TRIANGLE, h, widest, MU), 10.0) for h in sequences])
    assert broken.tolist() == reference.tolist()
    assert reference.any() and not reference.all(), reference  # both answers are tested
    assert checker.spared["sequences"] == int(reference.sum())


def test_without_a_kept_member_nothing_is_prescreened():
    family = parse_support_family("tripods:12", TRIANGLE)
    st = FamilyCheckSettings(MU, ClaimSettings(10.0, 0.995),
                             VerifySettings(20, seed=3, perturbation=Perturbation(**BOX)),
                             SearchSettings(3.0, model="minpower", worst_member_budget=20), 3)
    sequences = np.array([(15.0, -5.0, 15.0, 35.0)])
    assert not FamilyChecker(TRIANGLE, family, st).prescreen(sequences, np.zeros_like(sequences), 10.0).any()


@pytest.mark.parametrize("epsilon, beta, members", [(0.01, 0.05, 299), (0.01, 1e-6, 1375)])
def test_members_needed_is_the_scenario_bound(epsilon, beta, members):
    assert members_needed(epsilon, beta) == members
    # and the smallest such number: one fewer member does not reach epsilon at beta
    assert (1 - epsilon) ** members <= beta < (1 - epsilon) ** (members - 1)


def test_the_claim_states_epsilon_and_beta():
    claim = scenario_claim(0, 300, 0.95)
    assert claim["beta"] == pytest.approx(0.05)
    assert claim["epsilon"] == pytest.approx(1 - 0.05 ** (1 / 300), abs=1e-5)
    assert claim["violations"] == 0 and claim["members"] == 300
    assert "heuristic" in claim["search"] and "not a proof" in claim["search"]
    with_one = scenario_claim(1, 300, 0.95)
    assert with_one["epsilon"] > claim["epsilon"]


def _arc_holds_brute(must, tolerance, others, jammed, allowed, period=360.0):
    """Every start on a 0.01-degree grid (and at every angle) tried."""
    need = len(others) - allowed
    starts = np.concatenate([np.arange(0.0, period, 0.01), np.mod(must, period), np.mod(others, period),
                             np.mod(np.asarray(others) - tolerance, period)])
    for s in starts:
        if np.all(np.mod(np.asarray(must) - s, period) <= tolerance + 1e-9):
            held = np.sum((np.mod(np.asarray(others) - s, period) <= tolerance + 1e-9) & ~np.asarray(jammed))
            if held >= need:
                return True
    return False


@pytest.mark.parametrize("seed", range(40))
def test_arc_holds_matches_trying_every_start(seed):
    from pipeline.planning.family.worst_member import arc_holds
    rng = np.random.default_rng(seed)
    centre = rng.uniform(0, 360)
    must = centre + rng.uniform(-5, 5, rng.integers(1, 5))
    others = centre + rng.normal(0, 3, 15)
    jammed = rng.random(15) < 0.1
    allowed = int(rng.integers(0, 4))
    expect = _arc_holds_brute(must, 10.0, others, jammed, allowed)
    assert arc_holds(must, 10.0, 1, (others, jammed), allowed) == expect
    assert arc_holds(must, 10.0) == _arc_holds_brute(must, 10.0, np.zeros(0), np.zeros(0, bool), 0)


def test_the_random_arcs_have_both_answers():
    from pipeline.planning.family.worst_member import arc_holds
    answers = set()
    for seed in range(40):
        rng = np.random.default_rng(seed)
        centre = rng.uniform(0, 360)
        must = centre + rng.uniform(-5, 5, rng.integers(1, 5))
        others = centre + rng.normal(0, 3, 15)
        answers.add(arc_holds(must, 10.0, 1, (others, rng.random(15) < 0.1), int(rng.integers(0, 4))))
    assert answers == {True, False}
