"""Explanatory diagrams for the manual: the set-up of one pin contact, labelled.

World frame of the mechanics page: x downstream (the belt carries the part
to the right), y across the belt, the fence line at y = 0 with the part on
its +y side, the pin at x = 0. The planner's
:func:`pipeline.planning.mechanics_scene` computes the geometry (in mm) and
the contact model's motion; :func:`mechanics_diagram` draws it.
"""
from __future__ import annotations

import math

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.patches import Arc, Circle, FancyArrowPatch, Rectangle

from pipeline.present.figures.outline import PartPatch

FONT = 8
COLOURS = {"part": "tab:blue", "pin": "0.15", "dim": "tab:green", "cor": "tab:red",
           "fence": "0.25", "belt": "0.92", "theta": "tab:orange"}


def _label(ax, xy, text, gid, colour="k", **kwargs):
    """A direct label in data coordinates, named ``gid`` for tests."""
    kwargs = {"fontsize": FONT, "ha": "left", "va": "center", **kwargs}
    return ax.text(xy[0], xy[1], text, color=colour, gid=gid, **kwargs)


def _dimension(ax, p, q, text, at, gid, colour=COLOURS["dim"], **kwargs):
    """A two-headed dimension arrow from ``p`` to ``q`` (gid ``gid``, its ends
    are the drawn quantity) with its label ``text`` at ``at``."""
    arrow = FancyArrowPatch(tuple(p), tuple(q), arrowstyle="<|-|>", mutation_scale=7, lw=0.8,
                            color=colour, shrinkA=0, shrinkB=0, gid=gid, zorder=4)
    ax.add_patch(arrow)
    _label(ax, at, text, gid=gid + " label", colour=colour, **kwargs)
    return arrow


def _draw_belt(ax, box):
    """The belt's surface, and an arrow with its direction and speed below the part."""
    x0, x1, y0, y1 = box
    ax.add_patch(Rectangle((x0, y0), x1 - x0, y1 - y0, fc=COLOURS["belt"], ec="none", zorder=0,
                           gid="belt"))
    y = y0 + 0.3 * (-y0)
    ax.annotate("", xy=(x0 + 48, y), xytext=(x0 + 8, y), gid="belt arrow",
                arrowprops=dict(arrowstyle="-|>", color="0.3", lw=1.4, mutation_scale=12))
    _label(ax, (x0 + 50, y), r"belt moves at speed $v_b$ in +x", gid="belt label")


def _draw_fence(ax, box, x_end):
    """The fence: a rail along y = 0 on the belt's -y side, ending upstream of
    the part (which has just left it); the fence line continues as a dashed line."""
    x0 = box[0]
    ax.add_patch(Rectangle((x0, -2.5), x_end - x0, 2.5, fc=COLOURS["fence"], ec="none", zorder=2,
                           gid="fence"))
    _label(ax, (x0 + 3.0, -3.5), "fence", gid="fence label", va="top")
    ax.axhline(0.0, color="0.45", lw=0.6, ls=(0, (6, 3)), zorder=1)
    _label(ax, (box[1] - 2.0, -1.6), "fence line y = 0", gid="fence line label",
           fontsize=FONT - 1, colour="0.35", ha="right", va="top")


def _draw_part(ax, s):
    """The part, its centroid (COM) and the dimension a to its farthest vertex."""
    part, com, theta = s["part"], s["com"], s["theta"]
    ax.add_patch(PartPatch(part, theta, *com, fc=COLOURS["part"], ec="k", lw=1.0, alpha=0.35,
                           zorder=3, gid="part"))
    ax.plot(*com, marker="o", ms=5, mfc="white", mec="k", mew=1.0, zorder=6, gid="COM")
    far = s["outline"][np.argmax(np.hypot(*(s["outline"] - com).T))]
    along = com + 0.85 * (far - com)
    right = np.array([(far - com)[1], -(far - com)[0]]) / s["a"]
    _dimension(ax, com, far, f"$a$ = {s['a']:.1f} mm", along + 3.5 * right, "a", ha="left")
    _label(ax, com + (1.5, -1.5), "COM (centroid)", gid="COM label", va="top", fontsize=FONT - 1)
    left = float(s["outline"][:, 0].min())
    _label(ax, (0.5 * (left + com[0]), 0.3 * com[1]), "part", gid="part label", colour="navy",
           ha="center")


def _draw_theta(ax, s):
    """The orientation theta: an arc from world +x to the body x axis."""
    com, theta, a = s["com"], s["theta"], s["a"]
    u = np.array([math.cos(math.radians(theta)), math.sin(math.radians(theta))])
    ax.annotate("", xy=tuple(com + 0.75 * a * u), xytext=tuple(com), gid="body x",
                arrowprops=dict(arrowstyle="-|>", color=COLOURS["theta"], lw=1.1, shrinkA=0, shrinkB=0))
    _label(ax, com + 0.75 * a * u + (-1.0, 1.0), "body x axis", gid="body x label",
           colour=COLOURS["theta"], fontsize=FONT - 1, ha="right", va="bottom")
    r = 0.2 * a
    ax.add_patch(Arc(tuple(com), 2 * r, 2 * r, theta1=0.0, theta2=theta, color=COLOURS["theta"],
                     lw=1.1, gid="theta arc", zorder=5))
    at = math.radians(min(35.0, 0.5 * theta))
    _label(ax, com + (r + 1.5) * np.array([math.cos(at), math.sin(at)]),
           rf"$\theta$ = {theta:.0f}°", gid="theta label", colour=COLOURS["theta"], ha="left",
           va="bottom", bbox={"fc": "white", "ec": "none", "alpha": 0.7, "pad": 0.5})


def _draw_pin(ax, s):
    """The pin's circle, its centre and a leader label with its radius."""
    pin, r = s["pin"], s["pin_radius"]
    ax.add_patch(Circle(tuple(pin), r, fc=COLOURS["pin"], ec="k", lw=0.8, zorder=5, gid="pin"))
    at = np.array([pin[0] + 7.0, max(pin[1], s["y_c"]) + 14.0])
    ax.plot(*np.transpose([pin + r * np.array([0.6, 0.8]), at]), color="k", lw=0.6, zorder=5,
            gid="pin leader")
    _label(ax, at + (0.5, 0.0), rf"pin, radius $r_{{pin}}$ = {r:g} mm", gid="pin label",
           va="bottom")


def _draw_heights(ax, s, x):
    """Lines along the belt through the COM and the pin, and the heights y_c,
    y_p (from the fence line) and d a (between them) as dimensions."""
    com, pin = s["com"], s["pin"]
    for y in (com[1], pin[1]):
        ax.plot([com[0], x[2] + 2.0], [y, y], color="0.45", lw=0.6, ls=(0, (2, 2)), zorder=1)
    _dimension(ax, (x[0], 0.0), (x[0], com[1]), "$y_c$", (x[0] - 1.0, 0.5 * com[1]), "y_c",
               ha="right")
    _dimension(ax, (x[1], 0.0), (x[1], pin[1]), "$y_p$", (x[1] - 1.0, 0.5 * min(com[1], pin[1])),
               "y_p", ha="right")
    da = pin[1] - com[1]
    _dimension(ax, (x[2], com[1]), (x[2], pin[1]), f"$d \\cdot a$ = {da:.1f} mm\n$d$ = {s['d']:+.2f}",
               (x[2] + 1.0, com[1] + 0.5 * da), "d")


def _draw_cor(ax, s, box):
    """The centre of rotation (COR) with an arrow showing the sense of turning;
    a note in the corner instead when it lies outside the drawing."""
    cor = s["cor"]
    if cor is None or not (box[0] < cor[0] < box[1] and box[2] < cor[1] < box[3]):
        where = "none: the part translates" if cor is None else f"({cor[0]:.0f}, {cor[1]:.0f}) mm"
        _label(ax, (box[1] - 2.0, box[3] - 2.0), f"COR off the drawing: {where}", gid="COR label",
               colour=COLOURS["cor"], ha="right", va="top")
        return
    ax.plot(*cor, marker="X", ms=8, color=COLOURS["cor"], mec="white", mew=0.6, zorder=7, gid="COR")
    sense = 1.0 if s["motion"]["omega"] > 0 else -1.0
    r = 4.5
    t0, t1 = (200.0, 320.0) if sense > 0 else (320.0, 200.0)
    p0 = cor + r * np.array([math.cos(math.radians(t0)), math.sin(math.radians(t0))])
    p1 = cor + r * np.array([math.cos(math.radians(t1)), math.sin(math.radians(t1))])
    ax.add_patch(FancyArrowPatch(tuple(p0), tuple(p1), connectionstyle=f"arc3,rad={0.6 * sense}",
                                 arrowstyle="-|>", mutation_scale=8, color=COLOURS["cor"], lw=0.9,
                                 zorder=7, gid="COR turn"))
    _label(ax, cor + (r + 1.5, 0.5), "COR", gid="COR label", colour=COLOURS["cor"], fontweight="bold")


def _view(s):
    """The right edge of the part and pin, and the drawn area ``(x0, x1, y0, y1)``
    (mm): the part, the pin, the dimensions right of them, and the COR when
    it lies within 2 a of the centroid."""
    right = max(float(s["outline"][:, 0].max()), s["pin_radius"])
    x0, x1 = float(s["outline"][:, 0].min()) - 25.0, right + 43.0
    y0, y1 = -14.0, max(s["y_p"] + 26.0, float(s["outline"][:, 1].max()) + 12.0)
    cor = s["cor"]
    if cor is not None and np.hypot(*(cor - s["com"])) <= 2.0 * s["a"]:
        x0, x1 = min(x0, cor[0] - 10.0), max(x1, cor[0] + 16.0)
        y0, y1 = min(y0, cor[1] - 10.0), max(y1, cor[1] + 8.0)
    return right, (x0, x1, y0, y1)


def mechanics_diagram(s: dict):
    """A labelled top view of a part meeting a pin: the belt and its direction,
    the fence, the pin, the part with its centroid (COM), orientation theta and
    size a, the heights y_c and y_p, the contact parameter d, and the centre of
    rotation (COR) of the part's motion relative to the belt as the pin starts
    to push it (the contact model's, :func:`pipeline.maps.simulate.contact_motion`).

    Parameters
    ----------
    s : the scene, :func:`pipeline.planning.mechanics_scene` (part, pin, heights,
        contact and the contact model's motion, in mm).

    Returns
    -------
    matplotlib.figure.Figure
        Equal aspect, axes in mm. Artists carry gids (``"pin"``, ``"part"``,
        ``"COR"``, ``"d"``, ...) so that tests can find what was drawn.
    """
    fig, ax = plt.subplots(figsize=(7.0, 5.0))
    right, box = _view(s)
    ax.set_xlim(box[0], box[1])
    ax.set_ylim(box[2], box[3])
    _draw_belt(ax, box)
    _draw_fence(ax, box, float(s["outline"][:, 0].min()) - 6.0)
    _draw_part(ax, s)
    _draw_theta(ax, s)
    _draw_pin(ax, s)
    _draw_heights(ax, s, (right + 3.0, right + 12.0, right + 21.0))
    _draw_cor(ax, s, box)
    ax.set_aspect("equal")
    ax.set_xlabel("x along the belt, downstream (mm)", fontsize=FONT)
    ax.set_ylabel("y across the belt (mm)", fontsize=FONT)
    ax.tick_params(labelsize=FONT - 1)
    fig.tight_layout()
    return fig
