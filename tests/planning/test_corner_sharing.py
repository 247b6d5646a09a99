"""Trials that meet a pin in the same state are rolled out once.

The corners of the perturbation box differ only in some pins' offsets, so
two corners that share their first ``k`` offsets reach pin ``k + 1`` in the
same state. ``replay.pin_step`` rolls each distinct input (orientation,
contact parameter, friction, pin speed, support) out once; the reference here
replays every trial on its own, where nothing can be shared."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from rollout_counter import count_rollouts

from pipeline.parts.outlines import read_outline
from pipeline.parts.part import Part
from pipeline.parts.support import rim_support, tripod_support
from pipeline.planning.claims.replay import distinct_rows, replay
from pipeline.planning.claims.trials import corner_inputs
from pipeline.planning.core.resting import resting_states
from pipeline.planning.core.settings import VerifySettings

CAD = Path(__file__).resolve().parents[1] / "data" / "cad"
PARTS = {
    "triangle": lambda: Part.from_vertices([[0, 0], [60, 0], [15, 35]], name="tri"),
    "l_bracket": lambda: Part.from_vertices([[0, 0], [60, 0], [60, 15], [15, 15], [15, 40], [0, 40]], name="l"),
    "holed_bracket": lambda: (lambda o: Part.from_vertices(o.vertices, name="holed", holes=o.holes))(
        read_outline(CAD / "holed_bracket.dxf")),
}


def _corners(part, n_pins):
    """Every corner of the default perturbation box of every resting state."""
    rows = [corner_inputs(theta, y_c, (0.1, 0.3), n_pins, VerifySettings()) for theta, y_c in
            resting_states(part).values()]
    return tuple(np.concatenate([r[k] for r in rows]) for k in range(4))


def _heights(part, n_pins):
    """Pins spread over the part's reach, below its highest resting centroid."""
    top = max(y for _, y in resting_states(part).values())
    return list(np.linspace(0.25, 0.8, n_pins) * top)


@pytest.mark.parametrize("name", sorted(PARTS))
def test_corners_share_their_first_pins_and_give_each_trial_its_own_numbers(name, monkeypatch):
    part, n_pins = PARTS[name](), 3
    th, yc, mu, offs = _corners(part, n_pins)
    heights = _heights(part, n_pins)
    counted = count_rollouts(monkeypatch)
    shared = replay(part, heights, [0.0] * n_pins, th, yc, mu, offs, 3.0, "minpower")
    rolled = sum(counted)
    alone = [replay(part, heights, [0.0] * n_pins, th[i:i + 1], yc[i:i + 1], mu[i:i + 1], offs[i:i + 1], 3.0,
                    "minpower") for i in range(th.size)]
    for k, name_ in enumerate(("theta_f", "y_c", "jam", "missed")):
        assert np.array_equal(shared[k], np.concatenate([a[k] for a in alone])), name_
    # The inputs at pin k + 1 differ in the start (theta, y_c, friction: 8)
    # and the first k + 1 offsets: at most 8 * 2**(k + 1) distinct per state.
    states = len(resting_states(part))
    assert rolled <= states * sum(8 * 2 ** (k + 1) for k in range(n_pins)) < th.size * n_pins


def test_rows_on_different_supports_or_speeds_are_not_shared(monkeypatch):
    part = PARTS["l_bracket"]()
    theta, y_c = next(iter(resting_states(part).values()))
    n = 6
    th, yc, mu = np.full(n, theta), np.full(n, y_c), np.full(n, 0.2)
    offs = np.zeros((n, 1))
    supports = [tripod_support(part), rim_support(part)]
    support = np.array([0, 0, 1, 1, 0, 1])
    counted = count_rollouts(monkeypatch)
    out = replay(part, [0.5 * y_c], [[0.0]] * 3 + [[0.5]] * 3, th, yc, mu, offs, 3.0, "minpower",
                 support=support, supports=supports)
    # distinct (speed, support): (0, 0), (0, 1), (0.5, 0), (0.5, 1)
    assert sum(counted) == 4
    alone = [replay(part, [0.5 * y_c], [v], th[:1], yc[:1], mu[:1], offs[:1], 3.0, "minpower",
                    support=[s], supports=supports)[0][0] for v, s in zip([0.0] * 3 + [0.5] * 3, support)]
    assert np.array_equal(out[0], np.array(alone))


def test_distinct_rows_compares_bits():
    theta = np.array([1.0, 1.0, 1.0 + 1e-15, -0.0, 0.0, 1.0])
    d = np.array([0.1, 0.1, 0.1, 0.2, 0.2, 0.1])
    first, inverse = distinct_rows(theta, d, 0.2, 0.0, None)
    assert first.size == 4  # 1.0 thrice; the nudged 1.0; -0.0 and 0.0 apart
    assert np.array_equal(theta[first][inverse], theta) and np.array_equal(d[first][inverse], d)
    assert distinct_rows(np.arange(4.0), np.zeros(4), 0.2, 0.0, np.array([0, 1, 0, 1])) == (None, None)
