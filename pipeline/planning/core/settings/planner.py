"""How the planners search (:class:`SearchSettings`), the paper's bands
(:class:`BandSettings`) and :class:`PlannerSettings`, the frozen tree of
every typed part that :meth:`PlannerSettings.from_config` makes once from a
validated config."""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field

from pipeline.checks import check_time_limit
from pipeline.config import schema_default
from pipeline.planning.core.settings.claim_rules import ClaimSettings
from pipeline.planning.core.settings.defaults import schema_value
from pipeline.planning.core.settings.friction import Friction
from pipeline.planning.core.settings.stages import SpeedSettings
from pipeline.planning.core.settings.trials import KernelSettings, Perturbation, VerifySettings


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
    pins: object = schema_value("planner", "pins")
    depth: int = schema_value("planner", "depth")
    d_min: float = schema_value("planner", "d_min")
    d_max: float = schema_value("planner", "d_max")
    hard_d_limits: bool = schema_value("planner", "hard_d_limits")
    model: str = schema_value("planner", "model")
    kernel: tuple = ()  # ((key, value), ...) of sweep.kernel: ds_max, tol
    belt_speed: float | None = schema_value("planner", "belt_speed")
    mu_s: float = schema_value("planner", "mu_s")
    dynamic_speeds: tuple = ()
    dynamic_depth: int = schema_value("planner", "dynamic", "depth")
    beam: int = schema_value("planner", "dynamic", "beam")
    candidates: int = schema_value("planner", "candidates")
    max_branches: int = schema_value("planner", "max_branches")
    width_slack_deg: float = schema_value("planner", "width_slack_deg")
    worst_member_budget: int = schema_value("planner", "worst_member_budget")
    paper_depth: int = schema_value("planner", "paper_depth")
    coverage: str = schema_value("planner", "coverage")
    support_family: object = schema_value("planner", "support_family")
    shape_tolerance_mm: float | None = schema_value("planner", "shape_tolerance_mm")
    time_limit_s: float | None = schema_value("planner", "time_limit_s")

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
class BandSettings:
    """The paper's bands of a map (``bands`` section): a theta_f jump larger
    than ``threshold_T`` (deg) splits bands; adjusted bands are ``factor_c``
    circular standard deviations wide either side of the mean."""

    threshold_T: float = schema_value("bands", "threshold_T")
    factor_c: float = schema_value("bands", "factor_c")


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
