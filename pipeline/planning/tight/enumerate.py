"""Every fixed-pin sequence, by nominal rollouts, level by level.

The nominal path of a sequence starts each resting state exactly as it lies
on the fence (no perturbation) and rolls it past each pin in turn at one
friction. All sequences of one length are one level: the level's states are
arrays ``(sequences, resting states)``, and going one pin deeper repeats
each sequence once per candidate pin and rolls out the (state, pin) pairs of
all of them, one column (resting state) at a time, each column in one
parallel batch. Each (state, pin) pair starts from its pose rounded
to a multiple of ``QUANTUM`` (the orientation in degrees, the pin's offset
from the centroid in millimetres), and pairs that round alike share one
rollout (so an outcome depends on the rounded pose only): different
sequences often bring a state to the same pose (a pin that misses leaves it
as it was; a vertex pushed to rest ends where the vertex sits behind the
centroid whatever the offset was). Because an outcome is a function of its
rounded key (pose, offset, speed, support) alone, the tree keeps the
outcomes it has rolled out and reuses them in later columns, chunks and
levels (up to ``outcomes.MAX_OUTCOMES``).

Fewer rollouts, the same levels. A candidate whose rollout in one column
jams (or runs out of steps) or passes a touched centroid within
``pin_halfwidth`` is dropped by the rules below whatever its other columns
do, so its remaining columns are not rolled out; a candidate that survives
has had every column rolled out, from the same rounded keys, so its finals,
heights and margin are exactly those of one batch of every column.

The deepest level of a search is never extended, so there the nominal span
may stop a candidate early (``levels(..., span=...)``): once the columns
rolled out already spread its finals over the span limit (the screen's
``tolerance + SLACK_DEG``), its other columns are not rolled out (spans only
grow as points are added). Such a candidate is *spread out*: it is kept in
the level with its unrolled columns marked (``Level.unrolled``: they hold
the parent's pose), since a jam in one of them is not known; it is never
within the span limit, so the screen never sees it, and the evidence (which
ranks the level's sequences by their clusters of finals) rolls out the
columns of those that might rank among its fewest-cluster sequences
(:meth:`NominalTree.complete`), so it picks exactly the sequences a full
enumeration would. Every candidate within the limit has had every column
rolled out, from the same rounded keys, exactly as at once. Since most
candidates stop after two columns, the order of their columns sets the
level's cost: after a near miss each candidate takes its cheapest columns
first, else all take the drop order, which makes the evidence cheaper
(:mod:`~pipeline.planning.tight.column_order`).

A sequence is dropped (with all its extensions) when, on its nominal path:

- a rollout jams (or runs out of steps): a jam stops the feeder;
- its last pin touches no resting state: it adds nothing to the shorter
  sequence, which is enumerated too;
- a pin that touches a state passes within ``pin_halfwidth`` of that state's
  centroid: the pin's own placement error decides on which side it passes,
  so the part may turn either way (metastable).

Nothing else is pruned: every other sequence of up to ``depth`` pins is
enumerated (``NominalTree.levels``). Only a time limit (a
:class:`~pipeline.progress.Deadline`) ends the enumeration early: it is
checked between batches of parents, and a level it cuts says how many of its
candidate sequences were rolled out (``Level.cut``).

With several supports (a support family's representatives), every
resting state is rolled out under each of them: the level's columns are
(support, resting state) pairs, so the rules above and the planner's span
of the nominal finals take the union over the supports.
"""
from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from kernels.rollout import JAMMED, MISS, TRUNCATED

from pipeline.parts.part import Part
from pipeline.planning.claims import orient
from pipeline.planning.claims.replay import rollouts_by_speed
from pipeline.planning.tight.column_order import ColumnOrder, clears
from pipeline.planning.tight.fewest import ROUNDING
from pipeline.planning.tight.outcomes import Outcomes
from pipeline.progress import BATCH_SECONDS, NO_DEADLINE, SILENT, Deadline, Heartbeat, Stretch
from pipeline.rows import unique_rows

QUANTUM = 0.05  # deg and mm: poses that round to the same multiple share one nominal rollout
MAX_PAIRS = 4_000_000  # (sequence, pin, state) triples handled at once
FIRST_PARENTS = 64  # parents of the first batch of a level under a time limit (it sets the pace)
# Under a time limit a level's enumeration that will not end before the search
# time does stops after this share of the search time left when it started;
# the rest screens the sequences it enumerated.
ENUMERATION_SHARE = 0.7
SCREEN_SHARE = 0.1  # ... and one that will end in time goes on if it leaves at least this share to screen


@dataclass
class Level:
    """All surviving sequences of one length.

    ``seq``: pin indices ``(n, length)``; ``theta``, ``y``: each resting
    state's nominal orientation (deg) and centroid height (mm) after the
    sequence ``(n, states)``; ``margin``: the smallest distance of any
    touching nominal ``|d|`` from ``[d_min, d_max]`` (negative outside;
    ``inf`` if nothing was touched); ``cut``: ``None`` for a whole level,
    else ``(candidate sequences rolled out, candidate sequences of the
    level)`` when a time limit ended its enumeration early (its sequences are
    then those of the parents done).

    Spread-out sequences (the deepest level only, see the module's
    docstring): ``unrolled`` marks ``(n, states)`` the columns not rolled
    out (``None``: every column was), which hold the parent's pose, with
    ``margin`` over the columns rolled out only; ``touched`` says per
    sequence whether its last pin touched a state in a column rolled out;
    ``dropped`` marks the sequences whose columns, rolled out later
    (:meth:`NominalTree.complete`), broke a rule (``None``: none)."""
    seq: np.ndarray
    theta: np.ndarray
    y: np.ndarray
    margin: np.ndarray
    cut: tuple | None = None
    unrolled: np.ndarray | None = None
    touched: np.ndarray | None = None
    dropped: np.ndarray | None = None

    def rows(self, lo: int, hi: int) -> "Level":
        """The sequences ``lo`` to ``hi`` of the level."""
        return Level(self.seq[lo:hi], self.theta[lo:hi], self.y[lo:hi], self.margin[lo:hi], None,
                     *(None if x is None else x[lo:hi] for x in (self.unrolled, self.touched, self.dropped)))

    @property
    def size(self) -> int:
        """Number of sequences in the level."""
        return int(self.seq.shape[0])

    @property
    def spread_out(self) -> np.ndarray:
        """``(n,)``: the sequences with columns not rolled out (still unknown)."""
        if self.unrolled is None:
            return np.zeros(self.size, bool)
        return self.unrolled.any(axis=1)

    @property
    def alive(self) -> np.ndarray:
        """``(n,)``: the sequences not dropped once their columns were rolled out."""
        return np.ones(self.size, bool) if self.dropped is None else ~self.dropped


class NominalTree:
    """Nominal paths of every fixed-pin sequence over ``heights`` (mm).

    Parameters
    ----------
    part : the part.
    heights : candidate pin heights above the fence, mm (one per pin index).
    mu_c : the friction of the nominal paths.
    pin_radius, model, kernel : as for every rollout (``kernel``: optional
        ``ds_max`` and ``tol``).
    pin_halfwidth : the pins' placement tolerance (mm), for the metastable rule.
    d_min, d_max : the margin's limits on ``|d|`` (not a rule here).
    belt : ``{"belt_speed": mm/s, "mu_s": ...}`` for the dynamic model, or None.
    speeds : each candidate pin's speed across the belt, v_pin / v_b (default
        all 0: fixed pins; moving pins follow the same rules).
    supports : supports as ``simulate`` takes them (``None`` for uniform); each
        resting state is a column once per support (default: uniform only).
    """

    def __init__(self, part: Part, heights, mu_c: float, pin_radius: float, model: str = "minpower",
                 kernel: dict | None = None, pin_halfwidth: float = 0.3, d_min: float = 0.1,
                 d_max: float = 0.9, belt: dict | None = None, speeds=None, supports=None):
        self.part, self.mu_c, self.pin_radius, self.model = part, float(mu_c), float(pin_radius), model
        self.heights = np.asarray(heights, dtype=float)
        self.speeds = np.zeros(self.heights.size) if speeds is None else np.asarray(speeds, dtype=float)
        self.kernel = {k: v for k, v in (kernel or {}).items() if k in ("ds_max", "tol")}
        if belt:  # the dynamic model at a belt speed: its own step control
            self.model, self.kernel = "dynamic", dict(belt)
        self.pin_halfwidth, self.d_min, self.d_max = float(pin_halfwidth), float(d_min), float(d_max)
        self.supports = list(supports) if supports else [None]
        n_states = self.part.stable_states().shape[0]
        self.column_support = np.repeat(np.arange(len(self.supports)), n_states)
        self.rollouts = 0
        self._outcomes = Outcomes()
        self._column_tries = np.zeros(self.column_support.size, dtype=np.int64)
        self._column_drops = np.zeros(self.column_support.size, dtype=np.int64)

    def start_poses(self) -> np.ndarray:
        """``(columns, 2)``: each column's resting state ``(theta, y_c)``
        (the resting states, once per support)."""
        return np.tile(self.part.stable_states(), (len(self.supports), 1))

    def root(self) -> Level:
        """The empty sequence: every resting state as it lies on the fence."""
        states = self.start_poses()
        return Level(np.zeros((1, 0), dtype=np.int16), states[None, :, 0].copy(),
                     states[None, :, 1].copy(), np.full(1, np.inf))

    def levels(self, depth: int, root: Level | None = None, heartbeat=None, deadline: Deadline = NO_DEADLINE,
               span: tuple | None = None):
        """Yield the levels of lengths 1 to ``depth`` after ``root`` (default
        :meth:`root`) in turn (lazily, so a search may stop early).

        ``heartbeat(length, n)``, if given, returns the
        :class:`~pipeline.progress.Heartbeat` that the enumeration of the
        ``n`` sequences of ``length`` pins after ``root`` reports to.
        ``deadline``: no level starts once its search is over
        (:meth:`~pipeline.progress.Deadline.search_over`); a level's
        enumeration that at its pace would not end before the search time
        does stops once it has used ``ENUMERATION_SHARE`` of the search time
        left when it started (the rest is for screening what it enumerated;
        :func:`finishes_in_time`), and a level it cuts short is the last
        (``Level.cut``). ``span``: ``(limit_deg, symmetry order[, evidence])``:
        the deepest level stops a candidate once its finals spread over the
        limit (see the module's docstring); ``evidence`` (default True) says
        whether the search may rank that level for its evidence (it sets the
        order of the columns, :meth:`_column_order`); ``None``: every column
        of every level."""
        heartbeat = heartbeat or (lambda length, n: Heartbeat("", n))
        level = self.root() if root is None else root
        for k in range(depth):
            if deadline.search_over():
                return
            n = level.size * self.heights.size
            stop_at = None
            if deadline.limited:
                stop_at = deadline.elapsed() + ENUMERATION_SHARE * deadline.search_left()
            with heartbeat(level.seq.shape[1] + 1, n) as beat:
                level = self.extend(level, beat.stretch(0, n), deadline, stop_at, span if k == depth - 1 else None)
                if level.cut:
                    beat.finish(level.cut[0], "the time limit ended the enumeration here")
            yield level
            if level.size == 0 or level.cut:
                return

    def extend(self, level: Level, stretch: Stretch = SILENT, deadline: Deadline = NO_DEADLINE,
               stop_at: float | None = None, span: tuple | None = None) -> Level:
        """Every surviving sequence of ``level`` followed by every candidate pin
        (in chunks of parents, so memory stays bounded on long levels);
        ``stretch`` is told the share of parents done. Under a time limit
        (``deadline``) the chunks are about ``BATCH_SECONDS`` of work each and
        the enumeration stops between them once the search is over, or once
        ``stop_at`` seconds of the deadline have passed and the rest would
        not end before the search is over (:func:`finishes_in_time`): the
        level returned is then ``cut``. (An outcome depends on its rounded pose only, so the
        sequences enumerated are the same in any chunks.) ``span``: as for
        :meth:`levels`, for this level; each candidate's order of its columns
        is then fixed for the whole level (:meth:`_column_order`)."""
        per_parent = max(1, self.heights.size * level.theta.shape[1])
        step = max(1, MAX_PAIRS // per_parent)
        if span is not None:
            span = (*span[:2], self._column_order(level, span, step))
        if deadline.limited:
            return self._extend_timed(level, step, stretch, deadline, stop_at, span)
        if level.size <= step:
            return self._extend(level, stretch, span)
        parts = [self._extend(level.rows(i, i + step),
                              stretch.part(i / level.size, min(i + step, level.size) / level.size), span)
                 for i in range(0, level.size, step)]
        return _joined(parts)

    def _extend_timed(self, level: Level, step: int, stretch: Stretch, deadline: Deadline,
                      stop_at: float | None = None, span: tuple | None = None) -> Level:
        """:meth:`extend` under a time limit: chunks of parents sized by the pace
        of the ones before (up to ``step``), the deadline (and ``stop_at``)
        read between them."""
        if level.size == 0:
            return self._extend(level, stretch, span)
        parts, done, size = [], 0, min(step, FIRST_PARENTS)
        started = deadline.elapsed() if stop_at is not None else 0.0

        def stop() -> bool:
            if deadline.search_over():
                return True
            if stop_at is None:
                return False
            now = deadline.elapsed()
            return now >= stop_at and not finishes_in_time(now, started, done, level.size,
                                                           deadline.seconds - deadline.reserve)

        while done < level.size and not (parts and stop()):
            hi = min(level.size, done + size)
            t0 = time.monotonic()
            parts.append(self._extend(level.rows(done, hi), stretch.part(done / level.size, hi / level.size), span))
            took = max(time.monotonic() - t0, 1e-6)
            size = max(1, min(step, int((hi - done) * min(8.0, max(0.125, BATCH_SECONDS / took)))))
            done = hi
        out = _joined(parts)
        if done < level.size:
            out.cut = (done * self.heights.size, level.size * self.heights.size)
        return out

    def _cells(self, level: Level) -> tuple:
        """``(theta, y_c, dy_pin, v_pin, keys)`` of every (candidate, column)
        cell of the level after ``level`` (each parent once per pin): the
        pose (deg), centroid height and pin offset (mm), the pin's speed and
        the rollout keys (``(..., 4)``, :meth:`_keys`)."""
        n_pins, n = self.heights.size, level.size
        theta = np.repeat(level.theta, n_pins, axis=0)
        y_c = np.repeat(level.y, n_pins, axis=0)
        dy_pin = np.tile(self.heights, n)[:, None] - y_c
        v_pin = self._speeds_of(n)
        return theta, y_c, dy_pin, v_pin, self._keys(theta, dy_pin, v_pin)

    def _column_order(self, level: Level, span: tuple, step: int) -> ColumnOrder:
        """The deepest level's order of each candidate's columns after
        ``level``: cheapest first when the search keeps no evidence
        (``span[2]`` False) or some sequence of ``level`` ended within the
        span limit (a near miss, so a plan may end the next level), else the
        drop order, which makes the evidence cheaper
        (:mod:`~pipeline.planning.tight.column_order`). The level's key codes
        are gathered ``step`` parents at a time (memory stays bounded)."""
        evidence = span[2] if len(span) > 2 else True
        if evidence and not (orient.row_spans(level.theta, span[1]) <= span[0]).any():
            return ColumnOrder.shared(self._drop_order())
        codes = [_codes(self._cells(level.rows(i, i + step))[-1]) for i in range(0, level.size, step)]
        if not codes or any(c is None for c in codes):
            return ColumnOrder.shared(self._drop_order())
        return ColumnOrder.cheapest(np.concatenate(codes), self._outcomes, self._misses)

    def _extend(self, level: Level, stretch: Stretch = SILENT, span: tuple | None = None) -> Level:
        n_pins, n = self.heights.size, level.size
        theta, y_c, dy_pin, v_pin, keys = self._cells(level)
        orders = None if span is None else span[2].orders(_codes(keys), theta.shape[0])
        status, theta_f, dy, unrolled = self._columns(theta, dy_pin, v_pin, stretch, span, orders, keys)
        seq = np.concatenate([np.repeat(level.seq, n_pins, axis=0),
                              np.tile(np.arange(n_pins, dtype=np.int16), n)[:, None]], axis=1)
        keep, step_margin, touched = self._rules(status, dy_pin, None if unrolled is None
                                                 else ~unrolled.any(axis=1))
        margin = np.minimum(np.repeat(level.margin, n_pins), step_margin)
        out = Level(seq[keep], theta_f[keep], (y_c + dy)[keep], margin[keep])
        if unrolled is not None:
            out.unrolled, out.touched = unrolled[keep], touched[keep]
        return out

    def _speeds_of(self, n: int) -> np.ndarray:
        """``(n * pins, columns)``: the pin speed of every cell of ``n`` parents' candidates."""
        return np.broadcast_to(np.tile(self.speeds, n)[:, None], (n * self.speeds.size, self.column_support.size))

    def _keys(self, theta, dy_pin, v_pin, col_support=None) -> np.ndarray:
        """The rollout keys ``(..., 4)`` of the cells ``theta`` (deg), ``dy_pin``
        (mm) and ``v_pin``, columns ``col_support``'s (default all): the pose and
        offset rounded to ``QUANTUM``, the speed's index and the support."""
        col_support = self.column_support if col_support is None else col_support
        speed_index = np.searchsorted(np.unique(self.speeds), v_pin)
        support = np.broadcast_to(col_support[None, :], theta.shape)
        return np.stack([np.round(np.mod(theta, 360.0) / QUANTUM), np.round(dy_pin / QUANTUM), speed_index,
                         support], axis=-1).astype(np.int64)

    def _misses(self, codes: np.ndarray) -> np.ndarray:
        """Whether the pins of the key codes ``codes`` clear the part (an
        estimate that orders the deepest level's columns; :func:`clears`)."""
        keys = Outcomes.key_rows(codes)
        return clears(self.part.vertices, keys[:, 0] * QUANTUM, keys[:, 1] * QUANTUM,
                      np.unique(self.speeds)[keys[:, 2]], self.pin_radius)

    def _rules(self, status, dy_pin, whole=None):
        """The rules of the module's docstring on rollouts' ``status`` and pin
        offsets ``dy_pin`` (mm; a column not rolled out reads ``MISS``):
        ``(kept, step margin, touched)`` per row. Whether a row's last pin
        touches a state at all is known only for the rows ``whole`` marks
        (every column rolled out; ``None``: all rows), so only they are
        dropped for touching none."""
        touched = status != MISS
        d_abs = np.abs(dy_pin) / self.part.a
        bad = ((status == JAMMED) | (status == TRUNCATED)).any(axis=1)
        bad |= (touched & (np.abs(dy_pin) < self.pin_halfwidth)).any(axis=1)
        bad |= ~touched.any(axis=1) & (True if whole is None else whole)
        step_margin = np.where(touched, np.minimum(d_abs - self.d_min, self.d_max - d_abs), np.inf).min(axis=1)
        return ~bad, step_margin, touched.any(axis=1)

    def _columns(self, theta, dy_pin, v_pin, stretch: Stretch = SILENT, span: tuple | None = None, orders=None,
                 keys=None):
        """:meth:`_rollouts` of every (candidate sequence, column) pair, one
        column of each candidate at a time: a candidate whose rollout in one
        column jams (or runs out of steps) or passes a centroid it touches
        within ``pin_halfwidth`` is dropped whatever its other columns do, so
        its other columns are not rolled out. Those entries keep the pose they
        started from and read ``JAMMED``: the candidate is dropped all the
        same, and every surviving candidate has all its columns rolled out,
        exactly as at once. Without ``span`` the columns go in the order of the
        share of candidates each dropped so far (any order gives the same
        survivors).

        With ``span`` (``(limit_deg, order, ColumnOrder)``), a candidate whose
        columns rolled out so far span more than the limit stops too: its
        other columns keep the pose they started from, read ``MISS`` and are
        marked in the fourth array returned (``unrolled``; ``None`` without
        ``span``). Each candidate then takes its columns in its own order,
        ``orders`` (``(candidates, columns)``, from the level's
        :class:`~pipeline.planning.tight.column_order.ColumnOrder`: the
        cheapest keys first, or the drop order; :meth:`_column_order`). Which candidates stop (and so the level's count
        of sequences) depends on that order, which is fixed when the level
        begins, so chunks and time limits change nothing; the candidates
        within the limit and the evidence do not depend on it. ``keys``: the
        cells' rollout keys, if known (:meth:`_cells`)."""
        n, cols = theta.shape
        status = np.full(theta.shape, JAMMED, dtype=np.int8)
        theta_f, dy = theta.astype(float, copy=True), np.zeros(theta.shape)
        unrolled = None if span is None else np.zeros(theta.shape, bool)
        if orders is None:
            orders = np.broadcast_to(self._drop_order()[None, :], theta.shape)
        alive = np.arange(n)
        for k in range(cols):
            if alive.size == 0:
                break
            c = orders[alive, k]
            st, tf, d = self._rollouts(theta[alive, c][None, :], dy_pin[alive, c][None, :], v_pin[alive, c][None, :],
                                       stretch.part(k / cols, (k + 1) / cols), columns=c,
                                       keys=None if keys is None else keys[alive, c])
            st = st[0]
            status[alive, c], theta_f[alive, c], dy[alive, c] = st, tf[0], d[0]
            drop = (st == JAMMED) | (st == TRUNCATED) | ((st != MISS) & (np.abs(dy_pin[alive, c]) < self.pin_halfwidth))
            self._column_tries += np.bincount(c, minlength=cols)
            self._column_drops += np.bincount(c[drop], minlength=cols)
            alive = alive[~drop]
            if span is not None and 0 < k < cols - 1 and alive.size:
                done = orders[alive, :k + 1]
                # ROUNDING: a row within the limit is never stopped by rounding in its partial span
                wide = orient.row_spans(np.take_along_axis(theta_f[alive], done, axis=1), span[1]) > span[0] + ROUNDING
                stop = alive[wide]
                rest = orders[stop, k + 1:]
                status[stop[:, None], rest] = MISS
                unrolled[stop[:, None], rest] = True
                alive = alive[~wide]
        return status, theta_f, dy, unrolled

    def _drop_order(self) -> np.ndarray:
        """The columns in the order of the share of candidates each has dropped so far."""
        return np.argsort(-self._column_drops / np.maximum(self._column_tries, 1), kind="stable")

    def complete(self, level: Level, rows) -> None:
        """Roll out the columns of ``level``'s spread-out ``rows`` that were not
        (from the parent's pose they hold, with the sequence's last pin), in
        place: their finals, heights and margin become those of a full
        enumeration, and a row whose columns break a rule is marked in
        ``level.dropped`` (so the level's live sequences are exactly those a
        full enumeration keeps)."""
        rows = np.unique(np.asarray(rows, dtype=int))
        if level.unrolled is None or rows.size == 0:
            return
        at, c = np.nonzero(level.unrolled[rows])
        r = rows[at]
        pin = level.seq[r, -1].astype(int)
        dy_pin = self.heights[pin] - level.y[r, c]
        st, tf, d = self._rollouts(level.theta[r, c][None, :], dy_pin[None, :], self.speeds[pin][None, :],
                                   columns=c)
        status = np.full((rows.size, level.theta.shape[1]), MISS, dtype=np.int8)
        offsets = np.zeros(status.shape)
        status[at, c], offsets[at, c] = st[0], dy_pin
        # only these columns are in ``status``: the no-touch rule is applied below, over all of them
        keep, step_margin, touched = self._rules(status, offsets, whole=np.zeros(rows.size, bool))
        level.theta[r, c], level.y[r, c] = tf[0], level.y[r, c] + d[0]
        level.margin[rows] = np.minimum(level.margin[rows], step_margin)
        level.touched[rows] |= touched
        broken = ~keep | ~level.touched[rows]
        level.unrolled[rows] = False
        if level.dropped is None:
            level.dropped = np.zeros(level.size, bool)
        level.dropped[rows] |= broken

    def _rollouts(self, theta, dy_pin, v_pin, stretch: Stretch = SILENT, columns=None, keys=None):
        """``(status, theta_f, dy)`` arrays shaped like ``theta`` for the pin offsets
        ``dy_pin`` (mm) and pin speeds ``v_pin``, one rollout per distinct
        quantised pose and speed (``stretch`` is told the share done); the
        columns of ``theta`` are the tree's columns ``columns`` (default all).
        An outcome is a function of its key alone, so the outcomes of keys
        rolled out before (by any level, chunk or column of this tree) are
        reused (:class:`~pipeline.planning.tight.outcomes.Outcomes`). ``keys``:
        the cells' keys (``(..., 4)``), if known."""
        a = self.part.a
        if keys is None:
            col_support = self.column_support if columns is None else self.column_support[columns]
            keys = self._keys(theta, dy_pin, v_pin, col_support)
        keys = keys.reshape(-1, 4)
        if keys.shape[0] == 0:
            empty = np.zeros(theta.shape)
            return empty.astype(np.int8), empty, empty
        uniq, inverse = _distinct(keys)
        status, theta_f, dy, known = self._outcomes.lookup(uniq)
        new = np.flatnonzero(~known)
        if new.size:
            # Roll out from the rounded pose itself, so an outcome depends on its key only.
            todo = uniq[new]
            res = rollouts_by_speed(self.part, todo[:, 0] * QUANTUM, todo[:, 1] * QUANTUM / a,
                                    np.full(todo.shape[0], self.mu_c), np.unique(self.speeds)[todo[:, 2]],
                                    self.pin_radius, self.model, self.kernel, todo[:, 3], self.supports, stretch)
            status[new], theta_f[new], dy[new] = res["status"], res["theta_f"], res["dy"]
            self._outcomes.add(todo, status[new], theta_f[new], dy[new])
        self.rollouts += new.size
        shape = theta.shape
        return status[inverse].reshape(shape), theta_f[inverse].reshape(shape), dy[inverse].reshape(shape)


def finishes_in_time(now: float, started: float, done: int, total: int, search_end: float,
                     leave: float = SCREEN_SHARE) -> bool:
    """Whether a level's enumeration, begun at ``started`` with ``done`` of its
    ``total`` parents done at ``now``, ends at that pace with ``leave``
    (``SCREEN_SHARE``) of its time to ``search_end`` (seconds on the
    deadline's clock) left for its screen: then it goes on past its share of
    the time (a level that ends in time with room to screen it is never
    cut). The probe of a level's screen asks the same of its sequences."""
    pace = (now - started) / max(done, 1)
    return now + pace * (total - done) <= search_end - leave * (search_end - started)


def _joined(parts) -> Level:
    """The levels ``parts`` (sequences of one length) as one level, in order."""
    if len(parts) == 1:
        return parts[0]
    out = Level(*(np.concatenate([getattr(p, k) for p in parts]) for k in ("seq", "theta", "y", "margin")))
    if any(p.unrolled is not None for p in parts):
        out.unrolled = np.concatenate([np.zeros(p.theta.shape, bool) if p.unrolled is None else p.unrolled
                                       for p in parts])
        out.touched = np.concatenate([np.ones(p.size, bool) if p.touched is None else p.touched for p in parts])
    return out


def _distinct(keys) -> tuple:
    """``unique_rows(keys, return_inverse=True)`` (the distinct key rows in
    lexicographic order and each row's index among them), through one int64
    code per row where the keys fit (:meth:`Outcomes.key_codes
    <pipeline.planning.tight.outcomes.Outcomes.key_codes>` keeps that order)."""
    codes = Outcomes.key_codes(keys)
    if codes is None:
        return unique_rows(keys, return_inverse=True)
    _, first, inverse = np.unique(codes, return_index=True, return_inverse=True)
    return keys[first], inverse.reshape(-1)


def _codes(keys) -> np.ndarray | None:
    """``(candidates, columns)`` key codes of the cells ``keys`` (``(candidates,
    columns, 4)``), or ``None`` where a key is out of the codes' range."""
    codes = Outcomes.key_codes(keys.reshape(-1, 4))
    return None if codes is None else codes.reshape(keys.shape[:2])
