"""Whether a family's worst member breaks a plan: the check, and the checker the complete search calls.

A plan for a support family passed its sampled verification on the members
the family text draws; :func:`check_plan_for_family` then searches the
family's worst member (:func:`~pipeline.planning.family.member_search.search_worst_member`)
outside the set the plan claims (:func:`~pipeline.planning.claims.plan_claim.claimed_arc`). A member that breaks
the plan joins the verification's members, the plan is judged again and
the search runs again on the new set, up to ``MAX_ROUNDS`` times.

:class:`FamilyCheckSettings` is what the check reads: the planner's claim,
trials and mechanics (its typed settings) and the search's budget and seed.
:class:`FamilyChecker` is what the complete search calls on each plan that
passed its sampled verification; it keeps the members that broke a plan and
tries them first on the next (:meth:`FamilyChecker.prescreen`: whether they
break whole pin sequences before those are judged, :func:`arc_holds`).
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from pipeline.parts.support_family import SupportFamily
from pipeline.planning.claims import orient
from pipeline.planning.claims.plan_claim import claimed_arc, count_in_arc
from pipeline.planning.claims.replay import replay, replay_shared
from pipeline.planning.claims.trials import trial_inputs
from pipeline.planning.core.resting import resting_states
from pipeline.planning.core.settings import ClaimSettings, PlannerSettings, SearchSettings, VerifySettings
from pipeline.planning.family.member_search import (PlanProbe, WorstMember, check_budget, coarse_rows,
                                                    kernel_steps, score, search_worst_member)
from pipeline.planning.family.member_spaces import member_space
from pipeline.progress import Heartbeat

MAX_ROUNDS = 3  # worst member found -> joins the verification -> searched again
PRESCREEN_ROWS = 200_000  # rollouts per batch of the kept breakers' prescreen
PRESCREEN_CORNERS = 16  # corners per resting state in the kept members' middle prescreen stage


@dataclass
class FamilyCheckSettings:
    """How a plan is checked for a family: at friction ``mu_c`` (a value or
    ``(lo, hi)``), the planner's claim (``claims``: tolerance, required
    share, confidence, rule), its trials (``verify``) and its mechanics
    (``search``: pin radius, model, kernel steps, and the search's budget
    ``worst_member_budget``, checked when made); ``seed`` seeds the searches
    and the fresh members."""

    mu_c: object
    claims: ClaimSettings
    verify: VerifySettings
    search: SearchSettings
    seed: int = 0

    def __post_init__(self):
        check_budget(self.search.worst_member_budget)

    @classmethod
    def from_settings(cls, settings: PlannerSettings) -> "FamilyCheckSettings":
        """The planner's settings at its friction: its claim, its trials, its
        mechanics and its budget; the seed is the verification's."""
        return cls(settings.friction.value, settings.claims, settings.verify, settings.search, settings.verify.seed)

    @property
    def budget(self) -> int:
        """Member evaluations per worst-member search."""
        return check_budget(self.search.worst_member_budget)

    def with_tolerance(self, tolerance: float) -> "FamilyCheckSettings":
        """The same settings claiming one set of at most ``tolerance`` degrees."""
        return dataclasses.replace(self, claims=dataclasses.replace(self.claims, tolerance_deg=tolerance))

    def probe(self, part, heights, speeds=()) -> PlanProbe:
        """The probe of the plan of pins at ``heights`` (mm) with ``speeds``:
        its perturbation box's corners under these mechanics."""
        search = self.search
        return PlanProbe(part, tuple(float(h) for h in heights), self.mu_c, self.verify, search.pin_radius,
                         search.model, search.kernel_settings, tuple(float(v) for v in speeds))



def verify_members(part, heights, family: SupportFamily, st: FamilyCheckSettings, speeds=(),
                   progress=None, what: str = "verification on the family's members") -> dict:
    """The verification's trials of a plan (``verify.trial_inputs``) on ``family``,
    judged (``orient.judge``), with the arc a claim on them names
    (``claimed_arc_deg``, see :func:`family_claim_arc`) and how many of the
    trials end in it (``in_claimed_arc``). ``progress`` hears how far the
    trials have got (stage ``what``)."""
    inputs = trial_inputs(resting_states(part), st.mu_c, len(heights), st.verify.as_dict(), family)
    th, yc, mu, offs, sup = (np.concatenate([r[k] for r in inputs]) for k in range(5))
    search, claims = st.search, st.claims
    with Heartbeat(what, th.size, "trial", progress) as beat:
        tf, _, jam, _ = replay(part, list(heights), list(speeds) or [0.0] * len(heights), th, yc, mu, offs,
                               search.pin_radius, search.model, **kernel_steps(search.kernel_settings),
                               support=sup, supports=family.kernel_supports, stretch=beat.stretch(0, th.size))
    finals = tf[jam == ""]
    verdict = orient.judge(finals, th.size, claims.tolerance_deg, part.symmetry_order(), claims.required,
                           claims.confidence, rule=claims.rule)
    order = part.symmetry_order()
    arc = family_claim_arc(verdict, finals, claims.tolerance_deg, order)
    if arc is None:
        return {**verdict, "claimed_arc_deg": None, "in_claimed_arc": None}
    # Counted in the arc itself; stored, like the check's set, to 3 decimals (many trials end at
    # exactly the same orientation, on the end of the arc: a rounded end could leave them out).
    return {**verdict, "claimed_arc_deg": stored_set(arc, 360.0 / order),
            "in_claimed_arc": count_in_arc(finals, arc, order)}


def stored_set(arc: tuple, period: float) -> list:
    """A set ``(start, width)`` (deg) as the checks store it: ``[start, width]``,
    the start modulo ``period``, both to 3 decimals."""
    return [round(arc[0] % period, 3), round(arc[1], 3)]


def family_claim_arc(verdict: dict, finals, tolerance: float, order: int = 1) -> tuple | None:
    """The arc ``(start, width)`` (deg) a family claim names: the plan's
    claimed arc (``claimed_arc``), or, when no arc of the tolerance holds the
    required share (the verified set is wider), the arc of the tolerance
    that holds the most ``finals`` (modulo ``360 / order``); ``None``
    without a final."""
    arc = claimed_arc(verdict, tolerance)
    if arc is None or arc[1] > tolerance + 1e-9:
        if not len(finals):
            return None
        arc = (orient.best_arc(finals, tolerance, order)[1], tolerance)
    return arc


def known_member(probe: PlanProbe, members, arc: tuple, period: float, params=()) -> WorstMember | None:
    """The first of ``members`` (worst members kept from earlier plans) whose
    probe finals leave ``arc``, as a :class:`WorstMember` with its search
    parameters from ``params`` (one dict per member, when known); else None."""
    for k, support in enumerate(members):
        obj, tf = score(probe, support, arc, period)
        if obj > 0:
            found = params[k] if k < len(params) else {"member": support.label}
            return WorstMember(support, found, obj, tf, 1,
                               f"worst member kept from an earlier plan ({k + 1} of {len(members)})",
                               probe.nominal)
    return None


def check_plan_for_family(part, heights, family: SupportFamily, st: FamilyCheckSettings,
                          verdict: dict | None = None, speeds=(), progress=None, name: str = "the plan",
                          known=(), known_params=()) -> dict:
    """Search the worst member of ``family`` for the plan of pins at ``heights``
    (mm); when it breaks the plan, the member joins the verification's members
    and the plan is judged again, up to ``MAX_ROUNDS`` times.

    Returns a JSON-ready dict: ``holds`` (the last search found no member
    outside the re-judged set and the re-judged verification orients),
    ``worst_member`` (:meth:`WorstMember.to_dict`), ``members`` and ``trials``
    of the last verification, ``rounds`` (what each search found), the
    ``verdict`` and ``set_deg`` the claim rests on, ``space``. ``progress``
    hears how far each search and verification has got (the plan called ``name``).
    ``known``: members kept from earlier checks; the first round tries them
    first and searches only when none leaves the plan's set."""
    space = member_space(part, family)
    probe = st.probe(part, heights, speeds)
    period = 360.0 / part.symmetry_order()
    what = f"worst member of {family.label} for {name}"
    verdict = verdict or verify_members(part, heights, family, st, speeds, progress, f"{what}: verification")
    sampled = verdict  # the verdict on the family's sampled members, before any worst member joined
    joined, rounds, worst = family, [], None
    for k in range(MAX_ROUNDS):
        arc = claimed_arc(verdict, st.claims.tolerance_deg)
        if not verdict["orients"] or arc is None:
            break
        worst = known_member(probe, known, arc, period, known_params) if k == 0 and known else None
        if worst is None:
            beat = Heartbeat(f"{what}: search {k + 1}", st.budget, "member evaluation", progress)
            worst = search_worst_member(probe, space, arc, period, st.budget, st.seed + k, beat=beat)
        rounds.append({"set_deg": stored_set(arc, period), **worst.to_dict()})
        if not worst.breaks:
            break
        extra = dataclasses.replace(worst.support, label=f"worst member {k + 1}")
        joined = SupportFamily(f"{joined.label} + worst member {k + 1}", joined.members + (extra,),
                               tuple(joined.representatives) + (len(joined.members),))
        verdict = verify_members(part, heights, joined, st, speeds, progress,
                                 f"{what}: verification with worst member {k + 1}")
    holds = bool(verdict["orients"] and worst is not None and not worst.breaks)
    arc = claimed_arc(verdict, st.claims.tolerance_deg)
    return {"holds": holds, "space": space.describe(), "budget": st.budget,
            "members": len(joined.members), "trials": verdict["trials"],
            "verdict": verdict, "sampled_verdict": {k: sampled.get(k) for k in ("orients", "in_tolerance", "trials")},
            "set_deg": None if arc is None else stored_set(arc, period),
            "worst_member": None if worst is None else worst.to_dict(), "rounds": rounds,
            "_family": joined, "_worst": worst}


def arc_holds(must, tolerance: float, order: int = 1, others=None, allowed: int = 0) -> bool:
    """Whether one arc of ``tolerance`` degrees (modulo ``360 / order``) holds
    every angle of ``must`` and all but ``allowed`` of ``others`` (``(angles,
    jammed)``; a jammed one is never held)."""
    period = 360.0 / order
    x = np.sort(np.mod(np.asarray(must, float), period))
    if x.size == 0:
        return True
    gaps = np.diff(np.concatenate([x, [x[0] + period]]))
    k = int(np.argmax(gaps))
    first, span = x[(k + 1) % x.size], period - gaps[k]  # the smallest arc holding ``must``
    if span > tolerance + 1e-9:
        return False
    if others is None:
        return True
    theta, jammed = np.asarray(others[0], float)[~np.asarray(others[1], bool)], others[1]
    need = len(jammed) - int(allowed)
    if need <= 0:
        return True
    # Arcs that hold ``must`` start in [first - slack, first]; the count of
    # ``others`` held changes only where an arc's end reaches one of them or its
    # start passes one, so those starts and the range's ends are enough.
    slack = tolerance - span
    rel = np.mod(theta - (first - slack), period)
    ends = rel - tolerance
    starts = np.concatenate([[0.0, slack], rel[rel <= slack], ends[(ends >= 0.0) & (ends <= slack)]])
    held = ((np.mod(rel[None, :] - starts[:, None], period) <= tolerance + 1e-9).sum(axis=1))
    return bool(held.max() >= need)


class FamilyChecker:
    """What the complete search asks of a plan that passed its sampled
    verification: does the worst member of the family break it?
    Results are kept per pin sequence (``results``); each search tells
    ``progress`` (a function of one line) how far it has got.

    The worst members that broke a plan are kept (``breakers``): a member
    that breaks one plan often breaks its neighbours. A new plan's check
    tries the kept members first, in the first round of
    :func:`check_plan_for_family` (one that leaves the set joins the
    verification as a found one would, so the claim is the same), and
    searches only when none does. :meth:`prescreen` asks of many sequences
    at once, before they are judged, whether the kept members break them
    whatever their sets: when the kept members' probe finals and the screen
    trials leave no arc of the tolerance that could be claimed, no plan of
    the sequence holds for the family. That is exact for the members it
    replays (a family member shown by rollouts to end outside every possible
    set), and a member that breaks every candidate of a level ends that
    level before its sequences are judged.
    """

    def __init__(self, part, family: SupportFamily, settings: FamilyCheckSettings, progress=None):
        self.part, self.family, self.settings, self.progress = part, family, settings, progress
        self.space = member_space(part, family).describe()  # an empty space is an error before any search
        self.results: dict = {}
        self.breakers: list = []
        self.breaker_params: list = []  # each kept member's parameters (legs, coefficients)
        self.spared = {"searches": 0, "sequences": 0}

    def __call__(self, labels, heights, verdict: dict | None = None, speeds=()) -> bool:
        key = self.key(labels, heights)
        if key not in self.results:
            self.results[key] = check_plan_for_family(self.part, heights, self.family, self.settings,
                                                      verdict, speeds, self.progress, " ".join(labels),
                                                      known=tuple(self.breakers),
                                                      known_params=tuple(self.breaker_params))
            rounds = self.results[key]["rounds"]
            if rounds and rounds[0]["found_by"].startswith("worst member kept"):
                self.spared["searches"] += 1
            worst = self.results[key]["_worst"]
            if worst is not None and worst.breaks and not any(worst.support is b for b in self.breakers):
                self.breakers.append(worst.support)
                self.breaker_params.append(worst.params)
            self.results[key]["_speeds"] = tuple(float(v) for v in speeds)
        return self.results[key]["holds"]

    def prescreen(self, heights: np.ndarray, speeds: np.ndarray, tolerance: float, screened=None,
                  allowed: int = 0) -> np.ndarray:
        """True for each sequence (rows of ``heights``, ``speeds``) that the kept
        breakers break whatever the sequence's set.

        A plan for the family claims one arc of ``tolerance`` degrees that holds
        every kept member's probe finals (the resting states' nominal rollouts
        and the perturbation box's corners) and all but ``allowed`` of its
        verification trials. ``screened``, ``(finals, jammed)`` arrays
        ``(sequences, k)`` of some of those trials, makes the test sharper: no
        arc may then leave out more than ``allowed`` of them. A sequence is
        broken when a kept member's probe rollout jams or no such arc exists.

        In stages, each exact: the nominal rollouts first (if no arc holds
        them, none holds the whole probe), then ``PRESCREEN_CORNERS`` corners
        a state (the pins' diagonal), then, for the sequences left, the whole
        probe, or for a plan of many pins the rows the worst-member search
        scores on (:func:`coarse_rows`): a subset rejects less, never
        wrongly, at a fraction of the whole probe's cost."""
        heights, speeds = np.atleast_2d(heights), np.atleast_2d(speeds)
        broken = np.zeros(heights.shape[0], bool)
        if not self.breakers or heights.size == 0:
            return broken
        probe = self.settings.probe(self.part, (0.0,) * heights.shape[1])
        nominal = tuple(x[probe.nominal] for x in probe.inputs)
        last = probe.inputs if probe.coarse is None else probe.coarse
        few = tuple(x[coarse_rows(probe.inputs[3], probe.nominal, PRESCREEN_CORNERS)] for x in probe.inputs)
        stages = [nominal, few, last] if few[0].size < last[0].size else [nominal, last]
        for rows in stages:
            left = np.flatnonzero(~broken)
            if left.size == 0:
                break
            tf, jam = self._probe_finals(heights[left], speeds[left], rows)
            for j, i in enumerate(left):
                others = None if screened is None else (screened[0][i], screened[1][i])
                broken[i] = jam[j].any() or not arc_holds(tf[j], tolerance, self.part.symmetry_order(),
                                                          others, allowed)
        self.spared["sequences"] += int(broken.sum())
        return broken

    def _probe_finals(self, heights, speeds, rows) -> tuple[np.ndarray, np.ndarray]:
        """Finals and jam flags ``(sequences, members * rows)`` of every kept
        breaker on ``rows`` (``theta, y_c, mu, offsets``) past each sequence."""
        search, members = self.settings.search, len(self.breakers)
        th, yc, mu, offs = rows
        per = members * th.size  # rollouts per sequence
        kw = kernel_steps(search.kernel_settings)
        tfs, jams = [], []
        step = max(1, PRESCREEN_ROWS // per)
        for start in range(0, heights.shape[0], step):
            tf, jam = replay_shared(self.part, heights[start:start + step], speeds[start:start + step],
                                    np.tile(th, members), np.tile(yc, members), np.tile(mu, members),
                                    np.tile(offs, (members, 1)), search.pin_radius, search.model, **kw,
                                    support=np.repeat(np.arange(members), th.size), supports=list(self.breakers))
            tfs.append(tf)
            jams.append(jam)
        return np.concatenate(tfs), np.concatenate(jams)

    @staticmethod
    def key(labels, heights) -> tuple:
        """The cache key of a plan: its labels and heights."""
        return tuple(labels), tuple(round(float(h), 9) for h in heights)

    def result(self, labels, heights) -> dict | None:
        """The check of a plan already checked (else None)."""
        return self.results.get(self.key(labels, heights))
