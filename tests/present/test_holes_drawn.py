"""Parts with holes are drawn with their holes: every figure that draws a part
(outline, sequence diagram, both animations' frames, the feeder drawing and
its DXF) leaves each hole empty, at the part's pose.

Each check renders the figure with the Agg canvas twice, with the part
patches shown and hidden: at a point inside a hole (moved to the figure's
pose) the pixels must be the same both times (nothing drawn there), at a
point of material they must differ (the part is filled there). A figure that
drew the outline alone, or no part patch at all, fails.
"""
import math

import matplotlib
import numpy as np
import pytest
from matplotlib.patches import PathPatch

from pipeline.parts.part import Part
from pipeline.present.figures.outline import PartPatch, loops_path, part_path, posed

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def _plate():
    """A 50 x 40 mm plate with a 20 mm square hole left of centre and a round hole
    (radius 6 mm, 24 sides) right of centre."""
    outline = [[0, 0], [50, 0], [50, 40], [0, 40]]
    square = [[5, 10], [25, 10], [25, 30], [5, 30]]
    t = np.linspace(0.0, 2 * math.pi, 24, endpoint=False)
    round_hole = np.column_stack([38 + 6 * np.cos(t), 20 + 6 * np.sin(t)])
    return Part.from_vertices(outline, name="plate", holes=[square, round_hole])


PART = _plate()
SQUARE = next(h for h in PART.holes if len(h) == 4)
ROUND = next(h for h in PART.holes if len(h) == 24)
# Body-frame probes, a little off each hole's centre (clear of grid lines and markers).
IN_SQUARE = SQUARE.mean(axis=0) + [1.3, 2.1]
IN_ROUND = ROUND.mean(axis=0) + [0.9, -1.7]
# Material: between the square hole's lower edge and the plate's (5 mm of it).
MATERIAL = SQUARE.mean(axis=0) + [0.0, -15.0]


def _render(fig) -> np.ndarray:
    fig.canvas.draw()
    return np.asarray(fig.canvas.buffer_rgba())[..., :3].astype(float) / 255.0


def _patch_at(image, display_xy, half=2) -> np.ndarray:
    """The pixels around a display point (origin bottom left) as an array."""
    x, y = display_xy
    col, row = int(round(x)), image.shape[0] - 1 - int(round(y))
    assert half <= col < image.shape[1] - half and half <= row < image.shape[0] - half, "probe off the figure"
    return image[row - half:row + half + 1, col - half:col + half + 1]


def _assert_holes_empty(fig, probes):
    """``probes()``: (name, display point, is_material) rows, asked for once the
    figure is drawn (equal-aspect axes settle their place then). Renders ``fig``
    with its part patches (every PathPatch) shown and hidden, and compares."""
    patches = [p for p in fig.findobj(PathPatch)]
    assert patches, "no part drawn as a path patch"
    shown = _render(fig)
    probes = probes()
    for p in patches:
        p.set_visible(False)
    hidden = _render(fig)
    for p in patches:
        p.set_visible(True)
    for name, xy, material in probes:
        change = np.abs(_patch_at(shown, xy) - _patch_at(hidden, xy)).max()
        if material:
            assert change > 0.1, f"{name}: the material is not filled"
        else:
            assert change < 0.02, f"{name}: the hole is filled (changed by {change:.2f})"


def _probes(to_display, theta=0.0, x=0.0, y=0.0, tag=""):
    """The three probes at pose (theta, x, y), through ``to_display`` (data to pixels)."""
    out = []
    for name, point, material in (("square hole", IN_SQUARE, False), ("round hole", IN_ROUND, False),
                                  ("material", MATERIAL, True)):
        world = posed(np.asarray(point)[None, :], theta, x, y)[0]
        out.append((f"{tag}{name}", to_display.transform(world), material))
    return out


# ---------------------------------------------------------------- the shared helper


def test_part_path_holds_the_holes_at_the_pose_and_leaves_them_out():
    theta, x, y = 37.0, 120.0, -15.0
    path = part_path(PART, theta, x, y)
    for hole in PART.holes:  # every hole vertex, moved to the pose, is a vertex of the path
        for v in posed(hole, theta, x, y):
            assert np.min(np.hypot(*(path.vertices - v).T)) < 1e-9
    # One loop per MOVETO: the outline counter-clockwise, the holes clockwise (non-zero fill leaves them empty).
    starts = np.flatnonzero(path.codes == path.MOVETO).tolist() + [len(path.codes)]
    loops = [path.vertices[a:b - 1] for a, b in zip(starts, starts[1:])]
    assert [np.sign(_area(lp)) for lp in loops] == [1, -1, -1]
    patch = PartPatch(PART, theta, x, y)
    assert np.allclose(patch.get_xy()[:-1], posed(PART.vertices, theta, x, y))
    patch.set_pose(0.0, 0.0, 0.0)
    assert np.allclose(patch.get_xy()[:-1], PART.vertices)
    # Loops given in the wrong winding are turned round: still an outline with holes.
    turned = loops_path([PART.vertices[::-1], *(h[::-1] for h in PART.holes)])
    assert np.array_equal(turned.vertices, part_path(PART).vertices)


def _area(loop):
    return 0.5 * float(np.dot(loop[:, 0], np.roll(loop[:, 1], -1)) - np.dot(loop[:, 1], np.roll(loop[:, 0], -1)))


def test_a_solid_part_is_drawn_as_before():
    tri = Part.from_vertices([[0, 0], [60, 0], [15, 35]], name="tri")
    path = part_path(tri, 90.0, 5.0, 5.0)
    assert len(path.vertices) == 4 and np.allclose(path.vertices[:3], posed(tri.vertices, 90.0, 5.0, 5.0))


# ---------------------------------------------------------------- figures


def test_outline_figure_draws_the_holes():
    from pipeline.present.figures.outline import outline_figure
    fig = outline_figure(PART, "cad/plate.dxf")
    try:
        ax = fig.axes[0]
        ax.grid(False)
        _assert_holes_empty(fig, lambda: _probes(ax.transData))
        assert "2 holes" in ax.get_title()
    finally:
        plt.close(fig)


def test_sequence_figure_draws_the_holes_at_each_pose():
    from pipeline.present.figures.sequence import sequence_figure
    pins = {"P1": 5.0, "P2": 22.5}
    path = [(0.0, 20.0), (65.0, 24.0), (200.0, 21.0)]
    plan = {"pins": ["P1", "P2"], "final_sets": [{"start": 195.0, "width": 10.0}]}
    fig = sequence_figure(PART, plan, pins, {"state 1": path}, 3.0, "plate: best plan")
    try:
        ax = fig.axes[0]
        spacing = 3.2 * PART.a
        _assert_holes_empty(fig, lambda: [p for k, (theta, y) in enumerate(path)
                                          for p in _probes(ax.transData, theta, k * spacing, y,
                                                           tag=f"pose {k}: ")])
    finally:
        plt.close(fig)


def _lane(label, theta, y, x0=0.0, length=100.0):
    """A hand-made lane (no rollout): the part rides the belt at constant pose."""
    from pipeline.planning import Lane
    return Lane(label, np.array([0.0, length]), np.array([x0, x0 + length]), np.array([y, y]),
                np.array([theta, theta]))


def test_plan_animation_frame_draws_the_holes():
    from pipeline.present.animate import _moving_figure, _still_figure
    lanes = [_lane("state 1", 30.0, 25.0), _lane("state 2", 200.0, 22.0)]
    stations, heights, speeds = [160.0], [10.0], [0.0]
    still, panes = _still_figure(PART, lanes, stations, heights, speeds, ["P1"], 3.0, 220.0, "plate")
    fig, draw = _moving_figure(PART, still, panes, stations, heights, speeds, 3.0)
    plt.close(still)
    try:
        b = 40.0
        draw(b)
        # The frame is the still figure's image: its axes' transforms give the frame's pixels.
        probes = []
        for lane, ax, _ in panes:
            x, y, th = lane.pose(b)
            probes += _probes(ax.transData, th, x, y, tag=f"{lane.label}: ")
        _assert_holes_empty(fig, lambda: probes)
    finally:
        plt.close(fig)


def test_layout_animation_frame_draws_the_holes():
    from pipeline.planning import StationScene
    from pipeline.present.animate import station_figure
    lanes = [_lane("state 1", 0.0, 25.0, x0=-150.0, length=300.0),
             _lane("state 2", 120.0, 24.0, x0=-150.0, length=300.0)]
    stations = [{"label": "P1", "x_mm": 60.0, "y_mm": 5.0, "radius_mm": 3.0}]
    scene = StationScene(PART, lanes, stations, pitch=80.0, entry=150.0, n_parts=3, fence_y=0.0,
                         fence_end=-20.0, belt_y=(-5.0, 60.0), belt_speed=None, model="minpower", b_end=400.0)
    fig = station_figure(scene, "plate: layout")
    try:
        b = 170.0
        fig["draw"](b)
        poses = scene.part_poses(b)
        assert len(poses) == 3 and all(isinstance(p, PartPatch) for p in fig["parts"])
        _assert_holes_empty(fig["fig"], lambda: [p for k, _, x, y, th in poses
                                                 for p in _probes(fig["ax"].transData, th, x, y,
                                                                  tag=f"part {k}: ")])
    finally:
        plt.close(fig["fig"])


def _drawing_layout():
    """A layout with its drawing made by the layout's own code, from hand-made lanes."""
    from pipeline.planning.feeder.layout import entry_exit_outlines
    states = {"state 1": (0.0, 20.0), "state 2": (90.0, 25.0)}
    nominal = [_lane("state 1", 0.0, 20.0), _lane("state 2", 200.0, 26.0)]
    drawing = entry_exit_outlines(PART, states, nominal, [0.0, 60.0], 110.0, 60.0, 3.0, 5.0)
    return {"part": "plate", "pins": ["P1", "P2"],
            "stations": [{"label": "P1", "x_mm": 0.0, "y_mm": 5.0, "radius_mm": 3.0},
                         {"label": "P2", "x_mm": 60.0, "y_mm": 30.0, "radius_mm": 3.0}],
            "fence_y_mm": 0.0, "fence_end_x_mm": -40.0, "belt_y_mm": [-5.0, 60.0], "belt_width_mm": 65.0,
            "pitch_mm": 110.0, "belt_speed_mm_s": 100.0, "mu_s": 0.5, "mu_c": 0.15,
            "speed_limit_mm_s": 125.0, "speed_limit_trials": 30, "throughput_per_min": 54.5,
            "plan": {"number": 1, "friction": "0.15", "pins": ["P1", "P2"], "pin_heights_mm": [5.0, 30.0],
                     "final_sets": [{"start": 0, "width": 5}], "n_final_sets": 1},
            "drawing": drawing, "method": {"model": "minpower", "margins_mm": {"station_margin_mm": 5.0}},
            "warnings": []}


def test_layout_drawing_keeps_the_holes_at_each_pose():
    layout = _drawing_layout()
    drawn = layout["drawing"]["entry_parts"] + layout["drawing"]["exit_parts"]
    assert len(drawn) == 4
    for p in drawn:
        assert len(p["holes"]) == 2
        for hole, body in zip(p["holes"], PART.holes):
            assert np.allclose(hole, posed(body, p["theta_deg"], p["x_mm"], p["y_mm"]))
    solid = Part.from_vertices(PART.vertices, name="solid")
    from pipeline.planning.feeder.layout import entry_exit_outlines
    plain = entry_exit_outlines(solid, {"state 1": (0.0, 20.0)}, [_lane("state 1", 0.0, 20.0)], [0.0], 110.0,
                                60.0, 3.0, 5.0)
    assert "holes" not in plain["entry_parts"][0]  # a solid part's layout JSON as before


def test_feeder_drawing_draws_the_holes():
    from pipeline.present.figures.feeder import feeder_figure
    layout = _drawing_layout()
    fig = feeder_figure(layout)
    try:
        ax = fig.axes[0]
        _assert_holes_empty(fig, lambda: [p for key in ("entry_parts", "exit_parts")
                                          for d in layout["drawing"][key]
                                          for p in _probes(ax.transData, d["theta_deg"], d["x_mm"], d["y_mm"],
                                                           tag=f"{key} ")])
    finally:
        plt.close(fig)


def test_feeder_dxf_has_the_holes_on_the_parts_layer(tmp_path):
    import ezdxf

    from pipeline.present.figures.feeder import write_dxf
    layout = _drawing_layout()
    doc = ezdxf.readfile(str(write_dxf(layout, tmp_path / "feeder.dxf")))
    loops = [np.array([tuple(v)[:2] for v in e.get_points()])
             for e in doc.modelspace().query("LWPOLYLINE[layer=='PARTS']")]
    drawn = layout["drawing"]["entry_parts"] + layout["drawing"]["exit_parts"]
    assert len(loops) == len(drawn) * 3
    for p in drawn:
        for hole in p["holes"]:
            assert any(len(q) == len(hole) and np.allclose(q, hole, atol=1e-6) for q in loops)


# ---------------------------------------------------------------- stored parts keep their holes


def test_a_stored_plan_part_with_holes_passes_the_schema_and_comes_back_whole():
    from pipeline.errors import PinfeedError
    from pipeline.planning.core.types import validate_plan_dict
    data = {"part": PART.to_dict(), "model": "minpower", "plans": []}
    stored = validate_plan_dict(data, "plate.json")
    again = Part.from_dict(stored["part"])
    assert again.id == PART.id and len(again.holes) == 2
    bad = {**data, "part": {**PART.to_dict(), "holes": [[[0, 0], [1, 1]]]}}
    with pytest.raises(PinfeedError):
        validate_plan_dict(bad, "plate.json")
