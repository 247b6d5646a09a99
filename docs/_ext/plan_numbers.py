"""The numbers the manual states about a plan, read from a plan file.

This is the one place that knows the keys of a plan file (``pinfeed plan
--out``, ``pipeline/planning/core/plan.schema.json``) for the manual's
stored plans (``docs/_ext/stored_plans.py``): ``docs/conf.py`` turns
:func:`numbers` into the substitutions ``{{ stored.NAME.KEY }}``, and the
tests compare pages with it. When the plan file's keys change (the claim or
the final sets renamed), change the readers below and run
``python docs/_ext/stored_plans.py refresh``; no page changes.

Every reader takes the whole plan file (a dict) and looks at its first
``tight`` entry (the stored plans plan one friction or one range).
:func:`numbers` formats them as the pages show them (widths to 0.1 deg,
shares in percent to 0.01).
"""
from __future__ import annotations


# --------------------------------------------------------------------------- readers (the plan file's keys)

def entry(plan: dict) -> dict:
    """The tight planner's entry (the first friction planned)."""
    return plan["tight"][0]


def recommended(plan: dict) -> dict:
    """The recommended plan of that entry."""
    return entry(plan)["recommended"]


def pins(plan: dict) -> list[str]:
    """The recommended plan's pins, in order (``P23v-2``: a moving pin)."""
    return list(recommended(plan)["pins"])


def heights(plan: dict) -> list[float]:
    """Their heights above the fence line, mm."""
    return [float(h) for h in recommended(plan)["pin_heights_mm"]]


def pin_speeds(plan: dict) -> list[float]:
    """Their speeds across the belt (v_pin / v_b; 0: a fixed pin)."""
    speeds = recommended(plan).get("pin_speeds") or [0.0] * len(pins(plan))
    return [float(v) for v in speeds]


def candidate_heights(plan: dict) -> list[float]:
    """The candidate pin heights the planner chose from, lowest first (mm)."""
    return sorted(float(h) for h in entry(plan)["pins_used"].values())


def claim(plan: dict) -> dict:
    """The recommended plan's one claim (``claim`` in the plan file): the arc
    it promises, its counts, its trials and perturbations."""
    return recommended(plan)["claim"]


def claim_arc(plan: dict) -> tuple[float, float]:
    """The arc the plan claims: (start, width) in deg."""
    arc = claim(plan)["arc"]
    return float(arc["start"]), float(arc["width"])


def carried_sets(plan: dict) -> list[tuple[float, float]]:
    """The carried sets after the last pin (a propagated bound or a sampled
    hull; not the claim): (start, width) in deg."""
    return [(float(s["start"]), float(s["width"])) for s in recommended(plan)["final_sets"]]


def verified_set(plan: dict) -> tuple[float, float] | None:
    """The narrowest arc holding the required share of the held-out trials:
    (start, width) in deg, or None."""
    s = verdict(plan).get("set")
    return (float(s["start"]), float(s["width"])) if s else None


def carried_kind(plan: dict) -> str:
    """How the carried sets were found: ``propagated`` or ``sampled``."""
    return recommended(plan).get("carried_sets_kind", "propagated")


def verdict(plan: dict) -> dict:
    """The held-out verdict (its share, lower bound, width and interval)."""
    return recommended(plan)["verification"]["orientation"]


def trials(plan: dict) -> int:
    """The claim's trials (held-out; for a support family, the family check's)."""
    return int(claim(plan)["trials"])


def trials_in_set(plan: dict) -> int:
    """The claim's trials whose finals lie in its arc."""
    return int(claim(plan)["in_arc"])


def width(plan: dict) -> float | None:
    """The claim's width (deg): the narrowest arc holding the required share of its trials."""
    return claim(plan)["width_deg"]


def untruncated(plan: dict) -> dict:
    """The recommended plan's replay on untruncated normals ({} when none)."""
    return recommended(plan)["verification"].get("untruncated") or {}


def tolerance(plan: dict) -> float:
    return float(verdict(plan)["tolerance_deg"])


def resting_states(plan: dict) -> list[tuple[float, float]]:
    """The part's resting states: (theta deg, y_c mm)."""
    states = plan.get("initial_states") or entry(plan)["initial_states"]
    return [(float(s["theta"]), float(s["y_c"])) for s in states.values()]


def evidence(plan: dict) -> str | None:
    """What the fixed-pin search found, in one sentence (None when it kept none)."""
    return (entry(plan).get("fixed_pin_search") or {}).get("evidence")


def fixed_pin_levels(plan: dict) -> list[dict]:
    """The complete search's counts per number of fixed pins (sequences,
    within the tolerance nominally, dropped by a kept family member, replayed
    in full, orienting)."""
    return list((entry(plan).get("fixed_pin_search") or {}).get("levels") or ())


def speed_limit(plan: dict) -> dict:
    """The recommended plan's speed limit as ``pinfeed speed`` stored it ({} when none)."""
    return recommended(plan).get("speed_limit") or {}


def family_certificate(plan: dict) -> dict:
    """The support family's certificate of the recommended plan ({} when none)."""
    return entry(plan).get("family_certificate") or {}


def shape_tolerance(plan: dict) -> dict:
    """The shape tolerance's certificate ({} when none)."""
    return entry(plan).get("shape_tolerance") or {}


def nearest_yes(plan: dict) -> dict:
    """The nearest "yes": axis name -> its answer ({} when none)."""
    return {a["axis"]: a for a in (entry(plan).get("nearest_yes") or {}).get("axes", ())}


# --------------------------------------------------------------------------- as pages show them

def _arc(start: float, w: float) -> str:
    def wrap(x):
        r = round(x % 360.0, 1)
        return 0.0 if r >= 360.0 else r + 0.0
    return f"{wrap(start):.1f}-{wrap(start + w):.1f}"


def _pct(x) -> str:
    return f"{100 * x:.2f}"


def numbers(plan: dict) -> dict[str, str]:
    """Every number a page may quote of a stored plan, formatted: key -> text.
    Only the keys that apply to the plan are present."""
    p, h, v = pins(plan), heights(plan), pin_speeds(plan)
    out = {
        "pins": " ".join(p), "n_pins": str(len(p)),
        "n_fixed": str(sum(1 for s in v if s == 0)), "n_moving": str(sum(1 for s in v if s != 0)),
        "heights": ", ".join(f"{y:g}" for y in h),
        "pins_at": ", ".join(f"{q} at {y:g} mm" for q, y in zip(p, h)),
        "pins_path": " -> ".join(f"{q} at {y:g} mm" for q, y in zip(p, h)),
        "pins_arrow": " -> ".join(p),
        "claim": claim(plan)["statement"], "claim_arc": _arc(*claim_arc(plan)),
        "carried_sets": ", ".join(_arc(s, w) for s, w in carried_sets(plan)),
        "n_carried_sets": str(len(carried_sets(plan))), "carried_kind": carried_kind(plan),
        "sets_of_tolerance": str(verdict(plan)["sets_within_tolerance"]),
        "trials": str(trials(plan)), "trials_in_set": str(trials_in_set(plan)),
        "in_set": f"{trials_in_set(plan)}/{trials(plan)}",
        "share": _pct(claim(plan)["share"]), "share_lower_bound": _pct(claim(plan)["share_lower_bound"]),
        "orients": "orients" if claim(plan)["orients"] else "does not orient",
        "tolerance": f"{tolerance(plan):g}",
        "n_states": str(len(resting_states(plan))),
        "state_thetas": ", ".join(f"{round(t, 1):g}" for t, _ in resting_states(plan)),
        "friction": str(entry(plan)["friction"]),
    }
    if evidence(plan):
        out["evidence"] = evidence(plan)
    if width(plan) is not None:
        out["width"] = f"{width(plan):.1f}"
    if verified_set(plan):
        out["verified_set"] = _arc(*verified_set(plan))
    iv = claim(plan).get("width_interval_deg") or [None, None]
    if None not in iv:
        out["width_interval"] = f"{iv[0]:.1f}-{iv[1]:.1f}"
    margin = recommended(plan).get("margin")
    if margin is not None:
        out["margin"] = f"{margin:+.3f}"
    grid = candidate_heights(plan)
    if len(grid) > 1:
        out["pin_spacing"] = f"{grid[1] - grid[0]:g}"
    u = untruncated(plan)
    if u:
        out.update(untruncated_in_set=f"{u['in_one_set']}/{u['trials']}",
                   untruncated_share_lower_bound=_pct(u["lower_bound"]),
                   untruncated_orients="orients" if u["orients"] else "does not orient")
        if u.get("width_deg") is not None:
            out["untruncated_width"] = f"{u['width_deg']:.1f}"
        uiv = u.get("width_interval_deg") or [None, None]
        if None not in uiv:
            out["untruncated_interval"] = f"{uiv[0]:.1f}-{uiv[1]:.1f}"
    s = speed_limit(plan)
    if s.get("speed_limit_mm_s") is not None:
        out.update(speed_limit=f"{s['speed_limit_mm_s']:.0f}", speed_trials=str(s["trials"]))
    for level in fixed_pin_levels(plan):
        for key in ("sequences", "nominal_within", "broken_by_known_member", "judged", "orienting"):
            out[f"fixed_{level['pins']}_{key}"] = str(level.get(key, 0))
    out.update(_family(plan), **_shape(plan), **_nearest(plan))
    return out


def _family(plan: dict) -> dict:
    cert = family_certificate(plan)
    if not cert:
        return {}
    p, h, v = pins(plan), heights(plan), pin_speeds(plan)
    fixed = [q for q, s in zip(p, v) if s == 0]
    moving = [f"{q} ({y:g} mm, pin speed {s:g})" for q, y, s in zip(p, h, v) if s != 0]
    worst, fresh, claim = cert["worst_member"], cert["fresh"], cert["claim"]
    return {"family": cert["family"], "family_holds": "holds" if cert["holds"] else "does not hold",
            "family_members": str(cert["verification"]["members"]),
            "family_trials": str(cert["verification"]["trials"]),
            "family_worst_inside": f"{-(worst.get('outside_deg') or 0):.2f}",
            "prefix_pins": " ".join(fixed), "moving_pins_described": " and ".join(moving),
            "fresh_members": str(fresh["members"]), "fresh_outside": str(fresh["members_outside"]),
            "fresh_in_set": f"{fresh['in_tolerance']}/{fresh['trials']}",
            "epsilon": _pct(claim["epsilon"]), "beta": f"{claim['beta']:g}"}


def _shape(plan: dict) -> dict:
    shape = shape_tolerance(plan)
    if not shape or not shape.get("certificate"):
        return {}
    cert, claim = shape["certificate"], shape["certificate"]["claim"]
    holds = shape["radius_mm"] == shape["requested_mm"]
    return {"shape_requested": f"{shape['requested_mm']:g}", "shape_radius": f"{shape['radius_mm']:g}",
            "shape_verdict": "holds" if holds else "does not hold",
            "shape_pins": " ".join(pins(plan)), "shape_set": _arc(*cert["set_deg"]),
            "shape_worst_inside": f"{-cert['worst_member']['outside_deg']:.2f}",
            "shape_fresh_outside": str(claim["violations"]), "shape_fresh_members": str(claim["members"]),
            "shape_epsilon": _pct(claim["epsilon"]), "shape_beta": f"{claim['beta']:g}"}


def _nearest(plan: dict) -> dict:
    return {f"nearest_{axis.replace(' ', '_')}": a["statement"] for axis, a in nearest_yes(plan).items()}


# --------------------------------------------------------------------------- a design file (pinfeed design)

def design_plan(design: dict) -> dict:
    """The chosen change's plan, as a plan file the readers above take."""
    return {"tight": design["chosen"]["plan"]}


def design_numbers(design: dict) -> dict[str, str]:
    """The chosen change's plan's numbers (:func:`numbers`) and the change's own:
    ``change`` (its description), ``change_mm`` (its size), ``change_share``
    (the share of the area it changes, %), ``changes_tried``."""
    chosen = design["chosen"]
    size = chosen["legs_mm"][0] if chosen["kind"] == "chamfer" else chosen["width_mm"]
    return {**numbers(design_plan(design)), "change": chosen["description"], "change_mm": f"{size:.1f}",
            "change_share": f"{100 * chosen['share']:.1f}", "changes_tried": str(len(design["tried"]))}
