"""The plans the performance page's tables state are the recorded ones.

The table under "Planning time of new parts" (``docs/performance/index.md``,
the run of 2026-11-28) gives, per part, the recommended plan, its verdict
(width and the held-out trials in one set) and the sequences per level. Its
times are measurements; its plans are not: they must be the plans
``benchmarks/plan_record.py record --benchmark-parts also`` recorded
(``benchmarks/records/plans_corner_sharing.json.gz``, the same settings as
``benchmarks/plan_speed.py``). A plan, width or count typed into the table
that the record does not hold fails here. So does an answer or a nearest
"yes" of the corpus table ("Real parts planned under a time limit") that
its run's record (``benchmarks/records/real_parts_limit50_probe_budget_2026-11-28.json``)
does not hold.
"""
from __future__ import annotations

import gzip
import json
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
PAGE = ROOT / "docs" / "performance" / "index.md"
RECORD = ROOT / "benchmarks" / "records" / "plans_corner_sharing.json.gz"
HEADING = "### Planning time of new parts"


def _table(heading: str) -> list:
    """The cells of each row of the first table under ``heading`` (its header and rule left out)."""
    text = PAGE.read_text()
    rows, started = [], False
    for line in text[text.index(heading):].splitlines()[1:]:
        if line.startswith("| part |"):
            started = True
        elif started and not line.startswith("|"):
            break
        elif started and not line.startswith("|---"):
            rows.append([c.strip() for c in line.strip("|").split("|")])
    return rows


def _table_rows() -> dict:
    """part -> (recommended plan, verified, sequences per level): the planning-time table."""
    return {cells[0]: (cells[4], cells[5], cells[6]) for cells in _table(HEADING)}


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


# --------------------------------------------------------------------------- the corpus under a time limit

CORPUS_HEADING = "### Real parts planned under a time limit"
CORPUS_RECORD = ROOT / "benchmarks" / "records" / "real_parts_limit50_no_refcount_2026-11-29.json"


def _corpus_rows() -> dict:
    """file name -> (answer, nearest yes): the corpus table, the triangle's reference row left out."""
    return {cells[0]: (cells[6], cells[7]) for cells in _table(CORPUS_HEADING) if cells[0] != "default triangle"}


def test_the_corpus_table_states_the_recorded_answers():
    """Each part's answer and nearest "yes" in the corpus table are those the
    run recorded (``benchmarks/real_parts.py``'s record of that day)."""
    record = json.loads(CORPUS_RECORD.read_text())
    recorded = {Path(r["file"]).name: (r["plan"]["answer"], r["plan"]["nearest_yes"] or "")
                for r in record["rows"]}
    rows = _corpus_rows()
    assert len(rows) == len(recorded) >= 20
    assert rows == recorded
