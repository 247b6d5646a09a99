"""What "orients" means: the checks of the tolerance, the required share,
the rule and the confidence, and the typed :class:`ClaimSettings` they guard."""
from __future__ import annotations

import math
from dataclasses import dataclass

from pipeline.errors import PinfeedError
from pipeline.planning.core.settings.defaults import schema_value


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

    tolerance_deg: float = schema_value("planner", "tolerance_deg")
    required: float = schema_value("verify", "required")
    confidence: float = schema_value("verify", "confidence")
    rule: str = schema_value("verify", "rule")

    def __post_init__(self):
        object.__setattr__(self, "tolerance_deg", check_tolerance(self.tolerance_deg))
        object.__setattr__(self, "required", check_required(self.required))
        object.__setattr__(self, "confidence", check_confidence(self.confidence))
        object.__setattr__(self, "rule", check_rule(self.rule))
