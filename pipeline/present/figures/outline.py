"""A part's outline as the planner sees it: body frame, centroid, reference length a, resting states.

Also the one way every figure draws a part (:class:`PartPatch`, built on
:func:`part_path`): the outline and its holes as one compound path, the
outline counter-clockwise and the holes clockwise, so matplotlib's non-zero
fill (every backend's) leaves the holes empty: a hole reads as a hole, with
the outline's edge colour around it.
"""
from __future__ import annotations

import math
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.patches import Circle, PathPatch
from matplotlib.path import Path as MplPath

from pipeline.present.figures import save_figure


def posed(xy, theta_deg: float = 0.0, x: float = 0.0, y: float = 0.0) -> np.ndarray:
    """Body-frame points ``xy`` (n, 2) turned by ``theta_deg`` counter-clockwise
    about the centroid (the origin), then moved to ``(x, y)``."""
    c, s = math.cos(math.radians(theta_deg)), math.sin(math.radians(theta_deg))
    return np.asarray(xy, float) @ np.array([[c, s], [-s, c]]) + np.array([x, y], float)


def part_loops(part, theta_deg: float = 0.0, x: float = 0.0, y: float = 0.0) -> list[np.ndarray]:
    """The part's outline then each of its holes, at the pose ``(theta_deg, x, y)``."""
    return [posed(loop, theta_deg, x, y) for loop in (part.vertices, *part.holes)]


def _signed_area(loop: np.ndarray) -> float:
    return 0.5 * float(np.dot(loop[:, 0], np.roll(loop[:, 1], -1)) - np.dot(loop[:, 1], np.roll(loop[:, 0], -1)))


def loops_path(loops) -> MplPath:
    """One compound :class:`matplotlib.path.Path` of closed loops: the first the
    outline, the others holes. The outline is made counter-clockwise and the
    holes clockwise, whatever their winding as given, so a non-zero fill
    leaves the holes empty."""
    verts, codes = [], []
    for k, loop in enumerate(loops):
        loop = np.asarray(loop, float)
        if (_signed_area(loop) < 0) == (k == 0):  # outline clockwise, or a hole counter-clockwise
            loop = loop[::-1]
        verts += [loop, loop[:1]]
        codes += [MplPath.MOVETO] + [MplPath.LINETO] * (len(loop) - 1) + [MplPath.CLOSEPOLY]
    return MplPath(np.concatenate(verts), np.array(codes, dtype=MplPath.code_type))


def part_path(part, theta_deg: float = 0.0, x: float = 0.0, y: float = 0.0, to=None) -> MplPath:
    """The part (outline and holes) at the pose ``(theta_deg, x, y)`` as one
    compound path (:func:`loops_path`); ``to`` (a matplotlib transform, e.g.
    data to pixels) is applied after the pose."""
    path = loops_path(part_loops(part, theta_deg, x, y))
    return path if to is None else path.transformed(to)


class PartPatch(PathPatch):
    """A part drawn as one patch at a pose: the material filled, the holes empty.

    ``to``: a matplotlib transform applied after the pose (the animation draws
    in the pixels of a still figure); other keywords go to :class:`PathPatch`
    (``fc``, ``ec``, ``alpha``, ``zorder``, ``gid`` ...). :meth:`set_pose` moves
    it; :meth:`get_xy` is the outline as drawn, closed (as a ``Polygon``'s).
    """

    def __init__(self, part, theta_deg: float = 0.0, x: float = 0.0, y: float = 0.0, to=None, **kwargs):
        self.part, self._to = part, to
        super().__init__(part_path(part, theta_deg, x, y, to), **kwargs)

    def set_pose(self, theta_deg: float, x: float, y: float) -> None:
        """Draw the part turned by ``theta_deg`` with its centroid at ``(x, y)``."""
        self.set_path(part_path(self.part, theta_deg, x, y, self._to))
        self.stale = True

    def get_xy(self) -> np.ndarray:
        """The outline as drawn, first vertex repeated at the end."""
        n = self.part.n_vertices
        return np.asarray(self.get_path().vertices[:n + 1])


def outline_figure(part, source: str | None = None):
    """The outline (body frame, mm) with its centroid, the circle of radius a
    around it, and the fence line of each resting state (numbered as the
    initial states), drawn where the fence touches the part."""
    fig, ax = plt.subplots(figsize=(5.2, 5.0))
    ax.add_patch(PartPatch(part, fc="tab:blue", ec="k", alpha=0.45, gid="outline"))
    ax.add_patch(Circle((0, 0), part.a, fill=False, ls="--", lw=0.8, ec="0.5"))
    ax.plot([0], [0], "k+", ms=9)
    for k, (theta, y_c) in enumerate(part.stable_states(), start=1):
        # The fence seen from the body frame: world -y rotated back by theta, y_c away.
        t = math.radians(theta)
        n = np.array([-math.sin(t), -math.cos(t)])
        along = np.array([-n[1], n[0]]) * 0.55 * part.a
        foot = y_c * n
        ax.plot(*np.transpose([foot - along, foot + along]), color="tab:red", lw=1.2, gid=f"fence {k}")
        ax.text(*(foot + 0.2 * part.a * n), f"state {k}", ha="center", va="center", fontsize=7,
                color="tab:red")
    lim = 1.35 * part.a
    ax.set_xlim(-lim, lim)
    ax.set_ylim(-lim, lim)
    ax.set_aspect("equal")
    ax.set_xlabel("body frame $x$ (mm)", fontsize=8)
    ax.set_ylabel("body frame $y$ (mm)", fontsize=8)
    ax.tick_params(labelsize=7)
    ax.grid(True, lw=0.3, alpha=0.5)
    kind = "convex" if part.is_convex else "non-convex"
    origin = f"\nfrom {Path(source).name}" if source else ""
    holes = f", {len(part.holes)} hole{'s' if len(part.holes) > 1 else ''}" if part.has_holes else ""
    ax.set_title(f"{part.name}: {part.n_vertices} vertices, {kind}{holes}, area {part.area:.1f} mm², "
                 f"$a$ = {part.a:.2f} mm{origin}", fontsize=8)
    fig.tight_layout()
    return fig


def plot_outline(part, out, source: str | None = None) -> Path:
    """Draw the part's outline (and its source, if given) to the image file ``out``."""
    return save_figure(outline_figure(part, source), out)
