"""Candidate pin sequences replayed on the verification's trials and judged;
the orienting ones certified.

The complete search (``complete.FixedPinSearch``) decides which sequences to
try and in what order; this module answers, for any batch of them, what the
trials say.

:class:`TrialBench` holds everything a judgement needs besides the pins
themselves: the part and its resting states, the rollout settings (pin
radius, model, kernel, belt, support family), the verification's trials
(``trials.trial_inputs``; its held-out trials, ``VerifySettings.held_out``)
and the claim (tolerance, required share, confidence, rule). It replays
sequences given as arrays of pin heights and speeds (one row per sequence)
on rows of trials, counts the trials no one arc of the tolerance can hold
(the screen), and judges the outcome by the claim rule
(:func:`pipeline.planning.claims.orient.judge`).

:class:`Certifier` decides which orienting verdicts count: a sequence must
hold for the support family's worst member (``member_check``, set by the
planner) and orient the part on the held-out trials as well.
"""
from __future__ import annotations

from typing import Protocol

import numpy as np

from kernels.rollout import DEFAULT_DS_MAX, DEFAULT_TOL, MISS

from pipeline.parts.part import Part
from pipeline.planning.claims import orient
from pipeline.planning.claims.replay import ReplayMemo, jam_reasons, kernel_kw, pin_step
from pipeline.planning.claims.trials import trial_inputs
from pipeline.planning.core.resting import resting_states
from pipeline.planning.core.settings import ClaimSettings, Friction, SearchSettings, VerifySettings
from pipeline.progress import NO_DEADLINE, SILENT, Deadline, Heartbeat, Stretch
from pipeline.rows import unique_rows

MAX_ROWS = 150_000  # trials replayed in one batch
MAX_KEPT = 2_000_000  # trial states after a prefix kept for reuse (about 170 MB at most)


def stack(rows) -> tuple:
    """Per-state trial arrays ``(theta, y_c, mu, offsets, support)`` joined into one set of rows."""
    return tuple(np.concatenate([r[k] for r in rows]) for k in range(5))


class TrialBench:
    """The trials that judge candidate pin sequences for one part and friction.

    Parameters
    ----------
    part : the part.
    friction : a :class:`~pipeline.planning.core.settings.Friction`; the
        trials sample it as verification does.
    claims : what "orients" means (tolerance, required share, confidence, rule).
    verify : the verification's trials (number, perturbation sizes, seed).
    search : rollout settings (pin radius, model, kernel) and the belt (the
        dynamic model at ``belt_speed`` mm/s and ``mu_s`` instead of the
        quasi-static ``model``).
    family : a :class:`~pipeline.parts.support_family.SupportFamily` whose
        members the trials sample (``None`` or a uniform one: uniform pressure).

    A sequence is a row of ``heights`` (mm) and of ``speeds`` (``v_pin /
    v_b``, 0 for a fixed pin); a set of trial *rows* is what :func:`stack`
    makes of :meth:`trials`.
    """

    def __init__(self, part: Part, friction: Friction, claims: ClaimSettings, verify: VerifySettings,
                 search: SearchSettings, family=None):
        self.part, self.mu_c, self.model = part, friction.value, search.model
        self.belt_speed = None if search.belt_speed is None else float(search.belt_speed)
        self.mu_s = 0.5 if search.belt_speed is None else float(search.mu_s)
        self.tolerance, self.required = claims.tolerance_deg, claims.required
        self.confidence, self.rule = claims.confidence, claims.rule
        self.verify, self.holdout = verify, verify.held_out()
        self.pin_radius = float(search.pin_radius)
        self.step = search.kernel_step.with_defaults(DEFAULT_DS_MAX, DEFAULT_TOL)
        self.order = part.symmetry_order()
        self.states = resting_states(part)
        self.family = None if family is None or family.is_uniform else family
        self.supports = None if self.family is None else self.family.kernel_supports
        self.kept = ReplayMemo(MAX_KEPT)  # states after each prefix (shared, see ReplayMemo)

    @property
    def belt(self) -> dict:
        """The dynamic model's keywords ``{"belt_speed", "mu_s"}`` for a rollout, ``{}`` quasi-static."""
        return {} if self.belt_speed is None else {"belt_speed": self.belt_speed, "mu_s": self.mu_s}

    def trials(self, n_pins: int) -> list:
        """The verification's trials for plans of ``n_pins`` pins (``trials.trial_inputs``), per state."""
        return trial_inputs(self.states, self.mu_c, n_pins, self.verify, self.family)

    def held_out(self, n_pins: int) -> tuple:
        """The held-out trials for plans of ``n_pins`` pins, as rows (``VerifySettings.held_out``)."""
        return stack(trial_inputs(self.states, self.mu_c, n_pins, self.holdout, self.family))

    def allowed_failures(self, n_trials: int) -> int:
        """The most failures of ``n_trials`` trials a plan may have and still
        orient the part (negative: no plan can be claimed on so few trials)."""
        return orient.max_failures(n_trials, self.required, self.confidence, self.rule)

    def screen_rows(self, inputs, n_first: int, n_corners_wanted: int) -> tuple:
        """A subset of the trials ``inputs`` (per state), as rows: the first
        ``n_first`` random trials and ``n_corners_wanted`` evenly spread corners
        of each state."""
        n_random = int(self.verify.trials)
        rows = []
        for trials in inputs:
            n_corners = trials[0].size - n_random
            pick = list(range(min(n_first, n_random)))
            if n_corners:
                step = max(1, n_corners // n_corners_wanted)
                pick += list(range(n_random, trials[0].size, step))[:n_corners_wanted]
            rows.append(tuple(x[pick] for x in trials))
        return stack(rows)

    def replay(self, heights, speeds, rows, stretch: Stretch = SILENT):
        """Final orientations ``(sequences, trials)`` and jam flags of the
        sequences ``heights``, ``speeds`` on ``rows`` (``stretch`` is told how
        far the replay has got), as ``replay.replay_shared`` gives them:
        sequences that share their first pins share those rollouts, and so do
        the calls of this bench and of the replays that share its ``kept``
        (a :class:`~pipeline.planning.claims.replay.ReplayMemo`): the probe,
        the screen, the cascade and the full judgement replay subsets of one
        level's trials, in blocks whose sequences share prefixes with earlier
        blocks, and the final verification replays the held-out trials that
        certified a plan.
        A trial's state after a prefix depends on the trial and the prefix
        only, and each rollout is independent of its batch, so the numbers are
        those of one ``replay_shared`` call."""
        th0, yc0, mu, offsets, sup = rows
        heights, speeds = np.atleast_2d(np.asarray(heights, float)), np.atleast_2d(np.asarray(speeds, float))
        n_plans, n_pins = heights.shape
        n = np.size(th0)
        kw = kernel_kw(self.step.ds_max, self.step.tol, self.belt_speed, self.mu_s)
        kept = self.kept if self.kept.serves(self.part, self.pin_radius, self.model, kw, self.supports) else None
        trial = None if kept is None else kept.trial_ids(th0, yc0, mu, offsets, sup)
        node, key = np.zeros(n_plans, int), np.zeros(1, dtype=np.int64)  # distinct prefixes; their keys
        th, yc = np.asarray(th0, float)[None, :].copy(), np.asarray(yc0, float)[None, :].copy()
        jam = np.zeros((1, n), bool)
        for k in range(n_pins):
            nodes, node = unique_rows(np.column_stack([node, heights[:, k], speeds[:, k]]), return_inverse=True)
            parent = nodes[:, 0].astype(int)
            th, yc, jam = th[parent], yc[parent], jam[parent]
            rows_, cols = np.nonzero(~jam)
            if kept is not None:
                key = kept.nodes(key[parent], nodes[:, 1], nodes[:, 2])
                at = kept.lookup(key[rows_], trial[cols])
                old = at >= 0
                th[rows_[old], cols[old]], yc[rows_[old], cols[old]], reason, _ = kept.get(at[old])
                jam[rows_[old], cols[old]] = reason != ""
                rows_, cols = rows_[~old], cols[~old]
            if rows_.size:
                res = pin_step(self.part, nodes[rows_, 1] + offsets[cols, k], nodes[rows_, 2], th[rows_, cols],
                                yc[rows_, cols], mu[cols], self.pin_radius, self.model, kw,
                                None if sup is None else np.asarray(sup)[cols], self.supports,
                                stretch.part(k / n_pins, (k + 1) / n_pins))
                th[rows_, cols] = res["theta_f"]
                yc[rows_, cols] = yc[rows_, cols] + res["dy"]
                reason = jam_reasons(res)
                jam[rows_, cols] = reason != ""
                if kept is not None:
                    kept.add(key[rows_], trial[cols], th[rows_, cols], yc[rows_, cols], reason,
                             res["status"] == MISS)
        return th[node] % 360.0, jam[node]

    def failures(self, heights, speeds, rows, stretch: Stretch = SILENT) -> np.ndarray:
        """Trials of ``rows`` that no one arc of the tolerance can hold, per
        sequence, in batches of at most ``MAX_ROWS`` replays (``stretch`` is
        told the share of sequences done)."""
        n = heights.shape[0]
        out = np.empty(n, dtype=int)
        step = max(1, MAX_ROWS // rows[0].size)
        for start in range(0, n, step):
            stop = min(n, start + step)
            tf, jam = self.replay(heights[start:stop], speeds[start:stop], rows, stretch.part(start / n, stop / n))
            for k in range(stop - start):
                held, _ = orient.best_arc(tf[k][~jam[k]], self.tolerance, self.order)
                out[start + k] = rows[0].size - held
        return out

    def judge(self, heights, speeds, rows, interval: bool = False, stretch: Stretch = SILENT):
        """The claim's verdict (:func:`~pipeline.planning.claims.orient.judge`)
        of each sequence on ``rows``, one at a time; ``interval`` adds the
        width's bootstrap interval. The replay runs when the first is asked for."""
        tf, jam = self.replay(heights, speeds, rows, stretch)
        yield from self.verdicts(tf, jam, interval)

    def verdicts(self, finals, jammed, interval: bool = False):
        """The claim's verdict of each row of replayed ``finals`` (``jammed``:
        its trials that jammed), one at a time."""
        for k in range(finals.shape[0]):
            yield orient.judge(finals[k][~jammed[k]], finals.shape[1], self.tolerance, self.order, self.required,
                               self.confidence, interval, self.rule)

    def failing(self, finals, jammed) -> np.ndarray:
        """``(sequences, trials)``: the trials each row of replayed ``finals``
        leaves out of its best arc of the tolerance (or that jammed)."""
        period = 360.0 / self.order
        out = np.ones(finals.shape, dtype=bool)
        for k in range(finals.shape[0]):
            _, start = orient.best_arc(finals[k][~jammed[k]], self.tolerance, self.order)
            out[k] = jammed[k] | (np.mod(finals[k] - start, period) > self.tolerance + 1e-9)
        return out


class FamilyCheck(Protocol):
    """What the complete search asks of a support family
    (``worst_member.FamilyChecker``, made by the planner): called with a
    plan's ``(labels, heights, verdict, speeds)``, True when the family's worst
    member keeps the plan in its set; ``breakers``, the worst members kept
    from plans they broke, and :meth:`prescreen`, which asks of many
    sequences at once whether those members break them whatever their set."""

    breakers: list

    def __call__(self, labels, heights, verdict: dict | None = None, speeds=()) -> bool: ...

    def prescreen(self, heights: np.ndarray, speeds: np.ndarray, tolerance: float, screened=None,
                  allowed: int = 0) -> np.ndarray:
        """True for each sequence (rows of ``heights``, ``speeds``) that the kept
        ``breakers`` break whatever the sequence's set."""
        ...


class Certifier:
    """Which orienting verdicts count: those that hold for the support
    family's worst member and are confirmed on held-out trials.

    Parameters
    ----------
    bench : the :class:`TrialBench` whose held-out trials certify.

    ``member_check`` is ``None`` (no family check) or the family's
    :class:`FamilyCheck` (set by the planner, through
    ``FixedPinSearch.member_check``); the search asks about the family
    through this class alone (:attr:`checks_family`,
    :meth:`holds_for_family`, :attr:`keeps_members`,
    :meth:`broken_by_known_members`).
    """

    def __init__(self, bench: TrialBench):
        self.bench = bench
        self.member_check: FamilyCheck | None = None

    @property
    def checks_family(self) -> bool:
        """True when plans must hold for a support family (``member_check`` set)."""
        return self.member_check is not None

    def holds_for_family(self, plan) -> bool:
        """True without a family check; else whether the family's worst member
        found by ``member_check`` leaves the plan's set (a plan it breaks no
        longer orients: its verdict says so, and the search goes on as after a
        failed verification)."""
        if self.member_check is None:
            return True
        if self.member_check(plan.labels, plan.heights, plan.verdict, plan.speeds):
            return True
        plan.verdict = dict(plan.verdict, orients=False, broken_by_worst_member=True)
        return False

    @property
    def keeps_members(self) -> bool:
        """True when the family check keeps worst members that broke earlier plans."""
        return self.member_check is not None and bool(self.member_check.breakers)

    def broken_by_known_members(self, heights, speeds, screened=None, allowed: int = 0) -> np.ndarray:
        """True for each sequence (rows of ``heights``, ``speeds``) that a worst
        member kept from earlier plans breaks whatever its set
        (``FamilyChecker.prescreen``; ``screened``: the sequences' finals and
        jams on some of the trials, of which at most ``allowed`` may fall
        outside the set); all False without a family check."""
        if self.member_check is None:
            return np.zeros(np.atleast_2d(heights).shape[0], bool)
        return self.member_check.prescreen(heights, speeds, self.bench.tolerance, screened, allowed)

    def certify(self, found: list, heights, speeds, n_pins: int, beat: Heartbeat,
                deadline: Deadline = NO_DEADLINE) -> tuple[list, list]:
        """``(certified, untried)``: the plans of ``found`` (whose pins are the
        rows of ``heights`` and ``speeds``) whose verdict on the held-out
        trials orients the part, and those the time limit left unreplayed.
        Each certified plan's ``verdict`` becomes its held-out verdict (with
        the width's bootstrap interval) and ``selection`` keeps the verdict on
        the trials that chose it. ``beat`` hears how far it got.

        Under a time limit (``deadline``) the plans are replayed one at a
        time, in the order given (the caller's ranking, best first), until
        the limit has passed: the ones left are ``untried`` (never plans:
        unverified candidates)."""
        if not found:
            return [], []
        rows = self.bench.held_out(n_pins)
        step = 1 if deadline.limited else max(1, MAX_ROWS // rows[0].size)
        out = []
        with beat:
            for start in range(0, len(found), step):
                if start and deadline.over():
                    beat.finish(start, "the time limit has passed: the others are not replayed")
                    return out, found[start:]
                stop = min(len(found), start + step)
                verdicts = self.bench.judge(heights[start:stop], speeds[start:stop], rows, interval=True,
                                            stretch=beat.stretch(start, stop))
                for plan, held in zip(found[start:stop], verdicts):
                    plan.selection, plan.verdict = plan.verdict, held
                    if held["orients"]:
                        out.append(plan)
        return out, []
