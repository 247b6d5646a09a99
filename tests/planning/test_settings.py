"""The planner's settings: built once from the validated config, typed,
frozen, their defaults the schema's, and one truncation shared by the
planner's box and the verification's trials."""
import dataclasses

import numpy as np
import pytest
import yaml

from pipeline.config import DEFAULT_CONFIG, SCHEMA_PATH, load_config
from pipeline.errors import PinfeedError
from pipeline.planning import (ClaimSettings, Friction, Perturbation, PlannerSettings, SearchSettings,
                               VerifySettings, corner_inputs)
from pipeline.planning.tight.propagate import Uncertainty, friction_interval


def _schema_default(*path):
    node = yaml.safe_load(SCHEMA_PATH.read_text())
    for key in path:
        node = node["properties"][key]
    return node["default"]


def test_settings_of_the_default_config_are_the_config_file_values():
    raw = yaml.safe_load(DEFAULT_CONFIG.read_text())
    settings = PlannerSettings.from_config(load_config(None))
    lo, hi = (float(x) for x in raw["planner"]["mu_c"].split(":"))
    assert (settings.friction.lo, settings.friction.hi) == (lo, hi) and settings.friction.is_range
    assert settings.friction.sigma == raw["verify"]["mu_sigma"]
    # the recommended friction first, then each listed one once
    assert [f.value for f in settings.frictions] == [(lo, hi)] + [float(f) for f in raw["planner"]["frictions"]]
    assert settings.search.depth == raw["planner"]["depth"] and settings.search.model == raw["planner"]["model"]
    assert settings.search.pin_radius == raw["sweep"]["pin_radius"]
    assert settings.search.dynamic_speeds == tuple(raw["planner"]["dynamic"]["speeds"])
    assert settings.claims.tolerance_deg == raw["planner"]["tolerance_deg"]
    assert settings.verify.trials == raw["verify"]["trials"]
    assert settings.verify.perturbation.theta_sigma == raw["verify"]["theta_sigma"]
    assert settings.speed.trials == raw["speed"]["trials"]
    assert settings.swept_frictions == tuple(float(m) for m in raw["sweep"]["mu_c"])


@pytest.mark.parametrize("kind, field_name, path", [
    (ClaimSettings, "tolerance_deg", ("planner", "tolerance_deg")),
    (ClaimSettings, "required", ("verify", "required")),
    (ClaimSettings, "confidence", ("verify", "confidence")),
    (VerifySettings, "trials", ("verify", "trials")),
    (Perturbation, "mu_sigma", ("verify", "mu_sigma")),
    (Perturbation, "pin_halfwidth", ("verify", "pin_halfwidth")),
])
def test_defaults_are_the_schemas(kind, field_name, path):
    assert getattr(kind(), field_name) == _schema_default(*path)


def test_search_defaults_are_the_schemas():
    search = SearchSettings(3.0)
    for name, path in [("depth", ("planner", "depth")), ("width_slack_deg", ("planner", "width_slack_deg")),
                       ("worst_member_budget", ("planner", "worst_member_budget")),
                       ("candidates", ("planner", "candidates")), ("beam", ("planner", "dynamic", "beam"))]:
        assert getattr(search, name) == _schema_default(*path), name


def test_settings_are_frozen():
    settings = PlannerSettings.from_config(load_config(None))
    with pytest.raises(dataclasses.FrozenInstanceError):
        settings.search.depth = 9
    assert settings.at(0.2).friction.value == 0.2 and settings.friction.is_range  # a copy, not a change
    assert settings.without_moving_pins().search.dynamic_depth == 0 and settings.search.dynamic_depth > 0


@pytest.mark.parametrize("text, want", [("0.15", 0.15), ("0.1:0.3", (0.1, 0.3)), ([0.1, 0.3], (0.1, 0.3)),
                                        ("0.2:0.2", 0.2), (0, 0.0)])
def test_friction_values(text, want):
    f = Friction.parse(text)
    assert f.value == want
    assert f.nominal == (0.5 * (want[0] + want[1]) if isinstance(want, tuple) else want)


@pytest.mark.parametrize("bad", ["-0.1", "0.3:0.1", "nan", "a:b", [0.1, 0.2, 0.3]])
def test_bad_friction_is_one_line(bad):
    with pytest.raises(PinfeedError) as err:
        Friction.parse(bad)
    assert "\n" not in str(err.value)


@pytest.mark.parametrize("bad", [{"tolerance_deg": 0}, {"tolerance_deg": 400}, {"required": 1.5},
                                 {"confidence": 1.0}, {"rule": "maybe"}])
def test_bad_claim_settings_are_refused_when_made(bad):
    with pytest.raises(PinfeedError) as err:
        ClaimSettings(**bad)
    assert "\n" not in str(err.value)


@pytest.mark.parametrize("mu", [0.2, 0.01, (0.1, 0.3)])
def test_one_truncation_for_the_planners_box_and_the_trials_corners(mu):
    # The planner's uncertainty box and the verification's box corners cover
    # the same frictions: both stop at TRUNCATE_SIGMA sigma (a range as given).
    verify = VerifySettings(perturbation=Perturbation(mu_sigma=0.03))
    friction = Friction.parse(mu, verify.perturbation.mu_sigma)
    box = friction_interval(friction.value, Uncertainty.from_verify(verify))
    _, _, corner_mu, _ = corner_inputs(30.0, 5.0, friction.value, 1, verify)
    assert box == friction.interval() == (corner_mu.min(), corner_mu.max())
    assert np.all(np.isin(corner_mu, box))


def test_cli_overrides_reach_the_settings():
    from pipeline.workflow.commands import planner_settings
    config = planner_settings(load_config(None), mu_c="0.2", tolerance=12.0, depth=2, dynamic_depth=0)
    settings = PlannerSettings.from_config(config)
    assert settings.friction.value == 0.2 and [f.value for f in settings.frictions] == [0.2]
    assert settings.claims.tolerance_deg == 12.0 and settings.search.depth == 2
    assert settings.search.moving_speeds == []
