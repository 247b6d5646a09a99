"""Figures whose labels used to overlap (issue 27): the feeder drawing with close
pins, the layout animation's header, the maps-by-speed title; and a layout
leaving several final sets says so in red."""
import numpy as np
import pytest
import xarray as xr

from pipeline.parts.part import Part
from pipeline.planning import final_sets_warning, station_scene
from pipeline.present.animate import station_figure
from pipeline.present.figures import text_problems
from pipeline.present.figures.bands import band_maps_figure
from pipeline.present.figures.feeder import ALERT_COLOUR, feeder_figure

PART = Part.from_vertices([[0, 0], [60, 0], [15, 35]], name="tri")
STATES = {f"state {k}": (float(th), float(y)) for k, (th, y) in enumerate(PART.stable_states(), 1)}
# Four pins 14 mm apart at alternating heights: their labels and dimensions crowd.
CLOSE = [(0.0, 7.5), (14.0, 27.5), (28.0, 5.0), (42.0, 30.0)]


def _layout(warnings=()):
    """A layout with the keys the drawing and the animation read, by hand."""
    tri = np.array([[0, 0], [60, 0], [15, 35]], float) - [25.0, 11.7]
    part_at = lambda x, y: {"state": "state 1", "x_mm": x, "y_mm": y, "theta_deg": 0.0,  # noqa: E731
                            "outline": (tri + [x, y]).tolist()}
    stations = [{"label": f"P{k + 1}", "x_mm": x, "y_mm": y, "radius_mm": 3.0} for k, (x, y) in enumerate(CLOSE)]
    return {"part": "tri", "pins": [s["label"] for s in stations], "stations": stations,
            "fence_y_mm": 0.0, "fence_end_x_mm": -40.0, "belt_y_mm": [-40.0, 75.0], "belt_width_mm": 115.0,
            "pitch_mm": 150.0, "belt_speed_mm_s": 100.0, "mu_s": 0.5, "mu_c": 0.15,
            "speed_limit_mm_s": 125.0, "speed_limit_trials": 30, "throughput_per_min": 40.0,
            "plan": {"number": 2, "friction": "0.15", "pins": [s["label"] for s in stations],
                     "pin_heights_mm": [y for _, y in CLOSE], "final_sets": [{"start": 20, "width": 5},
                                                                            {"start": 130, "width": 4}],
                     "n_final_sets": 2},
            "drawing": {"entry_parts": [part_at(-80.0, 11.7), part_at(-230.0, 11.7)],
                        "exit_parts": [part_at(120.0, 11.7)]},
            "method": {"model": "minpower", "margins_mm": {"station_margin_mm": 5.0}},
            "warnings": list(warnings)}


def test_feeder_drawing_of_close_pins_has_no_overlapping_labels():
    import matplotlib.pyplot as plt
    fig = feeder_figure(_layout())
    try:
        assert text_problems(fig) == []
    finally:
        plt.close(fig)


def test_several_final_sets_are_a_warning_drawn_in_red():
    import matplotlib.pyplot as plt
    from matplotlib.colors import to_hex
    layout = _layout()
    warning = final_sets_warning(layout["plan"])
    assert warning == ["plan 2 leaves 2 final orientation sets (20.0-25.0 deg, 130.0-134.0 deg): parts "
                       "leave this feeder in more than one orientation"]
    assert final_sets_warning(dict(layout["plan"], n_final_sets=1)) == []
    # Two claimed sets that the verified trials find in one set within the tolerance: no warning.
    verified = {"orientation": {"orients": True, "width_deg": 7.3, "tolerance_deg": 10.0}}
    assert final_sets_warning(dict(layout["plan"], verification=verified)) == []
    verified["orientation"]["orients"] = False
    assert final_sets_warning(dict(layout["plan"], verification=verified)) == warning
    fig = feeder_figure(_layout(warning))
    try:
        red = [t for t in fig.findobj(lambda a: hasattr(a, "get_text") and "final orientation sets" in a.get_text())]
        assert red and all(to_hex(t.get_color()) == ALERT_COLOUR for t in red)
        assert text_problems(fig) == []
    finally:
        plt.close(fig)


def test_layout_animation_header_of_close_pins_does_not_overlap():
    import matplotlib.pyplot as plt
    scene = station_scene(PART, _layout(), STATES, 0.15, n_parts=2)
    f = station_figure(scene, "tri: the laid-out tight plan 12 at mu_c 0.1:0.3, pins P1 → P2 → P3 → P4; "
                              "belt 120 mm/s (dynamic model); pitch 155.5 mm")
    try:
        f["draw"](40.0)
        assert text_problems(f["fig"]) == []
    finally:
        plt.close(f["fig"])


def test_maps_by_speed_title_clears_the_panels():
    import matplotlib.pyplot as plt
    grid, d = np.arange(0, 360, 10.0), np.array([-0.5, -0.1, 0.3, 0.7])
    tf = np.tile(grid, (d.size, 1))
    ds = xr.Dataset({"theta_f": (("d", "theta_i"), tf), "dy": (("d", "theta_i"), 0 * tf),
                     "status": (("d", "theta_i"), np.zeros(tf.shape, np.int8))},
                    coords={"d": d, "theta_i": grid})
    maps = {f"$v_{{pin}}/v_b$ = {v:+g}": ds for v in (-2, -1, 0, 1, 2)}  # the default sweep's speeds
    for columns in (1, 4):
        fig = band_maps_figure(maps, list(d[:columns]), 5.0, 2.0, "asym_triangle: minpower maps by pin "
                               "speed, $\\mu_c$ = 0.15 (d at the centroid's station)")
        try:
            assert text_problems(fig) == [], columns
        finally:
            plt.close(fig)
