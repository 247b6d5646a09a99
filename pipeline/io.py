"""Reading and writing map files (HDF5 through xarray's h5netcdf engine).

Writes are atomic: the file is written under a temporary name in the same
folder and renamed into place, so an interrupted run never leaves a
half-written file under the real name.
"""
from __future__ import annotations

import json
import os
import tempfile
from contextlib import contextmanager
from pathlib import Path

import xarray as xr

from .errors import PinfeedError

MAP_VARIABLES = ("theta_f", "dy", "status")


def _umask_mode() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return 0o666 & ~mask


@contextmanager
def atomic_target(path):
    """Yield a temporary path beside ``path``; on success it is renamed onto
    ``path`` (with the umask's permissions), on any error it is removed."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    os.close(fd)
    try:
        yield tmp
        os.chmod(tmp, _umask_mode())  # mkstemp creates 0600
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


def write_atomic(ds: xr.Dataset, path, encoding=None) -> Path:
    with atomic_target(path) as tmp:
        ds.to_netcdf(tmp, engine="h5netcdf", encoding=encoding, invalid_netcdf=True)
    return Path(path)


def write_text_atomic(text: str, path) -> Path:
    with atomic_target(path) as tmp:
        Path(tmp).write_text(text)
    return Path(path)


def write_json(obj, path) -> Path:
    return write_text_atomic(json.dumps(obj, indent=1, sort_keys=True, default=float) + "\n", path)


def read_map(path) -> xr.Dataset:
    """Open a map file written by ``pinfeed map`` (or a catalog shard), checked."""
    path = Path(path)
    if not path.is_file():
        raise PinfeedError(f"no map file at {path}; create one with 'pinfeed map ... --out {path}'")
    try:
        ds = xr.open_dataset(path, engine="h5netcdf", phony_dims="sort")
        ds.load()
    except Exception as exc:  # h5py/h5netcdf raise several types for bad files
        raise PinfeedError(f"cannot read {path} as a pinfeed map (corrupt or not HDF5): {exc}") from None
    missing = [v for v in MAP_VARIABLES if v not in ds] + [c for c in ("d", "theta_i") if c not in ds.coords]
    if missing:
        raise PinfeedError(f"{path} is not a pinfeed map: it lacks {', '.join(missing)}")
    return ds
