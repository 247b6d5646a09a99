"""Shape-tolerance families: every part whose outline vertices lie within a
tolerance of the drawing.

The reference here builds each member part itself (the drawn vertices plus
the offsets), finds its own resting states, and replays every one of them
nominally and at every corner of the perturbation box, pin by pin, through
the public ``simulate.rollout_points`` only. Checked: the probe's finals are
the reference's; the default triangle's plan P9 P16 P25 holds at 0.2 mm
(the worst member found and 40 members drawn here stay in the set); at 1 mm
the worst member found breaks it (confirmed by the reference), and its
certified radius lies below 1 mm with members drawn here inside the set.
"""
import itertools

import numpy as np
import pytest

from kernels.rollout import JAMMED, TRUNCATED

from pipeline.errors import PinfeedError
from pipeline.maps import simulate
from pipeline.parts.part import Part
from pipeline.planning.family import shape
from pipeline.planning.core.settings import ClaimSettings, Perturbation, SearchSettings, VerifySettings
from pipeline.planning.claims.plan_claim import claimed_arc
from pipeline.planning.family.worst_member import FamilyCheckSettings

TRIANGLE = Part.from_vertices([(0, 0), (60, 0), (15, 35)], "asym_triangle")
BOX = {"theta_sigma": 1.0, "y_halfwidth": 0.5, "mu_sigma": 0.02, "pin_halfwidth": 0.3}
MU = (0.1, 0.3)
HEIGHTS = (10.0, 27.5, 50.0)  # the default config's recommended plan P9 P16 P25
ARC = claimed_arc({"set": {"start": 21.0834, "width": 5.504}}, 10.0)
ST = FamilyCheckSettings(MU, ClaimSettings(10.0, 0.995), VerifySettings(100, True, 1, None, Perturbation(**BOX)),
                         SearchSettings(3.0, model="minpower", worst_member_budget=40), 1)


def _member(offsets):
    return Part.from_vertices([tuple(v) for v in np.asarray(TRIANGLE.vertices) + np.asarray(offsets)], "m")


def _finals(part, heights=HEIGHTS, mu=MU):
    """Every resting state of ``part``, nominal and at every box corner; a jam is NaN."""
    starts = []
    for theta, y_c in part.stable_states():
        starts.append((theta, y_c, sum(mu) / 2, (0.0,) * len(heights)))
        for c in itertools.product((-2.0, 2.0), (-0.5, 0.5), mu, *[(-0.3, 0.3)] * len(heights)):
            starts.append((theta + c[0], y_c + c[1], c[2], c[3:]))
    th, yc = np.array([s[0] for s in starts]), np.array([s[1] for s in starts])
    mus = np.array([s[2] for s in starts])
    for k, h in enumerate(heights):
        d = (h + np.array([s[3][k] for s in starts]) - yc) / part.a
        res = simulate.rollout_points(part, th, d, mus, 3.0)
        stuck = (res["status"] == JAMMED) | (res["status"] == TRUNCATED)
        th, yc = np.where(stuck, np.nan, res["theta_f"]), yc + res["dy"]
    return th


def _outside(theta, arc):
    rel = np.mod(theta - arc[0], 360.0)
    return np.where(np.isnan(theta), 180.0, np.where(rel <= arc[1] + 1e-6, 0.0,
                                                      np.minimum(rel - arc[1], 360.0 - rel)))


def _drawn(n, tol, seed):
    rng = np.random.default_rng(seed)
    ang, r = rng.uniform(0, 2 * np.pi, (n, 3)), tol * np.sqrt(rng.uniform(0, 1, (n, 3)))
    return np.stack([r * np.cos(ang), r * np.sin(ang)], axis=-1)


def test_the_probe_replays_each_members_own_resting_states():
    probe = shape.ShapeProbe(TRIANGLE, HEIGHTS, MU, ST.verify)
    for offsets in _drawn(3, 0.5, 7):
        tf, jam = probe.finals(shape.member_part(TRIANGLE, offsets))
        ref = _finals(_member(offsets))
        assert np.array_equal(jam, np.isnan(ref))
        assert np.allclose(tf[~jam], ref[~jam], atol=1e-6)


def test_the_default_plan_holds_at_a_fifth_of_a_millimetre():
    cert = shape.shape_certificate(TRIANGLE, HEIGHTS, ARC, 0.2, ST, members=60)
    assert cert["holds"] and cert["claim"]["violations"] == 0
    worst = np.asarray(cert["worst_member"]["member"]["vertex_offsets_mm"])
    assert np.hypot(*worst.T).max() <= 0.2 + 1e-9
    assert _outside(_finals(_member(worst)), ARC).max() == 0.0
    for offsets in _drawn(40, 0.2, 11):
        assert _outside(_finals(_member(offsets)), ARC).max() == 0.0


def test_at_one_millimetre_it_breaks_and_its_radius_is_smaller():
    result = shape.certified_radius(TRIANGLE, HEIGHTS, ARC, 1.0, ST, steps=3, members=40)
    broken = result["at_requested"]["worst_member"]
    assert broken["breaks"]
    assert _outside(_finals(_member(broken["member"]["vertex_offsets_mm"])), ARC).max() > 0.5
    radius = result["radius_mm"]
    assert radius is not None and 0.0 < radius < 1.0
    for offsets in _drawn(20, radius, 13):
        assert _outside(_finals(_member(offsets)), ARC).max() == 0.0
    assert "certified radius" in shape.shape_line(result)


@pytest.mark.parametrize("tol", [0.0, -1.0, float("nan")])
def test_a_tolerance_must_be_a_length(tol):
    with pytest.raises(PinfeedError, match="shape tolerance must be a length"):
        shape.ShapeSpace(TRIANGLE, tol)


def test_a_result_without_a_fixed_pin_plan_gets_a_note():
    from pipeline.config import load_config
    from pipeline.planning import PlanFile, PlannerSettings, TightEntry, attach_shape_tolerance, shape_line
    settings = PlannerSettings.from_config(load_config(None))
    result = PlanFile({"name": "triangle"}, tight=(TightEntry((0.1, 0.3), "0.1:0.3", ()),))
    entry = attach_shape_tolerance(result, TRIANGLE, settings, 0.2).tight[0].shape_tolerance
    assert entry["radius_mm"] is None and "nothing to certify" in shape_line(entry)
    with pytest.raises(PinfeedError, match="--shape-tolerance must be a length"):
        attach_shape_tolerance(result, TRIANGLE, settings, -0.2)


def test_the_config_gives_the_shape_tolerance_and_the_command_line_overrides_it():
    """``planner.shape_tolerance_mm`` reaches the settings; ``--shape-tolerance``
    (``planner_settings``) replaces it, and a length that is not > 0 is a
    one-line error; the workflow's plan attaches the check only when it is set;
    the key at its default leaves the config hash alone."""
    from pipeline.config import config_hash, load_config, validate_config
    from pipeline.planning import PlanFile, PlannerSettings, TightEntry
    from pipeline.workflow.commands import planner_settings
    from pipeline.workflow.plan import with_shape_tolerance
    config = load_config(None)
    assert PlannerSettings.from_config(config).search.shape_tolerance_mm is None
    assert config_hash(config) == config_hash({**config, "planner": {
        k: v for k, v in config["planner"].items() if k != "shape_tolerance_mm"}})
    set_ = planner_settings(config, shape_tolerance=0.2)
    assert PlannerSettings.from_config(set_).search.shape_tolerance_mm == 0.2
    assert config_hash(set_) != config_hash(config)
    for bad in (0.0, -0.1, float("nan")):
        with pytest.raises(PinfeedError, match="--shape-tolerance must be a length > 0 mm"):
            planner_settings(config, shape_tolerance=bad)
    with pytest.raises(Exception):
        validate_config({**config, "planner": {**config["planner"], "shape_tolerance_mm": -1.0}})
    result = PlanFile({"name": "triangle"}, tight=(TightEntry((0.1, 0.3), "0.1:0.3", ()),))
    assert "shape_tolerance" not in with_shape_tolerance(result, TRIANGLE, PlannerSettings.from_config(config)
                                                         ).to_dict()["tight"][0]
    attached = with_shape_tolerance(result, TRIANGLE, PlannerSettings.from_config(set_))
    assert attached.to_dict()["tight"][0]["shape_tolerance"]["requested_mm"] == 0.2
