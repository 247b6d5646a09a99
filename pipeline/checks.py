"""Input limits shared by the config loader and the CLI: one place that says
what is refused and why, each as a one-line :class:`PinfeedError`.

The limits keep a valid-looking input from running without end or
allocating without bound ("Hardening"):

* a list or range of numbers holds at most ``MAX_VALUES`` values, all
  finite and distinct, and one map at most ``MAX_MAP`` rollouts;
* the integrator's largest step ``ds_max`` (units of a) lies in
  ``DS_MAX_RANGE`` and its tolerance ``tol`` in ``TOL_RANGE`` (the kernel's
  step count grows as 1/ds_max and as tol^(-1/order));
* the pin radius is at most ``MAX_PIN_RATIO`` times the part's size a (the
  time of a rollout grows with r_pin / a; a pin ten times the part is no
  longer a feeder);
* output files have a known suffix and a folder that exists or can be made;
* a belt speed is slow enough that the pin pushes the part rather than
  throwing it (Froude number at most ``FROUDE_MAX``), and belt friction
  ``mu_s`` lies in (0, ``MU_S_MAX``].
"""
from __future__ import annotations

import math
import numbers
from pathlib import Path

import numpy as np

from pipeline.errors import PinfeedError

MAX_VALUES = 100_000
MAX_MAP = 1_000_000  # rollouts in one map (d x theta_i): about half an hour on one core
DS_MAX_RANGE = (1e-3, 1.0)
TOL_RANGE = (1e-12, 1e-3)
MAX_PIN_RATIO = 10.0
MAP_SUFFIXES = (".h5", ".hdf5", ".nc")
IMAGE_SUFFIXES = (".png", ".pdf", ".svg")


def range_size(start: float, stop: float, step: float) -> int:
    """Number of values of the inclusive range ``start:stop:step`` (no allocation)."""
    return int(math.floor((stop - start) / step + 1e-9)) + 1


def check_values(values, what: str) -> np.ndarray:
    """``values`` as a float array, or an error if empty, non-finite or repeated."""
    arr = np.asarray(values, dtype=np.float64).ravel()
    if arr.size == 0:
        raise PinfeedError(f"{what} is empty; give at least one number")
    bad = arr[~np.isfinite(arr)]
    if bad.size:
        raise PinfeedError(f"{what} must be finite numbers, got {bad[0]:g}")
    uniq, counts = np.unique(arr, return_counts=True)
    if np.any(counts > 1):
        raise PinfeedError(f"{what} lists {uniq[counts > 1][0]:g} more than once; give each value once")
    return arr


def check_grid_size(n: int, what: str, limit: int = MAX_VALUES) -> None:
    """Refuse a grid of ``n`` values beyond ``limit`` before anything is allocated."""
    if n > limit:
        raise PinfeedError(f"{what} has {n:,} values, more than the limit of {limit:,}; "
                           f"use a coarser step or a shorter range")


def _real(x) -> bool:
    return isinstance(x, numbers.Real) and not isinstance(x, bool)


def check_kernel_settings(ds_max: float, tol: float) -> None:
    """The integrator settings within their sane ranges (see the module docstring)."""
    lo, hi = DS_MAX_RANGE
    if not (_real(ds_max) and lo <= ds_max <= hi):
        raise PinfeedError(f"kernel ds_max must be in [{lo:g}, {hi:g}] (units of a), got {ds_max!r}")
    lo, hi = TOL_RANGE
    if not (_real(tol) and lo <= tol <= hi):
        raise PinfeedError(f"kernel tol must be in [{lo:g}, {hi:g}], got {tol!r}")


def check_pin_ratio(part, pin_radius: float) -> None:
    """Refuse a pin more than ``MAX_PIN_RATIO`` times the part's size a."""
    if pin_radius > MAX_PIN_RATIO * part.a:
        raise PinfeedError(f"pin radius {pin_radius:g} is {pin_radius / part.a:.3g} times the size of "
                           f"part {part.name} (a = {part.a:.3g}), more than the limit of "
                           f"{MAX_PIN_RATIO:g}; use a smaller pin or check the outline's unit (mm)")


def check_out_path(path, suffixes, what: str = "--out") -> Path:
    """An output file path: not a folder, a known suffix, its folder usable."""
    path = Path(path)
    if path.is_dir():
        raise PinfeedError(f"{what} {path} is a folder; name a file in it, e.g. {path / ('out' + suffixes[0])}")
    if path.suffix.lower() not in suffixes:
        raise PinfeedError(f"{what} {path} has an unsupported suffix {path.suffix or '(none)'!r}; "
                           f"use one of {', '.join(suffixes)}")
    parent = next((p for p in path.parents if p.exists()), Path("."))
    if not parent.is_dir():
        raise PinfeedError(f"{what} {path}: {parent} is a file, not a folder; choose another path")
    return path


def check_finite_tree(obj, where: str = "") -> None:
    """Refuse NaN or infinity anywhere in a nested config (JSON schema's
    ``minimum`` lets NaN through, since every comparison with NaN is false)."""
    if isinstance(obj, float) and not math.isfinite(obj):
        raise PinfeedError(f"config error at {where or '(top level)'}: {obj} is not a finite number")
    if isinstance(obj, dict):
        for k, v in obj.items():
            check_finite_tree(v, f"{where}/{k}" if where else str(k))
    elif isinstance(obj, list):
        for k, v in enumerate(obj):
            check_finite_tree(v, f"{where}/{k}")


# Belt speed and belt friction, for the models at belt speed.
G_MM_S2 = 9810.0
MU_S_MAX = 5.0
# Largest v^2 / (mu_s g a): beyond it a plastic impact at belt speed sends the
# part sliding more than Fr a / 2 = 5 a ahead of the pin: thrown, not pushed.
FROUDE_MAX = 10.0


def froude(part, belt_speed: float, mu_s: float = 0.5) -> float:
    """``v_b^2 / (mu_s g a)`` with ``v_b`` in mm/s and the part in millimetres."""
    return float(belt_speed) ** 2 / (float(mu_s) * G_MM_S2 * part.a)


def check_belt(part, belt_speed, mu_s) -> float:
    """Raise :class:`PinfeedError` for a bad belt speed or belt friction; return Fr."""
    if not (isinstance(belt_speed, (int, float, np.floating, np.integer))
            and math.isfinite(belt_speed)) or belt_speed <= 0:
        raise PinfeedError(f"belt speed must be a finite number > 0 (mm/s), got {belt_speed!r}")
    if not (isinstance(mu_s, (int, float, np.floating, np.integer)) and math.isfinite(mu_s)) \
            or mu_s <= 0 or mu_s > MU_S_MAX:
        raise PinfeedError(f"belt friction mu_s must be in (0, {MU_S_MAX:g}], got {mu_s!r}")
    fr = froude(part, belt_speed, mu_s)
    if fr > FROUDE_MAX:
        raise PinfeedError(
            f"belt speed {belt_speed:g} mm/s is too fast for this part: v^2/(mu_s g a) = {fr:.3g} "
            f"> {FROUDE_MAX:g}, so the pin throws the part (it slides about {0.5 * fr * part.a:.0f} mm "
            f"after the impact) rather than pushing it; slow the belt below "
            f"{math.sqrt(FROUDE_MAX * mu_s * G_MM_S2 * part.a):.0f} mm/s")
    return fr


def schema_problem(data, schema: dict, limit: int = 120) -> str | None:
    """Where ``data`` first breaks the JSON ``schema`` (draft 2020-12), as
    ``"at PATH: MESSAGE"`` on one line (the message cut at ``limit``
    characters; jsonschema's best match), or None when it fits. Callers wrap
    it in their own :class:`PinfeedError` saying what the file is and how to
    make it again."""
    import jsonschema
    err = jsonschema.exceptions.best_match(jsonschema.Draft202012Validator(schema).iter_errors(data))
    if err is None:
        return None
    where = "/".join(str(p) for p in err.absolute_path) or "(top level)"
    return f"at {where}: {' '.join(err.message.split())[:limit]}"


def check_time_limit(value, what: str = "planner.time_limit_s") -> float | None:
    """A planning time limit in seconds (``None``: no limit), or a one-line
    :class:`PinfeedError` naming ``what`` for a value that is not a number of
    seconds above 0."""
    if value is None:
        return None
    try:
        seconds = float(value)
    except (TypeError, ValueError):
        seconds = math.nan
    if isinstance(value, bool) or not (math.isfinite(seconds) and seconds > 0):
        raise PinfeedError(f"{what} must be a number of seconds above 0, got {value!r}; "
                           "leave it out (or null in a config) to search without a time limit")
    return seconds
