"""One level of the complete search: its sequences kept by their nominal span,
screened on growing subsets of the verification's trials, judged on all of
them and certified (steps 2 to 5 of :mod:`pipeline.planning.tight.complete`).
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from pipeline.planning.claims import orient
from pipeline.planning.tight import pacing
from pipeline.planning.tight.enumerate import Level
from pipeline.planning.tight.fewest import fewest_sets
from pipeline.planning.tight.judge import MAX_ROWS, Certifier, TrialBench, stack
from pipeline.planning.tight.records import CandidatePins, FixedPlan
from pipeline.progress import NO_DEADLINE, Deadline, Heartbeat

SLACK_DEG = 1.0  # nominal finals may spread this much beyond the tolerance and still be tried
PROBE = (6, 2)  # random trials and corners per resting state that order the candidates
SCREEN = (12, 8)  # random trials and corners per resting state in the screen
# Then larger subsets, each about four times the last, before the full trials:
# a sequence that fails more than the allowed trials of a subset fails at
# least as many of the full set (the best arc of the full set holds no more
# of the subset than the subset's best arc), so each stage rejects exactly
# what the full judgement would, at a fraction of its cost.
CASCADE = ((48, 64), (150, 384))
SCREEN_BLOCK = 96  # candidates screened at once
HARD_TRIALS = 64  # trials that failed most often in a level's judged sequences, tried first (moving pins)
HARD_FIRST = 16  # ... the hardest of them first: a subset rejects exactly (see CASCADE), at a quarter of the cost


@dataclass(eq=False)
class _Screened:
    """What the screen of a level has gathered so far: the plans that orient
    and hold for the family (``found``, their level rows ``found_idx``),
    every plan judged in full (``judged``), the orienting ones whose family
    check is still to come (``pending``, ``(row, plan)``) and how many
    sequences the cascade rejected (``cascaded``, counted as judged)."""
    found: list = field(default_factory=list)
    found_idx: list = field(default_factory=list)
    judged: list = field(default_factory=list)
    pending: list = field(default_factory=list)
    cascaded: int = 0

    def enough(self, candidates: int, family_checked: bool) -> bool:
        """True once a plan orients and (without a family check, see
        :attr:`LevelScreen.family_checked`) at least ``candidates`` sequences
        are judged or cascaded out."""
        return bool(self.found) and (family_checked or len(self.judged) + self.cascaded >= candidates)


class LevelScreen:
    """One level of the complete search: its sequences (the rows of
    ``level.seq``, after the pins of ``prefix``) kept by their nominal span,
    screened, judged and certified (steps 2 to 5 of the complete search,
    :mod:`pipeline.planning.tight.complete`).

    Parameters
    ----------
    level : the level's nominal paths (``enumerate.Level``).
    n_pins : the pins of each of its sequences, the prefix's included.
    prefix : the plan every sequence starts with (no pin: an empty plan).
    pins : the search's :class:`~pipeline.planning.tight.records.CandidatePins`.
    bench : the :class:`~pipeline.planning.tight.judge.TrialBench` that replays and judges.
    certifier : the :class:`~pipeline.planning.tight.judge.Certifier` of orienting verdicts.
    name : the level for people (progress lines).
    learn : when the search keeps no evidence (the moving-pin stage keeps its
        plans only), the trials that fail most often in the sequences judged
        so far (``HARD_TRIALS``) screen the later ones first, with the
        cascade: a subset rejects exactly (see ``CASCADE``), and the
        orienting sequences, the only ones kept, pass any subset.
    """

    def __init__(self, level: Level, n_pins: int, prefix: FixedPlan, pins: CandidatePins, bench: TrialBench,
                 certifier: Certifier, name: str, learn: bool = False):
        self.level, self.n_pins, self.prefix, self.pins = level, n_pins, prefix, pins
        self.bench, self.certifier, self.name = bench, certifier, name
        self.unverified = []  # orienting on the selection trials, left uncertified by a time limit
        self.learn = learn
        self.rank = lambda plans: sorted(plans, key=FixedPlan.rank_key)  # best first; the search sets its own
        self.fail_counts = None  # per trial of the full set: the judged sequences it failed (learn)
        self.evidence_cut = False  # the time limit ended the roll-out of its spread-out sequences
        self.evidence_left = 0  # ... or the judging of its fewest-set sequences, leaving this many
        self.judge_pace = None  # seconds per sequence and pin of the last full judgement (this level's or before)

    @property
    def family_checked(self) -> bool:
        """True with a support family (``Certifier.checks_family``): the
        orienting plans of a block are then checked at the block's end, best
        first, and the level ends with the first block where one holds;
        without, every orienting plan holds and the level ends once
        ``candidates`` sequences are judged (``_Screened.enough``)."""
        return self.certifier.checks_family

    def sequences(self, idx) -> tuple:
        """``(heights, speeds)`` of the level's rows ``idx`` (:meth:`CandidatePins.rows`)."""
        return self.pins.rows(self.prefix, self.level.seq[idx])

    def plan(self, idx, span, verdict) -> FixedPlan:
        """The plan of the level's row ``idx``, with its nominal span and verdict."""
        return self.pins.plan(self.prefix, self.level.seq[idx], span, self.level.margin[idx], verdict)

    def search(self, candidates: int, progress=None, deadline: Deadline = NO_DEADLINE):
        """``(orienting plans, every judged plan, the level's counts)``; each
        stage tells ``progress`` how far it has got. Once ``deadline``'s
        search is over the level stops between chunks of the first screen or
        between blocks of the screen, and the first screen stops early once it
        has used its share of the search time (:func:`~pipeline.planning.tight.pacing.probe_goes_on`; the
        level goes on with the sequences it probed); ``complete`` False and
        ``unsearched`` in its counts say how far it got. Orienting sequences
        are certified, best first, until the limit itself has passed (the
        rest are kept in ``unverified``)."""
        level, bench = self.level, self.bench
        record = {"sequences": level.size, "nominal_within": 0, "screened_out": 0, "judged": 0,
                  "orienting": 0, "not_screened": 0, "held_out": 0, "certified": 0}
        if level.size == 0:
            return [], [], record
        inputs = bench.trials(self.n_pins)
        n_total = sum(x[0].size for x in inputs)
        allowed = bench.allowed_failures(n_total)
        if allowed < 0:  # no plan of this length can be claimed, however it ends
            record["too_few_trials"] = n_total
        span = orient.row_spans(level.theta, bench.order)
        spread_out = level.spread_out  # (deepest level) their finals spread over the limit: never within
        if spread_out.any():
            record["spread_out"] = int(spread_out.sum())
        within = np.flatnonzero((span <= bench.tolerance + SLACK_DEG) & ~spread_out)
        within = within[np.lexsort((-level.margin[within], span[within]))]
        record["nominal_within"] = int(within.size)
        if within.size == 0:
            return [], [], record
        # A probe of a few trials per state orders the candidates (most promising
        # first) and already rejects the hopeless ones.
        with Heartbeat(f"{self.name}: first screen", within.size, "sequence", progress) as beat:
            probe_fails = self._probe(within, bench.screen_rows(inputs, *PROBE), beat, deadline)
        within, probe_cut = self._probed(within, probe_fails, record, deadline)
        if within is None:
            return [], [], record
        order = within[probe_fails <= allowed][np.argsort(probe_fails[probe_fails <= allowed], kind="stable")]
        record["screened_out"] = int(within.size - order.size)
        with Heartbeat(f"{self.name}: screening and judging", order.size, "sequence", progress) as beat:
            found, found_idx, judged = self._screen_and_judge(order, inputs, allowed, span, candidates,
                                                              record, beat, deadline)
        if probe_cut:
            record["unsearched"] = "; ".join(filter(None, [f"{probe_cut}, only those screened and judged",
                                                           record.get("unsearched")]))
        record["judged"], record["orienting"] = len(judged), len(found)
        return self._certify(found, found_idx, record, progress, deadline), judged, record

    def _certify(self, found, found_idx, record, progress, deadline: Deadline) -> list:
        """The plans of ``found`` (level rows ``found_idx``) that orient on
        held-out trials, replayed while ``deadline`` lasts; the ones left
        become ``unverified`` candidates, named in ``record``."""
        untried = found
        certified = []
        if found and not deadline.over():
            if deadline.limited:  # one at a time until the limit: the best (as the search ranks) first
                at = {id(plan): idx for plan, idx in zip(found, found_idx)}
                found = self.rank(found)
                found_idx = [at[id(plan)] for plan in found]
            certified, untried = self.certifier.certify(
                found, *self.sequences(np.asarray(found_idx, dtype=int)), self.n_pins,
                Heartbeat(f"{self.name}: held-out trials", len(found), "sequence", progress), deadline)
            record["held_out"], record["certified"] = len(found) - len(untried), len(certified)
        if untried:  # no time left to certify them: candidates, not plans
            self.unverified = untried
            record["complete"] = False
            record["unverified"] = len(untried)
            record["unsearched"] = "; ".join(filter(None, [
                record.get("unsearched"), f"{self.name}: the {len(untried)} sequence(s) orienting on the "
                                          f"selection trials not replayed on held-out trials (unverified)"]))
        return certified

    def _probed(self, within, probe_fails, record, deadline: Deadline) -> tuple:
        """``(rows, cut)``: the rows of ``within`` the probe reached (one count
        each in ``probe_fails``) and, when the limit ended it early, what it
        left (else ``None``); ``rows`` is None when none can be judged."""
        if probe_fails.size == within.size:
            return within, None
        cut = (f"{self.name}: the first screen reached {probe_fails.size:,} of the {within.size:,} "
               f"sequences within the tolerance nominally")
        record["complete"] = False
        record["probed"] = int(probe_fails.size)
        if probe_fails.size == 0 or deadline.search_over():
            record["unsearched"] = f"{cut}; none judged"
            return None, cut
        return within[:probe_fails.size], cut

    def _probe(self, within, rows, beat, deadline: Deadline) -> np.ndarray:
        """Failures of the level's rows ``within`` on the probe's ``rows``, all at
        once; under a time limit in chunks of ``pacing.PROBE_CHUNK``, stopping between
        them (fewer failures than ``within`` then) once the search is over or
        :func:`~pipeline.planning.tight.pacing.probe_goes_on` says so."""
        if not deadline.limited:
            return self.bench.failures(*self.sequences(within), rows, beat.stretch(0, within.size))
        out = []
        started = deadline.elapsed()
        search_end = started + deadline.search_left()
        for start in range(0, within.size, pacing.PROBE_CHUNK):
            if start and (deadline.search_over()
                          or not pacing.probe_goes_on(deadline.elapsed(), started, start, within.size,
                                                      search_end)):
                beat.finish(start, "the time limit ended the first screen here")
                break
            chunk = within[start:start + pacing.PROBE_CHUNK]
            out.append(self.bench.failures(*self.sequences(chunk), rows, beat.stretch(start, start + chunk.size)))
        return np.concatenate(out) if out else np.zeros(0, dtype=int)

    def _screen_and_judge(self, order, inputs, allowed, span, candidates, record, beat,
                          deadline: Deadline = NO_DEADLINE):
        """Screen the sequences ``order`` (level rows, most promising first) in
        blocks of ``SCREEN_BLOCK`` and judge the survivors on all the trials
        ``inputs``, until ``candidates`` are judged and one orients;
        ``(orienting plans, their rows, every judged plan)``. Adds the
        screened-out and not-screened counts to ``record``; ``beat`` is
        ticked with the sequences done.

        After the first ``candidates`` judged in full (the evidence's best
        results come from those), a survivor passes the ``CASCADE`` of larger
        subsets first: one rejected there fails the full trials as well, so
        it counts as judged (and not orienting) without its full replay.

        With a support family, the orienting plans of a block are checked
        against it at the end of the block, best first, and the level ends
        with the first block where one holds (``_check_family``): each check
        is a worst-member search, dearer than a wider ranking is worth.

        Once ``deadline``'s search is over no further block starts, and a
        block judges no further chunk after its first (the reserve is for
        verifying): the sequences left are counted as not screened or not
        judged, ``complete`` is False and ``unsearched`` says how many."""
        stages = self._screen_stages(inputs)
        got = _Screened()
        done = unjudged = 0
        timed_out = False
        while done < order.size and not got.enough(candidates, self.family_checked):
            if deadline.search_over():
                timed_out = True
                break
            block = order[done:done + SCREEN_BLOCK]
            unjudged = self._screen_block(block, done, stages, allowed, span, candidates, record, beat, got,
                                          deadline)
            done += block.size
            beat.tick(done)
            if unjudged:
                timed_out = True
                break
        self._close_screen(order.size, done, timed_out, got, record, beat, unjudged)
        return got.found, got.found_idx, got.judged

    def _screen_stages(self, inputs) -> tuple:
        """The trials of each stage of the screen, drawn from ``inputs``:
        ``(screen rows, all the rows, the cascade's rows, the screen's share
        of a block's work)``. The ``CASCADE`` keeps only the subsets larger
        than the screen and under half of all the trials."""
        bench = self.bench
        screen, full = bench.screen_rows(inputs, *SCREEN), stack(inputs)
        cascade = [rows for rows in (bench.screen_rows(inputs, *c) for c in CASCADE)
                   if screen[0].size < rows[0].size < full[0].size // 2]
        share = screen[0].size / (screen[0].size + full[0].size)  # the screen's share of a block's work
        return screen, full, cascade, share

    def _screen_block(self, block, done: int, stages: tuple, allowed: int, span, candidates: int, record, beat,
                      got: "_Screened", deadline: Deadline = NO_DEADLINE) -> int:
        """Screen one ``block`` of level rows (the ``done`` rows before it
        already screened) on the screen rows of ``stages``
        (:meth:`_screen_stages`) and judge its survivors in full, in chunks,
        into ``got``; stop once ``got`` has enough (see
        :meth:`_screen_and_judge`), or after the first chunk once
        ``deadline``'s search is over; under a limit a chunk is cut to what
        ends within the search time left (at least one sequence) at the pace
        :func:`~pipeline.planning.tight.pacing.judging_pace` estimates. With a
        family check (:attr:`family_checked`) the block's orienting plans are
        checked at its end, else as they are judged. Returns the survivors
        left unjudged."""
        screen, full, cascade, share = stages
        family_checked = self.family_checked
        started = time.monotonic()
        fails = self.bench.failures(*self.sequences(block), screen, beat.stretch(done, done + share * block.size))
        per_sequence = pacing.judging_pace(self.judge_pace, self.n_pins, time.monotonic() - started,
                                           block.size * screen[0].size, full[0].size)
        alive = block[fails <= allowed][np.argsort(fails[fails <= allowed], kind="stable")]
        record["screened_out"] += int(block.size - alive.size)
        judging = beat.stretch(done + share * block.size, done + block.size)
        step = max(1, min(candidates, MAX_ROWS // full[0].size))
        start = unjudged = 0
        while start < alive.size:
            if start and deadline.search_over():
                unjudged = int(alive.size - start)
                break
            lo, size = start, pacing.fitting(step, deadline.search_left(), per_sequence)
            start += size
            # members kept from this block's earlier plans already count
            chunk = self._drop_known_broken(alive[lo:start], screen, allowed, record)
            if len(got.judged) >= candidates:  # the first ones are judged in full, for the evidence
                before = chunk.size
                chunk = self._hard_trials(chunk, full, allowed, record)
                chunk = self._cascade(chunk, cascade, allowed, record)
                got.cascaded += before - chunk.size
            if chunk.size == 0:
                continue
            self._judge(chunk, full, span, got.judged, got.pending,
                        judging.part(lo / alive.size, (lo + chunk.size) / alive.size))
            if not family_checked:
                self._check_family(got.pending, got.found, got.found_idx, record)
            if got.enough(candidates, family_checked):
                break
        if family_checked:
            self._check_family(got.pending, got.found, got.found_idx, record, screen, allowed)
        return unjudged

    def _close_screen(self, n_order: int, done: int, timed_out: bool, got: "_Screened", record, beat,
                      unjudged: int = 0) -> None:
        """Record how the screen of ``n_order`` sequences ended after ``done``
        of them: the ones not screened, and, when the time limit ended it
        (``timed_out``; ``unjudged`` of the last block's survivors left),
        that the level is not complete and what it left unsearched; ``beat``
        says why it stopped early."""
        record["not_screened"] = int(n_order - done)  # left once enough orienting plans were found
        if timed_out:
            left = n_order - done + unjudged
            beat.finish(done, f"the time limit ended the screen here: the other {left} are not screened or judged")
            record["complete"] = False
            if unjudged:
                record["not_judged"] = unjudged
            record["unsearched"] = (f"{self.name}: {left:,} of the {n_order:,} sequences that passed the first "
                                    f"screen not screened or judged"
                                    + (f" (the plans found are ranked among the {len(got.judged)} judged)"
                                       if got.found else ""))
        elif done < n_order:
            beat.finish(done, f"the other {n_order - done} are not screened: enough orienting plans found")

    def _judge(self, chunk, rows, span, judged, pending, stretch) -> None:
        """Judge the level's rows ``chunk`` on all the trials ``rows``: each
        plan joins ``judged``, and ``(row, plan)`` joins ``pending`` when it
        orients (its family check still to come); times it (``judge_pace``)."""
        started = time.monotonic()
        finals, jammed = self.bench.replay(*self.sequences(chunk), rows, stretch)
        if self.learn:
            failed = self.bench.failing(finals, jammed).sum(axis=0)
            self.fail_counts = failed if self.fail_counts is None else self.fail_counts + failed
        for idx, verdict in zip(chunk, self.bench.verdicts(finals, jammed)):
            plan = self.plan(idx, span[idx], verdict)
            judged.append(plan)
            if verdict["orients"]:
                pending.append((idx, plan))
        self.judge_pace = (time.monotonic() - started) / (chunk.size * self.n_pins)

    def _check_family(self, pending, found, found_idx, record, screen=None, allowed: int = 0) -> None:
        """Move the plans of ``pending`` (``(row, plan)``, orienting on the
        selection trials) that hold for the support family to ``found``
        (``found_idx``: their rows), emptying ``pending``.

        Without a family every plan holds. With one, each check is a
        worst-member search, the dearest step of the search: the plans are
        checked best first (their rank on the selection trials) up to the
        first that holds, and the ones ranked after it are left unchecked
        (``family_unchecked`` in their verdict and in ``record``): they
        could only be alternatives to it. After a plan fails, the members
        kept so far prescreen the rest (``_drop_known_broken`` on the
        ``screen`` rows) before the next is checked."""
        if not self.family_checked:
            found += [plan for _, plan in pending]
            found_idx += [idx for idx, _ in pending]
            pending.clear()
            return
        queue = sorted(pending, key=lambda item: item[1].rank_key())
        pending.clear()
        while queue:
            idx, plan = queue.pop(0)
            if self.certifier.holds_for_family(plan):
                found.append(plan)
                found_idx.append(idx)
                for _, rest in queue:
                    rest.verdict = dict(rest.verdict, family_unchecked=True)
                record["family_unchecked"] = record.get("family_unchecked", 0) + len(queue)
                return
            if queue and screen is not None:
                left = set(self._drop_known_broken(np.array([i for i, _ in queue]), screen, allowed,
                                                   record).tolist())
                for i, rest in queue:
                    if i not in left:
                        rest.verdict = dict(rest.verdict, orients=False, broken_by_known_member=True)
                queue = [(i, rest) for i, rest in queue if i in left]

    def _hard_trials(self, alive, full, allowed: int, record):
        """``alive`` without the sequences that fail more than ``allowed`` of the
        ``HARD_TRIALS`` trials of ``full`` that failed most often in the
        sequences judged so far (``learn`` only; exact, as the ``CASCADE``),
        the ``HARD_FIRST`` hardest first (a near miss fails the same few);
        counted in ``record``."""
        counts = self.fail_counts
        if not self.learn or counts is None or alive.size == 0 or np.count_nonzero(counts) <= allowed:
            return alive
        order = np.lexsort((np.arange(counts.size), -counts))
        n_hard = min(HARD_TRIALS, np.count_nonzero(counts))
        subsets = [tuple(np.asarray(x)[order[:size]] for x in full)
                   for size in sorted({min(HARD_FIRST, n_hard), n_hard}) if size > allowed]
        record.setdefault("hard_trials_out", 0)
        return self._cascade(alive, subsets, allowed, record, "hard_trials_out")

    def _cascade(self, alive, cascade, allowed: int, record, counter: str = "cascade_out"):
        """``alive`` without the sequences that fail more than ``allowed`` trials
        of one of the growing subsets ``cascade`` (rows; see ``CASCADE``), in
        turn; the rejected ones are counted as screened out and under
        ``counter`` in ``record``."""
        for rows in cascade:
            if alive.size == 0:
                break
            fails = self.bench.failures(*self.sequences(alive), rows)
            record["screened_out"] += int((fails > allowed).sum())
            record[counter] = record.get(counter, 0) + int((fails > allowed).sum())
            alive = alive[fails <= allowed]
        return alive

    def _drop_known_broken(self, alive, screen, allowed: int, record):
        """``alive`` without the sequences the worst members kept from earlier
        plans break (``Certifier.broken_by_known_members``, sharpened by their
        finals on the ``screen`` trials, of which a plan may leave out at most
        ``allowed``): with a support family, a member that broke every
        candidate so far ends the level without judging the rest. Counted
        in ``record``."""
        if alive.size == 0 or not self.certifier.keeps_members:
            return alive
        heights, speeds = self.sequences(alive)
        broken = self.certifier.broken_by_known_members(heights, speeds, self.bench.replay(heights, speeds, screen),
                                                        allowed)
        if broken.any():
            record["broken_by_known_member"] = record.get("broken_by_known_member", 0) + int(broken.sum())
        return alive[~broken]

    def several_sets(self, candidates: int, progress=None, complete=None, stop=None) -> list:
        """The level's sequences whose nominal finals fall into the fewest
        clusters (gaps over the tolerance), judged in full (telling
        ``progress``): the evidence when nothing orients
        (:func:`~pipeline.planning.tight.fewest.fewest_sets`; ``complete``
        rolls out the spread-out sequences that might be among them until
        ``stop()``; ``evidence_cut`` then says the ranking is over the
        sequences rolled out in full only). They are judged one at a time,
        the fewest-set first, and once ``stop()`` no further one is
        (``evidence_left`` counts them): one judgement of a many-edged part
        takes seconds."""
        level, bench = self.level, self.bench
        if level.size == 0:
            return []
        beat = Heartbeat(f"{self.name}: rolling out the spread-out sequences that may have the fewest sets",
                         int(level.spread_out.sum()) if complete else 0, "sequence", progress)
        best, self.evidence_cut = fewest_sets(level, bench.tolerance, bench.order, candidates, complete, beat.tick,
                                              stop)
        if beat.last is not None:
            beat.finish(beat.done, "the time limit ended it here" if self.evidence_cut
                        else "the others cannot be among the fewest-set sequences")
        if best.size == 0:
            return []
        spread = orient.row_spans(level.theta[best], bench.order)
        rows = stack(bench.trials(self.n_pins))
        plans = []
        with Heartbeat(f"{self.name}: judging the fewest-set sequences for the evidence", best.size,
                       "sequence", progress) as beat:
            for k in range(best.size):
                if k and stop is not None and stop():
                    self.evidence_left = int(best.size - k)
                    beat.finish(k, "the time limit ended it here")
                    break
                verdict = next(bench.judge(*self.sequences(best[k:k + 1]), rows, stretch=beat.stretch(k, k + 1)))
                plans.append(self.plan(best[k], spread[k], verdict))
        return plans

