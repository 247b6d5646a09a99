"""Does a plan orient the part, and how precisely? Judged on final orientations.

A plan *orients* a part within a tolerance ``T`` (degrees, the full width a
final set may have) when, with confidence ``verify.confidence`` (default
95 %), at least the required share ``verify.required`` of the trials it
would ever meet end in one arc no wider than ``T``: the one-sided
Clopper-Pearson lower bound on the share of its trials in the best arc of
``T`` (jams count as failures) is at least ``verify.required``
(:mod:`pipeline.planning.claims.confidence`). The *point rule* (the measured share
itself at least ``verify.required``) is reported beside it: a plan that
clears the point rule but not the bound is a near miss, ranked after the
plans that clear both. Orientations are taken on the circle of the part's
distinct orientations: a part with ``order``-fold rotational symmetry looks
the same every ``360 / order`` degrees. The functions below work on arrays
of orientations (degrees) and share nothing with the planner's propagation.

The *verified width* of a set of trials is the width of the narrowest arc
that holds the required share of them; its bootstrap interval
(:func:`pipeline.planning.claims.confidence.width_interval`) says how well the
trials pin it down.
"""
from __future__ import annotations

import math

import numpy as np

from pipeline.config import schema_default
from pipeline.planning.claims.confidence import DEFAULT_CONFIDENCE, share_lower_bound, width_interval
from pipeline.planning.core.settings import (RULES, check_confidence, check_required,  # noqa: F401 (re-exported)
                                             check_rule, check_tolerance)

DEFAULT_TOLERANCE = schema_default("planner", "tolerance_deg")  # deg
DEFAULT_REQUIRED = schema_default("verify", "required")  # share of trials that must end in the set


def needed(n_trials: int, required: float) -> int:
    """How many of ``n_trials`` must end in the set (the required share, rounded up)."""
    return int(math.ceil(required * n_trials - 1e-9))




def max_failures(n_trials: int, required: float, confidence: float = DEFAULT_CONFIDENCE,
                 rule: str = "bound") -> int:
    """The most failures ``n_trials`` trials may have and still orient the part:
    the largest ``f`` whose share ``(n - f) / n`` has a lower confidence bound
    of at least ``required`` (under ``rule`` ``point``: the share itself); -1
    when even no failure is enough, i.e. too few trials for the claim."""
    n = int(n_trials)
    f = n - needed(n, required)  # the point rule's allowance; the bound allows no more
    while rule == "bound" and f >= 0 and share_lower_bound(n - f, n, confidence) < required:
        f -= 1
    return f


def min_trials(required: float, confidence: float = DEFAULT_CONFIDENCE) -> int:
    """The fewest trials whose every success gives a share lower bound of at
    least ``required`` at ``confidence`` (the bound rule's floor).

    Notes
    -----
    With no failure the one-sided Clopper-Pearson bound is
    ``(1 - confidence) ** (1 / n)``, so ``n >= ln(1 - confidence) / ln(required)``.
    """
    n = max(1, math.ceil(math.log(1.0 - check_confidence(confidence)) / math.log(required)))
    while share_lower_bound(n, n, confidence) < required:  # guard the closed form's rounding
        n += 1
    return n


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
    the circle. All the greedy walks step together: each point's next
    uncovered point is looked up once."""
    period = 360.0 / order
    x, x2 = _doubled(theta, period)
    n = x.size
    if n == 0:
        return 0
    if width >= period:
        return 1
    after = np.searchsorted(x2, x2 + width + 1e-9, side="right")  # the first point past an arc from each
    start = np.arange(n)
    at, count = start.copy(), np.zeros(n, dtype=np.int64)
    walking = np.ones(n, dtype=bool)
    while walking.any():
        count[walking] += 1
        at[walking] = after[at[walking]]
        walking &= at < start + n
    return int(count.min())


def row_spans(theta: np.ndarray, order: int = 1) -> np.ndarray:
    """Per row of ``theta`` (n, k): the width of the narrowest arc holding all
    k orientations (modulo ``360 / order``), i.e. the period minus the largest gap."""
    period = 360.0 / order
    x = np.sort(np.mod(theta, period), axis=1)
    gaps = np.diff(np.concatenate([x, x[:, :1] + period], axis=1), axis=1)
    return period - gaps.max(axis=1)


def judge(finals, n_trials: int, tolerance: float, order: int = 1,
          required: float = DEFAULT_REQUIRED, confidence: float = DEFAULT_CONFIDENCE,
          interval: bool = False, rule: str = "bound") -> dict:
    """The orientation verdict on trials: ``finals`` are the final orientations
    of the trials that did not jam, ``n_trials`` all trials.

    Returns ``orients`` (the lower confidence bound on the share in one arc of
    the tolerance is at least ``required``), ``point_rule`` (the share itself
    is), ``share`` and ``share_lower_bound`` (at ``confidence``), ``trials``,
    ``jammed`` (trials that are not in ``finals``), ``in_tolerance`` (the most
    trials one arc of the tolerance holds), ``needed`` (the point rule's count),
    ``width_deg`` (the verified width: the narrowest arc holding the needed
    trials; ``None`` if too many jammed), ``set`` (that arc, ``{"start",
    "width"}``), ``spread_deg`` (the narrowest arc holding every trial that did
    not jam) and ``sets_within_tolerance`` (the fewest arcs of the tolerance
    holding every such trial). With ``interval``, also ``width_interval_deg``:
    the verified width's two-sided bootstrap interval at ``confidence``. Under
    ``rule`` ``point`` (``verify.rule``), ``orients`` is the point rule alone
    (for quick looks on few trials; no claim with confidence)."""
    finals = np.asarray(finals, dtype=float)
    confidence = check_confidence(confidence)
    need = needed(n_trials, required)
    count, _ = best_arc(finals, tolerance, order)
    arc = narrowest_arc(finals, need, order)
    spread = narrowest_arc(finals, finals.size, order)
    n = int(n_trials)
    lower = share_lower_bound(count, n, confidence) if n > 0 else 0.0
    point = bool(count >= need and n > 0)
    out = {"orients": bool(point and (rule == "point" or lower >= required)), "point_rule": point,
           "rule": check_rule(rule),
           "share": round(count / n, 6) if n else 0.0, "share_lower_bound": round(lower, 6),
           "confidence": confidence}
    if interval and n > 0:
        lo, hi = width_interval(finals, n, required, order, confidence)
        out["width_interval_deg"] = [_finite(lo), _finite(hi)]
    return {**out, "trials": int(n_trials),
            "jammed": int(n_trials - finals.size), "tolerance_deg": float(tolerance),
            "required": float(required), "in_tolerance": int(count), "needed": need,
            "width_deg": None if arc is None else round(arc[1], 4),
            "set": None if arc is None else {"start": round(arc[0], 4), "width": round(arc[1], 4)},
            "spread_deg": None if spread is None else round(spread[1], 4),
            "sets_within_tolerance": arcs_to_cover(finals, tolerance, order)}


def _finite(x: float):
    return round(float(x), 4) if math.isfinite(x) else None


def judge_verification(result: dict, tolerance: float, order: int = 1,
                       required: float = DEFAULT_REQUIRED,
                       confidence: float = DEFAULT_CONFIDENCE, rule: str = "bound") -> dict:
    """:func:`judge` on the trials of a ``verify.verify_plan`` result (its
    ``trials_detail``; jammed trials count as failures), with the verified
    width's bootstrap interval."""
    return judge(verification_finals(result), result["trials"], tolerance, order, required, confidence,
                 interval=True, rule=rule)


def verification_finals(result: dict) -> list:
    """The final orientations (deg) of the trials of a ``verify.verify_plan``
    result that did not jam."""
    return [t["final_theta"] for t in result["trials_detail"] if not t["reason"].startswith("jammed")]


def describe_claim(verdict: dict) -> str:
    """The verdict for people, in one line: the share in one set with its lower
    confidence bound, and the verified width with its bootstrap interval."""
    v = verdict
    c = v.get("confidence", DEFAULT_CONFIDENCE)
    text = (f"{v['in_tolerance']}/{v['trials']} trials ({100 * v.get('share', 0):.2f} %) in one set of "
            f"{v['tolerance_deg']:g} deg, at least {100 * v.get('share_lower_bound', 0):.2f} % with "
            f"{100 * c:g} % confidence (required {100 * v['required']:g} %)")
    if v.get("width_deg") is not None:
        text += f"; verified width {v['width_deg']:.1f} deg"
        iv = v.get("width_interval_deg")
        if iv and iv[0] is not None:
            text += (f" ({100 * c:g} % bootstrap interval {iv[0]:.1f}-"
                     + (f"{iv[1]:.1f}" if iv[1] is not None else "inf") + " deg)")
    if v.get("orients"):
        return text + (": orients the part" if v.get("rule", "bound") == "bound"
                       else ": orients the part by the point rule (no confidence claim)")
    if v.get("point_rule"):
        return text + ": clears the point rule but not its confidence bound (a near miss)"
    return text + ": does not orient the part"
