"""Names of issue 14: ``simulate.compute_map`` (no builtin shadowed) and the
band kernel K_j as ``Band.kernel_arcs`` in code, while stored files keep the
key ``"kernel"`` (file formats do not change)."""
from __future__ import annotations

import json

import numpy as np

from kernels.rollout import OK
from pipeline.maps import simulate
from pipeline.planning.paper.bands import extract_bands

KEYS_BEFORE = ["start", "width", "mean", "sigma", "adj_start", "adj_width", "com_min", "com_max",
               "n", "kernel", "members"]  # a stored band's keys, in their stored order


def test_map_set_function_does_not_shadow_the_builtin():
    assert callable(simulate.compute_map)
    assert not hasattr(simulate, "map")


def test_stored_band_keeps_the_kernel_key_and_its_order():
    theta_i = np.arange(0.0, 360.0, 10.0)
    theta_f = np.where((theta_i >= 100) & (theta_i <= 150), 40.0, 200.0)
    bands = extract_bands(theta_i, theta_f, np.zeros(theta_i.size), np.full(theta_i.size, OK), 5.0, 2.0)
    band = [b for b in bands if b.mean == 40.0][0]
    stored = json.loads(json.dumps(band.to_dict()))
    assert list(stored) == KEYS_BEFORE
    assert stored["kernel"] == [[100.0, 50.0]]  # K_j: grid points 100 .. 150
    assert "kernel_arcs" not in stored
