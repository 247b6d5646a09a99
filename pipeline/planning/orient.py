"""Does a plan orient the part, and how precisely? Judged on final orientations.

A plan *orients* a part within a tolerance ``T`` (degrees, the full width a
final set may have) when at least the required share of its trials (jams
count as failures) end in one arc no wider than ``T``, on the circle of the
part's distinct orientations: a part with ``order``-fold rotational symmetry
looks the same every ``360 / order`` degrees, so its orientations are taken
modulo that period. The functions below work on arrays of orientations
(degrees) and share nothing with the planner's propagation.

The *verified width* of a set of trials is the width of the narrowest arc
that holds the required share of them; a plan orients exactly when its
verified width is at most ``T``.
"""
from __future__ import annotations

import math

import numpy as np

from pipeline.errors import PinfeedError

DEFAULT_TOLERANCE = 10.0  # deg: planner.tolerance_deg
DEFAULT_REQUIRED = 0.995  # verify.required: share of trials that must end in the set


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


def needed(n_trials: int, required: float) -> int:
    """How many of ``n_trials`` must end in the set (the required share, rounded up)."""
    return int(math.ceil(required * n_trials - 1e-9))


def _doubled(theta, period):
    """Sorted orientations modulo ``period``, followed by the same plus ``period``
    (so an arc through the period's end is a plain window)."""
    x = np.sort(np.mod(np.asarray(theta, dtype=float), period))
    return x, np.concatenate([x, x + period])


def best_arc(theta, width: float, order: int = 1) -> tuple[int, float]:
    """``(count, start)``: the most orientations one arc of ``width`` degrees
    holds (modulo ``360 / order``) and where that arc starts."""
    period = 360.0 / order
    x, x2 = _doubled(theta, period)
    if x.size == 0:
        return 0, 0.0
    if width >= period:
        return int(x.size), 0.0
    counts = np.searchsorted(x2, x + width + 1e-9, side="right") - np.arange(x.size)
    i = int(np.argmax(counts))
    return int(counts[i]), float(x[i])


def narrowest_arc(theta, k: int, order: int = 1) -> tuple[float, float] | None:
    """``(start, width)`` of the narrowest arc holding ``k`` of the orientations
    (modulo ``360 / order``); ``None`` when there are fewer than ``k``."""
    period = 360.0 / order
    x, x2 = _doubled(theta, period)
    n = x.size
    if k <= 0:
        return (0.0, 0.0)
    if n < k:
        return None
    widths = x2[k - 1:k - 1 + n] - x
    i = int(np.argmin(widths))
    return float(x[i]), float(min(widths[i], period))


def arcs_to_cover(theta, width: float, order: int = 1) -> int:
    """Fewest arcs of ``width`` degrees that hold every orientation (modulo
    ``360 / order``): greedy from every possible first point, which is exact on
    the circle."""
    period = 360.0 / order
    x, x2 = _doubled(theta, period)
    n = x.size
    if n == 0:
        return 0
    if width >= period:
        return 1
    best = n
    for i in range(n):
        count, j = 0, i
        while j < i + n:
            count += 1
            j = int(np.searchsorted(x2, x2[j] + width + 1e-9, side="right"))
            if count >= best:
                break
        best = min(best, count)
    return best


def row_spans(theta: np.ndarray, order: int = 1) -> np.ndarray:
    """Per row of ``theta`` (n, k): the width of the narrowest arc holding all
    k orientations (modulo ``360 / order``), i.e. the period minus the largest gap."""
    period = 360.0 / order
    x = np.sort(np.mod(theta, period), axis=1)
    gaps = np.diff(np.concatenate([x, x[:, :1] + period], axis=1), axis=1)
    return period - gaps.max(axis=1)


def judge(finals, n_trials: int, tolerance: float, order: int = 1,
          required: float = DEFAULT_REQUIRED) -> dict:
    """The orientation verdict on trials: ``finals`` are the final orientations
    of the trials that did not jam, ``n_trials`` all trials.

    Returns ``orients``, ``trials``, ``jammed`` (trials that are not in
    ``finals``), ``in_tolerance`` (the most trials one arc of the
    tolerance holds), ``needed``, ``width_deg`` (the verified width: the
    narrowest arc holding the needed trials; ``None`` if too many jammed),
    ``set`` (that arc, ``{"start", "width"}``), ``spread_deg`` (the narrowest arc
    holding every trial that did not jam) and ``sets_within_tolerance`` (the
    fewest arcs of the tolerance holding every such trial)."""
    finals = np.asarray(finals, dtype=float)
    need = needed(n_trials, required)
    count, _ = best_arc(finals, tolerance, order)
    arc = narrowest_arc(finals, need, order)
    spread = narrowest_arc(finals, finals.size, order)
    return {"orients": bool(count >= need and n_trials > 0), "trials": int(n_trials),
            "jammed": int(n_trials - finals.size), "tolerance_deg": float(tolerance),
            "required": float(required), "in_tolerance": int(count), "needed": need,
            "width_deg": None if arc is None else round(arc[1], 4),
            "set": None if arc is None else {"start": round(arc[0], 4), "width": round(arc[1], 4)},
            "spread_deg": None if spread is None else round(spread[1], 4),
            "sets_within_tolerance": arcs_to_cover(finals, tolerance, order)}


def judge_verification(result: dict, tolerance: float, order: int = 1,
                       required: float = DEFAULT_REQUIRED) -> dict:
    """:func:`judge` on the trials of a ``verify.verify_plan`` result (its
    ``trials_detail``; jammed trials count as failures)."""
    finals = [t["final_theta"] for t in result["trials_detail"] if not t["reason"].startswith("jammed")]
    return judge(finals, result["trials"], tolerance, order, required)
