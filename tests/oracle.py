"""A brute-force planning oracle: no maps, no bands, no propagation.

Every pin sequence over a small pin grid is replayed, one rollout at a time
through the public ``simulate.rollout``, for random perturbed trials plus
every corner of the perturbation box. A sequence is admissible when no trial
jams and, at every pin, the pin stays on one side of the centroid for every
trial of a state; it ends in one set when all final orientations of all
states fall within one cluster (gaps larger than ``gap`` degrees split
clusters), counted modulo the part's rotational symmetry.
"""
from __future__ import annotations

import itertools

import numpy as np

from pipeline.maps import simulate


def trial_inputs(part, n_pins, n_random, seed, theta_half=2.0, y_half=0.5, mu=(0.0, 0.04),
                 pin_half=0.3):
    """Per initial state: list of trials (theta, y_c, mu, pin offsets), random and corners."""
    rng = np.random.default_rng(seed)
    out = []
    for theta, y_c in part.stable_states():
        rows = [(theta + rng.uniform(-theta_half, theta_half), y_c + rng.uniform(-y_half, y_half),
                 rng.uniform(*mu), rng.uniform(-pin_half, pin_half, n_pins)) for _ in range(n_random)]
        for c in itertools.product((-1, 1), (-1, 1), mu, *[(-pin_half, pin_half)] * n_pins):
            rows.append((theta + c[0] * theta_half, y_c + c[1] * y_half, c[2], np.array(c[3:])))
        out.append(rows)
    return out


def replay_sequence(part, heights, trials, pin_radius=3.0, model="minpower"):
    """Final (theta, y_c) of every trial of every state, or None if the sequence
    jams a trial or a pin passes some state's centroid on both sides."""
    finals = []
    for rows in trials:
        state = [(t, y) for t, y, _, _ in rows]
        for k, y_pin in enumerate(heights):
            ds = [(y_pin + rows[j][3][k] - state[j][1]) / part.a for j in range(len(rows))]
            if min(ds) < 0.0 < max(ds):
                return None
            nxt = []
            for j, d in enumerate(ds):
                r = simulate.rollout(part, state[j][0], d, rows[j][2], pin_radius, model=model)
                if str(r.status.item()) in ("jammed", "truncated"):
                    return None
                nxt.append((float(r.theta_f), state[j][1] + float(r.dy)))
            state = nxt
        finals.append(state)
    return finals


def n_clusters(thetas, order=1, gap=10.0) -> int:
    """Clusters of angles on the circle (modulo 360 / order)."""
    period = 360.0 / order
    s = np.sort(np.mod(np.asarray(thetas, float), period))
    if s.size == 0:
        return 0
    gaps = np.diff(np.concatenate([s, [s[0] + period]]))
    return max(1, int(np.sum(gaps > gap)))


def one_set_sequences(part, pins: dict, depth, trials_for):
    """Every admissible sequence up to ``depth`` that ends in one set: list of labels tuples."""
    order = part.symmetry_order()
    found = []
    for n in range(1, depth + 1):
        trials = trials_for(n)
        for seq in itertools.product(list(pins), repeat=n):
            finals = replay_sequence(part, [pins[p] for p in seq], trials)
            if finals is None:
                continue
            if n_clusters([t for st in finals for t, _ in st], order) == 1:
                found.append(seq)
    return found


# ---------------------------------------------------------------------- orientation within a tolerance
# A second oracle for the complete search (pipeline/planning/tight/complete.py): its
# own trials (uniform in the perturbation box, its corners and the nominal
# start), its own replay through the public batch rollout API and its own
# judgement of "one set within the tolerance". Nothing of the planner's
# enumeration, screening, verification or orient.py is used.


def box_trials(part, n_pins, n_random, seed, mu_range, theta_half=2.0, y_half=0.5, pin_half=0.3):
    """Per resting state: arrays (theta, y_c, mu, offsets (n, n_pins)); row 0 is the
    nominal start (middle friction, no pin error), then random trials, then corners."""
    rng = np.random.default_rng(seed)
    mu_lo, mu_hi = mu_range
    out = []
    for theta, y_c in part.stable_states():
        rows = [(theta, y_c, 0.5 * (mu_lo + mu_hi), np.zeros(n_pins))]
        for _ in range(n_random):
            rows.append((theta + rng.uniform(-theta_half, theta_half), y_c + rng.uniform(-y_half, y_half),
                         rng.uniform(mu_lo, mu_hi), rng.uniform(-pin_half, pin_half, n_pins)))
        for c in itertools.product((-1, 1), (-1, 1), (mu_lo, mu_hi), *[(-pin_half, pin_half)] * n_pins):
            rows.append((theta + c[0] * theta_half, y_c + c[1] * y_half, c[2], np.array(c[3:], float)))
        out.append(tuple(np.array([r[k] for r in rows], float) for k in range(4)))
    return out


def replay_box(part, heights, trials, pin_radius=3.0, model="minpower", pin_half=0.3, strict=True,
               speeds=None, support=None):
    """Final orientations of every trial of every state (one array). ``strict``:
    None if a trial jams or the nominal start passes a pin it touches within
    ``pin_half`` of the centroid (the complete search's admissibility rule);
    otherwise jammed trials are NaN. ``speeds``: each pin's v_pin / v_b (default
    fixed). ``support``: every trial rests on this support (default uniform)."""
    speeds = speeds or [0.0] * len(heights)
    finals = []
    for theta, y_c, mu, offs in trials:
        theta, y_c = theta.copy(), y_c.copy()
        for k, y_pin in enumerate(heights):
            gap = y_pin + offs[:, k] - y_c
            r = simulate.rollout_points(part, theta, gap / part.a, mu, pin_radius, model, v_pin=speeds[k],
                                        support=support)
            stuck = r["status"] >= 2  # jammed or truncated
            if strict and (stuck.any() or (r["status"][0] != 1 and abs(y_pin - y_c[0]) < pin_half)):
                return None
            theta, y_c = np.where(stuck, np.nan, r["theta_f"]), y_c + r["dy"]
        finals.append(theta)
    return np.concatenate(finals)


def most_in_arc(thetas, width, order=1) -> int:
    """The most angles one arc of ``width`` degrees holds (modulo 360 / order), by brute force."""
    period = 360.0 / order
    t = np.mod(np.asarray(thetas, float), period)
    t = t[np.isfinite(t)]  # jammed trials are in no arc
    best = 0
    for start in t:
        best = max(best, int(np.sum(np.mod(t - start, period) <= width + 1e-9)))
    return best


def orienting_sequences(part, pins: dict, depth, width, trials_for, order=1):
    """Every admissible sequence up to ``depth`` whose trials all end within one
    arc of ``width`` degrees: list of label tuples."""
    found = []
    for n in range(1, depth + 1):
        trials = trials_for(n)
        for seq in itertools.product(list(pins), repeat=n):
            finals = replay_box(part, [pins[p] for p in seq], trials)
            if finals is not None and most_in_arc(finals, width, order) == finals.size:
                found.append(seq)
    return found


def all_tight_plans(planner, depth):
    """Every sequence of up to ``depth`` of the planner's pins, followed by the
    tight propagation (``TightPlanner.follow``), best first by ``rank_key``."""
    plans = []
    for n in range(1, depth + 1):
        for seq in itertools.product(list(planner.pins), repeat=n):
            plan = planner.follow(seq)
            if plan is not None:
                plans.append(plan)
    return sorted(plans, key=lambda p: p.rank_key())
