"""Planning with a force/torque sensor on the first pin (spec section 7; the
paper's section V.C, Fig. 9 and Table 4).

Where fixed pins leave several final orientation sets, a sensor on the first
pin of the sequence reads the force profile of the passing part; if the
reading tells which initial state arrived, the final set that state reaches
is known, so initial states the sensor tells apart may end in different
sets. For every candidate first pin the sensor's groups (initial states it
cannot tell apart, from the synthetic score table of
:func:`pipeline.sensing.score_table`) are computed once; a plan (a pin
sequence from the fixed-pins planner, same for every state) is then ranked
by the worst number of final sets over the groups (each group's states, all
their branches, must end in one set for the reading to say the final
orientation), then as the planner ranks: widest margin in d, fewest pins,
narrowest final sets, and finally the sensor's accuracy at that first pin.

The result says, for each sensor verdict (group), which final orientation
set(s) result, and for every synthetic trial whether the verdict's
candidates name one final set and whether it is the true state's; the
chosen plan is then checked end to end by perturbed full rollouts with the
sensor reading the first pin (:func:`verify_sensor_plan`).
"""
from __future__ import annotations

from pathlib import Path

from .bands import in_arc
from .planner import Plan, Planner, merge_arcs
from .sensing import PERTURB_DEFAULTS, Sensor, score_table

# Keep every plan of the search: the sensor may prefer a plan the static ranking puts low.
ALL_PLANS = 10**9


def final_arcs(plan: Plan, labels) -> list[tuple[float, float]]:
    """Merged final orientation sets of the given initial states (all their branches)."""
    return merge_arcs([branch[-1].arc for lab in labels for branch in plan.branches[lab]])


def _arcs_dict(arcs):
    return [{"start": float(s), "width": float(w)} for s, w in arcs]


def _within(inner, sets) -> bool:
    """Every arc of ``inner`` lies inside one of ``sets`` (all circular, degrees)."""
    for s, w in inner:
        if not any(W >= 360.0 or (in_arc(s, S, W, 1e-6) and (s - S) % 360.0 + w <= W + 1e-6)
                   for S, W in sets):
            return False
    return True


def sensor_rank_key(plan: Plan, groups, accuracy: float = 0.0):
    worst = max(len(final_arcs(plan, g)) for g in groups)
    return (worst, -round(plan.margin, 9), len(plan.pins),
            round(sum(w for _, w in plan.final_sets), 6), -accuracy)


def verdict_outcome(candidates, truth, finals: dict) -> str:
    """``known`` (the candidates end in one set, the true state's), ``wrong``
    (one set, not the true state's) or ``ambiguous`` (several sets)."""
    sets = merge_arcs([a for c in candidates for a in finals[c]])
    if len(sets) != 1:
        return "ambiguous"
    return "known" if _within(finals[truth], sets) else "wrong"


def plan_with_sensor(planner: Planner, depth: int, mu_c: float, pin_radius: float, model: str,
                     sensor: Sensor, trials: int = 30, perturb: dict | None = None, seed: int = 1,
                     apart_fraction: float = 0.9, max_first_pins: int | None = None,
                     log=print) -> dict:
    """The best sensor plan for the planner's part (see the module docstring)."""
    plans = planner.search(depth, keep=ALL_PLANS)
    starts = planner.initial_states()
    labels = list(starts)
    states = {k: {"theta": float(s.arc[0]), "y_c": float(s.y_lo)} for k, s in starts.items()}
    out = {"initial_states": states, "depth": depth, "n_plans": len(plans), "found": bool(plans)}
    if not plans:
        return dict(out, note="no allowed plan within the depth")
    order = []  # first pins by the static rank of their best plan
    for p in plans:
        if p.pins[0] not in order:
            order.append(p.pins[0])
    evaluated = order if max_first_pins is None else order[:max_first_pins]
    tables = {}
    for pin in evaluated:
        tables[pin] = score_table(planner.part, states, planner.pins[pin], mu_c, pin_radius, model,
                                  sensor, trials=trials, perturb=perturb, seed=seed,
                                  apart_fraction=apart_fraction)
        log(f"first pin {pin} ({planner.pins[pin]:g} mm): groups {tables[pin]['groups']}, "
            f"accuracy {tables[pin]['accuracy']:.2f}, wrong {tables[pin]['wrong']:.2f}")
    best, best_key, per_pin = None, None, {}
    for p in plans:
        pin = p.pins[0]
        if pin not in tables:
            continue
        key = sensor_rank_key(p, tables[pin]["groups"], tables[pin]["accuracy"])
        if pin not in per_pin or key < per_pin[pin]:
            per_pin[pin] = key
        if best_key is None or key < best_key:
            best, best_key = p, key
    pin = best.pins[0]
    table = tables[pin]
    finals = {lab: final_arcs(best, [lab]) for lab in labels}
    groups = [{"states": g, "final_sets": _arcs_dict(final_arcs(best, g)),
               "known": len(final_arcs(best, g)) == 1} for g in table["groups"]]
    counts = {lab: {"known": 0, "wrong": 0, "ambiguous": 0} for lab in labels}
    for v in table["verdicts"]:
        counts[v["truth"]][verdict_outcome(v["candidates"], v["truth"], finals)] += 1
    n = max(1, trials)
    summary = {k: table[k] for k in ("labels", "mean_scores", "elements", "accuracy", "wrong",
                                     "told_apart", "groups", "trials", "perturb", "seed",
                                     "apart_fraction", "reference_signs")}
    return dict(
        out,
        first_pin=pin, y_pin=planner.pins[pin],
        plan=best.to_dict(),
        heights=[planner.pins[q] for q in best.pins],
        worst_sets=best_key[0],
        known_for_every_state=best_key[0] == 1,
        groups=groups,
        states={lab: {"group": next(k for k, g in enumerate(table["groups"]) if lab in g),
                      "final_sets": _arcs_dict(finals[lab])} for lab in labels},
        score_table=summary,
        final_outcomes={lab: {k: c / n for k, c in cnt.items()} for lab, cnt in counts.items()},
        first_pins=[{"pin": q, "y_pin": planner.pins[q], "groups": tables[q]["groups"],
                     "accuracy": tables[q]["accuracy"], "wrong": tables[q]["wrong"],
                     "worst_sets": per_pin[q][0] if q in per_pin else None,
                     "margin": -per_pin[q][1] if q in per_pin else None} for q in evaluated],
        static_best={"pins": list(plans[0].pins), "n_final_sets": plans[0].n_sets,
                     "final_sets": _arcs_dict(plans[0].final_sets)},
    )


def verify_sensor_plan(part, result: dict, mu_c: float, pin_radius: float, model: str,
                       sensor: Sensor, settings: dict | None = None) -> dict:
    """End-to-end check by perturbed full rollouts (as :mod:`pipeline.verify`): each
    trial perturbs theta_i, y_c, mu_c and every pin position, rolls the part past
    the first pin while the sensor reads it (bias and noise added), classifies the
    reading against the stored reference sign matrices, takes the final set(s)
    the verdict names, rolls on past the other pins and compares the final
    orientation. Per initial state: ``right`` (one set named and the part ends
    in it), ``wrong`` (one set named, the part ends elsewhere), ``ambiguous``
    (the verdict names several sets), ``jammed``."""
    import numpy as np

    from .progress import progress
    from .sensing import classify, measure, profile_from_rollout, sign_matrix
    from .simulate import rollout
    from .verify import DEFAULTS, perturbed_inputs
    cfg = dict(DEFAULTS, **(settings or {}))
    rng = np.random.default_rng(cfg["seed"])
    refs = {k: np.asarray(v) for k, v in result["score_table"]["reference_signs"].items()}
    plan_pins = result["plan"]["pins"]
    rows = {}
    states = result["initial_states"]
    for label, st in progress(states.items(), len(states), "verify sensor plan", unit="initial state"):
        row = {"trials": 0, "right": 0, "wrong": 0, "ambiguous": 0, "jammed": 0}
        for _ in range(int(cfg["trials"])):
            theta, y_c, mu, offsets = perturbed_inputs(st["theta"], st["y_c"], mu_c, len(plan_pins),
                                                       cfg, rng)
            row["trials"] += 1
            claimed, jammed = None, False
            for k, (pin, off) in enumerate(zip(plan_pins, offsets)):
                r = rollout(part, theta, (result["pins"][pin] + off - y_c) / part.a, mu, pin_radius,
                            model=model, trajectory=k == 0)
                if str(r.status.item()) == "jammed":
                    jammed = True
                    break
                if k == 0:
                    prof = profile_from_rollout(r.force_s.values, r.force_x.values, r.force_y.values,
                                                sensor)
                    v = classify(sign_matrix(measure(prof, sensor, rng), sensor), refs, sensor.margin)
                    claimed = final_for_verdict(result, v["candidates"])
                theta, y_c = float(r.theta_f), y_c + float(r.dy)
            if jammed:
                row["jammed"] += 1
            elif len(claimed) != 1:
                row["ambiguous"] += 1
            elif _within([(theta % 360.0, 0.0)], [(claimed[0]["start"], claimed[0]["width"])]):
                row["right"] += 1
            else:
                row["wrong"] += 1
        rows[label] = row
    return {"settings": cfg, "rows": rows}


def sense_part(cat, name: str, config: dict, log=print) -> dict:
    """The sensing stage for one planned part: score table at the chosen first
    pin, the sensor plan and its per-verdict final sets, with provenance."""
    from .provenance import provenance_attrs
    from .stages import build_planner, paper_depth
    sc = config["sensing"]
    part, planner, mu_used, selection = build_planner(cat, name, config, dynamic=False)
    sensor = Sensor.from_config(sc["sensor"])
    res = plan_with_sensor(planner, paper_depth(config), mu_used, config["sweep"]["pin_radius"],
                           config["planner"]["model"], sensor, trials=sc["trials"],
                           perturb=dict(PERTURB_DEFAULTS, **sc["perturb"]), seed=sc["seed"],
                           apart_fraction=sc["apart_fraction"], max_first_pins=sc["max_first_pins"],
                           log=log)
    out = {"part": part.to_dict(), "model": config["planner"]["model"], "mu_c": mu_used,
           "selection": selection, "pin_radius": config["sweep"]["pin_radius"],
           "pins": planner.pins, "sensor": sensor.to_dict(), **res}
    if res["found"]:
        out["verification"] = verify_sensor_plan(part, out, mu_used, config["sweep"]["pin_radius"],
                                                 config["planner"]["model"], sensor,
                                                 dict(config.get("verify", {}), trials=sc["trials"]))
    return dict(out, **provenance_attrs())


_OBJ = {"type": "object"}
_NUM = {"type": "number"}
# What ``pinfeed sense classify`` reads of a stored sensing result: checked
# first, so a file of another shape is an error naming it, not a traceback.
SENSING_SCHEMA = {
    "type": "object", "required": ["found", "part"],
    "properties": {"found": {"type": "boolean"}, "part": _OBJ},
    "if": {"properties": {"found": {"const": True}}},
    "then": {"required": ["first_pin", "y_pin", "sensor", "mu_c", "model", "plan", "states"],
             "properties": {"first_pin": {"type": "string"}, "y_pin": _NUM, "sensor": _OBJ,
                            "mu_c": _NUM, "model": {"type": "string"},
                            "plan": {"type": "object", "required": ["pins"],
                                     "properties": {"pins": {"type": "array"}}},
                            "states": {"type": "object", "additionalProperties": {
                                "type": "object", "required": ["final_sets"]}}}},
}
PLAN_SCHEMA = {
    "type": "object", "required": ["part", "pins", "plans"],
    "properties": {"part": _OBJ, "pins": _OBJ, "plans": {"type": "array", "items": _OBJ}},
}


def read_checked_json(path, schema: dict, what: str) -> dict:
    """A stored result file, checked against ``schema``; a file of the wrong shape
    is a :class:`PinfeedError` that says to delete it and re-run the workflow."""
    import jsonschema

    from .errors import PinfeedError
    from .stages import read_json
    data = read_json(path)
    err = jsonschema.exceptions.best_match(jsonschema.Draft202012Validator(schema).iter_errors(data))
    if err is not None:
        where = "/".join(str(p) for p in err.absolute_path) or "(top level)"
        raise PinfeedError(f"{path} is not a {what} (at {where}: {err.message[:100]}); delete it and "
                           f"re-run the workflow ('make run')")
    return data


def stored_sensor_plan(root, name: str):
    """The stored sensing result of part ``name`` under results folder ``root``, or None."""
    path = Path(root) / "sensing" / f"{name}.json"
    return read_checked_json(path, SENSING_SCHEMA, "pinfeed sensing result") if path.is_file() else None


def final_for_verdict(sensing: dict, candidates) -> list[dict]:
    """Final orientation sets that result when the verdict's candidates are ``candidates``."""
    arcs = [(s["start"], s["width"]) for c in candidates for s in sensing["states"][c]["final_sets"]]
    return _arcs_dict(merge_arcs(arcs))


def describe_sets(sets) -> str:
    """Final sets for people: ``223.1-232.2 deg, ...`` (see ``bands.format_arcs``)."""
    from .bands import format_arcs
    return format_arcs(sets)
