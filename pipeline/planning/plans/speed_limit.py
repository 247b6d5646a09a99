"""How fast may a plan run? Success rate against belt speed, and the speed limit.

:func:`speed_curve` takes plain inputs: a part, the pin heights of the
sequence, their speed ratios, the initial states, the plan's predicted final
arcs and the friction; :func:`stored_plan_speed` reads them from a stored
plan file (``pinfeed speed`` and the workflow's speed stage). Each trial
perturbs the initial state, the pin heights and mu_c, and replays the
sequence with the dynamic model (``kernels.dynamic``; every trial past one
pin in one parallel batch); a trial succeeds when every passage ends ok or
misses and the final orientation lies in one of the final arcs. The same random draws
are used at every speed (common random numbers), so the curve is not noisy
from speed to speed. The speed limit is the highest speed at which at least
``required`` of the trials succeed, found on the coarse grid and refined by
bisection to ``resolution`` mm/s.
"""
from __future__ import annotations

import math
import time
from dataclasses import replace

import numpy as np

from pipeline.checks import FROUDE_MAX, G_MM_S2, check_belt
from pipeline.errors import PinfeedError
from pipeline.parts.contact import contact_parameter
from pipeline.parts.part import Part
from pipeline.planning.core.arcs import in_arc
from pipeline.planning.core.settings import PlannerSettings, SpeedPerturbation, SpeedSettings
from pipeline.planning.core.types import PlanFile
from pipeline.progress import SILENT, Heartbeat, Stretch, prefixed

DEFAULT_SPEEDS = SpeedSettings().speeds  # the schema's speed grid, mm/s


def _in_arcs(theta_deg, arcs) -> np.ndarray:
    """Whether each orientation (degrees) lies in one of the arcs ``(start, width)``
    (:func:`~pipeline.planning.core.arcs.in_arc`, ends included, no tolerance)."""
    theta_deg = np.asarray(theta_deg, float)
    inside = np.zeros(theta_deg.shape, bool)
    for start, width in arcs:
        inside |= in_arc(theta_deg, start, width, tol=0.0)
    return inside


def _draws(part, pin_heights, states, mu_c, perturb: SpeedPerturbation, trials, seed):
    rng = np.random.default_rng(seed)
    lo, hi = (mu_c, mu_c) if np.isscalar(mu_c) else (float(mu_c[0]), float(mu_c[1]))
    out = []
    for theta, y_c in states:
        n = int(trials)
        th = theta + rng.uniform(-1, 1, n) * perturb.theta_deg
        yc = y_c + rng.uniform(-1, 1, n) * perturb.y_mm
        mu = rng.uniform(lo, hi, n)
        pins = np.asarray(pin_heights, float)[None, :] + \
            rng.uniform(-1, 1, (n, len(pin_heights))) * perturb.pin_mm
        # The corners of the perturbation box of the initial state.
        corners = [(theta + sa * perturb.theta_deg, y_c + sb * perturb.y_mm)
                   for sa in (-1, 1) for sb in (-1, 1)]
        th = np.concatenate([th, [c[0] for c in corners]])
        yc = np.concatenate([yc, [c[1] for c in corners]])
        mu = np.concatenate([mu, np.full(4, 0.5 * (lo + hi))])
        pins = np.vstack([pins, np.repeat(np.asarray(pin_heights, float)[None, :], 4, axis=0)])
        out.append((th, yc, mu, pins))
    return out


def success_fraction(part: Part, pin_heights, pin_speed_ratios, draws, final_arcs, belt_speed,
                     mu_s=0.5, r_pin=1.0, threads=None, stretch: Stretch = SILENT):
    """Fraction of the drawn trials that end in the final arcs at ``belt_speed``.

    Every trial of every initial state is rolled past pin 1, then the
    survivors past pin 2, and so on, one parallel batch per pin
    (``kernels.points._dyn_rollout_points`` through
    :func:`pipeline.maps.simulate.rollout_points`); a jammed or truncated passage
    fails the trial, a miss leaves the part as it was. ``stretch`` is told
    how far the trials have got, each pin an equal share.
    """
    from kernels.dynamic import JAMMED, TRUNCATED

    from pipeline.maps.simulate import rollout_points
    check_belt(part, belt_speed, mu_s)
    theta = np.concatenate([d[0] for d in draws])
    y_c = np.concatenate([d[1] for d in draws])
    mu = np.concatenate([d[2] for d in draws])
    pins = np.vstack([d[3] for d in draws])
    alive = np.ones(theta.size, bool)
    for k, v_pin in enumerate(pin_speed_ratios):
        idx = np.flatnonzero(alive)
        if idx.size == 0:
            break
        d_k = contact_parameter(pins[idx, k], y_c[idx], part.a)
        res = rollout_points(part, theta[idx], d_k, mu[idx], r_pin, "dynamic", v_pin=float(v_pin),
                             threads=threads, belt_speed=float(belt_speed), mu_s=float(mu_s),
                             stretch=stretch.part(k / len(pin_speed_ratios), (k + 1) / len(pin_speed_ratios)))
        stuck = (res["status"] == JAMMED) | (res["status"] == TRUNCATED)
        alive[idx[stuck]] = False
        theta[idx] = res["theta_f"]
        y_c[idx] = y_c[idx] + res["dy"]
    good = alive & _in_arcs(theta % 360.0, final_arcs)
    return float(good.sum()) / theta.size


def speed_curve(part: Part, pin_heights, pin_speed_ratios, initial_states, final_arcs, mu_c,
                mu_s=0.5, perturb: SpeedPerturbation | None = None, trials=300, speeds=DEFAULT_SPEEDS,
                resolution=5.0, required=0.99, r_pin=1.0, seed=0, progress=None):
    """Success fraction against belt speed and the plan's speed limit.

    Parameters
    ----------
    part : the part (millimetres).
    pin_heights : pin heights across the belt, mm, in passage order.
    pin_speed_ratios : ``v_pin / v_b`` of each pin (0 for fixed pins).
    initial_states : ``(theta_deg, y_c_mm)`` pairs.
    final_arcs : the plan's final set as ``(start_deg, width_deg)`` arcs.
    mu_c : contact friction, a number or a ``(lo, hi)`` range drawn uniformly.
    mu_s : belt friction.
    perturb : half-widths of the uniform perturbations (a
        :class:`~pipeline.planning.core.settings.SpeedPerturbation`; ``None``: its defaults).
    trials : random trials per initial state (plus its four corners).
    speeds : coarse grid of belt speeds, mm/s (capped where the pin would
        throw the part, see ``checks.FROUDE_MAX``).
    progress : takes a line per belt speed tried and, while its trials run,
        how far they have got (default: :func:`pipeline.progress.reporting`'s).

    Returns
    -------
    dict with ``curve`` (rows ``[speed_mm_s, success_fraction]``, sorted),
    ``speed_limit_mm_s`` (``0.0`` if even the slowest speed fails; the
    highest speed tried if none fails), ``trials_per_speed`` and
    ``seconds`` (wall time).
    """
    if len(pin_heights) != len(pin_speed_ratios):
        raise PinfeedError("give one speed ratio per pin")
    if not initial_states or not final_arcs:
        raise PinfeedError("give at least one initial state and one final arc")
    perturb = perturb or SpeedPerturbation()
    v_thrown = math.sqrt(FROUDE_MAX * mu_s * G_MM_S2 * part.a)
    grid = sorted(v for v in speeds if 0 < v <= v_thrown)
    if not grid:
        raise PinfeedError("no belt speed in the grid below the speed at which the part is thrown")
    start_time = time.perf_counter()
    draws = _draws(part, pin_heights, initial_states, mu_c, perturb, trials, seed)
    curve = {}

    n_trials = int(sum(d[0].size for d in draws))

    def frac(v):
        if v not in curve:
            with Heartbeat(f"speed limit: belt at {v:g} mm/s", n_trials, "trial", progress) as beat:
                curve[v] = success_fraction(part, pin_heights, pin_speed_ratios, draws, final_arcs, v,
                                            mu_s, r_pin, stretch=beat.stretch(0, n_trials))
        return curve[v]

    limit = _speed_limit(frac, grid, required, resolution)
    return {"curve": [[v, curve[v]] for v in sorted(curve)], "speed_limit_mm_s": float(limit),
            "trials_per_speed": n_trials,
            "seconds": round(time.perf_counter() - start_time, 2)}


def _speed_limit(frac, grid, required, resolution) -> float:
    """The highest belt speed (mm/s) whose success ``frac(v)`` reaches ``required``.

    Walks the sorted coarse ``grid`` up to the first failing speed, then
    bisects between the last success and it on multiples of ``resolution``;
    ``0.0`` if the slowest speed fails, the highest speed if none fails.
    """
    lo = None
    hi = None
    for v in grid:
        if frac(v) >= required:
            lo = v
        else:
            hi = v
            break
    if lo is None:
        return 0.0
    if hi is None:
        return lo
    while hi - lo > resolution:
        mid = resolution * round(0.5 * (lo + hi) / resolution)
        if mid <= lo or mid >= hi:
            break
        if frac(mid) >= required:
            lo = mid
        else:
            hi = mid
    return lo


def stored_plan_speed(result, settings: PlannerSettings, plan: int = 1, mu_text=None,
                      speed: SpeedSettings | None = None, progress=None, part: Part | None = None) -> dict:
    """The speed curve and speed limit of a stored tight plan (a plan file's
    ``tight`` entry, see :func:`pick_tight_plan`; ``result`` a
    :class:`~pipeline.planning.core.types.PlanFile` or its dict), with the
    verification's perturbation sizes and the pin radius of ``settings`` and
    the speed settings ``speed`` (``None``: ``settings.speed``: belt friction,
    trials per state, speed grid, bisection resolution, required share, seed).

    Returns the JSON of ``pinfeed speed`` and the workflow's speed stage:
    ``part``, ``pin_labels``, ``pin_heights_mm``, ``pin_speeds``,
    ``final_set`` (``start``, ``width`` in degrees), ``mu_c``, ``mu_s``,
    ``required``, ``speed_limit_mm_s``, ``curve`` (rows of speed in mm/s and
    success fraction), ``planned_belt_speed`` (``None``: planned
    quasi-static), ``trials``, ``trials_per_speed``, ``seconds`` and ``method``.
    ``progress`` hears about each belt speed tried (:func:`speed_curve`).
    ``part``: the part in hand (default: made from the file's outline).
    """
    from pipeline.planning.family.certificate import family_assumption
    from pipeline.planning.plans.stored_plan import pick_tight_plan
    from pipeline.planning.core.settings import friction_label
    from pipeline.planning.core.types import as_plan_file
    speed = speed or settings.speed
    mu_s, trials, required, resolution = speed.mu_s, speed.trials, speed.required, speed.resolution
    if not (isinstance(trials, int) and trials >= 1):
        raise PinfeedError(f"trials must be a whole number >= 1, got {trials!r}")
    result = as_plan_file(result)
    chosen, mu_c, entry = pick_tight_plan(result, plan, mu_text)
    part = part if part is not None else Part.from_dict(result.part, name=result.name)
    perturb = SpeedPerturbation.from_verify(settings.verify.perturbation)
    # A tight-only plan file keeps the resting states per friction entry.
    stored_states = entry.initial_states or result.initial_states or {}
    states = [(s.theta, s.y_c) for s in stored_states.values()]
    arcs = chosen.final_arcs
    res = speed_curve(part, chosen.pin_heights_mm, chosen.pin_speeds, states, arcs, mu_c,
                      mu_s=mu_s, perturb=perturb, trials=trials, speeds=speed.speeds,
                      resolution=resolution, required=required,
                      r_pin=settings.search.pin_radius, seed=speed.seed, progress=progress)
    return {"part": part.name, "pin_labels": list(chosen.pins),
            "pin_heights_mm": list(chosen.pin_heights_mm),
            "pin_speeds": list(chosen.pin_speeds),
            "final_set": [{"start": s, "width": w} for s, w in arcs],
            "mu_c": list(mu_c) if isinstance(mu_c, tuple) else mu_c, "friction": friction_label(mu_c),
            "mu_s": float(mu_s), "required": float(required),
            "speed_limit_mm_s": res["speed_limit_mm_s"], "curve": res["curve"],
            "planned_belt_speed": entry.belt_speed, "trials": int(trials),
            "trials_per_speed": res["trials_per_speed"], "seconds": res["seconds"],
            "method": f"dynamic model, {trials} perturbed trials per initial state plus corners "
                      f"at each speed; limit = highest speed with >= {100 * required:g} % in the "
                      f"final set, {resolution:g} mm/s bisection",
            **family_assumption(entry, "speed limit")}


def stored_speed_limit(plan) -> dict | None:
    """The speed limit stored with a tight plan (a :class:`~pipeline.planning.core.plan_records.Plan`
    or its dict; see :func:`attach_speed_limits`), or None."""
    return (plan.get("speed_limit") if isinstance(plan, dict) else plan.speed_limit) or None


def speed_label(record: dict) -> str:
    """``'250 mm/s (30 trials per state)'``: a speed limit with the trials it comes from."""
    return f"{record['speed_limit_mm_s']:g} mm/s ({record['trials']} trials per state)"


def attach_speed_limits(result: PlanFile, settings: PlannerSettings, part: Part | None = None) -> PlanFile:
    """``result`` (the record of what ``pinfeed plan`` and the workflow write)
    with the speed limit of the recommended tight plan and of the first tight
    plan of fixed pins (the one a layout uses) at the first planned friction:
    each such plan gets ``speed_limit``, the :func:`stored_plan_speed` result
    with the speed settings (``settings.speed``, kept under ``settings``), so
    that the report, ``pinfeed speed`` and ``pinfeed layout`` show one figure
    per plan. A plan whose speed limit cannot be computed (a part any grid
    speed would throw) gets none: the speed stage then says why. The belt
    speeds tried go to the progress report of
    :func:`pipeline.progress.reporting`, labelled with the friction and the
    plan's number. ``part``: the part in hand (default: made from the file's
    outline)."""
    if not result.tight or not result.tight[0].plans:
        return result
    entry = result.tight[0]
    plans = list(entry.plans)
    fixed = [k for k, p in enumerate(plans, start=1) if not any(float(v) for v in p.pin_speeds or ())]
    for number in sorted({1, *fixed[:1]}):
        try:
            record = stored_plan_speed(result, settings, plan=number,
                                       progress=prefixed(f"mu_c {entry.friction}: plan {number}"), part=part)
        except PinfeedError:
            continue
        record.pop("seconds", None)  # a timing would make the same plan differ between runs
        plans[number - 1] = replace(plans[number - 1], speed_limit=dict(record, settings=settings.speed.to_json()))
    recommended = entry.recommended
    if recommended is not None and plans[0].speed_limit:
        recommended = replace(recommended, speed_limit=plans[0].speed_limit)
    return replace(result, tight=(replace(entry, plans=tuple(plans), recommended=recommended), *result.tight[1:]))
