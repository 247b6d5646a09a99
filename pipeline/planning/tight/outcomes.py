"""The nominal rollouts' outcomes kept by key, for the enumeration to reuse.

A nominal rollout starts from its pose rounded to the enumeration's quantum,
so its outcome is a function of its key (the rounded pose, pin offset, speed
and support) alone: :class:`Outcomes` keeps them, sorted by one integer code
per key, so later columns, chunks, levels and searches look them up instead
of rolling them out again (:mod:`~pipeline.planning.tight.enumerate`).
"""
from __future__ import annotations

import numpy as np

MAX_OUTCOMES = 8_000_000  # nominal outcomes kept for reuse (about 200 MB)


class Outcomes:
    """The nominal rollouts' outcomes ``(status, theta_f, dy)`` by key (a
    rounded pose, pin offset, speed and support: a rollout starts from the
    rounded pose itself, so its outcome is a function of the key alone), up
    to ``MAX_OUTCOMES`` keys; later keys are rolled out without being kept."""

    def __init__(self):
        self.codes = np.zeros(0, dtype=np.int64)
        self.status = np.zeros(0, dtype=np.int8)
        self.theta_f, self.dy = np.zeros(0), np.zeros(0)

    @staticmethod
    def key_codes(keys):
        """One int64 per key row (``(n, 4)``: pose, offset, speed, support),
        ordered as the rows are lexicographically, or ``None`` where a key is
        out of range."""
        t, d, v, s = keys.T
        if keys.size and (t.min() < 0 or t.max() >= 1 << 14 or np.abs(d).max() >= 1 << 30 or v.max() >= 1 << 8
                          or s.max() >= 1 << 8 or v.min() < 0 or s.min() < 0):
            return None
        return (((t << 31) + (d + (1 << 30))) << 16) + (v << 8) + s

    @staticmethod
    def key_rows(codes) -> np.ndarray:
        """The key rows ``(n, 4)`` of the codes ``codes`` (:meth:`key_codes` undone)."""
        codes = np.asarray(codes, dtype=np.int64)
        rest = codes >> 16
        return np.stack([rest >> 31, (rest & ((1 << 31) - 1)) - (1 << 30), (codes >> 8) & 0xFF, codes & 0xFF],
                        axis=-1)

    def lookup(self, keys):
        """``(status, theta_f, dy, known)`` arrays over the key rows ``keys``."""
        n = keys.shape[0]
        status, theta_f, dy = np.zeros(n, dtype=np.int8), np.zeros(n), np.zeros(n)
        known = np.zeros(n, bool)
        codes = self.key_codes(keys)
        if codes is None or self.codes.size == 0:
            return status, theta_f, dy, known
        at, known = self._find(codes)
        status[known], theta_f[known], dy[known] = self.status[at[known]], self.theta_f[at[known]], self.dy[at[known]]
        return status, theta_f, dy, known

    def known_codes(self, codes):
        """``(n,)``: whether each of the key codes ``codes`` has its outcome kept."""
        if self.codes.size == 0:
            return np.zeros(codes.shape, bool)
        return self._find(codes)[1]

    def _find(self, codes):
        """``(at, known)``: where each code is (or would go) among the kept
        codes (not empty), and whether it is there."""
        at = np.minimum(np.searchsorted(self.codes, codes), self.codes.size - 1)
        return at, self.codes[at] == codes

    def add(self, keys, status, theta_f, dy) -> None:
        """Keep the outcomes of the (new) key rows ``keys``, while there is room."""
        codes = self.key_codes(keys)
        if codes is None or self.codes.size + codes.size > MAX_OUTCOMES:
            return
        order = np.argsort(np.concatenate([self.codes, codes]), kind="stable")
        self.codes = np.concatenate([self.codes, codes])[order]
        self.status = np.concatenate([self.status, np.asarray(status, dtype=np.int8)])[order]
        self.theta_f = np.concatenate([self.theta_f, theta_f])[order]
        self.dy = np.concatenate([self.dy, dy])[order]
