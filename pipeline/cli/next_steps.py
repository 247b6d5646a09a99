"""What ``pinfeed plan`` prints after a plan: where it went and what to run next.

After a plan that orients the part: the ``speed``, ``layout`` and ``animate``
commands that use it (:func:`pipeline.workflow.commands.next_step_hints`).
After one that does not: first what may still orient the part, each only
where it applies (:func:`fallback_steps`): more verification trials, a
force/torque sensor on the first pin, moving pins, a looser ``--tolerance``,
one pin more (``--depth``), a wider or denser pin grid (``--pins``); then the
same three commands, to look at the plan as it is.
"""
from __future__ import annotations

import math
from pathlib import Path

# A looser tolerance is suggested only up to this width (deg) and half the part's
# symmetry period: a set wider than that hardly is one orientation.
LOOSEST_TOLERANCE_DEG = 45.0


def print_next_steps(result, out, config, args, plan_options, stream) -> None:
    """Where the plan went and the commands that follow, on ``stream`` (stderr with
    ``--json``, which keeps stdout one JSON document). ``plan_options`` are the
    ``plan`` parser's option actions (the rerun commands repeat ``args`` with them)."""
    from pipeline.workflow.commands import next_step_hints
    name = result["part"]["name"]
    tight = (result.get("tight") or [None])[0]
    if out is None:
        print(f"not stored: the workflow stores {name}'s plan; give --out FILE.json to keep this one",
              file=stream)
    else:
        print(f"stored the plan at {out}", file=stream)
    orients = tight is None or tight.get("orients")
    if not orients:
        steps = fallback_steps(result, out, config, args, plan_options)
        print(f"this plan does not orient {name} within {tight['tolerance_deg']:g} deg; what may still work:",
              file=stream)
        for why, command in steps:
            print(f"  {why}" + (f":\n      {command}" if command else ""), file=stream)
    if out is None:
        return
    hints = next_step_hints(result, out, config, args.config)
    if hints and (orients or tight.get("plans")):
        if not orients:
            print("or look at the plan as it is (it leaves the part in several orientations):", file=stream)
        print("next: " + "\n      ".join(hints), file=stream)
    elif not hints:
        print("(speed, layout and animate read RESULTS/plans/NAME.json: store it there to use them)",
              file=stream)


def fallback_steps(result, out, config, args, plan_options) -> list[tuple[str, str | None]]:
    """``(why, command or None)`` for each way that may still orient a part the
    plan ``result`` does not orient, only those that apply to the search it ran."""
    tight = result["tight"][0]
    rerun = lambda **changes: rerun_command(args, plan_options, changes)  # noqa: E731
    steps = [_trials_step(tight, args.config), _sensor_step(result, tight, out, config, args.config),
             _moving_step(tight, config, rerun), _tolerance_step(tight, rerun),
             _depth_step(tight, rerun), _grid_step(result, tight, rerun)]
    return [s for s in steps if s]


def _trials_step(tight, config_path):
    """More verification trials, where too few (or a near miss) kept the claim from being made."""
    from pipeline.planning import min_trials
    search = tight.get("fixed_pin_search") or {}
    short = [lv for lv in search.get("levels", ()) if lv.get("too_few_trials")]
    where = f"in {config_path}" if config_path else "in a config file of your own (--config FILE)"
    if short:
        required, confidence = search["required"], search["confidence"]
        return (f"more verification trials: {short[0]['too_few_trials']} trials per plan of "
                f"{short[0]['pins']} pin(s) cannot show {100 * required:g} % at {100 * confidence:g} % "
                f"confidence even with no failure (at least {min_trials(required, confidence)} are "
                f"needed): raise verify.trials {where}, or set verify.rule: point for a quick look", None)
    verdict = _verdict(tight.get("recommended"))
    if verdict.get("point_rule"):
        return (f"more verification trials: the recommended plan is a near miss (its trials clear "
                f"{100 * verdict['required']:g} % but not with {100 * verdict['confidence']:g} % "
                f"confidence): raise verify.trials {where}", None)
    return None


def _sensor_step(result, tight, out, config, config_path):
    """A force/torque sensor on the first pin, where the recommended plan (first pin
    fixed) ends in several sets and each resting state in one of them."""
    from pipeline.workflow.commands import pinfeed_command
    rec = tight.get("recommended")
    verdict = _verdict(rec)
    if not rec or (verdict.get("sets_within_tolerance") or 0) < 2 or len(tight.get("initial_states", {})) < 2:
        return None
    if any(float(v) for v in (rec.get("pin_speeds") or ())[:1]) or not _each_state_in_one_set(rec, tight):
        return None
    name = result["part"]["name"]
    why = (f"a force/torque sensor on the first pin ({rec['pins'][0]} at {rec['pin_heights_mm'][0]:g} mm): "
           f"it tells which resting state arrived, and so which of the {verdict['sets_within_tolerance']} "
           f"sets the part ends in (docs/howto/force-torque-sensor.md)")
    root = _results_root(out, name)
    if out is not None and root is None:
        return (f"{why}; 'pinfeed sense classify' reads RESULTS/plans/{name}.json: store the plan there", None)
    from pipeline.config import results_folder
    results = None if root is None or root == results_folder(config) else root
    if out is None:
        why += "; the workflow's sense stage plans the sensor of the parts in sensing.parts"
    return why, pinfeed_command("sense", "classify", "--part", name, "--profile", "PROFILE.csv",
                                config_path=config_path, results=results)


def _each_state_in_one_set(rec, tight) -> bool:
    """Whether every initial state's branches of ``rec`` end within one arc of the
    tolerance (so that knowing the state tells the final set); true when unknown."""
    from pipeline.planning import narrowest_arc
    order = tight.get("symmetry_order") or 1
    for branches in (rec.get("initial_states") or {}).values():
        ends = [b[-1].get("carried", {}).get("arc") or b[-1]["band"] for b in branches if b]
        points = [x for arc in ends for x in (arc["start"], arc["start"] + arc["width"])]
        arc = narrowest_arc(points, len(points), order) if points else None
        if arc is not None and arc[1] > tight["tolerance_deg"]:
            return False
    return True


def _moving_step(tight, config, rerun):
    """Moving pins, where the search tried fixed pins only."""
    from pipeline.config import load_config
    if tight.get("moving_pin_search") is not None or tight.get("needs_no_pin"):
        return None
    dynamic, default = config["planner"]["dynamic"], load_config(None)["planner"]["dynamic"]
    depth = dynamic.get("depth") or default["depth"] or 1
    speeds = (dynamic.get("speeds") or [v for v in config["sweep"]["v_pin"] if v]
              or default["speeds"] or [-2.0, 2.0])
    return ("moving pins (this search tried fixed pins only)",
            rerun(dynamic_depth=depth, speeds=",".join(f"{float(v):g}" for v in speeds)))


def _tolerance_step(tight, rerun):
    """A looser tolerance, where a verified plan's trials all end in one arc a
    little wider than the tolerance (at most :data:`LOOSEST_TOLERANCE_DEG`)."""
    tolerance = tight["tolerance_deg"]
    cap = min(LOOSEST_TOLERANCE_DEG, 180.0 / (tight.get("symmetry_order") or 1))
    tried = [(v.get("spread_deg"), plan["pins"]) for plan in tight.get("plans") or ()
             for v in [_verdict(plan)]]
    tried += [(b.get("spread_deg"), b["pins"]) for b in (tight.get("fixed_pin_search") or {}).get("best_effort", ())]
    tried = sorted((w, pins) for w, pins in tried if w is not None)
    if not tried or not tolerance < tried[0][0] <= cap:
        return None
    width, pins = tried[0]
    return (f"a looser tolerance (every verified trial of {' '.join(pins)} ends within {width:.1f} deg)",
            rerun(tolerance=math.ceil(width * 2) / 2))


def _depth_step(tight, rerun):
    """One pin more than the search tried (beyond the embedded config's depth, slow)."""
    from pipeline.config import load_config
    depth = int(tight["depth"])
    slow = "; each pin more multiplies the search" if depth >= load_config(None)["planner"]["depth"] else ""
    return f"more pins (this search tried up to {depth}{slow})", rerun(depth=depth + 1)


def _grid_step(result, tight, rerun):
    """A wider or denser grid of candidate pin heights: the grid fitted to the part
    (``planner.pins: auto``), where the search's pins leave part of it out."""
    from pipeline.parts.part import Part
    from pipeline.planning import fitted_pins
    used = sorted(float(y) for y in (tight.get("pins_used") or {}).values())
    fitted = sorted(fitted_pins(Part.from_dict(result["part"])).values())
    if not used or len(fitted) < 2:
        return None
    lo, hi, step = fitted[0], fitted[-1], fitted[1] - fitted[0]
    wider = used[0] > lo + 1e-6 or used[-1] < hi - step - 1e-6
    gaps = [b - a for a, b in zip(used, used[1:])]
    denser = max(gaps, default=math.inf) > step + 1e-6
    if not (wider or denser):
        return None
    what = " and ".join(w for w, yes in (("wider", wider), ("denser", denser)) if yes)
    return (f"a {what} pin grid (this search tried {len(used)} height(s), {used[0]:g} to {used[-1]:g} mm; "
            f"the grid fitted to the part runs {lo:g} to {hi:g} mm every {step:g} mm)",
            rerun(pins=f"{lo:g}:{hi:g}:{step:g}"))


def _verdict(plan) -> dict:
    """The held-out orientation verdict of a stored plan (empty if none)."""
    return ((plan or {}).get("verification") or {}).get("orientation") or {}


def _results_root(out, name):
    """The results folder of a plan stored at ``RESULTS/plans/NAME.json``, else None."""
    if out is None:
        return None
    path = Path(out)
    return path.parent.parent if path.name == f"{name}.json" and path.parent.name == "plans" else None


def rerun_command(args, plan_options, changes: dict) -> str:
    """The ``pinfeed plan`` command of ``args`` with ``changes`` (dest -> value)
    applied: every option given (not at its default) in the parser's order."""
    from pipeline.workflow.commands import pinfeed_command
    words = []
    for action in plan_options:
        value = changes.get(action.dest, getattr(args, action.dest, action.default))
        if value is None or value is False or value == action.default:
            continue
        flag = action.option_strings[-1]
        if value is True:
            words.append(flag)
            continue
        for v in value if isinstance(value, list) else [value]:
            text = f"{v:g}" if isinstance(v, float) else str(v)
            words += [f"{flag}={text}"] if text.startswith("-") else [flag, text]
    return pinfeed_command("plan", *words)
