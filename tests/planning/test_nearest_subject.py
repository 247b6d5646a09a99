"""A nearest "yes" says what it is about (``subject``: a part or a support
family); its text is chosen by that, never guessed from the axes' keys.
Answers written before the key existed (the manual's stored plans) take the
subject from the caller, who reads it off the entry (``support_family``)."""
import json
from pathlib import Path
from types import SimpleNamespace

import pytest

from pipeline.errors import PinfeedError
from pipeline.planning import SUBJECT_FAMILY, SUBJECT_PART, nearest_yes_lines
from pipeline.planning.family import nearest

ROOT = Path(__file__).resolve().parents[2]
FAMILY_HEAD = 'the nearest "yes" (each verified: worst-member search, then fresh members):'
PART_HEAD = 'the nearest "yes" (each verified by full rollouts):'


def test_a_family_answer_without_certificates_reads_as_a_family():
    """The family's answer when no plan passed the sampled verification: no
    axis has a certificate and there is no ``steps`` key, so a guess from
    the keys would call it a part's."""
    checker = SimpleNamespace(results={}, settings=None)
    family = SimpleNamespace(label="tripods:12")
    answer = nearest.nearest_yes(None, family, checker, 2, None, None)
    assert answer["subject"] == SUBJECT_FAMILY
    assert not any("certificate" in a for a in answer["axes"]) and "steps" not in answer
    assert nearest_yes_lines(answer)[0] == FAMILY_HEAD


def test_a_part_answer_with_family_like_keys_reads_as_a_part():
    answer = {"subject": SUBJECT_PART, "steps": 5,
              "axes": [{"axis": "tolerance", "found": False, "statement": "none", "certificate": None}]}
    assert nearest_yes_lines(answer) == [PART_HEAD, "  tolerance: none"]


def test_an_answer_without_the_key_takes_the_callers_word():
    old = {"axes": [{"axis": "more pins", "found": False, "statement": "not searched"}]}
    assert nearest_yes_lines(old, SUBJECT_FAMILY)[0] == FAMILY_HEAD
    assert nearest_yes_lines(old, SUBJECT_PART)[0] == PART_HEAD
    with pytest.raises(PinfeedError, match="expected one of"):
        nearest_yes_lines(old)  # nobody says: refused, not guessed
    with pytest.raises(PinfeedError, match="not a part"):
        nearest_yes_lines(dict(old, subject=SUBJECT_FAMILY), SUBJECT_PART)


@pytest.mark.parametrize("name, head", [("family_answer", FAMILY_HEAD), ("bracket_one_pin", PART_HEAD),
                                        ("l_bracket_four_pins", PART_HEAD)])
def test_the_stored_plans_keep_their_text(name, head):
    """The manual's stored answers name their subject and print their
    heading; written before answers had a subject (the key taken out), they
    print the same heading, the subject read off the entry as the callers do."""
    data = json.loads((ROOT / "docs" / "plans" / f"{name}.json").read_text())
    entry = next(t for t in data["plan"]["tight"] if t.get("nearest_yes"))
    subject = SUBJECT_FAMILY if entry.get("support_family") else SUBJECT_PART
    assert entry["nearest_yes"]["subject"] == subject
    assert nearest_yes_lines(entry["nearest_yes"])[0] == head
    older = {k: v for k, v in entry["nearest_yes"].items() if k != "subject"}
    assert nearest_yes_lines(older, subject)[0] == head


def test_the_schema_names_the_same_subjects():
    from pipeline.planning.core.types import plan_schema
    entry = plan_schema()["$defs"]["tight_entry"]["properties"]["nearest_yes"]
    assert entry["properties"]["subject"]["enum"] == [SUBJECT_PART, SUBJECT_FAMILY]
