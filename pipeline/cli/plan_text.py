"""What ``pinfeed plan`` prints: a plan result for people, and its ``--json`` summary.

:func:`print_plan_result` prints the part's stable states, each tight plan
(pins, claimed final sets, verified width, margin) and paper mode's plans;
:func:`plan_json` is the one JSON document of ``plan --json``.
"""
from __future__ import annotations


def _verification_counts(plan) -> dict | None:
    v = plan.get("verification")
    if not v:
        return None
    reasons = {}
    for row in v.get("rows", []):
        for k, n in row.get("reasons", {}).items():
            reasons[k] = reasons.get(k, 0) + n
    return {"trials": v["trials"], "successes": v["successes"], "failures": v["failures"],
            "reasons": reasons}


def _plan_summary(plan, pins=None) -> dict:
    """One plan of ``plan --json``: its pins, its one ``claim`` (None for a
    plan never replayed on held-out trials, e.g. paper mode's), then, named
    for what they are, the carried sets, the selection trials' verdict and
    the held-out replay's counts."""
    heights = plan.get("pin_heights_mm") or [pins[p] for p in plan["pins"]]
    claim = plan.get("claim")
    kind = carried_kind(plan, plan.get("mode") == "tight")
    return {"pins": list(plan["pins"]), "pin_heights_mm": list(heights),
            "claim": claim if isinstance(claim, dict) else None,
            "carried_sets": {"kind": kind, "n_sets": plan.get("n_final_sets"), "sets": plan["final_sets"],
                             "note": CARRIED_NOTE.get(kind, "not the claim")},
            "selection": _selection_counts(plan),
            "verification": _verification_counts(plan)}


def carried_kind(keys: dict, tight: bool = True) -> str:
    """How a plan's carried sets were found, from its stored keys: ``propagated``
    or ``sampled`` (``carried_sets_kind``; in files written before claims were
    records, the string ``claim``), else ``propagated`` for a tight plan and
    ``paper bands`` for paper mode's."""
    older = keys.get("claim")
    return keys.get("carried_sets_kind") or (older if isinstance(older, str) else None) or (
        "propagated" if tight else "paper bands")


CARRIED_NOTE = {
    "propagated": "the tight propagation's sound bound over the perturbation box; not the claim",
    "sampled": "the hull of a sampled replay of the perturbation box; not the claim",
    "paper bands": "the paper's adjusted bands; not the claim",
}


def _selection_counts(plan) -> dict | None:
    """The verdict on the trials that chose the plan, apart from the held-out claim."""
    s = (plan.get("verification") or {}).get("selection")
    if not s:
        return None
    return {key: s.get(key) for key in ("orients", "in_tolerance", "trials", "width_deg")}


def plan_json(result, mode) -> dict:
    """The one JSON document of ``plan --json``: the tight plans per friction and paper mode's."""
    out = {"part": result["part"]["name"], "part_id": result["part"]["id"], "mode": mode,
           "belt_speed": result.get("belt_speed"), "mu_s": result.get("mu_s")}
    tight = result.get("tight")
    if tight:
        first = tight[0]
        out.update(mu_c=first["mu_c"], warning=first["warning"], tolerance_deg=first.get("tolerance_deg"),
                   support_family=(first.get("support_family") or {}).get("label", "uniform"),
                   orients=first.get("orients"), pins_used=first.get("pins_used"),
                   family_certificate=first.get("family_certificate"),
                   nearest_yes=first.get("nearest_yes"), shape_tolerance=first.get("shape_tolerance"),
                   evidence=(first.get("fixed_pin_search") or {}).get("evidence"),
                   recommended=_plan_summary(first["recommended"]) if first["recommended"] else None,
                   plans=[_plan_summary(p) for p in first["plans"]],
                   rejected=[_plan_summary(p) for p in first["rejected"]],
                   frictions=[{"mu_c": t["mu_c"], "warning": t["warning"],
                               "plans": [_plan_summary(p) for p in t["plans"]]} for t in tight])
    if "plans" in result and mode != "tight":
        paper = {"mu_c": result["mu_c"], "plans": [_plan_summary(p, result["pins"]) for p in result["plans"]]}
        if mode == "paper":
            out.update(paper)
        else:
            out["paper"] = paper
    return out


def print_plan_result(result, part, config, mode):
    """A plan result (the dict ``plan_command`` returns), for people."""
    from pipeline.planning import PlannerSettings, as_plan_file, format_arcs, mechanics_label, planner_belt
    result = as_plan_file(result)
    pc = config["planner"]
    search = PlannerSettings.from_config(config).search
    print(f"part {part.id}: model {mechanics_label(search.model, *planner_belt(search))}, depth {search.depth}")
    for k, (theta, y_c) in enumerate(part.stable_states(), start=1):
        print(f"  state {k}: resting on the fence at theta = {theta:.1f} deg, y_c = {y_c:.2f} mm")
    for t in result.tight or ():
        order = t.symmetry_order or part.symmetry_order()
        st = t.stats
        print(f"tight planner, friction {t.friction}: {st['rollouts']} new rollouts in "
              f"{st['seconds']:.0f} s, stored under {config['catalog_dir']}/refine/{part.id}/")
        family = t.support_family
        if family:
            print(f"  for every member of the support family {family['label']} ({len(family['members'])} "
                  f"supports; nominal paths under {', '.join(family['extremes'])})")
        search = t.fixed_pin_search
        if search:
            print(f"  {search['evidence']}")
        cert = t.family_certificate
        if cert:
            from pipeline.planning import family_certificate_line
            print(f"  {family_certificate_line(cert)}")
        if t.warning:
            print(f"  WARNING: {t.warning}")
        shape = t.shape_tolerance
        if shape:
            from pipeline.planning import shape_line
            print(f"  {shape_line(shape)}")
        nearest = t.nearest_yes
        if nearest:
            from pipeline.planning import SUBJECT_FAMILY, SUBJECT_PART, nearest_yes_lines
            for line in nearest_yes_lines(nearest, SUBJECT_FAMILY if family else SUBJECT_PART):
                print(f"  {line}")
        for k, plan in enumerate(t.plans, start=1):
            v = plan.verification
            heights = ", ".join(f"{q} at {y:g} mm" for q, y in zip(plan.pins, plan.pin_heights_mm))
            mark = " (recommended)" if t.recommended is not None and plan == t.recommended else ""
            print(f"  #{k}{mark}: {heights}; margin in d "
                  + (f"{plan.margin:+.3f}" if plan.margin is not None else "n/a (touches nothing)"))
            _print_claim(plan, order, isinstance(t.mu_c, (tuple, list)))
    if mode == "tight" or result.plans is None:
        return
    print(f"paper-mode planner (adjusted bands), {result.extra['selection']}:")
    if not result.plans:
        print("  no allowed pin sequence within the depth")
    speeds = result.pin_speeds
    for k, plan in enumerate(result.plans, start=1):
        heights = ", ".join(f"{q} at {result.pins[q]:g} mm" + (f" moving {speeds[q]:+g} v_b" if q in speeds else "")
                            for q in plan.pins)
        print(f"  #{k}: {heights} -> {plan.n_final_sets} final set(s): "
              f"{format_arcs(plan.final_arcs)}; "
              f"margin in d {plan.margin:.3f}")


def sets_text(arcs, order: int) -> str:
    """Final orientation sets for people, one arc per set: on a part with ``order``-fold
    rotational symmetry (``order`` > 1) the copies ``360 / order`` deg apart are one
    set, shown once in [0, 360 / order) and marked ``(xK by symmetry)``."""
    from pipeline.planning import format_arcs, merge_modulo
    if order <= 1 or not arcs:
        return format_arcs(arcs)
    pairs = [(s["start"], s["width"]) if isinstance(s, dict) else tuple(s) for s in arcs]
    return f"{format_arcs(merge_modulo(pairs, order))} (x{order} by symmetry)"


def _print_claim(plan, order: int, mu_range: bool = False) -> None:
    """The plan's one claim (what it promises, how sure, on which trials),
    then, apart and named for what they are, the checks beside it: the
    untruncated replay, the trials that chose the plan and the carried sets;
    then the margin in words (``mu_range``: the friction is a range, drawn
    uniformly). A plan file written before claims were recorded prints its
    held-out verdict instead."""
    from pipeline.planning import margin_text
    v = plan.verification
    c = plan.claim
    kind = plan.carried_sets_kind or carried_kind(plan.extra)
    if c:
        print(f"      claim: {c.statement()}")
        print(f"      its trials: {c.trials_text()}")
        if c.untruncated:
            u = c.untruncated
            print(f"      beside it: untruncated normals ({', '.join(u['not_cut'])} not cut; random draws only, "
                  f"no box corners): {u['in_best_arc']}/{u['trials']} in one arc of {c.tolerance_deg:g} deg, "
                  f"at least {100 * u['share_lower_bound']:.2f} % with {100 * c.confidence:g} % confidence"
                  + (f"; width {u['width_deg']:.1f} deg" if u.get("width_deg") is not None else ""))
    else:
        _print_verdict(plan, mu_range)
    sel = v.selection if v else None
    if sel:
        print(f"      beside it: the selection trials (chose the plan; no claim): {sel['in_tolerance']}/"
              f"{sel['trials']} in one set" + (f", width {sel['width_deg']:.1f} deg"
                                                if sel.get("width_deg") is not None else ""))
    what = "a sound bound over the perturbation box" if kind == "propagated" else "the hull of a sampled replay"
    hits = f"; {v.successes}/{v.trials} held-out trials in them" if v else ""
    print(f"      beside it: carried sets ({what}, not the claim): {sets_text(plan.final_arcs, order)}{hits}")
    print(f"      {margin_text(plan.margin)}")


def _print_verdict(plan, mu_range: bool = False) -> None:
    """A plan file without a claim record: its held-out verdict, as written then."""
    from pipeline.planning import describe_claim, describe_untruncated, truncation_text
    v = plan.verification
    o = v.orientation if v else None
    if o and "share_lower_bound" in o:
        where = "held-out trials" if v.held_out else "trials"
        sigma = v.truncation_sigma or None
        drawn = "" if sigma is None else f" ({truncation_text(sigma, mu_range)})"
        print(f"      {where}: {describe_claim(o)}{drawn}")
        if v.untruncated:
            print(f"      {describe_untruncated(v.untruncated, sigma)}")
    else:
        print(f"      {_orientation_text(v)}")


def _orientation_text(v) -> str:
    """Verified width next to the claim: how many trials ended in one set within the tolerance."""
    o = v.orientation if v else None
    if not o:
        return f"verified {v.successes}/{v.trials} trials in the claimed sets" if v else "not verified"
    width = "n/a" if o["width_deg"] is None else f"{o['width_deg']:.1f} deg"
    verdict = "orients" if o["orients"] else f"{o['sets_within_tolerance']} sets of {o['tolerance_deg']:g} deg"
    return (f"verified width {width} ({verdict}: {o['in_tolerance']}/{v.trials} trials in one set of "
            f"{o['tolerance_deg']:g} deg; {v.successes}/{v.trials} in the claimed sets)")
