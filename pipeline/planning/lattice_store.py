"""Refinement shards: the planner's on-demand rollouts, stored for reuse.

The tight propagation (:mod:`pipeline.planning.propagate`) computes rollouts at points
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
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
import xarray as xr

from kernels.rollout import DEFAULT_DS_MAX, DEFAULT_TOL

from pipeline.maps.catalog import REFINE_FOLDER
from pipeline.maps.io import write_atomic
from pipeline.parts.part import Part
from pipeline.planning.propagate import UNITS, OutcomeLattice
from pipeline.provenance import provenance_attrs

FOLDER = REFINE_FOLDER


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
                 kernel: dict | None = None, belt_speed: float | None = None,
                 mu_s: float = 0.5) -> OutcomeLattice:
    """The stored lattice of this part, model, speed and belt, or an empty one
    when none is stored or the stored one was made with other settings.
    ``belt_speed`` (mm/s) selects the dynamic model at that speed with belt
    friction ``mu_s``; ``None`` is the quasi-static ``model``."""
    kernel = kernel or {}
    lattice = OutcomeLattice(part, model, pin_radius, v_pin, kernel.get("ds_max"), kernel.get("tol"),
                             belt_speed=belt_speed, mu_s=mu_s)
    path = lattice_path(root, part, model, v_pin, belt_speed, mu_s)
    if not path.is_file():
        return lattice
    try:
        with xr.open_dataset(path, engine="h5netcdf") as ds:
            ds.load()
    except Exception:  # a corrupt file is replaced on the next save
        return lattice
    want = _settings(lattice)
    if ds.attrs.get("part_id") != part.id or ds.attrs.get("model") != lattice.model or any(
            # relative only: tolerances of 1e-9 and 2e-9 must differ (a default atol of 1e-8 hid them)
            not np.isclose(float(ds.attrs.get(k, 0.0 if k in ("belt_speed", "mu_s") else np.nan)), v,
                           rtol=1e-9, atol=0.0)
            for k, v in want.items()):
        return lattice
    keys = np.stack([ds["key_theta_i"].values, ds["key_d"].values, ds["key_mu_c"].values], axis=1)
    lattice.add(keys, ds["status"].values, ds["theta_f"].values, ds["dy"].values)
    lattice.n_stored = len(keys)
    return lattice


def save_lattice(root, lattice: OutcomeLattice) -> Path | None:
    """Write the lattice atomically (nothing if it holds no outcome)."""
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
               "part_vertices": np.asarray(lattice.part.vertices).ravel(), "model": lattice.model,
               "v_pin": float(lattice.v_pin), **_settings(lattice), **provenance_attrs()},
    )
    path = lattice_path(root, lattice.part, lattice.model, lattice.v_pin, lattice.belt_speed,
                        lattice.mu_s)
    return write_atomic(ds, path)
