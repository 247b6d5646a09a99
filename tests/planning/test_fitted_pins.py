"""Pins fitted to the part (issue 23): parts from 10 mm to 300 mm across get a
candidate grid from below the fence to above every resting state's highest
point at about a/15, and plan without a hand-made pin list."""
import math

import numpy as np
import pytest

from pipeline.parts.part import Part
from pipeline.planning.tight.complete import FixedPinSearch
from pipeline.planning.core.settings import candidate_pins, fitted_pins

TRIANGLE = np.array([[0.0, 0.0], [60.0, 0.0], [15.0, 35.0]])


def _highest_point(part):
    """Highest world y over the resting states, by rotating the outline directly."""
    top = -math.inf
    for theta, y_c in part.stable_states():
        t = math.radians(theta)
        rot = np.array([[math.cos(t), -math.sin(t)], [math.sin(t), math.cos(t)]])
        top = max(top, y_c + float((part.vertices @ rot.T)[:, 1].max()))
    return top


@pytest.mark.parametrize("across", [10.0, 20.0, 60.0, 150.0, 300.0])
def test_fitted_grid_spans_the_part(across):
    part = Part.from_vertices(TRIANGLE * across / 60.0)
    heights = np.array(list(fitted_pins(part).values()))
    step = np.diff(heights)
    assert np.allclose(step, step[0]) and step[0] >= 0.5
    assert abs(step[0] - part.a / 15.0) <= 0.25 + 1e-9  # a/15 rounded to 0.5 mm
    assert np.allclose(heights / 0.5, np.round(heights / 0.5))
    assert heights[0] < 0.0  # below the fence
    assert heights[-1] > _highest_point(part)  # above every resting state
    assert heights[-2] <= _highest_point(part) + step[0]  # but not far above


def test_config_pins_override_and_auto():
    part = Part.from_vertices(TRIANGLE)
    assert candidate_pins(part, [1.0, 2.5]) == {"P1": 1.0, "P2": 2.5}
    assert candidate_pins(part, "auto") == fitted_pins(part) == candidate_pins(part, None)


@pytest.mark.parametrize("across", [10.0, 300.0])
def test_small_and_large_parts_plan_with_fitted_pins(across):
    part = Part.from_vertices(TRIANGLE * across / 60.0)
    radius = 3.0 * across / 60.0  # the pin scaled with the part (scale invariance, spec section 4)
    from pipeline.planning.core.settings import ClaimSettings, Perturbation, SearchSettings, VerifySettings
    box = Perturbation(y_halfwidth=0.5 * across / 60.0, pin_halfwidth=0.3 * across / 60.0)
    search = FixedPinSearch(part, fitted_pins(part), (0.1, 0.3), ClaimSettings(15.0, 0.995, rule="point"),
                            VerifySettings(trials=10, perturbation=box), SearchSettings(radius))
    result = search.run(3, candidates=2, keep=1)
    assert result.plans, result.evidence()
    assert result.plans[0].verdict["width_deg"] <= 15.0
