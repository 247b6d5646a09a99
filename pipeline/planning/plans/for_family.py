"""A plan for a support family: the worst-member check of each orienting
candidate, the recommended plan's certificate, and the nearest "yes" when no
plan holds for the whole family."""
from __future__ import annotations

from dataclasses import replace

from pipeline.parts.part import Part
from pipeline.planning.claims.plan_claim import family_claim
from pipeline.planning.core.settings import PlannerSettings
from pipeline.planning.core.types import TightEntry
from pipeline.planning.family.certificate import family_certificate
from pipeline.planning.family.members import planning_family
from pipeline.planning.family.nearest import nearest_yes
from pipeline.planning.family.worst_member import FamilyChecker, FamilyCheckSettings
from pipeline.planning.tight.records import FixedSearch


def family_checker(part: Part, settings: PlannerSettings, family, progress=None) -> FamilyChecker | None:
    """The worst-member check for plans for ``family`` (None without a family),
    with the planner's verification settings and ``planner.worst_member_budget``;
    each search tells ``progress`` how far it has got."""
    if family is None or family.is_uniform:
        return None
    return FamilyChecker(part, family, FamilyCheckSettings.from_settings(settings), progress)


def judge_for_family(candidates, checker: FamilyChecker | None) -> None:
    """Each candidate that orients on the sampled verification is checked for
    the family's worst member (``worst_member.check_plan_for_family``): the
    record goes into ``verification["family_check"]`` and a plan the worst
    member breaks no longer orients (and cannot be recommended)."""
    if checker is None:
        return
    for plan in candidates:
        if not plan.verification["orientation"]["orients"]:
            continue
        checker(plan.pins, plan.pin_heights_mm, None, plan.pin_speeds)
        check = {k: v for k, v in checker.result(plan.pins, plan.pin_heights_mm).items()
                 if not k.startswith("_")}
        plan.verification["family_check"] = check
        plan.claim = family_claim(plan.claim, checker.family.label, check)
        if not check["holds"]:
            plan.verification["orientation"] = dict(plan.verification["orientation"], orients=False,
                                                    broken_by_worst_member=True)


def certify_for_family(entry: TightEntry, part: Part, settings: PlannerSettings, family, checker,
                       moving: FixedSearch | None = None) -> TightEntry:
    """``entry`` with the family certificate of its recommended plan
    (``family_certificate`` in the entry and in the recommended plan, whose
    claim becomes the family's), or, when no plan holds for the family, a
    warning naming the worst member that broke the best one; then the
    nearest "yes" (``moving``: the moving-pin search's record, if it ran)."""
    if checker is None:
        return entry
    rec = entry.recommended
    check = rec.verification.family_check if rec is not None else None
    moving_yes = None
    if check and check["holds"]:
        cert = family_certificate(part, rec.pin_heights_mm, family, check, checker.settings,
                                  speeds=rec.pin_speeds, progress=checker.progress)
        claim = family_claim(rec.claim, family.label, check, cert)
        entry = replace(entry, family_certificate=cert, recommended=replace(rec, claim=claim, family_certificate=cert),
                        plans=(replace(entry.plans[0], claim=claim), *entry.plans[1:]))
        if not any(rec.pin_speeds or ()):
            return entry
        # A moving-pin plan holds: the nearest "yes" without one is still asked for.
        moving_yes = {"labels": rec.pins, "heights": rec.pin_heights_mm, "speeds": rec.pin_speeds or (),
                      "certificate": cert}
    broken = [(key, r) for key, r in checker.results.items() if not r["holds"] and r["worst_member"]]
    if broken and moving_yes is None:
        entry = _broken_by_worst_member(entry, family, broken)
    nearest = nearest_yes(part, family, checker, entry.depth, moving,
                          lambda text: planning_family(part, text, settings), checker.progress, moving_yes)
    return replace(entry, nearest_yes=nearest)


def _broken_by_worst_member(entry: TightEntry, family, broken: list) -> TightEntry:
    """``entry`` when worst members break the ``broken`` plans: no
    certificate, the best plan broken with its worst member as evidence, and
    a warning that says so."""
    (labels, heights), record = max(broken, key=lambda kr: kr[1]["verdict"]["in_tolerance"])
    worst = record["worst_member"]
    warning = ((entry.warning + "; ") if entry.warning else "") + (
        f"no plan of up to {entry.depth} pins holds for the whole family {family.label}: "
        f"{len(broken)} plan(s) that passed the sampled verification are broken by a worst member "
        f"(e.g. {worst['parameters']}, nominal finals {worst['nominal_finals_deg']} deg, "
        f"{worst['outside_deg']:.2f} deg outside the set)")
    # The evidence, kept whole: the best plan it broke, that plan's set, the member.
    return replace(entry, family_certificate=None, warning=warning,
                   family_worst_member={"plan": list(labels), "pin_heights_mm": list(heights),
                                        "set_deg": record["set_deg"], **worst})
