"""The complete search's records and how its plans rank.

:class:`FixedPlan` (a pin sequence and its verdict), :class:`FixedSearch`
(what the search found, with its evidence in words and its record for the
plan file) and :class:`CandidatePins` (the pins a search tries); the ranking
of plans (:func:`orientation_rank`, :func:`robust_order`) and the margin in d
for people (:func:`margin_text`). The search itself is
:mod:`pipeline.planning.tight.complete`.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from pipeline.config import schema_default
from pipeline.planning.claims import orient
from pipeline.planning.claims.confidence import DEFAULT_CONFIDENCE

WIDTH_SLACK_DEG = schema_default("planner", "width_slack_deg")  # a safe margin outranks this much width


def rejected_because(verdict: dict) -> str:
    """Why a judged sequence is not a plan, in words (its verdict does not orient the part)."""
    if verdict.get("broken_by_worst_member"):
        return "a worst member of the support family ends outside its set"
    if verdict.get("broken_by_known_member"):
        return "a member of the support family that broke an earlier plan ends outside its set"
    if verdict.get("point_rule"):
        return "its share in one set clears the point rule but not the confidence bound"
    if verdict.get("sets_within_tolerance", 2) > 1:
        return f"its trials end in {verdict['sets_within_tolerance']} sets"
    return "too few of its trials end in one set (jams count as failures)"


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
            text += (f"; best fixed-pin result, rejected because {rejected_because(v)}: {' '.join(b.labels)} "
                     f"ends in {v['sets_within_tolerance']} set(s) of at most {self.tolerance:g} deg, at most "
                     f"{v['in_tolerance']} of {v['trials']} trials in one")
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
