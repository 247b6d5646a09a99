"""A measured force profile classified against the stored results
(``pinfeed sense classify``): which initial state arrived and, with a stored
sensor plan that reads this pin, which final orientation results.

The sensor pin is the stored sensor plan's first pin, else the first pin of
the stored recommended tight plan, else that of paper mode's best fixed-pin
plan, else the height given (``y_pin``, which always wins). The friction and
the sensor come from the stored sensor plan, else from the stored plan and the
config (:func:`pipeline.sensing.sensor_plan.sensing_frictions`).
"""
from __future__ import annotations

import math
from pathlib import Path

from pipeline.errors import PinfeedError
from pipeline.maps.catalog import Catalog, entry_part
from pipeline.maps.io import read_json
from pipeline.parts.families import config_part_id
from pipeline.parts.part import Part
from pipeline.planning import PlannerSettings, best_fixed_plan, load_plan, plan_hint, tight_entry
from pipeline.sensing.profiles import Sensor, classify, read_profile_csv, reference_profiles, resample, sign_matrix
from pipeline.sensing.sensor_plan import count_sets, final_for_verdict, sensing_frictions, stored_sensor_plan


def classify_measured(config: dict, part_name: str, profile, root, catalog=None, y_pin=None) -> tuple[dict, dict]:
    """Classify the measured profile (CSV at ``profile``) of part ``part_name``
    against the simulated profiles of its resting states at the sensor pin.
    ``root`` is the results folder of the stored plans and sensor plans,
    ``catalog`` overrides the config's catalog folder. Returns the result (the
    JSON of ``pinfeed sense classify --json``) and what printing it needs
    besides: ``note`` (why no verdict, if so) and ``stored`` (the stored
    sensor plan, or None)."""
    y_pin_given = y_pin
    root = Path(root)  # stored plans and sensor plans
    part, catalog_radius = _part(config, part_name, root, catalog)
    name = part.name
    stored, plan = _stored_plans(root, part)
    y_pin, first_pin, source, entry = _pin(y_pin, stored, plan, root, name)
    if y_pin is None:
        raise PinfeedError(f"no sensor pin for {name}: no stored sensor plan and no recommended plan under "
                           f"{root}; {plan_hint(config['planner']['parts'], name, root)} or give the sensor pin's height with "
                           f"--y-pin MM")
    sensor, mu_planned, mu_profiles, model, pin_radius = _sensing_inputs(config, stored, plan, entry,
                                                                         catalog_radius)
    measured = _measured_profile(profile, sensor)
    states = {f"state {k}": {"theta": float(th), "y_c": float(y)}
              for k, (th, y) in enumerate(part.stable_states(), start=1)}
    refs = {k: sign_matrix(p, sensor) for k, p in
            reference_profiles(part, states, y_pin, mu_profiles, pin_radius, model, sensor).items()}
    signs = sign_matrix(measured, sensor)
    verdict = classify(signs, refs, sensor.margin)
    on_plan = stored is not None and abs(y_pin - float(stored["y_pin"])) < 1e-9
    final = final_for_verdict(stored, verdict["candidates"]) if on_plan else None
    known = None
    if final is not None:  # one physical orientation (modulo the part's symmetry)
        known = count_sets([(f["start"], f["width"]) for f in final], stored["symmetry_order"]) == 1
    result = {"part": name, "part_id": part.id, "profile": str(profile), "y_pin": y_pin,
              "y_pin_source": source, "first_pin": first_pin if y_pin_given is None else None,
              "model": model, "mu_c": mu_planned, "mu_c_profiles": mu_profiles, "pin_radius": pin_radius,
              "sensor": sensor.to_dict(), "samples": int(measured.t.size), "duration": float(measured.t[-1]),
              "elements": int(signs.size), "margin": sensor.margin, "scores": verdict["scores"],
              "best": verdict["best"], "candidates": verdict["candidates"],
              "decided": verdict["decided"], "measured_signs": signs.tolist(),
              "sensor_plan": stored["plan"]["pins"] if on_plan else None,
              "final_sets": final, "final_known": known}
    return result, {"note": verdict.get("note"), "stored": stored}


def _stored_plans(root: Path, part: Part):
    """``(sensor plan, plan result)`` stored under ``root`` for ``part`` (the plan
    result a :class:`~pipeline.planning.core.types.PlanFile`); each None when
    absent, not found, or stored for another outline of that name."""
    stored = stored_sensor_plan(root, part.name)
    if stored is not None and (not stored.get("found") or stored["part"].get("id", part.id) != part.id):
        stored = None  # no sensor plan, or one for another outline of that name
    plan_path = root / "plans" / f"{part.name}.json"
    plan = load_plan(plan_path) if plan_path.is_file() else None
    if plan is not None and plan.part.get("id", part.id) != part.id:
        plan = None
    return stored, plan


def _sensing_inputs(config, stored, plan, entry, catalog_radius):
    """``(sensor, mu_planned, mu_profiles, model, pin_radius)``: the stored sensor
    plan's, else the plan's and the config's. The friction is resolved once
    (``sensor_plan.sensing_frictions``): as planned, and the one value of the
    simulated profiles (a range's middle)."""
    if stored is not None:
        return (Sensor.from_config(stored["sensor"]), stored["mu_c"], float(stored["mu_c_profiles"]),
                stored["model"], float(stored["pin_radius"]))
    sensor = Sensor.from_config(config["sensing"]["sensor"])
    if entry is not None:
        friction = {"mu_c": entry.mu_c}
    elif plan is not None and plan.mu_c is not None:
        friction = {"mu_c": plan.mu_c}
    else:
        friction = {"mu_c": PlannerSettings.from_config(config).friction.value}
    mu_planned, mu_profiles = sensing_frictions(friction)
    mu_planned = list(mu_planned) if isinstance(mu_planned, tuple) else mu_planned
    model = plan.model if plan is not None and plan.model is not None else config["planner"]["model"]
    pin_radius = catalog_radius if catalog_radius is not None else float(config["sweep"]["pin_radius"])
    return sensor, mu_planned, mu_profiles, model, pin_radius


def _measured_profile(profile, sensor: Sensor):
    """The measured profile (CSV at ``profile``) resampled at the sensor rate; a
    profile too short for the sensor's regions is a one-line error."""
    raw = read_profile_csv(profile)
    measured = resample(raw, sensor.rate_hz)
    if measured.t.size < sensor.regions:
        raise PinfeedError(f"{profile}: the profile spans {raw.t[-1] - raw.t[0]:.3g} s, fewer than "
                           f"{sensor.regions} samples at {sensor.rate_hz:g} Hz; give the whole contact")
    return measured


def _part(config, part_name, root, catalog=None):
    """The part to classify for: ``(part, pin_radius or None)`` from the catalog
    (the config's outline wins over older ones stored under the same name),
    else from a stored sensing or plan result of that name under ``root`` (a
    part planned with --vertices has refinement shards only)."""
    try:
        cat = Catalog.open(catalog or config["catalog_dir"])
        wanted = config_part_id(config, part_name)
        if wanted != part_name and not any(e["part_id"] == wanted for e in cat.entries):
            wanted = part_name  # the config's outline is not stored: use what the catalog has
        entry = cat.entries_for(wanted)[0]  # unknown part: says how to list them
        return entry_part(entry), float(entry["pin_radius"])
    except PinfeedError:
        for kind in ("sensing", "plans"):
            path = root / kind / f"{part_name}.json"
            if path.is_file():
                stored = read_json(path)["part"]
                return Part.from_dict(stored), None
        raise


def _pin(y_pin, stored, plan, root, name):
    """``(y_pin, first_pin, source, plan_entry)``: where the sensor sits. The
    stored sensor plan's first pin, else the first pin of the stored recommended
    tight plan (first planned friction), else that of paper mode's best
    fixed-pin plan, else ``y_pin`` (--y-pin, which always wins)."""
    entry = tight_entry(plan) if plan is not None and plan.tight else None
    plan_path = root / "plans" / f"{name}.json"
    if y_pin is not None:
        if not math.isfinite(y_pin):
            raise PinfeedError(f"--y-pin must be a finite height in mm, got {y_pin}")
        return float(y_pin), None, "--y-pin", entry
    if stored is not None:
        return float(stored["y_pin"]), stored["first_pin"], f"sensor plan {root / 'sensing' / (name + '.json')}", entry
    if entry is not None and entry.recommended:
        rec = entry.recommended
        return (float(rec.pin_heights_mm[0]), rec.pins[0],
                f"first pin of the recommended tight plan at mu_c {entry.friction} {plan_path}", entry)
    if plan is not None and plan.pins and best_fixed_plan(plan):
        first_pin = best_fixed_plan(plan).pins[0]  # the sensor sits on a fixed pin
        return (float(plan.pins[first_pin]), first_pin,
                f"first pin of the best fixed-pin plan {plan_path}", entry)
    return None, None, None, entry
