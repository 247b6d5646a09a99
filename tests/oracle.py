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
