"""The minpower warm start inside a rollout (issue 15).

``models._model_step`` moves a solve's start by one Newton step on a local
quadratic model of the belt power P (a twist, P's gradient there and a
Hessian from the solves before). It must make the start second-order
accurate in the change of the contact, for the sticking family (one
unknown) and the sliding family (two unknowns, where the start is rescaled
onto the family and the model with it). The observable: with ``take = 1``
a solve returns its start plus one unchecked Newton step, so its error is
about the square of the start's error; a correct model step makes that
error second order in the contact change *before* the Newton step.

The strict answers (``take = _DEC_TAKE``) are the reference; they are
checked against brute-force quadrature in ``test_models.py``. The rollout's
own threshold (``rollout._solve_take``) is checked against the fine
reference by the step-halving and vector tests.
"""
import math

import numpy as np
import pytest

from kernels.models import _DEC_TAKE, NO_MODEL, _cone_edge, _push_scale, _slide_solve, _stick_solve
from kernels.rollout import DEFAULT_TOL, _prepare, _solve_take

TRIANGLE = [(0.0, 0.0), (60.0, 0.0), (15.0, 35.0)]
QUAD = [(0.0, 0.0), (50.0, 0.0), (60.0, 30.0), (10.0, 25.0)]


def part(xy):
    verts, area, _, quad, _, _ = _prepare(np.asarray(xy, dtype=float))
    return verts, quad, area


def edge_contact(verts, j, t):
    """Contact at fraction ``t`` along edge ``j``: point and inward normal."""
    p, q = verts[j], verts[(j + 1) % len(verts)]
    e = (q - p) / np.linalg.norm(q - p)
    return p + t * (q - p), np.array([-e[1], e[0]])


def rotated(v, angle):
    c, s = math.cos(angle), math.sin(angle)
    return np.array([c * v[0] - s * v[1], s * v[0] + c * v[1]])


def model_of(xi, g, hess):
    return (1.0, *map(float, xi), *map(float, g), *map(float, hess))


def stick(verts, quad, area, c, vp, warm_om, model, take):
    vx, vy, om, g, hess, _ = _stick_solve(quad, area, float(c[0]), float(c[1]),
                                          float(vp[0]), float(vp[1]), float(warm_om), model,
                                          float(take))
    return np.array([vx, vy, om]), np.array(g), np.array(hess)


def slide(verts, quad, area, c, n, vp, mu, side, warm, model, take):
    """Sliding twist on the physical scale (``n . u(c) = n . v_p``), its
    gradient and Hessian (as ``models._minpower_twist`` returns them)."""
    ex, ey = _cone_edge(float(n[0]), float(n[1]), mu, side)
    vx, vy, om, g, hess, _ = _slide_solve(quad, area, float(c[0]), float(c[1]), ex, ey,
                                          float(warm[0]), float(warm[1]), float(warm[2]),
                                          model, float(take))
    scale = _push_scale(vx, vy, om, float(c[0]), float(c[1]), float(n[0]), float(n[1]),
                        float(vp[0]), float(vp[1]))
    assert scale > 0.0
    return scale * np.array([vx, vy, om]), np.array(g), np.array(hess) / scale


@pytest.mark.parametrize("xy,edge", [(TRIANGLE, 0), (TRIANGLE, 2), (QUAD, 1)])
def test_model_step_makes_the_sticking_start_second_order(xy, edge):
    verts, quad, area = part(xy)
    c0, n = edge_contact(verts, edge, 0.4)
    vp0 = 0.9 * n + 0.2 * np.array([-n[1], n[0]])
    xi0, g0, h0 = stick(verts, quad, area, c0, vp0, 0.0, NO_MODEL, _DEC_TAKE)
    errors = {}
    for delta in (2e-2, 1e-2):
        c1 = c0 + delta * np.array([-n[1], n[0]])  # slid along the edge
        vp1 = rotated(vp0, delta)  # and the part turned
        exact = stick(verts, quad, area, c1, vp1, 0.0, NO_MODEL, _DEC_TAKE)[0]
        one_newton = {
            "raw": stick(verts, quad, area, c1, vp1, xi0[2], NO_MODEL, 1.0)[0],
            "model": stick(verts, quad, area, c1, vp1, xi0[2], model_of(xi0, g0, h0), 1.0)[0],
        }
        errors[delta] = {k: np.linalg.norm(v - exact) / np.linalg.norm(exact)
                         for k, v in one_newton.items()}
    # Raw start: error ~delta, one Newton step ~delta^2. Model start: error
    # ~delta^2, one Newton step ~delta^4 (or rounding).
    for delta, err in errors.items():
        assert err["model"] <= 1e-2 * err["raw"] + 1e-13, (delta, err)
    assert errors[1e-2]["raw"] <= errors[2e-2]["raw"] / 3.0, errors  # sanity: quadratic


@pytest.mark.parametrize("xy,edge,mu,side", [(TRIANGLE, 0, 0.2, 1), (TRIANGLE, 1, 0.5, -1),
                                             (QUAD, 2, 0.0, 1), (QUAD, 3, 0.3, 1)])
def test_model_step_makes_the_sliding_start_second_order(xy, edge, mu, side):
    verts, quad, area = part(xy)
    c0, n = edge_contact(verts, edge, 0.6)
    vp0 = 0.8 * n - 0.5 * side * np.array([-n[1], n[0]])
    xi0, g0, h0 = slide(verts, quad, area, c0, n, vp0, mu, side, (1.0, 0.0, 0.0), NO_MODEL,
                        _DEC_TAKE)
    # Small changes: on some edges the sliding twist turns fast with the
    # contact (QUAD's edge 2 at mu 0: 20 % for a 2e-2 shift), and a model
    # step longer than 10 % of the start is not taken.
    for delta in (4e-3, 2e-3):
        c1 = c0 + delta * np.array([-n[1], n[0]])
        n1 = n  # same edge: same normal
        vp1 = rotated(vp0, delta)
        exact = slide(verts, quad, area, c1, n1, vp1, mu, side, (1.0, 0.0, 0.0), NO_MODEL,
                      _DEC_TAKE)[0]
        raw = slide(verts, quad, area, c1, n1, vp1, mu, side, xi0, NO_MODEL, 1.0)[0]
        modelled = slide(verts, quad, area, c1, n1, vp1, mu, side, xi0,
                         model_of(xi0, g0, h0), 1.0)[0]
        err_raw = np.linalg.norm(raw - exact) / np.linalg.norm(exact)
        err_model = np.linalg.norm(modelled - exact) / np.linalg.norm(exact)
        assert err_raw > 1e-9, "the contact change must move the answer"
        assert err_model <= 1e-2 * err_raw + 1e-13, (delta, err_raw, err_model)


@pytest.mark.parametrize("scale", [-0.5, -2.0, 0.5])
def test_model_step_on_a_twist_of_any_sign(scale):
    """A sliding twist continued past separation (``_continued_slide``) is
    the family's twist times a factor <= 0: the start and its model are
    rescaled with that sign (P is even: its gradient is odd, its Hessian
    even, of degrees 0 and -1), and stay second order."""
    verts, quad, area = part(TRIANGLE)
    c0, n = edge_contact(verts, 0, 0.6)
    mu, side = 0.3, 1
    vp0 = 0.8 * n - 0.5 * side * np.array([-n[1], n[0]])
    xi0, g0, h0 = slide(verts, quad, area, c0, n, vp0, mu, side, (1.0, 0.0, 0.0), NO_MODEL,
                        _DEC_TAKE)
    warm = scale * xi0
    model = model_of(warm, np.sign(scale) * g0, h0 / abs(scale))
    ex, ey = _cone_edge(float(n[0]), float(n[1]), mu, side)

    def family_twist(c, start, model, take):
        vx, vy, om, *_ = _slide_solve(quad, area, float(c[0]), float(c[1]), ex, ey,
                                      *map(float, start), model, float(take))
        return np.array([vx, vy, om])

    c1 = c0 + 3e-3 * np.array([-n[1], n[0]])
    exact = family_twist(c1, (1.0, 0.0, 0.0), NO_MODEL, _DEC_TAKE)
    raw = family_twist(c1, warm, NO_MODEL, 1.0)
    modelled = family_twist(c1, warm, model, 1.0)
    err_raw = np.linalg.norm(raw - exact) / np.linalg.norm(exact)
    err_model = np.linalg.norm(modelled - exact) / np.linalg.norm(exact)
    assert err_raw > 1e-9
    assert err_model <= 1e-2 * err_raw + 1e-13, (scale, err_raw, err_model)


def test_a_model_never_changes_the_converged_answer():
    """The model only moves the start: a strict solve from a poor model (the
    Hessian of another contact, a wrong gradient) ends at the same twist."""
    verts, quad, area = part(TRIANGLE)
    c, n = edge_contact(verts, 0, 0.3)
    vp = 0.7 * n + 0.4 * np.array([-n[1], n[0]])
    exact = stick(verts, quad, area, c, vp, 0.0, NO_MODEL, _DEC_TAKE)[0]
    far = stick(verts, quad, area, *edge_contact(verts, 1, 0.8)[:1], vp, 0.0, NO_MODEL,
                _DEC_TAKE)
    for model in (model_of(*far), model_of(exact, (0.3, -0.2, 0.5), far[2]),
                  model_of(exact, (0.0, 0.0, 0.0), np.zeros(6))):
        got = stick(verts, quad, area, c, vp, exact[2] + 0.05, model, _DEC_TAKE)[0]
        np.testing.assert_allclose(got, exact, rtol=0, atol=1e-9 * np.linalg.norm(exact))


def test_solve_threshold_follows_the_step_tolerance():
    """``take`` is a tenth of the step tolerance, never below a single
    solve's 1e-12: the solve's own error stays under the integration's."""
    assert _solve_take(DEFAULT_TOL) == pytest.approx(0.1 * DEFAULT_TOL)
    assert _solve_take(DEFAULT_TOL / 32) == pytest.approx(0.1 * DEFAULT_TOL / 32)
    assert _solve_take(1e-15) == _DEC_TAKE
