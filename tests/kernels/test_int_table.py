"""``kernels.int_table`` against a Python dict: batches of inserts (keys
repeated within and across batches, keys that share their first slot, keys
up to 2**62) and lookups of present and absent keys, in tables from 2 slots
up; and its refusals (a negative key, a table that would end over half full)
and a query of ``EMPTY`` itself, which finds nothing."""
from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from kernels.int_table import EMPTY, insert_keys, lookup_keys

keys_small = st.integers(0, 40)  # many repeats and shared slots
keys_any = st.integers(0, 2**62)
batches = st.lists(st.lists(st.one_of(keys_small, keys_any), max_size=30), min_size=1, max_size=8)


def _grown(keys, values, size, new_keys, new_values):
    """Insert, moving to a table twice as large (or more) when it refuses, as the memo does."""
    got = insert_keys(keys, values, new_keys, new_values, size)
    if got >= 0:
        return keys, values, got
    n_slots = keys.size
    while n_slots < 2 * (size + new_keys.size):
        n_slots *= 2
    held = keys != EMPTY
    bigger_keys, bigger_values = np.full(n_slots, EMPTY, np.int64), np.zeros(n_slots, np.int64)
    assert insert_keys(bigger_keys, bigger_values, keys[held], values[held], 0) == size
    got = insert_keys(bigger_keys, bigger_values, new_keys, new_values, size)
    assert got >= 0
    return bigger_keys, bigger_values, got


@settings(max_examples=150, deadline=None)
@given(batches, st.lists(st.one_of(keys_small, keys_any), max_size=40))
def test_the_table_answers_as_a_dict(batches, absent):
    keys, values, size = np.full(2, EMPTY, np.int64), np.zeros(2, np.int64), 0
    reference, counter = {}, 0
    for batch in batches:
        new_keys = np.array(batch, dtype=np.int64)
        new_values = np.arange(counter, counter + new_keys.size, dtype=np.int64)
        counter += new_keys.size
        keys, values, size = _grown(keys, values, size, new_keys, new_values)
        reference.update(zip(batch, new_values.tolist()))  # a repeated key takes its last value
        assert size == len(reference) and 2 * size <= keys.size
        queries = np.array(list(reference) + absent, dtype=np.int64)
        out = np.full(queries.size, -7, np.int64)
        lookup_keys(keys, values, queries, out)
        assert out.tolist() == [reference.get(q, -1) for q in queries.tolist()]


def test_keys_that_share_their_first_slot_probe_past_each_other():
    keys, values = np.full(64, EMPTY, np.int64), np.zeros(64, np.int64)
    many = np.arange(0, 32 * 2**40, 2**40, dtype=np.int64)  # differ in high bits only
    assert insert_keys(keys, values, many, many + 5, 0) == 32
    out = np.empty(33, np.int64)
    lookup_keys(keys, values, np.append(many, 3 * 2**40 + 1), out)
    assert out[:32].tolist() == (many + 5).tolist() and out[32] == -1


def test_refusals_leave_the_table_as_it_was():
    keys, values = np.full(8, EMPTY, np.int64), np.zeros(8, np.int64)
    assert insert_keys(keys, values, np.array([1, 2, 3, 4, 5]), np.arange(5), 0) == -1  # over half full
    assert insert_keys(keys, values, np.array([1, -3]), np.arange(2), 0) == -1  # EMPTY is -1: keys >= 0
    assert (keys == EMPTY).all() and not values.any()
    assert insert_keys(keys, values, np.array([1, 2, 3, 4]), np.arange(4), 0) == 4  # exactly half
    one, one_value = np.full(1, EMPTY, np.int64), np.zeros(1, np.int64)
    assert insert_keys(one, one_value, np.zeros(0, np.int64), np.zeros(0, np.int64), 0) == 0


def test_a_query_of_empty_itself_finds_nothing():
    keys, values = np.full(8, EMPTY, np.int64), np.zeros(8, np.int64)
    insert_keys(keys, values, np.array([5, 9], dtype=np.int64), np.array([0, 1], dtype=np.int64), 0)
    out = np.zeros(3, np.int64)
    lookup_keys(keys, values, np.array([EMPTY, 9, 6], dtype=np.int64), out)
    assert out.tolist() == [-1, 1, -1]
    one, one_value, got = np.full(1, EMPTY, np.int64), np.zeros(1, np.int64), np.zeros(1, np.int64)
    lookup_keys(one, one_value, np.array([3], dtype=np.int64), got)  # a table of one slot: no hash bits
    assert got[0] == -1
