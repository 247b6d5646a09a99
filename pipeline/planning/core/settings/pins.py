"""The global pin labels ``P1, P2, ...`` of the configured pin heights, or of
heights fitted to the part (:func:`fitted_pins`) when none are configured."""
from __future__ import annotations

import math

import numpy as np


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
