"""Reading and writing map files (HDF5 through xarray's h5netcdf engine) and result JSON.

Writes are atomic: the file is written under a temporary name in the same
folder and renamed into place, so an interrupted run never leaves a
half-written file under the real name. A ``kill -9`` can leave the
temporary file behind: its name starts with a dot and ends in ``.tmp``, so
the catalog never reads it, and the workflow's start removes it
(:func:`remove_stale_temps`), as does a sweep once the shard it belongs to
is in place (:func:`temps_beside`).
"""
from __future__ import annotations

import glob
import json
import os
import tempfile
from contextlib import contextmanager
from pathlib import Path

import xarray as xr

from pipeline.errors import PinfeedError

MAP_VARIABLES = ("theta_f", "dy", "status")
TMP_SUFFIX = ".tmp"  # atomic writes: '.NAME.XXXX.tmp' beside NAME; never a '*.h5' the catalog scans


def _umask_mode() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return 0o666 & ~mask


@contextmanager
def atomic_target(path):
    """Yield a temporary path beside ``path``; on success it is renamed onto
    ``path`` (with the umask's permissions), on any error it is removed."""
    path = Path(path)
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=TMP_SUFFIX, dir=path.parent)
    except OSError as exc:  # read-only folder, a file in the way, disk full...
        raise PinfeedError(f"cannot write {path}: {exc.strerror or exc} in {path.parent}; make the "
                           f"folder writable or choose another") from None
    os.close(fd)
    try:
        yield tmp
        os.chmod(tmp, _umask_mode())  # mkstemp creates 0600
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


def remove_stale_temps(folder) -> list[Path]:
    """Delete the temporary files of atomic writes that a killed run left under
    ``folder`` (only call it when no other run can be writing there)."""
    gone = []
    for tmp in Path(folder).rglob(f".*{TMP_SUFFIX}"):
        if tmp.is_file():
            tmp.unlink(missing_ok=True)
            gone.append(tmp)
    return gone


def temps_beside(path) -> list[Path]:
    """The temporary files that atomic writes of ``path`` left beside it (a
    writer killed mid-write cannot remove its own)."""
    path = Path(path)
    return sorted(path.parent.glob(f".{glob.escape(path.name)}.*{TMP_SUFFIX}"))


def write_atomic(ds: xr.Dataset, path, encoding=None) -> Path:
    """Write ``ds`` to the HDF5 file ``path`` atomically (a temporary file, then renamed)."""
    with atomic_target(path) as tmp:
        ds.to_netcdf(tmp, engine="h5netcdf", encoding=encoding, invalid_netcdf=True)
    return Path(path)


def write_text_atomic(text: str, path) -> Path:
    """Write ``text`` to ``path`` atomically (a temporary file, then renamed)."""
    with atomic_target(path) as tmp:
        Path(tmp).write_text(text)
    return Path(path)


def write_json(obj, path) -> Path:
    """Write ``obj`` as indented, key-sorted JSON to ``path`` atomically."""
    return write_text_atomic(json.dumps(obj, indent=1, sort_keys=True, default=float) + "\n", path)


def read_json(path) -> dict:
    """A result file (plan, verification, sensing, speed, layout JSON), checked:
    a missing or corrupt file raises :class:`PinfeedError` saying what to do."""
    path = Path(path)
    if not path.is_file():
        raise PinfeedError(f"no result file at {path}; run the workflow ('make run') first")
    try:
        return json.loads(path.read_text())
    except json.JSONDecodeError:
        raise PinfeedError(f"{path} is corrupt; delete it and re-run the workflow") from None


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
