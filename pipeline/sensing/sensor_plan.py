"""Planning with a force/torque sensor on the first pin (spec section 7; the
paper's section V.C, Fig. 9 and Table 4).

Where fixed pins leave several final orientation sets, a sensor on the first
pin of the sequence reads the force profile of the passing part; if the
reading tells which initial state arrived, the final set that state reaches
is known, so initial states the sensor tells apart may end in different
sets.

Where the plans come from (one propagation for every planner). The
sensor planner runs no search of its own: it reads the plan stage's stored
result (``RESULTS/plans/NAME.json``, from ``pinfeed plan --out`` or the
workflow) and takes the tight planner's *verified* plans at one friction
(default the first entry, ``planner.mu_c``, the friction of the recommended
plan), in the order the plan stage ranked them. Each stored plan holds, per
initial state, the branches of sets carried by the tight propagation
(:mod:`pipeline.planning.tight.propagate`) ending in that state's final arcs, and those arcs
have passed the verify stage's full rollouts; rejected plans are never
candidates. We chose the stored plans over a new search
(:mod:`pipeline.planning.tight.complete`) so that the sensor plan is one of
the plans the user was shown and verified. The price: a plan the plan stage
ranked below its stored ``keep`` best (for instance one pin that leaves each
state in its own set while a two-set plan exists) is not seen; a wider search
would need its own verification and is not done.

Ranking. Candidates are the stored plans whose first pin is fixed (the
sensor sits on it). For every candidate first pin the sensor's groups
(initial states it cannot tell apart, from the synthetic score table of
:func:`pipeline.sensing.profiles.score_table`) are computed once. A plan is ranked by
the worst number of final sets over the groups (each group's states, all
their branches, must end in one set for the reading to say the final
orientation; sets are counted modulo the part's rotational symmetry, as the
planner counts them), then by its number of moving pins (the sensor is the
paper's alternative to moving pins: fixed pins and a sensor beat moving pins
that reach no fewer sets), then by its stored rank (the plan stage's order:
fewest sets, verified success, fewest pins, jump steps, margin in d, set
width). The sensor's accuracy at the first pin is reported, not ranked.

Where a stored plan of fixed pins already ends in one set, the sensor is not
needed for the orientation (``sensor_needed`` false): the first such plan is
the sensor plan (nothing can rank above it), and the score table at its
first pin is still computed and reported, since users read the sensor to
tell which resting state arrived. ``sensor_needed`` is true where the chosen
plan alone leaves several sets and only the verdict says which results.

Friction, resolved once by :func:`sensing_frictions`: ``mu_c`` is the stored
entry's friction as planned (a value or a range ``[lo, hi]``); the simulated
reference profiles need one value, ``mu_c_profiles`` (the range's middle,
:func:`pipeline.planning.nominal_friction`). Synthetic measurements and the
end-to-end check draw the friction as the verify stage does (a range:
uniformly over it).

The result says, for each sensor verdict (group), which final orientation
set(s) result, and for every synthetic trial whether the verdict's
candidates name one final set and whether it is the true state's; the
chosen plan is then checked end to end by perturbed full rollouts with the
sensor reading the first pin (:func:`verify_sensor_plan`).
"""
from __future__ import annotations

from pathlib import Path

from pipeline.errors import PinfeedError
from pipeline.parts.contact import contact_parameter
from pipeline.planning import arc_within, merge_arcs, merge_modulo
from pipeline.planning import predicted_sets
from pipeline.sensing.profiles import PERTURB_DEFAULTS, Sensor, score_table


def sensing_frictions(entry: dict):
    """``(planned, profiles)``: the entry's friction as planned (a value or a
    tuple ``(lo, hi)``) and the one value the simulated profiles use."""
    from pipeline.planning import nominal_friction
    mu = entry["mu_c"]
    planned = (float(mu[0]), float(mu[1])) if isinstance(mu, (list, tuple)) else float(mu)
    return planned, nominal_friction(planned)


def group_arcs(plan: dict, labels) -> list[tuple[float, float]]:
    """Merged final orientation sets of the given initial states (all their branches)."""
    return merge_arcs([arc for lab in labels for arc in predicted_sets(plan, lab)])


def count_sets(arcs, order: int) -> int:
    """Number of physical orientations among ``arcs`` (modulo ``order``-fold symmetry)."""
    return len(merge_modulo(arcs, order))


def _arcs_dict(arcs):
    return [{"start": float(s), "width": float(w)} for s, w in arcs]


def _within(inner, sets) -> bool:
    """Every arc of ``inner`` lies inside one of ``sets`` (all circular, degrees)."""
    for s, w in inner:
        if not any(arc_within((s, w), outer) for outer in sets):
            return False
    return True


def worst_sets(plan: dict, groups, order: int = 1) -> int:
    """The largest number of final sets any sensor verdict (group) leaves."""
    return max(count_sets(group_arcs(plan, g), order) for g in groups)


def moving_pins(plan: dict) -> int:
    """Number of moving pins in a stored plan."""
    return sum(1 for v in plan["pin_speeds"] if v)


def sensor_rank_key(plan: dict, stored_rank: int, groups, order: int = 1):
    """Rank of a stored plan with the sensor: worst sets per verdict, then fewest
    moving pins, then its stored rank."""
    return (worst_sets(plan, groups, order), moving_pins(plan), stored_rank)


def verdict_outcome(candidates, truth, finals: dict, order: int = 1) -> str:
    """``known`` (the candidates end in one set, the true state's), ``wrong``
    (one set, not the true state's) or ``ambiguous`` (several sets)."""
    sets = merge_arcs([a for c in candidates for a in finals[c]])
    if count_sets(sets, order) != 1:
        return "ambiguous"
    return "known" if _within(finals[truth], sets) else "wrong"


def plan_with_sensor(part, entry: dict, pin_radius: float, model: str, sensor: Sensor,
                     trials: int = 30, perturb: dict | None = None, seed: int = 1,
                     apart_fraction: float = 0.9, max_first_pins: int | None = None,
                     log=print) -> dict:
    """The best sensor plan among the stored tight plans of one friction entry
    (``entry``: an element of a stored plan result's ``tight`` list); see the
    module docstring."""
    out, candidates = _entry_header(entry)
    if not candidates:
        why = entry.get("warning") or "no verified plan starts with a fixed pin"
        return dict(out, note=f"no stored verified plan to put the sensor on: {why}")
    order, states = out["symmetry_order"], out["initial_states"]
    stored = entry["plans"]
    fixed = [(rank, p) for rank, p in candidates if not moving_pins(p)]
    candidates, evaluated = _first_pins(candidates, fixed, max_first_pins)
    planned, _ = sensing_frictions(entry)
    tables = {}
    for pin, y_pin in evaluated:
        tables[pin] = score_table(part, states, y_pin, out["mu_c_profiles"], pin_radius, model, sensor,
                                  trials=trials, perturb=perturb, seed=seed,
                                  apart_fraction=apart_fraction, measured_mu=planned)
        log(f"first pin {pin} ({y_pin:g} mm): groups {tables[pin]['groups']}, "
            f"accuracy {tables[pin]['accuracy']:.2f}, wrong {tables[pin]['wrong']:.2f}")
    ranked = sorted((sensor_rank_key(p, rank, tables[p["pins"][0]]["groups"], order), rank, p)
                    for rank, p in candidates if p["pins"][0] in tables)
    best_key, best_rank, best = ranked[0]
    per_pin = {}
    for key, _, p in ranked:
        per_pin.setdefault(p["pins"][0], key)
    return dict(
        out,
        **_best_plan_fields(best, best_key, best_rank, tables[best["pins"][0]], list(states), order, trials),
        first_pins=[{"pin": q, "y_pin": y, "groups": tables[q]["groups"],
                     "accuracy": tables[q]["accuracy"], "wrong": tables[q]["wrong"],
                     "worst_sets": per_pin[q][0] if q in per_pin else None,
                     "best_stored_rank": per_pin[q][2] + 1 if q in per_pin else None}
                    for q, y in evaluated],
        without_sensor=_summary(stored[0]),
        best_fixed_pins=_summary(fixed[0][1]) if fixed else None,
    )


def _entry_header(entry: dict):
    """``(out, candidates)``: the fields every sensor plan result starts with, and
    the stored plans (``(rank, plan)``) whose first pin is fixed (a sensor can sit there)."""
    planned, mu_profiles = sensing_frictions(entry)
    order = int(entry.get("symmetry_order", 1))
    states = {k: {"theta": float(s["theta"]), "y_c": float(s["y_c"])}
              for k, s in entry["initial_states"].items()}
    candidates = [(rank, p) for rank, p in enumerate(entry["plans"]) if not p["pin_speeds"][0]]
    out = {"friction": entry["friction"], "mu_c": list(planned) if isinstance(planned, tuple) else planned,
           "mu_c_profiles": mu_profiles, "symmetry_order": order, "initial_states": states,
           "depth": entry["depth"], "n_candidates": len(candidates), "found": bool(candidates)}
    return out, candidates


def _first_pins(candidates, fixed, max_first_pins):
    """``(candidates, evaluated)``: the plans still in the running (only the best
    fixed-pin plan if one ends in one set: nothing ranks above it) and the first
    pins ``(label, height)`` to score, by the stored rank of their best plan,
    at most ``max_first_pins`` of them."""
    one_set = [(rank, p) for rank, p in fixed if p["n_final_sets"] == 1]
    if one_set:
        candidates = one_set[:1]
    order_of_pins = []
    for _, p in candidates:
        if (p["pins"][0], p["pin_heights_mm"][0]) not in order_of_pins:
            order_of_pins.append((p["pins"][0], p["pin_heights_mm"][0]))
    evaluated = order_of_pins if max_first_pins is None else order_of_pins[:max(1, int(max_first_pins))]
    return candidates, evaluated


def _best_plan_fields(best, best_key, best_rank, table, labels, order, trials) -> dict:
    """The result's fields about the chosen plan ``best`` and its first pin's score ``table``:
    the verdict groups and their final sets, each state's, and how often a verdict
    leaves the final orientation known, wrong or ambiguous."""
    sensor_needed = best["n_final_sets"] > 1
    finals = {lab: predicted_sets(best, lab) for lab in labels}
    groups = []
    for g in table["groups"]:
        arcs = group_arcs(best, g)
        groups.append({"states": g, "final_sets": _arcs_dict(arcs), "known": count_sets(arcs, order) == 1})
    counts = {lab: {"known": 0, "wrong": 0, "ambiguous": 0} for lab in labels}
    for v in table["verdicts"]:
        counts[v["truth"]][verdict_outcome(v["candidates"], v["truth"], finals, order)] += 1
    n = max(1, trials)
    summary = {k: table[k] for k in ("labels", "mean_scores", "elements", "accuracy", "wrong",
                                     "told_apart", "groups", "trials", "perturb", "seed",
                                     "apart_fraction", "reference_signs")}
    if sensor_needed:
        note = (f"the plan alone ends in {best['n_final_sets']} sets; the sensor's verdict says which "
                f"results (worst {best_key[0]} per verdict)")
    else:
        note = ("the plan ends in one set: the sensor is not needed for the final orientation "
                "(its verdict still tells which resting state arrived)")
    return dict(
        sensor_needed=sensor_needed, note=note,
        first_pin=best["pins"][0], y_pin=float(best["pin_heights_mm"][0]),
        plan=best, plan_rank=best_rank + 1,
        worst_sets=best_key[0],
        known_for_every_state=best_key[0] == 1,
        groups=groups,
        states={lab: {"group": next(k for k, g in enumerate(table["groups"]) if lab in g),
                      "final_sets": _arcs_dict(finals[lab])} for lab in labels},
        score_table=summary,
        final_outcomes={lab: {k: c / n for k, c in cnt.items()} for lab, cnt in counts.items()},
    )


def _summary(plan: dict) -> dict:
    return {"pins": list(plan["pins"]), "pin_heights_mm": list(plan["pin_heights_mm"]),
            "moving_pins": moving_pins(plan), "n_final_sets": plan["n_final_sets"],
            "final_sets": plan["final_sets"]}


def verify_sensor_plan(part, result: dict, pin_radius: float, model: str, sensor: Sensor,
                       settings: dict | None = None, kernel: dict | None = None) -> dict:
    """End-to-end check by perturbed full rollouts (as :mod:`pipeline.planning.claims.verify`): each
    trial perturbs theta_i, y_c, mu_c (a range: uniformly over it) and every
    pin position, rolls the part past the first pin while the sensor reads it
    (bias and noise added), classifies the reading against the stored
    reference sign matrices, takes the final set(s) the verdict names, rolls
    on past the other pins (heights ``pin_heights_mm``, moving pins at their
    ``pin_speeds``) and compares the final orientation. Per initial state:
    ``right`` (one set named, counted modulo the part's symmetry, and the part
    ends in it), ``wrong`` (one set named, the part ends elsewhere),
    ``ambiguous`` (the verdict names several sets), ``jammed``. Random trials
    only (``trials`` per state at the verify stage's perturbation sizes): the
    box's corners are not replayed here (``corners`` is stored as false)."""
    import numpy as np

    from pipeline.maps.simulate import rollout
    from pipeline.planning import VERIFY_DEFAULTS, Perturbation, perturbed_inputs
    from pipeline.progress import progress
    from pipeline.sensing.profiles import classify, measure, profile_from_rollout, sign_matrix
    cfg = dict(VERIFY_DEFAULTS, **(settings or {}))
    cfg["corners"] = False
    sizes = Perturbation.from_section(cfg)
    kernel = {k: v for k, v in (kernel or {}).items() if k in ("ds_max", "tol")}
    rng = np.random.default_rng(cfg["seed"])
    refs = {k: np.asarray(v) for k, v in result["score_table"]["reference_signs"].items()}
    plan = result["plan"]
    heights, speeds = plan["pin_heights_mm"], plan["pin_speeds"]
    order = int(result.get("symmetry_order", 1))
    mu_c = tuple(result["mu_c"]) if isinstance(result["mu_c"], list) else result["mu_c"]
    rows = {}
    states = result["initial_states"]
    for label, st in progress(states.items(), len(states), "verify sensor plan", unit="initial state"):
        row = {"trials": 0, "right": 0, "wrong": 0, "ambiguous": 0, "jammed": 0}
        for _ in range(int(cfg["trials"])):
            theta, y_c, mu, offsets = perturbed_inputs(st["theta"], st["y_c"], mu_c, len(heights), sizes, rng)
            row["trials"] += 1
            claimed, jammed = None, False
            for k, (y_pin, v_pin, off) in enumerate(zip(heights, speeds, offsets)):
                r = rollout(part, theta, contact_parameter(y_pin + off, y_c, part.a), mu, pin_radius, model=model,
                            v_pin=float(v_pin), trajectory=k == 0, **kernel)
                if str(r.status.item()) == "jammed":
                    jammed = True
                    break
                if k == 0:
                    prof = profile_from_rollout(r.force_s.values, r.force_x.values, r.force_y.values,
                                                sensor)
                    v = classify(sign_matrix(measure(prof, sensor, rng), sensor), refs, sensor.margin)
                    claimed = [(s["start"], s["width"]) for s in final_for_verdict(result, v["candidates"])]
                theta, y_c = float(r.theta_f), y_c + float(r.dy)
            if jammed:
                row["jammed"] += 1
            elif count_sets(claimed, order) != 1:
                row["ambiguous"] += 1
            elif _within([(theta % 360.0, 0.0)], claimed):
                row["right"] += 1
            else:
                row["wrong"] += 1
        rows[label] = row
    return {"settings": cfg, "rows": rows}


def sense_part(plan_path, config: dict, log=print, friction=None) -> dict:
    """The sensing stage for one planned part, from its stored plan result
    (``plan_path``, ``RESULTS/plans/NAME.json``): the sensor plan among the
    stored tight plans at ``friction`` (default the first planned), the score
    table at its first pin, the per-verdict final sets and their end-to-end
    check, with provenance."""
    from pipeline.parts.part import Part
    from pipeline.planning import tight_entry
    from pipeline.planning import load_plan
    from pipeline.provenance import provenance_attrs
    sc, sweep = config["sensing"], config["sweep"]
    stored = load_plan(plan_path)
    entry = tight_entry(stored, friction)
    part = Part.from_dict(stored.part, name=stored.name)
    model = stored.model if stored.model is not None else config["planner"]["model"]
    sensor = Sensor.from_config(sc["sensor"])
    res = plan_with_sensor(part, entry.to_dict(), sweep["pin_radius"], model, sensor, trials=sc["trials"],
                           perturb=dict(PERTURB_DEFAULTS, **sc["perturb"]), seed=sc["seed"],
                           apart_fraction=sc["apart_fraction"], max_first_pins=sc["max_first_pins"],
                           log=log)
    out = {"part": part.to_dict(), "model": model, "pin_radius": sweep["pin_radius"],
           "plan_file": str(plan_path), "plan_created": stored.extra.get("created"),
           "sensor": sensor.to_dict(), **res}
    if res["found"]:
        out["verification"] = verify_sensor_plan(part, out, sweep["pin_radius"], model, sensor,
                                                 dict(config.get("verify", {}), trials=sc["trials"]),
                                                 kernel=sweep.get("kernel"))
    return dict(out, **provenance_attrs())


_OBJ = {"type": "object"}
_NUM = {"type": "number"}
_FRICTION = {"anyOf": [_NUM, {"type": "array", "items": _NUM, "minItems": 2, "maxItems": 2}]}
# What ``pinfeed sense classify`` reads of a stored sensing result: checked
# first, so a file of another shape (an older format included) is an error
# naming it, not a traceback.
SENSING_SCHEMA = {
    "type": "object", "required": ["found", "part"],
    "properties": {"found": {"type": "boolean"}, "part": _OBJ},
    "if": {"properties": {"found": {"const": True}}},
    "then": {"required": ["first_pin", "y_pin", "sensor", "mu_c", "mu_c_profiles", "model", "plan",
                          "states", "symmetry_order"],
             "properties": {"first_pin": {"type": "string"}, "y_pin": _NUM, "sensor": _OBJ,
                            "mu_c": _FRICTION, "mu_c_profiles": _NUM, "model": {"type": "string"},
                            "symmetry_order": {"type": "integer", "minimum": 1},
                            "plan": {"type": "object", "required": ["pins", "pin_heights_mm"],
                                     "properties": {"pins": {"type": "array"},
                                                    "pin_heights_mm": {"type": "array"}}},
                            "states": {"type": "object", "additionalProperties": {
                                "type": "object", "required": ["final_sets"]}}}},
}
# A stored plan result is checked against ``pipeline/planning/core/plan.schema.json``
# (``pipeline.planning.core.types.validate_plan_file``).


def read_checked_json(path, schema: dict, what: str) -> dict:
    """A stored result file, checked against ``schema``; a file of the wrong shape
    is a :class:`PinfeedError` that says to delete it and re-run the workflow."""
    from pipeline.checks import schema_problem
    from pipeline.maps.io import read_json
    data = read_json(path)
    problem = schema_problem(data, schema, limit=100)
    if problem is not None:
        raise PinfeedError(f"{path} is not a {what} ({problem}); delete it and "
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


