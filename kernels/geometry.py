"""Polygon geometry kernels: checks, normalisation, hull, stable edges, pin contact.

Conventions (spec section 1): vertices are an ``(n, 2)`` float64 array; a
normalised part is counter-clockwise with its area centroid at the origin.
Contact features are encoded as ``(kind, index)`` with ``kind`` ``EDGE`` (edge
``j`` runs from vertex ``j`` to vertex ``j + 1``) or ``VERTEX``.
"""
import math

import numpy as np

from ._numba import jit, jit_alloc

EDGE = 0
VERTEX = 1

# Validation codes returned by ``_polygon_problem`` (0 = fine); the Python
# wrapper ``pipeline.parts`` turns them into messages.
POLY_OK = 0
POLY_TOO_FEW = 1
POLY_NOT_FINITE = 2
POLY_REPEATED = 3
POLY_SELF_INTERSECTING = 4
POLY_ZERO_AREA = 5
# Codes of ``_loops_problem`` (an outline and its holes).
LOOPS_OK = 0
LOOPS_MEET = 1
HOLE_OUTSIDE = 2
HOLE_IN_HOLE = 3


@jit
def _signed_area(xy):
    """Shoelace signed area: positive for counter-clockwise vertices."""
    n = xy.shape[0]
    s = 0.0
    for j in range(n):
        k = (j + 1) % n
        s += xy[j, 0] * xy[k, 1] - xy[k, 0] * xy[j, 1]
    return 0.5 * s


@jit
def _segments_cross(ax, ay, bx, by, cx, cy, dx, dy):
    """True if closed segments ab and cd share a point (collinear overlap included)."""
    d1 = (dx - cx) * (ay - cy) - (dy - cy) * (ax - cx)
    d2 = (dx - cx) * (by - cy) - (dy - cy) * (bx - cx)
    d3 = (bx - ax) * (cy - ay) - (by - ay) * (cx - ax)
    d4 = (bx - ax) * (dy - ay) - (by - ay) * (dx - ax)
    if ((d1 > 0 and d2 < 0) or (d1 < 0 and d2 > 0)) and ((d3 > 0 and d4 < 0) or (d3 < 0 and d4 > 0)):
        return True
    # Touching or collinear cases: a point lying on the other segment.
    if d1 == 0 and min(cx, dx) <= ax <= max(cx, dx) and min(cy, dy) <= ay <= max(cy, dy):
        return True
    if d2 == 0 and min(cx, dx) <= bx <= max(cx, dx) and min(cy, dy) <= by <= max(cy, dy):
        return True
    if d3 == 0 and min(ax, bx) <= cx <= max(ax, bx) and min(ay, by) <= cy <= max(ay, by):
        return True
    if d4 == 0 and min(ax, bx) <= dx <= max(ax, bx) and min(ay, by) <= dy <= max(ay, by):
        return True
    return False


@jit
def _polygon_problem(xy):
    """Return a validation code for a vertex list (``POLY_OK`` if it is a simple polygon).

    Returns ``(code, j, k)``: the offending vertex or edge indices where useful.
    """
    n = xy.shape[0]
    if n < 3:
        return POLY_TOO_FEW, n, -1
    for j in range(n):
        if not (math.isfinite(xy[j, 0]) and math.isfinite(xy[j, 1])):
            return POLY_NOT_FINITE, j, -1
    for j in range(n):
        for k in range(j + 1, n):
            if xy[j, 0] == xy[k, 0] and xy[j, 1] == xy[k, 1]:
                return POLY_REPEATED, j, k
    scale = 0.0
    for j in range(n):
        scale = max(scale, abs(xy[j, 0]), abs(xy[j, 1]))
    # All vertices on one line: zero area (before the crossing tests, which
    # would call the overlapping edges of such a sliver "crossing").
    collinear = True
    for j in range(2, n):
        cr = ((xy[1, 0] - xy[0, 0]) * (xy[j, 1] - xy[0, 1])
              - (xy[1, 1] - xy[0, 1]) * (xy[j, 0] - xy[0, 0]))
        if abs(cr) > 1e-12 * scale * scale:
            collinear = False
            break
    if collinear:
        return POLY_ZERO_AREA, -1, -1
    # Non-adjacent edges must not meet (O(n^2): parts have few vertices).
    for j in range(n):
        j1 = (j + 1) % n
        for k in range(j + 1, n):
            k1 = (k + 1) % n
            if k == j1 or j == k1:
                continue
            if _segments_cross(xy[j, 0], xy[j, 1], xy[j1, 0], xy[j1, 1],
                               xy[k, 0], xy[k, 1], xy[k1, 0], xy[k1, 1]):
                return POLY_SELF_INTERSECTING, j, k
    # Adjacent edges folding back onto each other also self-intersect.
    for j in range(n):
        i = (j - 1 + n) % n
        k = (j + 1) % n
        ux, uy = xy[i, 0] - xy[j, 0], xy[i, 1] - xy[j, 1]
        vx, vy = xy[k, 0] - xy[j, 0], xy[k, 1] - xy[j, 1]
        if ux * vy - uy * vx == 0.0 and ux * vx + uy * vy > 0.0:
            return POLY_SELF_INTERSECTING, i, j
    if abs(_signed_area(xy)) <= 1e-12 * scale * scale:
        return POLY_ZERO_AREA, -1, -1
    return POLY_OK, -1, -1


@jit
def _centroid(xy):
    """Area centroid ``(cx, cy)`` and signed area of a simple polygon."""
    n = xy.shape[0]
    # Shift by the first vertex to keep the sums well conditioned.
    ox, oy = xy[0, 0], xy[0, 1]
    a2 = 0.0
    sx = 0.0
    sy = 0.0
    for j in range(n):
        k = (j + 1) % n
        x0, y0 = xy[j, 0] - ox, xy[j, 1] - oy
        x1, y1 = xy[k, 0] - ox, xy[k, 1] - oy
        cr = x0 * y1 - x1 * y0
        a2 += cr
        sx += (x0 + x1) * cr
        sy += (y0 + y1) * cr
    return ox + sx / (3.0 * a2), oy + sy / (3.0 * a2), 0.5 * a2


@jit_alloc
def _normalise(xy):
    """Counter-clockwise copy of ``xy`` with the area centroid at the origin.

    Returns ``(verts, area, a)`` where ``a`` is the largest centroid-vertex distance.
    """
    n = xy.shape[0]
    cx, cy, area = _centroid(xy)
    out = np.empty((n, 2))
    for j in range(n):
        src = j if area > 0 else n - 1 - j
        out[j, 0] = xy[src, 0] - cx
        out[j, 1] = xy[src, 1] - cy
    a = 0.0
    for j in range(n):
        a = max(a, math.hypot(out[j, 0], out[j, 1]))
    return out, abs(area), a


@jit_alloc
def _keyhole(xy, starts):
    """One closed polygon whose signed edges bound the material of a part
    with holes: the outline, then each hole, joined by bridges.

    Parameters
    ----------
    xy : ``(N, 2)`` vertices of the loops, one after the other: the outline
        first (counter-clockwise), then the holes (clockwise).
    starts : ``(L + 1,)`` int64 offsets of the loops in ``xy`` (the last one
        ``N``).

    Returns
    -------
    ``(N + 2 (L - 1), 2)`` array: the outline, then for each hole the
    outline's first vertex, the hole's vertices and the hole's first vertex
    again; closing the polygon returns to the outline's first vertex.

    Notes
    -----
    Every integral here is a signed sum over edges (module notes), so a
    bridge, walked once each way, cancels (to rounding) wherever it runs,
    even across another hole: the sum is the outline's integral minus the
    holes'. With one loop the result is ``xy`` itself.
    """
    loops = starts.shape[0] - 1
    n_out = starts[1] - starts[0]
    total = n_out
    for k in range(1, loops):
        total += starts[k + 1] - starts[k] + 2
    out = np.empty((total, 2))
    m = 0
    for j in range(starts[0], starts[1]):
        out[m, 0], out[m, 1] = xy[j, 0], xy[j, 1]
        m += 1
    for k in range(1, loops):
        out[m, 0], out[m, 1] = xy[starts[0], 0], xy[starts[0], 1]
        m += 1
        for j in range(starts[k], starts[k + 1]):
            out[m, 0], out[m, 1] = xy[j, 0], xy[j, 1]
            m += 1
        out[m, 0], out[m, 1] = xy[starts[k], 0], xy[starts[k], 1]
        m += 1
    return out


@jit_alloc
def _normalise_loops(xy, starts):
    """Outline and holes oriented and centred on the material's area centroid.

    Parameters
    ----------
    xy, starts : the loops, one after the other (the outline first), and
        their int64 offsets (see ``_keyhole``); any winding.

    Returns
    -------
    ``(loops, area, a)``: ``xy`` with the outline counter-clockwise and the
    holes clockwise (material on the left of every edge), minus the area
    centroid of the material (outline minus holes); the material's area;
    the largest centroid-vertex distance (an outline vertex: the material
    lies inside the outline).
    """
    n_loops = starts.shape[0] - 1
    out = np.empty_like(xy)
    for k in range(n_loops):
        lo, hi = starts[k], starts[k + 1]
        flip = (_signed_area(xy[lo:hi]) > 0.0) != (k == 0)
        for j in range(lo, hi):
            src = hi - 1 - (j - lo) if flip else j
            out[j, 0], out[j, 1] = xy[src, 0], xy[src, 1]
    cx, cy, area = _centroid(_keyhole(out, starts))
    a = 0.0
    for j in range(xy.shape[0]):
        out[j, 0] -= cx
        out[j, 1] -= cy
    for j in range(starts[0], starts[1]):
        a = max(a, math.hypot(out[j, 0], out[j, 1]))
    return out, area, a


@jit
def _loops_problem(xy, starts):
    """Whether the holes lie strictly inside the outline and apart.

    ``xy``, ``starts`` as for ``_keyhole`` (each loop already a simple
    polygon). Returns ``(code, k, l)``: ``LOOPS_OK``; ``LOOPS_MEET`` when an
    edge of loop ``k`` meets one of loop ``l`` (crossing or touching);
    ``HOLE_OUTSIDE`` when hole ``k`` lies outside the outline; ``HOLE_IN_HOLE``
    when hole ``k`` lies inside hole ``l`` (an island). Loop 0 is the outline.
    """
    n_loops = starts.shape[0] - 1
    for k in range(n_loops):
        for l in range(k + 1, n_loops):
            for i in range(starts[k], starts[k + 1]):
                i1 = i + 1 if i + 1 < starts[k + 1] else starts[k]
                for j in range(starts[l], starts[l + 1]):
                    j1 = j + 1 if j + 1 < starts[l + 1] else starts[l]
                    if _segments_cross(xy[i, 0], xy[i, 1], xy[i1, 0], xy[i1, 1],
                                       xy[j, 0], xy[j, 1], xy[j1, 0], xy[j1, 1]):
                        return LOOPS_MEET, k, l
    for k in range(1, n_loops):
        px, py = xy[starts[k], 0], xy[starts[k], 1]
        if not _point_inside(xy, starts[0], starts[1], px, py):
            return HOLE_OUTSIDE, k, 0
        for l in range(1, n_loops):
            if l != k and _point_inside(xy, starts[l], starts[l + 1], px, py):
                return HOLE_IN_HOLE, k, l
    return LOOPS_OK, -1, -1


@jit
def _point_inside(xy, lo, hi, px, py):
    """Even-odd rule: whether ``(px, py)`` lies inside the loop ``xy[lo:hi]``."""
    inside = False
    j = hi - 1
    for i in range(lo, hi):
        yi, yj = xy[i, 1], xy[j, 1]
        if (yi > py) != (yj > py):
            xc = xy[i, 0] + (py - yi) * (xy[j, 0] - xy[i, 0]) / (yj - yi)
            if px < xc:
                inside = not inside
        j = i
    return inside


@jit
def _is_convex(verts):
    """True if a counter-clockwise polygon has no reflex vertex."""
    n = verts.shape[0]
    for j in range(n):
        i = (j - 1 + n) % n
        k = (j + 1) % n
        cr = ((verts[j, 0] - verts[i, 0]) * (verts[k, 1] - verts[j, 1])
              - (verts[j, 1] - verts[i, 1]) * (verts[k, 0] - verts[j, 0]))
        if cr < 0.0:
            return False
    return True


@jit
def _cross_o(verts, o, a, b):
    return ((verts[a, 0] - verts[o, 0]) * (verts[b, 1] - verts[o, 1])
            - (verts[a, 1] - verts[o, 1]) * (verts[b, 0] - verts[o, 0]))


@jit_alloc
def _convex_hull(verts):
    """Indices of the convex hull vertices, counter-clockwise (Andrew's monotone chain).

    Collinear points on hull edges are dropped, so every hull edge is maximal.
    """
    n = verts.shape[0]
    order = np.arange(n)
    for j in range(1, n):  # insertion sort by (x, y): parts have few vertices
        k = j
        while k > 0:
            a, b = order[k - 1], order[k]
            if verts[a, 0] > verts[b, 0] or (verts[a, 0] == verts[b, 0] and verts[a, 1] > verts[b, 1]):
                order[k - 1], order[k] = b, a
                k -= 1
            else:
                break
    hull = np.empty(2 * n, dtype=np.int64)
    m = 0
    for p in range(n):  # lower hull
        while m >= 2 and _cross_o(verts, hull[m - 2], hull[m - 1], order[p]) <= 0.0:
            m -= 1
        hull[m] = order[p]
        m += 1
    lower = m + 1
    for p in range(n - 2, -1, -1):  # upper hull
        while m >= lower and _cross_o(verts, hull[m - 2], hull[m - 1], order[p]) <= 0.0:
            m -= 1
        hull[m] = order[p]
        m += 1
    return hull[: m - 1].copy()


@jit_alloc
def _stable_edges(verts):
    """Stable resting edges against a fence (spec section 6).

    A hull edge is stable when the centroid (origin) projects strictly inside
    it. Returns an ``(m, 5)`` array of rows ``(i, j, theta, y_c, t)``: hull
    vertex indices of the edge, the orientation (radians, [0, 2 pi)) that puts
    the edge on the fence ``y = 0`` with the part on the ``+y`` side, the
    centroid's height above the fence, and where along the edge (0..1) the
    centroid projects.
    """
    hull = _convex_hull(verts)
    h = hull.shape[0]
    out = np.empty((h, 5))
    m = 0
    for p in range(h):
        i, j = hull[p], hull[(p + 1) % h]
        ex, ey = verts[j, 0] - verts[i, 0], verts[j, 1] - verts[i, 1]
        length = math.hypot(ex, ey)
        t = -(verts[i, 0] * ex + verts[i, 1] * ey) / (length * length)
        if t <= 1e-12 or t >= 1.0 - 1e-12:
            continue
        # Rotate so the edge direction (CCW, interior on its left) becomes +x:
        # the interior then lies on +y, i.e. the part rests on the fence below it.
        theta = -math.atan2(ey, ex)
        theta = theta % (2.0 * math.pi)
        yc = (verts[i, 0] * ey - verts[i, 1] * ex) / length  # distance centroid -> edge line
        out[m, 0] = i
        out[m, 1] = j
        out[m, 2] = theta
        out[m, 3] = abs(yc)
        out[m, 4] = t
        m += 1
    return out[:m].copy()


@jit
def _closest_on_segment(verts, j, qx, qy):
    """Closest point of edge ``j`` to ``q``: ``(px, py, t, length)`` with ``t`` in [0, length]."""
    n = verts.shape[0]
    k = (j + 1) % n
    ex, ey = verts[k, 0] - verts[j, 0], verts[k, 1] - verts[j, 1]
    length = math.hypot(ex, ey)
    ex /= length
    ey /= length
    t = (qx - verts[j, 0]) * ex + (qy - verts[j, 1]) * ey
    t = min(max(t, 0.0), length)
    return verts[j, 0] + t * ex, verts[j, 1] + t * ey, t, length


@jit
def _closest_feature(verts, qx, qy):
    """Closest boundary feature to the point ``q`` (a pin axis).

    Returns ``(kind, index, distance, cx, cy, nx, ny)``: the feature, the
    distance from ``q`` to the polygon boundary, the closest point ``c`` and the
    unit contact normal ``n`` pointing from ``q`` into the part (spec section 3).
    A closest point within ``1e-12`` (relative) of an edge end is a vertex.
    """
    n = verts.shape[0]
    best = np.inf
    bj = 0
    bt = 0.0
    bl = 1.0
    bx = 0.0
    by = 0.0
    for j in range(n):
        px, py, t, length = _closest_on_segment(verts, j, qx, qy)
        dist = math.hypot(qx - px, qy - py)
        if dist < best:
            best, bj, bt, bl, bx, by = dist, j, t, length, px, py
    tol = 1e-12 * bl
    if bt <= tol:
        kind, idx = VERTEX, bj
    elif bt >= bl - tol:
        kind, idx = VERTEX, (bj + 1) % n
    else:
        kind, idx = EDGE, bj
    if kind == EDGE:
        k = (bj + 1) % n
        ex, ey = (verts[k, 0] - verts[bj, 0]) / bl, (verts[k, 1] - verts[bj, 1]) / bl
        nx, ny = -ey, ex  # inward normal of a CCW edge
    else:
        dx, dy = verts[idx, 0] - qx, verts[idx, 1] - qy
        dd = math.hypot(dx, dy)
        nx, ny = (dx / dd, dy / dd) if dd > 0 else (0.0, 0.0)
        bx, by = verts[idx, 0], verts[idx, 1]
    return kind, idx, best, bx, by, nx, ny


@jit
def _ray_first_contact(verts, qx, qy, wx, wy, r_pin, s_lo):
    """First ``s > s_lo`` at which a disc of radius ``r_pin`` centred at
    ``q + s w`` touches the polygon while approaching it.

    The set of disc centres touching the polygon is bounded by the outward
    offsets of the edges and circles around the vertices; only entering
    crossings count, so a pin that is leaving a contact is not caught again.
    Returns ``(s, kind, index)``, ``s = inf`` if the path misses the part.
    """
    n = verts.shape[0]
    ww = wx * wx + wy * wy
    best = np.inf
    kind = -1
    idx = -1
    for j in range(n):
        k = (j + 1) % n
        ex, ey = verts[k, 0] - verts[j, 0], verts[k, 1] - verts[j, 1]
        length = math.hypot(ex, ey)
        ex /= length
        ey /= length
        mx, my = ey, -ex  # outward normal
        wm = wx * mx + wy * my
        if wm < 0.0:
            s = (r_pin - ((qx - verts[j, 0]) * mx + (qy - verts[j, 1]) * my)) / wm
            if s_lo < s < best:
                t = (qx + s * wx - verts[j, 0]) * ex + (qy + s * wy - verts[j, 1]) * ey
                if 0.0 < t < length:
                    best, kind, idx = s, EDGE, j
        # Vertex circle: entering root of |q + s w - v|^2 = r^2.
        dx, dy = qx - verts[j, 0], qy - verts[j, 1]
        b = wx * dx + wy * dy
        c = dx * dx + dy * dy - r_pin * r_pin
        disc = b * b - ww * c
        if disc > 0.0 and b < 0.0:
            s = (-b - math.sqrt(disc)) / ww
            if s_lo < s < best:
                best, kind, idx = s, VERTEX, j
    return best, kind, idx


@jit
def _other_contact_gap(verts, qx, qy, cx, cy, r_pin, same_feature):
    """Smallest ``distance - r_pin`` from ``q`` to boundary points that are not
    the current contact ``c`` (closest points within ``same_feature`` of ``c``
    are the same feature). Negative means a second contact (a notch)."""
    n = verts.shape[0]
    gap = np.inf
    for j in range(n):
        if gap < np.inf:
            # An edge whose bounding box lies farther from q than the pin
            # plus the best gap so far cannot lower it: skip its exact
            # distance (the margin covers rounding, so the minimum is the
            # same, bit for bit; a rollout of a CAD outline calls this
            # hundreds of times).
            k = j + 1 if j + 1 < n else 0
            ax, ay, bx, by = verts[j, 0], verts[j, 1], verts[k, 0], verts[k, 1]
            dx = max(min(ax, bx) - qx, 0.0, qx - max(ax, bx))
            dy = max(min(ay, by) - qy, 0.0, qy - max(ay, by))
            reach = gap + r_pin
            if dx * dx + dy * dy > reach * reach * (1.0 + 1e-9):
                continue
        px, py, t, length = _closest_on_segment(verts, j, qx, qy)
        if _other_feature(px, py, cx, cy, same_feature):
            gap = min(gap, math.hypot(qx - px, qy - py) - r_pin)
    return gap


_SQUARED_SLACK = 1e-9  # a squared length this far (relative) from the limit decides without math.hypot
_SQUARED_FLOOR = 1e-290  # below this squared limit, math.hypot decides


@jit
def _other_feature(px, py, cx, cy, same_feature):
    """``math.hypot(px - cx, py - cy) > same_feature``, the same answer,
    from the squared distance unless that lies within ``_SQUARED_SLACK`` of
    the limit or the squared limit is below ``_SQUARED_FLOOR``, where a
    product's rounding among the subnormals is coarser than the slack
    (``hypot`` is a library call, several times a product)."""
    dx, dy = px - cx, py - cy
    limit = same_feature * same_feature
    if limit >= _SQUARED_FLOOR:
        d2 = dx * dx + dy * dy
        if d2 > limit * (1.0 + _SQUARED_SLACK):
            return True
        if d2 < limit * (1.0 - _SQUARED_SLACK):
            return False
    return math.hypot(dx, dy) > same_feature


# The near-edge cache of ``_cached_gap``: ``cache[0]`` the number of near
# edges (-1: empty; -2: they did not fit, measure every edge until the pin
# has moved ``GAP_NEAR_REACH``), ``cache[1:3]`` the pin centre it was made at,
# ``cache[3]`` a lower bound on the distance from there to every other edge,
# ``cache[4:]`` pairs: a near edge's index and its distance from there.
GAP_CACHE_HEAD = 4
GAP_NEAR_REACH = 0.03  # beyond the pin radius (units of the lengths), an edge is near
_GAP_MARGIN = 1e-9  # a bound must clear zero by this much per unit length (rounding)
_GAP_EXACT_REACH = 0.1  # an exact gap below this remakes the list to hold its edge (units of the lengths)


@jit
def _near_edges(verts, qx, qy, reach, cache):
    """Fill ``cache`` at the pin centre ``q``: the edges within ``reach`` of
    ``q`` and a lower bound on the distance of every other edge. Returns
    False (cache left empty) when the near edges do not fit."""
    n = verts.shape[0]
    room = (cache.shape[0] - GAP_CACHE_HEAD) // 2
    count = 0
    far = np.inf
    for j in range(n):
        k = j + 1 if j + 1 < n else 0
        ax, ay, bx, by = verts[j, 0], verts[j, 1], verts[k, 0], verts[k, 1]
        dx = max(min(ax, bx) - qx, 0.0, qx - max(ax, bx))
        dy = max(min(ay, by) - qy, 0.0, qy - max(ay, by))
        dist = math.sqrt(dx * dx + dy * dy)  # the bounding box: a lower bound
        if dist < reach:
            px, py, t, length = _closest_on_segment(verts, j, qx, qy)
            dist = math.hypot(qx - px, qy - py)
            if dist < reach:
                if count == room:
                    cache[0], cache[1], cache[2] = -2.0, qx, qy
                    return False
                cache[GAP_CACHE_HEAD + 2 * count] = j
                cache[GAP_CACHE_HEAD + 2 * count + 1] = dist
                count += 1
                continue
        far = min(far, dist)
    cache[0], cache[1], cache[2], cache[3] = count, qx, qy, far
    return True


@jit
def _cached_gap(verts, qx, qy, cx, cy, r_pin, same_feature, cache, exact):
    """``_other_contact_gap`` where it can matter, a positive lower bound of
    it elsewhere, from the near edges kept in ``cache``; with ``exact``,
    ``_other_contact_gap`` everywhere, bit for bit.

    Returns the exact gap (bit for bit) wherever it is at most zero;
    elsewhere a value in ``(0, gap]`` (the exact gap, or the bound of an edge
    left unmeasured): both then say "no second contact", and an event
    function needs the value only below zero. A caller that needs it above,
    to locate a crossing, asks for ``exact``: every near edge is then
    measured, and the minimum over them is the answer where the bound on the
    other edges clears it; elsewhere every edge is measured, and the list is
    made again there to hold the nearest other edge (the edges within ``gap
    + GAP_NEAR_REACH`` beyond the pin, for a gap under ``_GAP_EXACT_REACH``):
    the search's next points lie close by.

    Notes
    -----
    The distance from ``q`` to a segment is 1-Lipschitz in ``q``, so every
    edge not in the near list stays at least ``far - |q - q0|`` from ``q``,
    where ``far`` bounds their distances from the centre ``q0`` the list was
    made at. While that bound minus ``r_pin`` clears zero, only the near
    edges are measured; once it does not, the list is made again at ``q``
    (within ``r_pin + GAP_NEAR_REACH``, then tighter reaches if it does not
    fit; if none fits, every edge is measured until the pin has moved
    ``GAP_NEAR_REACH``). The margin by which a bound must clear zero (or
    the near minimum, with ``exact``) grows with the lengths it is made of,
    so rounding cannot flip it. The excluded contact feature only removes
    candidates, so the bound holds with it too. Only the decisions use
    ``sqrt`` of a sum of squares; every value returned below zero, and every
    value with ``exact``, comes from ``math.hypot`` as in
    ``_other_contact_gap``.
    """
    far = -np.inf
    moved = 0.0
    if cache[0] != -1.0:
        dx, dy = qx - cache[1], qy - cache[2]
        moved = math.sqrt(dx * dx + dy * dy)
        if cache[0] == -2.0 and moved < GAP_NEAR_REACH:
            return _other_contact_gap(verts, qx, qy, cx, cy, r_pin, same_feature)
        far = cache[3] - moved - r_pin
    margin = _GAP_MARGIN * (1.0 + r_pin + moved)
    if not (cache[0] >= 0.0 and far > margin):
        _remake_near(verts, qx, qy, r_pin, GAP_NEAR_REACH, cache)
        if cache[0] >= 0.0:
            far, moved, margin = cache[3] - r_pin, 0.0, _GAP_MARGIN * (1.0 + r_pin)
    if cache[0] >= 0.0 and far > margin:
        gap = np.inf if exact else far
        for m in range(int(cache[0])):
            j = int(cache[GAP_CACHE_HEAD + 2 * m])
            near = cache[GAP_CACHE_HEAD + 2 * m + 1] - moved - r_pin
            if near > margin and not exact:
                gap = min(gap, near)  # this edge, too, is still clear
                continue
            px, py, t, length = _closest_on_segment(verts, j, qx, qy)
            # The contact's own feature is left out first (the minimum is
            # the same, in any order).
            if _other_feature(px, py, cx, cy, same_feature):
                gap = min(gap, math.hypot(qx - px, qy - py) - r_pin)
        if not exact or gap < far - margin * (1.0 + abs(gap)):
            return gap
    gap = _other_contact_gap(verts, qx, qy, cx, cy, r_pin, same_feature)
    if exact and gap < _GAP_EXACT_REACH and cache[0] != -2.0:  # (-2: no list fitted here at the near reach)
        # A crossing's search evaluates the next points near this one: the
        # list made here holds the nearest other edge, so they can use it.
        _remake_near(verts, qx, qy, r_pin, max(gap, 0.0) + GAP_NEAR_REACH, cache)
    return gap


@jit
def _remake_near(verts, qx, qy, r_pin, reach, cache):
    """Make the near-edge list at ``q`` with edges within ``r_pin + reach``,
    or a quarter and a sixteenth of ``reach`` where they do not fit."""
    for _ in range(3):
        if _near_edges(verts, qx, qy, r_pin + reach, cache):
            return
        reach *= 0.25
