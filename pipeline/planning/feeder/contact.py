"""The set-up of one pin contact, in mm: what the mechanics page's diagram draws.

World frame of the mechanics page: x downstream (the belt carries the part
to the right), y across the belt, the fence line at y = 0 with the part on
its +y side, the pin at x = 0. :func:`mechanics_scene` computes the geometry
and the contact model's instantaneous motion
(:func:`pipeline.maps.simulate.contact_motion`);
:func:`pipeline.present.figures.diagrams.mechanics_diagram` draws it.
"""
from __future__ import annotations

import math

import numpy as np

from pipeline.errors import PinfeedError
from pipeline.maps.simulate import contact_motion
from pipeline.parts.part import Part
from pipeline.planning.feeder.lanes import rotated

DEFAULT_VERTICES = ((0.0, 0.0), (60.0, 0.0), (15.0, 35.0))  # the paper's asymmetric triangle, mm


def first_contact(outline: np.ndarray, h: float, r: float) -> float:
    """Where a pin of radius ``r`` moving along ``y = h`` in -x first touches
    ``outline`` (counter-clockwise, any origin): the largest x on that line
    within ``r`` of the outline (vertex circles and edges offset outwards)."""
    xs = []
    for p, q in zip(outline, np.roll(outline, -1, axis=0)):
        if abs(h - p[1]) <= r:
            xs.append(p[0] + math.sqrt(r * r - (h - p[1]) ** 2))
        e = q - p
        m = np.array([e[1], -e[0]]) / np.hypot(*e)   # outward normal of a counter-clockwise edge
        a, b = p + r * m, q + r * m
        if (a[1] - h) * (b[1] - h) <= 0.0 and a[1] != b[1]:
            xs.append(a[0] + (h - a[1]) / (b[1] - a[1]) * (b[0] - a[0]))
    if not xs:
        raise PinfeedError(f"a pin {h:g} from the centroid across the belt misses the part")
    return max(xs)


def closest_point(outline: np.ndarray, point) -> np.ndarray:
    """The point of the closed polygon ``outline`` nearest to ``point``."""
    point = np.asarray(point, float)
    best, best_d = None, math.inf
    for p, q in zip(outline, np.roll(outline, -1, axis=0)):
        e = q - p
        t = min(1.0, max(0.0, float(np.dot(point - p, e) / np.dot(e, e))))
        c = p + t * e
        if np.hypot(*(c - point)) < best_d:
            best, best_d = c, float(np.hypot(*(c - point)))
    return best


def _default_theta(part: Part) -> float:
    """The resting state (edge on the fence) whose orientation is nearest 90
    degrees, so that the angle theta is clearly visible."""
    states = part.stable_states()
    return float(states[np.argmin(np.abs(states[:, 0] - 90.0)), 0])


def mechanics_scene(part: Part | None = None, theta: float | None = None, d: float = 0.3,
                    pin_radius: float = 3.0, mu_c: float = 0.15, model: str = "minpower") -> dict:
    """The geometry that :func:`pipeline.present.figures.diagrams.mechanics_diagram`
    draws, in mm, world frame.

    Parameters
    ----------
    part : the part (default: the paper's asymmetric triangle, 0,0 60,0 15,35 mm).
    theta : the part's orientation, degrees (default: its resting state
        nearest 90 degrees). The part rides with its lowest point on the fence
        line, so ``y_c`` is that point's distance from the centroid.
    d : contact parameter ``(y_p - y_c) / a``.
    pin_radius, mu_c, model : the pin's radius (mm), the pin-part friction
        and the contact model of the centre of rotation.

    Returns
    -------
    dict
        ``part``, ``theta``, ``d``, ``a``, ``y_c``, ``y_p``, ``pin`` (centre),
        ``pin_radius``, ``com``, ``outline`` (the part as drawn),
        ``contact`` (the touching point), ``normal`` (unit, into the part),
        ``motion`` (:func:`pipeline.maps.simulate.contact_motion`, relative to
        the centroid) and ``cor`` (the centre of rotation, world).
    """
    part = part or Part.from_vertices(DEFAULT_VERTICES, name="triangle")
    theta = _default_theta(part) if theta is None else float(theta)
    body = rotated(part.vertices, theta)
    y_c = -float(body[:, 1].min())
    y_p = y_c + d * part.a
    x_c = -first_contact(body, y_p - y_c, pin_radius)
    com, pin = np.array([x_c, y_c]), np.array([0.0, y_p])
    outline = body + com
    contact = closest_point(outline, pin)
    normal = (contact - pin) / np.hypot(*(contact - pin))
    motion = contact_motion(part, theta, contact - com, normal, mu_c=mu_c, model=model)
    cor = None if motion["cor"] is None else com + motion["cor"]
    return {"part": part, "theta": theta, "d": float(d), "a": part.a, "y_c": y_c, "y_p": y_p,
            "pin": pin, "pin_radius": float(pin_radius), "com": com, "outline": outline,
            "contact": contact, "normal": normal, "mu_c": float(mu_c), "model": model,
            "motion": motion, "cor": cor}

