"""Each candidate of the deepest level takes its columns cheapest first: the
keys known or whose pin clears the part, then the keys more cells share.
References: the rollout kernel's own miss, a plain Python sort of the cells,
and the deepest level rolled out in one order for all candidates."""
from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

from kernels.rollout import MISS
from pipeline.planning.claims import orient
from pipeline.maps.simulate import rollout_points
from pipeline.planning.tight.column_order import ColumnOrder, clears
from pipeline.planning.tight.enumerate import NominalTree
from pipeline.planning.tight.fewest import fewest_sets
from pipeline.planning.tight.outcomes import Outcomes

from tests.planning.test_fewer_rollouts import PARTS, _pins

R_PIN = 3.0


@pytest.mark.parametrize("name", list(PARTS))
@pytest.mark.parametrize("v_pin", [0.0, 0.5, -1.0])
def test_a_pin_that_clears_the_part_is_a_miss_of_the_kernel(name, v_pin):
    part = PARTS[name]()
    rng = np.random.default_rng(11)
    n = 4000
    theta = rng.uniform(0.0, 360.0, n)
    dy = rng.uniform(-1.6, 1.6, n) * part.a * np.sqrt(1.0 + v_pin ** 2)
    status = rollout_points(part, theta, dy / part.a, 0.2, R_PIN, v_pin=v_pin)["status"]
    said = clears(part.vertices, theta, dy, np.full(n, v_pin), R_PIN)
    assert said.sum() > n // 10 and (~said).sum() > n // 10
    assert np.all(status[said] == MISS)
    # a miss it does not name clears the part by less than a hair: a pin 1 um thinner clears it
    missed_not_said = (status == MISS) & ~said
    thinner = clears(part.vertices, theta, dy, np.full(n, v_pin), R_PIN - 1e-3)
    assert np.all(thinner[missed_not_said]) and missed_not_said.sum() <= n // 200


def _brute_orders(keys, known, misses, rank):
    """Per row: columns sorted by (free first, then more cells sharing the key, then rank)."""
    flat = [tuple(k) for k in keys.reshape(-1, 4)]
    count = {k: flat.count(k) for k in set(flat)}
    out = []
    for row in keys:
        cells = []
        for c, k in enumerate(map(tuple, row)):
            free = k in known or misses(np.array([k]))[0]
            cells.append((0 if free else 1, 0 if free else -count[k], rank[c], c))
        out.append([c for *_, c in sorted(cells)])
    return np.array(out)


@settings(max_examples=60, deadline=None)
@given(st.integers(1, 30), st.integers(2, 5), st.integers(0, 2**31 - 1))
def test_each_row_takes_its_cheapest_columns_first(rows, cols, seed):
    rng = np.random.default_rng(seed)
    keys = np.stack([rng.integers(0, 4, (rows, cols)), rng.integers(-2, 2, (rows, cols)),
                     np.zeros((rows, cols), np.int64), np.zeros((rows, cols), np.int64)], axis=-1)
    outcomes = Outcomes()
    known_rows = np.unique(keys.reshape(-1, 4)[rng.random(rows * cols) < 0.2], axis=0)
    if known_rows.size:
        outcomes.add(known_rows, np.zeros(len(known_rows), np.int8), np.zeros(len(known_rows)),
                     np.zeros(len(known_rows)))
    known = {tuple(k) for k in known_rows}

    def misses(codes):
        return Outcomes.key_rows(codes)[:, 1] == -2

    codes = Outcomes.key_codes(keys.reshape(-1, 4)).reshape(rows, cols)
    order = ColumnOrder.cheapest(codes, outcomes, misses)
    # the tie-break: columns by their count of new (not free) keys over the level
    new = [len({tuple(k) for k in keys[:, c] if tuple(k) not in known}) for c in range(cols)]
    rank = np.argsort(np.argsort(new, kind="stable"), kind="stable")
    np.testing.assert_array_equal(order.rank, rank)
    want = _brute_orders(keys, known, lambda k: k[:, 1] == -2, rank)
    # a miss is free only for ordering: new-key counts still include it
    np.testing.assert_array_equal(order.orders(codes, rows), want)


@given(st.lists(st.tuples(st.integers(0, 7199), st.integers(-2**30 + 1, 2**30 - 1), st.integers(0, 255),
                          st.integers(0, 255)), min_size=1, max_size=50))
def test_key_codes_keep_the_order_of_the_keys_and_decode_to_them(rows):
    keys = np.array(rows, dtype=np.int64)
    codes = Outcomes.key_codes(keys)
    np.testing.assert_array_equal(Outcomes.key_rows(codes), keys)
    np.testing.assert_array_equal(np.argsort(codes, kind="stable"), np.lexsort(keys.T[::-1]))


def _deepest(part, pins, span, mode, monkeypatch):
    """The deepest (third) level with every candidate's columns ``cheapest``
    first or in one order (``shared``), and the rollouts that touched the part."""
    real = NominalTree._column_order

    def column_order(self, level, span, step):
        if mode == "cheapest":
            return real(self, level, (*span[:2], False), step)  # no evidence kept: cheapest first
        return ColumnOrder.shared(self._drop_order())
    monkeypatch.setattr(NominalTree, "_column_order", column_order)
    tree = NominalTree(part, pins, 0.2, R_PIN)
    level = None
    for level in tree.levels(3, span=span):
        pass
    kept = tree._outcomes  # every key rolled out (far below MAX_OUTCOMES here)
    assert kept.codes.size == tree.rollouts
    return tree, level, int((kept.status != MISS).sum())


@pytest.mark.parametrize("name", ["triangle", "t_bracket"])
def test_cheapest_first_rolls_out_fewer_touching_rollouts_for_the_same_level(name, monkeypatch):
    """The same sequences within the limit (finals, heights, margins) and the
    same evidence for fewer rollouts that touch the part than with every
    candidate in the drop order."""
    part = PARTS[name]()
    pins = _pins(part, 13)
    order = part.symmetry_order()
    span = (11.0, order)
    runs = {mode: _deepest(part, pins, span, mode, monkeypatch) for mode in ("cheapest", "shared")}
    (c_tree, cheap, c_touching), (s_tree, shared, s_touching) = runs["cheapest"], runs["shared"]
    assert c_touching < 0.9 * s_touching
    for lv in (cheap, shared):
        lv.within = (orient.row_spans(lv.theta, order) <= span[0]) & ~lv.spread_out
    assert cheap.within.sum() == shared.within.sum() and (name != "triangle" or cheap.within.any())
    for k in ("seq", "theta", "y", "margin"):
        np.testing.assert_array_equal(getattr(cheap, k)[cheap.within], getattr(shared, k)[shared.within])
    got, _ = fewest_sets(cheap, 10.0, order, 6, c_tree.complete)
    want, _ = fewest_sets(shared, 10.0, order, 6, s_tree.complete)
    assert [tuple(cheap.seq[i]) for i in got] == [tuple(shared.seq[i]) for i in want]


def test_the_deepest_level_goes_cheapest_first_after_a_near_miss_or_without_evidence():
    part = PARTS["triangle"]()
    tree = NominalTree(part, _pins(part, 9), 0.2, R_PIN)
    two = tree.extend(tree.extend(tree.root()))
    near = orient.row_spans(two.theta, part.symmetry_order()) <= 11.0
    assert near.any() and not near.all()
    span = (11.0, part.symmetry_order())
    whole, chunked = tree._column_order(two, span, 10**6), tree._column_order(two, span, 7)
    assert whole.codes is not None  # cheapest first
    for k in ("rank", "codes", "score"):  # gathered in chunks of parents: the same scores
        np.testing.assert_array_equal(getattr(chunked, k), getattr(whole, k))
    far = type(two)(two.seq[~near], two.theta[~near], two.y[~near], two.margin[~near])
    shared = tree._column_order(far, span, 10**6)
    assert shared.codes is None
    np.testing.assert_array_equal(shared.orders(None, 3), np.tile(tree._drop_order(), (3, 1)))
    # a search that keeps no evidence (the moving-pin stage) always goes cheapest first
    assert tree._column_order(far, (*span, False), 10**6).codes is not None
