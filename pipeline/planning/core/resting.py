"""The resting states of a part against the fence, labelled as every planner
and the verification label them (``state 1``, ``state 2``, ...)."""
from __future__ import annotations

from pipeline.parts.part import Part


def resting_states(part: Part) -> dict[str, tuple[float, float]]:
    """The resting states against the fence: label ``state k`` -> ``(theta_deg,
    y_c_mm)``, the labels every planner and the verification share."""
    return {f"state {k}": (float(theta), float(y_c))
            for k, (theta, y_c) in enumerate(part.stable_states(), start=1)}
