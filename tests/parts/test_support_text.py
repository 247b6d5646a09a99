"""Support text that pinfeed prints reads back: points on the material's
edge (where a fit often puts them) stay on the material once rounded to
the printed decimals."""
from __future__ import annotations

import numpy as np
from hypothesis import given
from hypothesis import strategies as st

from conftest import TRIANGLE, fewer_examples
from drawn_shapes import circle
from pipeline.parts.part import Part
from pipeline.parts.support import (PRINT_DECIMALS, _off_material, format_mm, on_print_grid,
                                    parse_support)


TRI = Part.from_vertices(TRIANGLE, "asym_triangle")
HOLED = Part.from_vertices(TRIANGLE, "tri-hole", holes=[circle(26.0, 9.0, 7.0, 16)])
SLIVER = Part.from_vertices([(0.0, 0.0), (60.0, 0.0), (60.0, 0.01)], "sliver")


def _on_edges(part, loop, t):
    """Points at fractions ``t`` along the edges of ``loop`` (part frame)."""
    v = np.asarray(loop, dtype=float)
    w = np.roll(v, -1, axis=0)
    k = np.arange(len(t)) % len(v)
    return v[k] + np.asarray(t)[:, None] * (w[k] - v[k])


@given(st.lists(st.floats(0.0, 1.0), min_size=1, max_size=12), st.sampled_from([TRI, HOLED, SLIVER]),
       st.booleans())
@fewer_examples(0.5)
def test_points_on_the_edge_print_to_text_that_reads_back(t, part, on_hole):
    loop = part.holes[0] if on_hole and part.holes else part.vertices
    xy = _on_edges(part, loop, t)
    assert _off_material(part, xy) is None  # the points are on the material (its edge)
    printed = on_print_grid(part, xy)
    assert _off_material(part, printed) is None
    assert np.all(np.abs(printed - xy) <= 1.000001 * 10.0 ** -PRINT_DECIMALS)  # a corner of its cell
    text = "points:" + " ".join(f"{format_mm(x)},{format_mm(y)},1" for x, y in printed)
    support = parse_support(text, part)  # raises if a point read back lies off the material
    assert np.allclose(np.sort(support.points, axis=0), np.sort(np.unique(printed, axis=0), axis=0),
                       atol=1e-12)


def test_a_point_just_outside_after_rounding_moves_in():
    """The case a fit met: (11.9087, -11.6674) on the triangle's slanted edge
    rounds to (11.909, -11.667), 0.3 um outside."""
    v = np.asarray(TRI.vertices)
    edge = v[1] - v[2], v[2]
    xy = None
    for s in np.linspace(0.01, 0.99, 997):  # a point of the edge that rounds to outside
        p = edge[1] + s * edge[0]
        if _off_material(TRI, np.round(p, PRINT_DECIMALS)[None]) is not None:
            xy = p
            break
    assert xy is not None
    printed = on_print_grid(TRI, xy[None])
    assert _off_material(TRI, printed) is None
    assert np.all(np.abs(printed[0] - xy) <= 1.000001 * 10.0 ** -PRINT_DECIMALS)
    assert all(format_mm(c) == f"{c:.3f}" for c in printed[0])  # three decimals were enough


def test_format_mm_prints_three_decimals_unless_more_are_needed():
    assert format_mm(11.909) == "11.909"
    assert format_mm(-0.5) == "-0.500"
    assert format_mm(round(1.23456, 5)) == "1.23456"
