"""``pipeline.rows.unique_rows`` against ``np.unique(axis=0)`` and against
the definition (sorted distinct tuples, first occurrences, positions), on
the kinds of arrays the planner gives it: int64 keys, float rows with many
repeats, and float rows viewed as int64 (bit-for-bit comparison)."""
from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp

from pipeline.rows import unique_rows


def _by_definition(a):
    """Distinct rows sorted as tuples, each one's first index, each row's position."""
    rows = [tuple(r) for r in a.tolist()]
    distinct = sorted(set(rows))
    where = {r: k for k, r in enumerate(distinct)}
    first = [rows.index(r) for r in distinct]
    return distinct, first, [where[r] for r in rows]


small_ints = st.integers(-3, 3)
arrays = st.one_of(
    hnp.arrays(np.int64, st.tuples(st.integers(0, 60), st.integers(1, 5)), elements=small_ints),
    hnp.arrays(np.float64, st.tuples(st.integers(0, 80), st.integers(1, 4)),
               elements=st.sampled_from([-2.5, -1.0, 0.0, -0.0, 0.1, 0.2, 0.30000000000000004, 7.0, 1e300])),
)


@settings(max_examples=200, deadline=None)
@given(arrays)
def test_the_same_as_numpy_unique_and_the_definition(a):
    uniq, first, inverse = unique_rows(a, return_index=True, return_inverse=True)
    ref_uniq, ref_first, ref_inverse = np.unique(a, axis=0, return_index=True, return_inverse=True)
    assert uniq.dtype == a.dtype and uniq.shape == ref_uniq.shape
    assert np.array_equal(uniq, ref_uniq)
    assert np.array_equal(first, ref_first)
    assert np.array_equal(inverse, ref_inverse.ravel()) and inverse.shape == (a.shape[0],)
    distinct, first_def, where = _by_definition(a)
    assert [tuple(r) for r in uniq.tolist()] == distinct
    assert first.tolist() == first_def and inverse.tolist() == where
    assert np.array_equal(uniq[inverse], a)  # every row is its distinct row
    # the planner's calls ask for the inverse alone (np.unique's unstable sort then)
    only_uniq, only_inverse = unique_rows(a, return_inverse=True)
    ref_only_uniq, ref_only_inverse = np.unique(a, axis=0, return_inverse=True)
    assert np.array_equal(only_uniq, ref_only_uniq) and np.array_equal(only_inverse, ref_only_inverse.ravel())
    # of rows equal but for a zero's sign, the first one's bits
    assert np.array_equal(np.signbit(uniq), np.signbit(a[first]))


def test_bit_for_bit_rows_tell_signed_zeros_and_close_floats_apart():
    a = np.array([[0.1 + 0.2, 1.0], [0.3, 1.0], [0.0, 2.0], [-0.0, 2.0], [0.3, 1.0]])
    uniq, first, inverse = unique_rows(np.ascontiguousarray(a).view(np.int64), return_index=True,
                                       return_inverse=True)
    assert uniq.shape[0] == 4  # 0.1 + 0.2 != 0.3, and -0.0 differs from 0.0 in its bits
    assert inverse[1] == inverse[4] and len(set(inverse[:4].tolist())) == 4
    assert sorted(first.tolist()) == [0, 1, 2, 3]


def test_only_what_was_asked_is_returned_and_bad_shapes_are_refused():
    a = np.array([[2, 1], [1, 5], [2, 1]])
    assert np.array_equal(unique_rows(a), [[1, 5], [2, 1]])
    uniq, inverse = unique_rows(a, return_inverse=True)
    assert inverse.tolist() == [1, 0, 1]
    assert unique_rows(np.zeros((0, 3))).shape == (0, 3)
    with pytest.raises(ValueError, match="2-D"):
        unique_rows(np.arange(4))
