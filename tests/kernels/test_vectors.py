"""Rollouts against reference vectors from an independent implementation.

``tests/data/rollouts.json`` is a copy of the project's shared reference
vectors: rollouts computed by a brute-force implementation of the spec
(quadrature instead of closed-form support integrals, fixed small steps). Its
tolerances (theta_f within about 0.1 degree, same status, dy within about
0.05 mm) are the ones stated in the file.
"""
from __future__ import annotations

import json

import pytest

from conftest import DATA_DIR, circular_diff
from pipeline.maps import simulate
from pipeline.parts.part import Part

THETA_TOL = 0.1  # degrees, circular
DY_TOL = 0.05  # mm
MODELS = ("minpower", "ellipsoid")


def _cases():
    with open(DATA_DIR / "rollouts.json") as fh:
        cases = json.load(fh)["cases"]
    out = []
    for k, case in enumerate(cases):
        for model in MODELS:
            cid = f"{k:02d}-{case['part']}-th{case['theta_i']:g}-d{case['d']:+g}-mu{case['mu_c']:g}-{model}"
            out.append(pytest.param(case, model, id=cid))
    return out


def test_vector_file_is_complete(rollout_vectors):
    cases = rollout_vectors["cases"]
    assert len(cases) >= 20
    for case in cases:
        for key in ("part", "vertices", "theta_i", "d", "mu_c", "pin_radius"):
            assert key in case
        for model in MODELS:
            assert set(case[model]) >= {"status", "theta_f", "dy"}
    # The set exercises both outcomes and both friction regimes.
    statuses = {case["minpower"]["status"] for case in cases}
    assert {"ok", "miss"} <= statuses
    assert {c["mu_c"] for c in cases} >= {0.0, 0.25}


@pytest.mark.parametrize("case,model", _cases())
def test_rollout_matches_reference(case, model):
    part = Part.from_vertices(case["vertices"], name=case["part"])
    ds = simulate.rollout(part, case["theta_i"], case["d"], case["mu_c"], case["pin_radius"],
                          model=model)
    want = case[model]
    got_status = str(ds.status.item())
    got_theta = float(ds.theta_f)
    got_dy = float(ds.dy)
    msg = (f"{case['part']} theta_i={case['theta_i']} d={case['d']} mu_c={case['mu_c']} "
           f"{model}: got status={got_status} theta_f={got_theta:.4f} dy={got_dy:.4f}, "
           f"want {want}")
    assert got_status == want["status"], msg
    assert 0.0 <= got_theta < 360.0, msg
    assert abs(circular_diff(got_theta, want["theta_f"])) <= THETA_TOL, msg
    assert abs(got_dy - want["dy"]) <= DY_TOL, msg
