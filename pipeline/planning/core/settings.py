"""The planner's settings, built once from the validated config.

:class:`PlannerSettings` (:meth:`PlannerSettings.from_config`, the one place
a config's ``planner``, ``verify``, ``speed`` and ``sweep`` sections are
read for planning) is a frozen tree of typed parts: :class:`Friction` (the
friction a plan must work for: a value or a range, its sigma and the
truncation both widenings use), :class:`Perturbation` and
:class:`VerifySettings` (the trials), :class:`ClaimSettings` (tolerance,
required share, confidence, rule), :class:`SearchSettings` (pins, depth,
limits in d, model, belt, moving pins; the rollout kernel's step,
:class:`KernelSettings`) and :class:`SpeedSettings` (with the uniform box
of its trials, :class:`SpeedPerturbation`). Beside them, the settings of
the stages that stand on plans: :class:`LayoutSettings` (``layout``) and
:class:`DesignSettings` (``design``). Every default comes from
``config/schema.yaml`` (:func:`pipeline.config.schema_default`).

This is the one place in the planner where a config's dicts are read: each
type has a reader of its section (``from_config``, ``from_section``), and
:func:`as_verify_settings` and :func:`as_kernel_settings` turn the flat
dicts that callers not yet switched to the typed settings still pass into
the typed ones.

Three frictions have three names: the planner's ``friction`` (a
:class:`Friction`, ``planner.mu_c``), the sweep's ``swept_frictions`` (the
grid of map frictions, ``sweep.mu_c``) and the per-trial ``trial_mu`` (the
array each verification trial draws).

Also the global pin labels ``P1, P2, ...`` of the configured pin heights, or
of heights fitted to the part (``fitted_pins``) when none are configured.
"""
from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field

import numpy as np

from pipeline.checks import check_time_limit
from pipeline.config import schema_default
from pipeline.errors import PinfeedError

TRUNCATE_SIGMA = 2.0  # normal perturbations are drawn within +-2 sigma; the planner's box is as wide
HOLDOUT_STREAM = 4_001  # salt of the held-out trials' seed: a stream no screen or selection draws from
UNTRUNCATED_STREAM = 4_002  # salt of the untruncated trials' seed: no selection or held-out trial draws from it


def parse_friction(value):
    """``0.15`` -> 0.15; ``"0.1:0.3"`` or ``[0.1, 0.3]`` -> ``(0.1, 0.3)``; a
    :class:`Friction` -> its :attr:`~Friction.value`. Raises
    :class:`PinfeedError` for negative, non-finite or reversed values. The
    one place friction text is read (:meth:`Friction.parse` calls it)."""
    if isinstance(value, Friction):
        return value.value
    if isinstance(value, str):
        parts = value.split(":")
        try:
            nums = [float(p) for p in parts]
        except ValueError:
            raise PinfeedError(f"friction {value!r} is not a number or a range LO:HI") from None
    elif isinstance(value, (list, tuple)):
        nums = [float(v) for v in value]
    else:
        nums = [float(value)]
    if len(nums) not in (1, 2) or not all(math.isfinite(x) and x >= 0 for x in nums):
        raise PinfeedError(f"friction (--mu-c, planner.mu_c) {value!r} must be a finite number >= 0 or a range LO:HI of such numbers")
    if len(nums) == 2:
        if nums[1] < nums[0]:
            raise PinfeedError(f"friction range {value!r} has LO > HI; write it as LO:HI")
        return (nums[0], nums[1]) if nums[1] > nums[0] else nums[0]
    return nums[0]


def friction_label(mu_c) -> str:
    """``0.15`` -> ``'0.15'``; ``(0.1, 0.3)`` -> ``'0.1:0.3'``."""
    if isinstance(mu_c, Friction):
        return mu_c.label
    if isinstance(mu_c, tuple):
        return f"{mu_c[0]:g}:{mu_c[1]:g}"
    return f"{mu_c:g}"


def nominal_friction(mu_c) -> float:
    """One friction value to draw nominal paths with: the value or the range's middle."""
    if isinstance(mu_c, Friction):
        return mu_c.nominal
    return 0.5 * (mu_c[0] + mu_c[1]) if isinstance(mu_c, (tuple, list)) else float(mu_c)


def pins_from_config(values) -> dict:
    """Global pin labels ``P1, P2, ...`` for the configured heights (mm above the fence)."""
    return {f"P{k}": float(y) for k, y in enumerate(values, start=1)}


FITTED_STEP = 15.0  # fitted pins are about a / FITTED_STEP apart
BELOW_FENCE = 0.25  # ... and start this many a below the fence


def fitted_pins(part) -> dict:
    """Candidate pins fitted to ``part``: labels ``P1, P2, ...`` -> heights (mm).

    From ``BELOW_FENCE * a`` below the fence to one step above the highest
    point of every resting state (so every pin height that can touch a
    resting part is there), every ``a / 15`` rounded to 0.5 mm (at least
    0.5 mm). A 20 mm part gets pins about 1 mm apart, a 150 mm one 5 mm."""
    a = float(part.a)
    step = max(0.5, round(a / FITTED_STEP / 0.5) * 0.5)
    top = 0.0
    for theta, y_c in part.stable_states():
        c, s = math.cos(math.radians(theta)), math.sin(math.radians(theta))
        top = max(top, y_c + float(np.max(s * part.vertices[:, 0] + c * part.vertices[:, 1])))
    lo = -math.ceil(BELOW_FENCE * a / step) * step
    hi = (math.ceil(top / step) + 1) * step
    n = int(round((hi - lo) / step)) + 1
    return {f"P{k}": round(lo + (k - 1) * step, 6) for k in range(1, n + 1)}


def candidate_pins(part, pins) -> dict:
    """The planner's candidate fixed pins for ``part``: ``pins`` (the search
    settings' heights, ``planner.pins``) when it lists heights, else
    :func:`fitted_pins` (``None`` or ``"auto"``)."""
    if pins is None or pins == "auto":
        return fitted_pins(part)
    return pins_from_config(pins)


# ---------------------------------------------------------------------- typed settings


def _default(*path):
    """A dataclass field whose default is the schema's (read when the class is made)."""
    value = schema_default(*path)
    if isinstance(value, (list, dict)):
        return field(default_factory=lambda: schema_default(*path))
    return field(default=value)


@dataclass(frozen=True)
class Friction:
    """The pin friction a plan must work for: ``lo == hi`` for one value, or a
    range ``[lo, hi]`` (then the range is the uncertainty). ``sigma`` is the
    spread of a single value (``verify.mu_sigma``); both the planner's box and
    the verification's draws stop at ``truncate`` sigma."""

    lo: float
    hi: float
    sigma: float = _default("verify", "mu_sigma")
    truncate: float = TRUNCATE_SIGMA

    @classmethod
    def parse(cls, value, sigma: float | None = None) -> "Friction":
        """``0.15``, ``"0.1:0.3"``, ``[0.1, 0.3]`` (or a Friction) as a Friction
        (one-line :class:`PinfeedError` on a bad value)."""
        if isinstance(value, Friction) and sigma is None:
            return value
        v = parse_friction(value)
        lo, hi = (v, v) if not isinstance(v, tuple) else v
        return cls(float(lo), float(hi), *(() if sigma is None else (float(sigma),)))

    @property
    def is_range(self) -> bool:
        """Whether this is a range (else one value widened by its sigma)."""
        return self.hi > self.lo

    @property
    def value(self):
        """The value (a float) or ``(lo, hi)``: the form plan files and callers of old keep."""
        return (self.lo, self.hi) if self.is_range else self.lo

    @property
    def nominal(self) -> float:
        """One friction to draw nominal paths with: the value or the range's middle."""
        return 0.5 * (self.lo + self.hi) if self.is_range else self.lo

    @property
    def label(self) -> str:
        """``'0.15'`` or ``'0.1:0.3'``."""
        return friction_label(self.value)

    @property
    def halfwidth(self) -> float:
        """How far a single value is widened either side (``truncate`` sigma)."""
        return self.truncate * self.sigma

    def interval(self) -> tuple[float, float]:
        """The frictions to cover: the range as given, or the value +- ``truncate`` sigma (not below 0)."""
        if self.is_range:
            return self.lo, self.hi
        return max(0.0, self.lo - self.halfwidth), self.lo + self.halfwidth

    def to_json(self):
        """The plan file's ``mu_c``: a number or ``[lo, hi]``."""
        return [self.lo, self.hi] if self.is_range else self.lo


@dataclass(frozen=True)
class Perturbation:
    """Sizes of the errors each trial draws (``verify`` section): orientation
    (normal, deg), centroid height (uniform half-width, mm), friction (normal)
    and every pin's position (uniform half-width, mm)."""

    theta_sigma: float = _default("verify", "theta_sigma")
    y_halfwidth: float = _default("verify", "y_halfwidth")
    mu_sigma: float = _default("verify", "mu_sigma")
    pin_halfwidth: float = _default("verify", "pin_halfwidth")

    @classmethod
    def from_section(cls, section) -> "Perturbation":
        """The sizes of a ``verify``-style section (``theta_sigma``,
        ``y_halfwidth``, ``mu_sigma``, ``pin_halfwidth``; the schema's where
        one is absent; other keys ignored), values as given."""
        sizes = dict(dataclasses.asdict(cls()), **(section or {}))
        return cls(sizes["theta_sigma"], sizes["y_halfwidth"], sizes["mu_sigma"], sizes["pin_halfwidth"])


@dataclass(frozen=True)
class VerifySettings:
    """The perturbed trials a plan is replayed on: ``trials`` per resting state,
    the perturbation box's ``corners``, the ``seed``, and ``holdout_trials``
    (``None``: as many as ``trials``) for the held-out trials that certify it.

    ``truncate_sigma`` is where the normals of theta and of a single friction
    are cut (``None``: not cut, the tails' trials of :meth:`untruncated`);
    ``holdout`` says which trials these are, for the record: ``None`` the
    trials that screen and select plans, ``True`` the held-out ones
    (:meth:`held_out`), ``False`` the untruncated ones."""

    trials: int = _default("verify", "trials")
    corners: bool = _default("verify", "corners")
    seed: int = _default("verify", "seed")
    holdout_trials: int | None = _default("verify", "holdout_trials")
    perturbation: Perturbation = field(default_factory=Perturbation)
    truncate_sigma: float | None = TRUNCATE_SIGMA
    holdout: bool | None = None

    @classmethod
    def from_section(cls, section) -> "VerifySettings":
        """The trials of a ``verify`` section, whole or partial (the schema's
        defaults for what it leaves out; the claim's keys ``required``,
        ``confidence`` and ``rule`` ignored), values as given. Also reads the
        flat dict of :meth:`as_dict` back (``truncate_sigma``, ``holdout``)."""
        d = dict(cls().as_dict(), **(section or {}))
        return cls(d["trials"], d["corners"], d["seed"], d["holdout_trials"], Perturbation.from_section(d),
                   d.get("truncate_sigma", TRUNCATE_SIGMA), d.get("holdout"))

    def held_out(self, attempt: int = 0) -> "VerifySettings":
        """The settings of the held-out trials that certify a plan.

        The search screens and selects plans on these trials (seed ``seed``);
        the plan it picks is certified on fresh trials from a seed derived
        from ``(seed, HOLDOUT_STREAM, attempt)``, which no screen or selection
        draws from, ``holdout_trials`` per state (default: as many as
        ``trials``; fewer is refused with a one-line :class:`PinfeedError`).
        The same settings give the same held-out trials. The box corners are
        replayed again (they are not random)."""
        n = int(self.trials) if self.holdout_trials is None else int(self.holdout_trials)
        if n < int(self.trials):
            raise PinfeedError(f"verify.holdout_trials ({n}) must be at least verify.trials ({self.trials}): "
                               "the trials that certify a plan may not be fewer than those that chose it")
        seed = int(np.random.SeedSequence([int(self.seed), HOLDOUT_STREAM, int(attempt)]).generate_state(1)[0])
        return dataclasses.replace(self, trials=n, seed=seed, holdout=True)

    def untruncated(self, trials_per_state: int) -> "VerifySettings":
        """The settings of the untruncated trials (the tails,
        :mod:`pipeline.planning.claims.tails`): ``trials_per_state`` random
        trials per initial state (no box corners: the box has no edge),
        normals not cut, seed derived from ``(seed, UNTRUNCATED_STREAM)``,
        which neither the selection nor the held-out trials draw from."""
        seed = int(np.random.SeedSequence([int(self.seed), UNTRUNCATED_STREAM]).generate_state(1)[0])
        return dataclasses.replace(self, trials=int(trials_per_state), seed=seed, corners=False,
                                   truncate_sigma=None, holdout=False)

    def as_dict(self) -> dict:
        """The flat dict a verification record keeps under ``settings``: the
        trials, corners, seed, ``holdout_trials`` and the perturbation sizes;
        then ``truncate_sigma`` when the normals are not cut at
        ``TRUNCATE_SIGMA`` and ``holdout`` when it is set."""
        out = {"trials": self.trials, "corners": self.corners, "seed": self.seed,
               "holdout_trials": self.holdout_trials, **dataclasses.asdict(self.perturbation)}
        if self.truncate_sigma != TRUNCATE_SIGMA:
            out["truncate_sigma"] = self.truncate_sigma
        if self.holdout is not None:
            out["holdout"] = self.holdout
        return out


def as_verify_settings(settings) -> VerifySettings:
    """``settings`` as a :class:`VerifySettings`: one as it is, ``None`` as the
    schema's, and a flat dict of :meth:`VerifySettings.as_dict` keys (whole or
    partial) read with :meth:`VerifySettings.from_section`: the dicts that
    callers not yet switched to the typed settings still pass."""
    if isinstance(settings, VerifySettings):
        return settings
    return VerifySettings.from_section(settings)


@dataclass(frozen=True)
class KernelSettings:
    """The rollout kernel's integrator step (``sweep.kernel``): the largest
    step ``ds_max`` (units of a) and the tolerance ``tol``; ``None``: the
    kernel's own default."""

    ds_max: float | None = None
    tol: float | None = None

    @classmethod
    def from_section(cls, section) -> "KernelSettings":
        """The step of a ``sweep.kernel`` section (``None`` or ``{}``: the kernel's defaults)."""
        section = section or {}
        return cls(section.get("ds_max"), section.get("tol"))

    def with_defaults(self, ds_max: float, tol: float) -> "KernelSettings":
        """The same step with ``ds_max`` and ``tol`` where it leaves them to the kernel."""
        return KernelSettings(ds_max if self.ds_max is None else self.ds_max, tol if self.tol is None else self.tol)

    def as_kwargs(self) -> dict:
        """The keywords of a rollout: ``ds_max`` and ``tol``, those that are set."""
        return {k: v for k, v in (("ds_max", self.ds_max), ("tol", self.tol)) if v is not None}


def as_kernel_settings(kernel) -> KernelSettings:
    """``kernel`` as a :class:`KernelSettings`: one as it is, ``None`` as the
    kernel's defaults, a dict (``ds_max``, ``tol``; other keys ignored) read
    with :meth:`KernelSettings.from_section`: the dicts that callers not yet
    switched to the typed settings still pass."""
    if isinstance(kernel, KernelSettings):
        return kernel
    return KernelSettings.from_section(kernel)


def check_tolerance(value, what: str = "tolerance (--tolerance, planner.tolerance_deg)") -> float:
    """The tolerance as a float in (0, 360) degrees, or a one-line :class:`PinfeedError`."""
    try:
        tol = float(value)
    except (TypeError, ValueError):
        raise PinfeedError(f"{what} {value!r} is not a number; give degrees, e.g. 10") from None
    if not (math.isfinite(tol) and 0.0 < tol < 360.0):
        raise PinfeedError(f"{what} must be more than 0 and less than 360 degrees, got {value!r}")
    return tol


def check_required(value) -> float:
    """``verify.required`` as a share in (0, 1], or a one-line :class:`PinfeedError`."""
    req = float(value)
    if not (0.0 < req <= 1.0):
        raise PinfeedError(f"verify.required must be a share in (0, 1], e.g. 0.995; got {value!r}")
    return req


RULES = ("bound", "point")  # verify.rule


def check_rule(value) -> str:
    """``verify.rule`` (``bound`` or ``point``), or a one-line :class:`PinfeedError`."""
    if value not in RULES:
        raise PinfeedError(f"verify.rule must be 'bound' (the confidence bound, default) or 'point' "
                           f"(the sample's share alone); got {value!r}")
    return value


def check_confidence(value, what: str = "verify.confidence") -> float:
    """A confidence level as a float strictly between 0 and 1, or a one-line error."""
    try:
        c = float(value)
    except (TypeError, ValueError):
        raise PinfeedError(f"{what} {value!r} is not a number; give a share such as 0.95") from None
    if not (math.isfinite(c) and 0.0 < c < 1.0):
        raise PinfeedError(f"{what} must lie strictly between 0 and 1 (e.g. 0.95); got {value!r}")
    return c


@dataclass(frozen=True)
class ClaimSettings:
    """What "orients" means: ``required`` of the trials in one set at most
    ``tolerance_deg`` wide, with ``confidence`` (``rule`` ``bound``) or on the
    share alone (``point``). Checked when made (one-line :class:`PinfeedError`)."""

    tolerance_deg: float = _default("planner", "tolerance_deg")
    required: float = _default("verify", "required")
    confidence: float = _default("verify", "confidence")
    rule: str = _default("verify", "rule")

    def __post_init__(self):
        object.__setattr__(self, "tolerance_deg", check_tolerance(self.tolerance_deg))
        object.__setattr__(self, "required", check_required(self.required))
        object.__setattr__(self, "confidence", check_confidence(self.confidence))
        object.__setattr__(self, "rule", check_rule(self.rule))


@dataclass(frozen=True)
class SearchSettings:
    """How the planners search: candidate ``pins`` (heights in mm, or ``"auto"``
    fitted to the part), ``depth``, the contact-parameter limits, the
    mechanics (``model``, ``pin_radius``, kernel step ``ds_max`` and ``tol``),
    the belt (``belt_speed`` mm/s, ``None`` quasi-static; ``mu_s``), moving
    pins (``dynamic_speeds``, ``dynamic_depth``, ``beam``), the search's
    sizes and ranking slack, the support family, the outline's shape
    tolerance (mm; ``None``: no shape check) and the time limit of one
    part's planning (``time_limit_s``, seconds; ``None``: none, the complete
    search; checked when made)."""

    pin_radius: float  # sweep.pin_radius (mm), which the config must give
    pins: object = _default("planner", "pins")
    depth: int = _default("planner", "depth")
    d_min: float = _default("planner", "d_min")
    d_max: float = _default("planner", "d_max")
    hard_d_limits: bool = _default("planner", "hard_d_limits")
    model: str = _default("planner", "model")
    kernel: tuple = ()  # ((key, value), ...) of sweep.kernel: ds_max, tol
    belt_speed: float | None = _default("planner", "belt_speed")
    mu_s: float = _default("planner", "mu_s")
    dynamic_speeds: tuple = ()
    dynamic_depth: int = _default("planner", "dynamic", "depth")
    beam: int = _default("planner", "dynamic", "beam")
    candidates: int = _default("planner", "candidates")
    max_branches: int = _default("planner", "max_branches")
    width_slack_deg: float = _default("planner", "width_slack_deg")
    worst_member_budget: int = _default("planner", "worst_member_budget")
    paper_depth: int = _default("planner", "paper_depth")
    coverage: str = _default("planner", "coverage")
    support_family: object = _default("planner", "support_family")
    shape_tolerance_mm: float | None = _default("planner", "shape_tolerance_mm")
    time_limit_s: float | None = _default("planner", "time_limit_s")

    def __post_init__(self):
        object.__setattr__(self, "time_limit_s", check_time_limit(self.time_limit_s))

    @property
    def kernel_step(self) -> KernelSettings:
        """The kernel's step settings (``ds_max``, ``tol``)."""
        return KernelSettings.from_section(dict(self.kernel))

    @property
    def kernel_settings(self) -> dict:
        """The kernel's step settings as a dict, for callers not yet switched to :attr:`kernel_step`."""
        return dict(self.kernel)

    @property
    def moving_speeds(self) -> list:
        """The moving pins' speed ratios the search may add (none at dynamic depth 0)."""
        return list(self.dynamic_speeds) if self.dynamic_depth else []


@dataclass(frozen=True)
class SpeedSettings:
    """How a plan's speed limit is found (``speed`` section): belt friction
    ``mu_s``, ``trials`` per resting state, the ``speeds`` tried (mm/s),
    bisection ``resolution`` (mm/s), ``required`` share and ``seed``."""

    mu_s: float = _default("speed", "mu_s")
    trials: int = _default("speed", "trials")
    speeds: tuple = tuple(float(v) for v in schema_default("speed", "speeds"))
    resolution: float = _default("speed", "resolution")
    required: float = _default("speed", "required")
    seed: int = _default("speed", "seed")

    @classmethod
    def from_json(cls, record: dict) -> "SpeedSettings":
        """The settings a stored speed limit keeps (:meth:`to_json`; the schema's for any it lacks)."""
        d = dict(cls().to_json(), **record)
        return cls(float(d["mu_s"]), int(d["trials"]), tuple(float(v) for v in d["speeds"]),
                   float(d["resolution"]), float(d["required"]), int(d["seed"]))

    def to_json(self) -> dict:
        """The settings as a speed limit stored with a plan keeps them (``speed_limit.settings``)."""
        return {"mu_s": float(self.mu_s), "trials": int(self.trials), "speeds": [float(v) for v in self.speeds],
                "resolution": float(self.resolution), "required": float(self.required),
                "seed": int(self.seed)}


@dataclass(frozen=True)
class SpeedPerturbation:
    """The uniform half-widths of a speed limit's trials: orientation
    ``theta_deg`` (deg), centroid height ``y_mm`` and pin position ``pin_mm`` (mm)."""

    theta_deg: float = 1.0
    y_mm: float = 0.5
    pin_mm: float = 0.2

    @classmethod
    def from_verify(cls, perturbation: Perturbation) -> "SpeedPerturbation":
        """The box of the verification's perturbation sizes: orientation +-
        ``TRUNCATE_SIGMA`` sigma (verification truncates its normal there),
        centroid height and pin position as verified."""
        return cls(TRUNCATE_SIGMA * perturbation.theta_sigma, perturbation.y_halfwidth, perturbation.pin_halfwidth)

    @classmethod
    def from_section(cls, section) -> "SpeedPerturbation":
        """A dict of half-widths (``theta_deg``, ``y_mm``, ``pin_mm``; 0 where one is absent)."""
        return cls(section.get("theta_deg", 0.0), section.get("y_mm", 0.0), section.get("pin_mm", 0.0))


def _layout_number(key: str, value) -> float:
    """A layout setting as a finite number, or a one-line :class:`PinfeedError`."""
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise PinfeedError(f"layout setting {key} must be a finite number, got {value!r}")
    return float(value)


LAYOUT_MARGINS = ("station_margin_mm", "pitch_margin_mm", "belt_margin_mm")


@dataclass(frozen=True)
class LayoutSettings:
    """The feeder's layout (``layout`` section): ``trials`` per resting state
    (and the box ``corners``), the ``seed``, the station, pitch and belt
    margins (mm), the belt at ``speed_fraction`` of the plan's speed limit
    (found with ``speed_trials`` trials per state at belt friction ``mu_s``),
    the clock's ``time_step_mm`` and the slabs' height ``slab_mm``. Values are
    kept as given; a negative margin or a bad count or step is a one-line
    :class:`PinfeedError` when made."""

    trials: int = _default("layout", "trials")
    corners: bool = _default("layout", "corners")
    station_margin_mm: float = _default("layout", "station_margin_mm")
    pitch_margin_mm: float = _default("layout", "pitch_margin_mm")
    belt_margin_mm: float = _default("layout", "belt_margin_mm")
    speed_fraction: float = _default("layout", "speed_fraction")
    speed_trials: int = _default("layout", "speed_trials")
    mu_s: float = _default("layout", "mu_s")
    time_step_mm: float = _default("layout", "time_step_mm")
    slab_mm: float = _default("layout", "slab_mm")
    seed: int = _default("layout", "seed")

    def __post_init__(self):
        for key in LAYOUT_MARGINS:
            if _layout_number(key, getattr(self, key)) < 0:
                raise PinfeedError(f"layout margin {key} must be a length >= 0 mm, got {getattr(self, key)!r}")
        for key in ("time_step_mm", "slab_mm"):
            if _layout_number(key, getattr(self, key)) <= 0:
                raise PinfeedError(f"layout setting {key} must be > 0 mm, got {getattr(self, key)!r}")
        if not 0 < _layout_number("speed_fraction", self.speed_fraction) <= 1:
            raise PinfeedError(f"layout speed_fraction must be in (0, 1], got {self.speed_fraction!r}")
        for key in ("trials", "speed_trials"):
            value = getattr(self, key)
            if isinstance(value, bool) or not isinstance(value, int) or value < 1:
                raise PinfeedError(f"layout {key} must be a whole number >= 1, got {value!r}")

    @classmethod
    def from_section(cls, section) -> "LayoutSettings":
        """The settings of a ``layout`` section with any overrides (whole or
        partial: the schema's defaults for what it leaves out), checked."""
        return cls(**dict(dataclasses.asdict(cls()), **(section or {})))

    @property
    def margins(self) -> dict:
        """The margins by name (mm), as given."""
        return {key: getattr(self, key) for key in LAYOUT_MARGINS}


DESIGN_KINDS = ("chamfer", "notch", "tab")  # the kinds of outline change design for feeding tries


@dataclass(frozen=True)
class DesignGrid:
    """The sizes of the outline changes design for feeding tries, as fractions
    of the part's size ``a``.

    Attributes
    ----------
    kinds : which kinds of change to try (of :data:`DESIGN_KINDS`).
    chamfer : chamfer legs (both the same), fractions of ``a``.
    notch, tab : ``(width, depth)`` pairs, fractions of ``a``.
    positions : where a notch or tab is centred along its edge (fractions of its length).
    """

    kinds: tuple = DESIGN_KINDS
    chamfer: tuple = (0.05, 0.1, 0.15, 0.2)
    notch: tuple = ((0.1, 0.05), (0.2, 0.1))
    tab: tuple = ((0.1, 0.05), (0.2, 0.1))
    positions: tuple = (0.5,)


@dataclass(frozen=True)
class DesignLimits:
    """What the user allows: ``keep_edges`` (edges that must not change),
    ``min_wall_mm`` (material left behind every new edge) and ``max_change``
    (largest area removed or added, a fraction of the part's area)."""

    keep_edges: tuple = ()
    min_wall_mm: float = 1.0
    max_change: float = 0.1


@dataclass(frozen=True)
class DesignSettings:
    """The design search: the changes tried (:class:`DesignGrid`), the user's
    :class:`DesignLimits` and the planner's ``depth`` (``None``: the planner's own)."""

    grid: DesignGrid = field(default_factory=DesignGrid)
    limits: DesignLimits = field(default_factory=DesignLimits)
    depth: int | None = None

    @classmethod
    def from_section(cls, design: dict, keep_edges=()) -> "DesignSettings":
        """The settings of a validated config's ``design`` section, with the edges to keep."""
        grid = DesignGrid(kinds=tuple(design["kinds"]), chamfer=tuple(design["chamfer"]),
                          notch=tuple(tuple(p) for p in design["notch"]),
                          tab=tuple(tuple(p) for p in design["tab"]),
                          positions=tuple(design["positions"]))
        limits = DesignLimits(keep_edges=tuple(int(k) for k in keep_edges),
                              min_wall_mm=float(design["min_wall_mm"]), max_change=float(design["max_change"]))
        return cls(grid=grid, limits=limits, depth=design.get("depth"))

    def check(self, n_edges: int) -> None:
        """One-line :class:`PinfeedError` for a setting this outline cannot take."""
        bad = [k for k in self.limits.keep_edges if not 0 <= k < n_edges]
        if bad:
            raise PinfeedError(f"--keep-edges {bad[0]}: the outline has edges 0 to {n_edges - 1}")
        if not 0 < self.limits.max_change <= 1:
            raise PinfeedError(f"--max-change must be a fraction in (0, 1], got {self.limits.max_change:g}")
        if not (math.isfinite(self.limits.min_wall_mm) and self.limits.min_wall_mm >= 0):
            raise PinfeedError(f"--min-wall must be a length >= 0 mm, got {self.limits.min_wall_mm:g}")
        unknown = [k for k in self.grid.kinds if k not in DESIGN_KINDS]
        if unknown or not self.grid.kinds:
            raise PinfeedError(f"--kinds {','.join(self.grid.kinds)}: choose from {','.join(DESIGN_KINDS)}")
        if self.depth is not None and self.depth < 1:
            raise PinfeedError(f"--depth must be at least 1, got {self.depth}")


@dataclass(frozen=True)
class BandSettings:
    """The paper's bands of a map (``bands`` section): a theta_f jump larger
    than ``threshold_T`` (deg) splits bands; adjusted bands are ``factor_c``
    circular standard deviations wide either side of the mean."""

    threshold_T: float = _default("bands", "threshold_T")
    factor_c: float = _default("bands", "factor_c")


@dataclass(frozen=True)
class PlannerSettings:
    """Everything planning reads, made once from a validated config.

    ``friction`` is the friction the recommended plans must work for
    (``planner.mu_c``) and ``frictions`` every friction planned at (it first,
    then ``planner.frictions``); ``swept_frictions`` the map grid
    (``sweep.mu_c``), ``swept_d`` its contact parameters and
    ``swept_theta_step`` its theta_i step (deg); ``parts`` the planned parts."""

    search: SearchSettings
    friction: Friction = field(default_factory=lambda: Friction.parse(schema_default("planner", "mu_c")))
    frictions: tuple = ()
    claims: ClaimSettings = field(default_factory=ClaimSettings)
    verify: VerifySettings = field(default_factory=VerifySettings)
    speed: SpeedSettings = field(default_factory=SpeedSettings)
    bands: BandSettings = field(default_factory=BandSettings)
    swept_frictions: tuple = ()
    swept_d: tuple = ()
    swept_theta_step: float = 1.0
    parts: tuple = ()

    @classmethod
    def from_config(cls, config: dict) -> "PlannerSettings":
        """The settings of a validated config (:func:`pipeline.config.validate_config`)."""
        pc, sweep, vc, sc = config["planner"], config["sweep"], config["verify"], config["speed"]
        sigma = float(vc["mu_sigma"])
        friction = Friction.parse(pc["mu_c"], sigma)
        frictions = [friction]
        for f in pc.get("frictions") or []:
            f = Friction.parse(f, sigma)
            if f.value not in [g.value for g in frictions]:
                frictions.append(f)
        dyn = pc["dynamic"]
        pins = pc["pins"] if pc["pins"] in (None, "auto") else tuple(float(y) for y in pc["pins"])
        search = SearchSettings(
            pin_radius=float(sweep["pin_radius"]), pins=pins, depth=int(pc["depth"]), d_min=float(pc["d_min"]), d_max=float(pc["d_max"]),
            hard_d_limits=bool(pc["hard_d_limits"]), model=pc["model"], kernel=tuple(sorted((sweep.get("kernel") or {}).items())),
            belt_speed=None if pc["belt_speed"] is None else float(pc["belt_speed"]), mu_s=float(pc["mu_s"]),
            dynamic_speeds=tuple(float(v) for v in dyn["speeds"]), dynamic_depth=int(dyn["depth"]),
            beam=int(dyn["beam"]), candidates=int(pc["candidates"]), max_branches=int(pc["max_branches"]),
            width_slack_deg=float(pc["width_slack_deg"]), worst_member_budget=int(pc["worst_member_budget"]),
            paper_depth=int(pc["paper_depth"]), coverage=pc["coverage"], support_family=pc.get("support_family"),
            shape_tolerance_mm=pc.get("shape_tolerance_mm"), time_limit_s=pc.get("time_limit_s"))
        claims = ClaimSettings(pc["tolerance_deg"], vc["required"], vc["confidence"], vc["rule"])
        verify = VerifySettings(int(vc["trials"]), bool(vc["corners"]), int(vc["seed"]), vc["holdout_trials"],
                                Perturbation(float(vc["theta_sigma"]), float(vc["y_halfwidth"]), sigma,
                                             float(vc["pin_halfwidth"])))
        speed = SpeedSettings(float(sc["mu_s"]), int(sc["trials"]), tuple(float(v) for v in sc["speeds"]),
                              float(sc["resolution"]), float(sc["required"]), int(sc["seed"]))
        bands = BandSettings(float(config["bands"]["threshold_T"]), float(config["bands"]["factor_c"]))
        return cls(search, friction, tuple(frictions), claims, verify, speed, bands,
                   tuple(float(m) for m in sweep["mu_c"]), tuple(float(d) for d in sweep["d"]),
                   float(sweep["theta_step"]), tuple(pc["parts"]))

    def without_moving_pins(self) -> "PlannerSettings":
        """The same settings with fixed pins only (moving-pin depth 0)."""
        return dataclasses.replace(self, search=dataclasses.replace(self.search, dynamic_depth=0))

    def at(self, friction: Friction) -> "PlannerSettings":
        """The same settings planning at ``friction``."""
        return dataclasses.replace(self, friction=Friction.parse(friction, self.verify.perturbation.mu_sigma))
