"""The report's support section shows the nearest "yes" a family study found."""
from pipeline.present.report import _support_section

SPREAD = {"shift_median_deg": 1, "shift_p90_deg": 2, "shift_max_deg": 3, "cells_compared": 4, "cells": 5,
          "frictions": [0.2], "outcome_changed_share": 0.1}


def _study(nearest):
    return {"spread": SPREAD, "family": {"label": "tripods:12", "members": [1, 2], "extremes": ["a"]},
            "survives": None, "family_plan": {"orients": False, "warning": "no plan holds", "evidence": "e",
                                              "nearest_yes": nearest}}


def test_each_axis_is_a_line_of_the_report():
    cert = {"claim": {"epsilon": 0.00994, "beta": 0.05, "violations": 0, "members": 300}}
    nearest = {"axes": [
        {"axis": "inset", "found": True, "statement": "tripods whose legs stay at least 0.260 a inside the outline",
         "plan": ["P1", "P2"], "holds": True, "certificate": cert},
        {"axis": "tolerance", "found": False, "statement": "no plan tried holds for the family within 45 deg"}]}
    text = "\n".join(_support_section(_study(nearest), {}, "."))
    assert "0.260 a inside the outline: P1 P2 holds (epsilon 0.99 % at beta 0.05, 0 of 300" in text
    assert "<li>tolerance: no plan tried holds for the family within 45 deg</li>" in text


def test_no_nearest_yes_no_line():
    assert "nearest" not in "\n".join(_support_section(_study(None), {}, "."))


def test_a_part_without_a_plan_lists_its_nearest_yes_among_the_warnings():
    from pipeline.present.report import _warnings
    verdict = {"in_tolerance": 186, "trials": 186}
    nearest = {"axes": [
        {"axis": "tolerance", "found": True, "statement": "a tolerance of 30 deg (asked: 6 deg)",
         "plan": ["P14", "P2"], "verdict": verdict},
        {"axis": "sensor", "found": True, "statement": "a force/torque-sensing pin after P14 tells its 4 sets apart"},
        {"axis": "more pins", "found": False, "statement": "not searched"}]}
    plans = {"trapezoid": {"tight": [{"friction": "0.2", "warning": "no plan", "nearest_yes": nearest}]}}
    text = "\n".join(_warnings(plans, {}))
    assert "tolerance: a tolerance of 30 deg (asked: 6 deg): P14 P2 holds 186 of 186 trials in one set" in text
    assert "sensor: a force/torque-sensing pin after P14 tells its 4 sets apart" in text
    assert "verified by full rollouts" in text


def test_a_family_entry_lists_its_answer_as_a_familys():
    """A family's answer whose axes carry no certificate (and no ``steps``,
    written before answers said what they are about): the entry's
    ``support_family`` makes it a family's, not a guess from the axes."""
    from pipeline.present.report import _warnings
    nearest = {"axes": [{"axis": "tolerance", "found": False, "statement": "no plan tried holds for the family"}]}
    plans = {"plate": {"tight": [{"friction": "0.2", "support_family": {"label": "tripods:12"},
                                  "nearest_yes": nearest}]}}
    text = "\n".join(_warnings(plans, {}))
    assert "worst-member search, then fresh members" in text and "full rollouts" not in text
