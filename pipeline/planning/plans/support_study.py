"""The support study: plans against a support family.

:func:`support_study` answers a user's three questions for one
part (spec section 9): how far the family moves ``theta_f`` from uniform
pressure over the configured map grid, whether the recommended (uniform)
plan survives the family, and if it does not, the plan that does.
"""
from __future__ import annotations

import dataclasses

import numpy as np

from pipeline.maps.support_spread import extreme_members, family_spread, spread_numbers
from pipeline.parts.part import Part
from pipeline.parts.support_family import SupportFamily
from pipeline.planning.family.members import as_family, check_family_mechanics
from pipeline.planning.claims.orient import judge_verification
from pipeline.planning.plans.plan import plan_tight
from pipeline.planning.core.resting import resting_states
from pipeline.planning.core.settings import PlannerSettings
from pipeline.planning.claims.verify import verify_plan
from pipeline.progress import Heartbeat


def map_spread(part: Part, family: SupportFamily, settings: PlannerSettings) -> tuple:
    """``(summary, spreads, extremes)``: the family's shift from uniform over the
    configured map grid (sweep ``d`` and ``theta_step``) at every swept
    friction, the :class:`FamilySpread` per friction and the extreme members'
    indices. The summary pools
    the cells of all frictions (``support_spread.spread_numbers``) and names
    the extremes over all of them."""
    theta = np.arange(0.0, 360.0, settings.swept_theta_step)
    spreads = {mu: family_spread(part, family, theta, list(settings.swept_d), mu, settings.search.pin_radius)
               for mu in settings.swept_frictions}
    shifts = np.concatenate([s.flat_shift for s in spreads.values()], axis=1)
    extremes = extreme_members(shifts)
    summary = {"family": family.label, "members": len(family), "frictions": sorted(spreads),
               **spread_numbers(shifts, np.concatenate([s.changed for s in spreads.values()])),
               "extremes": [family.labels[k] for k in extremes]}
    return summary, spreads, extremes


def verify_under_family(part: Part, settings: PlannerSettings, plan: dict, family: SupportFamily,
                        progress=None) -> dict:
    """A stored plan (``to_dict()``) replayed with the verification's trials,
    each on a member of ``family`` at ``settings.friction``; the orientation
    verdict (judged by the required share's confidence bound at its
    default confidence) and the counts.
    ``progress`` hears how far the trials have got."""
    pins = dict(zip(plan["pins"], plan["pin_heights_mm"]))
    speeds = dict(zip(plan["pins"], plan.get("pin_speeds", [0.0] * len(plan["pins"]))))
    states = resting_states(part)
    with Heartbeat(f"trials of {' '.join(plan['pins'])} under {family.label}", len(states), "initial state",
                   progress) as beat:
        res = verify_plan(part, plan, pins, states, settings.friction.value, settings.search.pin_radius,
                          settings.search.model, settings.verify,
                          speeds={k: v for k, v in speeds.items() if v}, kernel=settings.search.kernel_step,
                          family=family, stretch=beat.stretch(0, len(states)))
    verdict = judge_verification(res, settings.claims.tolerance_deg, part.symmetry_order(),
                                 settings.claims.required)
    by_member = {}
    for t in res["trials_detail"]:
        row = by_member.setdefault(t["support"], {"trials": 0, "failures": 0})
        row["trials"] += 1
        row["failures"] += 0 if t["ok"] else 1
    return {"trials": res["trials"], "failures": res["failures"], "orientation": verdict,
            "by_member": by_member}


def support_study(part: Part, settings: PlannerSettings, family, uniform_entry: dict | None,
                  progress=None) -> dict:
    """The support study of ``part``: three numbers (a JSON-ready dict):

    - ``spread``: how far the family moves theta_f from uniform over the
      configured map grid (:func:`map_spread`);
    - ``survival``: the recommended plan of ``uniform_entry`` (the stored
      tight-planner entry at ``settings.friction``) replayed with each trial on a
      member of the family (:func:`verify_under_family`); ``survives`` when it
      still orients the part within the tolerance (a part that needs no pin
      survives: the resting states do not depend on the support);
      ``widening``: its verified width (the narrowest arc holding the
      required share of trials) under uniform pressure and under the family;
    - ``family_plan``: when it does not survive, the fixed-pin plan for the
      family (:func:`~pipeline.planning.plans.plan.plan_tight` with the family and
      no moving pins: moving pins under a family, each candidate checked
      against the worst member, take far longer than a workflow stage
      should; ``pinfeed plan --support-family`` still tries them), each candidate checked against the family's worst
      member (:mod:`pipeline.planning.family.worst_member`).

    The figure's maps come back apart, under ``"_spreads"`` (not JSON)."""
    family = as_family(part, family)
    check_family_mechanics(settings.search)
    summary, spreads, extremes = map_spread(part, family, settings)
    family = dataclasses.replace(family, extremes=extremes)
    rec = (uniform_entry or {}).get("recommended")
    out = {"part": part.name, "family": family.to_dict(), "mu_c": settings.friction.label,
           "tolerance_deg": settings.claims.tolerance_deg, "required": settings.claims.required,
           "spread": summary, "uniform_plan": rec and list(rec["pins"]), "survival": None,
           "survives": None, "family_plan": None, "_spreads": spreads}
    if (uniform_entry or {}).get("needs_no_pin"):
        out["survives"] = True  # the resting states do not depend on where the part presses
        return out
    if rec is not None:
        if progress:
            progress(f"replaying the recommended plan {' '.join(rec['pins'])} under {family.label}")
        out["survival"] = verify_under_family(part, settings, rec, family, progress)
        out["survives"] = bool(out["survival"]["orientation"]["orients"])
        uniform_width = ((rec.get("verification") or {}).get("orientation") or {}).get("width_deg")
        out["widening"] = {"uniform_width_deg": uniform_width,
                           "family_width_deg": out["survival"]["orientation"]["width_deg"]}
    if not out["survives"]:
        if progress:
            progress(f"planning for every member of {family.label}")
        res = plan_tight(part, settings.without_moving_pins(), family=family, progress=progress)
        out["family_plan"] = _family_plan(res)
    return out


def _family_plan(entry) -> dict:
    """What the support study keeps of the planner's ``entry`` for the family
    (a :class:`~pipeline.planning.core.types.TightEntry`): the answer, the
    recommended plan with its verification and claim, the worst member and
    the nearest "yes"."""
    best = entry.recommended
    return {"orients": entry.orients, "warning": entry.warning, "evidence": entry.fixed_pin_search["evidence"],
            "pins": best and list(best.pins), "pin_heights_mm": best and list(best.pin_heights_mm),
            "pin_speeds": best and list(best.pin_speeds),
            "verification": best and best.verification.to_dict(),
            "claim": best and (best.claim.to_dict() if best.claim else None),
            "plans": [p.to_dict() for p in entry.plans],
            "worst_member": entry.family_worst_member or None, "nearest_yes": entry.nearest_yes or None}
