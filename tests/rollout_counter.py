"""Counting the rollouts a piece of code asks for.

Every rollout of the planner and its checks goes through
``pipeline.maps.simulate.rollout_points``; :func:`count_rollouts` wraps it so
a test can tell how many rows a step rolled out (and that a step reusing
kept states rolled out none).
"""
import numpy as np

from pipeline.maps import simulate


def count_rollouts(monkeypatch) -> list:
    """Patch ``simulate.rollout_points`` (undone with ``monkeypatch``) to
    append the number of rows of each call to the returned list."""
    counted = []
    original = simulate.rollout_points

    def counting(part, theta, *args, **kwargs):
        counted.append(np.size(theta))
        return original(part, theta, *args, **kwargs)

    monkeypatch.setattr(simulate, "rollout_points", counting)
    return counted
