"""Tabulated support integrals for parts with many edges.

A part drawn in CAD has tens to hundreds of edges once its fillets and holes
are flattened, and the exact sums of ``edge_integrals`` cost a logarithm per
edge at every evaluation of the belt's power: a rollout of such a part cost
15 to 25 times a triangle's. This module builds, once per part, a table in
the part's body frame that gives the same E(r), G(r), N(r) (and, for a
centre of rotation far away, the power itself) at a cost that does not grow
with the number of edges.

Notes
-----
**Near field** (``_table_support``): the square ``|x|, |y| < _R_INNER`` is
cut into ``_N_INNER``^2 cells and the square ``|x|, |y| < _R_OUTER`` into
``_N_OUTER``^2 coarser ones. For each cell the edges within ``_NEAR`` cell
widths of it are its *near* edges; the sum over all other edges is analytic
on the cell (an edge's term is singular on the edge only), so a tensor
polynomial of degree ``_DEGREE`` interpolates it at the cell's Chebyshev
points with an error that falls geometrically with the degree. A cell with
more than ``_SPLIT_NEAR`` near edges is split in four, down to ``_MAX_SPLIT``
times, so the cells along the outline stay cheap; a child's far part is its
parent's polynomial plus the few edges near the parent but not near it. At
a point ``r`` of a cell::

    E(r) = poly(r) + sum over near edges of E_edge(r)      (exact near terms)
    G = -grad E,    N = tr(H) I - H,  H = grad grad E

(``N = integral w_hat w_hat^T / rho dA`` and the Hessian of E is
``integral (I - w_hat w_hat^T) / rho dA``, both of trace
``integral 1 / rho dA``). E, G and N are derivatives of one function, so
Newton's method sees a consistent model. The bridges of a part with holes
(``geometry._keyhole``: each walked once each way) cancel and are never near
edges.

**Far field** (``_moment_power``): for a centre of rotation beyond
``support._R_FAR`` (|beta| = |omega| / |v| < 1/8) the power is a double series
in the complex moments ``M_jk = integral w^j conj(w)^k dA`` of the material.
With complex ``v = v_x + i v_y``, ``u(w) = v + i omega w = v (1 + beta w)``,
``beta = i omega / v``::

    |u| = |v| (1 + beta w)^(1/2) (1 + conj(beta w))^(1/2)
        = |v| sum_jk b_j b_k beta^j conj(beta)^k w^j conj(w)^k

(``b_j = binom(1/2, j)``), so ``P = |v| / A sum_jk b_j b_k beta^j
conj(beta)^k M_jk``, and the gradient and Hessian are the same sums with the
binomial series of exponents -1/2 and -3/2 and shifted moments (see
``_moment_power``). Terms with ``j + k <= _ORDER`` are kept: the rest is
below ``8^-(_ORDER+1)`` of P.

Layout. The table is rows of three float64 appended to the support table
``quad`` (``support._fan_quadrature``) after the edge directions, before the
trailer row, whose third entry gives the table's number of rows (0: none).
Offsets below are rows from the table's first row::

    row 0: (_R_INNER, _N_INNER, _DEGREE)
    row 1: (_R_OUTER, _N_OUTER, _ORDER)
    row 2: (offset of the cell index, offset of the moments, first outer cell)
    moments: (M + 1)^2 rows (Re, Im, 0) of M_jk, M = _ORDER + 2, j major
    cell index: one row per cell: the inner grid's cells (x major), the
        children of its split cells (four at a time, x major), then the
        outer grid's cells and their children; a leaf's row is (offset of
        its coefficients, number of near edges, offset of their indices), a
        split cell's (-2, row of its first child, 0), an unused outer cell
        inside the inner square's (-1, 0, 0)
    coefficients: (D + 1)^2 / 3 rows per cell, c_ij of X^i Y^j at index
        i (D + 1) + j, X and Y the cell's local coordinates in [-1, 1]
    near edges: edge indices, three to a row
"""
import math

import numpy as np
from numba import prange

from ._numba import jit, jit_alloc, jit_parallel
from .edge_integrals import _edge_support, _support_sum, _table_sizes

_R_INNER = 1.25  # units of a: the outline lies within the unit disc
_N_INNER = 40
_R_OUTER = 8.0  # support._R_FAR: beyond it _moment_power takes over
_N_OUTER = 16
_DEGREE = 8  # (D + 1)^2 = 81 coefficients, 27 rows of three
_NEAR = 1.5  # near edges: within this many cell widths of the cell
_ORDER = 12  # far-field series: terms with j + k <= _ORDER
_SPLIT_NEAR = 3  # a cell with more near edges is split in four ...
_MAX_SPLIT = 3  # ... at most this many times
_HEADER = 3
# Parts whose material has at least this many edges (keyhole bridges
# included) roll out on the table: below it the exact sum is as fast, and
# the parts people plan most (triangles, simple brackets) keep their exact
# arithmetic bit for bit.
TABLE_MIN_EDGES = 24

# Chebyshev points of the first kind on [-1, 1] and T_p at them.
_NODES = np.cos((2.0 * np.arange(_DEGREE + 1) + 1.0) * np.pi / (2.0 * (_DEGREE + 1)))
_CHEB_AT_NODES = np.cos(np.outer(np.arange(_DEGREE + 1),
                                 (2.0 * np.arange(_DEGREE + 1) + 1.0) * np.pi / (2.0 * (_DEGREE + 1))))


def _chebyshev_to_monomial(degree):
    """``C[p, i]``: the coefficient of ``x^i`` in ``T_p(x)``."""
    c = np.zeros((degree + 1, degree + 1))
    c[0, 0] = 1.0
    if degree > 0:
        c[1, 1] = 1.0
    for p in range(2, degree + 1):
        c[p, 1:] = 2.0 * c[p - 1, :-1]
        c[p] -= c[p - 2]
    return c


_CHEB_TO_MONO = _chebyshev_to_monomial(_DEGREE)


def _binomials(alpha, n):
    out = np.empty(n)
    out[0] = 1.0
    for j in range(1, n):
        out[j] = out[j - 1] * (alpha - j + 1) / j
    return out


_B_HALF = _binomials(0.5, _ORDER + 1)
_B_MHALF = _binomials(-0.5, _ORDER + 1)
_B_M3HALF = _binomials(-1.5, _ORDER + 1)

# A collapsed Gauss rule on each fan triangle, exact for the moments used
# (degree up to _ORDER + 2 in w and conj(w)).
_MOM_G = 10
_MOM_X, _MOM_W = np.polynomial.legendre.leggauss(_MOM_G)
_MOM_X = 0.5 * (_MOM_X + 1.0)
_MOM_W = 0.5 * _MOM_W


@jit
def _has_table(quad):
    """True if ``quad`` carries a table (``_with_table``)."""
    return quad[quad.shape[0] - 1, 2] > 0.0


@jit_alloc
def _moments(quad, order):
    """``M[j, k] = integral w^j conj(w)^k dA`` (real and imaginary parts) of
    the material of ``quad``, for ``j + k <= order``, by a collapsed Gauss
    rule on the signed centroid fan of its edges."""
    f, n = _table_sizes(quad)
    m = order + 1
    re = np.zeros((m, m))
    im = np.zeros((m, m))
    g = _MOM_X.shape[0]
    pw_re = np.empty(m)
    pw_im = np.empty(m)
    for e in range(n):
        px, py = quad[f + e, 0], quad[f + e, 1]
        k2 = e + 1 if e + 1 < n else 0
        qx, qy = quad[f + k2, 0], quad[f + k2, 1]
        jac = px * qy - py * qx
        if jac == 0.0:
            continue
        for a in range(g):
            u = _MOM_X[a]
            for b in range(g):
                v = _MOM_X[b]
                wx = u * (px + v * (qx - px))
                wy = u * (py + v * (qy - py))
                wt = _MOM_W[a] * _MOM_W[b] * u * jac
                # powers of w
                pw_re[0], pw_im[0] = 1.0, 0.0
                for j in range(1, m):
                    pw_re[j] = pw_re[j - 1] * wx - pw_im[j - 1] * wy
                    pw_im[j] = pw_re[j - 1] * wy + pw_im[j - 1] * wx
                for j in range(m):
                    for k in range(m - j):
                        # w^j conj(w)^k = w^j conj(w^k)
                        ar, ai = pw_re[j], pw_im[j]
                        br, bi = pw_re[k], -pw_im[k]
                        re[j, k] += wt * (ar * br - ai * bi)
                        im[j, k] += wt * (ar * bi + ai * br)
    return re, im


@jit_alloc
def _twin_edges(quad):
    """``True`` for each edge walked once each way (a bridge of
    ``geometry._keyhole``): the pair cancels and is never a near edge."""
    f, n = _table_sizes(quad)
    twin = np.zeros(n, dtype=np.bool_)
    for j in range(n):
        j2 = j + 1 if j + 1 < n else 0
        for k in range(n):
            k2 = k + 1 if k + 1 < n else 0
            if (quad[f + k, 0] == quad[f + j2, 0] and quad[f + k, 1] == quad[f + j2, 1]
                    and quad[f + k2, 0] == quad[f + j, 0] and quad[f + k2, 1] == quad[f + j, 1]):
                twin[j] = True
                break
    return twin


@jit
def _segment_box_distance(ax, ay, bx, by, x0, y0, x1, y1):
    """Distance between the segment ab and the box ``[x0, x1] x [y0, y1]``."""
    if (x0 <= ax <= x1 and y0 <= ay <= y1) or (x0 <= bx <= x1 and y0 <= by <= y1):
        return 0.0
    best = math.inf
    # Box corners to the segment.
    dx, dy = bx - ax, by - ay
    ll = dx * dx + dy * dy
    for c in range(4):
        cx = x0 if c < 2 else x1
        cy = y0 if c % 2 == 0 else y1
        t = 0.0 if ll == 0.0 else max(0.0, min(1.0, ((cx - ax) * dx + (cy - ay) * dy) / ll))
        ex, ey = ax + t * dx - cx, ay + t * dy - cy
        best = min(best, math.sqrt(ex * ex + ey * ey))
    # Segment ends to the box.
    for c in range(2):
        px = ax if c == 0 else bx
        py = ay if c == 0 else by
        ex = max(x0 - px, 0.0, px - x1)
        ey = max(y0 - py, 0.0, py - y1)
        best = min(best, math.sqrt(ex * ex + ey * ey))
    # A segment crossing the box without an end inside: it crosses an edge
    # of the box, where the corner distances above are not zero.
    for c in range(4):
        if c < 2:
            sx, sy, tx, ty = x0 if c == 0 else x1, y0, x0 if c == 0 else x1, y1
        else:
            sx, sy, tx, ty = x0, y0 if c == 2 else y1, x1, y0 if c == 2 else y1
        d1 = (tx - sx) * (ay - sy) - (ty - sy) * (ax - sx)
        d2 = (tx - sx) * (by - sy) - (ty - sy) * (bx - sx)
        d3 = dx * (sy - ay) - dy * (sx - ax)
        d4 = dx * (ty - ay) - dy * (tx - ax)
        if d1 * d2 <= 0.0 and d3 * d4 <= 0.0:
            return 0.0
    return best


@jit
def _near_edge_terms(quad, f, n, edge, rx, ry):
    """Edge ``edge``'s share of E, G, N about r as the table adds it:
    ``(E_e, Gx, Gy, Nxx, Nxy, Nyy)`` with ``E_e`` its triangle's E
    (``edge_integrals._edge_support``) and the rest such that
    ``G = -grad E`` and ``N = tr(H) I - H`` of any sum of them plus a
    smooth remainder hold (module notes: the spoke terms).

    Notes
    -----
    The triangle ``(r, p, q)`` moves with r, so its own G and N are not the
    derivatives of its E: with ``P = p - r``, ``Q = q - r`` (Reynolds'
    transport over the two spokes from r)::

        grad E_e = -G_e + S(P) - S(Q),      S(X) = |X| (X_y, -X_x) / 6
        H_e = tr(N_e) I - N_e + K(P) - K(Q),
        K(X) = 1 / (3 |X|) [[-2 X_x X_y, X_x^2 - X_y^2], [X_x^2 - X_y^2, 2 X_x X_y]]

    Around a closed loop the spoke terms cancel (``_support_sum``); for a
    cell's near edges they do not, so they are returned with the edge.
    """
    k = edge + 1 if edge + 1 < n else 0
    px, py = quad[f + edge, 0] - rx, quad[f + edge, 1] - ry
    qx, qy = quad[f + k, 0] - rx, quad[f + k, 1] - ry
    r1 = math.sqrt(px * px + py * py)
    r2 = math.sqrt(qx * qx + qy * qy)
    i1 = 1.0 / r1 if r1 > 0.0 else 0.0
    i2 = 1.0 / r2 if r2 > 0.0 else 0.0
    e6, gx2, gy2, nxx, nxy, nyy = _edge_support(px, py, r1, i1, qx, qy, r2, i2,
                                                quad[f + n + edge, 0], quad[f + n + edge, 1])
    gx = 0.5 * gx2 - (r1 * py - r2 * qy) / 6.0
    gy = 0.5 * gy2 + (r1 * px - r2 * qx) / 6.0
    k1, k2 = i1 / 3.0, i2 / 3.0
    kxx = -2.0 * (k1 * px * py - k2 * qx * qy)
    kxy = k1 * (px * px - py * py) - k2 * (qx * qx - qy * qy)
    return e6 / 6.0, gx, gy, nxx - kxx, nxy - kxy, nyy + kxx


@jit
def _poly_value(block, xl, yl):
    """The cell polynomial ``block`` (coefficient rows) at local ``(xl, yl)``."""
    d1 = _DEGREE + 1
    val = 0.0
    for ii in range(_DEGREE, -1, -1):
        row = 0.0
        for jj in range(_DEGREE, -1, -1):
            idx = ii * d1 + jj
            row = row * yl + block[idx // 3, idx % 3]
        val = val * xl + row
    return val


@jit_alloc
def _fit(vals, out):
    """Tensor Chebyshev interpolation of ``vals`` (at the cell's Chebyshev
    points) written as monomial coefficients into ``out`` (three to a row)."""
    d1 = _DEGREE + 1
    cheb = np.zeros((d1, d1))
    for p in range(d1):
        for q in range(d1):
            acc = 0.0
            for a in range(d1):
                ta = _CHEB_AT_NODES[p, a]
                for b in range(d1):
                    acc += vals[a, b] * ta * _CHEB_AT_NODES[q, b]
            wp = 1.0 if p == 0 else 2.0
            wq = 1.0 if q == 0 else 2.0
            cheb[p, q] = acc * wp * wq / (d1 * d1)
    tmp = np.zeros((d1, d1))
    for i in range(d1):
        for q in range(d1):
            acc = 0.0
            for p in range(i, d1):
                acc += _CHEB_TO_MONO[p, i] * cheb[p, q]
            tmp[i, q] = acc
    for i in range(d1):
        for j in range(d1):
            acc = 0.0
            for q in range(j, d1):
                acc += tmp[i, q] * _CHEB_TO_MONO[q, j]
            idx = i * d1 + j
            out[idx // 3, idx % 3] = acc


@jit_alloc
def _far_values(quad, f, n, cell, near, n_near):
    """E of the edges far from a grid cell ``cell`` (``(x0, y0, width)``) at
    its Chebyshev points: the exact sum less its ``n_near`` near edges."""
    d1 = _DEGREE + 1
    x0, y0, w = cell
    half = 0.5 * w
    vals = np.empty((d1, d1))
    for a in range(d1):
        rx = x0 + half + half * _NODES[a]
        for b in range(d1):
            ry = y0 + half + half * _NODES[b]
            e = _support_sum(quad, rx, ry)[0]
            for m in range(n_near):
                e -= _near_edge_terms(quad, f, n, near[m], rx, ry)[0]
            vals[a, b] = e
    return vals


@jit_alloc
def _child_far_values(quad, f, n, cell, near, n_near, parent, parent_cell, parent_near):
    """``_far_values`` of a split cell's child: its parent's polynomial
    ``parent`` (valid over the parent cell ``parent_cell``, whose far edges
    are the child's too) plus the edges near the parent (``parent_near``)
    but not near the child (``near``, a sublist in the same order)."""
    d1 = _DEGREE + 1
    x0, y0, w = cell
    half = 0.5 * w
    px0, py0, pw = parent_cell
    vals = np.empty((d1, d1))
    for a in range(d1):
        rx = x0 + half + half * _NODES[a]
        for b in range(d1):
            ry = y0 + half + half * _NODES[b]
            e = _poly_value(parent, (rx - px0 - 0.5 * pw) * 2.0 / pw, (ry - py0 - 0.5 * pw) * 2.0 / pw)
            k = 0
            for m in range(parent_near.shape[0]):
                edge = parent_near[m]
                if k < n_near and near[k] == edge:
                    k += 1
                else:
                    e += _near_edge_terms(quad, f, n, edge, rx, ry)[0]
            vals[a, b] = e
    return vals


@jit
def _near_edges(quad, f, n, candidates, n_cand, x0, y0, h, near):
    """Write into ``near`` (in order) the edges among the first ``n_cand`` of
    ``candidates`` within ``_NEAR`` cell widths of the cell ``[x0, x0 + h] x
    [y0, y0 + h]``; return their number."""
    m = 0
    reach = _NEAR * h
    for c in range(n_cand):
        e = candidates[c]
        e2 = e + 1 if e + 1 < n else 0
        if _segment_box_distance(quad[f + e, 0], quad[f + e, 1], quad[f + e2, 0],
                                 quad[f + e2, 1], x0, y0, x0 + h, y0 + h) < reach:
            near[m] = e
            m += 1
    return m


@jit_parallel
def _top_cells(quad, f, n, every, n_every, r_grid, n_grid, skip_inside):
    """Near edges and far values of every top-level cell of one grid, the
    cells in parallel (each on its own; the costly part of a table: the far
    sum at each Chebyshev point runs over every edge).

    Returns
    -------
    (near, count, vals)
        Per cell ``i n_grid + j``: its near edges (``near[c, :count[c]]``,
        ``_near_edges``) and ``_far_values`` (``vals[c]``); a cell inside
        ``skip_inside`` has count -1.
    """
    h = 2.0 * r_grid / n_grid
    d1 = _DEGREE + 1
    n_cells = n_grid * n_grid
    near = np.empty((n_cells, max(n, 1)), dtype=np.int64)
    count = np.full(n_cells, -1, dtype=np.int64)
    vals = np.empty((n_cells, d1, d1))
    for c in prange(n_cells):
        x0, y0 = -r_grid + (c // n_grid) * h, -r_grid + (c % n_grid) * h
        if (skip_inside > 0.0 and x0 >= -skip_inside and x0 + h <= skip_inside
                and y0 >= -skip_inside and y0 + h <= skip_inside):
            continue
        m = _near_edges(quad, f, n, every, n_every, x0, y0, h, near[c])
        count[c] = m
        vals[c] = _far_values(quad, f, n, (x0, y0, h), near[c], m)
    return near, count, vals


@jit_alloc
def _grid_cells(quad, f, n, twin, r_grid, n_grid, top, cells, coefs, nears):
    """Fit every cell of one grid, splitting a cell with more than
    ``_SPLIT_NEAR`` near edges into four (down to ``_MAX_SPLIT`` times);
    append to the lists ``cells`` (index rows: a leaf's block, near count and
    list, ``(-2, first child, 0)`` for a split cell, ``(-1, 0, 0)`` unused),
    ``coefs`` (coefficient blocks) and ``nears`` (near-edge lists).

    A child's far part is its parent's polynomial plus the few edges near
    the parent but not near it (``_child_far_values``), so splitting costs the
    parent's near edges per point, not all of them. ``top`` is
    ``_top_cells`` of the grid (its top-level cells' near edges and far
    values, computed in parallel); the order of the cells, and so the
    table, is the serial one."""
    h = 2.0 * r_grid / n_grid
    rows_per_cell = (_DEGREE + 1) * (_DEGREE + 1) // 3
    every = np.empty(n, dtype=np.int64)
    n_every = 0
    for e in range(n):
        if not twin[e]:
            every[n_every] = e
            n_every += 1
    first = len(cells)
    top_near, top_count, top_vals = top
    # Split cells kept while their children are fitted: block, geometry, near list.
    parents = [np.empty((1, 3))]
    parents.pop()
    parent_geom = [(0.0, 0.0, 0.0)]
    parent_geom.pop()
    parent_near = [np.empty(1, dtype=np.int64)]
    parent_near.pop()
    # Pending cells: (row in cells, x0, y0, width, times split, parent or -1).
    stack = [(0, 0.0, 0.0, 0.0, 0, 0)]
    stack.pop()
    for i in range(n_grid):
        for j in range(n_grid):
            cells.append((-1.0, 0.0, 0.0))
            x0, y0 = -r_grid + i * h, -r_grid + j * h
            if top_count[i * n_grid + j] >= 0:
                stack.append((first + i * n_grid + j, x0, y0, h, 0, -1))
    near = np.empty(n, dtype=np.int64)
    while len(stack) > 0:
        row, x0, y0, w, depth, par = stack.pop()
        if par < 0:
            k_top = row - first
            m = top_count[k_top]
            near[:m] = top_near[k_top, :m]
            vals = top_vals[k_top]
        else:
            pn = parent_near[par]
            m = _near_edges(quad, f, n, pn, pn.shape[0], x0, y0, w, near)
            vals = _child_far_values(quad, f, n, (x0, y0, w), near, m, parents[par], parent_geom[par], pn)
        block = np.empty((rows_per_cell, 3))
        _fit(vals, block)
        if m > _SPLIT_NEAR and depth < _MAX_SPLIT:
            parents.append(block)
            parent_geom.append((x0, y0, w))
            parent_near.append(near[:m].copy())
            me = len(parents) - 1
            child = len(cells)
            cells[row] = (-2.0, float(child), 0.0)
            half = 0.5 * w
            for c in range(4):
                cells.append((-1.0, 0.0, 0.0))
                stack.append((child + c, x0 + half * (c // 2), y0 + half * (c % 2), half, depth + 1, me))
            continue
        coefs.append(block)
        nears.append(near[:m].copy())
        cells[row] = (float(len(coefs) - 1), float(m), float(len(nears) - 1))


def _with_table(quad):
    """``quad`` with the support table of its material appended (module notes).

    Returns a new array; ``_has_table`` is then true and ``support._power``
    reads the table instead of summing every edge. A Python function: the
    top-level cells of both grids are computed by ``_top_cells`` over the
    cores (called from Python, as a parallel kernel called from a cached
    serial one can crash when loaded from Numba's cache, a known Numba bug),
    then ``_table_from`` builds the table serially.
    """
    f, n = _table_sizes(quad)
    twin = _twin_edges(quad)
    every = np.flatnonzero(~twin).astype(np.int64)
    inner = _top_cells(quad, f, n, every, every.size, _R_INNER, _N_INNER, 0.0)
    outer = _top_cells(quad, f, n, every, every.size, _R_OUTER, _N_OUTER, _R_INNER)
    return _table_from(quad, twin, inner, outer)


@jit_alloc
def _table_from(quad, twin, inner, outer):
    """The table of ``_with_table`` from the top-level cells of the inner and
    outer grids (``_top_cells``)."""
    f, n = _table_sizes(quad)
    cells = [(0.0, 0.0, 0.0)]
    cells.pop()
    coefs = [np.empty((1, 3))]
    coefs.pop()
    nears = [np.empty(1, dtype=np.int64)]
    nears.pop()
    _grid_cells(quad, f, n, twin, _R_INNER, _N_INNER, inner, cells, coefs, nears)
    outer_first = len(cells)
    _grid_cells(quad, f, n, twin, _R_OUTER, _N_OUTER, outer, cells, coefs, nears)
    mom_re, mom_im = _moments(quad, _ORDER + 2)
    m1 = _ORDER + 3
    rows_per_cell = (_DEGREE + 1) * (_DEGREE + 1) // 3
    n_cells = len(cells)
    near_rows = 0
    for lst in nears:
        near_rows += (lst.shape[0] + 2) // 3
    mom_off = _HEADER
    cell_off = mom_off + m1 * m1
    coef_off = cell_off + n_cells
    near_off = coef_off + len(coefs) * rows_per_cell
    size = near_off + near_rows
    start = f + 2 * n
    out = np.zeros((start + size + 1, 3))
    out[:start] = quad[:start]
    t = out[start:start + size]
    t[0, 0], t[0, 1], t[0, 2] = _R_INNER, _N_INNER, _DEGREE
    t[1, 0], t[1, 1], t[1, 2] = _R_OUTER, _N_OUTER, _ORDER
    t[2, 0], t[2, 1], t[2, 2] = cell_off, mom_off, outer_first
    for j in range(m1):
        for k in range(m1):
            t[mom_off + j * m1 + k, 0] = mom_re[j, k]
            t[mom_off + j * m1 + k, 1] = mom_im[j, k]
    for b in range(len(coefs)):
        t[coef_off + b * rows_per_cell:coef_off + (b + 1) * rows_per_cell] = coefs[b]
    near_start = np.empty(len(nears), dtype=np.int64)
    r = near_off
    for b in range(len(nears)):
        near_start[b] = r
        lst = nears[b]
        for m in range(lst.shape[0]):
            t[r + m // 3, m % 3] = lst[m]
        r += (lst.shape[0] + 2) // 3
    for c in range(n_cells):
        blk, cnt, lst = cells[c]
        if blk < 0.0:
            t[cell_off + c, 0] = blk
            t[cell_off + c, 1] = cnt
        else:
            t[cell_off + c, 0] = coef_off + blk * rows_per_cell
            t[cell_off + c, 1] = cnt
            t[cell_off + c, 2] = near_start[int(lst)]
    out[start + size, 0] = f
    out[start + size, 1] = n
    out[start + size, 2] = size
    return out


@jit
def _table_support(quad, rx, ry):
    """E(r), G(r), N(r) from the table of ``quad`` (``_with_table``), as
    ``edge_integrals._support_sum`` returns them; the exact sum outside the
    tabulated squares.

    Returns ``(E, Gx, Gy, Nxx, Nxy, Nyy)``.
    """
    f, n = _table_sizes(quad)
    t0 = f + 2 * n
    r_in, n_in = quad[t0, 0], int(quad[t0, 1])
    r_out, n_out = quad[t0 + 1, 0], int(quad[t0 + 1, 1])
    cell_off = int(quad[t0 + 2, 0])
    if abs(rx) < r_in and abs(ry) < r_in:
        r_grid, n_grid, base = r_in, n_in, 0
    elif abs(rx) < r_out and abs(ry) < r_out:
        r_grid, n_grid, base = r_out, n_out, int(quad[t0 + 2, 2])
    else:
        return _support_sum(quad, rx, ry)
    h = 2.0 * r_grid / n_grid
    i = min(n_grid - 1, max(0, int((rx + r_grid) / h)))
    j = min(n_grid - 1, max(0, int((ry + r_grid) / h)))
    row = t0 + cell_off + base + i * n_grid + j
    xc, yc = -r_grid + (i + 0.5) * h, -r_grid + (j + 0.5) * h
    coef = quad[row, 0]
    while coef == -2.0:  # a split cell: its quadrant holding r
        h *= 0.5
        ix = 1 if rx >= xc else 0
        iy = 1 if ry >= yc else 0
        xc += (ix - 0.5) * h
        yc += (iy - 0.5) * h
        row = t0 + cell_off + int(quad[row, 1]) + 2 * ix + iy
        coef = quad[row, 0]
    if coef < 0.0:  # an outer cell inside the inner square (not reached)
        return _support_sum(quad, rx, ry)
    n_near, near = int(quad[row, 1]), t0 + int(quad[row, 2])
    cb = t0 + int(coef)
    s = 2.0 / h
    xl = (rx - xc) * s
    yl = (ry - yc) * s
    d1 = _DEGREE + 1
    # x^i and y^j with their first and second derivatives, carried along.
    f0 = fx = fxx = gy = gxy = hyy = 0.0
    xp, xd, xdd = 1.0, 0.0, 0.0
    for ii in range(d1):
        r0 = r1 = r2 = 0.0
        yp, yd, ydd = 1.0, 0.0, 0.0
        base = ii * d1
        for jj in range(d1):
            idx = base + jj
            c = quad[cb + idx // 3, idx % 3]
            r0 += c * yp
            r1 += c * yd
            r2 += c * ydd
            ydd = (jj + 1.0) * yd
            yd = (jj + 1.0) * yp
            yp *= yl
        f0 += xp * r0
        fx += xd * r0
        fxx += xdd * r0
        gy += xp * r1
        gxy += xd * r1
        hyy += xp * r2
        xdd = (ii + 1.0) * xd
        xd = (ii + 1.0) * xp
        xp *= xl
    ex, ey = fx * s, gy * s
    exx, exy, eyy = fxx * s * s, gxy * s * s, hyy * s * s
    e_val = f0
    gxs, gys = -ex, -ey
    nxx, nxy, nyy = eyy, -exy, exx
    for m in range(n_near):
        edge = int(quad[near + m // 3, m % 3])
        a0, a1, a2, a3, a4, a5 = _near_edge_terms(quad, f, n, edge, rx, ry)
        e_val += a0
        gxs += a1
        gys += a2
        nxx += a3
        nxy += a4
        nyy += a5
    return e_val, gxs, gys, nxx, nxy, nyy


@jit
def _moment_power(quad, area, vx, vy, om):
    """Belt power, its gradient and Hessian in the twist (``support._power``'s
    ten values) for a centre of rotation beyond ``support._R_FAR``, from the
    complex moments of the table (module notes).

    Notes
    -----
    With ``V = |v|``, ``vh = v / V``, ``beta = i omega / v`` and the sums
    ``S[alpha, gamma; s, t] = sum_{j+k<=K} binom(alpha, j) binom(gamma, k)
    beta^j conj(beta)^k M_{j+s, k+t}``::

        P           = V / A  Re S[1/2, 1/2; 0, 0]
        gx + i gy   = vh / A  S[1/2, -1/2; 0, 0]         (integral of u/|u|)
        g_omega     = Im(vh S[1/2, -1/2; 0, 1]) / A      (integral of Im(conj(w) u)/|u|)

    and the Hessian ``integral (1/|u|) a a^T`` with ``a = (Re p, Im p,
    Im(conj(w) p))``, ``p = i u / |u|`` (``support._point_power``), written
    with ``|p| = 1`` through ``I = integral {1, conj(w), |w|^2} / |u|`` (series
    ``S[-1/2, -1/2]`` over V) and ``J = integral {1, conj(w), conj(w)^2} p^2
    / |u|`` (``p^2 / |u| = -(vh^2 / V) (1 + beta w)^(1/2) (1 + conj(beta
    w))^(-3/2)``, series ``S[1/2, -3/2]``).
    """
    f, n = _table_sizes(quad)
    t0 = f + 2 * n
    order = int(quad[t0 + 1, 2])
    mom = t0 + int(quad[t0 + 2, 1])
    m1 = order + 3
    vv = math.sqrt(vx * vx + vy * vy)
    hr, hi = vx / vv, vy / vv
    br, bi = om * vy / (vv * vv), om * vx / (vv * vv)
    # Accumulators (complex): P, S1, S2, I0, Iw, Iww, J0, Jw, Jww.
    sp_r = s1_r = s1_i = s2_r = s2_i = 0.0
    i0 = iw_r = iw_i = iww = 0.0
    j0_r = j0_i = jw_r = jw_i = jww_r = jww_i = 0.0
    pj_r, pj_i = 1.0, 0.0  # beta^j
    for j in range(order + 1):
        pk_r, pk_i = pj_r, pj_i  # beta^j conj(beta)^k
        for k in range(order + 1 - j):
            row = mom + j * m1 + k
            m_r, m_i = quad[row, 0], quad[row, 1]
            m1_r, m1_i = quad[row + 1, 0], quad[row + 1, 1]  # M_{j, k+1}
            m2_r, m2_i = quad[row + 2, 0], quad[row + 2, 1]  # M_{j, k+2}
            mw_r, mw_i = quad[row + m1 + 1, 0], quad[row + m1 + 1, 1]  # M_{j+1, k+1}
            # products with beta^j conj(beta)^k
            a_r, a_i = pk_r * m_r - pk_i * m_i, pk_r * m_i + pk_i * m_r
            b_r, b_i = pk_r * m1_r - pk_i * m1_i, pk_r * m1_i + pk_i * m1_r
            c_r, c_i = pk_r * m2_r - pk_i * m2_i, pk_r * m2_i + pk_i * m2_r
            w_r = pk_r * mw_r - pk_i * mw_i
            hh = _B_HALF[j] * _B_HALF[k]
            hm = _B_HALF[j] * _B_MHALF[k]
            mm = _B_MHALF[j] * _B_MHALF[k]
            h3 = _B_HALF[j] * _B_M3HALF[k]
            sp_r += hh * a_r
            s1_r += hm * a_r
            s1_i += hm * a_i
            s2_r += hm * b_r
            s2_i += hm * b_i
            i0 += mm * a_r
            iw_r += mm * b_r
            iw_i += mm * b_i
            iww += mm * w_r
            j0_r += h3 * a_r
            j0_i += h3 * a_i
            jw_r += h3 * b_r
            jw_i += h3 * b_i
            jww_r += h3 * c_r
            jww_i += h3 * c_i
            # times conj(beta)
            pk_r, pk_i = pk_r * br + pk_i * bi, pk_i * br - pk_r * bi
        pj_r, pj_i = pj_r * br - pj_i * bi, pj_r * bi + pj_i * br
    inv_a = 1.0 / area
    p_val = vv * sp_r * inv_a
    g0 = (hr * s1_r - hi * s1_i) * inv_a
    g1 = (hr * s1_i + hi * s1_r) * inv_a
    g2 = (hr * s2_i + hi * s2_r) * inv_a
    k = inv_a / vv
    # -vh^2 times J sums
    q_r, q_i = -(hr * hr - hi * hi), -2.0 * hr * hi
    J0r, J0i = q_r * j0_r - q_i * j0_i, q_r * j0_i + q_i * j0_r
    Jwr, Jwi = q_r * jw_r - q_i * jw_i, q_r * jw_i + q_i * jw_r
    Jwwr = q_r * jww_r - q_i * jww_i
    h00 = 0.5 * k * (i0 + J0r)
    h11 = 0.5 * k * (i0 - J0r)
    h01 = 0.5 * k * J0i
    h02 = 0.5 * k * (Jwi + iw_i)
    h12 = 0.5 * k * (iw_r - Jwr)
    h22 = 0.5 * k * (iww - Jwwr)
    return p_val, g0, g1, g2, h00, h01, h02, h11, h12, h22
