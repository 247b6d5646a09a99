"""The planner's settings as the config and the command line give them.

Friction as a value or a range ``LO:HI`` (``parse_friction``, its label and
its nominal value) and the global pin labels ``P1, P2, ...`` of the
configured pin heights, or of heights fitted to the part (``fitted_pins``)
when none are configured. Both planners (``paper.py`` and ``plan.py``) and
everything downstream read these here, so neither planner imports the other
for them.
"""
from __future__ import annotations

import math

import numpy as np

from pipeline.errors import PinfeedError


def parse_friction(value):
    """``0.15`` -> 0.15; ``"0.1:0.3"`` or ``[0.1, 0.3]`` -> ``(0.1, 0.3)``. Raises
    :class:`PinfeedError` for negative, non-finite or reversed values."""
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
    if isinstance(mu_c, tuple):
        return f"{mu_c[0]:g}:{mu_c[1]:g}"
    return f"{mu_c:g}"


def nominal_friction(mu_c) -> float:
    """One friction value to draw nominal paths with: the value or the range's middle."""
    return 0.5 * (mu_c[0] + mu_c[1]) if isinstance(mu_c, tuple) else float(mu_c)


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


def candidate_pins(part, planner: dict) -> dict:
    """The planner's candidate fixed pins for ``part``: ``planner.pins`` when the
    config (or ``--pins``) lists heights, else :func:`fitted_pins` (``pins``
    absent, null or ``auto``)."""
    pins = planner.get("pins")
    if pins is None or pins == "auto":
        return fitted_pins(part)
    return pins_from_config(pins)
