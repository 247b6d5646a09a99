"""The plans the performance page's planning-time table states are the
recorded plans of the ten benchmark parts.

The table under "Planning time of new parts" (``docs/performance/index.md``,
the run of 2026-11-28) gives, per part, the recommended plan, its verdict
(width and the held-out trials in one set) and the sequences per level. Its
times are measurements; its plans are not: they must be the plans
``benchmarks/plan_record.py record --benchmark-parts also`` recorded
(``benchmarks/records/plans_typed_record.json.gz``, the same settings as
``benchmarks/plan_speed.py``). A plan, width or count typed into the table
that the record does not hold fails here.
"""
from __future__ import annotations

import gzip
import json
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
PAGE = ROOT / "docs" / "performance" / "index.md"
RECORD = ROOT / "benchmarks" / "records" / "plans_typed_record.json.gz"
HEADING = "### Planning time of new parts"


def _table_rows() -> dict:
    """part -> (recommended plan, verified, sequences per level): the first table under the heading."""
    text = PAGE.read_text()
    section = text[text.index(HEADING):]
    rows, started = {}, False
    for line in section.splitlines()[1:]:
        if line.startswith("| part |"):
            started = True
            continue
        if started and not line.startswith("|"):
            break
        if started and not line.startswith("|---"):
            cells = [c.strip() for c in line.strip("|").split("|")]
            rows[cells[0]] = (cells[4], cells[5], cells[6])
    return rows


def _record() -> dict:
    return json.loads(gzip.decompress(RECORD.read_bytes()))


ROWS = _table_rows()


def test_the_table_lists_the_ten_benchmark_parts():
    recorded = {k.split("/", 1)[1] for k in _record() if k.startswith("bench/")}
    assert set(ROWS) == recorded and len(ROWS) == 10


@pytest.mark.parametrize("part", sorted(ROWS))
def test_a_row_states_the_recorded_plan(part):
    plan_text, verified, levels = ROWS[part]
    entry = _record()[f"bench/{part}"]["tight"][0]
    rec = entry["recommended"]
    assert json.loads(levels) == entry["stats"]["per_level"]
    if entry["needs_no_pin"]:
        assert plan_text == "no pin" and rec is None
        return
    assert plan_text == " ".join(rec["pins"])
    verdict = rec["verification"]["orientation"]
    m = re.fullmatch(r"(\*\*does not orient\*\*|orients): ([\d.]+) deg, (\d+)/(\d+)", verified)
    assert m, verified
    assert (m.group(1) == "orients") == bool(verdict["orients"])
    assert float(m.group(2)) == pytest.approx(verdict["width_deg"], abs=0.05)
    assert (int(m.group(3)), int(m.group(4))) == (verdict["in_tolerance"], verdict["trials"])
