"""The fewest-cluster sequences of a level: the evidence when nothing orients.

A level's sequences are ranked by the clusters their nominal finals fall into
(gaps wider than the tolerance split them, modulo the part's symmetry), then
by their spread (the narrowest arc holding them all), then by their margin in
d (larger first), ties kept in level order; the first few are judged in full
as the evidence (:meth:`~pipeline.planning.tight.screen.LevelScreen.several_sets`).

On the deepest level some sequences are *spread out*: the enumeration
stopped rolling out their columns once their finals spread over the screen's
limit (:mod:`~pipeline.planning.tight.enumerate`). Their rank is bounded from
what is known, so only those that might rank among the first are rolled out
(:func:`fewest_sets`), and the sequences picked are exactly those of a full
enumeration:

- the spread only grows as finals are added (the largest gap only shrinks);
- a gap ``g`` wider than the tolerance ``T`` stops splitting the finals only
  once every piece is at most ``T``, which takes at least ``ceil(g / T) - 1``
  of the finals still to come; so with ``r`` finals to come, at most as many
  of the gaps as the cheapest of those costs add up to within ``r`` can
  close, and the clusters are at least the wide gaps minus that number
  (and at least 1).
"""
from __future__ import annotations

import numpy as np

ROUNDING = 1e-9  # deg: the bounds give this much away, so rounding in the gaps never makes them unsound
COMPLETE_BATCH = 1024  # spread-out sequences rolled out in the first batch (then twice as many each time ...)
MAX_BATCH = 16_384  # ... up to this many: a batch may roll out rows the one before has already ruled out


def cluster_keys(theta: np.ndarray, tolerance: float, order: int):
    """``(clusters, spread)`` per row of ``theta`` (deg, every column known)."""
    period = 360.0 / order
    x = np.sort(np.mod(theta, period), axis=1)
    gaps = np.diff(np.concatenate([x, x[:, :1] + period], axis=1), axis=1)
    return np.maximum(1, (gaps > tolerance).sum(axis=1)), period - gaps.max(axis=1)


def cluster_bounds(theta: np.ndarray, unrolled: np.ndarray, tolerance: float, order: int):
    """Lower bounds on ``(clusters, spread)`` per row of ``theta`` from its
    columns not marked in ``unrolled`` (at least two per row), for any finals
    its marked columns may bring (see the module's docstring)."""
    period = 360.0 / order
    n, cols = theta.shape
    known = (~unrolled).sum(axis=1)
    x = np.sort(np.where(unrolled, np.inf, np.mod(theta, period)), axis=1)
    clusters, spread = np.ones(n, dtype=np.int64), np.zeros(n)
    for m in np.unique(known):
        at = np.flatnonzero(known == m)
        xm = x[at, :m]
        gaps = np.diff(np.concatenate([xm, xm[:, :1] + period], axis=1), axis=1)
        spread[at] = period - gaps.max(axis=1) - ROUNDING
        cost = np.where(gaps > tolerance, np.ceil((gaps - ROUNDING) / tolerance) - 1, np.inf)
        closable = (np.cumsum(np.sort(cost, axis=1), axis=1) <= cols - m).sum(axis=1)
        clusters[at] = np.maximum(1, (gaps > tolerance).sum(axis=1) - closable)
    return clusters, spread


def fewest_sets(level, tolerance: float, order: int, k: int, complete=None, tick=None, stop=None) -> tuple:
    """``(rows, cut)``: the rows of ``level`` (an ``enumerate.Level``) of its
    ``k`` best ranked sequences (see the module's docstring), best first.
    Spread-out rows that might rank among them are rolled out first by
    ``complete(level, rows)`` (``NominalTree.complete``, which clears their
    ``unrolled``), lowest bound first, in batches that double up to
    ``MAX_BATCH``, until none
    might: rows it drops (``level.dropped``) are not ranked. ``tick(n)``
    hears how many rows were rolled out so far; once ``stop()`` is true no
    further batch starts, and the rows are the best of those rolled out in
    full (``cut`` True: not necessarily a full enumeration's)."""
    pending = np.flatnonzero(level.alive & level.spread_out) if complete is not None else np.zeros(0, int)
    if pending.size:  # a pending row's bounds do not change until it is rolled out
        lb_c, lb_s = cluster_bounds(level.theta[pending], level.unrolled[pending], tolerance, order)
        by_bound = np.lexsort((lb_s, lb_c))
        pending, lb_c, lb_s = pending[by_bound], lb_c[by_bound], lb_s[by_bound]
    rolled, batch = 0, COMPLETE_BATCH
    while True:
        exact = np.flatnonzero(level.alive & ~level.spread_out)
        clusters, spread = cluster_keys(level.theta[exact], tolerance, order)
        ranked = exact[np.lexsort((-level.margin[exact], spread, clusters))] if exact.size else exact
        if k <= 0:
            return ranked[:0], False
        if rolled >= pending.size:
            return ranked[:k], False
        if ranked.size >= k:
            at = np.searchsorted(exact, ranked[k - 1])
            c_k, s_k = clusters[at], spread[at]
            c, s = lb_c[rolled], lb_s[rolled]  # the lowest bound of the rows still pending
            if c > c_k or (c == c_k and s > s_k):
                return ranked[:k], False
        if stop is not None and stop():
            return ranked[:k], True
        complete(level, pending[rolled:rolled + batch])
        rolled = min(pending.size, rolled + batch)
        batch = min(2 * batch, MAX_BATCH)
        if tick is not None:
            tick(rolled)
