"""The settings of the stages that stand on plans: the speed limit
(:class:`SpeedSettings`, with the uniform box of its trials,
:class:`SpeedPerturbation`), the feeder's layout (:class:`LayoutSettings`)
and design for feeding (:class:`DesignSettings`, :class:`DesignGrid`,
:class:`DesignLimits`)."""
from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field

from pipeline.config import schema_default
from pipeline.errors import PinfeedError
from pipeline.planning.core.settings.defaults import schema_value
from pipeline.planning.core.settings.trials import TRUNCATE_SIGMA, Perturbation


@dataclass(frozen=True)
class SpeedSettings:
    """How a plan's speed limit is found (``speed`` section): belt friction
    ``mu_s``, ``trials`` per resting state, the ``speeds`` tried (mm/s),
    bisection ``resolution`` (mm/s), ``required`` share and ``seed``."""

    mu_s: float = schema_value("speed", "mu_s")
    trials: int = schema_value("speed", "trials")
    speeds: tuple = tuple(float(v) for v in schema_default("speed", "speeds"))
    resolution: float = schema_value("speed", "resolution")
    required: float = schema_value("speed", "required")
    seed: int = schema_value("speed", "seed")

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

    trials: int = schema_value("layout", "trials")
    corners: bool = schema_value("layout", "corners")
    station_margin_mm: float = schema_value("layout", "station_margin_mm")
    pitch_margin_mm: float = schema_value("layout", "pitch_margin_mm")
    belt_margin_mm: float = schema_value("layout", "belt_margin_mm")
    speed_fraction: float = schema_value("layout", "speed_fraction")
    speed_trials: int = schema_value("layout", "speed_trials")
    mu_s: float = schema_value("layout", "mu_s")
    time_step_mm: float = schema_value("layout", "time_step_mm")
    slab_mm: float = schema_value("layout", "slab_mm")
    seed: int = schema_value("layout", "seed")

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
