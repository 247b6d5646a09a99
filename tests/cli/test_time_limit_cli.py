"""``pinfeed plan --time-limit S``: back in time with the best verified answer
so far, saying in the text, the ``--json`` document and the stored plan file
that the search is not complete and what it left unsearched; without a limit
(or with one it never reaches) the same plan as before."""
from __future__ import annotations

import json
import time

from cli_runs import TRI_PLAN_ARGS, run_cli, small_config_file
from pipeline.planning.core.types import validate_plan_file

# The triangle at a 1 deg tolerance, 11 pins, depth 6: the whole search
# (over a million sequences at 6 pins) takes minutes, far more than the limit.
DEEP_ARGS = ["--vertices", "0,0 60,0 15,35", "--name", "tri", "--depth", "6", "--pins=3:43:4", "--mu-c", "0",
             "--dynamic-depth", "0", "--tolerance", "1"]
HANG = 60.0  # seconds beyond the limit that would mean a hang (not a performance bound)


def _plan(capsys, tmp_path, args, *extra):
    out = tmp_path / "plan.json"
    argv = ["plan", *args, "--config", str(small_config_file(tmp_path)), "--catalog", str(tmp_path / "cat"),
            "--out", str(out), *extra]
    t0 = time.monotonic()
    code, stdout, stderr = run_cli(capsys, argv)
    return code, stdout, stderr, out, time.monotonic() - t0


def test_a_one_second_limit_returns_in_time_and_says_what_it_left(capsys, tmp_path):
    code, out, err, path, took = _plan(capsys, tmp_path, DEEP_ARGS, "--time-limit", "1")
    assert code in (0, None), err
    assert took < 1 + HANG
    assert "time limit 1 s: the search is NOT complete" in out
    assert "Not searched:" in out and "6 fixed pin(s)" in out, out
    assert "among the sequences searched" in out  # never the complete search's "no"
    assert "no fixed-pin sequence of up to 6 pins orients this part" not in out
    assert "fixed pin(s): " in err and "of the time limit left" in err  # the levels' first lines
    stored = validate_plan_file(path)["tight"][0]  # the plan file still meets its schema
    assert stored["time_limit_s"] == 1.0 and stored["complete"] is False
    assert any("6 fixed pin(s)" in u for u in stored["unsearched"])
    assert stored["fixed_pin_search"]["complete"] is False


def test_the_json_document_carries_the_limit(capsys, tmp_path):
    code, out, err, _, took = _plan(capsys, tmp_path, DEEP_ARGS, "--time-limit", "1", "--json")
    assert code in (0, None), err
    assert took < 1 + HANG
    doc = json.loads(out)
    assert doc["time_limit_s"] == 1.0 and doc["complete"] is False
    assert doc["unsearched"] and all(isinstance(u, str) for u in doc["unsearched"])
    assert "not searched:" in doc["evidence"]


def test_without_a_limit_or_with_a_roomy_one_the_plan_is_the_same(capsys, tmp_path):
    code, out, err, _, _ = _plan(capsys, tmp_path, TRI_PLAN_ARGS, "--json")
    assert code in (0, None), err
    plain = json.loads(out)
    assert plain["time_limit_s"] is None and plain["complete"] is True and plain["unsearched"] == []
    code, out, err, _, _ = _plan(capsys, tmp_path, TRI_PLAN_ARGS, "--json", "--time-limit", "3600")
    assert code in (0, None), err
    roomy = json.loads(out)
    assert roomy["time_limit_s"] == 3600.0 and roomy["complete"] is True and roomy["unsearched"] == []
    for key in ("orients", "evidence", "warning", "recommended", "plans", "nearest_yes"):
        assert roomy[key] == plain[key], key


def test_a_bad_limit_is_one_line_with_the_way_out(capsys, tmp_path):
    for value in ("0", "-3"):
        code, out, err, _, _ = _plan(capsys, tmp_path, TRI_PLAN_ARGS, "--time-limit", value)
        assert code not in (0, None)
        lines = [ln for ln in err.strip().splitlines() if "time-limit" in ln]
        assert len(lines) == 1 and "above 0" in lines[0] and "without a time limit" in lines[0]


def test_the_limit_is_for_the_tight_planner(capsys, tmp_path):
    code, out, err, _, _ = _plan(capsys, tmp_path, TRI_PLAN_ARGS, "--time-limit", "5", "--mode", "paper")
    assert code not in (0, None)
    assert "--mode tight" in err
