"""The friction a plan must work for: its text, its label, its nominal value
and the typed :class:`Friction` (a value or a range, its sigma and the
truncation both widenings use).

Three frictions have three names: the planner's ``friction`` (a
:class:`Friction`, ``planner.mu_c``), the sweep's ``swept_frictions`` (the
grid of map frictions, ``sweep.mu_c``) and the per-trial ``trial_mu`` (the
array each verification trial draws).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

from pipeline.errors import PinfeedError
from pipeline.planning.core.settings.defaults import schema_value
from pipeline.planning.core.settings.trials import TRUNCATE_SIGMA


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


@dataclass(frozen=True)
class Friction:
    """The pin friction a plan must work for: ``lo == hi`` for one value, or a
    range ``[lo, hi]`` (then the range is the uncertainty). ``sigma`` is the
    spread of a single value (``verify.mu_sigma``); both the planner's box and
    the verification's draws stop at ``truncate`` sigma."""

    lo: float
    hi: float
    sigma: float = schema_value("verify", "mu_sigma")
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

