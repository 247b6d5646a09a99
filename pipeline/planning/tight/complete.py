"""The complete search for fixed-pin plans that orient a part within a tolerance.

What "complete" means here. Take the candidate pins, the depth ``N``, the
tolerance ``T`` and the verification's trials (``verify.trial_inputs``: the
configured random trials per resting state plus every corner of the
perturbation box). A sequence *orients* the part when at least
``verify.required`` of those trials end in one arc no wider than ``T``
(``orient.judge``; jams count as failures). The search returns a plan of
``n`` pins whenever some sequence of ``n <= N`` pins orients the part and
its nominal paths (``enumerate.NominalTree``: every resting state unperturbed,
at the middle friction, each pose rounded to 0.05 deg and mm) neither jam nor pass a centroid within the pins'
placement tolerance, and end within ``T + SLACK_DEG`` of each other; and it
never returns a plan with more pins than such a sequence. It does so by
trying every sequence, level by level:

1. enumerate all sequences of the level by nominal rollouts;
2. keep those whose nominal finals span at most ``T + SLACK_DEG`` (modulo the
   part's symmetry), narrowest first;
3. replay a small subset of the verification trials (``PROBE``: six random
   trials and two corners per state) for all of them at once, and order them
   by its failures; then, in blocks of ``SCREEN_BLOCK`` in that order, a larger
   subset (``SCREEN``: 12 and 8). A sequence whose subset already has more
   failures than the whole verification allows is rejected (exact: more
   trials cannot mend it); after the first ``candidates`` survivors of a
   level, two more subsets, each about four times the last (``CASCADE``),
   reject the same way before the full replay;
4. replay all the verification trials for the survivors and judge them
   (the *selection* trials);
5. certify each sequence that orients on them on *held-out* trials
   (``verify.holdout_settings``: a fresh seed no screen or selection drew
   from, at least as many trials): only a sequence whose held-out verdict
   orients the part counts, so a sequence chosen because its sample was
   lucky does not pass (the winner's curse);
6. stop at the first level where some sequence is certified.

"Orients" is the claim rule of :mod:`pipeline.planning.claims.orient`: the lower
confidence bound on the share of trials in one arc of ``T`` is at least
``verify.required`` (``verify.rule: point`` judges by the share alone).
Among the certified sequences of that level the narrowest held-out width
wins, then the larger margin in d, except that a sequence with a negative
margin yields to one with a positive margin whose width is within
``planner.width_slack_deg`` (:func:`robust_order`); at least ``candidates``
survivors of step 3 are judged (all of them if fewer), so the width ranking
is over those; blocks after that are not screened (``not_screened`` in the
level's counts).

The *margin in d* of a sequence is how far, as a share of the part's size
``a``, every contact offset ``|d|`` its nominal paths meet stays inside the
band ``planner.d_min <= |d| / a <= planner.d_max``: negative means some
pin meets the part outside it, next to a critical contact (near the line
through the centroid, where the turning direction flips, or near the end of
the outline, where the pin may miss), so a pin placed within its tolerance
may change the outcome.

When no sequence of up to ``N`` pins orients, the result says so with the
evidence: per level, how many sequences were enumerated, kept, screened out
and judged, and the best fixed-pin results found (the most trials in one set,
and the fewest sets within ``T``) among the judged sequences and the
``EVIDENCE_PER_LEVEL`` sequences of each level whose nominal finals fall
into the fewest clusters.

Under a time limit (a :class:`~pipeline.progress.Deadline`, ``planner.time_limit_s``)
the search reads the clock between its steps (a batch of nominal rollouts,
a chunk of the first screen, a block of ``SCREEN_BLOCK`` sequences) and
stops at the first step after its search time is over, keeping what it
judged. A level's enumeration stops earlier, once it has used
``enumerate.ENUMERATION_SHARE`` of the search time left when it began: the
sequences it enumerated are then screened and judged like a whole level's,
so a plan of that many pins may still be found (it has the fewest pins: the
levels before are complete). It is then complete only up to the last level it finished: the
result says so (``complete``, ``unsearched``: the level cut short and how
far it got, the levels not reached, the evidence not judged), and its "no"
covers the sequences searched only. Orienting sequences found before the
stop are still certified on held-out trials while the limit lasts; those it
leaves no time for are ``unverified`` candidates, never plans.

Who does what. :class:`FixedPinSearch` drives the levels (steps 1 and 6, the
ranking and the evidence); a :class:`LevelScreen` takes one level through
steps 2 to 5; :class:`~pipeline.planning.tight.judge.TrialBench` replays and
judges sequences on the trials, and
:class:`~pipeline.planning.tight.judge.Certifier` checks the orienting ones
against the support family and the held-out trials (``judge.py``).
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from pipeline.parts.part import Part
from pipeline.planning.claims import orient
from pipeline.planning.tight.enumerate import Level, NominalTree
from pipeline.planning.tight.judge import MAX_ROWS, Certifier, TrialBench, stack
from pipeline.config import schema_default
from pipeline.planning.core.settings import ClaimSettings, Friction, SearchSettings, VerifySettings
from pipeline.planning.claims.confidence import DEFAULT_CONFIDENCE
from pipeline.planning.claims.verify import replay
from pipeline.progress import NO_DEADLINE, Deadline, Heartbeat, duration_text

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
PROBE_CHUNK = 1024  # candidates probed at once under a time limit (the clock is read between chunks)
EVIDENCE_PER_LEVEL = 4  # several-set sequences judged per level when nothing orients
WIDTH_SLACK_DEG = schema_default("planner", "width_slack_deg")  # a safe margin outranks this much width


def orientation_rank(verdict: dict | None, n_pins: int, margin: float | None, n_moving: int = 0) -> tuple:
    """The ranking of plans (best first): plans that orient the part, by fewest
    pins, narrowest verified width, largest margin in d; then the near misses
    that clear the point rule but not its confidence bound, in the same order;
    then plans ending in
    several sets within the tolerance (those that jam too often last, then
    those with moving pins: a moving pin is there to orient the part, and a
    sensor finishes fixed pins' sets as well), by fewest sets, fewest pins,
    most trials in one set."""
    v = verdict or {}
    width = v.get("width_deg")
    margin = -margin if margin is not None and np.isfinite(margin) else 0.0
    if v.get("orients") or v.get("point_rule"):
        return (0, 0 if v.get("orients") else 1, 0, 0, n_pins, width, margin)
    trials = v.get("trials", 1)
    jams_decide = trials - v.get("jammed", 0) < v.get("needed", trials)  # too many jams for any set
    share = v.get("in_tolerance", 0) / max(1, trials)
    return (1, int(jams_decide), int(n_moving > 0), v.get("sets_within_tolerance", 10 ** 6), n_pins,
            -share, margin)


def margin_text(margin) -> str:
    """The margin in d for people, in words."""
    if margin is None or not np.isfinite(margin):
        return "margin in d: n/a (no pin touches the part on its nominal paths)"
    if margin >= 0.0:
        return (f"margin in d {margin:+.3f}: every contact of the nominal paths stays {margin:.3f} a "
                "inside the safe band d_min <= |d|/a <= d_max, away from the critical contacts")
    return (f"margin in d {margin:+.3f}: a contact of the nominal paths lies {-margin:.3f} a outside the "
            "safe band d_min <= |d|/a <= d_max, next to a critical contact, so a pin within its "
            "placement tolerance may change the outcome")


def _distinct(plans) -> list:
    """``plans`` without repeats of a pin sequence (a sequence judged in its
    level may also be among the level's fewest-cluster evidence), first kept."""
    seen, out = set(), []
    for p in plans:
        if p.labels not in seen:
            seen.add(p.labels)
            out.append(p)
    return out


def _safe(margin) -> bool:
    return margin is None or not np.isfinite(margin) or margin >= 0.0


def robust_order(plans, key, width, margin, slack: float = WIDTH_SLACK_DEG) -> list:
    """``plans`` sorted by ``key`` (best first), except that robustness ranks
    before a tenth of a degree: a plan with a negative margin in d yields to the
    best later plan of the same claim and pin count (the first five entries of
    ``key``) whose margin is not negative and whose width (``width(plan)``,
    deg) is within ``slack`` degrees of its own. ``margin(plan)`` may be None
    or infinite (no pin touches: nothing to be near)."""
    rest = sorted(plans, key=key)
    out = []
    while rest:
        best = rest[0]
        kb = key(best)
        if kb[0] == 0 and not _safe(margin(best)) and width(best) is not None:
            for p in rest[1:]:
                if key(p)[:5] == kb[:5] and _safe(margin(p)) and width(p) is not None \
                        and width(p) <= width(best) + slack:
                    best = p
                    break
        out.append(best)
        rest.remove(best)
    return out


@dataclass
class FixedPlan:
    """A fixed-pin sequence and its verdict: on the held-out trials once it has
    been certified (``selection``: its verdict on the trials that chose it),
    else on the verification (selection) trials."""
    labels: tuple
    heights: tuple
    nominal_span: float
    margin: float
    verdict: dict | None = None
    speeds: tuple = ()  # v_pin / v_b of each pin (empty: all fixed)
    selection: dict | None = None

    def width(self):
        """The verified width (deg) of the plan's verdict (None before it is judged, or
        when too many trials jammed)."""
        return (self.verdict or {}).get("width_deg")

    def rank_key(self):
        """Orienting first, then fewer pins, narrower verified width, larger margin."""
        return orientation_rank(self.verdict, len(self.labels), self.margin,
                                sum(1 for v in self.speeds if v))


@dataclass
class FixedSearch:
    """What the complete search found: ``plans`` orient the part (best first);
    ``best_effort`` are the best fixed-pin results when none does."""
    plans: list
    best_effort: list
    depth: int
    tolerance: float
    required: float
    levels: list = field(default_factory=list)
    confidence: float = DEFAULT_CONFIDENCE
    rule: str = "bound"
    rollouts: int = 0
    seconds: float = 0.0
    resting: dict | None = None  # the verdict on the resting states themselves (no pin)
    skipped: list = field(default_factory=list)  # moving pins: prefixes a shorter plan made moot
    time_limit: float | None = None  # seconds (None: no limit, the complete search)
    unsearched: list = field(default_factory=list)  # what a time limit left out, for people
    unverified: list = field(default_factory=list)  # orienting on the selection trials; no time for held-out

    @property
    def complete(self) -> bool:
        """True unless a time limit left part of the search out (``unsearched``)."""
        return not self.unsearched

    @property
    def complete_to(self) -> int:
        """Pins of the deepest level searched in full before any level a time limit cut short."""
        deepest = 0
        for lv in self.levels:
            if lv.get("complete") is False:
                break
            deepest = lv["pins"]
        return deepest

    @property
    def orients(self) -> bool:
        """True if some fixed-pin sequence orients the part."""
        return bool(self.plans)

    @property
    def needs_no_pin(self) -> bool:
        """True if the resting states alone end in one set within the tolerance
        (a part whose symmetry makes its resting states one orientation)."""
        return bool(self.resting and self.resting["orients"])

    def evidence(self) -> str:
        """One sentence: what was found, or why fixed pins are not enough."""
        if self.needs_no_pin:
            best = self.plans[0] if self.plans else None
            return (f"no pin is needed: the resting states alone orient this part within "
                    f"{self.tolerance:g} deg (verified width {self.resting['width_deg']:.1f} deg)"
                    + (f"; with pins, {' '.join(best.labels)} would end within "
                       f"{best.verdict['width_deg']:.1f} deg" if best else ""))
        if self.plans:
            best = self.plans[0]
            return (f"{len(best.labels)} fixed pins orient this part within {self.tolerance:g} deg "
                    f"(held-out width {best.verdict['width_deg']:.1f} deg); no sequence of fewer does"
                    + self._time_limit_text())
        if not self.complete:
            deepest = max((lv["pins"] for lv in self.levels), default=0)
            text = (f"no fixed-pin sequence of up to {deepest} pins among the sequences searched orients this "
                    f"part within {self.tolerance:g} deg" if deepest else
                    f"no fixed-pin sequence was searched")
        else:
            text = (f"no fixed-pin sequence of up to {self.depth} pins orients this part within "
                    f"{self.tolerance:g} deg")
        text += self._time_limit_text()
        if self.unverified:
            u = self.unverified[0]
            text += (f"; unverified candidate: {' '.join(u.labels)} orients on the selection trials "
                     f"(width {u.verdict['width_deg']:.1f} deg) but the time limit left no time to "
                     f"replay it on held-out trials")
        if self.best_effort:
            b = self.best_effort[0]
            v = b.verdict
            text += (f"; best fixed-pin result: {' '.join(b.labels)} ends in {v['sets_within_tolerance']} "
                     f"set(s) of at most {self.tolerance:g} deg, at most {v['in_tolerance']} of "
                     f"{v['trials']} trials in one"
                     + (", but a member of the support family ends outside that set"
                        if v.get("broken_by_worst_member") else ""))
        return text + self._too_few_trials()

    def _time_limit_text(self) -> str:
        """What a time limit left out, in words (empty when nothing was)."""
        if self.complete:
            return ""
        done = (f"complete up to {self.complete_to} pin(s) only" if self.complete_to
                else "no level searched in full")
        return f" (time limit {self.time_limit:g} s: {done}; not searched: {'; '.join(self.unsearched)})"

    def _too_few_trials(self) -> str:
        """Where some level's verification had too few trials for the claim at all."""
        short = [lv for lv in self.levels if lv.get("too_few_trials")]
        if not short:
            return ""
        need = orient.min_trials(self.required, self.confidence)
        return (f"; {short[0]['too_few_trials']} trials per plan of {short[0]['pins']} pin(s) cannot show "
                f"{100 * self.required:g} % at {100 * self.confidence:g} % confidence even with no failure "
                f"(at least {need} are needed): raise verify.trials, or set verify.rule: point")

    def to_dict(self) -> dict:
        """The search's record for the plan file (``fixed_pin_search``)."""
        return {"orients": self.orients, "needs_no_pin": self.needs_no_pin, "resting": self.resting,
                "depth": self.depth, "tolerance_deg": self.tolerance,
                "required": self.required, "confidence": self.confidence, "rule": self.rule,
                "evidence": self.evidence(), "levels": self.levels,
                "nominal_rollouts": self.rollouts, "seconds": round(self.seconds, 2),
                "best_effort": [{"pins": list(b.labels), "pin_heights_mm": list(b.heights),
                                 **b.verdict} for b in self.best_effort],
                **({} if self.time_limit is None else self.time_limit_record())}

    def time_limit_record(self) -> dict:
        """The time limit's part of the record: the limit, whether the search
        was complete, the deepest level searched in full, what was left out and
        the unverified candidates."""
        return {"time_limit_s": self.time_limit, "complete": self.complete, "complete_to_pins": self.complete_to,
                "unsearched": list(self.unsearched),
                "unverified": [{"pins": list(u.labels), "pin_heights_mm": list(u.heights), **(u.verdict or {})}
                               for u in self.unverified]}


@dataclass(eq=False)
class CandidatePins:
    """The candidate pins of a search: ``labels``, ``heights`` (mm) and
    ``speeds`` (``v_pin / v_b``, 0 for a fixed pin), indexed alike; the rows
    of a level's ``seq`` index them."""
    labels: list
    heights: np.ndarray
    speeds: np.ndarray

    def rows(self, prefix: FixedPlan, seq) -> tuple:
        """``(heights, speeds)``, one row per sequence: the pins of ``prefix``
        followed by those the rows of ``seq`` index."""
        n = seq.shape[0]
        pre_speeds = prefix.speeds or (0.0,) * len(prefix.labels)
        return (np.hstack([np.tile(prefix.heights, (n, 1)), self.heights[seq]]),
                np.hstack([np.tile(pre_speeds, (n, 1)), self.speeds[seq]]))

    def plan(self, prefix: FixedPlan, seq, span, margin, verdict) -> FixedPlan:
        """The plan of ``prefix`` followed by the pins the row ``seq`` indexes,
        with its nominal span, margin in d and verdict."""
        return FixedPlan(prefix.labels + tuple(self.labels[i] for i in seq),
                         prefix.heights + tuple(float(self.heights[i]) for i in seq),
                         float(span), float(margin), verdict,
                         (prefix.speeds or (0.0,) * len(prefix.labels)) + tuple(float(self.speeds[i]) for i in seq))


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

    def enough(self, candidates: int, lazy: bool) -> bool:
        """True once a plan orients and (without ``lazy`` family checks) at
        least ``candidates`` sequences are judged or cascaded out."""
        return bool(self.found) and (lazy or len(self.judged) + self.cascaded >= candidates)


class LevelScreen:
    """One level of the complete search: its sequences (the rows of
    ``level.seq``, after the pins of ``prefix``) kept by their nominal span,
    screened, judged and certified (steps 2 to 5 of the module's search).

    Parameters
    ----------
    level : the level's nominal paths (``enumerate.Level``).
    n_pins : the pins of each of its sequences, the prefix's included.
    prefix : the plan every sequence starts with (no pin: an empty plan).
    pins : the search's :class:`CandidatePins`.
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
        self.fail_counts = None  # per trial of the full set: the judged sequences it failed (learn)

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
        between blocks of the screen (``complete`` False and ``unsearched`` in
        its counts say how far it got); orienting sequences are certified
        unless the limit itself has passed (then they are kept in
        ``unverified``)."""
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
        within = np.flatnonzero(span <= bench.tolerance + SLACK_DEG)
        within = within[np.lexsort((-level.margin[within], span[within]))]
        record["nominal_within"] = int(within.size)
        if within.size == 0:
            return [], [], record
        # A probe of a few trials per state orders the candidates (most promising
        # first) and already rejects the hopeless ones.
        with Heartbeat(f"{self.name}: first screen", within.size, "sequence", progress) as beat:
            probe_fails = self._probe(within, bench.screen_rows(inputs, *PROBE), beat, deadline)
        if probe_fails.size < within.size:  # the time limit ended the first screen
            record["complete"] = False
            record["unsearched"] = (f"{self.name}: the first screen reached {probe_fails.size:,} of the "
                                    f"{within.size:,} sequences within the tolerance nominally; none judged")
            return [], [], record
        order = within[probe_fails <= allowed][np.argsort(probe_fails[probe_fails <= allowed], kind="stable")]
        record["screened_out"] = int(within.size - order.size)
        with Heartbeat(f"{self.name}: screening and judging", order.size, "sequence", progress) as beat:
            found, found_idx, judged = self._screen_and_judge(order, inputs, allowed, span, candidates,
                                                              record, beat, deadline)
        record["judged"], record["orienting"] = len(judged), len(found)
        if found and deadline.over():  # no time left to certify them: candidates, not plans
            self.unverified = found
            record["complete"] = False
            record["unverified"] = len(found)
            record["unsearched"] = "; ".join(filter(None, [
                record.get("unsearched"), f"{self.name}: the {len(found)} sequence(s) orienting on the selection "
                                          f"trials not replayed on held-out trials (unverified)"]))
            return [], judged, record
        certified = self.certifier.certify(
            found, *self.sequences(np.asarray(found_idx, dtype=int)), self.n_pins,
            Heartbeat(f"{self.name}: held-out trials", len(found), "sequence", progress))
        record["held_out"], record["certified"] = len(found), len(certified)
        return certified, judged, record

    def _probe(self, within, rows, beat, deadline: Deadline) -> np.ndarray:
        """Failures of the level's rows ``within`` on the probe's ``rows``, all at
        once; under a time limit in chunks of ``PROBE_CHUNK``, stopping between
        them once the search is over (fewer failures than ``within`` then)."""
        if not deadline.limited:
            return self.bench.failures(*self.sequences(within), rows, beat.stretch(0, within.size))
        out = []
        for start in range(0, within.size, PROBE_CHUNK):
            if start and deadline.search_over():
                beat.finish(start, "the time limit ended the first screen here")
                break
            chunk = within[start:start + PROBE_CHUNK]
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

        Once ``deadline``'s search is over no further block starts: the
        blocks left are counted as not screened, ``complete`` is False and
        ``unsearched`` says how many were left."""
        stages = self._screen_stages(inputs)
        lazy = self.certifier.member_check is not None  # family checks: once per block, best first
        got = _Screened()
        done = 0
        timed_out = False
        while done < order.size and not got.enough(candidates, lazy):
            if deadline.search_over():
                timed_out = True
                break
            block = order[done:done + SCREEN_BLOCK]
            self._screen_block(block, done, stages, allowed, span, candidates, record, beat, got, lazy)
            done += block.size
            beat.tick(done)
        self._close_screen(order.size, done, timed_out, got, record, beat)
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
                      got: "_Screened", lazy: bool) -> None:
        """Screen one ``block`` of level rows (the ``done`` rows before it
        already screened) on the screen rows of ``stages``
        (:meth:`_screen_stages`) and judge its survivors in full, in chunks,
        into ``got``; stop once ``got`` has enough (see
        :meth:`_screen_and_judge`). With ``lazy`` family checks the block's
        orienting plans are checked at its end."""
        screen, full, cascade, share = stages
        fails = self.bench.failures(*self.sequences(block), screen, beat.stretch(done, done + share * block.size))
        alive = block[fails <= allowed][np.argsort(fails[fails <= allowed], kind="stable")]
        record["screened_out"] += int(block.size - alive.size)
        judging = beat.stretch(done + share * block.size, done + block.size)
        step = max(1, min(candidates, MAX_ROWS // full[0].size))
        for start in range(0, alive.size, step):
            # members kept from this block's earlier plans already count
            chunk = self._drop_known_broken(alive[start:start + step], screen, allowed, record)
            if len(got.judged) >= candidates:  # the first ones are judged in full, for the evidence
                size = chunk.size
                chunk = self._hard_trials(chunk, full, allowed, record)
                chunk = self._cascade(chunk, cascade, allowed, record)
                got.cascaded += size - chunk.size
            if chunk.size == 0:
                continue
            self._judge(chunk, full, span, got.judged, got.pending,
                        judging.part(start / alive.size, (start + chunk.size) / alive.size))
            if not lazy:
                self._check_family(got.pending, got.found, got.found_idx, record)
            if got.enough(candidates, lazy):
                break
        if lazy:
            self._check_family(got.pending, got.found, got.found_idx, record, screen, allowed)

    def _close_screen(self, n_order: int, done: int, timed_out: bool, got: "_Screened", record, beat) -> None:
        """Record how the screen of ``n_order`` sequences ended after ``done``
        of them: the ones not screened, and, when the time limit ended it
        (``timed_out``), that the level is not complete and what it left
        unsearched; ``beat`` says why it stopped early."""
        record["not_screened"] = int(n_order - done)  # left once enough orienting plans were found
        if timed_out:
            beat.finish(done, f"the time limit ended the screen here: the other {n_order - done} are not "
                              "screened")
            record["complete"] = False
            record["unsearched"] = (f"{self.name}: {n_order - done:,} of the {n_order:,} sequences that "
                                    f"passed the first screen not screened or judged"
                                    + (f" (the plans found are ranked among the {len(got.judged)} judged)"
                                       if got.found else ""))
        elif done < n_order:
            beat.finish(done, f"the other {n_order - done} are not screened: enough orienting plans found")

    def _judge(self, chunk, rows, span, judged, pending, stretch) -> None:
        """Judge the level's rows ``chunk`` on all the trials ``rows``: each
        plan joins ``judged``, and ``(row, plan)`` joins ``pending`` when it
        orients (its family check still to come)."""
        finals, jammed = self.bench.replay(*self.sequences(chunk), rows, stretch)
        if self.learn:
            failed = self.bench.failing(finals, jammed).sum(axis=0)
            self.fail_counts = failed if self.fail_counts is None else self.fail_counts + failed
        for idx, verdict in zip(chunk, self.bench.verdicts(finals, jammed)):
            plan = self.plan(idx, span[idx], verdict)
            judged.append(plan)
            if verdict["orients"]:
                pending.append((idx, plan))

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
        if self.certifier.member_check is None:
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
        sequences judged so far (``learn`` only; exact, as the ``CASCADE``);
        counted in ``record``."""
        counts = self.fail_counts
        if not self.learn or counts is None or alive.size == 0 or np.count_nonzero(counts) <= allowed:
            return alive
        order = np.lexsort((np.arange(counts.size), -counts))
        hard = order[:min(HARD_TRIALS, np.count_nonzero(counts))]
        fails = self.bench.failures(*self.sequences(alive), tuple(np.asarray(x)[hard] for x in full))
        out = int((fails > allowed).sum())
        record["screened_out"] += out
        record["hard_trials_out"] = record.get("hard_trials_out", 0) + out
        return alive[fails <= allowed]

    def _cascade(self, alive, cascade, allowed: int, record):
        """``alive`` without the sequences that fail more than ``allowed`` trials
        of one of the growing subsets ``cascade`` (rows; see ``CASCADE``), in
        turn; the rejected ones are counted as screened out in ``record``."""
        for rows in cascade:
            if alive.size == 0:
                break
            fails = self.bench.failures(*self.sequences(alive), rows)
            record["screened_out"] += int((fails > allowed).sum())
            record["cascade_out"] = record.get("cascade_out", 0) + int((fails > allowed).sum())
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

    def several_sets(self, candidates: int, progress=None) -> list:
        """The level's sequences whose nominal finals fall into the fewest
        clusters (gaps over the tolerance), judged in full (telling
        ``progress``): the evidence when nothing orients."""
        level, bench = self.level, self.bench
        if level.size == 0:
            return []
        period = 360.0 / bench.order
        x = np.sort(np.mod(level.theta, period), axis=1)
        gaps = np.diff(np.concatenate([x, x[:, :1] + period], axis=1), axis=1)
        clusters = np.maximum(1, (gaps > bench.tolerance).sum(axis=1))
        spread = period - gaps.max(axis=1)
        best = np.lexsort((-level.margin, spread, clusters))[:candidates]
        inputs = bench.trials(self.n_pins)
        with Heartbeat(f"{self.name}: judging the fewest-set sequences for the evidence", best.size,
                       "sequence", progress) as beat:
            verdicts = bench.judge(*self.sequences(best), stack(inputs), stretch=beat.stretch(0, best.size))
            return [self.plan(i, spread[i], v) for i, v in zip(best, verdicts)]


def _empty_record(sequences: int) -> dict:
    """A level's counts before any of its sequences is screened."""
    return {"sequences": int(sequences), "nominal_within": 0, "screened_out": 0, "judged": 0, "orienting": 0,
            "not_screened": 0, "held_out": 0, "certified": 0}


def level_estimate(name: str, n: int, rate: float | None, deadline: Deadline = NO_DEADLINE) -> str:
    """A level's first progress line: its ``n`` candidate sequences and, from
    ``rate`` (candidate sequences per second over the level before; ``None``:
    none yet), about how long the level will take; under a time limit, the
    seconds of it left."""
    line = f"{name}: {n:,} candidate sequences"
    if rate:
        line += f", about {duration_text(n / rate)} at {rate:,.0f}/s (the pace of the level before)"
    if deadline.limited:
        left = max(0.0, deadline.left())
        line += f"; {left:.1f} s of the time limit left" if left < 10 else f"; {left:.0f} s of the time limit left"
    return line


class FixedPinSearch:
    """The complete search over ``pins`` (label -> height, mm) for one part and friction.

    The search drives the levels: it enumerates each level's nominal paths
    (``enumerate.NominalTree``), hands them to a :class:`LevelScreen`, stops at
    the first level with a certified plan and, when none orients, gathers the
    evidence. A :class:`~pipeline.planning.tight.judge.TrialBench` replays
    and judges the sequences; a :class:`~pipeline.planning.tight.judge.Certifier`
    checks the orienting ones (support family, held-out trials).

    Parameters
    ----------
    part : the part.
    pins : candidate fixed pins ``{label: height_mm}``.
    friction : a :class:`~pipeline.planning.core.settings.Friction` (or a
        value or range ``(lo, hi)``; the nominal paths use its middle, the
        trials sample it as verification does).
    claims : what "orients" means (tolerance, required share, confidence, rule).
    verify : the verification's trials (number, perturbation sizes, seed).
    search : rollout settings (pin radius, model, kernel), the margin's limits
        on ``|d|``, the belt (the dynamic model at ``belt_speed`` mm/s and
        ``mu_s`` instead of the quasi-static ``model``) and the ranking slack.
    speeds : ``{label: v_pin / v_b}`` for candidate pins that move (the
        others are fixed); :meth:`run` with a ``prefix`` lets them follow a
        fixed-pin sequence.
    family : a :class:`~pipeline.parts.support_family.SupportFamily` the
        plans must orient the part for: the nominal paths run under
        each of its ``representatives`` (the union over them is what must fit
        the tolerance) and the trials sample its members as the verification
        does; ``None``: uniform pressure.
    """

    def __init__(self, part: Part, pins: dict, friction, claims: ClaimSettings, verify: VerifySettings,
                 search: SearchSettings, speeds: dict | None = None, family=None):
        self.friction = Friction.parse(friction, None if isinstance(friction, Friction)
                                       else verify.perturbation.mu_sigma)
        self.bench = bench = TrialBench(part, self.friction, claims, verify, search, family)
        self.certifier = Certifier(bench)
        labels = list(pins)
        self.pins = CandidatePins(labels, np.array([float(pins[k]) for k in labels]),
                                  np.array([float((speeds or {}).get(k, 0.0)) for k in labels]))
        self.width_slack = float(search.width_slack_deg)
        nominal = None if bench.family is None else [bench.supports[k] for k in bench.family.representatives]
        self.tree = NominalTree(part, self.pins.heights, self.friction.nominal, bench.pin_radius, search.model,
                                bench.kernel, float(bench.cfg["pin_halfwidth"]), search.d_min, search.d_max,
                                belt=bench.belt, speeds=self.pins.speeds, supports=nominal)
        self.prefix = FixedPlan((), (), 0.0, np.inf)  # the pins every sequence starts with (run)
        # The best results when nothing orients (``best_effort``): the moving-pin stage keeps
        # only the plans, so it turns this off (and its screens learn their hardest trials).
        self.evidence = True

    def reuse_rollouts(self, other: "FixedPinSearch") -> None:
        """Take the nominal outcomes and the trials' states after each prefix
        that ``other`` (a search of the same part, pins, friction, trials and
        rollout settings, at another tolerance, say) has rolled out: both
        are functions of their keys alone (a rounded pose; a prefix and a
        trial), so this search finds exactly what it would alone, with fewer
        rollouts."""
        self.tree = other.tree
        self.bench.kept = other.bench.kept

    @property
    def member_check(self):
        """With a family: the check of a plan against the family's worst member
        (``worst_member.FamilyChecker``, set by the planner); else ``None``."""
        return self.certifier.member_check

    @member_check.setter
    def member_check(self, check) -> None:
        """Hand the family check to the certifier (``None``: no check)."""
        self.certifier.member_check = check

    def run(self, depth: int, candidates: int = 12, keep: int = 5, progress=None,
            prefix: FixedPlan | None = None, deadline: Deadline = NO_DEADLINE) -> FixedSearch:
        """Search levels 1 to ``depth`` (after the pins of ``prefix``, if given:
        every sequence then starts with them); stop at the first level with an
        orienting plan. ``progress`` (a function of one line of text) hears
        about each level (its first line: its candidate sequences and, from
        the pace of the level before, about how long it will take) and, at
        most every few seconds, how far each stage of a level has got
        (:class:`pipeline.progress.Heartbeat`). ``deadline``: a time limit
        (see the module's docstring); the result then says what it left
        unsearched."""
        t0, rollouts_before = time.perf_counter(), self.tree.rollouts
        bench = self.bench
        result = FixedSearch([], [], int(depth), bench.tolerance, bench.required,
                             confidence=bench.confidence, rule=bench.rule, time_limit=deadline.seconds)
        self.prefix, root = prefix or FixedPlan((), (), 0.0, np.inf), None
        if prefix is not None:
            root = self._after(prefix)
            if root is None:  # the prefix jams its own nominal path
                return result
        else:  # no pin at all: the resting states' own spread (a symmetric part may need none)
            empty = self.tree.root()
            result.resting = next(bench.judge(*self.pins.rows(self.prefix, empty.seq[np.array([0])]),
                                              stack(bench.trials(0))))
        runners_up, levels = [], []
        last = self._search_levels(result, root, int(depth), candidates, keep, progress, deadline,
                                   runners_up, levels)
        if deadline.limited and not result.plans:
            self._not_reached(result, last, int(depth))
        result.unverified = self.ranked(result.unverified)[:keep]
        if not result.plans and self.evidence:  # the best several-set results of every level
            self._gather_evidence(result, levels, runners_up, candidates, keep, progress, deadline)
        result.rollouts = self.tree.rollouts - rollouts_before
        result.seconds = time.perf_counter() - t0
        return result

    def _search_levels(self, result: FixedSearch, root, depth: int, candidates: int, keep: int, progress,
                       deadline: Deadline, runners_up: list, levels: list):
        """Enumerate and screen the levels after ``root`` (``None``: no pin)
        up to ``depth``, into ``result`` (its levels, plans, unverified
        candidates and what was left unsearched), until a level has a
        certified plan, a level is cut short or the levels run out. Every
        judged plan joins ``runners_up``, the :class:`LevelScreen` of each
        level without a plan joins ``levels``. Returns the deepest level
        enumerated in full (the root when none was)."""
        last = root if root is not None else self.tree.root()
        for level in self.tree.levels(depth, root, self._level_heralds(progress, deadline), deadline):
            n_pins = len(self.prefix.labels) + (level.seq.shape[1] if level.size else len(result.levels) + 1)
            if level.cut:  # the time limit ended the enumeration: screen what it enumerated, if time is left
                record = self._cut_level(result, level, n_pins, candidates, keep, progress, deadline,
                                         runners_up, levels)
                result.levels.append(record)
                result.unsearched.append(record["unsearched"])
                break
            record = self._screen(result, level, n_pins, candidates, keep, progress, deadline, runners_up, levels)
            result.levels.append({"pins": n_pins, **record})
            if record.get("unsearched"):
                result.unsearched.append(record["unsearched"])
            last = level
            if result.plans or record.get("complete") is False:
                break
        return last

    def _screen(self, result: FixedSearch, level: Level, n_pins: int, candidates: int, keep: int, progress,
                deadline: Deadline, runners_up: list, levels: list, whose: str = "") -> dict:
        """Screen, judge and certify the sequences of ``level`` (a
        :class:`LevelScreen`) and return its counts: its certified plans
        become ``result.plans`` (best first), its judged plans join
        ``runners_up`` and, when none is certified, its screen joins
        ``levels`` (for the evidence); ``whose`` ends its progress line."""
        screen = LevelScreen(level, n_pins, self.prefix, self.pins, self.bench, self.certifier, self._name(n_pins),
                             learn=not self.evidence)
        found, judged, record = screen.search(candidates, progress, deadline)
        if progress:
            progress(self._level_summary(n_pins, record) + whose)
        runners_up.extend(judged)
        result.unverified += screen.unverified
        if found:
            result.plans = self.ranked(found)[:keep]
        else:
            levels.append(screen)
        return record

    def _level_heralds(self, progress, deadline: Deadline):
        """The function ``NominalTree.levels`` calls as each level's
        enumeration starts (``(length, n)``: the level's length after the
        prefix and its candidate sequences): it tells ``progress`` the
        level's first line (:func:`level_estimate`, from the pace of the level
        before) and returns the enumeration's :class:`Heartbeat`."""
        pace = {}  # the level before: its candidate sequences and when it started

        def enumeration(length, n):
            name = self._name(len(self.prefix.labels) + length)
            now = time.perf_counter()
            if progress:
                rate = pace["n"] / max(now - pace["t"], 1e-9) if pace.get("n") else None
                progress(level_estimate(name, n, rate, deadline))
            pace.update(n=n, t=now)
            return Heartbeat(f"{name}: nominal paths", n, "candidate sequence", progress)

        return enumeration

    def _cut_level(self, result: FixedSearch, level: Level, n_pins: int, candidates: int, keep: int, progress,
                   deadline: Deadline, runners_up: list, levels: list) -> dict:
        """The record of a level of ``n_pins`` pins whose enumeration the time
        limit cut short: when search time is left, its enumerated sequences
        are screened and judged as a level's are (an orienting plan found
        there has the fewest pins, the levels before being complete, and is
        ranked among the sequences judged), else none is judged."""
        record = self._cut_record(level, n_pins)
        if level.size == 0 or deadline.search_over():
            return record
        screened = self._screen(result, level, n_pins, candidates, keep, progress, deadline, runners_up, levels,
                                " (of the sequences enumerated)")
        done, total = level.cut
        return {**record, **screened, "complete": False,
                "unsearched": "; ".join(filter(None, [
                    f"{self._name(n_pins)}: nominal paths of {done:,} of {total:,} candidate sequences rolled "
                    f"out, only those screened", screened.get("unsearched")]))}

    def _cut_record(self, level: Level, n_pins: int) -> dict:
        """The counts of a level of ``n_pins`` pins whose enumeration the time
        limit cut short (``level.cut``: rolled out, of how many): none judged."""
        return {"pins": n_pins, **_empty_record(level.size), "complete": False,
                "candidates": level.cut[1], "candidates_enumerated": level.cut[0],
                "unsearched": f"{self._name(n_pins)}: nominal paths of {level.cut[0]:,} of "
                              f"{level.cut[1]:,} candidate sequences rolled out, none judged"}

    def _level_summary(self, n_pins: int, record: dict) -> str:
        """A searched level's last progress line: its sequences, how many were
        within the tolerance nominally, replayed in full and orienting."""
        return (f"{self._name(n_pins)}: {record['sequences']} sequences, "
                f"{record['nominal_within']} within {self.bench.tolerance:g} deg nominally, "
                f"{record['judged']} replayed in full, {record['orienting']} orient the part")

    def _gather_evidence(self, result: FixedSearch, levels: list, runners_up: list, candidates: int, keep: int,
                         progress, deadline: Deadline) -> None:
        """When nothing orients: judge the fewest-set sequences of each of
        ``levels`` (while the search time lasts; the levels left are named in
        ``result.unsearched``) and keep the best of them and ``runners_up``
        as ``result.best_effort``."""
        for k, screen in enumerate(levels):
            if deadline.search_over():
                result.unsearched.append(f"the fewest-set sequences of {len(levels) - k} level(s) "
                                         "(the evidence when nothing orients): not judged")
                break
            runners_up.extend(screen.several_sets(min(candidates, EVIDENCE_PER_LEVEL), progress))
        result.best_effort = self.ranked(_distinct(runners_up))[:keep]

    def _not_reached(self, result: FixedSearch, last: Level, depth: int) -> None:
        """Add the levels up to ``depth`` that a time limit left unstarted to
        ``result.unsearched`` (``last``: the deepest level enumerated in full;
        after a level of no sequence no deeper level exists)."""
        reached = len(result.levels)
        cut_enumeration = bool(result.levels) and "candidates_enumerated" in result.levels[-1]
        if reached >= depth or (result.levels and not cut_enumeration and last.size == 0):
            return
        for length in range(reached + 1, depth + 1):
            name = self._name(len(self.prefix.labels) + length)
            known = length == reached + 1 and not cut_enumeration
            result.unsearched.append(f"{name}: not reached"
                                     + (f" ({last.size * self.pins.heights.size:,} candidate sequences)"
                                        if known else ""))

    def _name(self, n_pins: int) -> str:
        """A level of the search for people: ``3 fixed pin(s)``, or its moving pins after the prefix."""
        if not self.pins.speeds.any():
            return f"{n_pins} fixed pin(s)"
        after = " ".join(self.prefix.labels) or "no fixed pin"
        return f"{n_pins - len(self.prefix.labels)} moving pin(s) after {after}"

    def ranked(self, plans) -> list:
        """``plans`` best first (:func:`robust_order` with ``planner.width_slack_deg``)."""
        return robust_order(plans, FixedPlan.rank_key, FixedPlan.width, lambda p: p.margin, self.width_slack)

    def _after(self, prefix: FixedPlan):
        """The nominal level after ``prefix`` (its pins replayed exactly from the
        resting states at the middle friction), or None if it jams."""
        bench = self.bench
        states = self.tree.start_poses()
        n = len(prefix.labels)
        speeds = prefix.speeds or (0.0,) * n
        theta, y_c, jam, _ = replay(bench.part, list(prefix.heights), list(speeds), states[:, 0], states[:, 1],
                                    np.full(len(states), self.friction.nominal), np.zeros((len(states), n)),
                                    bench.pin_radius, bench.model, bench.kernel["ds_max"], bench.kernel["tol"],
                                    **bench.belt, support=self.tree.column_support, supports=self.tree.supports)
        if (jam != "").any():
            return None
        return Level(np.zeros((1, 0), dtype=np.int16), theta[None, :], y_c[None, :], np.array([prefix.margin]))
