"""The nearest "yes" when no plan holds for a support family.

When the complete search finds no plan of up to ``N`` pins that holds for a
family, an engineer asks what would make it hold. This module answers along
each axis that applies, starting from the plans the search had to reject
(those that passed the sampled verification and that a worst member broke,
best first), and verifies each answer the way any family plan is verified:
the worst-member search with the breaking members joining the verification
(:func:`~pipeline.planning.family.worst_member.check_plan_for_family`), then
a certificate on fresh members (:func:`~pipeline.planning.family.certificate.family_certificate`):
a value counts as "yes" only when no fresh member leaves the set (with 300
members, epsilon about 1 % at beta 0.05).

The axes:

* **the largest certified sub-family** in the family's own terms:

  - ``tripods``: the smallest leg inset (legs at least ``F a`` inside the
    outline) for which a plan holds, the family as given otherwise;
  - ``friction``: the widest friction range about the middle of a range
    ``lo:hi`` for which a plan holds (the family as given);

* **a looser tolerance**: the smallest ``tolerance_deg`` for which a plan
  holds for the whole family;
* **moving pins**: what the search's moving-pin stage found (it runs when
  pin speeds are configured and no fixed-pin plan holds);
* **more pins or a wider pin grid**: not searched here (a deeper complete
  search costs more than the rest together); the entry says how to run it.

Each number is found by bisection (``STEPS`` halvings,
:func:`~pipeline.planning.core.nearest_axes.bisect_smallest`) on the assumption
that holding is monotone along the axis (a smaller family or a looser
tolerance does not break a plan that held): an assumption of the search,
not a guarantee; the certificate at the answer is the evidence.
"""
from __future__ import annotations

import dataclasses

import numpy as np

from pipeline.errors import PinfeedError
from pipeline.parts.support import material_distance
from pipeline.parts.support_family import DEFAULT_INSET, FamilySpec, parse_support_family
from pipeline.planning.core.nearest_axes import (MAX_TOLERANCE, SUBJECT_FAMILY, bisect_smallest, ladder_up,
                                                 more_pins_axis, unanswered_axis)
from pipeline.planning.family.certificate import MIN_FRESH_MEMBERS, family_certificate, fresh_finals, fresh_members
from pipeline.planning.family.member_spaces import member_space
from pipeline.planning.family.worst_member import FamilyChecker, check_plan_for_family

STEPS = 5  # bisection halvings per axis
PLANS_TRIED = 3  # rejected plans tried on each axis, best first
INSET_RESOLUTION = 0.005  # of a: the largest inset with a member is found to this


def rejected_plans(checker: FamilyChecker, n: int = PLANS_TRIED, fixed_only: bool = False) -> list:
    """The plans a worst member broke after they passed the sampled
    verification, most trials in one set first: ``(labels, heights, speeds)``
    (``fixed_only``: those without a moving pin)."""
    def sampled(r):  # the verdict the plan passed before a worst member joined (older records: the last)
        return r.get("sampled_verdict") or r.get("verdict", {})

    broken = [(key, r) for key, r in checker.results.items()
              if not r["holds"] and sampled(r).get("orients")
              and not (fixed_only and any(r.get("_speeds", ())))]
    broken.sort(key=lambda kr: -sampled(kr[1])["in_tolerance"])
    return [(key[0], key[1], r.get("_speeds", ())) for key, r in broken[:n]]


def kept_members(part, kept, inset: float | None = None) -> list:
    """The worst members the search kept (``FamilyChecker.breakers``) that are
    members of the family an axis asks about: all of them for the same family
    at another friction or tolerance; with ``inset``, a tripod only when all
    its legs lie at least ``inset * a`` inside the material (fewer members
    only make the screen below weaker, never wrong)."""
    kept = list(kept or ())
    if inset is None:
        return kept

    def inside(m):
        on, dist = material_distance(part, m.points)
        return bool(on.all() and dist.min() >= inset * part.a - 1e-9)
    return [m for m in kept if m.n_points == 0 or inside(m)]


def _kept_screen(part, family, st, kept):
    """A check that says, for a plan's pins, whether a kept member's probe
    finals (nominal rollouts and box corners) fit in no arc of the tolerance:
    then no set the plan may claim holds that member
    (``FamilyChecker.prescreen`` with ``kept`` as its breakers); None
    without kept members."""
    if not kept:
        return None
    screen = FamilyChecker(part, family, st)
    screen.breakers = list(kept)

    def broken(heights, speeds) -> bool:
        speeds = list(speeds) or [0.0] * len(heights)
        return bool(screen.prescreen(np.atleast_2d(np.asarray(heights, float)),
                                     np.atleast_2d(np.asarray(speeds, float)), st.claims.tolerance_deg)[0])
    return broken


def _holds(part, plans, family, st, progress, kept=()) -> tuple | None:
    """The first of ``plans`` that holds for ``family`` under ``st`` and whose
    certificate finds no fresh member outside its set: ``(plan, check,
    certificate)``, or None. Cheap refutations come first, each exact: a
    member ``kept`` from the search (:func:`kept_members`) that no set can
    hold, then the certificate's fresh members, replayed before the search:
    when their finals do not fit in one arc of the tolerance, no
    worst-member search can make the certificate count none outside
    (``certificate.fresh_fit``). A plan refuted either way is passed over without a
    worst-member search."""
    broken_by_kept = _kept_screen(part, family, st, kept)
    members = None  # the fresh sample, drawn once for every plan
    for labels, heights, speeds in plans:
        if broken_by_kept is not None and broken_by_kept(heights, speeds):
            continue
        members = members or fresh_members(part, family, MIN_FRESH_MEMBERS, st.seed)
        fresh = fresh_finals(part, heights, family, st, speeds=speeds, progress=progress, must_fit=True,
                             members=members)
        if fresh is None:  # the fresh finals fit in no arc of the tolerance
            continue
        check = check_plan_for_family(part, heights, family, st, None, speeds, progress, " ".join(labels))
        if not check["holds"]:
            continue
        cert = family_certificate(part, heights, family, check, st, speeds=speeds, progress=progress,
                                  fresh=fresh)
        if cert["holds"] and cert["claim"]["violations"] == 0:
            return (labels, heights, speeds), check, cert
    return None


def _answer(axis: str, value, unit: str, words: str, found, family) -> dict:
    """The record of one axis's answer, with its certificate on fresh members."""
    (labels, heights, speeds), _, cert = found
    return {"axis": axis, "found": True, "value": value, "unit": unit, "family": family.label,
            "statement": words, "plan": list(labels), "pin_heights_mm": [float(h) for h in heights],
            "pin_speeds": [float(v) for v in speeds], "holds": bool(cert["holds"]),
            "certificate": cert}


def with_inset(spec: FamilySpec, inset: float) -> str:
    """The text of the family ``spec`` with its tripods' inset set to ``inset`` (to 4 digits)."""
    return spec.with_option("tripods", "inset", f"{inset:.4g}").format()


def tripod_inset(spec: FamilySpec) -> float | None:
    """The tripods' inset of the family ``spec`` (None: no tripods item)."""
    tripods = spec.first("tripods")
    return None if tripods is None else float(tripods.option("inset", DEFAULT_INSET))


def largest_inset(part, spec: FamilySpec, lo: float) -> float:
    """The largest tripod inset (share of ``a``) that still has members (the
    search's space and the family's drawn sample), to ``INSET_RESOLUTION``,
    searched above ``lo``."""
    def has_member(f):  # the search's space and the family text's sample both exist
        try:
            member_space(part, with_inset(spec, f))
            parse_support_family(with_inset(spec, f), part)
            return True
        except PinfeedError:
            return False
    hi = lo
    while has_member(hi + 0.05) and hi < 1.0:
        hi += 0.05
    top = hi + 0.05
    while top - hi > INSET_RESOLUTION:
        mid = 0.5 * (hi + top)
        hi, top = (mid, top) if has_member(mid) else (hi, mid)
    return hi


def inset_axis(part, family, plans, st, make_family, progress=None, kept=()) -> dict:
    """The smallest tripod inset for which one of ``plans`` holds (the
    largest sub-family of legs far enough inside the outline)."""
    spec = FamilySpec.parse(family.label)
    inset0 = tripod_inset(spec)
    if inset0 is None:
        return unanswered_axis("inset", "the family has no tripods: no inset to narrow")
    top = largest_inset(part, spec, inset0)
    families = {}

    def holds_at(f):
        key = round(f, 4)
        families[key] = families.get(key) or make_family(with_inset(spec, key))
        return _holds(part, plans, families[key], st, progress, kept_members(part, kept, key))
    value, found = bisect_smallest(holds_at, inset0, top, STEPS)
    if found is None:
        return unanswered_axis("inset", f"no plan tried holds even for tripods at the largest inset with a "
                                   f"member ({top:.3f} a)")
    value = round(value, 4)
    return _answer("inset", value, "a", f"tripods whose legs stay at least {value:.3f} a "
                   f"({value * part.a:.2f} mm) inside the {'material' if part.holes else 'outline'}",
                   found, families[value])


def friction_axis(part, family, plans, st, progress=None, kept=()) -> dict:
    """The widest friction range about the middle of ``st.mu_c`` for which one of ``plans`` holds."""
    if not isinstance(st.mu_c, (tuple, list)):
        return unanswered_axis("friction", f"the friction is one value ({st.mu_c:g}): no range to narrow")
    lo, hi = (float(x) for x in st.mu_c)
    mid, half = 0.5 * (lo + hi), 0.5 * (hi - lo)

    def at(h):  # h: the share of the half-width given up
        w = half * (1.0 - h)
        return (round(mid - w, 4), round(mid + w, 4)) if w > 1e-9 else round(mid, 4)

    def holds_at(h):
        return _holds(part, plans, family, dataclasses.replace(st, mu_c=at(h)), progress, kept)
    value, found = bisect_smallest(holds_at, 0.0, 1.0, STEPS)
    if found is None:
        return unanswered_axis("friction", f"no plan tried holds even at the middle friction {mid:g}")
    mu = at(value)
    text = f"{mu[0]:g}:{mu[1]:g}" if isinstance(mu, tuple) else f"{mu:g}"
    return _answer("friction", text, "", f"a friction range {text} (the family as given)", found, family)


def family_tolerance_axis(part, family, plans, st, progress=None, kept=()) -> dict:
    """The smallest tolerance (deg, on the ladder of
    :func:`~pipeline.planning.core.nearest_axes.ladder_up`) for which one of
    ``plans`` holds for the whole family."""
    top = min(MAX_TOLERANCE, 180.0 / part.symmetry_order())

    def holds_at(t):
        return _holds(part, plans, family, st.with_tolerance(ladder_up(t)), progress, kept)
    value, found = bisect_smallest(holds_at, st.claims.tolerance_deg, top, STEPS)
    if found is None:
        return unanswered_axis("tolerance", f"no plan tried holds for the family within {top:g} deg")
    value = ladder_up(value)
    return _answer("tolerance", value, "deg", f"a tolerance of {value:g} deg (the family as given)", found,
                   family)


def family_moving_axis(family_label: str, moving, moving_yes: dict | None = None) -> dict:
    """What the search's moving-pin stage (``moving``: its record, ``None``
    when it did not run) found for the family ``family_label``:
    ``moving_yes``, the recommended moving-pin plan with its check and
    certificate, when one holds."""
    if moving_yes is not None:
        cert = moving_yes["certificate"]
        return {"axis": "moving pins", "found": True, "holds": bool(cert["holds"]),
                "value": int(sum(1 for v in moving_yes["speeds"] if v)), "unit": "moving pins",
                "statement": f"the same family with {sum(1 for v in moving_yes['speeds'] if v)} moving pin(s)",
                "plan": list(moving_yes["labels"]), "pin_heights_mm": list(moving_yes["heights"]),
                "pin_speeds": list(moving_yes["speeds"]), "family": family_label, "certificate": cert}
    if moving is None:
        return unanswered_axis("moving pins", "not searched: no pin speeds given (planner.dynamic.speeds, --speeds)")
    return unanswered_axis("moving pins", "searched after the fixed pins: no moving-pin plan holds for the "
                                          "family either")


def nearest_yes(part, family, checker: FamilyChecker, depth: int | None, moving, make_family, progress=None,
                moving_yes: dict | None = None) -> dict:
    """Every axis's nearest "yes" for a family no fixed-pin plan holds for (see
    the module docstring); ``depth``: the search's; ``moving``: the
    moving-pin search's record (``None``: it did not run); ``make_family``
    turns family text into the planning family (with its extremes).
    ``moving_yes`` (``labels``, ``heights``, ``speeds``, ``certificate``):
    the moving-pin plan that holds, when the search found one; the other
    axes then start from the fixed-pin plans a worst member broke (the
    answer without a moving pin)."""
    plans = rejected_plans(checker, fixed_only=moving_yes is not None)
    st = checker.settings
    moving_axis = family_moving_axis(family.label, moving, moving_yes)
    if not plans:
        nothing = "no plan passed the sampled verification: nothing to loosen"
        return {"subject": SUBJECT_FAMILY, "plans_tried": [],
                "axes": [unanswered_axis(a, nothing) for a in ("inset", "friction", "tolerance")]
                + [moving_axis, more_pins_axis(depth)]}
    kept = kept_members(part, checker.breakers)
    axes = [inset_axis(part, family, plans, st, make_family, progress, kept),
            friction_axis(part, family, plans, st, progress, kept),
            family_tolerance_axis(part, family, plans, st, progress, kept),
            moving_axis, more_pins_axis(depth)]
    return {"subject": SUBJECT_FAMILY, "plans_tried": [list(p[0]) for p in plans], "steps": STEPS,
            "assumes": "holding is monotone along each axis (bisection)", "axes": axes}
