"""The order in which the deepest level rolls out each candidate's columns.

On the deepest level of a search a candidate stops as soon as the columns
(resting states) rolled out spread its finals over the span limit
(:mod:`~pipeline.planning.tight.enumerate`), and most candidates stop after
two. Two orders serve two different ends there:

- **Cheapest first**, when a plan may end the level or no evidence is
  kept: what the level costs is the number of distinct rollout keys among
  the columns rolled out first, so each candidate rolls out first the
  columns whose keys cost least: keys already known, and keys whose pin clears the part (a miss
  costs about 1/400 of a rollout that touches; :func:`clears`), then keys
  that more of the level's cells share, ties in the order of the columns'
  count of new keys over the level. On the T bracket of
  ``benchmarks/plan_speed.py`` the nominal paths take 128,320 rollouts
  (70,421 that touch the part) where the drop order took 211,696 (143,553).
- **The drop order** (the columns by the share of candidates each dropped
  so far, the same for every candidate), when nothing is likely to orient
  and the evidence will rank the level: a candidate dropped is not rolled
  out again for the evidence, and the columns that tell candidates apart
  come first, so the evidence's bounds rule out more of the stopped ones
  (:mod:`~pipeline.planning.tight.fewest`). On the corpus heart cam, where
  nothing orients, cheapest first left the evidence 310,272 of its 448,768
  stopped sequences to roll out, the drop order 48,128 of 447,245.

:meth:`NominalTree.levels <pipeline.planning.tight.enumerate.NominalTree.levels>`
takes cheapest first when the search keeps no evidence (the moving-pin
stage and the nearest "yes"'s searches keep their plans only) or some
sequence of the level before ended within the span limit (a near miss, so a
plan may follow), else the drop order.
Either order is fixed when the level begins, from the keys of all its
candidates, so it does not depend on how the level is cut into chunks (nor
on a time limit).

What the order changes: which spread-out candidates stop before a jam in a
column they never roll out, so the level's count of sequences and of
spread-out ones. What it does not: every candidate within the limit has all
its columns rolled out, from the same keys, and the evidence rolls out what
it needs of the others, so the plans, verdicts, claims and evidence are
those of any other order.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from pipeline.planning.tight.outcomes import Outcomes


@dataclass
class ColumnOrder:
    """Each candidate's order of the columns of a level, fixed when it begins.

    ``rank``: per column, its place in the order every candidate shares
    (the drop order), or the tie-break of the cheapest-first order (the
    columns by their count of new keys over the level). Cheapest first
    only: ``codes``, the distinct key codes of the level's cells, sorted
    (:meth:`Outcomes.key_codes
    <pipeline.planning.tight.outcomes.Outcomes.key_codes>`), and ``score``,
    per code, how many of the level's cells share it, or more than any count
    where it costs (almost) nothing: rolled out before, or a pin that clears
    the part. Without ``codes`` every candidate takes the columns in
    ``rank``'s order."""
    rank: np.ndarray
    codes: np.ndarray | None = None
    score: np.ndarray | None = None

    @classmethod
    def shared(cls, order) -> "ColumnOrder":
        """Every candidate takes the columns in ``order``."""
        rank = np.empty(len(order), dtype=np.int64)
        rank[np.asarray(order)] = np.arange(len(order))
        return cls(rank)

    @classmethod
    def cheapest(cls, codes: np.ndarray, outcomes: Outcomes, misses=None) -> "ColumnOrder":
        """Cheapest first for the cells of a level about to be rolled out, by
        their key codes ``codes`` (``(candidates, columns)``, :meth:`Outcomes.key_codes
        <pipeline.planning.tight.outcomes.Outcomes.key_codes>`), with
        ``outcomes`` the keys known and ``misses`` (optional) a function of
        key codes that says which pins clear the part."""
        cols = codes.shape[1]
        uniq, inverse, counts = np.unique(codes, return_inverse=True, return_counts=True)
        known = outcomes.known_codes(uniq)
        free = known | misses(uniq) if misses is not None else known
        score = np.where(free, codes.size + 1, counts).astype(np.int64)
        cells = inverse.reshape(-1, cols)
        per_column = [np.unique(cells[~known[cells[:, c]], c]).size for c in range(cols)]
        rank = cls.shared(np.argsort(per_column, kind="stable")).rank
        return cls(rank, uniq, score)

    def orders(self, codes: np.ndarray | None, n: int) -> np.ndarray:
        """``(n, columns)``: each of ``n`` candidates' columns in order, for
        their cells' key codes ``codes`` (``(n, columns)``; ``None``, or a
        shared order: every candidate takes ``rank``'s order)."""
        cols = self.rank.size
        if codes is None or self.codes is None or self.codes.size == 0:
            return np.broadcast_to(np.argsort(self.rank)[None, :], (n, cols)).copy()
        at = np.minimum(np.searchsorted(self.codes, codes), self.codes.size - 1)
        score = np.where(self.codes[at] == codes, self.score[at], 0)
        # Highest score first, then the lower rank: one integer per cell.
        return np.argsort(-score * cols + self.rank[None, :], axis=1, kind="stable")


def clears(vertices: np.ndarray, theta_deg, dy_pin, v_pin, r_pin: float, margin: float = 1e-6) -> np.ndarray:
    """Whether a pin of radius ``r_pin`` passing ``dy_pin`` from the centroid
    (mm, across the belt), moving across the belt at ``v_pin`` (v_pin / v_b),
    clears the outline ``vertices`` (body frame, mm) of a part at ``theta_deg``
    by more than ``margin`` mm: it never touches it (the rollout kernel's miss).

    Notes
    -----
    In the belt frame the pin's path relative to the centroid is the line
    ``y + v_pin x = dy_pin``; the outline's points ``w = R(theta) b`` lie
    between the least and largest ``y_w + v_pin x_w``, and the pin clears
    them when the line is farther than ``r_pin sqrt(1 + v_pin^2)`` from both
    ends of that range. The range depends on the pose and speed only, so it
    is computed once per distinct pair. An estimate for ordering rollouts
    only: an outcome always comes from the rollout itself.
    """
    theta = np.asarray(theta_deg, dtype=float).ravel()
    v = np.broadcast_to(np.asarray(v_pin, dtype=float), np.shape(theta_deg)).ravel()
    pairs, inverse = np.unique(np.stack([theta, v], axis=1), axis=0, return_inverse=True)
    t = np.radians(pairs[:, :1])
    c, s = np.cos(t), np.sin(t)
    bx, by = vertices[:, 0], vertices[:, 1]
    along = s * bx + c * by + pairs[:, 1:] * (c * bx - s * by)
    reach = r_pin * np.sqrt(1.0 + v ** 2) + margin
    lo, hi = along.min(axis=1)[inverse.ravel()], along.max(axis=1)[inverse.ravel()]
    dy = np.broadcast_to(np.asarray(dy_pin, dtype=float), np.shape(theta_deg)).ravel()
    return ((dy >= hi + reach) | (dy <= lo - reach)).reshape(np.shape(theta_deg))
