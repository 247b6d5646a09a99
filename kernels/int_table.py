"""A table from int64 keys to int64 values in two plain arrays, for the
planner's memo of trial states: many keys looked up or inserted per call,
in compiled loops.

The planner keeps each trial's state after each prefix of pins
(``pipeline.planning.claims.replay.ReplayMemo``, keys ``prefix << 32 |
trial``) and looks up a million or more of them in a plan; a Python dict
cost about 0.3 us per key there, a twentieth of a small part's plan.

Notes
-----
Open addressing with linear probing (Knuth, *TAOCP* vol. 3, 6.4,
algorithm L) in a table of ``2**bits`` slots: ``keys`` holds ``EMPTY``
(-1) in a free slot, so keys must be >= 0. A key's first slot is the top
``bits`` bits of ``key * 0x9E3779B97F4A7C15 mod 2**64`` (Fibonacci hashing,
*ibid.* 6.4, multiplicative hashing), which spreads keys that differ only
in their low bits, as consecutive trial numbers do. The caller keeps the
load at most one half (:func:`insert_keys` refuses more), so a search
probes about 1.5 slots on average when it finds its key and 2.5 when it
does not. Nothing is ever removed.
"""
import numpy as np

from ._numba import jit

EMPTY = -1
_GOLDEN = np.uint64(0x9E3779B97F4A7C15)


@jit
def _bits(n_slots):
    """``log2(n_slots)`` for a power of two."""
    bits = 0
    while (1 << bits) < n_slots:
        bits += 1
    return bits


@jit
def _first_slot(key, bits):
    """The first slot of ``key`` in a table of ``2**bits`` slots."""
    if bits == 0:
        return 0
    return np.int64((np.uint64(key) * _GOLDEN) >> np.uint64(64 - bits))


@jit
def _slot(keys, key, bits):
    """The slot of ``key`` in the table ``keys`` of ``2**bits`` slots, or the
    free slot where the probe from its first slot ends (an ``EMPTY`` key is
    never found: the probe stops at the first free slot it meets)."""
    mask = keys.size - 1
    j = _first_slot(key, bits)
    while keys[j] != EMPTY and keys[j] != key:
        j = (j + 1) & mask
    return j


@jit
def lookup_keys(keys, values, queries, out):
    """``out[i]``: the value of ``queries[i]`` in the table ``keys, values``
    (``len(keys)`` a power of two), or -1 where it holds no such key.

    Parameters
    ----------
    keys, values : int64 arrays of the table's slots (``EMPTY`` keys free).
    queries : int64 keys (>= 0) to look up.
    out : int64 array of ``len(queries)`` (written).
    """
    bits = _bits(keys.size)
    for i in range(queries.size):
        j = _slot(keys, queries[i], bits)
        out[i] = -1 if keys[j] == EMPTY else values[j]


@jit
def insert_keys(keys, values, new_keys, new_values, size):
    """Put ``new_keys[i] -> new_values[i]`` into the table ``keys, values``
    that holds ``size`` keys, in order (a key already there, or repeated,
    takes the last value given, as ``dict.update`` does). Returns the number
    of keys held after, or -1 (the table unchanged) when a key is negative
    or the table could end more than half full: the caller then inserts into
    a larger table (``size + len(new_keys) <= len(keys) // 2`` always fits).
    """
    if 2 * (size + new_keys.size) > keys.size:
        return -1
    for i in range(new_keys.size):
        if new_keys[i] < 0:
            return -1
    bits = _bits(keys.size)
    for i in range(new_keys.size):
        j = _slot(keys, new_keys[i], bits)
        if keys[j] == EMPTY:
            keys[j] = new_keys[i]
            size += 1
        values[j] = new_values[i]
    return size
