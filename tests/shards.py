"""Shards compared as read back: two runs of the same config must write the same bits
(values, dtypes, shapes and attributes; chunking and filters are not compared)."""
from __future__ import annotations

import h5py
import numpy as np

# Provenance that differs by design between two runs: the write time, and the
# commit recorded when each job ran (HEAD may move between the two runs).
RUN_STAMPS = frozenset({"created", "git_commit"})


def _bits(h5file, value):
    """An attribute or dataset value as comparable bytes: a NaN equals itself, and
    an object reference (netCDF's dimension lists) is the name it points to."""
    if isinstance(value, (str, bytes)):
        return value
    if isinstance(value, h5py.Reference):
        return "ref", h5file[value].name
    arr = np.asarray(value)
    if arr.dtype.names:  # a compound type (netCDF's reference lists): field by field
        return arr.shape, tuple((field, _bits(h5file, arr[field])) for field in arr.dtype.names)
    if arr.dtype == object:
        return arr.shape, tuple(_bits(h5file, x) for x in arr.ravel())
    return arr.dtype.str, arr.shape, arr.tobytes()


def assert_same_shard(path, reference, ignore=RUN_STAMPS) -> None:
    """Every group and dataset of ``path`` equal to ``reference``'s bit for bit
    (dtype, shape and bytes), and every attribute equal except ``ignore``."""
    with h5py.File(path, "r") as got, h5py.File(reference, "r") as want:
        names_got, names_want = [], []
        got.visit(names_got.append)
        want.visit(names_want.append)
        assert names_got == names_want, f"{path}: other objects than {reference}"
        for name in ["/", *names_want]:
            attrs_got = {k: _bits(got, v) for k, v in got[name].attrs.items() if k not in ignore}
            attrs_want = {k: _bits(want, v) for k, v in want[name].attrs.items() if k not in ignore}
            assert attrs_got == attrs_want, f"{path}: attributes of {name} differ"
            if isinstance(want[name], h5py.Dataset):
                assert _bits(got, got[name][()]) == _bits(want, want[name][()]), f"{path}: {name} differs"
