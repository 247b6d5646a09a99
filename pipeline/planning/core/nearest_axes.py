"""What the two nearest-"yes" answers share: the tolerance ladder, one bisection, the axis records.

When no plan orients a part (:mod:`pipeline.planning.plans.nearest_part`)
or holds for a support family (:mod:`pipeline.planning.family.nearest`),
the planner answers axis by axis what would make one. Both answer a looser
tolerance on the same ladder (``LADDER`` steps up to ``MAX_TOLERANCE``),
both say the same about more pins (:func:`more_pins_axis`), an axis they
did not answer is the same record (:func:`unanswered_axis`), and one text
for people serves both (:func:`nearest_yes_lines`). Each answer says what it
is about in its ``subject`` key (:data:`SUBJECT_PART` or
:data:`SUBJECT_FAMILY`). :func:`bisect_smallest`
is the bisection of a family's axes (a smaller family or a looser tolerance
assumed not to break a plan that held); a part's tolerance is bisected on
the ladder itself (``plans.nearest_part.searched_tolerance``).
"""
from __future__ import annotations

import math

from pipeline.errors import PinfeedError

MAX_TOLERANCE = 45.0  # deg: the loosest tolerance asked about
LADDER = 0.5  # deg: tolerances are answered on this ladder

#: What a nearest "yes" is about, stored as the answer's ``subject``: a part
#: (under uniform pressure) or a support family (every member of it).
SUBJECT_PART = "part"
SUBJECT_FAMILY = "support family"
_HEADINGS = {SUBJECT_PART: "the nearest \"yes\" (each verified by full rollouts):",
             SUBJECT_FAMILY: "the nearest \"yes\" (each verified: worst-member search, then fresh members):"}


def ladder_up(tolerance: float, slack: float = 0.0) -> float:
    """``tolerance`` (deg) rounded up to the ``LADDER``; ``slack`` (in steps)
    forgives rounding error just above a step."""
    return math.ceil(tolerance / LADDER - slack) * LADDER


def bisect_smallest(holds_at, lo: float, hi: float, steps: int):
    """``(x, found)`` with ``x`` the smallest value in ``[lo, hi]`` found to
    hold (``holds_at(x)`` not None) in ``steps`` halvings, assuming it holds
    from some value on; ``found`` is ``holds_at``'s answer there.
    ``(None, None)`` when ``hi`` does not hold."""
    top = holds_at(hi)
    if top is None:
        return None, None
    best = (hi, top)
    for _ in range(steps):
        mid = 0.5 * (lo + hi)
        got = holds_at(mid)
        if got is None:
            lo = mid
        else:
            hi, best = mid, (mid, got)
    return best


def unanswered_axis(axis: str, statement: str) -> dict:
    """The record of an axis with no "yes": its name and why, in words."""
    return {"axis": axis, "found": False, "statement": statement}


def more_pins_axis(depth: int | None) -> dict:
    """The more-pins axis of a part or a family searched to ``depth`` pins:
    not searched; the line says how to run the deeper search."""
    return unanswered_axis("more pins", f"not searched (a deeper complete search costs more than the rest): "
                                        f"run with --depth {depth + 1 if depth else 'N+1'} or a finer --pins grid")


def nearest_yes_subject(nearest: dict, subject: str | None = None) -> str:
    """What the nearest "yes" ``nearest`` is about: :data:`SUBJECT_PART` or
    :data:`SUBJECT_FAMILY`. The answer's own ``subject`` key says it; an
    answer written before that key existed has none, and then ``subject``,
    the caller's word, does (the caller knows: a tight entry with a
    ``support_family`` holds a family's answer). Never guessed from the
    axes; refused when neither says, or when the two disagree."""
    stored = nearest.get("subject")
    if stored is not None and subject is not None and stored != subject:
        raise PinfeedError(f'the nearest "yes" is about a {stored}, not a {subject}')
    found = stored if stored is not None else subject
    if found not in _HEADINGS:
        raise PinfeedError(f'the nearest "yes" is about {found!r}: expected one of '
                           f'{", ".join(map(repr, _HEADINGS))}')
    return found


def nearest_yes_lines(nearest: dict, subject: str | None = None) -> list[str]:
    """The nearest "yes" of a part or a family for people: a heading and one
    line per axis. ``subject``: what it is about, for an answer written
    before answers said so themselves (see :func:`nearest_yes_subject`)."""
    out = [_HEADINGS[nearest_yes_subject(nearest, subject)]]
    for axis in nearest["axes"]:
        if not axis["found"] or "certificate" not in axis:
            verdict = axis.get("verdict") if axis["found"] else None
            tail = (f": {' '.join(axis['plan'])} holds {verdict['in_tolerance']} of {verdict['trials']} "
                    f"trials in one set" if verdict and axis.get("plan") else "")
            out.append(f"  {axis['axis']}: {axis['statement']}{tail}")
            continue
        claim = axis["certificate"]["claim"]
        verdict = "holds" if axis["holds"] else "does NOT hold on fresh members"
        out.append(f"  {axis['axis']}: {axis['statement']}: {' '.join(axis['plan'])} {verdict} "
                   f"(epsilon {100 * claim['epsilon']:.2f} % at beta {claim['beta']:g}, "
                   f"{claim['violations']} of {claim['members']} fresh members outside)")
    return out
