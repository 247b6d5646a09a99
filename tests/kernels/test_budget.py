"""The integrator's step budget (issue 12, "Runs that never end").

Every rollout ends: after ``max_steps_for(n)`` integration steps it stops
with status ``truncated`` and reason "step budget". The extreme inputs the
issue lists (a pin far larger than the part, a 1e-9-scale part, a sliver
against a huge pin at low friction, ``ds_max = 1e-9``, ``tol = 1e-30``) ran
for minutes before; here each must finish within the budget and in seconds.
"""
from __future__ import annotations

import math
import time

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from conftest import TRIANGLE, fewer_examples
from kernels.models import ELLIPSOID, MINPOWER, TIP
from kernels.rollout import (JAM_REASONS, JAMMED, MAX_STEPS, MIN_STEPS, OK, TRUNC_STEP_BUDGET,
                             TRUNCATED, _prepare, _rollout, _rollout_budget, max_steps_for)
from pipeline.maps import simulate
from strategies import convex_polygons, star_polygons, triangles

LOCATE_STEPS = 61  # one event location may run past the budget
TRI = np.array(TRIANGLE, float)
SLIVER = np.array([(0.0, 0.0), (60.0, 0.0), (60.0, 0.5)])


def _run(xy, model=MINPOWER, mu=0.2, r_pin=3.0, theta=0.3, d=0.3, ds_max=0.1, tol=1e-7,
         record=False, max_steps=None, v_pin=0.0):
    prep = _prepare(np.asarray(xy, float))
    budget = max_steps_for(len(xy)) if max_steps is None else max_steps
    return _rollout_budget(*prep, model, mu, r_pin, theta, d, v_pin, np.inf, ds_max, tol,
                           record, budget), budget


def test_budget_depends_on_polygon_size():
    assert max_steps_for(3) == MAX_STEPS
    assert max_steps_for(500) == MIN_STEPS
    assert MIN_STEPS <= max_steps_for(100) <= MAX_STEPS


def test_budget_large_enough_is_invisible():
    # A normal rollout uses a few dozen steps: with any budget above that the
    # results are bit-identical to _rollout's, and the trajectory has one row
    # per accepted step plus the start.
    prep = _prepare(TRI)
    ref = _rollout(*prep, MINPOWER, 0.2, 3.0, 0.3, 0.3, 0.0, np.inf, 0.1, 1e-7, True)
    res, _ = _run(TRI, record=True, max_steps=10_000)
    assert res[9] < 300
    for k in range(7):
        assert res[k] == ref[k]
    np.testing.assert_array_equal(res[7], ref[7])
    np.testing.assert_array_equal(res[8], ref[8])
    assert res[7].shape[0] <= res[9] + 1


def test_budget_too_small_truncates():
    full, _ = _run(TRI, max_steps=10_000)
    assert full[0] == OK and full[9] > 10
    res, _ = _run(TRI, max_steps=5)
    assert res[0] == TRUNCATED and res[1] == TRUNC_STEP_BUDGET
    assert 5 <= res[9] <= 5 + LOCATE_STEPS
    assert res[4] < full[4]  # stopped early
    assert JAM_REASONS[TRUNC_STEP_BUDGET] == "step budget"


EXTREME = {
    "huge pin (r_pin / a = 1e5)": dict(xy=TRI, r_pin=3.7e6),
    "1e-9-scale part": dict(xy=TRI * 1e-11, r_pin=3.0),
    "sliver, huge pin, low friction": dict(xy=SLIVER, r_pin=3e4, mu=0.01, theta=0.1, d=0.2),
    "ds_max 1e-9": dict(xy=TRI, ds_max=1e-9),
    "tol 1e-30": dict(xy=TRI, tol=1e-30),
}


@pytest.mark.parametrize("model", [MINPOWER, TIP, ELLIPSOID])
@pytest.mark.parametrize("case", list(EXTREME))
def test_issue_cases_end_quickly(case, model, warm_kernels):
    kw = dict(EXTREME[case])
    _run(kw["xy"], model=model, max_steps=3)  # compile outside the timing
    t0 = time.perf_counter()
    res, budget = _run(model=model, **kw)
    elapsed = time.perf_counter() - t0
    assert res[9] <= budget + LOCATE_STEPS
    assert res[0] in (TRUNCATED, JAMMED, OK)
    if res[0] == TRUNCATED:
        assert res[1] == TRUNC_STEP_BUDGET and res[9] >= budget
    assert math.isfinite(res[2]) and 0.0 <= res[2] < 2.0 * math.pi
    # Seconds, not minutes (generous: the CI machine is shared and slow).
    assert elapsed < 10.0, f"{case}: {elapsed:.1f} s"


def test_public_rollout_names_the_limit(triangle):
    # The public wrappers refuse settings outside sane ranges (pipeline.checks);
    # the kernel's budget is the second line, and names itself in the flags.
    from pipeline.errors import PinfeedError
    with pytest.raises(PinfeedError, match="ds_max must be in"):
        simulate.rollout(triangle, 17.0, 0.3, 0.2, 3.0, ds_max=1e-9)
    m = _budget_map(triangle)
    code = m.jam_reason.attrs["flag_meanings"].split().index("step_budget")
    assert np.all(m.status.values == simulate.STATUSES.index("truncated"))
    assert np.all(m.jam_reason.values == code)


def _budget_map(part):
    """A map whose rollouts exhaust the budget: the kernel grid called with a
    tolerance no public wrapper accepts, packed as the wrapper would."""
    import xarray as xr

    from kernels.batch import _rollout_grid, blocks_for
    res = _rollout_grid(*part.prepared(), 0, 0.2, 3.0, np.radians([17.0, 40.0]), np.array([0.3]), 0.0,
                        np.inf, 0.1, 1e-30, blocks_for(1, 2))
    return xr.Dataset({"status": (("d", "theta_i"), res[0]),
                       "jam_reason": (("d", "theta_i"), res[1], dict(simulate.JAM_ATTRS))})


def _log_uniform(lo, hi):
    return st.floats(math.log10(lo), math.log10(hi)).map(lambda e: 10.0 ** e)


BUDGET = 150


# Each example runs a full rollout to its step budget: 15 in CI.
@fewer_examples(0.15)
@given(poly=st.one_of(triangles(), convex_polygons(), star_polygons()),
       scale=_log_uniform(1e-9, 1e6), rp_ratio=_log_uniform(1e-3, 1e6),
       mu=st.one_of(st.just(0.0), st.floats(0.0, 2.0)), model=st.sampled_from([0, 1, 2]),
       v_pin=st.one_of(st.just(0.0), st.floats(-3.0, 3.0)),
       ds_max=_log_uniform(1e-9, 1.0), tol=_log_uniform(1e-30, 1e-3),
       theta=st.floats(0.0, 2.0 * math.pi), d=st.floats(-1.2, 1.2), record=st.booleans())
def test_extreme_inputs_respect_the_step_budget(poly, scale, rp_ratio, mu, model, v_pin, ds_max,
                                                tol, theta, d, record):
    xy = poly * scale
    prep = _prepare(xy)
    r_pin = rp_ratio * prep[2]
    res = _rollout_budget(*prep, model, mu, r_pin, theta, d, v_pin, np.inf, ds_max, tol, record,
                          BUDGET)
    status, reason, theta_f, steps = res[0], res[1], res[2], res[9]
    assert steps <= BUDGET + LOCATE_STEPS
    assert status in (0, 1, 2, 3)
    assert math.isfinite(theta_f) and 0.0 <= theta_f < 2.0 * math.pi
    assert (status == TRUNCATED) == (reason == TRUNC_STEP_BUDGET)  # no max_travel given
    if status == TRUNCATED:
        assert steps >= BUDGET
    if record:
        assert res[7].shape[0] <= BUDGET + 1 and res[8].shape[0] <= BUDGET + 2
