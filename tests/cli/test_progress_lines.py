"""Long commands say on stderr what they are doing, at least every few seconds.

The heartbeat is checked with a fake clock (no sleeping); one real ``pinfeed
plan`` on a small part, with ``PINFEED_PROGRESS_SECONDS`` tiny, shows lines
from inside a search level while stdout holds the plan alone.
"""
from __future__ import annotations

import json
import re

import numpy as np
import pytest

from cli_runs import run_cli, small_config_file
from pipeline.errors import PinfeedError
from pipeline.maps import simulate
from pipeline.parts.part import Part
from pipeline.planning.plans.speed_limit import speed_curve
from pipeline.progress import Heartbeat, Stretch, prefixed, progress_interval, reporting, row_batches


class FakeClock:
    """A clock that moves only when told to."""

    def __init__(self):
        self.now = 0.0
        self.reads = 0

    def __call__(self):
        self.reads += 1
        return self.now


def _seconds(line: str) -> float:
    return float(re.search(r", (\d+) s\)", line).group(1))


def test_a_slow_loop_prints_a_line_at_least_every_ten_seconds():
    clock, lines, stamps = FakeClock(), [], []

    def report(line):
        lines.append(line)
        stamps.append(clock.now)

    n = 40
    with Heartbeat("3 fixed pin(s): screening and judging", n, "sequence", report, interval=5.0,
                   clock=clock) as beat:
        for k in range(1, n + 1):
            clock.now += 3.0  # each item takes 3 s
            beat.tick(k)
    assert lines[0] == "3 fixed pin(s): screening and judging: 40 sequences to do"
    assert lines[-1].startswith("3 fixed pin(s): screening and judging: 40/40 sequences done (100%")
    assert max(np.diff(stamps)) <= 10.0 and clock.now - stamps[-1] <= 10.0
    assert 15 <= len(lines) <= 25  # about one line per 5 s of 120 s, not one per item
    assert "12/40 sequences done (30%, 36 s)" in "\n".join(lines)
    assert [_seconds(ln) for ln in lines[1:]] == sorted(_seconds(ln) for ln in lines[1:])


def test_a_fast_loop_prints_only_its_start_and_end_and_reads_the_clock_sparingly():
    clock, lines = FakeClock(), []
    beat = Heartbeat("verification", 10_000, "trial", lines.append, interval=5.0, clock=clock,
                     check_every=100).start()
    for k in range(1, 10_001):
        beat.tick(k)
    beat.finish()
    assert lines == ["verification: 10000 trials to do", "verification: 10000/10000 trials done (100%, 0 s)"]
    assert clock.reads < 10_000 // 100 + 10


def test_a_stage_that_stops_early_says_why_and_a_silent_one_prints_nothing():
    clock, lines = FakeClock(), []
    beat = Heartbeat("worst member", 150, "member evaluation", lines.append, interval=5.0, clock=clock).start()
    clock.now = 12.0
    beat.tick(12)
    beat.finish(12, "a member breaks the plan")
    beat.finish()  # once only
    assert lines[-1] == "worst member: 12/150 member evaluations done (8%, 12 s); a member breaks the plan"
    assert len(lines) == 3
    quiet = Heartbeat("nobody listens", 5, "plan")
    with quiet:
        quiet.tick(3)
    assert not quiet.enabled
    nothing = []
    with Heartbeat("empty", 0, "plan", nothing.append, interval=5.0):
        pass
    assert nothing == []


def test_inner_work_reports_into_its_stretch_of_the_stage():
    clock, lines = FakeClock(), []
    beat = Heartbeat("judging", 10, "sequence", lines.append, interval=1.0, clock=clock).start()
    stretch = beat.stretch(4, 6)  # sequences 4 and 5, replayed pin by pin
    second_pin = stretch.part(0.5, 1.0)
    clock.now = 2.0
    second_pin.tick(0.5)
    assert beat.done == pytest.approx(5.5)
    assert lines[-1] == "judging: 5/10 sequences done (55%, 2 s)"
    Stretch(None).tick(0.3)  # nobody watches: nothing happens


def test_row_batches_cover_the_rows_in_order_and_tick_between_them():
    clock, lines = FakeClock(), []
    beat = Heartbeat("rollouts", 10_000, "rollout", lines.append, interval=0.5, clock=clock).start()
    ranges = []
    for lo, hi in row_batches(10_000, beat.stretch(0, 10_000), seconds=1.0, clock=clock):
        ranges.append((lo, hi))
        clock.now += 2.0  # slower than a second: the next piece is smaller
    assert ranges[0][0] == 0 and ranges[-1][1] == 10_000
    assert all(a[1] == b[0] for a, b in zip(ranges, ranges[1:]))
    assert len(ranges) > 2 and ranges[1][1] - ranges[1][0] < ranges[0][1] - ranges[0][0]
    assert len(lines) >= len(ranges)
    assert list(row_batches(10_000)) == [(0, 10_000)]  # nobody watches: one piece
    assert list(row_batches(0)) == [(0, 0)]


def test_rollouts_in_pieces_equal_rollouts_in_one_call():
    part = Part.from_vertices(np.array([[0.0, 0.0], [60.0, 0.0], [15.0, 35.0]]), name="tri")
    rng = np.random.default_rng(3)
    n = 1500
    theta, d, mu = rng.uniform(0, 360, n), rng.uniform(-0.9, 0.9, n), rng.uniform(0.0, 0.4, n)
    whole = simulate.rollout_points(part, theta, d, mu, 1.0)
    lines = []
    beat = Heartbeat("x", n, "rollout", lines.append, interval=1e-9).start()
    pieces = simulate.rollout_points(part, theta, d, mu, 1.0, stretch=beat.stretch(0, n))
    assert len(lines) > 2  # it did go in pieces, with a line between them
    for key in whole:
        np.testing.assert_array_equal(whole[key], pieces[key])


def test_a_reporting_block_takes_the_lines_of_heartbeats_without_their_own():
    outer, inner = [], []
    with reporting(outer.append):
        with Heartbeat("outer", 1, "plan", interval=5.0):
            with reporting(inner.append):
                with Heartbeat("inner", 1, "plan", interval=5.0):
                    pass
    with Heartbeat("outside", 1, "plan"):
        pass
    assert outer == ["outer: 1 plan to do", "outer: 1/1 plan done (100%, 0 s)"]
    assert inner == ["inner: 1 plan to do", "inner: 1/1 plan done (100%, 0 s)"]
    with reporting(outer.append):
        prefixed("mu_c 0: plan 1")("speed limit: belt at 50 mm/s: 12 trials to do")
    assert outer[-1] == "mu_c 0: plan 1: speed limit: belt at 50 mm/s: 12 trials to do"
    assert prefixed("mu_c 0") is None  # outside a reporting block: nowhere to go


def test_a_speed_limit_says_which_belt_speed_it_tries_and_finds_the_same_limit():
    part = Part.from_vertices(np.array([[0.0, 0.0], [60.0, 0.0], [15.0, 35.0]]), name="tri")
    states = [(float(t), float(y)) for t, y in part.stable_states()]
    args = (part, [15.0, -7.5], [0.0, 0.0], states, [(0.0, 360.0)], 0.0)
    kw = dict(trials=3, speeds=(50.0, 300.0), resolution=50.0)
    lines = []
    with_lines = speed_curve(*args, **kw, progress=lines.append)
    quiet = speed_curve(*args, **kw)
    assert with_lines["curve"] == quiet["curve"] and with_lines["speed_limit_mm_s"] == quiet["speed_limit_mm_s"]
    tried = [ln for ln in lines if ln.endswith("trials to do")]
    assert len(tried) == len(quiet["curve"]) and tried[0].startswith("speed limit: belt at 50 mm/s: ")


def test_a_bad_interval_is_one_line_before_any_work(monkeypatch, capsys, tmp_path):
    monkeypatch.setenv("PINFEED_PROGRESS_SECONDS", "soon")
    code, out, err = run_cli(capsys, ["atlas", "--results", str(tmp_path)])
    assert code == 2 and out == ""
    assert err == ("pinfeed: error: PINFEED_PROGRESS_SECONDS must be a positive number of seconds (e.g. 5), "
                   "got 'soon'; fix or unset it\n")


def test_the_interval_comes_from_the_environment(monkeypatch):
    monkeypatch.delenv("PINFEED_PROGRESS_SECONDS", raising=False)
    assert progress_interval() == 5.0
    monkeypatch.setenv("PINFEED_PROGRESS_SECONDS", "0.25")
    assert progress_interval() == 0.25
    assert Heartbeat("x", 1, report=print).interval == 0.25
    for bad in ("0", "-1", "soon", "nan"):
        monkeypatch.setenv("PINFEED_PROGRESS_SECONDS", bad)
        with pytest.raises(PinfeedError, match="PINFEED_PROGRESS_SECONDS must be a positive number"):
            progress_interval()


def test_plan_shows_progress_inside_a_level_on_stderr_and_the_plan_on_stdout(tmp_path, capsys,
                                                                              monkeypatch):
    monkeypatch.setenv("PINFEED_PROGRESS_SECONDS", "0.000001")
    config = small_config_file(tmp_path)
    out_file = tmp_path / "tri.json"
    code, out, err = run_cli(capsys, [
        "plan", "--vertices", "0,0 60,0 15,35", "--name", "tri", "--depth", "2", "--pins=-7.5,7.5,15,27.5",
        "--mu-c", "0", "--dynamic-depth", "0", "--config", str(config), "--catalog", str(tmp_path / "cat"),
        "--out", str(out_file)])
    assert code == 0, err
    lines = err.splitlines()
    assert all(ln.startswith("  ... mu_c 0: ") for ln in lines)  # which friction, on stderr only
    for stage in ("2 fixed pin(s): nominal paths", "2 fixed pin(s): first screen",
                  "2 fixed pin(s): screening and judging", "2 fixed pin(s): held-out trials",
                  "verifying the chosen plans on held-out trials"):
        mine = [ln for ln in lines if f": {stage}: " in ln]
        assert re.search(r": \d+ (candidate )?(sequence|plan)s? to do$", mine[0]), mine
        assert re.search(r"done \(100%, \d+ s\)$", mine[-1]), mine
    inside = [ln for ln in lines if "screening and judging" in ln and "done (" in ln and "(100%" not in ln]
    assert inside, "no line from inside the level's screening"
    level = lines.index(next(ln for ln in lines if "2 fixed pin(s): 12 sequences" in ln))
    assert any("2 fixed pin(s): held-out trials" in ln for ln in lines[:level])  # before the level's summary
    assert any(ln.startswith("  ... mu_c 0: plan 1: speed limit: belt at ") for ln in lines)  # stored too
    assert " ... " not in out and "to do" not in out
    assert "2 fixed pins orient this part" in out and "stored the plan at" in out
    assert json.loads(out_file.read_text())["tight"][0]["orients"]
