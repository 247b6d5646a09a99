"""The tails of the arrivals: the claim states its 2-sigma truncation, and the
recommended plan is replayed on untruncated normals beside it.

The draws are checked against the normal they claim to be; the stored
``untruncated`` record of a small plan is checked against a replay of the
test's own (own draws, own narrowest arc, the public rollout API); the plan
file carries the keys and ``pinfeed plan`` prints the line."""
from __future__ import annotations

import contextlib
import html
import io
import json
import math

import numpy as np
import pytest
import yaml

from pipeline.planning import replay
from pipeline.planning.claims.tails import describe_untruncated
from pipeline.planning.claims.trials import perturbed_batch, trial_inputs
from pipeline.planning.core.settings import HOLDOUT_STREAM, TRUNCATE_SIGMA, UNTRUNCATED_STREAM, VerifySettings

VERTICES = "0,0 60,0 15,35"
MU_C = 0.15


def _draws(settings, n=40_000, mu_c=MU_C):
    """Perturbations of theta and mu_c about 0 and ``mu_c`` (``n`` of each)."""
    th, _, mu, _ = perturbed_batch(0.0, 0.0, mu_c, 1, settings, np.random.default_rng(3), n)
    return th, mu - mu_c


def test_untruncated_draws_reach_beyond_two_sigma_with_the_normals_spread():
    base = VerifySettings(seed=7).held_out()
    tails = VerifySettings(seed=7).untruncated(10)
    sizes = tails.perturbation
    assert tails.truncate_sigma is None and not tails.corners and tails.holdout is False
    dth, dmu = _draws(tails, mu_c=1.0)  # far from 0: the clip at 0 never bites
    for x, sigma in ((dth, sizes.theta_sigma), (dmu, sizes.mu_sigma)):
        beyond = np.mean(np.abs(x) > TRUNCATE_SIGMA * sigma)
        assert 0.040 < beyond < 0.051  # a normal leaves 4.55 % beyond 2 sigma
        assert abs(np.std(x) / sigma - 1.0) < 0.02
    dth, dmu = _draws(base, mu_c=1.0)
    assert np.abs(dth).max() <= TRUNCATE_SIGMA * base.perturbation.theta_sigma
    assert np.abs(dmu).max() <= TRUNCATE_SIGMA * base.perturbation.mu_sigma
    # the 2-sigma cut leaves a spread of about 0.88 sigma
    assert abs(np.std(dth) / base.perturbation.theta_sigma - 0.880) < 0.02


def test_untruncated_trials_have_a_seed_and_count_of_their_own():
    chosen = VerifySettings(seed=11, trials=20)
    held = chosen.held_out()
    tails = chosen.untruncated(52)
    assert tails.seed not in (chosen.seed, held.seed)
    assert tails.seed == int(np.random.SeedSequence([11, UNTRUNCATED_STREAM]).generate_state(1)[0])
    assert UNTRUNCATED_STREAM != HOLDOUT_STREAM
    rows = trial_inputs({"s1": (0.0, 10.0), "s2": (90.0, 12.0)}, (0.1, 0.3), 2, tails)
    assert [r[0].size for r in rows] == [52, 52]  # random trials only: the box has no corners
    assert all(np.all((r[2] >= 0.1) & (r[2] <= 0.3)) for r in rows)  # a friction range stays uniform


@pytest.fixture(scope="module")
def planned(tmp_path_factory):
    """``pinfeed plan`` of a triangle on two pins, depth 2, few trials (the point
    rule): its config, plan file and what it printed."""
    from pipeline.cli import main
    from pipeline.config import load_config
    root = tmp_path_factory.mktemp("tails")
    config = load_config(None)
    config["verify"].update(trials=10, rule="point")
    config["planner"]["dynamic"]["depth"] = 0
    (root / "config.yaml").write_text(yaml.safe_dump(config))
    out = root / "tri.json"
    printed = io.StringIO()
    with contextlib.redirect_stdout(printed):
        code = main(["plan", "--config", str(root / "config.yaml"), "--vertices", VERTICES, "--name", "tri",
                     "--catalog", str(root / "cat"), "--depth", "2", "--pins=7.5,27.5",
                     "--mu-c", f"{MU_C:g}", "--out", str(out)])
    assert code == 0
    return config, json.loads(out.read_text()), printed.getvalue()


def test_the_plan_file_states_the_truncation_and_keeps_the_untruncated_record(planned):
    _, plan_file, _ = planned
    entry = plan_file["tight"][0]
    rec = entry["recommended"]["verification"]
    assert rec["truncation_sigma"] == TRUNCATE_SIGMA
    u = rec["untruncated"]
    for key in ("trials", "in_one_set", "lower_bound", "width_deg", "width_interval_deg", "orients", "seed"):
        assert key in u
    assert u["trials"] >= rec["trials"]  # at least as many as the held-out trials
    assert u["seed"] != rec["seed"] and u["normal"] == ["theta", "mu_c"]
    for plan in entry["plans"][1:] + entry["rejected"]:  # one replay: the recommended plan only
        assert plan["verification"]["truncation_sigma"] == TRUNCATE_SIGMA
        assert "untruncated" not in plan["verification"]


def _narrowest(theta, k, period):
    """Width of the narrowest arc holding ``k`` of the orientations (deg)."""
    x = np.sort(np.mod(theta, period))
    x2 = np.concatenate([x, x + period])
    return float(np.min(x2[k - 1:k - 1 + x.size] - x))


def test_an_own_replay_of_untruncated_draws_agrees_with_the_stored_record(planned):
    config, plan_file, _ = planned
    entry = plan_file["tight"][0]
    plan = entry["recommended"]
    u = plan["verification"]["untruncated"]
    v = config["verify"]
    n_states = len(entry["initial_states"])
    per_state = u["trials"] // n_states
    rng = np.random.default_rng(u["seed"])
    finals, jammed = [], 0
    for state in entry["initial_states"].values():  # the draws in the order verification makes them
        th = state["theta"] + rng.normal(0.0, v["theta_sigma"], per_state)
        yc = state["y_c"] + rng.uniform(-v["y_halfwidth"], v["y_halfwidth"], per_state)
        mu = np.maximum(0.0, MU_C + rng.normal(0.0, v["mu_sigma"], per_state))
        offs = rng.uniform(-v["pin_halfwidth"], v["pin_halfwidth"], (per_state, len(plan["pins"])))
        tf, _, jam, _ = replay(_part(), plan["pin_heights_mm"], [0.0] * len(plan["pins"]), th, yc, mu, offs,
                               config["sweep"]["pin_radius"], "minpower")
        finals.append(tf[jam == ""])
        jammed += int(np.sum(jam != ""))
    finals = np.concatenate(finals)
    order = entry["symmetry_order"]
    need = math.ceil(v["required"] * u["trials"] - 1e-9)
    assert u["trials"] == n_states * per_state and u["jammed"] == jammed
    assert u["width_deg"] == pytest.approx(_narrowest(finals, need, 360.0 / order), abs=1e-3)
    lo, hi = u["width_interval_deg"]
    assert lo <= u["width_deg"] + 1e-9 and hi >= lo


def _part():
    from pipeline.parts.part import Part
    return Part.from_vertices([[float(c) for c in p.split(",")] for p in VERTICES.split()], name="tri")


def test_pinfeed_plan_prints_the_truncation_and_the_untruncated_line(planned):
    _, plan_file, printed = planned
    rec = plan_file["tight"][0]["recommended"]
    u = rec["verification"]["untruncated"]
    lines = printed.splitlines()
    claims = [k for k, ln in enumerate(lines) if ln.strip().startswith("claim:")]
    assert claims and len(claims) == len(plan_file["tight"][0]["plans"])  # one claim per plan
    # Each claim is followed by its trials, which say where the normals are cut.
    assert all(lines[k + 1].strip().startswith("its trials: held-out trials") and
               "normals cut at 2 sigma" in lines[k + 1] for k in claims)
    untruncated = [k for k, ln in enumerate(lines) if "untruncated normals" in ln]
    assert len(untruncated) == 1 and untruncated[0] == claims[0] + 2  # under the recommended plan's claim
    line = lines[untruncated[0]]
    assert line.strip().startswith("beside it: untruncated normals (theta, mu_c not cut; random draws only, "
                                   "no box corners)")
    assert f"{u['in_one_set']}/{u['trials']} in one arc of 10 deg" in line
    assert rec["claim"]["untruncated"]["box_corners"] is False


def test_the_untruncated_line_says_a_friction_range_stays_uniform():
    record = {"normal": ["theta"], "in_one_set": 990, "trials": 996, "tolerance_deg": 10.0,
              "lower_bound": 0.9884, "confidence": 0.95, "width_deg": 8.44, "width_interval_deg": [8.1, 8.9],
              "orients": False, "point_rule": True}
    line = describe_untruncated(record)
    assert line.startswith("untruncated normals (theta not cut at 2 sigma; mu_c uniform over its range; random "
                           "draws only, no box corners): "
                           "990/996 in one set of 10 deg, at least 98.84 % with 95 % confidence; width 8.4 deg "
                           "(95 % bootstrap interval 8.1-8.9 deg)")
    assert line.endswith("clears the point rule but not its confidence bound")


def test_the_report_shows_the_untruncated_width_beside_the_claimed_one(planned):
    from pipeline.present.report import _width_cell
    _, plan_file, _ = planned
    plan = plan_file["tight"][0]["recommended"]
    claim, u = plan["claim"], plan["verification"]["untruncated"]
    cell = _width_cell(plan)
    assert cell.split(">", 1)[1].startswith(html.escape(claim["statement"]))
    lo, hi = u["width_interval_deg"]
    assert "normals cut at 2 sigma" in cell
    assert (f"untruncated normals (random draws only, no box corners): width {u['width_deg']:.1f} deg "
            f"({lo:.1f}-{hi:.1f}), {u['in_one_set']}/{u['trials']} in one set") in cell
