"""The candidate plans of one friction: the complete fixed-pin search, the
moving pins after the best fixed-pin prefixes when fixed pins are not
enough, and the carried sets of the chosen sequences."""
from __future__ import annotations

from pipeline.parts.part import Part
from pipeline.planning.core.settings import PlannerSettings
from pipeline.planning.plans.planner import planner_for
from pipeline.planning.tight.certify import carried_plan
from pipeline.planning.tight.complete import FixedPinSearch
from pipeline.planning.tight.records import FixedPlan, FixedSearch
from pipeline.planning.claims.replay import ReplayMemo
from pipeline.progress import NO_DEADLINE, SILENT, Deadline, Heartbeat


MOVING_PREFIXES = 3  # best fixed-pin results (besides none) that moving pins may follow


MOVING_NOT_REACHED = "moving pins: not reached"  # how a time limit that came first is listed


def add_moving_pins(part: Part, settings: PlannerSettings, planner, fixed: FixedSearch, chosen, keep, progress,
                     family, checker, deadline: Deadline, candidates: list, selections: list,
                     unsearched: list, memo: ReplayMemo | None = None) -> tuple:
    """When fixed pins neither orient the part nor are unneeded: the moving
    pins' search after the ``chosen`` fixed-pin results (if the settings
    allow moving pins and the search time lasts; else ``unsearched`` says
    so). Its plans' carried sets join ``candidates`` and their selection
    verdicts ``selections``; what it left out joins ``unsearched``. Its
    trials' states join ``memo`` (the fixed-pin search's, whose states after
    the fixed prefixes it reads) while that is less than half full.

    Returns
    -------
    tuple
        ``(planner, moving_search)``: the planner whose pins the candidates
        use (the moving one once moving pins were searched) and the moving
        pins' :class:`FixedSearch` (``None`` when not searched).
    """
    moving = None if fixed.orients or fixed.needs_no_pin else _moving_planner(part, settings, planner)
    if moving is None:
        return planner, None
    if deadline.search_over():
        unsearched.append(f"{MOVING_NOT_REACHED} (up to {settings.search.dynamic_depth} moving pin(s) after "
                          f"no fixed pin and after the {MOVING_PREFIXES} best fixed-pin results)")
        return planner, None
    moving_search = _moving_search(part, settings, moving, chosen, keep, progress, family, checker, deadline,
                                   memo)
    unsearched += moving_search.unsearched
    carried = carried_sets(moving, moving_search.plans, settings.verify, family, progress, deadline, unsearched)
    candidates += carried
    selections += [p.selection or p.verdict for p in moving_search.plans[:len(carried)]]
    return moving, moving_search


def _pin_search(part, settings: PlannerSettings, planner, moving: bool, family=None,
                checker=None) -> FixedPinSearch:
    """The complete search over the planner's fixed pins (``moving`` False) or
    its moving pins (True), with the settings' claim, trials and search."""
    pins = {k: p for k, p in planner.pins.items() if bool(p.v_pin) == moving}
    search = FixedPinSearch(part, {k: p.y for k, p in pins.items()}, settings.friction, settings.claims,
                            settings.verify, settings.search,
                            speeds={k: p.v_pin for k, p in pins.items()}, family=family)
    search.member_check = checker
    search.evidence = not moving  # the moving-pin stage keeps its plans only
    return search


def fixed_search(part, settings: PlannerSettings, planner, depth, keep, progress, family=None,
                  checker=None, deadline: Deadline = NO_DEADLINE) -> tuple:
    """``(record, search)``: the complete fixed-pin search with the planner's
    pins and the settings, run (its :class:`FixedSearch` record), and the
    search itself, whose rollouts later searches of the same part and pins
    reuse (:meth:`FixedPinSearch.reuse_rollouts`)."""
    search = _pin_search(part, settings, planner, moving=False, family=family, checker=checker)
    return search.run(depth, candidates=settings.search.candidates, keep=keep, progress=progress,
                      deadline=deadline), search


def _moving_planner(part, settings: PlannerSettings, planner):
    """The planner with moving pins, if the settings allow them (else ``None``)."""
    if not (settings.search.dynamic_depth and settings.search.dynamic_speeds):
        return None
    return planner_for(part, settings, planner.lattices, moving=True)


def _moving_search(part, settings: PlannerSettings, moving, chosen, keep, progress, family=None,
                   checker=None, deadline: Deadline = NO_DEADLINE, memo: ReplayMemo | None = None) -> FixedSearch:
    """Up to ``search.dynamic_depth`` moving pins after no fixed pin and after
    each of the ``MOVING_PREFIXES`` best fixed-pin results, by the same
    enumeration, screen and judgement as the fixed pins; the orienting plans,
    best first.

    A plan that orients ranks before every plan with more pins
    (:func:`~pipeline.planning.tight.records.orientation_rank`), so once some
    sequence orients with ``k`` pins a prefix of ``L`` fixed pins is searched
    only up to ``k - L`` moving pins, and not at all when ``L >= k``
    (``skipped`` in the search's record): the plans left out could only rank
    after the one found. Under a time limit (``deadline``) the prefixes
    not reached and what each search left out are in ``unsearched``."""
    if progress:
        progress(f"mu_c {settings.friction.label}: fixed pins do not orient the part: adding moving pins")
    search = _pin_search(part, settings, moving, moving=True, family=family, checker=checker)
    if memo is not None and not memo.half_full:  # else its own memo, with room for its trials
        search.bench.kept = memo
    depth = settings.search.dynamic_depth
    total = FixedSearch([], [], depth, settings.claims.tolerance_deg, settings.claims.required,
                        time_limit=deadline.seconds)
    for prefix in [None, *chosen[:MOVING_PREFIXES]]:
        after = list(prefix.labels) if prefix else []
        if deadline.search_over():
            total.unsearched.append(f"moving pins after {' '.join(after) or 'no fixed pin'}: not reached")
            continue
        room = moving_room(total.plans, len(after), depth, fewer=family is not None)
        if room < 1:  # then room = (pins of the shortest plan found) - len(after), less one with a family
            total.skipped.append({"after": after,
                                  "why": f"a plan of {len(after) + room + (family is not None)} pins already "
                                         f"orients the part" + (" for the family" if family is not None else "")})
            continue
        res = search.run(room, candidates=settings.search.candidates, keep=keep, progress=progress,
                         prefix=prefix, deadline=deadline)
        total.plans += res.plans
        total.unsearched += res.unsearched
        total.levels += [dict(lv, after=after) for lv in res.levels]
        total.rollouts += res.rollouts
        total.seconds += res.seconds
    total.plans = sorted(total.plans, key=FixedPlan.rank_key)[:keep]
    return total


def moving_room(found: list, n_prefix: int, depth: int, fewer: bool = False) -> int:
    """How many moving pins to try after a prefix of ``n_prefix`` fixed pins:
    ``depth``, or fewer so that no sequence has more pins than the shortest
    orienting plan of ``found`` (0 or less: none); ``fewer``: so that each
    has fewer pins than it (with a support family, where a plan of as many
    pins would only be an alternative and each costs worst-member searches)."""
    fewest = min((len(p.labels) for p in found), default=None)
    return depth if fewest is None else min(depth, fewest - n_prefix - int(fewer))


def carried_sets(planner, chosen, verify, family, progress, deadline: Deadline = NO_DEADLINE,
             unsearched: list | None = None) -> list:
    """The carried sets of each chosen plan (``certify.carried_plan``), telling
    ``progress`` how many are done (and, between the propagation's rollout
    batches, that it is still at it). Once ``deadline`` has passed no further
    plan is started (each one started is then verified): the plans left are
    named in ``unsearched``. The first (the search's best) is always done,
    past the limit too: dropping it would leave no answer at all where the
    search had one (a certified plan's verification reads the held-out
    states its certification left; a best effort's replays its held-out
    trials). Sampled carried sets of plans that share their first pins
    share those rollouts (``verify.ReplayMemo``)."""
    out, memo = [], ReplayMemo()
    with Heartbeat("carried sets of the chosen plans", len(chosen), "plan", progress) as beat:
        try:
            for p in chosen:
                if out and deadline.over():
                    left = chosen[len(out):]
                    beat.finish(len(out), "the time limit has passed")
                    if unsearched is not None:
                        unsearched.append(f"carried sets and held-out verification of {len(left)} chosen "
                                          f"plan(s): skipped ({', '.join(' '.join(q.labels) for q in left)})")
                    break
                for lattice in planner.lattices.values():
                    lattice.stretch = beat.stretch(len(out), len(out))
                out.append(carried_plan(planner, p.labels, p.margin, verify, family, memo))
                beat.tick(len(out))
        finally:
            for lattice in planner.lattices.values():
                lattice.stretch = SILENT
    return out
