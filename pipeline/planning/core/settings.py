"""The planner's settings, built once from the validated config.

:class:`PlannerSettings` (:meth:`PlannerSettings.from_config`, the one place
a config's ``planner``, ``verify``, ``speed`` and ``sweep`` sections are
read for planning) is a frozen tree of typed parts: :class:`Friction` (the
friction a plan must work for: a value or a range, its sigma and the
truncation both widenings use), :class:`Perturbation` and
:class:`VerifySettings` (the trials), :class:`ClaimSettings` (tolerance,
required share, confidence, rule), :class:`SearchSettings` (pins, depth,
limits in d, model, belt, moving pins) and :class:`SpeedSettings`. Every
default comes from ``config/schema.yaml`` (:func:`pipeline.config.schema_default`).

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


@dataclass(frozen=True)
class VerifySettings:
    """The perturbed trials a plan is replayed on: ``trials`` per resting state,
    the perturbation box's ``corners``, the ``seed``, and ``holdout_trials``
    (``None``: as many as ``trials``) for the held-out trials that certify it."""

    trials: int = _default("verify", "trials")
    corners: bool = _default("verify", "corners")
    seed: int = _default("verify", "seed")
    holdout_trials: int | None = _default("verify", "holdout_trials")
    perturbation: Perturbation = field(default_factory=Perturbation)

    def as_dict(self) -> dict:
        """The flat dict of the trial drawing functions (``claims.verify``)."""
        return {"trials": self.trials, "corners": self.corners, "seed": self.seed,
                "holdout_trials": self.holdout_trials, **dataclasses.asdict(self.perturbation)}


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
    def kernel_settings(self) -> dict:
        """The kernel's step settings as keyword arguments (``ds_max``, ``tol``)."""
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

    def as_kwargs(self) -> dict:
        """Keyword arguments of ``stored_plan_speed``."""
        return {"mu_s": float(self.mu_s), "trials": int(self.trials), "speeds": [float(v) for v in self.speeds],
                "resolution": float(self.resolution), "required": float(self.required),
                "seed": int(self.seed)}


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
