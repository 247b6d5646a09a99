"""The contact parameter ``d``: where a pin meets a part, in units of the part's size.

One helper for one idea: every layer that turns a pin height into
``d`` calls :func:`contact_parameter`.
"""
from __future__ import annotations


def contact_parameter(pin_y, y_c, a):
    """``d = (pin_y - y_c) / a``: the pin's offset across the belt from the part's
    centroid, in units of ``a`` (spec, mechanics section 2).

    ``pin_y`` is the pin axis's world y, ``y_c`` the centroid's world y before
    contact and ``a`` the largest centroid-to-vertex distance of the part. The
    sign convention: ``d > 0`` when the pin is on the +y side of the centroid
    ("above" it in the paper's figures, the belt running left to right),
    ``d < 0`` below it; ``d = 0`` and small ``|d|`` are metastable. Scalars or
    NumPy arrays (broadcast)."""
    return (pin_y - y_c) / a
