"""``simulate.contact_motion``: the part's instantaneous motion for one pin
contact, in world axes and millimetres, checked against the mechanics
page's statements worked out here: a force line through the centroid
translates the part; the tip model's centre of rotation lies on the
perpendicular from the centroid to the force line, on the far side, a^2/rho
from the centroid; the answer, in world axes, does not depend on the frame
the part was drawn in."""
import numpy as np
import pytest

from pipeline.errors import PinfeedError
from pipeline.maps.simulate import contact_motion
from pipeline.parts.part import Part

PART = Part.from_vertices([(0, 0), (60, 0), (15, 35)], name="triangle")


def edge_point(y):
    """The point of the edge from vertex 1 to vertex 2 at body height ``y``, and the edge's inward normal."""
    a, b = PART.vertices[1], PART.vertices[2]
    c = a + (y - a[1]) / (b[1] - a[1]) * (b - a)
    e = (b - a) / np.hypot(*(b - a))
    return c, np.array([-e[1], e[0]])          # counter-clockwise outline: inward is z x e


@pytest.mark.parametrize("model", ["minpower", "tip", "ellipsoid"])
def test_a_force_line_through_the_centroid_translates(model):
    c, _ = edge_point(0.0)
    out = contact_motion(PART, 0.0, c, -c, mu_c=0.0, model=model)
    assert out["status"] == "ok" and out["cor"] is None and out["omega"] == pytest.approx(0.0, abs=1e-12)
    assert out["force"] / np.hypot(*out["force"]) == pytest.approx([-1.0, 0.0])


def test_tip_cor_is_a_squared_over_rho_on_the_far_side():
    c, n = edge_point(5.0)
    out = contact_motion(PART, 0.0, c, n, mu_c=0.0, model="tip")   # frictionless: force along n
    foot = c - np.dot(c, n) * n                                   # the force line's nearest point
    rho = np.hypot(*foot)
    assert out["cor"] == pytest.approx(-foot / rho * PART.a ** 2 / rho, rel=1e-9)


@pytest.mark.parametrize("phi", [30.0, 200.0])
def test_the_answer_is_in_world_axes_whatever_the_drawing_frame(phi):
    c, n = edge_point(8.0)
    base = contact_motion(PART, 0.0, c, n, mu_c=0.15)
    # The drawing turned back by phi, posed at theta = phi: the same shape in the world.
    out = contact_motion(PART.rotated(-phi), phi, c, n, mu_c=0.15)
    assert out["mode"] == base["mode"]
    for key in ("cor", "velocity", "force"):
        assert out[key] == pytest.approx(base[key], abs=1e-6), key
    assert out["omega"] == pytest.approx(base["omega"], rel=1e-6)


def test_bad_inputs_are_refused():
    c, n = edge_point(5.0)
    with pytest.raises(PinfeedError, match="mu_c"):
        contact_motion(PART, 0.0, c, n, mu_c=-1.0)
    with pytest.raises(PinfeedError, match="unknown model"):
        contact_motion(PART, 0.0, c, n, model="dynamic")
