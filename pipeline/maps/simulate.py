"""Public wrappers around the rollout kernels: validate, call, pack into xarray.

Angles a person reads or writes are degrees; lengths are in the part's unit
(``length_unit``, millimetres by default); forces in units of ``mu_s m g``.

``d`` for a moving pin (``v_pin != 0``) is the pin's offset as it passes the
centroid's starting station along the belt (for a static pin, simply its
offset).
"""
from __future__ import annotations

import math
from contextlib import contextmanager

import numba
import numpy as np
import xarray as xr

from kernels.batch import _rollout_grid, blocks_for
from kernels.points import _rollout_points
from kernels.models import MINPOWER_POINTS, MODEL_NAMES, STICK, TWIST_OK, _contact_twist
from kernels.support import _point_table
from kernels.rollout import (DEFAULT_DS_MAX, DEFAULT_TOL, JAM_REASONS, STATUS_NAMES,
                             _rollout, max_steps_for)

from pipeline import __version__
from pipeline.checks import check_belt, check_kernel_settings, check_pin_ratio
from pipeline.errors import PinfeedError
from pipeline.parts.contact import contact_parameter
from pipeline.parts.part import Part
from pipeline.parts.support import Support, parse_support, point_support

MODELS = MODEL_NAMES
STATUSES = STATUS_NAMES

STATUS_ATTRS = {
    "long_name": "rollout status",
    "flag_values": np.arange(len(STATUS_NAMES), dtype=np.int8),
    "flag_meanings": " ".join(STATUS_NAMES),
}
JAM_ATTRS = {
    "long_name": "why a rollout was declared jammed, or 'step budget' for a truncated "
                 "rollout that ran out of integration steps",
    "flag_values": np.arange(len(JAM_REASONS), dtype=np.int8),
    "flag_meanings": " ".join(["none"] + [r.replace(" ", "_") for r in JAM_REASONS[1:]]),
}


def check_parameters(mu_c, pin_radius, model="minpower", v_pin=0.0, max_travel=None):
    """Raise :class:`PinfeedError` with a clear message for bad physical parameters."""
    if not (isinstance(mu_c, (int, float, np.floating, np.integer)) and math.isfinite(mu_c)) or mu_c < 0:
        raise PinfeedError(f"contact friction mu_c must be a finite number >= 0, got {mu_c!r}")
    if not (isinstance(pin_radius, (int, float, np.floating, np.integer)) and math.isfinite(pin_radius)) \
            or pin_radius <= 0:
        raise PinfeedError(f"pin radius must be a finite number > 0, got {pin_radius!r}")
    if model not in MODELS:
        raise PinfeedError(f"unknown model {model!r}; choose one of {', '.join(MODELS)}")
    if not math.isfinite(v_pin):
        raise PinfeedError(f"pin speed ratio v_pin must be finite, got {v_pin!r}")
    if max_travel is not None and not (max_travel > 0):
        raise PinfeedError(f"max travel must be > 0, got {max_travel!r}")


def resolve_support(part: Part, support, model: str = "minpower") -> Support | None:
    """The checked point support of ``part`` that ``support`` names, or
    ``None`` for the spec's uniform pressure.

    ``support`` is ``None``, a :class:`~pipeline.parts.support.Support` or
    the CLI's text (``"uniform"``, ``"points:x,y,w ..."``, ``"rim:N"``,
    ``"tripod"``; see :func:`~pipeline.parts.support.parse_support`). A point
    support needs the quasi-static ``minpower`` model or the MuJoCo rig
    (``"mujoco"``, which takes the points as its belt contacts); ``tip`` and
    ``ellipsoid`` are built on uniform pressure and ``dynamic`` integrates
    the uniform belt force: anything else is a one-line :class:`PinfeedError`.
    """
    if support is None:
        return None
    if isinstance(support, str):
        support = parse_support(support, part)
    elif isinstance(support, Support):
        if not support.is_uniform:  # checked again against this part's outline
            support = point_support(part, support.points, support.weights, support.kind,
                                    support.label)
    else:
        raise PinfeedError(f"support must be a Support or its text, got {type(support).__name__}")
    if support.is_uniform:
        return None
    if model not in ("minpower", "mujoco"):
        raise PinfeedError(f"support {support.label!r} needs model minpower or mujoco (model {model} "
                           f"assumes uniform pressure); use model minpower or mujoco, or support uniform")
    return support


def _kernel_part(part: Part, model: str, support: Support | None):
    """The arrays a rollout kernel takes for ``part`` (``Part.prepared``) and
    the kernel's model code; for a point support the ``quad`` array holds
    the points in units of a, weights summing to 1, in place of its
    quadrature rows (``kernels.support._point_table``), and the code is ``MINPOWER_POINTS``."""
    prep = part.prepared()
    if support is None:
        return prep, MODELS.index(model)
    verts, area, a, quad, m_max, convex = prep
    # The kernel centres the outline again (to rounding): move the points with it.
    shift = np.asarray(part.vertices).mean(axis=0) - (verts * a).mean(axis=0)
    rows = np.column_stack([(support.points - shift) / a, support.weights])
    pts = _point_table(quad, np.ascontiguousarray(rows))
    return (verts, area, a, pts, m_max, convex), MINPOWER_POINTS


def _support_attrs(support: Support | None) -> dict:
    """Map attributes naming a point support (none for uniform: outputs unchanged)."""
    if support is None:
        return {}
    return {"support": support.label, "support_kind": support.kind,
            "support_points": support.points.ravel(), "support_weights": support.weights}


def _angles(values, what) -> np.ndarray:
    arr = np.atleast_1d(np.asarray(values, dtype=np.float64))
    if arr.ndim != 1 or not np.all(np.isfinite(arr)):
        raise PinfeedError(f"{what} must be finite numbers, got {values!r}")
    return arr


@contextmanager
def _threads(n):
    if n is None:
        yield numba.get_num_threads()
        return
    old = numba.get_num_threads()
    numba.set_num_threads(max(1, min(int(n), numba.config.NUMBA_NUM_THREADS)))
    try:
        yield numba.get_num_threads()
    finally:
        numba.set_num_threads(old)


def _common_attrs(part, model, mu_c, pin_radius, v_pin, ds_max, tol, length_unit):
    return {
        "part_name": part.name,
        "part_id": part.id,
        "part_vertices": np.asarray(part.vertices).ravel(),
        **part.hole_attrs(),
        "part_a": part.a,
        "model": model,
        "mu_c": float(mu_c),
        "pin_radius": float(pin_radius),
        "v_pin": float(v_pin),
        "length_unit": length_unit,
        "kernel_ds_max": float(ds_max),
        "kernel_tol": float(tol),
        "pinfeed_version": __version__,
    }


def rollout(part: Part, theta_i: float, d: float, mu_c: float, pin_radius: float,
            model: str = "minpower", v_pin: float = 0.0, max_travel: float | None = None,
            trajectory: bool = False, ds_max: float = DEFAULT_DS_MAX, tol: float = DEFAULT_TOL,
            length_unit: str = "mm", belt_speed: float | None = None,
            mu_s: float = 0.5, support=None) -> xr.Dataset:
    """One passage of ``part`` past one pin (see the manual's mechanics page, section 4).

    Parameters
    ----------
    theta_i : initial orientation, degrees.
    d : contact parameter ``(y_pin - y_com) / a``.
    mu_c : pin-part friction coefficient (>= 0).
    pin_radius : pin radius, in the part's length unit (> 0).
    model : ``"minpower"`` (default), ``"tip"`` or ``"ellipsoid"``
        (quasi-static); ``"dynamic"`` or ``"mujoco"`` need ``belt_speed``
        (mm/s) and take ``mu_s`` (see :func:`dynamic_rollout`).
    v_pin : pin speed across the belt over belt speed (0 for a static pin).
    max_travel : stop after this belt travel since first contact (status
        ``truncated``); ``None`` runs to the end.
    trajectory : also return the trajectory (dim ``step``: ``s``, ``x``,
        ``y``, ``theta``) and the force on the pin (dim ``sample``).
    support : ``None`` (uniform pressure, the default) or a point support
        (see :func:`resolve_support`); model minpower only.

    Returns
    -------
    xarray.Dataset
        Scalars ``status`` (a string), ``theta_f`` (degrees, [0, 360)),
        ``dy``, ``contact_travel``, ``feature_changes``, ``peak_force``,
        ``jam_reason``.
    """
    if model in BELT_MODELS:
        if belt_speed is None:
            raise PinfeedError(f"model {model!r} needs a belt speed (mm/s)")
        return dynamic_rollout(part, theta_i, d, mu_c, pin_radius, belt_speed, mu_s, model=model,
                               v_pin=v_pin, max_travel=max_travel, trajectory=trajectory,
                               support=resolve_support(part, support, model))
    check_parameters(mu_c, pin_radius, model, v_pin, max_travel)
    check_pin_ratio(part, pin_radius)
    check_kernel_settings(ds_max, tol)
    sup = resolve_support(part, support, model)
    theta = float(_angles(theta_i, "theta_i")[0])
    dd = float(_angles(d, "d")[0])
    cap = np.inf if max_travel is None else float(max_travel)
    prep, code = _kernel_part(part, model, sup)
    res = _rollout(*prep, code, float(mu_c), float(pin_radius),
                   math.radians(theta), dd, float(v_pin), cap, float(ds_max), float(tol),
                   bool(trajectory))
    status, reason, theta_f, dy, travel, changes, peak, traj, force = res
    ds = _passage_dataset(STATUS_NAMES[status], JAM_REASONS[reason] or "none",
                          "why jammed (or truncated by the step budget)",
                          theta_f, dy, travel, changes, peak, theta, dd, length_unit,
                          dict(_common_attrs(part, model, mu_c, pin_radius, v_pin, ds_max, tol,
                                             length_unit), **_support_attrs(sup)))
    if trajectory:
        _add_trajectory(ds, traj, force, length_unit, "centroid displacement along the belt")
    return ds


def nominal_path(part: Part, theta: float, y_c: float, heights, mu_c: float, pin_radius: float,
                 model: str = "minpower", speeds=None) -> list[tuple[float, float]]:
    """An unperturbed passage past a sequence of pins, one :func:`rollout` each.

    Parameters
    ----------
    part : Part
    theta, y_c : float
        The orientation (deg) and centroid height (mm above the fence line)
        before the first pin.
    heights : sequence of float
        The pins' heights above the fence line, mm, in the order the part meets them.
    mu_c, pin_radius, model
        As :func:`rollout`.
    speeds : sequence of float, optional
        Each pin's speed across the belt over the belt speed (default: static).

    Returns
    -------
    list of (theta deg, y_c mm)
        Before the first pin, then after each pin.
    """
    path = [(float(theta), float(y_c))]
    for k, height in enumerate(heights):
        v_pin = float(speeds[k]) if speeds is not None else 0.0
        one = rollout(part, theta, contact_parameter(height, y_c, part.a), mu_c, pin_radius,
                      model=model, v_pin=v_pin)
        theta, y_c = float(one.theta_f), y_c + float(one.dy)
        path.append((theta, y_c))
    return path


def _passage_dataset(status_name, reason_name, reason_long_name, theta_f, dy, travel, changes,
                     peak, theta, dd, unit, attrs) -> xr.Dataset:
    """The scalar Dataset of one passage (``theta_f`` in radians, unwrapped)."""
    return xr.Dataset(
        {
            "status": ((), status_name, {"long_name": "rollout status"}),
            "jam_reason": ((), reason_name, {"long_name": reason_long_name}),
            "theta_f": ((), _wrap_deg(math.degrees(theta_f)),
                        {"units": "degree", "long_name": "final orientation"}),
            "dy": ((), dy, {"units": unit, "long_name": "centroid displacement across the belt"}),
            "contact_travel": ((), travel, {"units": unit, "long_name": "pin travel in contact"}),
            "feature_changes": ((), int(changes), {"long_name": "contact feature changes"}),
            "peak_force": ((), peak, {"units": "mu_s m g", "long_name": "peak force on the pin"}),
        },
        coords={"theta_i": ((), theta, {"units": "degree", "long_name": "initial orientation"}),
                "d": ((), dd, {"units": "1", "long_name": "contact parameter (y_pin - y_com) / a"})},
        attrs=attrs,
    )


def _add_trajectory(ds, traj, force, unit, x_long_name):
    """Add the trajectory (dim ``step``) and the force on the pin (dim ``sample``) to ``ds``."""
    ds["traj_s"] = ("step", traj[:, 0], {"units": unit, "long_name": "belt travel since first contact"})
    ds["traj_x"] = ("step", traj[:, 1], {"units": unit, "long_name": x_long_name})
    ds["traj_y"] = ("step", traj[:, 2], {"units": unit, "long_name": "centroid displacement across the belt"})
    ds["traj_theta"] = ("step", np.degrees(traj[:, 3]), {"units": "degree", "long_name": "orientation (unwrapped)"})
    ds["force_s"] = ("sample", force[:, 0], {"units": unit, "long_name": "belt travel since first contact"})
    ds["force_x"] = ("sample", force[:, 1], {"units": "mu_s m g", "long_name": "force on the pin along the belt"})
    ds["force_y"] = ("sample", force[:, 2], {"units": "mu_s m g", "long_name": "force on the pin across the belt"})


def _wrap_deg(x):
    """Wrap degrees to [0, 360) without returning 360.0 for tiny negatives."""
    w = np.mod(x, 360.0)
    return np.where(w >= 360.0, 0.0, w) if np.ndim(w) else (0.0 if w >= 360.0 else float(w))


BACKENDS = ("cpu", "cuda")


def cuda_grid():
    """The GPU grid function, or a one-line :class:`PinfeedError` saying why
    the ``cuda`` backend cannot run here."""
    try:
        from numba import cuda
    except ImportError:  # pragma: no cover - numba ships numba.cuda or numba-cuda
        cuda = None
    if cuda is None or not _cuda_installed():
        raise PinfeedError("backend 'cuda' needs numba-cuda: pip install '.[cuda]' "
                           "(or use backend 'cpu')")
    from kernels import cuda as kcuda
    if not kcuda.available():
        raise PinfeedError("backend 'cuda': no usable NVIDIA GPU or driver found here; "
                           "use backend 'cpu'")
    return kcuda.rollout_grid


def _cuda_installed() -> bool:
    import importlib.util
    return importlib.util.find_spec("numba_cuda") is not None


def compute_map(part: Part, theta_i, d, mu_c: float, pin_radius: float, model: str = "minpower",
                v_pin: float = 0.0, max_travel: float | None = None, threads: int | None = None,
                ds_max: float = DEFAULT_DS_MAX, tol: float = DEFAULT_TOL,
                length_unit: str = "mm", belt_speed: float | None = None,
                mu_s: float = 0.5, backend: str = "cpu", support=None) -> xr.Dataset:
    """Configuration map set: rollouts over ``d x theta_i`` (paper eq. 2).

    ``model="dynamic"`` needs ``belt_speed`` (mm/s; the part in mm) and takes
    ``mu_s``; its ``jam_reason`` flags add ``step_budget``.

    Runs in parallel on ``threads`` Numba threads (default: all Numba has),
    or with ``backend="cuda"`` one rollout per GPU thread (numba-cuda, same
    kernel code; ``threads`` is then ignored; quasi-static models only).
    Returns a Dataset with dims ``(d, theta_i)`` and variables ``theta_f``,
    ``dy``, ``status`` (int8 flags, see its ``flag_meanings``), ``jam_reason``,
    ``contact_travel``, ``feature_changes`` and ``peak_force``. ``support``:
    ``None`` (uniform pressure, the default) or a point support (see
    :func:`resolve_support`; model minpower, either backend), named in the
    attributes ``support*``.
    """
    dynamic = model == "dynamic"
    fr = _check_map_inputs(part, mu_c, pin_radius, model, v_pin, max_travel, ds_max, tol,
                           belt_speed, mu_s, backend)
    sup = resolve_support(part, support, model)
    th = _angles(theta_i, "theta_i")
    dd = _angles(d, "d")
    cap = np.inf if max_travel is None else float(max_travel)
    if backend == "cuda":
        prep, code = _kernel_part(part, model, sup)
        out = cuda_grid()(
            *prep, code, float(mu_c), float(pin_radius), np.radians(th), dd,
            float(v_pin), cap, float(ds_max), float(tol), max_steps_for(int(prep[3][-1, 1])))
    elif dynamic:
        out = _dynamic_grid(part, mu_c, pin_radius, th, dd, v_pin, fr, belt_speed, cap, threads)
    else:
        prep, code = _kernel_part(part, model, sup)
        with _threads(threads) as n:
            out = _rollout_grid(
                *prep, code, float(mu_c), float(pin_radius),
                np.radians(th), dd, float(v_pin), cap, float(ds_max), float(tol),
                blocks_for(n, th.size * dd.size))
    attrs = dict(_common_attrs(part, model, mu_c, pin_radius, v_pin, ds_max, tol, length_unit),
                 **_support_attrs(sup))
    jam_attrs = dict(JAM_ATTRS)
    if dynamic:
        jam_attrs = _dynamic_jam_attrs()
        attrs.update(belt_speed=float(belt_speed), mu_s=float(mu_s), froude=fr)
    return _map_dataset(out, th, dd, length_unit, jam_attrs, dict(attrs, kernel_backend=backend))


def _check_map_inputs(part, mu_c, pin_radius, model, v_pin, max_travel, ds_max, tol,
                      belt_speed, mu_s, backend):
    """Refuse bad map arguments; the Froude number for ``model="dynamic"`` (else ``None``)."""
    dynamic = model == "dynamic"
    fr = None
    if model == "mujoco":
        raise PinfeedError("the MuJoCo rig is for single passages (seconds each), not maps")
    if dynamic:
        if belt_speed is None:
            raise PinfeedError("model 'dynamic' needs a belt speed (mm/s)")
        fr = check_belt(part, belt_speed, mu_s)
    check_parameters(mu_c, pin_radius, "minpower" if dynamic else model, v_pin, max_travel)
    check_pin_ratio(part, pin_radius)
    check_kernel_settings(ds_max, tol)
    if backend not in BACKENDS:
        raise PinfeedError(f"unknown backend {backend!r}; choose one of {', '.join(BACKENDS)}")
    if backend == "cuda" and dynamic:
        raise PinfeedError("the cuda backend runs the quasi-static models; use backend cpu for model dynamic")
    return fr


def _dynamic_grid(part, mu_c, pin_radius, th, dd, v_pin, fr, belt_speed, cap, threads):
    """The dynamic model's grid kernel over ``d x theta_i`` (``th`` in degrees)."""
    from kernels.batch import _dyn_rollout_grid
    from kernels.dynamic import DEFAULT_H, DEFAULT_MAX_STEPS, DEFAULT_V_REG
    verts, area, a, quad, _, convex = part.prepared()
    with _threads(threads) as n:
        return _dyn_rollout_grid(
            verts, area, a, quad, convex, float(mu_c), float(pin_radius), np.radians(th), dd,
            float(v_pin), fr, 0.0, DEFAULT_V_REG / float(belt_speed), DEFAULT_H, cap,
            DEFAULT_MAX_STEPS, blocks_for(n, th.size * dd.size))


def _dynamic_jam_attrs() -> dict:
    """``jam_reason`` flag attributes of the dynamic model (its reasons add ``step_budget``)."""
    from kernels.dynamic import DYN_REASONS
    return {"long_name": "why a rollout was declared jammed or truncated",
            "flag_values": np.arange(len(DYN_REASONS), dtype=np.int8),
            "flag_meanings": " ".join(["none"] + [r.replace(" ", "_") for r in DYN_REASONS[1:]])}


def _map_dataset(out, th, dd, unit, jam_attrs, attrs) -> xr.Dataset:
    """Pack a grid kernel's arrays (dims ``d x theta_i``) into the map Dataset."""
    status, reason, theta_f, dy, travel, changes, peak = out
    return xr.Dataset(
        {
            "theta_f": (("d", "theta_i"), _wrap_deg(np.degrees(theta_f)),
                        {"units": "degree", "long_name": "final orientation"}),
            "dy": (("d", "theta_i"), dy, {"units": unit, "long_name": "centroid displacement across the belt"}),
            "status": (("d", "theta_i"), status, dict(STATUS_ATTRS)),
            "jam_reason": (("d", "theta_i"), reason, jam_attrs),
            "contact_travel": (("d", "theta_i"), travel, {"units": unit, "long_name": "pin travel in contact"}),
            "feature_changes": (("d", "theta_i"), changes, {"long_name": "contact feature changes"}),
            "peak_force": (("d", "theta_i"), peak, {"units": "mu_s m g", "long_name": "peak force on the pin"}),
        },
        coords={
            "d": ("d", dd, {"units": "1", "long_name": "contact parameter (y_pin - y_com) / a"}),
            "theta_i": ("theta_i", th, {"units": "degree", "long_name": "initial orientation"}),
        },
        attrs=attrs,
    )


def rollout_points(part: Part, theta_i, d, mu_c, pin_radius: float, model: str = "minpower",
                   v_pin: float = 0.0, ds_max: float = DEFAULT_DS_MAX, tol: float = DEFAULT_TOL,
                   threads: int | None = None, belt_speed: float | None = None,
                   mu_s: float = 0.5, support=None, stretch=None) -> dict:
    """Final states of independent rollouts at scattered points.

    ``theta_i`` (degrees), ``d`` and ``mu_c`` are equal-length 1-D arrays (or
    scalars, broadcast). Used by the planner's uncertainty propagation and by
    verification, where the points are not a grid. ``model="dynamic"``
    (``kernels.dynamic``) needs ``belt_speed`` (mm/s; the part in mm) and
    takes the belt friction ``mu_s``; ``ds_max`` and ``tol`` are then unused.
    Returns a dict of NumPy arrays: ``status`` (int8 codes, see
    :data:`STATUSES`), ``jam_reason`` (int8, an index into
    ``kernels.rollout.JAM_REASONS``, which the dynamic model shares),
    ``theta_f`` (degrees, [0, 360)) and ``dy`` (the part's unit). ``support``
    as for :func:`compute_map` (model minpower).

    ``stretch`` (a :class:`pipeline.progress.Stretch`) is told the share of
    points done: with one that prints, the points are rolled out in pieces of
    about a second (:func:`pipeline.progress.row_batches`) with a tick
    between them; every point is independent, so the results are the same.
    """
    dynamic = model == "dynamic"
    if dynamic:
        if belt_speed is None:
            raise PinfeedError("model 'dynamic' needs a belt speed (mm/s)")
        fr = check_belt(part, belt_speed, mu_s)
    elif belt_speed is not None:
        raise PinfeedError(f"a belt speed needs model 'dynamic' (the {model} model is quasi-static)")
    check_parameters(0.0, pin_radius, "minpower" if dynamic else model, v_pin)
    sup = resolve_support(part, support, model)
    th, dd, mu = np.broadcast_arrays(*(np.atleast_1d(np.asarray(x, dtype=np.float64))
                                       for x in (theta_i, d, mu_c)))
    for arr, what in ((th, "theta_i"), (dd, "d"), (mu, "mu_c")):
        if arr.ndim != 1 or not np.all(np.isfinite(arr)):
            raise PinfeedError(f"{what} must be finite numbers")
    if np.any(mu < 0):
        raise PinfeedError("contact friction mu_c must be >= 0")
    mu, th, dd = np.ascontiguousarray(mu), np.radians(th), np.ascontiguousarray(dd)
    with _threads(threads) as n:
        if dynamic:
            from kernels.dynamic import DEFAULT_H, DEFAULT_MAX_STEPS, DEFAULT_V_REG
            from kernels.points import _dyn_rollout_points
            verts, area, a, quad, _, convex = part.prepared()

            def kernel(rows):
                return _dyn_rollout_points(verts, area, a, quad, convex, mu[rows], float(pin_radius),
                                           th[rows], dd[rows], float(v_pin), fr, 0.0,
                                           DEFAULT_V_REG / float(belt_speed), DEFAULT_H, np.inf,
                                           DEFAULT_MAX_STEPS, n)
        else:
            prep, code = _kernel_part(part, model, sup)

            def kernel(rows):
                return _rollout_points(*prep, code, mu[rows], float(pin_radius), th[rows], dd[rows],
                                       float(v_pin), np.inf, float(ds_max), float(tol), n)
        status, reason, theta_f, dy = _in_batches(kernel, th.size, stretch)
    return {"status": status, "jam_reason": reason,
            "theta_f": _wrap_deg(np.degrees(theta_f)), "dy": dy}


def _in_batches(kernel, n: int, stretch) -> tuple:
    """``kernel(rows)`` over the row ranges of :func:`pipeline.progress.row_batches`
    (one range without a printing ``stretch``), its arrays joined in row order."""
    from pipeline.progress import row_batches
    pieces = [kernel(slice(lo, hi)) for lo, hi in row_batches(n, stretch)]
    if len(pieces) == 1:
        return pieces[0]
    return tuple(np.concatenate(arrays) for arrays in zip(*pieces))


def status_names(codes) -> np.ndarray:
    """Decode int8 status flags to their names."""
    return np.asarray(STATUS_NAMES, dtype=object)[np.asarray(codes, dtype=int)]


# ----------------------------------------------------------------------------
# Models at belt speed: "dynamic" (kernels.dynamic) and "mujoco"
# (pipeline.maps.mujoco_rig, an independent engine). Quasi-static models above.

BELT_MODELS = ("dynamic", "mujoco")
def dynamic_rollout(part: Part, theta_i: float, d: float, mu_c: float, pin_radius: float,
                    belt_speed: float, mu_s: float = 0.5, model: str = "dynamic",
                    v_pin: float = 0.0, restitution: float = 0.0,
                    max_travel: float | None = None, trajectory: bool = False,
                    h: float | None = None, max_steps: int | None = None,
                    support: Support | None = None) -> xr.Dataset:
    """One passage at belt speed ``belt_speed`` (mm/s; the part in millimetres).

    ``model`` is ``"dynamic"`` (``kernels.dynamic``) or ``"mujoco"`` (the
    independent MuJoCo rig, ``pipeline.maps.mujoco_rig``). Same variables as
    :func:`rollout`; with ``trajectory`` also the force on the pin and, for
    ``dynamic``, the twist history (``twist_*``: belt-frame velocity in units
    of the belt speed, omega in belt speeds per a, the relative normal
    contact velocity and the normal impulse). ``support`` (``mujoco`` only; see
    :func:`resolve_support`): the rig's belt friction acts at its points.
    """
    sup = resolve_support(part, support, model)
    if model not in BELT_MODELS:
        raise PinfeedError(f"unknown belt-speed model {model!r}; choose one of {', '.join(BELT_MODELS)}")
    check_parameters(mu_c, pin_radius, "minpower", v_pin, max_travel)
    fr = check_belt(part, belt_speed, mu_s)
    if not (math.isfinite(restitution) and 0.0 <= restitution <= 1.0):
        raise PinfeedError(f"restitution must be in [0, 1], got {restitution!r}")
    theta = float(_angles(theta_i, "theta_i")[0])
    dd = float(_angles(d, "d")[0])
    cap = np.inf if max_travel is None else float(max_travel)
    if model == "dynamic":
        out = _dynamic_passage(part, theta, dd, mu_c, pin_radius, v_pin, fr, restitution,
                               belt_speed, cap, h, max_steps, trajectory)
    else:
        from pipeline.maps.mujoco_rig import mujoco_rollout
        out = mujoco_rollout(part, theta, dd, float(mu_c), float(pin_radius), float(belt_speed),
                             float(mu_s), v_pin=float(v_pin), max_travel=cap,
                             trajectory=bool(trajectory), support=sup) + (None,)
    status, reason_name, theta_f, dy, travel, changes, peak, traj, force, twist = out
    ds = _passage_dataset(STATUS_NAMES[status], reason_name, "why jammed or truncated",
                          theta_f, dy, travel, changes, peak, theta, dd, "mm",
                          dict(_common_attrs(part, model, mu_c, pin_radius, v_pin, 0.0, 0.0, "mm"),
                               belt_speed=float(belt_speed), mu_s=float(mu_s), froude=fr,
                               restitution=float(restitution), **_support_attrs(sup)))
    if trajectory:
        _add_trajectory(ds, traj, force, "mm", "centroid displacement along the belt (belt frame)")
        if twist is not None:
            for j, name in enumerate(("s", "vx", "vy", "omega", "vn", "impulse_n")):
                ds[f"twist_{name}"] = ("step", twist[:, j])
    return ds


def _dynamic_passage(part, theta, dd, mu_c, pin_radius, v_pin, fr, restitution, belt_speed,
                     cap, h, max_steps, trajectory):
    """``kernels.dynamic``'s one passage, its jam reason decoded to a name (``theta`` in degrees)."""
    from kernels.dynamic import DEFAULT_H, DEFAULT_MAX_STEPS, DEFAULT_V_REG, DYN_REASONS, _dyn_rollout
    verts, area, a, quad, _, convex = part.prepared()
    res = _dyn_rollout(verts, area, a, quad, convex, float(mu_c), float(pin_radius),
                       math.radians(theta), dd, float(v_pin), fr, float(restitution),
                       DEFAULT_V_REG / float(belt_speed), float(h or DEFAULT_H), cap,
                       int(max_steps or DEFAULT_MAX_STEPS), bool(trajectory))
    status, reason, theta_f, dy, travel, changes, peak, traj, force, twist = res
    return status, DYN_REASONS[reason] or "none", theta_f, dy, travel, changes, peak, traj, force, twist


CONTACT_MODES = {0: "stick", 1: "slide", -1: "slide", 2: "separate"}


def contact_motion(part: Part, theta: float, contact, normal, mu_c: float = 0.0,
                   model: str = "minpower", v_pin: float = 0.0) -> dict:
    """The part's instantaneous motion relative to the belt while one pin pushes
    it: its centre of rotation, turning rate and the pin force (see the manual's
    mechanics page, section 3). Uniform pressure; quasi-static models only.

    Parameters
    ----------
    theta : the part's orientation, degrees.
    contact : ``(x, y)`` the contact point on the outline, world axes, relative
        to the centroid, in the part's unit.
    normal : ``(x, y)`` the contact normal, world axes, pointing into the part
        (from the pin's centre towards the contact point); need not be unit.
    mu_c : pin-part friction coefficient (>= 0).
    model : ``"minpower"`` (default), ``"tip"`` or ``"ellipsoid"``.
    v_pin : pin speed across the belt over belt speed (0 for a static pin).

    Returns
    -------
    dict
        ``mode`` (``"stick"``, ``"slide"`` or ``"separate"``), ``omega``
        (radians per unit of belt travel, counter-clockwise positive),
        ``velocity`` (the centroid's, world axes, per unit of belt travel),
        ``cor`` (the centre of rotation, world axes relative to the centroid,
        in the part's unit; ``None`` for a pure translation or no motion) and
        ``force`` (the pin's force on the part, world axes, units of
        ``mu_s m g``). ``status`` is ``"ok"``, or ``"jammed"`` when the pin
        moves into the part and no pushing motion exists.
    """
    check_parameters(mu_c, 1.0, model, v_pin)
    (verts, area, a, quad, m_max, _), code = _kernel_part(part, model, None)
    t = math.radians(float(theta))
    to_world = np.array([[math.cos(t), -math.sin(t)], [math.sin(t), math.cos(t)]])
    c = to_world.T @ np.asarray(contact, float) / a
    n = to_world.T @ np.asarray(normal, float)
    n = n / np.linalg.norm(n)
    vp = to_world.T @ np.array([-1.0, float(v_pin)])
    status, vx, vy, om, fx, fy, mode = _contact_twist(
        code, quad, area, m_max, c[0], c[1], n[0], n[1], vp[0], vp[1], float(mu_c),
        vp[0], vp[1], 0.0, STICK)
    cor = None
    if abs(om) > 1e-12 * (abs(vx) + abs(vy) + 1.0):
        cor = to_world @ np.array([-vy / om, vx / om]) * a
    return {"status": "ok" if status == TWIST_OK else "jammed", "mode": CONTACT_MODES[int(mode)],
            "omega": om / a, "velocity": to_world @ np.array([vx, vy]), "cor": cor,
            "force": to_world @ np.array([fx, fy])}
