"""Refinement shards: the planner's on-demand rollouts, stored for reuse.

The tight propagation (:mod:`pipeline.planning.tight.propagate`) computes rollouts at points
of a dyadic lattice in ``(theta_i, d, mu_c)`` wherever a state needs them:
denser maps exactly where neighbouring outcomes disagree. They are stored in
the catalog like any shard, one self-describing HDF5 file per part, model,
pin speed and belt: ``catalog/refine/PART_ID/MODEL/v_pin=V.h5`` for the
quasi-static models and ``catalog/refine/PART_ID/dynamic/v_pin=V_belt=S_mu_s=M.h5``
for the dynamic model at belt speed ``S`` mm/s and belt friction ``M`` (so
quasi-static and belt-speed outcomes never mix), dim ``sample`` with
the lattice coordinates (integers, and the values they stand for) and the
outcomes ``status``, ``theta_f`` and ``dy``, plus the part, kernel settings,
belt speed and ``mu_s`` (``belt_speed = 0`` for quasi-static) and provenance
as attributes. A file whose part, pin radius, belt or kernel settings differ
from the planner's is not used (and is replaced). Writes are
atomic. ``Catalog.rebuild`` lists these files under ``refinements``, apart
from the map shards.

A read-only catalog (shared on a cluster, a colleague's) is never written:
its refinements are kept in a user cache folder instead, one per catalog
(:func:`cache_root`: ``$PINFEED_CACHE``, default the platform's cache folder,
e.g. ``~/.cache/pinfeed``), said once on stderr, and read back with the
catalog's own on the next run.
"""
from __future__ import annotations

import hashlib
import os
import sys
from pathlib import Path

import numpy as np
import xarray as xr

from kernels.rollout import DEFAULT_DS_MAX, DEFAULT_TOL

from pipeline.maps.catalog import REFINE_FOLDER
from pipeline.errors import PinfeedError
from pipeline.maps.io import write_atomic
from pipeline.parts.part import Part
from pipeline.planning.core.settings import KernelSettings, as_kernel_settings
from pipeline.planning.tight.propagate import UNITS, OutcomeLattice
from pipeline.provenance import provenance_attrs

FOLDER = REFINE_FOLDER
CACHE_ENV = "PINFEED_CACHE"
_announced = set()  # catalogs whose cache folder was named once already


def cache_root(root) -> Path:
    """The user cache folder standing in for catalog ``root``'s refinements:
    ``$PINFEED_CACHE`` (else the platform's cache folder ``/pinfeed``), then
    ``catalogs/NAME-HASH`` of the catalog's absolute path (one per catalog)."""
    base = os.environ.get(CACHE_ENV)
    if not base:
        if sys.platform == "win32":
            base = Path(os.environ.get("LOCALAPPDATA", Path.home() / "AppData" / "Local")) / "pinfeed"
        elif sys.platform == "darwin":
            base = Path.home() / "Library" / "Caches" / "pinfeed"
        else:
            base = Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache") / "pinfeed"
    resolved = Path(root).resolve()
    key = hashlib.sha256(str(resolved).encode()).hexdigest()[:12]
    return Path(base) / "catalogs" / f"{resolved.name}-{key}"


def _writable(path: Path) -> bool:
    """Whether ``path`` could be created: its nearest existing folder is writable."""
    folder = path.parent
    while not folder.exists() and folder != folder.parent:
        folder = folder.parent
    return folder.is_dir() and os.access(folder, os.W_OK | os.X_OK)


def lattice_path(root, part: Part, model: str, v_pin: float, belt_speed: float | None = None,
                 mu_s: float = 0.5) -> Path:
    """Where the refinement shard of this part, model, pin speed and belt lives
    (``belt_speed=None``: quasi-static ``model``; else the dynamic model)."""
    folder = Path(root) / FOLDER / part.id
    if belt_speed is None:
        return folder / model / f"v_pin={float(v_pin):g}.h5"
    return folder / "dynamic" / f"v_pin={float(v_pin):g}_belt={float(belt_speed):g}_mu_s={float(mu_s):g}.h5"


def _settings(lattice: OutcomeLattice) -> dict:
    out = {"pin_radius": float(lattice.pin_radius),
           "kernel_ds_max": float(lattice.ds_max if lattice.ds_max is not None else DEFAULT_DS_MAX),
           "kernel_tol": float(lattice.tol if lattice.tol is not None else DEFAULT_TOL),
           "belt_speed": float(lattice.belt_speed or 0.0),
           "mu_s": float(lattice.mu_s if lattice.belt_speed is not None else 0.0)}
    if lattice.belt_speed is not None:
        from kernels.dynamic import DEFAULT_H, DEFAULT_V_REG
        out.update(dynamic_h=float(DEFAULT_H), dynamic_v_reg=float(DEFAULT_V_REG))
    return out


def load_lattice(root, part: Part, model: str, v_pin: float, pin_radius: float,
                 kernel: KernelSettings | None = None, belt_speed: float | None = None,
                 mu_s: float = 0.5) -> OutcomeLattice:
    """The stored lattice of this part, model, speed and belt, or an empty one
    when none is stored or the stored one was made with other settings
    (``kernel``: the rollout kernel's step, ``None`` its defaults; the
    kernel's dict, which plans/plan.py still passes, is read with
    ``as_kernel_settings``). ``belt_speed`` (mm/s) selects the dynamic model
    at that speed with belt friction ``mu_s``; ``None`` is the quasi-static
    ``model``."""
    kernel = as_kernel_settings(kernel)
    lattice = OutcomeLattice(part, model, pin_radius, v_pin, kernel.ds_max, kernel.tol,
                             belt_speed=belt_speed, mu_s=mu_s)
    # the catalog's own, then what a run against it read-only kept in the cache
    for where in (root, cache_root(root)):
        _read_into(lattice, lattice_path(where, part, model, v_pin, belt_speed, mu_s))
    lattice.n_stored = len(lattice.known)
    return lattice


def _read_into(lattice: OutcomeLattice, path: Path) -> None:
    """Add the outcomes stored at ``path`` to ``lattice``, when the file is
    there, readable, and made with the lattice's part and settings."""
    if not path.is_file():
        return
    try:
        with xr.open_dataset(path, engine="h5netcdf") as ds:
            ds.load()
    except Exception:  # a corrupt file is replaced on the next save
        return
    want = _settings(lattice)
    if ds.attrs.get("part_id") != lattice.part.id or ds.attrs.get("model") != lattice.model or any(
            # relative only: tolerances of 1e-9 and 2e-9 must differ (a default atol of 1e-8 hid them)
            not np.isclose(float(ds.attrs.get(k, 0.0 if k in ("belt_speed", "mu_s") else np.nan)), v,
                           rtol=1e-9, atol=0.0)
            for k, v in want.items()):
        return
    keys = np.stack([ds["key_theta_i"].values, ds["key_d"].values, ds["key_mu_c"].values], axis=1)
    lattice.add(keys, ds["status"].values, ds["theta_f"].values, ds["dy"].values)


def save_lattice(root, lattice: OutcomeLattice) -> Path | None:
    """Write the lattice atomically (nothing if it holds no outcome) into the
    catalog ``root``, or into :func:`cache_root` when the catalog cannot be
    written (saying so once on stderr). Returns the file written."""
    if not lattice.known:
        return None
    keys = sorted(lattice.known)
    k = np.asarray(keys, dtype=np.int64)
    vals = [lattice.known[key] for key in keys]
    ds = xr.Dataset(
        {
            "key_theta_i": ("sample", k[:, 0], {"long_name": "lattice index of theta_i",
                                                "units": f"{UNITS[0]:g} degree"}),
            "key_d": ("sample", k[:, 1], {"long_name": "lattice index of d", "units": f"{UNITS[1]:g}"}),
            "key_mu_c": ("sample", k[:, 2], {"long_name": "lattice index of mu_c",
                                             "units": f"{UNITS[2]:g}"}),
            "theta_i": ("sample", k[:, 0] * UNITS[0], {"units": "degree", "long_name": "initial orientation"}),
            "d": ("sample", k[:, 1] * UNITS[1], {"units": "1", "long_name": "contact parameter"}),
            "mu_c": ("sample", k[:, 2] * UNITS[2], {"units": "1", "long_name": "pin friction"}),
            "status": ("sample", np.array([v[0] for v in vals], np.int8), {"long_name": "rollout status"}),
            "theta_f": ("sample", np.array([v[1] for v in vals]), {"units": "degree",
                                                                   "long_name": "final orientation"}),
            "dy": ("sample", np.array([v[2] for v in vals]), {"units": "mm",
                                                              "long_name": "centroid displacement across the belt"}),
        },
        attrs={"kind": "refinement", "part_id": lattice.part.id, "part_name": lattice.part.name,
               "part_vertices": np.asarray(lattice.part.vertices).ravel(), **lattice.part.hole_attrs(),
               "model": lattice.model,
               "v_pin": float(lattice.v_pin), **_settings(lattice), **provenance_attrs()},
    )
    where = (lattice.part, lattice.model, lattice.v_pin, lattice.belt_speed, lattice.mu_s)
    path = lattice_path(root, *where)
    if _writable(path):
        try:
            return write_atomic(ds, path)
        except PinfeedError:  # writable by its mode, yet refused (ACLs, a read-only mount...)
            pass
    cached = write_atomic(ds, lattice_path(cache_root(root), *where))
    if str(root) not in _announced:
        _announced.add(str(root))
        print(f"pinfeed: catalog {root} cannot be written: the planner's rollouts are kept in "
              f"{cache_root(root)} (set {CACHE_ENV} to move it) and reused on the next run", file=sys.stderr)
    return cached
