"""One helper per idea (issue 14): each shared helper checked against closed forms.

- ``planning.arcs.arc_within``: arc containment, through 360 included;
- ``planning.arcs.format_arcs``: orientation sets for people (both styles);
- ``parts.contact.contact_parameter``: d from a pin height, the spec's sign;
- ``planning.paper.load_maps``: the one reader of a map set's bands;
- ``sensing.profiles.synthetic_measurement`` draws through ``trials.perturbed_inputs``;
- ``workflow.commands``: what ``pinfeed plan`` / ``layout`` decide below the CLI.
"""
from __future__ import annotations

import numpy as np
import pytest
import xarray as xr

from pipeline.errors import PinfeedError
from pipeline.parts.contact import contact_parameter
from pipeline.planning.core.arcs import arc_within, format_arcs, in_arc

# ---------------------------------------------------------------- arc containment


@pytest.mark.parametrize("inner, outer, inside", [
    ((20.0, 10.0), (10.0, 30.0), True),     # 20..30 in 10..40
    ((20.0, 25.0), (10.0, 30.0), False),    # 20..45 passes 40
    ((5.0, 10.0), (10.0, 30.0), False),     # starts before the outer arc
    ((350.0, 15.0), (340.0, 40.0), True),   # 350..5 in 340..20, through 360
    ((5.0, 10.0), (350.0, 30.0), True),     # 5..15 in 350..20, the outer arc wraps
    ((5.0, 16.0), (350.0, 30.0), False),    # 5..21 passes 20
    ((345.0, 10.0), (350.0, 30.0), False),  # 345 is before 350: outside, not "360 degrees later"
    ((0.0, 360.0), (123.0, 360.0), True),   # a full circle holds everything
    ((10.0, 0.0), (10.0, 0.0), True),       # a point in itself
    ((0.0, 30.0), (10.0, 359.0), False),    # 0..30 crosses the gap 9..10 deg
    ((200.0, 30.0), (10.0, 359.0), True),   # 200..230 in 10..9 (through 360)
])
def test_arc_within_closed_forms(inner, outer, inside):
    assert arc_within(inner, outer) is inside


def test_arc_within_agrees_with_sampling_the_inner_arc():
    # An independent check: an arc lies inside another iff every point of it does.
    rng = np.random.default_rng(3)
    for _ in range(300):
        inner = (rng.uniform(0, 360), rng.uniform(0, 90))
        outer = (rng.uniform(0, 360), rng.uniform(0, 180))
        points = inner[0] + np.linspace(0.0, inner[1], 200)
        sampled = bool(np.all(in_arc(points, outer[0], outer[1], 1e-6)))
        # Sampling can only be fooled at the ends; stay clear of them.
        ends = ((inner[0] - outer[0]) % 360.0, (inner[0] + inner[1] - outer[0]) % 360.0)
        if min(abs(e - b) for e in ends for b in (0.0, outer[1], 360.0)) < 1e-3:
            continue
        assert arc_within(inner, outer) is sampled, (inner, outer)


def test_arc_within_tolerance():
    assert arc_within((10.0, 30.0 + 1e-7), (10.0, 30.0))
    assert not arc_within((10.0, 30.0 + 1e-3), (10.0, 30.0))
    assert arc_within((10.0, 30.0 + 1e-3), (10.0, 30.0), tol=1e-2)


# ---------------------------------------------------------------- set formatting


def test_format_arcs_range_style_wraps_through_zero_and_takes_dicts_or_pairs():
    sets = [{"start": 355.0, "width": 10.0}, (90.0, 5.25)]
    assert format_arcs(sets) == "355.0-5.0 deg, 90.0-95.2 deg"
    assert format_arcs(sets, digits=0) == "355-5 deg, 90-95 deg"
    assert format_arcs([(12.0, 0.0)]) == "12.0 deg"
    assert format_arcs([(0.0, 360.0)]) == "any orientation (0-360 deg)"
    assert format_arcs([]) == "none"


def test_format_arcs_interval_style_is_start_and_unwrapped_end():
    sets = [{"start": 355.4, "width": 10.0}, {"start": 90.0, "width": 5.0}]
    assert format_arcs(sets, digits=0, style="interval") == "[355, 365], [90, 95]"
    assert format_arcs([(1.25, 2.0)], digits=2, style="interval") == "[1.25, 3.25]"
    assert format_arcs([], digits=0, style="interval") == ""
    with pytest.raises(ValueError):
        format_arcs(sets, style="braces")


# ---------------------------------------------------------------- contact parameter


def test_contact_parameter_sign_follows_the_spec():
    # Spec, mechanics section 2: d = (y_p - y_c) / a, positive with the pin on the
    # +y side of the centroid.
    assert contact_parameter(30.0, 10.0, 20.0) == pytest.approx(1.0)
    assert contact_parameter(5.0, 10.0, 10.0) == pytest.approx(-0.5)
    assert contact_parameter(10.0, 10.0, 7.0) == 0.0
    assert contact_parameter(12.0, 10.0, 4.0) > 0 > contact_parameter(8.0, 10.0, 4.0)


def test_contact_parameter_broadcasts_arrays():
    pins = np.array([11.0, 12.0, 9.0])
    y_c = np.array([10.0, 10.0, 10.0])
    np.testing.assert_allclose(contact_parameter(pins, y_c, 2.0), [0.5, 1.0, -0.5])
    np.testing.assert_allclose(contact_parameter(20.0, y_c, 5.0), [2.0, 2.0, 2.0])


def test_contact_parameter_of_a_part():
    # A pin at y_c + a/2 meets a part at d = 1/2, whatever its size.
    from pipeline.parts.part import Part
    part = Part.from_vertices([(0, 0), (60, 0), (15, 35)])
    assert contact_parameter(10.0 + 0.5 * part.a, 10.0, part.a) == pytest.approx(0.5)


# ---------------------------------------------------------------- one reader of a map set's bands


def test_load_maps_sorts_by_d_and_keeps_each_maps_bands():
    from pipeline.planning.paper.bands import extract_bands
    from pipeline.planning.paper.planner import load_maps
    theta = np.arange(0.0, 360.0, 10.0)
    d = np.array([0.5, -0.3, 0.1])  # stored out of order
    tf = np.stack([np.where(theta < 180, 45.0, 225.0), np.full(theta.size, 90.0),
                   (theta + 3.0) % 360.0])
    dy = np.stack([np.full(theta.size, v) for v in (1.0, -2.0, 0.5)])
    st = np.zeros(tf.shape, np.int8)
    ds = xr.Dataset({"theta_f": (("d", "theta_i"), tf), "dy": (("d", "theta_i"), dy),
                     "status": (("d", "theta_i"), st)}, coords={"d": d, "theta_i": theta})
    maps = load_maps(ds, 5.0, 2.0)
    assert [m.d for m in maps] == [-0.3, 0.1, 0.5]
    by_d = {m.d: m for m in maps}
    # d = 0.5: two bands at 45 and 225 deg; d = -0.3: one band at 90 deg
    assert sorted(round(b.start) for b in by_d[0.5].bands) == [45, 225]
    assert [round(b.start) for b in by_d[-0.3].bands] == [90]
    for k, dd in enumerate(d):
        want = extract_bands(theta, tf[k], dy[k], st[k], 5.0, 2.0)
        assert [b.to_dict() for b in by_d[float(dd)].bands] == [b.to_dict() for b in want]
        np.testing.assert_array_equal(by_d[float(dd)].theta_f, tf[k])


# ---------------------------------------------------------------- synthetic measurements


def test_synthetic_measurement_draws_through_perturbed_inputs(monkeypatch):
    from pipeline.planning.claims.trials import PERTURB_DEFAULTS, perturbed_inputs
    from pipeline.planning.core.settings import Perturbation
    from pipeline.sensing import profiles
    from pipeline.sensing.profiles import Sensor

    class Drawn(Exception):
        pass

    seen = []

    def record(part, theta, y_c, y_pin, mu_c, pin_radius, model):
        seen.append((theta, y_c, y_pin, mu_c))
        raise Drawn

    monkeypatch.setattr(profiles, "first_pin_rollout", record)
    perturb = dict(PERTURB_DEFAULTS, theta_sigma=3.0)  # as the sensing section gives it
    sizes = Perturbation(theta_sigma=3.0)
    for mu_c in (0.2, (0.1, 0.3)):
        seen.clear()
        rng = np.random.default_rng(7)
        for _ in range(50):
            with pytest.raises(Drawn):
                profiles.synthetic_measurement(None, {"theta": 30.0, "y_c": 10.0}, 20.0, mu_c, 3.0,
                                               "minpower", Sensor(), perturb, rng)
        ref = np.random.default_rng(7)
        for theta, y_c, y_pin, mu in seen:
            th, yc, m, offs = perturbed_inputs(30.0, 10.0, mu_c, 1, sizes, ref)
            assert (theta, y_c, y_pin, mu) == pytest.approx((th, yc, 20.0 + offs[0], m))
        thetas = np.array([s[0] for s in seen])
        assert np.all(np.abs(thetas - 30.0) <= 2 * 3.0)  # truncated at 2 sigma, as verification
        assert np.all(np.abs(np.array([s[2] for s in seen]) - 20.0) <= sizes.pin_halfwidth)


# ---------------------------------------------------------------- the commands below the CLI


def _config():
    from pipeline.config import load_config
    return load_config(None)


def test_planner_settings_applies_each_override_to_a_copy():
    from pipeline.workflow.commands import planner_settings
    config = _config()
    before = repr(config)
    out = planner_settings(config, catalog="/tmp/cat", mu_c="0.1:0.3", depth=3, model="tip",
                           coverage="bracket", speeds=[-2.0, 2.0], dynamic_depth=1, pins=[5, 7.5],
                           belt_speed=100.0, mu_s=0.4)
    assert repr(config) == before  # the caller's config is untouched
    pc = out["planner"]
    assert out["catalog_dir"] == "/tmp/cat"
    assert (pc["mu_c"], pc["frictions"], pc["depth"], pc["model"], pc["coverage"]) == \
        ("0.1:0.3", [], 3, "tip", "bracket")
    assert pc["dynamic"]["speeds"] == [-2.0, 2.0] and pc["dynamic"]["depth"] == 1
    assert pc["pins"] == [5.0, 7.5] and pc["belt_speed"] == 100.0 and pc["mu_s"] == 0.4
    # depth 0 of moving pins drops the speeds
    assert planner_settings(config, speeds=[2.0], dynamic_depth=0)["planner"]["dynamic"]["speeds"] == []
    # nothing given: the config's values
    assert planner_settings(config)["planner"] == config["planner"]


@pytest.mark.parametrize("kw, message", [
    ({"depth": 0}, "--depth must be at least 1"),
    ({"speeds": [0.0, 2.0]}, "drop 0"),
    ({"dynamic_depth": -1}, "--dynamic-depth must be 0"),
    ({"mu_s": 0.3}, "give --belt-speed too"),
    ({"mu_c": "abc"}, "abc"),
])
def test_planner_settings_rejects_bad_values(kw, message):
    from pipeline.workflow.commands import planner_settings
    with pytest.raises(PinfeedError, match=message):
        planner_settings(_config(), **kw)


def test_layout_settings():
    from pipeline.workflow.commands import layout_settings
    assert layout_settings() == {}
    assert layout_settings(2.5, 40) == {"station_margin_mm": 2.5, "trials": 40}
    for bad in (-1.0, float("nan"), float("inf")):
        with pytest.raises(PinfeedError, match="--margin"):
            layout_settings(bad)
