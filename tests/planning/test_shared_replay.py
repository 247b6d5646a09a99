"""Replaying many sequences that share their first pins once per distinct
prefix (``replay.replay_shared``) gives exactly the numbers of replaying
every sequence on every trial (``replay.replay`` on the tiled rows): the
same finals to the last bit, the same jams, with fixed and moving pins,
uniform pressure and a support family's members."""
import numpy as np
import pytest

from pipeline.parts.part import Part
from pipeline.parts.support_family import parse_support_family
from pipeline.planning.claims.replay import replay, replay_shared
from pipeline.planning.claims.trials import trial_inputs
from pipeline.planning.core.resting import resting_states
from pipeline.planning.core.settings import VerifySettings
from pipeline.planning.tight.judge import stack

MU = (0.1, 0.3)
TRIALS = VerifySettings(trials=20, seed=3)


def _tiled(part, heights, speeds, rows, supports=None):
    """The plain replay: every sequence on every trial, one row each."""
    th, yc, mu, offs, sup = rows
    n_plans, n_trials = heights.shape[0], th.size
    tf, _, jam, _ = replay(part, np.repeat(heights, n_trials, axis=0), np.repeat(speeds, n_trials, axis=0),
                           np.tile(th, n_plans), np.tile(yc, n_plans), np.tile(mu, n_plans),
                           np.tile(offs, (n_plans, 1)), 3.0, "minpower",
                           support=np.tile(sup, n_plans), supports=supports)
    return tf.reshape(n_plans, n_trials), (jam != "").reshape(n_plans, n_trials)


def _sequences(part, n_pins, seed, moving=False):
    """Sequences with shared prefixes: a fixed first pin for half of them, a
    common two-pin prefix for a quarter, the rest random; low pins that jam
    or miss among them."""
    rng = np.random.default_rng(seed)
    top = 1.5 * max(y for _, y in part.stable_states())
    heights = rng.choice(np.linspace(0.0, top, 9), size=(16, n_pins))
    heights[:8, 0] = heights[0, 0]
    heights[:4, :2] = heights[0, :2]
    heights[12:] = heights[11]  # duplicates
    speeds = np.zeros_like(heights)
    if moving:
        speeds[:, -1] = rng.choice([-2.0, -1.0, 0.0], size=16)
    return heights, speeds


@pytest.mark.parametrize("vertices, n_pins, moving", [
    ([[0, 0], [60, 0], [45, 50]], 3, False),
    ([[0, 0], [70, 0], [50, 25], [10, 25]], 4, True),
    ([[0, 0], [50, 0], [50, 12], [18, 12], [18, 30], [0, 30]], 2, False),
])
def test_shared_prefixes_replay_exactly_as_every_row(vertices, n_pins, moving):
    part = Part.from_vertices(vertices)
    rows = stack(trial_inputs(resting_states(part), MU, n_pins, TRIALS))
    heights, speeds = _sequences(part, n_pins, seed=n_pins, moving=moving)
    tf0, jam0 = _tiled(part, heights, speeds, rows)
    tf1, jam1 = replay_shared(part, heights, speeds, *rows[:4], 3.0, "minpower", support=rows[4])
    assert np.array_equal(jam0, jam1)
    assert np.array_equal(tf0[~jam0], tf1[~jam1])
    assert np.all((tf1 >= 0.0) & (tf1 < 360.0))


def test_shared_prefixes_with_support_family_members():
    part = Part.from_vertices([[0, 0], [60, 0], [45, 50]])
    family = parse_support_family("tripods:4", part)
    rows = stack(trial_inputs(resting_states(part), MU, 3, TRIALS, family))
    supports = family.kernel_supports
    assert len(set(rows[4].tolist())) > 1  # the trials rest on several members
    heights, speeds = _sequences(part, 3, seed=7)
    tf0, jam0 = _tiled(part, heights, speeds, rows, supports)
    tf1, jam1 = replay_shared(part, heights, speeds, *rows[:4], 3.0, "minpower", support=rows[4],
                              supports=supports)
    assert np.array_equal(jam0, jam1)
    assert np.array_equal(tf0[~jam0], tf1[~jam1])
