"""How a level of the complete search spends its time under a time limit.

The deadline (:class:`pipeline.progress.Deadline`) says how much search time
is left; these rules say how a level's stages share it, so that a level
whose first stages could fill the limit still judges, and the reserve for
verifying stays whole: the enumeration's share is
:data:`pipeline.planning.tight.enumerate.ENUMERATION_SHARE`; the probe
(the level's first screen) goes on by :func:`probe_goes_on`; a chunk of
sequences judged in full is cut by :func:`fitting`, at the pace
:func:`judging_pace` estimates. Without a limit none of
these cuts anything.
"""
from __future__ import annotations

import math

from pipeline.planning.tight.enumerate import finishes_in_time

PROBE_CHUNK = 256  # candidates probed at once under a time limit (the clock is read between chunks)
PROBE_SHARE = 0.3  # of the search time left, the most a probe uses under a limit (see probe_goes_on) ...
JUDGE_SHARE = 0.5  # ... unless it ends leaving this share to screen and judge what it probed
# A full judgement's cost per trial over the screen's: the screen's trials meet
# the pins in states the probe and earlier blocks rolled out more often
# (measured 3.3 on the pear cam's 3- and 4-pin levels).
SCREEN_TO_JUDGE = 3.0


def probe_goes_on(now: float, started: float, done: int, total: int, search_end: float) -> bool:
    """Whether a level's probe, begun at ``started`` with ``done`` of its
    ``total`` sequences probed at ``now`` (seconds on the deadline's clock),
    goes on: within ``PROBE_SHARE`` of its time to ``search_end``, or past it
    if at its pace it ends leaving ``JUDGE_SHARE`` of that time to judge.
    A probe that would use up the search time leaves none judged, and no
    plan where one was within reach: the level then judges what it probed."""
    if now - started < PROBE_SHARE * (search_end - started):
        return True
    return finishes_in_time(now, started, done, total, search_end, leave=JUDGE_SHARE)


def fitting(step: int, seconds_left: float, per_sequence: float) -> int:
    """The sequences of a chunk to judge: ``step``, or under a time limit as
    many as end within ``seconds_left`` at ``per_sequence`` seconds each
    (at least one, so a block started always judges)."""
    if not math.isfinite(seconds_left) or per_sequence <= 0.0:
        return step
    return max(1, min(step, int(seconds_left / per_sequence)))


def judging_pace(judge_pace, n_pins: int, screen_seconds: float, screen_replays: int, full_trials: int) -> float:
    """Seconds to judge one sequence of ``n_pins`` pins on ``full_trials``
    trials: the last full judgement's ``judge_pace`` (seconds per sequence
    and pin; ``None`` before the first), or the screen's pace
    (``screen_seconds`` for ``screen_replays`` sequence-trial replays)
    times ``SCREEN_TO_JUDGE``, whichever is slower."""
    from_screen = screen_seconds / max(screen_replays, 1) * full_trials * SCREEN_TO_JUDGE
    return max((judge_pace or 0.0) * n_pins, from_screen)
