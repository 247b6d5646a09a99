"""What ``make run`` shows on the terminal: Snakemake's own output goes to a log
file, and the terminal gets one line per finished stage (a rule whose jobs
are all done), with counts and the time since the start, plus, on a terminal,
one live line saying what runs now (``[ 3:12] 40/82 jobs; running: plan 0/2,
sweep_shard 38/60``)::

    pinfeed: 141 jobs on 2 cores; Snakemake's full log: logs/config/snakemake-20261126-100009.log
    [ 2:41] sweep_shard      60/60   map shards               2:33
    [ 2:55] bands            60/60   bands of every map       2:40
    ...
    [ 6:58] done: 141 of 141 jobs in 6:58

A failed job shows its rule, its log file and the last lines of that log (or
of Snakemake's output when the log says nothing). :class:`Progress` reads
Snakemake's output line by line (live, or a recorded log in the tests);
:func:`follow` runs Snakemake with its output to the log file and feeds the
lines to a :class:`Progress` as they come.
"""
from __future__ import annotations

import os
import re
import subprocess
import sys
import time
from dataclasses import dataclass, field
from datetime import datetime
from pathlib import Path

# What each rule makes, in a few words (rules/*.smk); other rules show their name only.
STAGES = {
    "sweep_shard": "map shards",
    "catalog_index": "catalog index",
    "bands": "bands of every map",
    "plan": "plans (searched, verified)",
    "verify": "plans on held-out trials",
    "sense": "sensor plans",
    "sensing_figures": "sensing figures",
    "speed": "speed limits",
    "layout": "feeder layouts, drawings",
    "outline": "part outlines",
    "animate": "animations",
    "figures": "maps, bands, sequences",
    "atlas": "feedability atlas",
    "report": "report",
    "support": "support-family study",
    "report_support": "report with the study",
}
# Target rules: no work of their own, no line.
TARGETS = {"all", "support_study"}
ERROR_LINES = 12  # last lines of a failed job's log shown on the terminal

_STAMP = re.compile(r"^\[(\w{3} \w{3} +\d+ \d\d:\d\d:\d\d \d{4})\]$")
_DATE = re.compile(r"^\s*Date: (\d{4}-\d\d-\d\d \d\d:\d\d:\d\d)")
_START = re.compile(r"^(?:local)?rule (\w+):$")
_JOBID = re.compile(r"^\s+jobid: (\d+)$")
_FINISHED = re.compile(r"^Finished jobid: (\d+) \(Rule: (\w+)\)")
_STEPS = re.compile(r"^(\d+) of (\d+) steps \(.*\) done")
_CORES = re.compile(r"^Provided cores: (\d+)")
_ERROR = re.compile(r"^Error in rule (\w+):$")
_ERR_LOG = re.compile(r"^\s+log: (.*?)(?: \(check log file\(s\) for error details\))?$")
_ERR_JOB = re.compile(r"^\s+jobid: (\d+)$")
# Snakemake's lines that say nothing to a person reading the error.
_NOISE = re.compile(r"^(Shutting down|Complete log|Exiting because|Select jobs|Execute \d+ jobs|"
                    r"Assuming unrestricted|Building DAG|Using shell|Rules claiming|Conda environments|"
                    r"WorkflowError:$|At least one job did not complete|Elapsed time|\[\w{3} \w{3} )")


def clock(seconds: float) -> str:
    """``m:ss`` (``h:mm:ss`` from an hour), right-aligned to 5 characters."""
    seconds = max(0, int(round(seconds)))
    h, rest = divmod(seconds, 3600)
    text = f"{h}:{rest // 60:02d}:{rest % 60:02d}" if h else f"{rest // 60}:{rest % 60:02d}"
    return f"{text:>5}"


@dataclass
class Failure:
    """A job Snakemake reported failed: its rule, jobid and log files."""
    rule: str
    jobid: str | None = None
    logs: list[str] = field(default_factory=list)
    at: float = 0.0


@dataclass
class Progress:
    """Snakemake's output read line by line (:meth:`feed`), the terminal lines
    it makes returned. Times are seconds from ``start`` (a datetime; by default
    the ``Date:`` of Snakemake's header, else its first time stamp) to the
    job's time stamp in the output."""
    start: datetime | None = None
    workdir: Path = Path(".")  # where the jobs' log paths start (Snakemake's --directory)
    totals: dict = field(default_factory=dict)
    done: dict = field(default_factory=dict)
    first_start: dict = field(default_factory=dict)
    running: dict = field(default_factory=dict)  # jobid -> rule
    steps: tuple = (0, 0)
    cores: int | None = None
    failures: list = field(default_factory=list)
    nothing_to_do: bool = False
    tail: list = field(default_factory=list)  # Snakemake's last lines, outside job listings
    _stamp: datetime | None = None
    _in_header: bool = False
    _in_stats: bool = False
    _stats_seen: bool = False
    _job_rule: str | None = None
    _failure: Failure | None = None

    def elapsed(self, when: datetime | None = None) -> float:
        """Seconds from the run's start to ``when`` (default: the last time stamp read)."""
        when = when or self._stamp
        if when is None or self.start is None:
            return 0.0
        return (when - self.start).total_seconds()

    def feed(self, line: str) -> list[str]:
        """Read one line of Snakemake's output; return the terminal lines it completes."""
        line = line.rstrip("\n")
        out = []
        if self._failure is not None:
            if self._failure_detail(line):
                return out
            out += self.close_failure()
        if self._in_stats:
            return out + self._stats_line(line)
        if line.startswith("SNAKEMAKE") or (self._in_header and not line.startswith("Building DAG")):
            self._in_header = True  # Snakemake's banner: date, versions, paths (no line of ours)
            if self.start is None and (m := _DATE.match(line)):
                self.start = datetime.strptime(m.group(1), "%Y-%m-%d %H:%M:%S")
            return out
        self._in_header = False
        if m := _STAMP.match(line):
            self._stamp = datetime.strptime(m.group(1), "%a %b %d %H:%M:%S %Y")
            self.start = self.start or self._stamp  # no header: from the first job
            return out
        if line.startswith("Job stats:"):
            self._in_stats = True
            return out
        if m := _CORES.match(line):
            self.cores = int(m.group(1))
            return out
        if m := _START.match(line):
            self._job_rule = m.group(1)
            self.first_start.setdefault(self._job_rule, self.elapsed())
            return out
        if self._job_rule and (m := _JOBID.match(line)):
            self.running[m.group(1)] = self._job_rule
            return out
        if line.startswith((" ", "\t")) and self._job_rule:
            return out  # the rest of a job's listing
        self._job_rule = None
        if m := _FINISHED.match(line):
            jobid, rule = m.groups()
            self.running.pop(jobid, None)
            self.done[rule] = self.done.get(rule, 0) + 1
            if rule not in TARGETS and self.done[rule] == self.totals.get(rule, 0):
                out.append(self.stage_line(rule))
            return out
        if m := _STEPS.match(line):
            self.steps = (int(m.group(1)), int(m.group(2)))
            return out
        if m := _ERROR.match(line):
            self._failure = Failure(m.group(1), at=self.elapsed())
            self.failures.append(self._failure)
            return out
        if line.startswith("Nothing to be done"):
            self.nothing_to_do = True
        if line.startswith("pinfeed:"):
            out.append(line)  # the Snakefile's own notes (a stale catalog index, ...)
        if line.strip() and not _NOISE.match(line):
            self.tail = (self.tail + [line])[-ERROR_LINES:]
        return out

    def _failure_detail(self, line: str) -> bool:
        """Take a line that belongs to the failure being read (its log files,
        its job id, an indented detail); False for the first line after it."""
        m_log, m_job = _ERR_LOG.match(line), _ERR_JOB.match(line)
        if m_log:
            self._failure.logs = [p.strip() for p in m_log.group(1).split(", ") if p.strip()]
        elif m_job:
            self._failure.jobid = m_job.group(1)
        return bool(m_log or m_job or line.startswith((" ", "\t")))

    def _stats_line(self, line: str) -> list[str]:
        """A line of Snakemake's job-stats table: the count per rule, and at
        its total the one line saying how many jobs will run."""
        parts = line.split()
        if len(parts) != 2 or not parts[1].isdigit():
            return []
        if parts[0] != "total":
            if not self._stats_seen:
                self.totals[parts[0]] = int(parts[1])
            return []
        self._in_stats = False
        if self._stats_seen:
            return []
        self._stats_seen = True
        cores = f" on {self.cores} core{'s' if self.cores > 1 else ''}" if self.cores else ""
        return [f"pinfeed: {int(parts[1])} jobs to run{cores}"]

    def close_failure(self) -> list[str]:
        """The terminal lines of the failure just read: its rule, its log files
        and their last lines (Snakemake's last lines where the logs say nothing)."""
        f, self._failure = self._failure, None
        if f is None:
            return []
        out = [f"[{clock(f.at)}] FAILED: rule {f.rule}" + (f" (jobid {f.jobid})" if f.jobid else "")]
        shown = False
        for path in f.logs:
            out.append(f"  log: {path}")
            lines = _last_lines(Path(self.workdir) / path)
            out += [f"  | {t}" for t in lines]
            shown = shown or bool(lines)
        if not shown:
            out.append("  Snakemake's last lines:" if f.logs else "  no log; Snakemake's last lines:")
            out += [f"  | {t}" for t in self.tail]
        return out

    def stage_line(self, rule: str) -> str:
        """``[elapsed] rule  done/total  what  stage time`` for a finished stage."""
        now = self.elapsed()
        took = now - self.first_start.get(rule, now)
        total = self.totals.get(rule, self.done.get(rule, 0))
        count = f"{self.done.get(rule, 0)}/{total}"
        return f"[{clock(now)}] {rule:<16} {count:>7}  {STAGES.get(rule, ''):<26} {clock(took).strip():>5}"

    def status(self, seconds: float) -> str:
        """The live line: jobs done, and the stages running now with their counts."""
        if not self._stats_seen:
            return f"[{clock(seconds)}] Snakemake is building its job graph"
        now = sorted(set(self.running.values()) - TARGETS)
        doing = ", ".join(f"{r} {self.done.get(r, 0)}/{self.totals.get(r, '?')}" for r in now)
        done, total = self.steps
        total = total or sum(self.totals.values())
        return f"[{clock(seconds)}] {done}/{total} jobs" + (f"; running: {doing}" if doing else "")

    def summary(self, code: int, seconds: float, log_path) -> list[str]:
        """The closing lines: done, nothing to do, or what failed and where to look."""
        if code == 0:
            if self.nothing_to_do or not self._stats_seen:
                return [f"[{clock(seconds)}] nothing to do: every result is up to date"]
            done, total = self.steps
            return [f"[{clock(seconds)}] done: {done} of {total} jobs in {clock(seconds).strip()}"]
        out = self.close_failure()
        if not self.failures:
            out.append("Snakemake's last lines:")
            out += [f"  | {t}" for t in self.tail]
        done, total = self.steps
        out.append(f"pinfeed: the workflow failed after {clock(seconds).strip()} ({done} of "
                   f"{total or sum(self.totals.values())} jobs done); Snakemake's full log: {log_path}")
        return out


def _last_lines(path: Path, n: int = ERROR_LINES) -> list[str]:
    """The last ``n`` non-blank lines of a file (none if it is missing)."""
    try:
        text = path.read_text(errors="replace")
    except OSError:
        return []
    return [t for t in text.splitlines() if t.strip()][-n:]


class Terminal:
    """Prints the lines; on a terminal also keeps one live line, rewritten in place."""

    def __init__(self, stream=None, live: bool | None = None):
        self.stream = stream or sys.stdout
        self.live = self.stream.isatty() if live is None else live
        self._shown = ""  # the live line on screen

    def line(self, text: str) -> None:
        """Print ``text`` as a line of its own (clearing the live line first)."""
        self._clear()
        print(text, file=self.stream, flush=True)

    def status(self, text: str) -> None:
        """Show ``text`` as the live line (cut to the terminal's width); nothing
        when the output is not a terminal."""
        if self.live and text != self._shown:
            self.stream.write("\r\033[K" + text[:_columns() - 1])
            self.stream.flush()
            self._shown = text

    def _clear(self) -> None:
        if self._shown:
            self.stream.write("\r\033[K")
            self._shown = ""


def _columns() -> int:
    """The terminal's width (100 where it says none)."""
    try:
        return os.get_terminal_size().columns or 100
    except OSError:
        return 100


def follow(cmd: list[str], log_path: Path, terminal: Terminal | None = None, poll: float = 0.25,
           workdir=".") -> int:
    """Run ``cmd`` (Snakemake) with its output to ``log_path``, showing its
    progress on ``terminal`` (one line per finished stage, the summary at the
    end); return its exit status. Snakemake writes the log itself, so it
    carries on if this process dies."""
    terminal = terminal or Terminal()
    log_path = Path(log_path)
    log_path.parent.mkdir(parents=True, exist_ok=True)
    t0 = time.monotonic()
    progress = Progress(start=datetime.now().replace(microsecond=0), workdir=Path(workdir))
    terminal.line(f"pinfeed: running Snakemake; its full log: {log_path}")
    env = {**os.environ, "PYTHONUNBUFFERED": "1"}
    with open(log_path, "w") as sink:
        proc = subprocess.Popen(cmd, stdout=sink, stderr=subprocess.STDOUT, stdin=subprocess.DEVNULL, env=env)
    code, pending, interrupted = None, "", False
    with open(log_path, errors="replace") as reader:
        while True:
            try:
                code = proc.poll()
                chunk = reader.read()
                pending += chunk
                *lines, pending = pending.split("\n")
                for line in lines:
                    for text in progress.feed(line):
                        terminal.line(text)
                if code is not None and not chunk:
                    break
                terminal.status(progress.status(time.monotonic() - t0))
                time.sleep(poll)
            except KeyboardInterrupt:  # Snakemake got it too (same process group): let it stop
                if interrupted:
                    raise
                interrupted = True
                terminal.line("pinfeed: interrupted; waiting for Snakemake to stop its jobs "
                              "(Ctrl-C again to leave it)")
    for text in progress.feed(pending) if pending else []:
        terminal.line(text)
    for text in progress.summary(code, time.monotonic() - t0, log_path):
        terminal.line(text)
    return code
