"""How fast may a plan run? Success rate against belt speed, and the speed limit.

Plain inputs only (the planner's plan format is being rewritten): a part, the
pin heights of the sequence, their speed ratios, the initial states, the
plan's predicted final arcs and the friction. Each trial perturbs the initial
state, the pin heights and mu_c, and replays the sequence with the dynamic
model (``kernels.dynamic``); a trial succeeds when every passage ends ok and
the final orientation lies in one of the final arcs. The same random draws
are used at every speed (common random numbers), so the curve is not noisy
from speed to speed. The speed limit is the highest speed at which at least
``required`` of the trials succeed, found on the coarse grid and refined by
bisection to ``resolution`` mm/s.
"""
from __future__ import annotations

import math

import numpy as np

from .errors import PinfeedError
from .parts import Part
from .simulate import FROUDE_MAX, G_MM_S2, check_belt

DEFAULT_SPEEDS = (10.0, 50.0, 100.0, 150.0, 200.0, 300.0, 400.0, 500.0)


def perturbation_from_verify(verify: dict) -> dict:
    """The uniform half-widths of :func:`speed_curve` from a config's ``verify``
    section: orientation +-2 sigma (verification truncates its normal there),
    centroid height and pin position as verified."""
    v = dict(verify or {})
    return {"theta_deg": 2.0 * v.get("theta_sigma", 1.0), "y_mm": v.get("y_halfwidth", 0.5),
            "pin_mm": v.get("pin_halfwidth", 0.3)}


def _in_arcs(theta_deg, arcs):
    for start, width in arcs:
        if (theta_deg - start) % 360.0 <= width:
            return True
    return False


def _draws(part, pin_heights, states, mu_c, perturb, trials, seed):
    rng = np.random.default_rng(seed)
    lo, hi = (mu_c, mu_c) if np.isscalar(mu_c) else (float(mu_c[0]), float(mu_c[1]))
    out = []
    for theta, y_c in states:
        n = int(trials)
        th = theta + rng.uniform(-1, 1, n) * perturb.get("theta_deg", 0.0)
        yc = y_c + rng.uniform(-1, 1, n) * perturb.get("y_mm", 0.0)
        mu = rng.uniform(lo, hi, n)
        pins = np.asarray(pin_heights, float)[None, :] + \
            rng.uniform(-1, 1, (n, len(pin_heights))) * perturb.get("pin_mm", 0.0)
        # The corners of the perturbation box of the initial state.
        corners = [(theta + sa * perturb.get("theta_deg", 0.0), y_c + sb * perturb.get("y_mm", 0.0))
                   for sa in (-1, 1) for sb in (-1, 1)]
        th = np.concatenate([th, [c[0] for c in corners]])
        yc = np.concatenate([yc, [c[1] for c in corners]])
        mu = np.concatenate([mu, np.full(4, 0.5 * (lo + hi))])
        pins = np.vstack([pins, np.repeat(np.asarray(pin_heights, float)[None, :], 4, axis=0)])
        out.append((th, yc, mu, pins))
    return out


def success_fraction(part: Part, pin_heights, pin_speed_ratios, draws, final_arcs, belt_speed,
                     mu_s=0.5, r_pin=1.0):
    """Fraction of the drawn trials that end in the final arcs at ``belt_speed``."""
    from kernels.dynamic import DEFAULT_H, DEFAULT_MAX_STEPS, DEFAULT_V_REG, OK, _dyn_rollout
    fr = check_belt(part, belt_speed, mu_s)
    verts, area, a, quad, _, convex = part.prepared()
    good = total = 0
    for th, yc, mu, pins in draws:
        for i in range(th.size):
            theta, y = math.radians(th[i]), yc[i]
            ok = True
            for k, v_pin in enumerate(pin_speed_ratios):
                res = _dyn_rollout(verts, area, a, quad, convex, float(mu[i]), float(r_pin), theta,
                                   (pins[i, k] - y) / a, float(v_pin), fr, 0.0,
                                   DEFAULT_V_REG / belt_speed, DEFAULT_H, np.inf,
                                   DEFAULT_MAX_STEPS, False)
                if res[0] not in (OK, 1):  # a miss leaves the part as it was
                    ok = False
                    break
                theta, y = res[2], y + res[3]
            good += ok and _in_arcs(math.degrees(theta) % 360.0, final_arcs)
            total += 1
    return good / total


def speed_curve(part: Part, pin_heights, pin_speed_ratios, initial_states, final_arcs, mu_c,
                mu_s=0.5, perturb=None, trials=300, speeds=DEFAULT_SPEEDS, resolution=5.0,
                required=0.99, r_pin=1.0, seed=0):
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
    perturb : half-widths of the uniform perturbations,
        ``{"theta_deg": .., "y_mm": .., "pin_mm": ..}``.
    trials : random trials per initial state (plus its four corners).
    speeds : coarse grid of belt speeds, mm/s (capped where the pin would
        throw the part, see ``simulate.FROUDE_MAX``).

    Returns
    -------
    dict with ``curve`` (rows ``[speed_mm_s, success_fraction]``, sorted) and
    ``speed_limit_mm_s`` (``0.0`` if even the slowest speed fails; the
    highest speed tried if none fails).
    """
    if len(pin_heights) != len(pin_speed_ratios):
        raise PinfeedError("give one speed ratio per pin")
    if not initial_states or not final_arcs:
        raise PinfeedError("give at least one initial state and one final arc")
    perturb = dict(perturb or {"theta_deg": 1.0, "y_mm": 0.5, "pin_mm": 0.2})
    v_thrown = math.sqrt(FROUDE_MAX * mu_s * G_MM_S2 * part.a)
    grid = sorted(v for v in speeds if 0 < v <= v_thrown)
    if not grid:
        raise PinfeedError("no belt speed in the grid below the speed at which the part is thrown")
    draws = _draws(part, pin_heights, initial_states, mu_c, perturb, trials, seed)
    curve = {}

    def frac(v):
        if v not in curve:
            curve[v] = success_fraction(part, pin_heights, pin_speed_ratios, draws, final_arcs, v,
                                        mu_s, r_pin)
        return curve[v]

    lo = None
    hi = None
    for v in grid:
        if frac(v) >= required:
            lo = v
        else:
            hi = v
            break
    if lo is None:
        limit = 0.0
    elif hi is None:
        limit = lo
    else:
        while hi - lo > resolution:
            mid = resolution * round(0.5 * (lo + hi) / resolution)
            if mid <= lo or mid >= hi:
                break
            if frac(mid) >= required:
                lo = mid
            else:
                hi = mid
        limit = lo
    return {"curve": [[v, curve[v]] for v in sorted(curve)], "speed_limit_mm_s": float(limit)}
