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
   trials cannot mend it);
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
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from kernels.rollout import DEFAULT_DS_MAX, DEFAULT_TOL

from pipeline.parts.part import Part
from pipeline.planning.claims import orient
from pipeline.planning.tight.enumerate import Level, NominalTree
from pipeline.planning.core.resting import resting_states
from pipeline.config import schema_default
from pipeline.planning.core.settings import ClaimSettings, Friction, SearchSettings, VerifySettings
from pipeline.planning.claims.confidence import DEFAULT_CONFIDENCE
from pipeline.planning.claims.verify import holdout_settings, replay, trial_inputs
from pipeline.progress import SILENT, Heartbeat, Stretch

SLACK_DEG = 1.0  # nominal finals may spread this much beyond the tolerance and still be tried
PROBE = (6, 2)  # random trials and corners per resting state that order the candidates
SCREEN = (12, 8)  # random trials and corners per resting state in the screen
SCREEN_BLOCK = 96  # candidates screened at once
MAX_ROWS = 150_000  # trials replayed in one batch
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
                    f"(held-out width {best.verdict['width_deg']:.1f} deg); no sequence of fewer does")
        text = f"no fixed-pin sequence of up to {self.depth} pins orients this part within {self.tolerance:g} deg"
        if self.best_effort:
            b = self.best_effort[0]
            v = b.verdict
            text += (f"; best fixed-pin result: {' '.join(b.labels)} ends in {v['sets_within_tolerance']} "
                     f"set(s) of at most {self.tolerance:g} deg, at most {v['in_tolerance']} of "
                     f"{v['trials']} trials in one"
                     + (", but a member of the support family ends outside that set"
                        if v.get("broken_by_worst_member") else ""))
        return text + self._too_few_trials()

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
                                 **b.verdict} for b in self.best_effort]}


class FixedPinSearch:
    """The complete search over ``pins`` (label -> height, mm) for one part and friction.

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
        self.part, self.mu_c, self.model = part, self.friction.value, search.model
        belt_speed, mu_s = search.belt_speed, search.mu_s
        self.belt = {} if belt_speed is None else {"belt_speed": float(belt_speed), "mu_s": float(mu_s)}
        self.labels = list(pins)
        self.heights = np.array([float(pins[k]) for k in self.labels])
        self.speeds = np.array([float((speeds or {}).get(k, 0.0)) for k in self.labels])
        self.tolerance, self.required = claims.tolerance_deg, claims.required
        self.confidence, self.rule = claims.confidence, claims.rule
        self.cfg = verify.as_dict()
        self.holdout = holdout_settings(self.cfg)
        self.width_slack = float(search.width_slack_deg)
        self.pin_radius = float(search.pin_radius)
        self.kernel = {"ds_max": DEFAULT_DS_MAX, "tol": DEFAULT_TOL, **search.kernel_settings}
        d_min, d_max, model = search.d_min, search.d_max, search.model
        self.order = part.symmetry_order()
        self.states = resting_states(part)
        self.family = None if family is None or family.is_uniform else family
        self.supports = None if self.family is None else self.family.kernel_supports
        nominal = None if self.family is None else [self.supports[k] for k in self.family.representatives]
        self.tree = NominalTree(part, self.heights, self.friction.nominal, self.pin_radius, model,
                                self.kernel, float(self.cfg["pin_halfwidth"]), d_min, d_max,
                                belt=self.belt, speeds=self.speeds, supports=nominal)
        self.prefix = FixedPlan((), (), 0.0, np.inf)  # the pins every sequence starts with (run)
        self.member_check = None  # with a family: worst_member.FamilyChecker (set by the planner)

    def run(self, depth: int, candidates: int = 12, keep: int = 5, progress=None,
            prefix: FixedPlan | None = None) -> FixedSearch:
        """Search levels 1 to ``depth`` (after the pins of ``prefix``, if given:
        every sequence then starts with them); stop at the first level with an
        orienting plan. ``progress`` (a function of one line of text) hears
        about each level and, at most every few seconds, how far each stage
        of a level has got (:class:`pipeline.progress.Heartbeat`)."""
        t0 = time.perf_counter()
        result = FixedSearch([], [], int(depth), self.tolerance, self.required,
                             confidence=self.confidence, rule=self.rule)
        runners_up, levels = [], []
        self.prefix, root = prefix or FixedPlan((), (), 0.0, np.inf), None
        if prefix is not None:
            root = self._after(prefix)
            if root is None:  # the prefix jams its own nominal path
                return result
        else:  # no pin at all: the resting states' own spread (a symmetric part may need none)
            empty = self.tree.root()
            result.resting = next(self._judge(empty, np.array([0]),
                                              self._stack(self._trials(0))))
        def enumeration(length, n):
            return Heartbeat(f"{self._name(len(self.prefix.labels) + length)}: nominal paths", n,
                             "candidate sequence", progress)

        for level in self.tree.levels(int(depth), root, enumeration):
            n_pins = len(self.prefix.labels) + (level.seq.shape[1] if level.size else len(result.levels) + 1)
            found, judged, record = self._level(level, candidates, progress)
            result.levels.append({"pins": n_pins, **record})
            if progress:
                progress(f"{self._name(n_pins)}: {record['sequences']} sequences, "
                         f"{record['nominal_within']} within {self.tolerance:g} deg nominally, "
                         f"{record['judged']} replayed in full, {record['orienting']} orient the part")
            runners_up.extend(judged)
            if found:
                result.plans = self.ranked(found)[:keep]
                break
            levels.append(level)
        if not result.plans:  # the evidence: the best several-set results of every level
            for level in levels:
                runners_up.extend(self._several_sets(level, min(candidates, EVIDENCE_PER_LEVEL), progress))
            result.best_effort = self.ranked(_distinct(runners_up))[:keep]
        result.rollouts = self.tree.rollouts
        result.seconds = time.perf_counter() - t0
        return result

    def _name(self, n_pins: int) -> str:
        """A level of the search for people: ``3 fixed pin(s)``, or its moving pins after the prefix."""
        if not self.speeds.any():
            return f"{n_pins} fixed pin(s)"
        after = " ".join(self.prefix.labels) or "no fixed pin"
        return f"{n_pins - len(self.prefix.labels)} moving pin(s) after {after}"

    def ranked(self, plans) -> list:
        """``plans`` best first (:func:`robust_order` with ``planner.width_slack_deg``)."""
        return robust_order(plans, FixedPlan.rank_key, FixedPlan.width, lambda p: p.margin, self.width_slack)

    def _after(self, prefix: FixedPlan):
        """The nominal level after ``prefix`` (its pins replayed exactly from the
        resting states at the middle friction), or None if it jams."""
        states = self.tree.start_poses()
        n = len(prefix.labels)
        speeds = prefix.speeds or (0.0,) * n
        theta, y_c, jam, _ = replay(self.part, list(prefix.heights), list(speeds), states[:, 0], states[:, 1],
                                    np.full(len(states), self.friction.nominal), np.zeros((len(states), n)),
                                    self.pin_radius, self.model, self.kernel["ds_max"], self.kernel["tol"],
                                    **self.belt, support=self.tree.column_support, supports=self.tree.supports)
        if (jam != "").any():
            return None
        return Level(np.zeros((1, 0), dtype=np.int16), theta[None, :], y_c[None, :], np.array([prefix.margin]))

    # ------------------------------------------------------------------ one level

    def _level(self, level, candidates, progress=None):
        """``(orienting plans, every judged plan, the level's counts)``; each
        stage tells ``progress`` how far it has got."""
        record = {"sequences": level.size, "nominal_within": 0, "screened_out": 0, "judged": 0,
                  "orienting": 0, "not_screened": 0, "held_out": 0, "certified": 0}
        if level.size == 0:
            return [], [], record
        n_pins = len(self.prefix.labels) + level.seq.shape[1]
        inputs = self._trials(n_pins)
        n_total = sum(x[0].size for x in inputs)
        allowed = orient.max_failures(n_total, self.required, self.confidence, self.rule)
        if allowed < 0:  # no plan of this length can be claimed, however it ends
            record["too_few_trials"] = n_total
        span = orient.row_spans(level.theta, self.order)
        within = np.flatnonzero(span <= self.tolerance + SLACK_DEG)
        within = within[np.lexsort((-level.margin[within], span[within]))]
        record["nominal_within"] = int(within.size)
        if within.size == 0:
            return [], [], record
        # A probe of a few trials per state orders the candidates (most promising
        # first) and already rejects the hopeless ones.
        name = self._name(n_pins)
        with Heartbeat(f"{name}: first screen", within.size, "sequence", progress) as beat:
            probe_fails = self._failures(level, within, self._screen_rows(inputs, *PROBE),
                                         beat.stretch(0, within.size))
        order = within[probe_fails <= allowed][np.argsort(probe_fails[probe_fails <= allowed], kind="stable")]
        record["screened_out"] = int(within.size - order.size)
        with Heartbeat(f"{name}: screening and judging", order.size, "sequence", progress) as beat:
            found, found_idx, judged = self._screen_and_judge(level, order, inputs, allowed, span, candidates,
                                                              record, beat)
        record["judged"], record["orienting"] = len(judged), len(found)
        certified = self._certify(level, found, np.asarray(found_idx, dtype=int), n_pins,
                                  Heartbeat(f"{name}: held-out trials", len(found), "sequence", progress))
        record["held_out"], record["certified"] = len(found), len(certified)
        return certified, judged, record

    def _screen_and_judge(self, level, order, inputs, allowed, span, candidates, record, beat):
        """Screen the sequences ``order`` (level rows, most promising first) in
        blocks of ``SCREEN_BLOCK`` and judge the survivors on all the trials
        ``inputs``, until ``candidates`` are judged and one orients;
        ``(orienting plans, their rows, every judged plan)``. Adds the
        screened-out and not-screened counts to ``record``; ``beat`` is
        ticked with the sequences done."""
        screen, full = self._screen_rows(inputs, *SCREEN), self._stack(inputs)
        share = screen[0].size / (screen[0].size + full[0].size)  # the screen's share of a block's work
        found, found_idx, judged = [], [], []
        step = max(1, min(candidates, MAX_ROWS // full[0].size))
        done = 0
        while done < order.size and not (found and len(judged) >= candidates):
            block = order[done:done + SCREEN_BLOCK]
            fails = self._failures(level, block, screen, beat.stretch(done, done + share * block.size))
            alive = block[fails <= allowed][np.argsort(fails[fails <= allowed], kind="stable")]
            record["screened_out"] += int(block.size - alive.size)
            judging = beat.stretch(done + share * block.size, done + block.size)
            done += block.size
            for start in range(0, alive.size, step):
                chunk = alive[start:start + step]
                verdicts = self._judge(level, chunk, full, stretch=judging.part(
                    start / alive.size, (start + chunk.size) / alive.size))
                for idx, verdict in zip(chunk, verdicts):
                    plan = self._plan(level, idx, span[idx], verdict)
                    judged.append(plan)
                    if verdict["orients"] and self._holds_for_family(plan):
                        found.append(plan)
                        found_idx.append(idx)
                if found and len(judged) >= candidates:
                    break
            beat.tick(done)
        record["not_screened"] = int(order.size - done)  # left once enough orienting plans were found
        if done < order.size:
            beat.finish(done, f"the other {order.size - done} are not screened: enough orienting plans found")
        return found, found_idx, judged

    def _certify(self, level, found, idx, n_pins, beat: Heartbeat) -> list:
        """The plans of ``found`` (level rows ``idx``) whose verdict on the held-out
        trials orients the part; each plan's ``verdict`` becomes its held-out
        verdict (with the width's bootstrap interval) and ``selection`` keeps
        the verdict on the trials that chose it. ``beat`` hears how far it got."""
        if not found:
            return []
        rows = self._stack(trial_inputs(self.states, self.mu_c, n_pins, self.holdout, self.family))
        out = []
        step = max(1, MAX_ROWS // rows[0].size)
        with beat:
            for start in range(0, idx.size, step):
                chunk = idx[start:start + step]
                verdicts = self._judge(level, chunk, rows, interval=True,
                                       stretch=beat.stretch(start, start + chunk.size))
                for plan, held in zip(found[start:start + step], verdicts):
                    plan.selection, plan.verdict = plan.verdict, held
                    if held["orients"]:
                        out.append(plan)
        return out

    def _holds_for_family(self, plan: FixedPlan) -> bool:
        """True without a family check; else whether the family's worst member
        found by ``member_check`` leaves the plan's set (a plan it breaks no
        longer orients: the search goes on as after a failed verification)."""
        if self.member_check is None:
            return True
        if self.member_check(plan.labels, plan.heights, plan.verdict, plan.speeds):
            return True
        plan.verdict = dict(plan.verdict, orients=False, broken_by_worst_member=True)
        return False

    def _plan(self, level, idx, span, verdict) -> FixedPlan:
        seq, pre = level.seq[idx], self.prefix
        return FixedPlan(pre.labels + tuple(self.labels[i] for i in seq),
                         pre.heights + tuple(float(self.heights[i]) for i in seq),
                         float(span), float(level.margin[idx]), verdict,
                         (pre.speeds or (0.0,) * len(pre.labels)) + tuple(float(self.speeds[i]) for i in seq))

    def _screen_rows(self, inputs, n_first: int, n_corners_wanted: int):
        """A subset of the verification trials: the first ``n_first`` random trials
        and ``n_corners_wanted`` evenly spread corners of each state."""
        n_random = int(self.cfg["trials"])
        rows = []
        for trials in inputs:
            n_corners = trials[0].size - n_random
            pick = list(range(min(n_first, n_random)))
            if n_corners:
                step = max(1, n_corners // n_corners_wanted)
                pick += list(range(n_random, trials[0].size, step))[:n_corners_wanted]
            rows.append(tuple(x[pick] for x in trials))
        return self._stack(rows)

    def _trials(self, n_pins: int) -> list:
        """The verification's trials for plans of ``n_pins`` pins (``verify.trial_inputs``)."""
        return trial_inputs(self.states, self.mu_c, n_pins, self.cfg, self.family)

    @staticmethod
    def _stack(rows):
        return tuple(np.concatenate([r[k] for r in rows]) for k in range(5))

    def _replay(self, level, idx, rows, stretch: Stretch = SILENT):
        """Final orientations ``(len(idx), trials)`` and jam flags of plans ``idx`` on ``rows``
        (``stretch`` is told how far the replay has got)."""
        th, yc, mu, offs, sup = rows
        n_trials, n_plans = th.size, idx.size
        pre = self.prefix
        pre_speeds = pre.speeds or (0.0,) * len(pre.labels)
        heights = np.hstack([np.tile(pre.heights, (n_plans, 1)), self.heights[level.seq[idx]]])
        speeds = np.hstack([np.tile(pre_speeds, (n_plans, 1)), self.speeds[level.seq[idx]]])
        tf, _, jam, _ = replay(self.part, np.repeat(heights, n_trials, axis=0),
                               np.repeat(speeds, n_trials, axis=0), np.tile(th, n_plans), np.tile(yc, n_plans),
                               np.tile(mu, n_plans), np.tile(offs, (n_plans, 1)), self.pin_radius,
                               self.model, self.kernel["ds_max"], self.kernel["tol"], **self.belt,
                               support=np.tile(sup, n_plans), supports=self.supports, stretch=stretch)
        return tf.reshape(n_plans, n_trials), (jam != "").reshape(n_plans, n_trials)

    def _failures(self, level, idx, rows, stretch: Stretch = SILENT):
        """Trials of ``rows`` that no one arc of the tolerance can hold, per plan
        (``stretch`` is told the share of plans done)."""
        out = np.empty(idx.size, dtype=int)
        step = max(1, MAX_ROWS // rows[0].size)
        for start in range(0, idx.size, step):
            chunk = idx[start:start + step]
            tf, jam = self._replay(level, chunk, rows,
                                   stretch.part(start / idx.size, (start + chunk.size) / idx.size))
            for k in range(chunk.size):
                held, _ = orient.best_arc(tf[k][~jam[k]], self.tolerance, self.order)
                out[start + k] = rows[0].size - held
        return out

    def _judge(self, level, idx, rows, interval: bool = False, stretch: Stretch = SILENT):
        tf, jam = self._replay(level, idx, rows, stretch)
        for k in range(idx.size):
            yield orient.judge(tf[k][~jam[k]], rows[0].size, self.tolerance, self.order, self.required,
                               self.confidence, interval, self.rule)

    # ------------------------------------------------------------------ when nothing orients

    def _several_sets(self, level, candidates, progress=None):
        """The level's sequences whose nominal finals fall into the fewest
        clusters (gaps over the tolerance), judged in full (telling ``progress``)."""
        if level.size == 0:
            return []
        period = 360.0 / self.order
        x = np.sort(np.mod(level.theta, period), axis=1)
        gaps = np.diff(np.concatenate([x, x[:, :1] + period], axis=1), axis=1)
        clusters = np.maximum(1, (gaps > self.tolerance).sum(axis=1))
        spread = period - gaps.max(axis=1)
        best = np.lexsort((-level.margin, spread, clusters))[:candidates]
        n_pins = len(self.prefix.labels) + level.seq.shape[1]
        inputs = self._trials(n_pins)
        with Heartbeat(f"{self._name(n_pins)}: judging the fewest-set sequences for the evidence", best.size,
                       "sequence", progress) as beat:
            verdicts = self._judge(level, best, self._stack(inputs), stretch=beat.stretch(0, best.size))
            return [self._plan(level, i, spread[i], v) for i, v in zip(best, verdicts)]
