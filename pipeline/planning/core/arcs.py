"""Arcs on the circle of orientations, in degrees: one helper per idea.

An arc is ``(start, width)`` with ``start`` in [0, 360) and ``0 <= width <=
360``; it covers ``start + [0, width]`` modulo 360.
"""
from __future__ import annotations

import numpy as np


def in_arc(x, start, width, tol=1e-9, period=360.0):
    """True where angle ``x`` lies in the arc ``start + [0, width]`` on a circle
    of ``period`` degrees (``360 / order`` for a part with ``order``-fold symmetry)."""
    if width >= period:
        return np.ones(np.shape(x), dtype=bool)
    return (np.asarray(x) - start) % period <= width + tol


def arc_within(inner, outer, tol=1e-6) -> bool:
    """True if arc ``inner`` lies inside arc ``outer`` (both ``(start, width)``,
    degrees), up to ``tol`` degrees: ``inner``'s start, taken from ``outer``'s
    start going counter-clockwise (through 360 if need be), plus its width
    does not pass ``outer``'s end. An ``outer`` of width 360 holds every arc.
    The one containment test of the house (planner, paper mode, sensing)."""
    if outer[1] >= 360.0:
        return True
    return (inner[0] - outer[0]) % 360.0 + inner[1] <= outer[1] + tol


def merge_arcs(arcs) -> list[tuple[float, float]]:
    """Union of circular arcs ``(start, width)``; overlapping or touching arcs merge."""
    arcs = [(s % 360.0, w) for s, w in arcs]
    if any(w >= 360.0 for _, w in arcs):
        return [(0.0, 360.0)]
    if not arcs:
        return []
    arcs.sort()
    merged = [list(arcs[0])]
    for s, w in arcs[1:]:
        ms, mw = merged[-1]
        if s <= ms + mw + 1e-9:
            merged[-1][1] = max(mw, s + w - ms)
        else:
            merged.append([s, w])
    if len(merged) > 1:  # join the last with the first across 360
        ls, lw = merged[-1]
        fs, fw = merged[0]
        if ls + lw >= fs + 360.0 - 1e-9:
            merged[0] = [ls, max(lw, fs + 360.0 + fw - ls)]
            merged.pop()
    if len(merged) == 1 and merged[0][1] >= 360.0:
        return [(0.0, 360.0)]
    return sorted((float(s), float(min(w, 360.0))) for s, w in merged)


def merge_modulo(arcs, order: int) -> list[tuple[float, float]]:
    """Union of arcs on the circle of a part with ``order``-fold rotational
    symmetry: orientations ``360 / order`` apart are one physical orientation.
    Returns arcs in [0, 360 / order) as ``(start, width)`` in degrees."""
    if order <= 1:
        return merge_arcs(arcs)
    period = 360.0 / order
    scaled = merge_arcs([((s % period) * order, w * order) for s, w in arcs])
    return [(s / order, w / order) for s, w in scaled]


def format_arc(start: float, width: float, digits: int = 1) -> str:
    """An arc for people: ``223.1-232.2 deg``; both ends within [0, 360), so an arc
    through 0 reads ``355.0-5.0 deg``; a single angle reads ``12.0 deg``."""
    if width >= 360.0:
        return "any orientation (0-360 deg)"

    def wrap(x):
        r = round(float(x) % 360.0, digits)
        return 0.0 if r >= 360.0 else r + 0.0

    lo, hi = wrap(start), wrap(start + width)
    return f"{lo:.{digits}f} deg" if lo == hi else f"{lo:.{digits}f}-{hi:.{digits}f} deg"


def format_arcs(sets, digits: int = 1, style: str = "range") -> str:
    """Orientation sets for people: the one formatter every report, figure and
    CLI line uses. ``sets`` are ``(start, width)`` pairs or ``{"start",
    "width"}`` dicts (as stored plans hold them); comma-separated.

    ``style="range"`` (default): each as :func:`format_arc` (``355.0-5.0 deg``),
    ``"none"`` for no sets. ``style="interval"``: ``[start, start + width]``
    unwrapped, ``digits`` decimals (``[355, 365]``), empty for no sets."""
    pairs = [(s["start"], s["width"]) if isinstance(s, dict) else tuple(s) for s in sets]
    if style == "interval":
        return ", ".join(f"[{s:.{digits}f}, {s + w:.{digits}f}]" for s, w in pairs)
    if style != "range":
        raise ValueError(f"style must be 'range' or 'interval', got {style!r}")
    return ", ".join(format_arc(s, w, digits) for s, w in pairs) or "none"
