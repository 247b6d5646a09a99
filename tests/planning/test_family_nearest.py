"""The nearest "yes" for a family no plan holds for.

The rectangle's plan Q5 Q1 Q5 holds for ``tripods:4`` within 30 deg but
not within 10. The tolerance axis answers the smallest tolerance (to 0.5
deg) at which it holds for the family with no fresh member outside. Checked
here: the answer is the smallest on the 0.5-degree ladder (a "yes" there,
not half a degree tighter), and the family's tripods on a grid of leg
positions, replayed by the public rollout API alone, all end inside the
claimed set at the answer. On the triangle's plan P11 P3 P11 P19 a fresh
tripod jams: no tolerance is a "yes", and the axis says so. The bisection is checked against a sweep of a monotone predicate;
the inset text and the largest inset with members against brute force.
"""
import numpy as np
import pytest

from pipeline.parts.part import Part
from pipeline.parts.support import point_support
from pipeline.parts.support_family import FamilySpec, parse_support_family
from pipeline.planning.core.nearest_axes import MAX_TOLERANCE, SUBJECT_FAMILY, bisect_smallest, nearest_yes_lines
from pipeline.planning.core.settings import ClaimSettings, Perturbation, SearchSettings, VerifySettings
from pipeline.planning.family import nearest
from pipeline.planning.family.member_spaces import member_space
from pipeline.planning.family.worst_member import FamilyCheckSettings, check_plan_for_family

from test_worst_member import RECTANGLE, _corner_finals, _grid_tripods, _outside, _pins, _settings

TRIANGLE = Part.from_vertices([(0, 0), (60, 0), (15, 35)], "asym_triangle")
BOX = {"theta_sigma": 1.0, "y_halfwidth": 0.5, "mu_sigma": 0.02, "pin_halfwidth": 0.3}
HEIGHTS = (15.0, -5.0, 15.0, 35.0)


def test_the_smallest_tolerance_holds_and_half_a_degree_less_does_not():
    family = parse_support_family("tripods:4", RECTANGLE)
    st = _settings((0.1, 0.2), 10.0, 20, budget=40)
    pins = _pins(RECTANGLE, 6)
    heights = (pins["Q5"], pins["Q1"], pins["Q5"])
    plans = [(("Q5", "Q1", "Q5"), heights, ())]
    answer = nearest.family_tolerance_axis(RECTANGLE, family, plans, st)
    assert answer["found"] and answer["holds"], answer["statement"]
    value = answer["value"]
    assert 10.0 < value <= MAX_TOLERANCE
    # the smallest on the half-degree ladder: half a degree tighter is not a "yes"
    assert nearest._holds(RECTANGLE, plans, family, st.with_tolerance(value - 0.5), None) is None
    claim = answer["certificate"]["claim"]
    assert claim["violations"] == 0 and claim["members"] >= 300  # a "yes" has no fresh member outside
    # the grid: every tripod 0.2 a inside, replayed without the planner's code, ends in the claimed set
    start, width = answer["certificate"]["set_deg"]
    period = 360.0 / RECTANGLE.symmetry_order()
    grid = _grid_tripods(RECTANGLE, 0.2, RECTANGLE.a / 5)
    assert len(grid) >= 50
    worst = max(float(_outside(_corner_finals(RECTANGLE, heights, point_support(RECTANGLE, legs, w), (0.1, 0.2)),
                               start, width, period).max()) for legs, w in grid)
    assert worst == 0.0


def test_a_jam_is_never_a_yes():
    """On the triangle's plan P11 P3 P11 P19 one fresh tripod jams: no tolerance makes it a "yes"."""
    family = parse_support_family("tripods:12", TRIANGLE)
    st = FamilyCheckSettings((0.1, 0.3), ClaimSettings(10.0, 0.995),
                             VerifySettings(100, True, 3, None, Perturbation(**BOX)),
                             SearchSettings(3.0, model="minpower", worst_member_budget=40), 3)
    answer = nearest.family_tolerance_axis(TRIANGLE, family, [(("P11", "P3", "P11", "P19"), HEIGHTS, ())], st)
    assert not answer["found"] and "45 deg" in answer["statement"]


@pytest.mark.parametrize("threshold", [0.0, 0.13, 0.5, 0.77, 0.99])
def test_the_bisection_finds_the_threshold_of_a_sweep(threshold):
    grid = np.linspace(0.0, 1.0, 1001)
    first = grid[grid >= threshold][0]  # the sweep's answer
    value, found = bisect_smallest(lambda x: "yes" if x >= threshold else None, 0.0, 1.0, steps=10)
    assert found == "yes" and first <= value <= first + 1.0 / 2 ** 10
    assert bisect_smallest(lambda x: None, 0.0, 1.0, nearest.STEPS) == (None, None)


def test_the_inset_text():
    spec = FamilySpec.parse
    assert nearest.with_inset(spec("tripods:12"), 0.25) == "tripods:12:inset=0.25"
    assert nearest.with_inset(spec("tripods:12:inset=0.1:seed=4; rim:8"), 0.3) == "tripods:12:seed=4:inset=0.3;rim:8"
    assert nearest.with_inset(spec("warp:0.3 ;uniform"), 0.3) == "warp:0.3;uniform"
    assert nearest.tripod_inset(spec("tripods:12")) == 0.2
    assert nearest.tripod_inset(spec("tripods:12:inset=0.15")) == 0.15
    assert nearest.tripod_inset(spec("warp:0.3")) is None
    assert spec("tripods:12:inset=0.1:seed=4; rim:8").format() == "tripods:12:inset=0.1:seed=4;rim:8"


def test_the_largest_inset_with_members_against_brute_force():
    top = nearest.largest_inset(TRIANGLE, FamilySpec.parse("tripods:12"), 0.2)

    def has(f):
        try:
            member_space(TRIANGLE, f"tripods:12:inset={f:.4g}")
            parse_support_family(f"tripods:12:inset={f:.4g}", TRIANGLE)
            return True
        except Exception:
            return False
    assert has(top) and not has(top + 2 * nearest.INSET_RESOLUTION)


def test_a_moving_plan_that_holds_is_the_moving_axis_and_the_rest_ask_without_it():
    """When a moving-pin plan holds for the family, the moving-pins axis is
    that plan with its certificate; the other axes start from the fixed-pin
    plans a worst member broke, never from a broken moving-pin plan."""
    from types import SimpleNamespace
    verdict = {"orients": True, "in_tolerance": 10}
    results = {(("P1", "P2"), (1.0, 2.0)): {"holds": False, "verdict": dict(verdict, in_tolerance=30),
                                            "_speeds": (0.0, -1.0)},
               (("P3", "P4"), (3.0, 4.0)): {"holds": False, "verdict": verdict, "_speeds": (0.0, 0.0)},
               (("P5",), (5.0,)): {"holds": False, "verdict": dict(verdict, in_tolerance=20)},
               (("P6",), (6.0,)): {"holds": True, "verdict": dict(verdict, in_tolerance=99)}}
    checker = SimpleNamespace(results=results)
    assert [p[0] for p in nearest.rejected_plans(checker)] == [("P1", "P2"), ("P5",), ("P3", "P4")]
    assert [p[0] for p in nearest.rejected_plans(checker, fixed_only=True)] == [("P5",), ("P3", "P4")]
    cert = {"holds": True, "claim": {"epsilon": 0.01, "beta": 0.05, "violations": 0, "members": 299}}
    moving = {"labels": ("P1", "P2v-1"), "heights": (1.0, 2.0), "speeds": (0.0, -1.0), "certificate": cert}
    axis = nearest.family_moving_axis("tripods:12", None, moving)
    assert axis["found"] and axis["holds"] and axis["value"] == 1 and axis["plan"] == ["P1", "P2v-1"]
    assert axis["family"] == "tripods:12"
    assert "holds" in nearest_yes_lines({"subject": SUBJECT_FAMILY, "axes": [axis]})[1]
    searched = nearest.family_moving_axis("tripods:12", SimpleNamespace(levels=[]))  # the stage ran, found none
    assert not searched["found"] and searched["statement"].startswith("searched")
    assert nearest.family_moving_axis("tripods:12", None)["statement"].startswith("not searched")


@pytest.mark.parametrize("tolerance", [10.0, 30.0])
def test_fresh_finals_that_fit_no_arc_leave_a_member_outside_of_every_set(tolerance):
    """The falsifier before each worst-member search (``certificate.fresh_fit``):
    when the fresh members' finals fit in no arc of the tolerance, every
    claimable set (each start on a 0.05-degree sweep, width the tolerance)
    has a fresh member outside, so the certificate cannot be a "yes"; when
    they fit, some set on the sweep holds them all."""
    from pipeline.planning.family.certificate import fresh_finals, fresh_fit
    from pipeline.planning.family.member_search import outside
    family = parse_support_family("tripods:4", RECTANGLE)
    st = _settings((0.1, 0.2), tolerance, 20, budget=40)
    pins = _pins(RECTANGLE, 6)
    fresh = fresh_finals(RECTANGLE, (pins["Q5"], pins["Q1"], pins["Q5"]), family, st)
    _, tf, jam = fresh
    period = 360.0 / RECTANGLE.symmetry_order()
    leaving = [int(np.any(outside(tf, (start, tolerance), period) > 0, axis=1).sum() + jam.any(axis=1).sum())
               for start in np.arange(0.0, period, 0.05)]
    assert fresh_fit(fresh, tolerance, RECTANGLE.symmetry_order()) == (min(leaving) == 0)
    # replayed a chunk at a time, stopping once the members so far fit no arc: the same numbers, or none
    early = fresh_finals(RECTANGLE, (pins["Q5"], pins["Q1"], pins["Q5"]), family, st, must_fit=True)
    assert (early is None) == (min(leaving) > 0)  # a result is a sample that fits
    if early is not None:
        assert np.array_equal(early[1], tf) and np.array_equal(early[2], jam)
    if tolerance == 10.0:
        assert min(leaving) > 0  # the plan's 10-degree "no" (see the first test): the falsifier has work here


def test_a_kept_member_refutes_only_where_no_arc_holds_its_finals():
    """The kept members' screen before each axis's checks: on the rectangle's
    plan Q5 Q1 Q5 the worst member found at 20 deg is kept; the screen says
    "broken" at a tolerance exactly when no arc of it (a 0.05-degree sweep)
    holds that member's nominal and corner finals, replayed pin by pin
    through the public rollout API."""
    from test_worst_member import _inside
    family = parse_support_family("tripods:4", RECTANGLE)
    pins = _pins(RECTANGLE, 6)
    heights = (pins["Q5"], pins["Q1"], pins["Q5"])
    st = _settings((0.1, 0.2), 20.0, 20, budget=40)
    check = check_plan_for_family(RECTANGLE, heights, family, st)
    member = check["_worst"].support
    assert check["_worst"].breaks
    finals = _corner_finals(RECTANGLE, heights, member, (0.1, 0.2))
    period = 360.0 / RECTANGLE.symmetry_order()
    starts = np.arange(0.0, period, 0.05)
    seen = set()
    for tolerance in (10.0, 20.0, 30.0, 45.0):
        fits = any(_outside(finals, s, tolerance, period).max() == 0.0 for s in starts)
        seen.add(fits)
        broken = nearest._kept_screen(RECTANGLE, family, st.with_tolerance(tolerance),
                                      [member])(heights, ())
        assert broken == (not fits), tolerance
    assert seen == {True, False}  # both answers met
    # a tripod belongs to a narrower family only when every leg is that far inside
    verts = np.asarray(RECTANGLE.vertices, float)
    depth = min(_inside(verts, p)[1] for p in member.points)
    assert nearest.kept_members(RECTANGLE, [member], depth / RECTANGLE.a - 1e-3) == [member]
    assert nearest.kept_members(RECTANGLE, [member], depth / RECTANGLE.a + 1e-3) == []
