"""The worst-member search for a support family.

Soundness: a plan the complete search returns for a tripod family (with the
worst-member check on) is replayed under every tripod of a dense grid of leg
positions built here (its own inset test, its own statics, its own replay
through the public ``simulate.rollout_points`` only): no grid member puts a
final outside the plan's claimed set. Not vacuous: the plan the planner used
to recommend for the default triangle and ``tripods:12`` is rejected because
the search finds a member that breaks it (the widest tripod, legs at the
inset outline's corners, ends every resting state below the set). Bad input:
a family with no member, a search with no budget.
"""
import itertools

import numpy as np
import pytest

from kernels.rollout import JAMMED, TRUNCATED

from pipeline.errors import PinfeedError
from pipeline.maps import simulate
from pipeline.parts.part import Part
from pipeline.parts.support import point_support
from pipeline.parts.support_family import parse_support_family
from pipeline.planning.core.settings import ClaimSettings, Perturbation, SearchSettings, VerifySettings
from pipeline.planning.tight.complete import FixedPinSearch
from pipeline.planning.family.member_search import check_budget
from pipeline.planning.family.member_spaces import member_space
from pipeline.planning.family.worst_member import FamilyChecker, FamilyCheckSettings, check_plan_for_family

TRIANGLE = Part.from_vertices([(0, 0), (60, 0), (15, 35)], "asym_triangle")
RECTANGLE = Part.from_vertices([(0, 0), (40, 0), (40, 20), (0, 20)], "rectangle")
BOX = {"theta_sigma": 1.0, "y_halfwidth": 0.5, "mu_sigma": 0.02, "pin_halfwidth": 0.3}


def _settings(mu, tolerance, trials, budget=60):
    return FamilyCheckSettings(mu, ClaimSettings(tolerance, 0.995),
                               VerifySettings(trials, True, 3, None, Perturbation(**BOX)),
                               SearchSettings(3.0, model="minpower", worst_member_budget=budget), 3)


# --------------------------------------------------------------------------- the reference (no search code)

def _inside(verts, p):
    """Point in polygon by crossings, and the distance to the nearest edge."""
    inside, dist = False, np.inf
    for (x0, y0), (x1, y1) in zip(verts, np.roll(verts, -1, axis=0)):
        if (y0 > p[1]) != (y1 > p[1]) and p[0] < x0 + (p[1] - y0) * (x1 - x0) / (y1 - y0):
            inside = not inside
        e = np.array([x1 - x0, y1 - y0])
        t = np.clip(((p[0] - x0) * e[0] + (p[1] - y0) * e[1]) / (e @ e), 0.0, 1.0)
        dist = min(dist, float(np.hypot(x0 + t * e[0] - p[0], y0 + t * e[1] - p[1])))
    return inside, dist


def _grid_tripods(part, inset, step):
    """Every tripod on a square grid of leg positions ``inset a`` inside the
    outline whose legs carry >= 5 % each (weights solved from statics here)."""
    verts = np.asarray(part.vertices, float)
    xs = np.arange(verts[:, 0].min(), verts[:, 0].max(), step)
    ys = np.arange(verts[:, 1].min(), verts[:, 1].max(), step)
    pts = [np.array([x, y]) for x in xs for y in ys]
    pts = [p for p in pts if (lambda r: r[0] and r[1] >= inset * part.a)(_inside(verts, p))]
    out = []
    for tri in itertools.combinations(pts, 3):
        m = np.vstack([np.array(tri).T, np.ones(3)])
        if abs(np.linalg.det(m)) < 1e-6:
            continue
        w = np.linalg.solve(m, np.array([0.0, 0.0, 1.0]))  # sum w p = centroid (origin), sum w = 1
        if np.all(w >= 0.05):
            out.append((np.array(tri), w))
    return out


def _corner_finals(part, heights, support, mu):
    """Finals of the nominal start and every perturbation-box corner of every
    resting state, replayed pin by pin through ``simulate.rollout_points``."""
    starts = []
    for theta, y_c in part.stable_states():
        starts.append((theta, y_c, sum(mu) / 2, (0.0,) * len(heights)))
        for c in itertools.product((-2.0, 2.0), (-0.5, 0.5), mu, *[(-0.3, 0.3)] * len(heights)):
            starts.append((theta + c[0], y_c + c[1], c[2], c[3:]))
    th = np.array([s[0] for s in starts])
    yc = np.array([s[1] for s in starts])
    mus = np.array([s[2] for s in starts])
    for k, h in enumerate(heights):
        d = (h + np.array([s[3][k] for s in starts]) - yc) / part.a
        res = simulate.rollout_points(part, th, d, mus, 3.0, support=support)
        stuck = (res["status"] == JAMMED) | (res["status"] == TRUNCATED)
        th, yc = np.where(stuck, np.nan, res["theta_f"]), yc + res["dy"]
    return np.mod(th, 360.0)  # a jam is NaN: counted as outside


def _outside(theta, start, width, period=360.0):
    rel = np.mod(theta - start, period)
    out = np.where(rel <= width + 1e-6, 0.0, np.minimum(rel - width, period - rel))
    return np.where(np.isnan(theta), 180.0, out)


# --------------------------------------------------------------------------- soundness

def _pins(part, n):
    top = max(y for _, y in part.stable_states()) * 1.8
    return {f"Q{k}": float(y) for k, y in enumerate(np.linspace(-0.1 * part.a, top, n), start=1)}


@pytest.mark.parametrize("part, n_pins, depth, tolerance, grid_step", [
    (TRIANGLE, 5, 4, 20.0, 1 / 9), (RECTANGLE, 6, 3, 30.0, 1 / 5)])
def test_no_grid_tripod_breaks_a_plan_the_search_returns(part, n_pins, depth, tolerance, grid_step):
    mu = (0.1, 0.2)
    family = parse_support_family("tripods:4", part)
    st = _settings(mu, tolerance, 20, budget=60)
    search = FixedPinSearch(part, _pins(part, n_pins), mu, ClaimSettings(tolerance, 0.995),
                            VerifySettings(20, True, 3, None, Perturbation(**BOX)), SearchSettings(3.0), family=family)
    search.member_check = FamilyChecker(part, family, st)
    result = search.run(depth, candidates=1)
    assert result.plans, result.evidence()
    plan = result.plans[0]
    check = search.member_check.result(plan.labels, plan.heights)
    assert check["holds"] and check["worst_member"]["outside_deg"] <= 0.0
    start, width = check["set_deg"]
    period = 360.0 / part.symmetry_order()
    grid = _grid_tripods(part, 0.2, grid_step * part.a)
    assert len(grid) >= 100  # dense enough to mean something
    worst = 0.0
    for legs, w in grid:
        finals = _corner_finals(part, plan.heights, point_support(part, legs, w), mu)
        worst = max(worst, float(_outside(finals, start, width, period).max()))
    assert worst == 0.0, f"a grid tripod puts a final {worst:.2f} deg outside {plan.labels}' set"


# --------------------------------------------------------------------------- not vacuous

def test_the_old_family_plan_is_broken_by_the_widest_tripod():
    """P11 P3 P11 P19 (15, -5, 15, 35 mm) passed the sampled verification on
    ``tripods:12``; the search names a member that ends outside its set."""
    family = parse_support_family("tripods:12", TRIANGLE)
    st = _settings((0.1, 0.3), 10.0, 300, budget=40)
    heights = (15.0, -5.0, 15.0, 35.0)
    check = check_plan_for_family(TRIANGLE, heights, family, st)
    assert not check["holds"]
    first = check["rounds"][0]
    assert first["breaks"] and first["outside_deg"] > 0.5
    # confirmed here by the public rollout API: the member's nominal finals lie outside the set
    legs, weights = np.array(first["member"]["points"]), np.array(first["member"]["weights"])
    start, width = first["set_deg"]
    finals = _corner_finals(TRIANGLE, heights, point_support(TRIANGLE, legs, weights), (0.1, 0.3))
    assert _outside(finals, start, width).max() > 0.5
    # the sampled members alone did not break it: the verification on them orients the part
    from pipeline.planning.family.worst_member import verify_members
    sampled = verify_members(TRIANGLE, heights, family, st)
    assert sampled["orients"]
    # The count in the arc the plan claims (an arc of the tolerance's width about the set) is the
    # best arc's count: that arc holds the set, and no arc of that width holds more.
    assert sampled["in_claimed_arc"] == sampled["in_tolerance"] <= sampled["trials"]
    assert sampled["claimed_arc_deg"][1] == pytest.approx(10.0)


def test_a_family_claim_that_fails_names_an_arc_of_the_tolerance():
    """One pin leaves the triangle in several sets for the family: the set
    its trials need is far wider than the tolerance, so the claim names the
    arc of the tolerance that holds the most trials, and counts those (the
    same count the verdict's best arc has), never the wide set."""
    from pipeline.planning.claims.plan_claim import family_claim, held_out_claim
    from pipeline.planning.family.worst_member import verify_members
    family = parse_support_family("tripods:12", TRIANGLE)
    st = _settings((0.1, 0.3), 10.0, 60, budget=10)
    verdict = verify_members(TRIANGLE, (15.0,), family, st)
    assert not verdict["orients"] and verdict["set"]["width"] > 10.0
    assert verdict["claimed_arc_deg"][1] == pytest.approx(10.0)
    assert verdict["in_claimed_arc"] == verdict["in_tolerance"] < verdict["trials"]
    base = held_out_claim(verdict, [], st.claims, 1, {}, {})
    claim = family_claim(base, family.label, {"verdict": verdict, "holds": False, "members": 12,
                                             "set_deg": [0.0, verdict["set"]["width"]]})
    assert claim.arc == tuple(verdict["claimed_arc_deg"]) and claim.in_arc == verdict["in_tolerance"]
    assert not claim.orients and "NOT" in claim.statement()


# --------------------------------------------------------------------------- bad input

def test_a_family_with_no_member_is_one_line():
    with pytest.raises(PinfeedError, match="has no member") as err:
        member_space(TRIANGLE, "tripods:12:inset=0.36")
    assert "\n" not in str(err.value) and "lower the inset" in str(err.value)


@pytest.mark.parametrize("budget", [0, -5, None, "x"])
def test_a_search_with_no_budget_is_one_line(budget):
    with pytest.raises(PinfeedError, match="a search with no budget") as err:
        check_budget(budget)
    assert "\n" not in str(err.value)


# --------------------------------------------------------------------------- the certificate

def test_certificate_of_a_plan_that_holds():
    from scipy.stats import beta

    from pipeline.planning.family.certificate import family_certificate, family_certificate_line
    family = parse_support_family("tripods:4", RECTANGLE)
    st = _settings((0.1, 0.2), 30.0, 20, budget=40)
    pins = _pins(RECTANGLE, 6)
    heights = (pins["Q5"], pins["Q1"], pins["Q5"])
    check = check_plan_for_family(RECTANGLE, heights, family, st)
    assert check["holds"]
    cert = family_certificate(RECTANGLE, heights, family, check, st)
    fresh = cert["fresh"]
    assert fresh["members"] >= 300
    k, n = fresh["members_outside"], fresh["members"]
    closed = 1 - 0.05 ** (1 / n) if k == 0 else beta.ppf(0.95, k + 1, n - k)
    assert fresh["share_outside_upper_bound"] == pytest.approx(closed, abs=1e-5)
    assert cert["worst_member"]["outside_deg"] <= 0.0 and cert["verification"]["members"] >= 4
    line = family_certificate_line(cert)
    assert "\n" not in line and f"of {n} fresh members" in line


def test_downstream_stages_say_they_assume_uniform_pressure():
    from pipeline.planning.family.certificate import family_assumption
    plan_file = {"tight": [{"support_family": {"label": "tripods:12", "members": []}}]}
    for stage in ("speed limit", "layout"):
        note = family_assumption(plan_file, stage)
        assert note["assumes"] == "uniform pressure" and "tripods:12" in note["assumption"]
        assert "\n" not in note["assumption"]
    assert family_assumption({"tight": [{}]}, "speed limit") == {}


def test_the_search_scores_members_on_a_subset_of_a_many_pin_probe():
    """Plans of many pins: the search's rows are a subset of the probe with
    each state's nominal row and the pins' diagonal corners, at most
    SEARCH_CORNERS corners a state; a member's objective there never exceeds
    its objective on the full probe (so a break found there is a break)."""
    import numpy as np
    from pipeline.parts.part import Part
    from pipeline.parts.support_family import parse_support_family
    from pipeline.planning.family.member_search import SEARCH_CORNERS, PlanProbe, coarse_rows, score
    from pipeline.planning.family.member_spaces import member_space
    part = Part.from_vertices([[0, 0], [60, 0], [45, 50]])
    probe = PlanProbe(part, (8.0, 20.0, 30.0, 12.0, 25.0), (0.1, 0.3), VerifySettings(trials=10))
    offsets = probe.inputs[3]
    rows = coarse_rows(offsets, probe.nominal, SEARCH_CORNERS)
    assert probe.coarse is not None and probe.coarse[0].size == rows.size
    assert set(probe.nominal.tolist()) <= set(rows.tolist())
    assert np.unique(rows).size == rows.size
    n_states = probe.nominal.size
    assert rows.size == n_states * (1 + SEARCH_CORNERS)
    diagonal = np.flatnonzero(offsets.min(axis=1) == offsets.max(axis=1))
    assert set(diagonal.tolist()) - set(probe.nominal.tolist()) <= set(rows.tolist())
    family = parse_support_family("tripods:6", part)
    arc = (0.0, 10.0)
    for member in family.members[:4]:
        coarse, _ = score(probe, member, arc, 360.0, coarse=True)
        full, _ = score(probe, member, arc, 360.0)
        assert coarse <= full + 1e-12
    assert member_space(part, family).describe()


def test_the_quick_weight_test_changes_no_drawn_tripod(monkeypatch):
    """``TripodSpace.random`` tests each random triple's centroid weights in
    plain floats before the full feasibility test: it never rejects a triple
    the statics' weights accept (random triples, some near the weight bound),
    and the drawn tripods are the same with it and without it."""
    from pipeline.planning.family import member_spaces as wm
    rng = np.random.default_rng(4)
    near = 0
    for _ in range(4000):
        x = rng.uniform(-30.0, 30.0, 6)
        lam = wm._weights(x.reshape(3, 2), TRIANGLE.a)
        accepted = lam is not None and lam.min() >= wm.MIN_LEG_WEIGHT
        near += bool(lam is not None and abs(lam.min() - wm.MIN_LEG_WEIGHT) < 0.02)
        assert wm._may_hold_centroid(x, TRIANGLE.a) or not accepted
    assert near > 10
    space = wm.member_space(TRIANGLE, "tripods:12:inset=0.25").spaces[0]
    quick = space.random(np.random.default_rng(9), 60)
    monkeypatch.setattr(wm, "_may_hold_centroid", lambda x, a: True)
    slow = space.random(np.random.default_rng(9), 60)
    assert len(quick) == len(slow) == 60
    assert all(np.array_equal(p, q) for p, q in zip(quick, slow))
