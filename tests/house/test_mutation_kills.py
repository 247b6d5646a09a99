"""Tests added because a deliberate wrong edit of benchmarks/mutation_check.py
survived the rest of the suite (see the README's "Mutation checks")."""
from __future__ import annotations

import numpy as np
import pytest

from conftest import TRIANGLE, circular_diff
from pipeline.maps import simulate
from pipeline.parts.part import Part
from pipeline.planning.core.settings import KernelSettings
from pipeline.planning.tight.store import load_lattice, save_lattice
from pipeline.planning.tight.propagate import OutcomeLattice

PART = Part.from_vertices(TRIANGLE, name="tri")
R_PIN = 3.0


# ------------------------------------------------------------- wrap to [0, 360)

@pytest.mark.parametrize("theta_i", [-1e-13, -1e-300, 360.0, 720.0 - 1e-13])
def test_theta_f_is_in_0_360_for_angles_at_the_seam(theta_i):
    """Spec: theta_f in [0, 360). A miss leaves the part as it was, so theta_f
    is theta_i wrapped; angles a rounding error below 0 (or 720) wrap onto
    360.0 in floating point (the kernel's radians, then degrees), which is
    outside the range and must come back as 0."""
    d_far = 1.01 * (1.0 + R_PIN / PART.a)
    one = simulate.rollout(PART, theta_i, d_far, 0.2, R_PIN)
    assert one.status.item() == "miss"
    assert 0.0 <= float(one.theta_f) < 360.0
    assert abs(circular_diff(float(one.theta_f), theta_i)) < 1e-9
    grid = simulate.compute_map(PART, [theta_i, 10.0], [d_far], 0.2, R_PIN)
    assert np.all((grid.theta_f.values >= 0.0) & (grid.theta_f.values < 360.0))


@pytest.mark.parametrize("x", [-1e-14, -1e-300, 360.0, -360.0, 720.0])
def test_wrap_never_returns_360(x):
    """np.mod(-1e-14, 360) rounds to 360.0 exactly; the wrap must map it to 0
    (through the public rollout the kernel's own radian wrap rarely hands it
    such a value, so the guard is checked here directly)."""
    w = simulate._wrap_deg(x)
    assert 0.0 <= w < 360.0 and abs(circular_diff(w, x)) < 1e-9
    arr = simulate._wrap_deg(np.array([x, 1.0]))
    assert np.all((arr >= 0.0) & (arr < 360.0))


# ---------------------------------------------- stored lattice: every setting checked

@pytest.mark.parametrize("changed", ["pin_radius", "ds_max", "tol"])
def test_stored_lattice_is_not_reused_under_other_settings(tmp_path, changed):
    """A refinement lattice stores rollout outcomes; reused under another pin
    radius or integrator setting it would hand the planner outcomes of a
    different computation. Each setting alone must invalidate it."""
    base = {"pin_radius": R_PIN, "ds_max": 0.05, "tol": 1e-7}  # tol: the kernels' default
    lattice = OutcomeLattice(PART, "minpower", base["pin_radius"], 0.0, base["ds_max"], base["tol"])
    keys = np.array([[0, 50, 20], [900, -50, 20]])  # integer lattice keys
    lattice.add(keys, np.zeros(2, np.int8), np.array([10.0, 20.0]), np.zeros(2))
    save_lattice(tmp_path, lattice)
    same = load_lattice(tmp_path, PART, "minpower", 0.0, base["pin_radius"],
                        KernelSettings(ds_max=base["ds_max"], tol=base["tol"]))
    assert same.known == lattice.known and len(same.known) == 2
    other = dict(base)
    other[changed] = base[changed] * 2.0
    moved = load_lattice(tmp_path, PART, "minpower", 0.0, other["pin_radius"],
                         KernelSettings(ds_max=other["ds_max"], tol=other["tol"]))
    assert not moved.known, f"lattice reused with another {changed}"


def test_stored_lattice_tells_tiny_tolerances_apart(tmp_path):
    """Kernel tolerances below 1e-8 (1e-9 vs 2e-9) are different settings: a lattice
    made with one is not reused for the other (an absolute tolerance once hid this)."""
    lattice = OutcomeLattice(PART, "minpower", R_PIN, 0.0, 0.05, 1e-9)
    lattice.add(np.array([[0, 50, 20]]), np.zeros(1, np.int8), np.array([10.0]), np.zeros(1))
    save_lattice(tmp_path, lattice)
    assert not load_lattice(tmp_path, PART, "minpower", 0.0, R_PIN, KernelSettings(ds_max=0.05, tol=2e-9)).known


# ---------------------------------------- a stored plan's predicted sets: every branch

def test_predicted_sets_take_every_branch_of_a_state():
    """A state that splits at a pin has one branch per piece; the plan predicts
    the union of every branch's last set (a state with no branch predicts
    nothing). Arcs by hand: [10, 15] and [12, 22] overlap into [10, 22]
    (start 10, width 12); [200, 204] and [350, 365] stay apart."""
    from pipeline.planning.claims.verify import predicted_sets

    def step(start, width):
        return {"band": {"start": start, "width": width}}
    plan = {"initial_states": {
        "split": [[step(90.0, 1.0), step(10.0, 5.0)], [step(90.0, 1.0), step(200.0, 4.0)],
                  [step(12.0, 10.0)], [step(350.0, 15.0)]],
        "none": [[]],
    }}
    got = sorted((round(s, 9), round(w, 9)) for s, w in predicted_sets(plan, "split"))
    assert got == [(10.0, 12.0), (200.0, 4.0), (350.0, 15.0)]
    assert predicted_sets(plan, "none") == []
