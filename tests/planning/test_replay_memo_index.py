"""``ReplayMemo``'s bookkeeping against a dict of states: batches of
(prefix, trial) keys, some given twice within one batch or again in a later
one, past the first tables' sizes (the index grows several times) and up to
``max_kept``; ``lookup`` and ``get`` must give each key's last state, and
``len`` the number of distinct keys."""
from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from pipeline.planning.claims.replay import ReplayMemo

REASONS = ["", "jammed (notch)", "jammed (truncated)"]


def _batch(rng, size, key_range):
    nodes = rng.integers(1, key_range, size)
    trials = rng.integers(0, key_range, size)
    if size > 1:  # a key given twice in one batch
        nodes[-1], trials[-1] = nodes[0], trials[0]
    theta, y_c = rng.normal(size=size), rng.normal(size=size)
    reasons = np.array([REASONS[k] for k in rng.integers(0, 3, size)], dtype=object)
    return nodes, trials, theta, y_c, reasons, rng.random(size) < 0.3


@settings(max_examples=25, deadline=None)
@given(st.integers(0, 2**32 - 1), st.lists(st.integers(1, 900), min_size=1, max_size=6), st.sampled_from([40, 3000]))
def test_lookup_and_get_give_each_keys_last_state(seed, sizes, key_range):
    rng = np.random.default_rng(seed)
    memo, reference = ReplayMemo(max_kept=10_000_000), {}
    for size in sizes:
        nodes, trials, theta, y_c, reasons, missed = _batch(rng, size, key_range)
        memo.add(nodes, trials, theta, y_c, reasons, missed)
        for k in range(size):
            reference[(int(nodes[k]), int(trials[k]))] = (theta[k], y_c[k], reasons[k], bool(missed[k]))
        assert len(memo) == len(reference)
    keys = list(reference) + [(key_range + 5, 1), (1, key_range + 7)]  # and two never added
    at = memo.lookup(np.array([k[0] for k in keys]), np.array([k[1] for k in keys]))
    assert (at[-2:] == -1).all() and (at[:-2] >= 0).all()
    theta, y_c, reason, missed = memo.get(at[:-2])
    for k, key in enumerate(keys[:-2]):
        assert (theta[k], y_c[k], reason[k], bool(missed[k])) == reference[key]


def test_max_kept_keeps_the_first_states_and_half_full_counts_them():
    rng = np.random.default_rng(3)
    memo = ReplayMemo(max_kept=1500)
    nodes, trials, theta, y_c, reasons, missed = _batch(rng, 2000, 10**6)
    memo.add(nodes, trials, theta, y_c, reasons, missed)
    assert memo.half_full
    at = memo.lookup(nodes, trials)
    assert (at[:1500] >= 0).all() and (at[1500:-1] == -1).all()  # the last row repeats the first
    assert np.array_equal(memo.get(at[1:1500])[0], theta[1:1500])
    memo.add(nodes[1600:1700], trials[1600:1700], theta[1600:1700], y_c[1600:1700], reasons[1600:1700],
             missed[1600:1700])
    assert (memo.lookup(nodes[1600:1700], trials[1600:1700]) == -1).all()  # full: nothing more is kept
