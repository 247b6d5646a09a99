"""The integrator's step control on flattened arcs (``kernels.rollout``).

A drawing's fillets and arcs flatten to runs of short edges and vertices of
small exterior angle; each one is a contact feature. Three rules keep that
cheap without moving the answers: a vertex step turns the contact normal at
most 1.25 exterior angles (the pin has left the vertex by then), the step
control keeps its proposal per kind of feature (a travel on edges, a turn on
vertices), and events are located to 1e-5 at most (the state at a located
event is then off by delta^2 / (2 r_pin): at most the step tolerance, and
less for small pins and fine tolerances, see ``_locate_tol``). The
references here are closed forms (exterior angles), a much finer tolerance
(1e-10) and step counts of the rule each test names.
"""
from __future__ import annotations

import math

import numpy as np
import pytest

from conftest import circular_diff
from drawn_shapes import circle, rounded_rectangle
from kernels.geometry import EDGE, VERTEX
from kernels.rollout import (_DTHETA_CAP, _LOCATE_ANGLE, _LOCATE_TOL, _VERTEX_TURN, _VERTEX_TURN_MIN,
                             OK, TRUNCATED, _exterior_angle, _first_step_size, _locate_tol,
                             _rollout_budget, max_steps_for)
from pipeline.parts.part import Part

MU_C, R_PIN = 0.2, 3.0
THETA = np.radians(np.arange(0.0, 360.0, 10.0) + 0.37)
D = np.array([-0.7, -0.3, 0.2, 0.6])


ARC_PARTS = {
    "64-gon disk": Part.from_vertices(circle(0.0, 0.0, 20.0, 64)),
    "plate, 6 mm fillets, a hole": Part.from_vertices(rounded_rectangle(50.0, 40.0, 6.0, 14),
                                                      holes=[circle(12.0, 20.0, 3.25, 16)]),
}


@pytest.mark.parametrize("n", [3, 5, 8, 64])
def test_exterior_angle_of_a_regular_polygon(n):
    verts = circle(0.0, 0.0, 20.0, n, phase=0.3)
    for idx in range(n):
        assert _exterior_angle(verts, idx) == pytest.approx(2 * math.pi / n, abs=1e-12)


def test_exterior_angle_of_a_straight_vertex_is_zero():
    verts = np.array([(0.0, 0.0), (1.0, 0.0), (2.0, 0.0), (1.0, 1.0)])
    assert _exterior_angle(verts, 1) == pytest.approx(0.0, abs=1e-15)


@pytest.mark.parametrize("n", [16, 64, 200])
@pytest.mark.parametrize("speed", [0.05, 1.0, 20.0])
def test_a_vertex_step_turns_at_most_a_quarter_past_the_vertex(n, speed):
    verts = circle(0.0, 0.0, 20.0, n)
    rp = 0.1
    k1 = np.array([0.0, speed * 0.6, speed * 0.8, 0.0, 0.0])  # the pin moves at `speed` around it
    h = _first_step_size(verts, k1, 1.0, VERTEX, 2, rp, _DTHETA_CAP)
    turn = speed / rp * h
    allowed = min(_DTHETA_CAP, max(_VERTEX_TURN * 2 * math.pi / n, _VERTEX_TURN_MIN))
    assert turn == pytest.approx(min(allowed, speed / rp), rel=1e-12)
    # The last turn the step control proposed on a vertex caps it too, ...
    h_memory = _first_step_size(verts, k1, 1.0, VERTEX, 2, rp, 0.5 * allowed)
    assert speed / rp * h_memory <= max(0.5 * allowed, _VERTEX_TURN_MIN) * (1 + 1e-12)
    # ... and neither touches a step on an edge (only the rotation cap does).
    assert _first_step_size(verts, k1, 0.07, EDGE, 2, rp, 1e-9) == 0.07


def test_a_straight_vertex_still_gets_a_step():
    verts = np.array([(0.0, 0.0), (1.0, 0.0), (2.0, 0.0), (1.0, 1.0)])
    k1 = np.array([0.0, 1.0, 0.0, 0.0, 0.0])
    h = _first_step_size(verts, k1, 1.0, VERTEX, 1, 0.1, 0.0)
    assert h == pytest.approx(_VERTEX_TURN_MIN * 0.1)


def _grid(part, tol):
    prep = part.prepared()
    budget = max_steps_for(prep[0].shape[0])
    out = [_rollout_budget(*prep, 0, MU_C, R_PIN, t, d, 0.0, np.inf, 0.1, tol, False, 100 * budget)
           for t in THETA for d in D]
    status = np.array([r[0] for r in out])
    theta_f = np.degrees([r[2] for r in out])
    steps = sum(r[9] for r in out)
    changes = sum(r[5] for r in out)
    return status, theta_f, steps, changes


@pytest.mark.parametrize("name", list(ARC_PARTS))
def test_flattened_arcs_cost_few_steps_per_feature_change(name):
    """Each short edge and small vertex of a flattened arc ends a step on an
    event. Restarting every edge from the vertex's short steps, trying a
    vertex with a turn of 0.2 rad and locating each event to 1e-8 took about
    eight integration steps per feature change on these parts (8.2 on the
    disk, 7.7 on the plate); the rules above take about six (5.8 and 6.3)."""
    _, _, steps, changes = _grid(ARC_PARTS[name], 1e-7)
    assert changes > 5 * THETA.size * D.size  # the grid does cross arcs
    assert steps / changes <= 7.0


@pytest.mark.parametrize("name", list(ARC_PARTS))
def test_flattened_arcs_converge_to_a_fine_tolerance(name):
    """theta_f at the default tolerance against a thousand times finer one:
    the step rules must not trade accuracy for speed. Rollouts that graze a
    vertex end on either side of it (a band jump) and may differ by degrees;
    there are a few on the disk, none on the plate."""
    status, theta_f, _, _ = _grid(ARC_PARTS[name], 1e-7)
    status_fine, theta_fine, _, _ = _grid(ARC_PARTS[name], 1e-10)
    ok = (status == OK) & (status_fine == OK)
    assert ok.mean() > 0.5
    err = np.abs(circular_diff(theta_f[ok], theta_fine[ok]))
    assert np.median(err) <= 3e-5
    assert np.percentile(err, 90) <= 3e-4
    assert (err > 0.01).mean() <= 0.05


@pytest.mark.parametrize("rp, tol", [(0.08, 1e-7), (1e-3, 1e-7), (0.08, 1e-10), (1e-5, 1e-12), (10.0, 1e-7)])
def test_events_are_located_to_what_the_step_tolerance_and_the_pin_allow(rp, tol):
    delta = _locate_tol(rp, tol)
    assert delta <= _LOCATE_TOL
    assert delta * delta / (2 * rp) <= tol * (1 + 1e-12)  # the state's error at a located event
    assert delta / rp <= _LOCATE_ANGLE * (1 + 1e-12)  # the pin's angle around a vertex
    assert delta == pytest.approx(min(_LOCATE_TOL, math.sqrt(2 * rp * tol), _LOCATE_ANGLE * rp))


@pytest.mark.parametrize("r_pin", [0.01, 0.2])
def test_a_small_pin_rolls_around_an_arc_without_bouncing(r_pin):
    """A small pin (r_pin 0.01 mm on a 40 mm disk: 7e-4 a) circles each
    vertex within a tiny turn; an event located too early would put it back
    on the edge it left, again and again."""
    prep = ARC_PARTS["64-gon disk"].prepared()
    budget = max_steps_for(prep[0].shape[0])
    for t in THETA[::3]:
        for d in D:
            r = _rollout_budget(*prep, 0, MU_C, r_pin, t, d, 0.0, np.inf, 0.1, 1e-7, False, budget)
            assert r[0] != TRUNCATED
            assert r[5] < 200  # feature changes: the pin passes about ten vertices
