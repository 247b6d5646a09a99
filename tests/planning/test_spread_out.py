"""The deepest level stops a candidate once its nominal finals spread over the
screen's limit, and still finds what a full enumeration finds: the same
sequences within the limit (finals, heights, margins), the same
fewest-cluster evidence, and, once its other columns are rolled out, the
same level. The references here roll every column out and rank by a plain
Python sort."""
from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

from pipeline.planning.claims import orient
from pipeline.planning.tight.enumerate import NominalTree
from pipeline.planning.tight.fewest import cluster_bounds, cluster_keys, fewest_sets

from tests.planning.test_fewer_rollouts import PARTS, _pins

TOLERANCE = 10.0
LIMIT = TOLERANCE + 1.0


def _levels(part, pins, span, depth=3):
    tree = NominalTree(part, pins, 0.2, 3.0)
    level = None
    for level in tree.levels(depth, span=span):
        pass
    return tree, level


def _brute_fewest(level, order, k):
    """The first ``k`` rows by (clusters, spread, -margin, row): gaps over the
    tolerance counted one by one."""
    period = 360.0 / order
    keys = []
    for i in range(level.size):
        x = sorted(float(t) % period for t in level.theta[i])
        gaps = [b - a for a, b in zip(x, x[1:])] + [x[0] + period - x[-1]]
        keys.append((max(1, sum(g > TOLERANCE for g in gaps)), period - max(gaps), -level.margin[i], i))
    return [key[3] for key in sorted(keys)[:k]]


@pytest.mark.parametrize("name", list(PARTS))
def test_the_deepest_level_keeps_what_a_full_enumeration_finds(name):
    part = PARTS[name]()
    pins = _pins(part, 9)
    order = part.symmetry_order()
    full_tree, full = _levels(part, pins, None)
    tree, lazy = _levels(part, pins, (LIMIT, order))
    spread = lazy.spread_out
    assert spread.any() and tree.rollouts < full_tree.rollouts
    # what is rolled out of a spread-out row already spans over the limit
    for i in np.flatnonzero(spread)[:200]:
        known = ~lazy.unrolled[i]
        assert known.sum() >= 2 and orient.row_spans(lazy.theta[i:i + 1, known], order)[0] > LIMIT
    # the rows within the limit are exactly the full level's, every column rolled out
    within_full = orient.row_spans(full.theta, order) <= LIMIT
    within = (orient.row_spans(lazy.theta, order) <= LIMIT) & ~spread
    assert within_full.sum() == within.sum()
    for k in ("seq", "theta", "y", "margin"):
        np.testing.assert_array_equal(getattr(lazy, k)[within], getattr(full, k)[within_full])
    # the evidence: the fewest-cluster rows of the full level, by a plain sort
    for k in (1, 4, 12):
        want = [tuple(full.seq[i]) for i in _brute_fewest(full, order, k)]
        rows, cut = fewest_sets(lazy, TOLERANCE, order, k, tree.complete)
        assert not cut and [tuple(lazy.seq[i]) for i in rows] == want
    # every column rolled out: the full level itself
    tree.complete(lazy, np.flatnonzero(lazy.spread_out))
    alive = lazy.alive
    assert not lazy.spread_out.any()
    for k in ("seq", "theta", "y", "margin"):
        np.testing.assert_array_equal(getattr(lazy, k)[alive], getattr(full, k))


def test_only_the_deepest_level_stops_early():
    part = PARTS["t_bracket"]()
    pins = _pins(part, 9)
    tree = NominalTree(part, pins, 0.2, 3.0)
    levels = list(tree.levels(2, span=(LIMIT, part.symmetry_order())))
    assert levels[0].unrolled is None and levels[1].spread_out.any()


@settings(max_examples=300, deadline=None)
@given(st.integers(3, 10).flatmap(lambda n: st.tuples(
    st.lists(st.floats(0.0, 359.99), min_size=n, max_size=n),
    st.lists(st.booleans(), min_size=n, max_size=n))),
    st.sampled_from([1, 2, 4]), st.floats(2.0, 60.0))
def test_the_bounds_never_exceed_the_clusters_and_spread_of_any_completion(data, order, tolerance):
    theta, hidden = np.array(data[0]), np.array(data[1])
    hidden[:2] = False  # at least two known
    clusters, spread = cluster_keys(theta[None, :], tolerance, order)
    lb_c, lb_s = cluster_bounds(theta[None, :], hidden[None, :], tolerance, order)
    assert lb_c[0] <= clusters[0] and lb_s[0] <= spread[0] + 1e-12


def test_the_cluster_bound_is_met_when_the_hidden_finals_close_the_cheapest_gaps():
    # known finals 0, 30, 60 (period 360, tolerance 10): three gaps of 30, 30, 300;
    # two hidden finals close one 30 gap (two points split it into 10s): at least 2 clusters
    theta = np.array([[0.0, 30.0, 60.0, 0.0, 0.0]])
    hidden = np.array([[False, False, False, True, True]])
    lb_c, lb_s = cluster_bounds(theta, hidden, 10.0, 1)
    assert lb_c[0] == 2 and abs(lb_s[0] - 60.0) < 1e-6
    filled = np.array([[0.0, 30.0, 60.0, 40.0, 50.0]])
    assert cluster_keys(filled, 10.0, 1)[0][0] == 2


def test_what_was_rolled_out_before_changes_no_sequence_within_the_limit_nor_the_evidence():
    """Each candidate takes its states cheapest first, and what the tree
    rolled out before is free, so which sequences stop depends on it; the
    sequences within the limit and the fewest-set sequences do not."""
    part = PARTS["l_bracket"]()
    pins = _pins(part, 9)
    order = part.symmetry_order()
    fresh_tree, fresh = _levels(part, pins, (LIMIT, order))
    tree = NominalTree(part, pins, 0.2, 3.0)
    for _ in tree.levels(3, span=(46.0, order)):
        pass
    for level in tree.levels(3, span=(LIMIT, order)):
        pass
    for lv in (fresh, level):
        lv.within = (orient.row_spans(lv.theta, order) <= LIMIT) & ~lv.spread_out
    for k in ("seq", "theta", "y", "margin"):
        np.testing.assert_array_equal(getattr(level, k)[level.within], getattr(fresh, k)[fresh.within])
    rows, _ = fewest_sets(level, TOLERANCE, order, 4, tree.complete)
    want, _ = fewest_sets(fresh, TOLERANCE, order, 4, fresh_tree.complete)
    assert [tuple(level.seq[i]) for i in rows] == [tuple(fresh.seq[i]) for i in want]


def test_a_stopped_roll_out_ranks_the_sequences_rolled_out_in_full_and_says_so():
    part = PARTS["t_bracket"]()
    pins = _pins(part, 9)
    order = part.symmetry_order()
    tree, lazy = _levels(part, pins, (LIMIT, order))
    before = lazy.spread_out.copy()
    rows, cut = fewest_sets(lazy, TOLERANCE, order, 4, tree.complete, stop=lambda: True)
    assert cut and np.array_equal(lazy.spread_out, before)  # nothing more was rolled out
    assert not before[rows].any()  # the best of those rolled out in full (maybe none)
    exact = np.flatnonzero(~before)
    assert rows.size == min(4, exact.size)
    assert fewest_sets(lazy, TOLERANCE, order, 0, tree.complete)[0].size == 0


def test_the_deepest_level_is_the_same_in_any_chunks(monkeypatch):
    """Which sequences stop depends on each candidate's order of the states,
    fixed when the deepest level begins, so the chunks a time limit cuts it
    into change no row."""
    from pipeline.planning.tight import enumerate as enumerate_module
    from pipeline.progress import Deadline
    part = PARTS["t_bracket"]()
    pins = _pins(part, 9)
    span = (LIMIT, part.symmetry_order())

    def deepest(deadline=None):
        tree = NominalTree(part, pins, 0.2, 3.0)
        two = tree.extend(tree.extend(tree.root()))
        return tree.extend(two, span=span) if deadline is None else tree.extend(two, deadline=deadline, span=span)

    want = deepest()
    monkeypatch.setattr(enumerate_module, "FIRST_PARENTS", 2)  # chunks of 2 parents, then at most 16
    monkeypatch.setattr(enumerate_module, "BATCH_SECONDS", 1e-9)  # ... each as small as the pace allows
    got = deepest(Deadline(3600.0))
    assert got.cut is None
    for k in ("seq", "theta", "y", "margin", "unrolled"):
        np.testing.assert_array_equal(getattr(got, k), getattr(want, k))
