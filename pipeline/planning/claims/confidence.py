"""How sure a claim on sampled trials is: exact binomial bounds and a bootstrap.

A plan's verdict rests on a finite sample of trials (or of support family
members). A share measured on that sample is an estimate; the functions here
turn it into a statement with its uncertainty:

* :func:`share_lower_bound` and :func:`share_upper_bound`: one-sided
  Clopper-Pearson bounds on a binomial share from ``k`` successes in ``n``
  trials. They are exact (never below the stated confidence) and need no
  normal approximation, which fails next to a share of 1.
* :func:`width_interval`: a percentile bootstrap interval for the verified
  width (the narrowest arc holding the required share of trials).

Notes
-----
With ``k`` successes in ``n`` trials and confidence ``c``, the one-sided
lower bound is the ``1 - c`` quantile of ``Beta(k, n - k + 1)`` (0 when
``k = 0``) and the one-sided upper bound is the ``c`` quantile of
``Beta(k + 1, n - k)`` (1 when ``k = n``) [1]_. With no failure the lower
bound has the closed form ``(1 - c) ** (1 / n)``; with no success the upper
bound is ``1 - (1 - c) ** (1 / n)`` (the "rule of three" for ``c = 0.95``).

References
----------
.. [1] C. J. Clopper and E. S. Pearson, "The use of confidence or fiducial
   limits illustrated in the case of the binomial", Biometrika 26 (1934).
"""
from __future__ import annotations

import math

import numpy as np
from scipy.special import betaincinv  # beta.ppf's own function, without scipy.stats' import time

from pipeline.config import schema_default
from pipeline.errors import PinfeedError
from pipeline.planning.core.settings import check_confidence  # noqa: F401 (re-exported)

DEFAULT_CONFIDENCE = schema_default("verify", "confidence")


def _counts(k, n) -> tuple[int, int]:
    k, n = int(k), int(n)
    if n < 0 or not (0 <= k <= n):
        raise PinfeedError(f"a share needs 0 <= successes <= trials; got {k} of {n}")
    return k, n


def share_lower_bound(k, n, confidence: float = DEFAULT_CONFIDENCE) -> float:
    """One-sided Clopper-Pearson lower bound on the share behind ``k`` of ``n``.

    The true share is at least this with probability ``confidence`` (0 for no
    trial or no success)."""
    k, n = _counts(k, n)
    c = check_confidence(confidence)
    if k == 0:
        return 0.0
    return float(betaincinv(k, n - k + 1, 1.0 - c))


def share_upper_bound(k, n, confidence: float = DEFAULT_CONFIDENCE) -> float:
    """One-sided Clopper-Pearson upper bound on the share behind ``k`` of ``n``
    (1 for no trial or when every trial succeeded)."""
    k, n = _counts(k, n)
    c = check_confidence(confidence)
    if k == n:
        return 1.0
    return float(betaincinv(k + 1, n - k, c))


def narrowest_width(theta, k: int, period: float) -> float:
    """Width (deg) of the narrowest arc holding ``k`` of the angles ``theta``
    (NaN marks a jammed trial, which no arc holds) modulo ``period``; ``inf``
    when fewer than ``k`` angles are finite."""
    x = np.sort(np.mod(np.asarray(theta, dtype=float)[np.isfinite(theta)], period))
    n = x.size
    if k <= 0:
        return 0.0
    if n < k:
        return math.inf
    x2 = np.concatenate([x, x + period])
    return float(min(np.min(x2[k - 1:k - 1 + n] - x), period))


def width_interval(theta, n_trials: int, required: float, order: int = 1,
                   confidence: float = DEFAULT_CONFIDENCE, n_boot: int = 400,
                   seed: int = 0) -> tuple[float, float]:
    """Two-sided percentile bootstrap interval ``(lo, hi)`` (deg) of the verified width.

    ``theta`` holds the final orientations of the trials that did not jam;
    the other ``n_trials - len(theta)`` trials jammed and count as failures.
    Each resample draws ``n_trials`` trials with replacement and takes the
    narrowest arc holding ``ceil(required * n_trials)`` of them (modulo
    ``360 / order``); ``inf`` where too many jammed. Seeded, so the same
    trials give the same interval."""
    c = check_confidence(confidence)
    finals = np.asarray(theta, dtype=float)
    n = int(n_trials)
    if n <= 0:
        return (math.inf, math.inf)
    trials = np.concatenate([finals, np.full(n - finals.size, np.nan)])
    need = int(math.ceil(required * n - 1e-9))
    period = 360.0 / order
    rng = np.random.default_rng(seed)
    widths = np.array([narrowest_width(trials[rng.integers(0, n, n)], need, period)
                       for _ in range(int(n_boot))])
    lo, hi = np.quantile(widths, [(1.0 - c) / 2.0, (1.0 + c) / 2.0], method="inverted_cdf")
    return (float(lo), float(hi))
