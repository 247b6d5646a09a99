"""The mechanics page's labelled diagram (pipeline.present.figures.diagrams):
no overlapping labels, every symbol labelled, and the drawing geometrically
right, checked against quantities recomputed here from what was drawn: the
pin touches the outline, the drawn d is (y_p - y_c) / a with the centroid and
a of the drawn outline, theta turns the body frame counter-clockwise from the
belt direction, and the COR is the contact model's for that contact."""
import math

import matplotlib.pyplot as plt
import numpy as np
import pytest
from matplotlib.text import Text

from pipeline.maps.simulate import contact_motion
from pipeline.parts.part import Part
from pipeline.present.figures import text_problems
from pipeline.planning import mechanics_scene
from pipeline.present.figures.diagrams import mechanics_diagram

TRIANGLE = [(0, 0), (60, 0), (15, 35)]


@pytest.fixture(scope="module", params=[0.3, -0.3], ids=["d=+0.3", "d=-0.3"])
def drawn(request):
    fig = mechanics_diagram(mechanics_scene(d=request.param))
    yield request.param, fig
    plt.close(fig)


def by_gid(fig, gid):
    found = fig.findobj(lambda o: o.get_gid() == gid)
    assert len(found) == 1, (gid, found)
    return found[0]


def centroid_and_a(xy):
    """Area centroid (shoelace) of a closed polygon and its largest centroid-vertex distance."""
    x, y = xy[:, 0], xy[:, 1]
    x1, y1 = np.roll(x, -1), np.roll(y, -1)
    cross = x * y1 - x1 * y
    area = cross.sum() / 2
    c = np.array([((x + x1) * cross).sum(), ((y + y1) * cross).sum()]) / (6 * area)
    return c, np.hypot(*(xy - c).T).max()


def distance_to_outline(xy, p):
    best = math.inf
    for a, b in zip(xy, np.roll(xy, -1, axis=0)):
        t = np.clip(np.dot(p - a, b - a) / np.dot(b - a, b - a), 0, 1)
        best = min(best, np.hypot(*(a + t * (b - a) - p)))
    return best


def nearest_on_outline(xy, p):
    pts = []
    for a, b in zip(xy, np.roll(xy, -1, axis=0)):
        t = np.clip(np.dot(p - a, b - a) / np.dot(b - a, b - a), 0, 1)
        pts.append(a + t * (b - a))
    return min(pts, key=lambda q: np.hypot(*(q - p)))


def geometry(fig):
    pin = by_gid(fig, "pin")
    outline = by_gid(fig, "part").get_xy()[:-1]
    com, a = centroid_and_a(outline)
    return np.asarray(pin.center, float), pin.radius, outline, com, a


def test_labels_do_not_overlap(drawn):
    _, fig = drawn
    assert text_problems(fig) == []


def test_every_symbol_is_labelled(drawn):
    _, fig = drawn
    texts = [t.get_text() for t in fig.findobj(Text) if t.get_visible()]
    for needle in ("belt", "$v_b$", "fence", "pin", "$r_{pin}$", "$d$ =", r"$d \cdot a$", "$a$ =",
                   r"$\theta$", "COR", "COM", "$y_c$", "$y_p$"):
        assert any(needle in t for t in texts), needle
    assert fig.axes[0].get_xlabel().endswith("(mm)") and fig.axes[0].get_ylabel().endswith("(mm)")


def test_the_belt_moves_downstream_and_the_part_rests_on_the_fence_line(drawn):
    _, fig = drawn
    arrow = by_gid(fig, "belt arrow")
    assert arrow.xy[0] > arrow.xyann[0] and arrow.xy[1] == arrow.xyann[1]   # +x
    _, _, outline, _, _ = geometry(fig)
    assert outline[:, 1].min() == pytest.approx(0.0, abs=1e-9)               # y = 0, part on +y
    fence = by_gid(fig, "fence")
    assert fence.get_y() + fence.get_height() == pytest.approx(0.0)           # rail below y = 0
    assert fence.get_x() + fence.get_width() < outline[:, 0].min()            # it ends before the part


def test_the_pin_touches_the_outline_from_outside(drawn):
    _, fig = drawn
    pin, r, outline, _, _ = geometry(fig)
    assert distance_to_outline(outline, pin) == pytest.approx(r, abs=1e-6)
    assert not by_gid(fig, "part").get_path().contains_point(pin)
    assert pin[0] == 0.0                                        # the pin stands at x = 0
    # First touch: a little upstream the part clears the pin, a little downstream it would overlap it.
    assert distance_to_outline(outline - [1e-3, 0.0], pin) > r + 1e-4
    assert distance_to_outline(outline + [1e-3, 0.0], pin) < r - 1e-4


def test_drawn_d_is_the_pin_offset_across_the_belt_over_a(drawn):
    d, fig = drawn
    pin, _, outline, com, a = geometry(fig)
    assert by_gid(fig, "COM").get_xydata()[0] == pytest.approx(com, abs=1e-9)
    assert a == pytest.approx(Part.from_vertices(TRIANGLE).a)
    d_drawn = (pin[1] - com[1]) / a                    # d = (y_p - y_c) / a, y from the fence line
    assert d_drawn == pytest.approx(d, abs=1e-9)
    p, q = by_gid(fig, "d")._posA_posB
    assert (p[1], q[1]) == pytest.approx((com[1], pin[1]), abs=1e-9)
    assert f"$d$ = {d:+.2f}" in by_gid(fig, "d label").get_text()
    assert f"= {d * a:.1f} mm" in by_gid(fig, "d label").get_text()
    assert (by_gid(fig, "y_c")._posA_posB[1][1], by_gid(fig, "y_p")._posA_posB[1][1]) == \
        pytest.approx((com[1], pin[1]), abs=1e-9)
    p, q = by_gid(fig, "a")._posA_posB
    assert np.allclose(p, com) and np.hypot(*np.subtract(q, p)) == pytest.approx(a, abs=1e-9)


def test_theta_turns_the_body_frame_counter_clockwise_from_the_belt_direction(drawn):
    _, fig = drawn
    _, _, outline, com, _ = geometry(fig)
    body = Part.from_vertices(TRIANGLE).vertices
    arc = by_gid(fig, "theta arc")
    theta = arc.theta2
    assert arc.theta1 == 0.0 and 0.0 < theta < 360.0
    t = math.radians(theta)
    turned = body @ np.array([[math.cos(t), math.sin(t)], [-math.sin(t), math.cos(t)]]) + com
    assert turned == pytest.approx(outline, abs=1e-9)
    axis = by_gid(fig, "body x")
    direction = np.subtract(axis.xy, axis.xyann)
    assert math.degrees(math.atan2(direction[1], direction[0])) % 360 == pytest.approx(theta)
    assert f"{theta:.0f}°" in by_gid(fig, "theta label").get_text()


def test_the_cor_is_the_contact_models_for_the_drawn_contact(drawn):
    d, fig = drawn
    pin, _, outline, com, _ = geometry(fig)
    theta = by_gid(fig, "theta arc").theta2
    contact = nearest_on_outline(outline, pin)
    motion = contact_motion(Part.from_vertices(TRIANGLE), theta, contact - com,
                            (contact - pin) / np.hypot(*(contact - pin)), mu_c=0.15)
    cor = by_gid(fig, "COR").get_xydata()[0]
    assert cor == pytest.approx(com + motion["cor"], abs=1e-6)
    # Independent of the model: the pin pushes back on the part at the side it
    # stands, so the part turns counter-clockwise for d > 0 (clockwise for
    # d < 0), about a point on the far side of the centroid from the pin;
    # while the contact sticks, the contact point moves with the pin (-x in
    # the belt frame), so the COR lies straight across the belt from it.
    assert np.sign(motion["omega"]) == np.sign(d)
    assert np.sign(cor[1] - com[1]) == -np.sign(d)
    if motion["mode"] == "stick":
        assert cor[0] == pytest.approx(contact[0], abs=1e-6)
