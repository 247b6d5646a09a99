"""Outlines as a CAD tool flattens them, for tests: arcs as runs of short
edges (mm, counter-clockwise)."""
from __future__ import annotations

import math

import numpy as np


def circle(cx, cy, r, n, phase=0.0) -> np.ndarray:
    """A circle of radius ``r`` about ``(cx, cy)`` as a regular ``n``-gon,
    its first vertex at angle ``phase`` (radians)."""
    t = phase + np.linspace(0.0, 2 * np.pi, n, endpoint=False)
    return np.column_stack([cx + r * np.cos(t), cy + r * np.sin(t)])


def rounded_rectangle(w, h, r, per_corner) -> np.ndarray:
    """A ``w`` x ``h`` rectangle (corner at the origin) with fillets of
    radius ``r``, each flattened to ``per_corner`` edges."""
    pts = []
    for cx, cy, a0 in ((w - r, r, -90), (w - r, h - r, 0), (r, h - r, 90), (r, r, 180)):
        for k in range(per_corner + 1):
            a = math.radians(a0 + 90.0 * k / per_corner)
            pts.append((cx + r * math.cos(a), cy + r * math.sin(a)))
    return np.array(pts)
