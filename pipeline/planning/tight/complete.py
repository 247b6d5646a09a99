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

1. enumerate all sequences of the level by nominal rollouts (on the deepest
   level a sequence stops once its finals spread over ``T + SLACK_DEG``:
   it could not be kept in step 2; see :mod:`~pipeline.planning.tight.enumerate`);
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
   (``VerifySettings.held_out``: a fresh seed no screen or selection drew
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
``planner.width_slack_deg``
(:func:`~pipeline.planning.tight.records.robust_order`); at least
``candidates`` survivors of step 3 are judged (all of them if fewer), so the
width ranking is over those; blocks after that are not screened (``not_screened`` in the
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
levels before are complete). A level's first screen likewise stops once it
has used ``pacing.PROBE_SHARE`` of the search time left when it began
(unless it ends leaving ``pacing.JUDGE_SHARE`` of it), and the level goes on
with the sequences it probed. It is then complete only up to the last level it finished: the
result says so (``complete``, ``unsearched``: the level cut short and how
far it got, the levels not reached, the evidence not judged), and its "no"
covers the sequences searched only. Orienting sequences found before the
stop are still certified on held-out trials, one at a time and best first,
while the limit lasts; those it leaves no time for are ``unverified``
candidates, never plans.

Who does what. :class:`FixedPinSearch` drives the levels (steps 1 and 6, the
ranking and the evidence); a :class:`~pipeline.planning.tight.screen.LevelScreen`
takes one level through steps 2 to 5 (``screen.py``, with the screen's
constants ``SLACK_DEG``, ``PROBE``, ``SCREEN``, ``CASCADE`` and
``SCREEN_BLOCK``); :class:`~pipeline.planning.tight.judge.TrialBench` replays and
judges sequences on the trials, and
:class:`~pipeline.planning.tight.judge.Certifier` checks the orienting ones
against the support family and the held-out trials (``judge.py``); the plans,
the search's answer and their ranking are records of ``records.py``.
"""
from __future__ import annotations

import time

import numpy as np

from pipeline.parts.part import Part
from pipeline.planning.tight.enumerate import Level, NominalTree
from pipeline.planning.tight.judge import Certifier, FamilyCheck, TrialBench, stack
from pipeline.planning.tight.records import CandidatePins, FixedPlan, FixedSearch, robust_order
from pipeline.planning.tight.screen import SLACK_DEG, LevelScreen
from pipeline.planning.core.settings import ClaimSettings, Friction, SearchSettings, VerifySettings
from pipeline.planning.claims.replay import replay
from pipeline.progress import NO_DEADLINE, Deadline, Heartbeat, duration_text

EVIDENCE_PER_LEVEL = 4  # several-set sequences judged per level when nothing orients


def _distinct(plans) -> list:
    """``plans`` without repeats of a pin sequence (a sequence judged in its
    level may also be among the level's fewest-cluster evidence), first kept."""
    seen, out = set(), []
    for p in plans:
        if p.labels not in seen:
            seen.add(p.labels)
            out.append(p)
    return out


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
    (``enumerate.NominalTree``), hands them to a
    :class:`~pipeline.planning.tight.screen.LevelScreen`, stops at
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
                                bench.step.as_kwargs(), float(bench.verify.perturbation.pin_halfwidth),
                                search.d_min, search.d_max,
                                belt=bench.belt, speeds=self.pins.speeds, supports=nominal)
        self.prefix = FixedPlan((), (), 0.0, np.inf)  # the pins every sequence starts with (run)
        # The best results when nothing orients (``best_effort``): the moving-pin stage keeps
        # only the plans, so it turns this off (and its screens learn their hardest trials).
        self.evidence = True
        self.judge_pace = None  # seconds per sequence and pin of the last full judgement, from level to level

    def reuse_rollouts(self, other: "FixedPinSearch") -> None:
        """Take the nominal outcomes and the trials' states after each prefix
        that ``other`` (a search of the same part, pins, friction, trials and
        rollout settings, at another tolerance, say) has rolled out: both
        are functions of their keys alone (a rounded pose; a prefix and a
        trial), so this search finds exactly what it would alone, with fewer
        rollouts."""
        self.tree = other.tree
        self.bench.kept = other.bench.kept

    def shares_rollouts_with(self, other: "FixedPinSearch") -> bool:
        """Whether ``other``'s rollouts are this search's own
        (:meth:`reuse_rollouts`): the same part, pins (heights and speeds, in
        order), friction, trials, supports and rollout settings; the
        tolerance, the claim and the evidence may differ. Only searches under
        uniform pressure (no support family) are compared."""
        a, b, mine, theirs = self.tree, other.tree, self.bench, other.bench
        # the tree's friction, pin radius, model, kernel and pin tolerance come from the bench's settings
        return (a.part is b.part and np.array_equal(a.heights, b.heights) and np.array_equal(a.speeds, b.speeds)
                and (a.d_min, a.d_max) == (b.d_min, b.d_max)
                and a.supports == b.supports == [None] and mine.family is theirs.family is None
                and (mine.mu_c, mine.pin_radius, mine.model, mine.step, mine.belt, mine.verify)
                == (theirs.mu_c, theirs.pin_radius, theirs.model, theirs.step, theirs.belt, theirs.verify))

    @property
    def member_check(self) -> FamilyCheck | None:
        """With a family: the check of a plan against the family's worst member
        (a :class:`~pipeline.planning.tight.judge.FamilyCheck`, the planner's
        ``worst_member.FamilyChecker``); else ``None``. The certifier holds it,
        and the levels ask it about the family."""
        return self.certifier.member_check

    @member_check.setter
    def member_check(self, check: FamilyCheck | None) -> None:
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
        # the deepest level's nominal span stop (and whether its evidence may be wanted)
        span = (self.bench.tolerance + SLACK_DEG, self.bench.order, self.evidence)
        for level in self.tree.levels(depth, root, self._level_heralds(progress, deadline), deadline, span):
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
        screen.rank, screen.judge_pace = self.ranked, self.judge_pace
        found, judged, record = screen.search(candidates, progress, deadline)
        self.judge_pace = screen.judge_pace
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
        spread = (f" ({record['spread_out']} spread over {self.bench.tolerance + SLACK_DEG:g} deg before every "
                  "state was rolled out)" if record.get("spread_out") else "")
        return (f"{self._name(n_pins)}: {record['sequences']} sequences{spread}, "
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
            runners_up.extend(screen.several_sets(min(candidates, EVIDENCE_PER_LEVEL), progress, self.tree.complete,
                                                  deadline.search_over))
            if screen.evidence_cut:
                result.unsearched.append(f"the fewest-set sequences of {screen.name}: ranked among the sequences "
                                         "rolled out in full only (the time limit ended the roll-out of the "
                                         "spread-out ones)")
            if screen.evidence_left:
                result.unsearched.append(f"the fewest-set sequences of {screen.name}: {screen.evidence_left} not "
                                         "judged (the time limit ended their judging)")
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
                                    bench.pin_radius, bench.model, bench.step.ds_max, bench.step.tol,
                                    **bench.belt, support=self.tree.column_support, supports=self.tree.supports)
        if (jam != "").any():
            return None
        return Level(np.zeros((1, 0), dtype=np.int16), theta[None, :], y_c[None, :], np.array([prefix.margin]))
