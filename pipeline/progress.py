"""Progress for long work: what a command is doing and how far it has got.

One idea (say on stderr that long work is moving, never on stdout), four tools:

* :func:`progress` iterates over items with a tqdm bar on a terminal; in
  logs (Snakemake rules, pipes), where a bar would fill the file with
  carriage returns, it prints one line when the stage starts, at every tenth
  of the way, and when it ends.
* :class:`Heartbeat` is for loops whose items take long or vary a lot (a
  level of the planner's search, the verification of candidates, a
  worst-member search): the loop calls :meth:`Heartbeat.tick` with how much
  is done, as often as it likes, and a line
  ``<what>: <done>/<total> <unit>s done (<pct>%, <elapsed> s)`` is printed
  at most once per *interval*, besides a line when the stage starts and one
  when it ends. A tick between lines costs a counter and a clock read.
* :class:`Stretch` is a part of a heartbeat's work that an inner loop reports
  into as a fraction (0 to 1), so that a function that rolls out a batch
  (``simulate.rollout_points``, ``verify.replay``) moves the bar of whatever
  stage called it. :func:`row_batches` splits such a batch into pieces of
  about :data:`BATCH_SECONDS` of work, so a tick comes between pieces even
  when one kernel call over the whole batch would take minutes; each row is
  computed exactly as in one call (the kernels roll out every row on its
  own), so results do not change.

Where the lines go: a heartbeat's own ``report`` (a function of one line,
such as the planner's ``progress`` callback), else the ``report`` of the
innermost :func:`reporting` block (``pinfeed`` wraps every command in one
that prints on stderr), else nowhere: a library call outside such a block is
silent and does not split its batches.

The interval is ``PINFEED_PROGRESS_SECONDS`` from the environment (seconds,
default :data:`DEFAULT_SECONDS`): with the default a long stage prints a line
at least every 5 to 6 seconds.

Long work may also have an end: a :class:`Deadline` (``pinfeed plan
--time-limit``) that the work reads between its steps, stopping there and
saying what it left undone; :func:`duration_text` writes the estimate of
how long a stage will take.
"""
from __future__ import annotations

import contextvars
import math
import os
import sys
import time
from contextlib import contextmanager

from pipeline.errors import PinfeedError

DEFAULT_SECONDS = 5.0  # default interval between progress lines of one stage
INTERVAL_VARIABLE = "PINFEED_PROGRESS_SECONDS"
BATCH_SECONDS = 1.0  # kernel work between two ticks of a split batch
FIRST_BATCH = 256  # rows of the first piece of a split batch (it sets the pace)
_REPORT = contextvars.ContextVar("pinfeed_progress_report", default=None)


@contextmanager
def reporting(report):
    """Inside this block, heartbeats without a ``report`` of their own send
    their lines to ``report`` (a function of one line; ``None``: nowhere)."""
    token = _REPORT.set(report)
    try:
        yield
    finally:
        _REPORT.reset(token)


def prefixed(label: str, report=None):
    """A report that puts ``label:`` before each line and passes it on to
    ``report`` (default: that of the enclosing :func:`reporting` block, looked
    up now); ``None`` when there is nowhere to pass it."""
    target = report if report is not None else _REPORT.get()
    if target is None:
        return None
    return lambda line: target(f"{label}: {line}")


def progress(items, total: int, desc: str, unit: str = "item", enabled: bool = True, stream=None):
    """Iterate ``items`` (``total`` of them) showing progress on ``stream`` (stderr).

    Off a terminal, a line at the start, at every tenth of the way and at
    the end, and, between them, at most one line per interval (a tenth of a
    slow loop may take minutes)."""
    stream = stream or sys.stderr
    if not enabled or total == 0:
        yield from items
        return
    if getattr(stream, "isatty", lambda: False)():
        from tqdm import tqdm
        yield from tqdm(items, total=total, desc=desc, unit=unit, file=stream)
        return
    beat = Heartbeat(desc, total, unit, report=lambda line: print(line, file=stream, flush=True))
    beat.start()
    step = max(1, total // 10)
    for k, item in enumerate(items, start=1):
        yield item
        if k % step == 0 or k == total:
            beat.line(k)
        else:
            beat.tick(k)


def progress_interval() -> float:
    """Seconds between two progress lines of one stage: ``PINFEED_PROGRESS_SECONDS``
    (a positive number), else :data:`DEFAULT_SECONDS`."""
    text = os.environ.get(INTERVAL_VARIABLE, "").strip()
    if not text:
        return DEFAULT_SECONDS
    try:
        seconds = float(text)
    except ValueError:
        seconds = math.nan
    if not (seconds > 0 and math.isfinite(seconds)):
        raise PinfeedError(f"{INTERVAL_VARIABLE} must be a positive number of seconds (e.g. 5), "
                           f"got {text!r}; fix or unset it")
    return seconds


class Heartbeat:
    """Progress lines of one stage of long work, at most one per ``interval``.

    Parameters
    ----------
    what : the stage, as people read it (``"3 fixed pins: screening"``).
    total : how many ``unit`` the stage has to do.
    unit : what is counted, singular (``"sequence"``).
    report : takes each line (the command's progress callback); ``None``:
        that of the enclosing :func:`reporting` block, if any, else silent
        (so is a stage with nothing to do).
    interval : seconds between lines (default :func:`progress_interval`).
    clock : seconds, monotonic (injectable for tests).
    check_every : read the clock only every this many ticks (for loops whose
        items take microseconds).

    Use as a context manager (a line when the stage starts, one when it ends
    without an error) or call :meth:`start` and :meth:`finish`.
    """

    def __init__(self, what: str, total: float, unit: str = "item", report=None,
                 interval: float | None = None, clock=time.monotonic, check_every: int = 1):
        self.what, self.total, self.unit = what, total, unit
        self.report = report if report is not None else _REPORT.get()
        self.interval = progress_interval() if interval is None and self.report else (interval or 0.0)
        self.clock, self.check_every = clock, max(1, int(check_every))
        self.done, self.started, self.last, self.ticks = 0.0, None, None, 0
        self.finished, self.shown = False, None  # shown: the count on the last line printed

    @property
    def enabled(self) -> bool:
        """True when the heartbeat prints: it has a ``report`` and something to do."""
        return self.report is not None and self.total > 0

    def start(self) -> "Heartbeat":
        """Print ``<what>: <total> <unit>s to do`` and start the clock."""
        if self.enabled:
            self.started = self.last = self.clock()
            self.report(f"{self.what}: {_count(self.total)} {_plural(self.unit, self.total)} to do")
        return self

    def tick(self, done: float | None = None) -> None:
        """``done`` (of ``total``; ``None``: as before) is done; print a line if
        the interval has passed since the last one."""
        if done is not None:
            self.done = done
        if not self.enabled:
            return
        self.ticks += 1
        if self.ticks % self.check_every:
            return
        if self.last is None:
            self.start()
        elif self.clock() - self.last >= self.interval:
            self.line(self.done)

    def line(self, done: float, note: str = "") -> None:
        """Print how far the stage has got now, whatever the interval (``note``
        is appended after a semicolon)."""
        self.done = done
        if not self.enabled:
            return
        if self.started is None:
            self.started = self.clock()
        self.last, self.shown = self.clock(), done
        share = self.done / self.total if self.total else 1.0
        self.report(f"{self.what}: {_count(self.done)}/{_count(self.total)} {_plural(self.unit, self.total)} done "
                    f"({int(100 * share + 1e-9)}%, {self.last - self.started:.0f} s)"
                    + (f"; {note}" if note else ""))

    def finish(self, done: float | None = None, note: str = "") -> None:
        """Print the last line (once, unless the line before said the same):
        ``done`` (default all of ``total``) is done, with ``note`` saying why
        when the stage stopped early."""
        done = self.total if done is None else done
        if not self.finished and (note or self.shown != done):
            self.line(done, note)
        self.finished = True

    def stretch(self, lo: float, hi: float) -> "Stretch":
        """The work from ``lo`` to ``hi`` (of ``total``), for an inner loop to report into."""
        return Stretch(self, lo, hi)

    def __enter__(self) -> "Heartbeat":
        return self.start()

    def __exit__(self, kind, value, traceback) -> None:
        if kind is None:
            self.finish()


class Stretch:
    """A part (``lo`` to ``hi`` of its total) of a :class:`Heartbeat`'s work,
    reported into as a fraction: ``tick(0.5)`` ticks the heartbeat at
    ``lo + 0.5 (hi - lo)``. ``beat`` ``None``: reports nowhere (:data:`SILENT`)."""

    def __init__(self, beat: Heartbeat | None, lo: float = 0.0, hi: float = 1.0):
        self.beat, self.lo, self.hi = beat, float(lo), float(hi)

    @property
    def enabled(self) -> bool:
        """True when ticks reach a heartbeat that prints."""
        return self.beat is not None and self.beat.enabled

    def tick(self, fraction: float) -> None:
        """This much (0 to 1) of the stretch is done."""
        if self.beat is not None:
            self.beat.tick(self.lo + min(1.0, max(0.0, fraction)) * (self.hi - self.lo))

    def part(self, lo: float, hi: float) -> "Stretch":
        """The fractions ``lo`` to ``hi`` of this stretch, as a stretch of its own."""
        width = self.hi - self.lo
        return Stretch(self.beat, self.lo + lo * width, self.lo + hi * width)


SILENT = Stretch(None)  # the stretch of work nobody watches


def row_batches(n: int, stretch: Stretch | None = None, seconds: float = BATCH_SECONDS,
                clock=time.monotonic):
    """``(lo, hi)`` row ranges that cover ``range(n)`` in order, each about
    ``seconds`` of the caller's work (sized by the pace of the pieces before
    it); ``stretch`` is ticked with the share of rows done after each piece.
    Without a printing ``stretch``, one range ``(0, n)``: nothing to report
    between pieces, so nothing is split."""
    if stretch is None or not stretch.enabled or n <= FIRST_BATCH:
        yield 0, n
        if stretch is not None:
            stretch.tick(1.0)
        return
    lo, size = 0, FIRST_BATCH
    while lo < n:
        hi = min(n, lo + size)
        t0 = clock()
        yield lo, hi
        took = max(clock() - t0, 1e-6)
        stretch.tick(hi / n)
        size = max(1, int(size * min(8.0, max(0.125, seconds / took))))
        lo = hi


RESERVE_SHARE = 0.2  # of a time limit kept for verifying what the search found ...
RESERVE_MAX = 60.0  # ... but at most this many seconds


class Deadline:
    """The end of time-limited work, on a monotonic clock: ``seconds`` from
    when it is made (``None``: no end; every check then says there is time).

    The work checks it between its steps (a block of sequences screened, a
    batch of rollouts), so it ends within the limit plus the step that was
    running. Of the limit, ``reserve`` seconds (:data:`RESERVE_SHARE` of it,
    at most :data:`RESERVE_MAX`) are kept for verifying what a search found:
    :meth:`search_over` is true that much before :meth:`over`.
    """

    def __init__(self, seconds: float | None = None, clock=time.monotonic):
        self.seconds = None if seconds is None else float(seconds)
        self.clock = clock
        self.started = clock()
        self.reserve = 0.0 if self.seconds is None else min(RESERVE_SHARE * self.seconds, RESERVE_MAX)

    @property
    def limited(self) -> bool:
        """True when there is a time limit."""
        return self.seconds is not None

    def elapsed(self) -> float:
        """Seconds since the deadline was made."""
        return self.clock() - self.started

    def left(self) -> float:
        """Seconds left before the limit (``inf`` without one; negative once past it)."""
        return math.inf if self.seconds is None else self.seconds - self.elapsed()

    def search_left(self) -> float:
        """Seconds of search time left: :meth:`left` less the reserve, never negative."""
        return math.inf if self.seconds is None else max(0.0, self.left() - self.reserve)

    def search_over(self) -> bool:
        """True when a search should stop: less than the reserve for verification is left."""
        return self.seconds is not None and self.left() <= self.reserve

    def over(self) -> bool:
        """True once the limit has passed (nothing more should start, verification included)."""
        return self.seconds is not None and self.left() <= 0.0


NO_DEADLINE = Deadline()  # work without a time limit


class OutOfTime(Exception):
    """Raised by work that a :class:`Deadline` ended before it could answer
    whole (a bisection over searches, say, whose part answer would mislead):
    its caller says the stage was not finished."""


def duration_text(seconds: float) -> str:
    """A duration for people, rounded: ``12 s``, ``4 min``, ``1 h 58 min``."""
    if not math.isfinite(seconds):
        return "an unknown time"
    seconds = max(0.0, float(seconds))
    if seconds < 90:
        return f"{max(1, round(seconds))} s"
    minutes = round(seconds / 60)
    if minutes < 60:
        return f"{minutes} min"
    hours, minutes = divmod(minutes, 60)
    return f"{hours} h" + (f" {minutes} min" if minutes else "")


def _plural(unit: str, n: float) -> str:
    """``unit`` for ``n`` of them: ``1 plan``, ``5 plans``."""
    return unit if n == 1 else f"{unit}s"


def _count(x: float) -> str:
    """A count for people: the whole units done (a part-done unit is not done yet)."""
    return str(int(math.floor(x + 1e-9)))
