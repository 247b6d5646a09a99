"""The support table of parts with many edges against the exact edge sums.

``kernels.support_table`` replaces, for a part of ``TABLE_MIN_EDGES`` material
edges or more, the exact sums of ``kernels.edge_integrals`` (themselves
checked against brute-force quadrature in ``test_support.py``) by a table
built once per part. These tests hold it to the exact sums: the integrals at
random centres of rotation in both grids, the far-field series against the
quadrature it replaces, the spoke terms that make a near edge's share the
derivative of its E (by finite differences), and whole rollouts and maps of a
CAD-like part (fillets, holes) with and without the table.
"""
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from drawn_shapes import circle, rounded_rectangle
from kernels.batch import _rollout_grid
from kernels.edge_integrals import _support_sum, _table_sizes
from kernels.rollout import DEFAULT_DS_MAX, DEFAULT_TOL, _prepare, _prepare_loops
from kernels.support import _R_FAR, _point_sums, _point_table, _power
from kernels.support_table import (_N_INNER, _N_OUTER, _R_INNER, _R_OUTER, TABLE_MIN_EDGES, _far_values,
                                   _has_table, _moment_power, _near_edge_terms, _near_edges, _table_support,
                                   _top_cells, _twin_edges, _with_table)
from pipeline.parts.part import Part, _stack


# A 50 x 40 mm plate with 6 mm fillets (60 outline vertices) and two holes of
# 16 vertices: 96 material edges with the keyhole's bridges.
PLATE = rounded_rectangle(50.0, 40.0, 6.0, 14)
PLATE_HOLES = [circle(12.0, 20.0, 3.25, 16), circle(38.0, 20.0, 3.25, 16)]
# A non-convex filleted L bracket (no holes), 26 outline vertices.
L_BRACKET = np.array([(0, 0), (50, 0), (50, 12)]
                     + [(17 + 5 * math.cos(math.radians(270 - 90 * k / 20)),
                         17 + 5 * math.sin(math.radians(270 - 90 * k / 20))) for k in range(21)]
                     + [(12, 40), (0, 40)], dtype=float)[::-1].copy()


def _raw(quad):
    """The support table ``quad`` without its tabulated part."""
    f, n = _table_sizes(quad)
    return np.vstack([quad[:f + 2 * n], [[f, n, 0.0]]])


def _plate_quads():
    verts, area, a, quad, m_max, convex = _prepare_loops(*_stack(PLATE, PLATE_HOLES))
    return verts, area, quad, _raw(quad)


def _scales(exact):
    e, gx, gy, nxx, nxy, nyy = exact
    g = math.hypot(gx, gy)
    nn = abs(nxx) + abs(nyy)
    return np.array([abs(e), g, g, nn, nn, nn])


def test_parts_with_many_edges_carry_a_table_and_small_ones_do_not():
    tri = _prepare(np.array([(0, 0), (60, 0), (15, 35)], dtype=float))[3]
    assert not _has_table(tri)
    _, _, quad, raw = _plate_quads()
    assert _has_table(quad) and not _has_table(raw)
    n = _table_sizes(raw)[1]
    assert n >= TABLE_MIN_EDGES
    # Just below the threshold: exact sums, bit for bit the code of before.
    below = _prepare(circle(0.0, 0.0, 10.0, TABLE_MIN_EDGES - 1))[3]
    at = _prepare(circle(0.0, 0.0, 10.0, TABLE_MIN_EDGES))[3]
    assert not _has_table(below) and _has_table(at)


@pytest.mark.parametrize("grid", [(_R_INNER, _N_INNER, 0.0), (_R_OUTER, _N_OUTER, _R_INNER)])
def test_the_top_cells_built_in_parallel_are_those_built_one_by_one(grid):
    """The table's costly part, each top-level cell's near edges and far
    values, runs over the cells in parallel: every cell's numbers are, bit
    for bit, those of the cell computed alone (no scratch is shared)."""
    _, _, _, raw = _plate_quads()
    f, n = _table_sizes(raw)
    r_grid, n_grid, skip = grid
    every = np.flatnonzero(~_twin_edges(raw)).astype(np.int64)
    near, count, vals = _top_cells(raw, f, n, every, every.size, r_grid, n_grid, skip)
    h = 2.0 * r_grid / n_grid
    one = np.empty(n, dtype=np.int64)
    skipped = 0
    for c in range(n_grid * n_grid):
        x0, y0 = -r_grid + (c // n_grid) * h, -r_grid + (c % n_grid) * h
        if skip and -skip <= x0 and x0 + h <= skip and -skip <= y0 and y0 + h <= skip:
            assert count[c] == -1
            skipped += 1
            continue
        m = _near_edges(raw, f, n, every, every.size, x0, y0, h, one)
        assert count[c] == m and np.array_equal(near[c, :m], one[:m])
        assert vals[c].tobytes() == _far_values(raw, f, n, (x0, y0, h), one, m).tobytes()
    assert skipped == (4 if skip else 0)  # the outer grid leaves out its 2 x 2 cells inside the inner square


@pytest.mark.parametrize("half_width", [1.2, 3.0, 7.9])
def test_table_matches_the_exact_sums(half_width):
    """E to 1e-9, G to 5e-8 and N to 1e-5 of their size, inside the part,
    around it and out to the far-field switch."""
    _, _, quad, raw = _plate_quads()
    rng = np.random.default_rng(7)
    worst = np.zeros(6)
    for rx, ry in rng.uniform(-half_width, half_width, (800, 2)):
        exact = np.array(_support_sum(raw, rx, ry))
        table = np.array(_table_support(quad, rx, ry))
        worst = np.maximum(worst, np.abs(table - exact) / _scales(exact))
    assert worst[0] < 1e-9, worst
    assert max(worst[1:3]) < 5e-8, worst
    assert max(worst[3:]) < 1e-5, worst


@settings(max_examples=6, deadline=None)
@given(st.integers(min_value=24, max_value=60), st.floats(min_value=0.15, max_value=0.45),
       st.integers(min_value=0, max_value=2**31 - 1))
def test_table_matches_the_exact_sums_on_random_stars(n, wobble, seed):
    """Random star-shaped outlines (non-convex) with a hole: the same bounds,
    at random points and at points on edges and vertices."""
    rng = np.random.default_rng(seed)
    ang = np.sort(rng.uniform(0.0, 2 * math.pi, n))
    ang += np.arange(n) * 1e-3  # distinct
    rad = 30.0 * (1.0 - wobble * rng.uniform(0.0, 1.0, n))
    outline = np.column_stack([rad * np.cos(ang), rad * np.sin(ang)])
    hole = circle(0.0, 0.0, 0.3 * 30.0 * (1.0 - wobble), 12)[::-1]
    verts, _, _, quad, _, _ = _prepare_loops(*_stack(outline, [hole]))
    raw = _raw(quad)
    f, m = _table_sizes(raw)
    pts = list(rng.uniform(-1.2, 1.2, (200, 2))) + list(rng.uniform(-6.0, 6.0, (100, 2)))
    pts += [raw[f + j, :2] for j in range(0, m, 3)]  # on vertices
    pts += [0.5 * (raw[f + j, :2] + raw[f + (j + 1) % m, :2]) for j in range(0, m, 3)]  # on edges
    for rx, ry in pts:
        exact = np.array(_support_sum(raw, rx, ry))
        table = np.array(_table_support(quad, rx, ry))
        err = np.abs(table - exact) / _scales(exact)
        assert err[0] < 1e-9 and max(err[1:3]) < 5e-8 and max(err[3:]) < 1e-5, (rx, ry, err)


def test_spoke_terms_make_each_edge_share_a_derivative_of_its_e():
    """A near edge's G and N (with the spoke terms) are -grad E_e and
    tr(H) I - H of its E_e, by central differences."""
    _, _, _, raw = _plate_quads()
    f, n = _table_sizes(raw)
    rng = np.random.default_rng(3)
    eps = 1e-5
    for edge in rng.choice(n, 12, replace=False):
        for rx, ry in rng.uniform(-1.0, 1.0, (3, 2)):
            e, gx, gy, nxx, nxy, nyy = _near_edge_terms(raw, f, n, edge, rx, ry)

            def term(x, y, k):
                return _near_edge_terms(raw, f, n, edge, x, y)[k]
            dex = (term(rx + eps, ry, 0) - term(rx - eps, ry, 0)) / (2 * eps)
            dey = (term(rx, ry + eps, 0) - term(rx, ry - eps, 0)) / (2 * eps)
            assert gx == pytest.approx(-dex, abs=1e-7) and gy == pytest.approx(-dey, abs=1e-7)
            hxx = -(term(rx + eps, ry, 1) - term(rx - eps, ry, 1)) / (2 * eps)
            hxy = -(term(rx, ry + eps, 1) - term(rx, ry - eps, 1)) / (2 * eps)
            hyy = -(term(rx, ry + eps, 2) - term(rx, ry - eps, 2)) / (2 * eps)
            tr = hxx + hyy
            assert nxx == pytest.approx(tr - hxx, abs=1e-5)
            assert nxy == pytest.approx(-hxy, abs=1e-5)
            assert nyy == pytest.approx(tr - hyy, abs=1e-5)


def test_far_series_matches_the_quadrature_it_replaces():
    """Beyond R_FAR (and for pure translations) the moment series gives the
    power, its gradient and Hessian of the collapsed Gauss rule to 1e-12."""
    _, area, quad, raw = _plate_quads()
    f = _table_sizes(raw)[0]
    rng = np.random.default_rng(11)
    for k in range(60):
        phi = rng.uniform(0, 2 * math.pi)
        vx, vy = math.cos(phi), math.sin(phi)
        om = 0.0 if k % 10 == 0 else rng.uniform(-1.0, 1.0) / (_R_FAR * rng.uniform(1.0, 30.0))
        quadrature = np.array(_point_sums(raw, f, vx, vy, om, -1, -1.0)[:10]) / area
        series = np.array(_moment_power(quad, area, vx, vy, om))
        assert np.allclose(series, quadrature, rtol=0, atol=1e-12 * abs(quadrature[0])), (om, series - quadrature)
        # _power dispatches to the series there.
        assert np.array_equal(np.array(_power(quad, area, vx, vy, om)), series)


def _grid(verts, area, a, quad, m_max, convex, theta, d, mu_c=0.2, r_pin=3.0):
    return _rollout_grid(verts, area, a, quad, m_max, convex, 0, mu_c, r_pin / a, np.radians(theta), d,
                         0.0, np.inf, DEFAULT_DS_MAX, DEFAULT_TOL, 1)


@pytest.mark.parametrize("which", ["holed plate", "L bracket"])
def test_rollouts_on_the_table_agree_with_the_exact_sums(which):
    """The spec's convergence criterion is 0.05 deg; the table moves theta_f
    by far less (1e-3 deg), with the same statuses, over a map of the
    paper's d values."""
    if which == "holed plate":
        verts, area, a, quad, m_max, convex = _prepare_loops(*_stack(PLATE, PLATE_HOLES))
    else:
        verts, area, a, quad, m_max, convex = _prepare(L_BRACKET)
    assert _has_table(quad)
    theta = np.arange(0.0, 360.0, 9.0)
    d = np.array([-0.8, -0.5, -0.2, 0.2, 0.5, 0.8])
    tab = _grid(verts, area, a, quad, m_max, convex, theta, d)
    exact = _grid(verts, area, a, _raw(quad), m_max, convex, theta, d)
    assert np.array_equal(tab[0], exact[0])
    ok = tab[0] == 0
    assert ok.sum() > 100
    dtheta = np.degrees(np.abs(np.angle(np.exp(1j * (tab[2][ok] - exact[2][ok])))))
    assert dtheta.max() < 1e-3, dtheta.max()
    assert np.abs(tab[3][ok] - exact[3][ok]).max() < 1e-4  # dy, mm (the reference tests allow 0.05)


def test_point_supports_roll_out_the_same_on_a_tabulated_part():
    """A point support replaces the quadrature rows and ignores the table:
    the same rollouts bit for bit whether the part's table is there or not."""
    verts, area, a, quad, m_max, convex = _prepare_loops(*_stack(PLATE, PLATE_HOLES))
    pts = np.array([[-0.3, -0.2, 0.4], [0.35, -0.1, 0.3], [0.0, 0.3, 0.3]])
    with_table = _point_table(quad, pts)
    without = _point_table(_raw(quad), pts)
    assert _table_sizes(with_table) == (3, _table_sizes(quad)[1])
    from kernels.models import MINPOWER_POINTS
    theta = np.radians(np.arange(0.0, 360.0, 30.0))
    d = np.array([-0.5, 0.3])
    args = (0.2, 3.0 / a, theta, d, 0.0, np.inf, DEFAULT_DS_MAX, DEFAULT_TOL, 1)
    one = _rollout_grid(verts, area, a, with_table, m_max, convex, MINPOWER_POINTS, *args)
    two = _rollout_grid(verts, area, a, without, m_max, convex, MINPOWER_POINTS, *args)
    for x, y in zip(one, two):
        assert np.array_equal(x, y)


def test_parts_keep_their_prepared_arrays_and_do_not_pickle_them():
    import pickle
    part = Part.from_vertices(PLATE, holes=PLATE_HOLES)
    first = part.prepared()
    assert part.prepared() is first
    again = pickle.loads(pickle.dumps(part))
    assert "_prepared" not in again.__dict__
    assert np.array_equal(again.prepared()[3], first[3])
