"""pinfeed layout (issue 19): stations, pitch, throughput, the drawing, bad input.

The replay checks below rebuild the world-frame motion of two consecutive
parts past two consecutive pins from the public rollout API, with their own
first-touch search and their own polygon/disc intersection tests (a simple
reference, independent of ``pipeline.planning.feeder.layout``'s slab and reach geometry).
"""
import json
import math

import numpy as np
import pytest

from images import assert_png_figure
from pipeline.cli import main
from pipeline.config import load_config
from pipeline.errors import PinfeedError
from pipeline.maps import simulate
from pipeline.parts.part import Part
from pipeline.planning import LayoutSettings, layout_stored

TRIANGLE = "0,0 60,0 15,35"
SPEED = 100.0


# ------------------------------------------------------------ reference geometry


def _seg_dist(p, a, b):
    ab = b - a
    t = 0.0 if not ab.any() else min(1.0, max(0.0, float((p - a) @ ab) / float(ab @ ab)))
    return float(np.hypot(*(a + t * ab - p)))


def _inside(p, poly):
    x, y = p
    n, inside = len(poly), False
    for i in range(n):
        (x1, y1), (x2, y2) = poly[i], poly[(i + 1) % n]
        if (y1 > y) != (y2 > y) and x < x1 + (y - y1) * (x2 - x1) / (y2 - y1):
            inside = not inside
    return inside


def disc_overlaps(poly, centre, r):
    """True if the closed disc meets the polygon (reference)."""
    c = np.asarray(centre, float)
    return _inside(c, poly) or min(_seg_dist(c, poly[i], poly[(i + 1) % len(poly)])
                                   for i in range(len(poly))) <= r


def _cross(o, a, b):
    return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])


def _segments_meet(p1, p2, q1, q2):
    d1, d2 = _cross(q1, q2, p1), _cross(q1, q2, p2)
    d3, d4 = _cross(p1, p2, q1), _cross(p1, p2, q2)
    return (d1 * d2 <= 0) and (d3 * d4 <= 0)


def polygons_overlap(p, q):
    """True if two simple polygons share a point (reference: crossing edges or containment)."""
    for i in range(len(p)):
        for j in range(len(q)):
            if _segments_meet(p[i], p[(i + 1) % len(p)], q[j], q[(j + 1) % len(q)]):
                return True
    return _inside(p[0], q) or _inside(q[0], p)


def outline(part, x, y, theta):
    t = math.radians(theta)
    rot = np.array([[math.cos(t), -math.sin(t)], [math.sin(t), math.cos(t)]])
    return part.vertices @ rot.T + np.array([x, y])


def first_touch(part, theta, y, pin, r):
    """Centroid x at which a part riding downstream first touches the pin (bisection)."""
    lo, hi = pin[0] - 4 * part.a, pin[0] + 4 * part.a
    if not disc_overlaps(outline(part, hi, y, theta), pin, r) and \
            not any(disc_overlaps(outline(part, x, y, theta), pin, r) for x in np.linspace(lo, hi, 400)):
        return None
    xs = np.linspace(lo, hi, 400)
    k = next(i for i, x in enumerate(xs) if disc_overlaps(outline(part, x, y, theta), pin, r))
    a, b = xs[max(k - 1, 0)], xs[k]
    for _ in range(40):
        m = 0.5 * (a + b)
        a, b = (a, m) if disc_overlaps(outline(part, m, y, theta), pin, r) else (m, b)
    return b


def world_motion(part, theta, y, pins, r, mu_c, model):
    """Belt travel B and centroid poses of one part riding from x = -200 past the pins."""
    B, X, Y, T = [0.0], [-200.0], [y], [theta]
    for pin in pins:
        u = first_touch(part, theta, y, pin, r)
        if u is None:
            continue
        b0 = B[-1] + (u - X[-1])
        ds = simulate.rollout(part, theta, (pin[1] - y) / part.a, mu_c, r, model=model, trajectory=True)
        s = np.asarray(ds.traj_s, float)
        B += [b0] + list(b0 + s)
        X += [u] + list(u + s + np.asarray(ds.traj_x, float))
        Y += [y] + list(y + np.asarray(ds.traj_y, float))
        T += [theta] + list(np.asarray(ds.traj_theta, float))
        theta, y = float(ds.theta_f), Y[-1]
    return np.array(B), np.array(X), np.array(Y), np.array(T)


def pose_at(motion, b):
    B, X, Y, T = motion
    if b <= B[0]:
        return X[0] + b - B[0], Y[0], T[0]
    if b >= B[-1]:
        return X[-1] + b - B[-1], Y[-1], T[-1]
    return float(np.interp(b, B, X)), float(np.interp(b, B, Y)), float(np.interp(b, B, T))


# ------------------------------------------------------------------- fixtures


@pytest.fixture(scope="module")
def stored(tmp_path_factory):
    root = tmp_path_factory.mktemp("layout")
    plan = root / "results" / "plans" / "tri.json"
    assert main(["plan", "--vertices", TRIANGLE, "--name", "tri", "--pins=-5:40:7.5", "--depth", "2",
                 "--mu-c", "0", "--dynamic-depth", "0", "--catalog", str(root / "cat"),
                 "--out", str(plan)]) == 0
    result = json.loads(plan.read_text())
    config = load_config()
    from pipeline.planning import PlannerSettings
    layout = layout_stored(result, PlannerSettings.from_config(config), belt_speed=SPEED, quasi_static=True,
                           settings=LayoutSettings(trials=4, speed_trials=3))
    return {"root": root, "results": root / "results", "result": result, "layout": layout,
            "config": config}


def _states(result):
    entry = result["tight"][0]
    return [(s["theta"], s["y_c"]) for s in entry["initial_states"].values()]


# ----------------------------------------------------------------------- tests


def test_layout_keys_and_stations(stored):
    out = stored["layout"]
    for key in ("part", "plan", "stations", "fence_y_mm", "belt_width_mm", "pitch_mm",
                "belt_speed_mm_s", "speed_limit_mm_s", "throughput_per_min", "method"):
        assert key in out
    xs = [s["x_mm"] for s in out["stations"]]
    assert xs[0] == 0.0 and all(b > a for a, b in zip(xs, xs[1:]))
    assert [s["y_mm"] for s in out["stations"]] == out["plan"]["pin_heights_mm"]
    assert out["method"]["model"] == "minpower" and out["method"]["trials"]["replayed"] >= 4


def test_throughput_arithmetic(stored):
    out = stored["layout"]
    assert out["throughput_per_min"] == pytest.approx(60.0 * SPEED / out["pitch_mm"])
    # A 120 mm pitch at 100 mm/s is 50 parts a minute.
    assert 60.0 * 100.0 / 120.0 == pytest.approx(50.0)


def test_two_pins_replay_no_touch_at_station_touch_when_closer(stored):
    """The part rests after pin 1 before pin 2's disc touches it; at a station
    clearly closer, pin 2 would touch a part still moving at pin 1."""
    out, result = stored["layout"], stored["result"]
    part = Part.from_vertices(result["part"]["vertices"])
    r = out["stations"][0]["radius_mm"]
    p1, p2 = ((s["x_mm"], s["y_mm"]) for s in out["stations"][:2])
    margin = out["method"]["margins_mm"]["station_margin_mm"]
    closer = (p2[0] - margin - 12.0, p2[1])
    touched_closer = False
    for theta, y in _states(result):
        B, X, Y, T = world_motion(part, theta, y, [p1], r, 0.0, "minpower")
        start = int(np.searchsorted(B, B[1]))  # from the first touch of pin 1 on
        polys = [outline(part, x, yy, t) for x, yy, t in zip(X[start:], Y[start:], T[start:])]
        assert not any(disc_overlaps(p, p2, r) for p in polys), "pin 2 touches a part at pin 1"
        touched_closer |= any(disc_overlaps(p, closer, r) for p in polys)
    assert touched_closer


def _conflict(part, motions, pins, r, pitch, step=0.5):
    """Whether two consecutive parts (any pair of states) touch, or a pin touches both."""
    end = max(m[0][-1] for m in motions) + pitch + 50
    for lead in motions:
        for trail in motions:
            for b in np.arange(0.0, end, step):
                pa = outline(part, *pose_at(lead, b))
                pb = outline(part, *pose_at(trail, b - pitch))
                if abs(pa[:, 0].mean() - pb[:, 0].mean()) > 3 * part.a:
                    continue
                if polygons_overlap(pa, pb):
                    return True
                if any(disc_overlaps(pa, pin, r) and disc_overlaps(pb, pin, r) for pin in pins):
                    return True
    return False


def test_two_parts_replay_apart_at_pitch_touch_when_closer(stored):
    out, result = stored["layout"], stored["result"]
    part = Part.from_vertices(result["part"]["vertices"])
    r = out["stations"][0]["radius_mm"]
    pins = [(s["x_mm"], s["y_mm"]) for s in out["stations"][:2]]
    motions = [world_motion(part, theta, y, pins, r, 0.0, "minpower") for theta, y in _states(result)]
    assert not _conflict(part, motions, pins, r, out["pitch_mm"])
    assert _conflict(part, motions, pins, r, 0.5 * out["pitch_mm"])


def test_dxf_entities_stand_where_the_json_says(stored, tmp_path):
    import ezdxf

    from pipeline.parts.outlines import read_outline
    from pipeline.present.layout import write_drawing
    out = stored["layout"]
    path = write_drawing(out, tmp_path / "feeder.dxf")
    doc = ezdxf.readfile(str(path))
    assert {"BELT", "FENCE", "PINS", "DIMENSIONS", "PARTS", "TITLE"} <= {ly.dxf.name for ly in doc.layers}
    msp = doc.modelspace()
    circles = sorted((c.dxf.center.x, c.dxf.center.y, c.dxf.radius) for c in msp.query("CIRCLE[layer=='PINS']"))
    want = sorted((s["x_mm"], s["y_mm"], s["radius_mm"]) for s in out["stations"])
    assert np.allclose(circles, want, atol=1e-6)
    handles = [e.dxf.handle for e in msp.query("LWPOLYLINE[layer=='PARTS']")]
    drawn = out["drawing"]["entry_parts"] + out["drawing"]["exit_parts"]
    assert len(handles) == len(drawn)
    got = sorted(sorted(map(tuple, np.round(read_outline(path, layer="PARTS", id=h).vertices, 6).tolist()))
                 for h in handles)
    expected = sorted(sorted(map(tuple, np.round(np.asarray(p["outline"]), 6).tolist())) for p in drawn)
    assert got == expected
    # Each drawn outline is the part itself, moved: same area.
    part = Part.from_vertices(stored["result"]["part"]["vertices"])
    for p in drawn:
        q = np.asarray(p["outline"])
        area = 0.5 * abs(np.dot(q[:, 0], np.roll(q[:, 1], -1)) - np.dot(q[:, 1], np.roll(q[:, 0], -1)))
        assert area == pytest.approx(part.area, rel=1e-9)


def test_svg_and_png_drawings(stored, tmp_path):
    from pipeline.present.layout import write_drawing
    for suffix in (".svg", ".png"):
        path = write_drawing(stored["layout"], tmp_path / f"feeder{suffix}")
        if suffix == ".png":
            assert_png_figure(path)
            from PIL import Image
            with Image.open(path) as image:  # the PNG records the plan it draws
                assert image.text["pinfeed-plan"] == " ".join(stored["layout"]["plan"]["pins"])
        else:
            assert path.read_text().lstrip().startswith("<?xml") and "<svg" in path.read_text()
    assert "pitch" in (tmp_path / "feeder.svg").read_text()


def _one_line(capsys, argv):
    code = main(argv)
    err = capsys.readouterr().err.strip()
    assert code != 0 and len(err.splitlines()) == 1 and err.startswith("pinfeed: error:")
    return err


def test_bad_input_one_line_errors(stored, capsys, tmp_path):
    res = str(stored["results"])
    assert "no stored plan for nope" in _one_line(capsys, ["layout", "--part", "nope", "--results", res])
    assert "--margin" in _one_line(capsys, ["layout", "--part", "tri", "--results", res, "--margin", "-1"])
    blocker = tmp_path / "afile"
    blocker.write_text("x")
    assert "is a file" in _one_line(capsys, ["layout", "--part", "tri", "--results", res,
                                             "--out", str(blocker / "feeder.dxf")])
    assert "suffix" in _one_line(capsys, ["layout", "--part", "tri", "--results", res,
                                          "--out", str(tmp_path / "feeder.pdf")])
    with pytest.raises(PinfeedError, match="station_margin_mm"):
        LayoutSettings(station_margin_mm=-0.5)


def test_belt_speed_above_limit_warns_naming_the_limit(stored, capsys):
    limit = stored["layout"]["speed_limit_mm_s"]
    fast = limit + 200.0
    code = main(["layout", "--part", "tri", "--results", str(stored["results"]), "--belt-speed",
                 str(fast), "--quasi-static", "--trials", "2", "--json"])
    captured = capsys.readouterr()
    assert code == 0
    warning = [ln for ln in captured.err.splitlines() if ln.startswith("pinfeed: warning: belt speed")]
    assert len(warning) == 1 and f"{limit:g} mm/s" in warning[0]
    assert json.loads(captured.out)["warnings"][0] == warning[0].removeprefix("pinfeed: warning: ")
