"""The MuJoCo rig with point supports (issue 25): the belt's friction acts at
the support's points (the rig shares no code with the kernels), and on a slow
belt the rig's final orientations agree with the quasi-static kernel's under
the same support, where the support moves them far from uniform's."""
import functools
import json
import math

import pytest

from pipeline.errors import PinfeedError
from pipeline.maps import simulate
from pipeline.parts.part import Part

mujoco = pytest.importorskip("mujoco")

ASYM = Part.from_vertices([(0, 0), (60, 0), (15, 35)], "asym_triangle")
FOUR = "points:-10,-6,1 12,-6,1 -2,8,1 4,0,1"
CASES = [(10.0, 0.3, 0.0), (200.0, -0.5, 0.3), (300.0, 0.3, 0.3), (100.0, -0.5, 0.0),
         (150.0, 0.5, 0.15), (60.0, -0.3, 0.15)]
BELT = 50.0  # mm/s: a slow belt (the quasi-static limit within a degree for uniform pressure)
# Measured 2026-11-24 (2-core VM), rig vs kernel under the same support on
# CASES: tripod <= 0.40 deg, FOUR <= 0.93 deg; uniform pressure <= 1.13 deg
# (the rig's own error at this belt speed: finite speed, soft contact). 1.5 deg
# is that uniform error with a margin; the supports move theta_f by up to
# 29 deg (tripod) and 11 deg (FOUR), well over 4x the tolerance.
AGREE_DEG = 1.5


def _circ(a, b):
    return abs((a - b + 180.0) % 360.0 - 180.0)


@functools.cache
def _uniform(theta, d, mu):
    """theta_f (deg) of the kernel and of the rig under uniform pressure."""
    kernel = simulate.rollout(ASYM, theta, d, mu, 3.0)
    rig = simulate.rollout(ASYM, theta, d, mu, 3.0, model="mujoco", belt_speed=BELT)
    return float(kernel.theta_f), float(rig.theta_f)


@pytest.mark.parametrize("support", ["tripod", FOUR])
def test_rig_agrees_with_the_kernel_under_the_same_support(support):
    kernel_shifts, rig_shifts = [], []
    for theta, d, mu in CASES:
        kernel = simulate.rollout(ASYM, theta, d, mu, 3.0, support=support)
        rig = simulate.rollout(ASYM, theta, d, mu, 3.0, model="mujoco", belt_speed=BELT, support=support)
        assert str(rig.status.item()) == str(kernel.status.item()) == "ok", (theta, d, mu)
        assert _circ(float(rig.theta_f), float(kernel.theta_f)) <= AGREE_DEG, (theta, d, mu)
        assert rig.attrs["support"] == support
        kernel_uniform, rig_uniform = _uniform(theta, d, mu)
        kernel_shifts.append(_circ(float(kernel.theta_f), kernel_uniform))
        rig_shifts.append(_circ(float(rig.theta_f), rig_uniform))
    # The support matters, in both engines: a rig ignoring it would fail here.
    assert max(kernel_shifts) > 4 * AGREE_DEG and max(rig_shifts) > 4 * AGREE_DEG
    assert sum(s > 2 * AGREE_DEG for s in rig_shifts) >= len(CASES) // 2


def test_cli_rollout_mujoco_takes_the_support(capsys):
    from pipeline.cli import main
    base = ["rollout", "--vertices", "0,0 60,0 15,35", "--theta-i", "10", "--d", "0.3",
            "--mu-c", "0", "--pin-radius", "3", "--model", "mujoco", "--belt-speed", str(BELT),
            "--json"]
    assert main(base + ["--support", FOUR]) == 0
    row = json.loads(capsys.readouterr().out)[0]
    ref = simulate.rollout(ASYM, 10.0, 0.3, 0.0, 3.0, model="mujoco", belt_speed=BELT, support=FOUR)
    assert row["status"] == "ok" and row["theta_f"] == float(ref.theta_f)
    assert _circ(row["theta_f"], _uniform(10.0, 0.3, 0.0)[1]) > 2 * AGREE_DEG


def test_rig_steps_are_short_enough_for_points_at_the_vertices():
    """The tripod of a triangle is its vertices: a friction moment 3 to 4 times
    uniform's. With uniform's step the explicit integration of the regularised
    friction oscillated about rest and never ended (the step budget)."""
    from pipeline.maps.mujoco_rig import TIMESTEP, _support, _timestep
    from pipeline.parts.support import parse_support
    _, _, izz, pts, load = _support(ASYM, 0.01, 0.5, parse_support("tripod", ASYM))
    assert _timestep(pts, load, izz, 0.01, 0.5) <= TIMESTEP / 3
    _, _, izz, pts, load = _support(ASYM, 0.01, 0.5)
    assert _timestep(pts, load, izz, 0.01, 0.5) == TIMESTEP


def test_dynamic_model_refuses_a_support():
    with pytest.raises(PinfeedError, match="needs model minpower or mujoco"):
        simulate.rollout(ASYM, 10.0, 0.3, 0.2, 3.0, model="dynamic", belt_speed=50.0, support="tripod")
    assert math.isfinite(float(simulate.rollout(ASYM, 10.0, 0.3, 0.2, 3.0, model="mujoco", belt_speed=300.0,
                                                support="uniform").theta_f))
