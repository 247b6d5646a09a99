"""Plans with tight propagation for one part and one friction, verified.

This is what ``pinfeed plan`` and the workflow's plan stage call: it runs the
search (``search.TightPlanner``), replays the best candidates by full
rollouts on held-out trials (``verify.verify_plan`` with
``verify.holdout_settings``: perturbed trials from a seed no screen or
selection drew from, at least as many per initial state as the
verification's, plus every corner of the perturbation box), re-ranks them
with that verdict and recommends the best plan that fails at most
``MAX_FAILURE`` of its trials. A plan that fails more is never recommended:
a warning with the reason is returned instead. Each plan keeps its verdict
on the trials that chose it apart, as ``verification.selection``.

Outcomes computed for the propagation are kept in the catalog under
``refine/PART_ID/MODEL/v_pin=V.h5`` (see :mod:`pipeline.planning.lattice_store`) and
reused by later runs.

With ``planner.belt_speed`` (mm/s) set, the planner plans with the dynamic
model (``kernels.dynamic``) at that belt speed and belt friction
``planner.mu_s``, stores its outcomes apart
(``refine/PART_ID/dynamic/v_pin=V_belt=S_mu_s=M.h5``) and verification
replays with the dynamic model at the same speed.
"""
from __future__ import annotations

import time
from pathlib import Path

from pipeline.errors import PinfeedError
from pipeline.parts.part import Part
from pipeline.planning.arcs import format_arcs
from pipeline.planning.certify import carried_plan
from pipeline.planning.complete import (WIDTH_SLACK_DEG, FixedPinSearch, FixedPlan, FixedSearch,
                                        orientation_rank, robust_order)
from pipeline.planning.family import planning_family
from pipeline.planning.family_certificate import family_certificate
from pipeline.planning.worst_member import FamilyChecker, FamilyCheckSettings
from pipeline.planning.lattice_store import load_lattice, save_lattice
from pipeline.planning.confidence import DEFAULT_CONFIDENCE, check_confidence
from pipeline.planning.orient import (DEFAULT_REQUIRED, DEFAULT_TOLERANCE, check_required, check_rule,
                                      check_tolerance, describe_claim, judge_verification)
from pipeline.planning.propagate import Tolerances, Uncertainty, resting_states
from pipeline.planning.search import TightPlanner
from pipeline.planning.settings import candidate_pins, friction_label, parse_friction
from pipeline.planning.types import Plan, TightEntry, as_plan_file
from pipeline.planning.verify import DEFAULTS as VERIFY_DEFAULTS
from pipeline.planning.verify import holdout_settings, verify_plan
from pipeline.progress import SILENT, Heartbeat


MAX_FAILURE = 0.01  # a recommended plan fails at most this fraction of its trials
MOVING_PREFIXES = 3  # best fixed-pin results (besides none) that moving pins may follow


def planner_belt(config: dict, part: Part | None = None):
    """``(belt_speed, mu_s)`` the planner plans at: ``planner.belt_speed`` (mm/s;
    ``None`` = quasi-static) and ``planner.mu_s`` (default 0.5). With ``part``,
    a bad belt (speed <= 0, mu_s out of range, a part thrown rather than
    pushed) raises a one-line :class:`PinfeedError`."""
    pc = config["planner"]
    speed = pc.get("belt_speed")
    mu_s = pc.get("mu_s")
    mu_s = 0.5 if mu_s is None else mu_s
    if speed is None:
        return None, float(mu_s)
    if part is not None:
        from pipeline.checks import check_belt
        check_belt(part, speed, mu_s)
    return float(speed), float(mu_s)


def mechanics_label(model: str, belt_speed: float | None, mu_s: float) -> str:
    """What the plans were computed with: ``'minpower'`` or ``'dynamic at 150 mm/s, mu_s 0.5'``."""
    return model if belt_speed is None else f"dynamic at {belt_speed:g} mm/s, mu_s {mu_s:g}"


def planner_for(part: Part, config: dict, mu_c, lattices=None, moving: bool = False) -> TightPlanner:
    """A :class:`TightPlanner` with the config's pins, limits, model and sizes
    (and, with ``moving``, every candidate height at every ``planner.dynamic``
    speed as a moving pin, labelled like ``P23v-2``); at ``planner.belt_speed``
    when it is set (:func:`planner_belt`)."""
    pc, sweep = config["planner"], config["sweep"]
    belt_speed, mu_s = planner_belt(config, part)
    static = candidate_pins(part, pc)
    speeds = [float(v) for v in pc.get("dynamic", {}).get("speeds", [])] if moving else []
    moving_pins = {f"{k}v{v:+g}": (y, v) for k, y in static.items() for v in speeds}
    verify_cfg = dict(VERIFY_DEFAULTS, **config.get("verify", {}))
    tol = Tolerances(**pc.get("tolerances", {}))
    return TightPlanner(part, static, pc["d_min"], pc["d_max"], mu_c,
                        sweep["pin_radius"], pc["model"], Uncertainty.from_verify(verify_cfg), tol,
                        moving=moving_pins, lattices=lattices, kernel=sweep.get("kernel"),
                        max_branches=pc.get("max_branches", 4),
                        hard_limits=pc.get("hard_d_limits", False), belt_speed=belt_speed, mu_s=mu_s)


def plan_tight(part: Part, config: dict, mu_c, lattices=None, depth: int | None = None,
               keep: int = 5, progress=None, family=None) -> dict:
    """Search, verify and rank plans for ``part`` at friction ``mu_c`` (a value
    or a range); returns a JSON-ready dict (``plans`` best first, each with
    its ``verification`` and orientation verdict; ``recommended``; ``warning``;
    ``fixed_pin_search``: what the complete search found, or its evidence that
    no fixed-pin plan orients the part; search statistics).

    Fixed pins first, by the complete search (``complete.FixedPinSearch``);
    only when no fixed-pin sequence of up to ``depth`` pins orients the part
    within ``planner.tolerance_deg`` do moving pins follow the best fixed-pin
    prefixes (``planner.dynamic``).

    ``family`` (a :class:`~pipeline.parts.support_family.SupportFamily`, see
    :func:`pipeline.planning.family.planning_family`): the plans must
    orient the part for every member; the search, the carried sets and the
    verification sample its members (``support_family`` in the result).
    ``None``: uniform pressure."""
    depth = int(depth if depth is not None else config["planner"]["depth"])
    family = None if family is None or family.is_uniform else family
    planner = planner_for(part, config, mu_c, lattices)
    checker = family_checker(part, config, mu_c, family, progress)
    fixed = _fixed_search(part, config, mu_c, planner, depth, keep, progress, family, checker)
    verify_cfg = dict(VERIFY_DEFAULTS, **config.get("verify", {}))
    # No pin is the plan with the fewest pins: then nothing is certified or recommended.
    chosen = [] if fixed.needs_no_pin else fixed.plans or fixed.best_effort
    candidates = _carried(planner, chosen, verify_cfg, family, progress)
    selections = [p.selection or p.verdict for p in chosen]
    moving = None if fixed.orients or fixed.needs_no_pin else _moving_planner(part, config, mu_c, planner)
    moving_search = None
    if moving is not None:
        moving_search = _moving_search(part, config, mu_c, moving, chosen, keep, progress, family, checker)
        candidates += _carried(moving, moving_search.plans, verify_cfg, family, progress)
        selections += [p.selection or p.verdict for p in moving_search.plans]
        planner = moving
    states = resting_states(part)
    _verify_candidates(part, config, mu_c, planner, candidates, states, progress, family, selections)
    judge_for_family(candidates, checker)
    candidates = robust_order(candidates, _rank, lambda p: p.verification["orientation"].get("width_deg"),
                              lambda p: p.margin, planner_width_slack(config))
    good = [p for p in candidates if _acceptable(p)]
    result = _tight_result(config, mu_c, depth, keep, planner, candidates, good, states, fixed, moving_search)
    if family is not None:
        result["support_family"] = family.to_dict()
        certify_for_family(result, part, config, mu_c, family, checker, good)
    return result


def _carried(planner, chosen, verify_cfg: dict, family, progress) -> list:
    """The carried sets of each chosen plan (``certify.carried_plan``), telling
    ``progress`` how many are done (and, between the propagation's rollout
    batches, that it is still at it)."""
    out = []
    with Heartbeat("carried sets of the chosen plans", len(chosen), "plan", progress) as beat:
        try:
            for p in chosen:
                for lattice in planner.lattices.values():
                    lattice.stretch = beat.stretch(len(out), len(out))
                out.append(carried_plan(planner, p.labels, p.margin, verify_cfg, family))
                beat.tick(len(out))
        finally:
            for lattice in planner.lattices.values():
                lattice.stretch = SILENT
    return out


def planner_tolerance(config: dict) -> float:
    """``planner.tolerance_deg`` (default 10), checked: the full width a final set may have."""
    return check_tolerance(config["planner"].get("tolerance_deg", DEFAULT_TOLERANCE))


def verify_required(config: dict) -> float:
    """``verify.required`` (default 0.995): the share of trials that must end in the set."""
    return check_required(config.get("verify", {}).get("required", DEFAULT_REQUIRED))


def verify_confidence(config: dict) -> float:
    """``verify.confidence`` (default 0.95): how sure the claim "orients" is."""
    return check_confidence(config.get("verify", {}).get("confidence", DEFAULT_CONFIDENCE))


def verify_rule(config: dict) -> str:
    """``verify.rule`` (default ``bound``): judge by the confidence bound or the share alone."""
    return check_rule(config.get("verify", {}).get("rule", "bound"))


def planner_width_slack(config: dict) -> float:
    """``planner.width_slack_deg`` (default 1): how much wider a plan with a safe
    margin in d may be and still rank before one with a negative margin."""
    slack = float(config["planner"].get("width_slack_deg", WIDTH_SLACK_DEG))
    if not slack >= 0.0:
        raise PinfeedError(f"planner.width_slack_deg must be 0 or more degrees, got {slack!r}")
    return slack


def _pin_search(part, config, mu_c, planner, moving: bool, family=None, checker=None) -> FixedPinSearch:
    """The complete search over the planner's fixed pins (``moving`` False) or
    its moving pins (True), with the config's tolerance, verification and
    kernel settings and the planner's belt."""
    pc, sweep = config["planner"], config["sweep"]
    pins = {k: p for k, p in planner.pins.items() if bool(p.v_pin) == moving}
    search = FixedPinSearch(part, {k: p.y for k, p in pins.items()}, mu_c, planner_tolerance(config),
                          verify_required(config), config.get("verify", {}), sweep["pin_radius"],
                          pc["model"], sweep.get("kernel"), pc["d_min"], pc["d_max"],
                          belt_speed=planner.belt_speed, mu_s=planner.mu_s,
                          speeds={k: p.v_pin for k, p in pins.items()}, family=family,
                          width_slack=planner_width_slack(config))
    search.member_check = checker
    return search


def _fixed_search(part, config, mu_c, planner, depth, keep, progress, family=None,
                  checker=None) -> FixedSearch:
    """The complete fixed-pin search with the planner's pins and the config's settings."""
    search = _pin_search(part, config, mu_c, planner, moving=False, family=family, checker=checker)
    return search.run(depth, candidates=int(config["planner"].get("candidates", 12)), keep=keep,
                      progress=progress)


def _moving_planner(part, config, mu_c, planner):
    """The planner with moving pins, if the config allows them (else ``None``)."""
    dyn = config["planner"].get("dynamic", {})
    if not (dyn.get("depth", 0) and dyn.get("speeds")):
        return None
    return planner_for(part, config, mu_c, planner.lattices, moving=True)


def _moving_search(part, config, mu_c, moving, chosen, keep, progress, family=None,
                   checker=None) -> FixedSearch:
    """Up to ``planner.dynamic.depth`` moving pins after no fixed pin and after
    each of the ``MOVING_PREFIXES`` best fixed-pin results, by the same
    enumeration, screen and judgement as the fixed pins; the orienting plans,
    best first.

    A plan that orients ranks before every plan with more pins
    (:func:`~pipeline.planning.complete.orientation_rank`), so once some
    sequence orients with ``k`` pins a prefix of ``L`` fixed pins is searched
    only up to ``k - L`` moving pins, and not at all when ``L >= k``
    (``skipped`` in the search's record): the plans left out could only rank
    after the one found."""
    pc, dyn = config["planner"], config["planner"]["dynamic"]
    if progress:
        progress(f"mu_c {friction_label(mu_c)}: fixed pins do not orient the part: adding moving pins")
    search = _pin_search(part, config, mu_c, moving, moving=True, family=family, checker=checker)
    depth = int(dyn["depth"])
    total = FixedSearch([], [], depth, planner_tolerance(config), verify_required(config))
    for prefix in [None, *chosen[:MOVING_PREFIXES]]:
        after = list(prefix.labels) if prefix else []
        room = moving_room(total.plans, len(after), depth)
        if room < 1:  # then room = (pins of the shortest plan found) - len(after)
            total.skipped.append({"after": after,
                                  "why": f"a plan of {len(after) + room} pins already orients the part"})
            continue
        res = search.run(room, candidates=int(pc.get("candidates", 12)), keep=keep, progress=progress,
                         prefix=prefix)
        total.plans += res.plans
        total.levels += [dict(lv, after=after) for lv in res.levels]
        total.rollouts += res.rollouts
        total.seconds += res.seconds
    total.plans = sorted(total.plans, key=FixedPlan.rank_key)[:keep]
    return total


def moving_room(found: list, n_prefix: int, depth: int) -> int:
    """How many moving pins to try after a prefix of ``n_prefix`` fixed pins:
    ``depth``, or fewer so that no sequence has more pins than the shortest
    orienting plan of ``found`` (0 or less: none)."""
    fewest = min((len(p.labels) for p in found), default=None)
    return depth if fewest is None else min(depth, fewest - n_prefix)


def _rank(plan) -> tuple:
    v = plan.verification or {}
    return orientation_rank(v.get("orientation"), len(plan.pins), plan.margin, plan.n_dynamic)


def _acceptable(plan) -> bool:
    """May ``plan`` be recommended? It orients the part, or it ends in several
    sets within the tolerance (for a sensor or moving pins to finish) and its
    claimed sets hold all but ``MAX_FAILURE`` of the trials."""
    v = plan.verification
    verdict = v["orientation"]
    if not v.get("family_check", {}).get("holds", True):
        return False  # the family's worst member breaks it
    return verdict["orients"] or v["failures"] <= MAX_FAILURE * v["trials"]


def _verify_candidates(part: Part, config: dict, mu_c, planner, candidates, states, progress,
                       family=None, selections=None) -> None:
    """Replay each candidate by perturbed full rollouts on the held-out trials
    (``verify_plan`` with ``holdout_settings``) and attach the summary as
    ``plan.verification``, with the orientation verdict (``orient.judge``: one
    set within the tolerance, with confidence?) as ``orientation`` and the
    verdict on the trials that chose it (``selections``, in order) as
    ``selection``."""
    pc = config["planner"]
    verify_cfg = holdout_settings(dict(VERIFY_DEFAULTS, **config.get("verify", {})))
    tolerance, required = planner_tolerance(config), verify_required(config)
    confidence, rule = verify_confidence(config), verify_rule(config)
    selections = list(selections or []) + [None] * len(candidates)
    speeds = {label: pin.v_pin for label, pin in planner.pins.items() if pin.v_pin}
    beat = Heartbeat("verifying the chosen plans on held-out trials", len(candidates), "plan", progress).start()
    for k, (plan, selection) in enumerate(zip(candidates, selections)):
        res = verify_plan(part, plan.to_dict(), planner_pin_heights(planner), states, mu_c,
                          config["sweep"]["pin_radius"], pc["model"], verify_cfg, speeds=speeds,
                          kernel=config["sweep"].get("kernel"), belt_speed=planner.belt_speed,
                          mu_s=planner.mu_s, family=family, stretch=beat.stretch(k, k + 1))
        verdict = judge_verification(res, tolerance, planner.order, required, confidence, rule)
        plan.verification = {"held_out": True, "seed": verify_cfg["seed"],
                             "trials": res["trials"], "successes": res["successes"],
                             "failures": res["failures"], "rows": res["rows"], "model": res["model"],
                             **({"belt_speed": res["belt_speed"], "mu_s": res["mu_s"]}
                                if "belt_speed" in res else {}),
                             **({"support_family": res["support_family"]}
                                if "support_family" in res else {}),
                             "orientation": verdict, "selection": selection}
        if progress:
            progress(f"mu_c {friction_label(mu_c)}: verified {' '.join(plan.pins)} on held-out trials: "
                     + describe_claim(verdict))
    beat.finish()


def _no_plan_warning(depth: int, candidates, good, fixed: FixedSearch, tolerance: float,
                     moving: FixedSearch | None = None):
    """Why the recommended plan does not orient the part, or why nothing is
    recommended (None when a plan orients it)."""
    if good and good[0].verification["orientation"]["orients"]:
        return None
    if fixed.needs_no_pin:
        return fixed.evidence()
    why = fixed.evidence()
    if moving is not None:
        why += (f"; nor do up to {moving.depth} moving pins after no fixed pin or after the "
                f"{MOVING_PREFIXES} best fixed-pin results")
    if not candidates:
        return f"{why}; no allowed pin sequence within depth {depth}"
    if not good:
        best = candidates[0]
        return (f"{why}; no plan passed verification: the best, {' '.join(best.pins)} "
                f"({format_arcs(best.final_sets)}), failed {best.verification['failures']} of "
                f"{best.verification['trials']} trials")
    verdict = good[0].verification["orientation"]
    if verdict.get("point_rule"):
        return (f"no plan clears the confidence bound on held-out trials; the best, "
                f"{' '.join(good[0].pins)}, is a near miss: {describe_claim(verdict)}")
    return (f"{why}; the recommended plan ends in {verdict['sets_within_tolerance']} "
            f"sets of at most {tolerance:g} deg: a sensor must tell them apart")


def _tight_result(config: dict, mu_c, depth: int, keep: int, planner, candidates, good, states,
                  fixed: FixedSearch, moving: FixedSearch | None = None) -> dict:
    """The JSON-ready tight-planner entry at one friction (the stored format)."""
    pc = config["planner"]
    recommended = good[0] if good else None
    tolerance = planner_tolerance(config)
    return {
        "mu_c": list(mu_c) if isinstance(mu_c, tuple) else mu_c,
        "friction": friction_label(mu_c),
        "belt_speed": planner.belt_speed, "mu_s": planner.mu_s if planner.belt_speed else None,
        "mechanics": mechanics_label(pc["model"], planner.belt_speed, planner.mu_s),
        "symmetry_order": planner.order,
        "depth": depth, "complete_depth": depth,
        "beam": int(pc.get("dynamic", {}).get("beam", 30)),
        "tolerance_deg": tolerance, "required": verify_required(config),
        "orients": bool(recommended and recommended.verification["orientation"]["orients"])
        or fixed.needs_no_pin,
        "needs_no_pin": fixed.needs_no_pin,
        "plans": [p.to_dict() for p in good[:keep]],
        "rejected": [p.to_dict() for p in candidates if p not in good][:keep],
        "recommended": recommended.to_dict() if recommended else None,
        "warning": _no_plan_warning(depth, candidates, good, fixed, tolerance, moving),
        "fixed_pin_search": fixed.to_dict(),
        "moving_pin_search": None if moving is None else {
            "orients": moving.orients, "depth": moving.depth, "levels": moving.levels,
            "found": [list(p.labels) for p in moving.plans], "skipped": moving.skipped,
            "nominal_rollouts": moving.rollouts,
            "seconds": round(moving.seconds, 2)},
        "pins_used": {label: pin.y for label, pin in planner.pins.items() if pin.v_pin == 0.0},
        "stats": {"transitions": planner.stats.transitions,
                  "rollouts": planner.stats.rollouts + fixed.rollouts + (moving.rollouts if moving else 0),
                  "nominal_rollouts": fixed.rollouts + (moving.rollouts if moving else 0),
                  "joint_states": planner.stats.nodes, "seconds": round(fixed.seconds + planner.stats.seconds, 2),
                  "pruned_branching": planner.stats.pruned_branching,
                  "unresolved": planner.stats.unresolved,
                  "per_level": [lv["sequences"] for lv in fixed.levels]},
        "initial_states": {k: {"theta": t, "y_c": y} for k, (t, y) in states.items()},
        "lattices": planner.lattices,
    }


def planner_pin_heights(planner: TightPlanner) -> dict:
    """Pin label -> pin height across the belt (mm) of ``planner``."""
    return {label: pin.y for label, pin in planner.pins.items()}


def tight_entry(plan_result, friction=None) -> TightEntry:
    """The stored tight-planner entry at ``friction`` (a value, a range or its
    text ``LO:HI``; default the first planned friction, ``planner.mu_c``) of a
    stored plan (a :class:`PlanFile` or its dict), as a :class:`TightEntry`."""
    tight = as_plan_file(plan_result).tight or ()
    if not tight:
        raise PinfeedError("the stored plan has no tight-planner plans; re-plan with 'pinfeed plan' "
                           "(--mode tight or both) or re-run the workflow")
    if friction is None:
        return tight[0]
    want = friction_label(parse_friction(friction))
    found = [t for t in tight if t.friction == want]
    if not found:
        raise PinfeedError(f"no stored plan at mu_c {want}; stored: {', '.join(t.friction for t in tight)}")
    return found[0]


def pick_tight_plan(result, n: int, mu_text) -> tuple:
    """``(plan, mu_c, entry)``: plan ``n`` (1 = recommended, a :class:`Plan`) of
    the stored tight plans at friction ``mu_text`` (default: the first planned
    friction) of a stored plan (a :class:`PlanFile` or its dict), that
    friction (a value or ``(lo, hi)``) and its :class:`TightEntry`."""
    entry = tight_entry(result, mu_text)
    if not entry.plans:
        raise PinfeedError(f"no verified plan at mu_c {entry.friction}: {entry.warning}")
    if not 1 <= n <= len(entry.plans):
        raise PinfeedError(f"--plan must be 1 to {len(entry.plans)}, got {n}")
    return entry.plans[n - 1], entry.mu_c, entry


def best_fixed_plan(plan_result) -> Plan | None:
    """The best plan of fixed pins only in a stored plan (a :class:`PlanFile` or
    its dict; paper mode's ``best_static``, else its first plan without moving
    pins), as a :class:`Plan` (None if none)."""
    result = as_plan_file(plan_result)
    if result.best_static:
        return result.best_static
    return next((p for p in result.plans or () if not p.n_dynamic_pins), None)


def plan_hint(config: dict, name: str, root) -> str:
    """How to make the stored plan of ``name`` under results folder ``root``: the
    workflow plans the config's parts; a part planned from --vertices or
    --outline needs 'pinfeed plan'."""
    if name in config["planner"]["parts"]:
        return "run the workflow ('make run')"
    return f"run 'pinfeed plan --part {name} --out {Path(root) / 'plans' / (name + '.json')}'"


# ---------------------------------------------------------------------- every configured friction


def plan_frictions(config: dict) -> list:
    """The frictions the workflow plans at: ``planner.mu_c`` (a value or a range
    ``LO:HI``; the recommended plan) first, then each of ``planner.frictions``."""
    pc = config["planner"]
    out = [parse_friction(pc["mu_c"])]
    for f in pc.get("frictions", []):
        f = parse_friction(f)
        if f not in out:
            out.append(f)
    return out


def plan_tight_all(part: Part, config: dict, catalog_root, keep: int = 5, progress=None) -> list:
    """Tight plans at every friction of :func:`plan_frictions` (the first is the
    recommended one), at ``planner.belt_speed`` when it is set, for every
    member of ``planner.support_family`` when it is set (its extremes found
    at each friction); the planner's rollouts are stored in the catalog
    (keyed by model, pin speed and belt)."""
    sweep, model = config["sweep"], config["planner"]["model"]
    belt_speed, mu_s = planner_belt(config, part)
    speeds = [0.0] + [float(v) for v in config["planner"].get("dynamic", {}).get("speeds", [])]
    lattices = {v: load_lattice(catalog_root, part, model, v, sweep["pin_radius"], sweep.get("kernel"),
                                belt_speed=belt_speed, mu_s=mu_s)
                for v in speeds}
    out = []
    try:
        for mu_c in plan_frictions(config):
            t0 = time.perf_counter()
            family = planning_family(part, config["planner"].get("support_family") or "uniform", config, mu_c)
            res = plan_tight(part, config, mu_c, lattices=lattices, keep=keep,
                             progress=_labelled(progress, f"mu_c {friction_label(mu_c)}"), family=family)
            res["stats"]["wall_seconds"] = round(time.perf_counter() - t0, 2)  # search, verification and all
            res.pop("lattices")
            out.append(res)
    finally:  # also on Ctrl-C: the rollouts done so far are reused by the next run
        for lattice in lattices.values():
            save_lattice(catalog_root, lattice)
    return out


def _labelled(progress, label: str):
    """``progress`` with each message prefixed by ``label`` (which friction it is
    for), unless the message already starts with it."""
    if progress is None:
        return None
    return lambda message: progress(message if message.startswith(label) else f"{label}: {message}")


# ---------------------------------------------------------------------- support families: the family's edge

def family_checker(part: Part, config: dict, mu_c, family, progress=None) -> FamilyChecker | None:
    """The worst-member check for plans for ``family`` (None without a family),
    with the planner's verification settings and ``planner.worst_member_budget``;
    each search tells ``progress`` how far it has got."""
    if family is None or family.is_uniform:
        return None
    return FamilyChecker(part, family, FamilyCheckSettings.from_config(config, mu_c), progress)


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
        if not check["holds"]:
            plan.verification["orientation"] = dict(plan.verification["orientation"], orients=False,
                                                    broken_by_worst_member=True)


def certify_for_family(result: dict, part: Part, config: dict, mu_c, family, checker, good) -> None:
    """The family certificate of the recommended plan (``family_certificate``
    in ``result`` and in the recommended plan), or, when no plan holds for the
    family, a warning naming the worst member that broke the best one."""
    if checker is None:
        return
    rec = good[0] if good else None
    check = rec and rec.verification.get("family_check")
    if check and check["holds"]:
        cert = family_certificate(part, rec.pin_heights_mm, family, check, checker.settings,
                                  speeds=rec.pin_speeds, progress=checker.progress)
        result["family_certificate"] = cert
        result["recommended"]["family_certificate"] = cert
        return
    broken = [(key, r) for key, r in checker.results.items() if not r["holds"] and r["worst_member"]]
    if broken:
        (labels, heights), record = max(broken, key=lambda kr: kr[1]["verdict"]["in_tolerance"])
        worst = record["worst_member"]
        result["family_certificate"] = None
        # The evidence, kept whole: the best plan it broke, that plan's set, the member.
        result["family_worst_member"] = {"plan": list(labels), "pin_heights_mm": list(heights),
                                         "set_deg": record["set_deg"], **worst}
        result["warning"] = ((result["warning"] + "; ") if result["warning"] else "") + (
            f"no plan of up to {result['depth']} pins holds for the whole family {family.label}: "
            f"{len(broken)} plan(s) that passed the sampled verification are broken by a worst member "
            f"(e.g. {worst['parameters']}, nominal finals {worst['nominal_finals_deg']} deg, "
            f"{worst['outside_deg']:.2f} deg outside the set)")
