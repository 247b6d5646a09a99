"""Sign matrix, scores and classification of force profiles (building blocks of issue 5)."""
import json

import numpy as np
import pytest

from cli_runs import run_cli
from pipeline.errors import PinfeedError
from pipeline.sensing.profiles import (Profile, Sensor, classify, measure, profile_from_rollout, read_profile_csv,
                              score, sensor_groups, sign_matrix)

S = Sensor(window=1, regions=4, dead_zone=0.05, margin=2, rate_hz=100.0)


def _profile(fx, fy):
    t = np.arange(len(fx)) / S.rate_hz
    return Profile(t, np.asarray(fx, float), np.asarray(fy, float))


def test_sign_matrix_of_hand_made_profile():
    n = 40
    fx = np.concatenate([np.linspace(0, 1, n // 2), np.linspace(1, 0.2, n // 2)])  # up, then down
    fy = np.concatenate([-np.ones(n // 4), np.zeros(n // 2), np.ones(n // 4)])       # -, 0, 0, +
    m = sign_matrix(_profile(fx, fy), S)
    assert m.shape == (4, 4)
    assert m[0].tolist() == [1, 1, 1, 1]          # F_x positive throughout
    assert m[1].tolist() == [-1, 0, 0, 1]          # F_y: negative, zero, zero, positive
    assert m[2].tolist() == [1, 1, -1, -1]         # dF_x/dt: rising then falling
    assert m[1].dtype == np.int8


def test_sign_matrix_ignores_force_units():
    rng = np.random.default_rng(0)
    fx, fy = rng.normal(size=80).cumsum(), rng.normal(size=80).cumsum()
    a = sign_matrix(_profile(fx, fy), S)
    b = sign_matrix(_profile(9.81 * fx, 9.81 * fy), S)  # the same profile in other units
    assert (a == b).all()


def test_score_and_margin():
    ref = {"A": np.array([[1, 1], [0, -1]]), "B": np.array([[1, -1], [0, -1]]),
           "C": np.array([[-1, -1], [1, 1]])}
    v = classify(np.array([[1, 1], [0, -1]]), ref, margin=2)
    assert v["scores"] == {"A": 4, "B": 3, "C": 0}
    assert v["best"] == "A" and v["candidates"] == ["A", "B"] and not v["decided"]
    v = classify(np.array([[1, 1], [0, -1]]), ref, margin=1)
    assert v["decided"] and v["candidates"] == ["A"]
    assert score(ref["A"], ref["C"]) == 0


def test_profile_from_rollout_samples_at_the_sensor_rate():
    s = np.array([0.0, 10.0, 20.0, 20.0])  # mm of belt travel, last row: drop to zero
    fx = np.array([0.0, 1.0, 0.5, 0.0])
    fy = np.array([0.2, 0.2, 0.2, 0.0])
    sensor = Sensor(rate_hz=10.0, belt_speed=20.0)  # 1 s of contact, 10 Hz
    p = profile_from_rollout(s, fx, fy, sensor)
    assert p.t.tolist() == pytest.approx(np.arange(11) / 10.0)
    assert p.fx[5] == pytest.approx(1.0) and p.fx[-1] == pytest.approx(0.5)
    assert np.all(p.fy == pytest.approx(0.2))


def test_measured_profile_csv(tmp_path):
    good = tmp_path / "p.csv"
    good.write_text("time,Fx,Fy\n0.0,0.1,0.2\n0.01,0.3,0.1\n0.02,0.2,0.0\n")
    p = read_profile_csv(good)
    assert p.t.tolist() == pytest.approx([0.0, 0.01, 0.02]) and p.fx[1] == 0.3
    for text, message in (("0,1,2\n0,1,2\n", "time must increase"),
                          ("0,1,2\n0.1,x,2\n", "line 2: not three numbers"),
                          ("0,1\n0.1,1\n", "needs three columns"),
                          ("0,1,2\n", "at least two samples")):
        bad = tmp_path / "bad.csv"
        bad.write_text(text)
        with pytest.raises(PinfeedError, match=message):
            read_profile_csv(bad)
    with pytest.raises(PinfeedError, match="no profile file"):
        read_profile_csv(tmp_path / "missing.csv")


def test_moments_at_the_sensor():
    p = _profile([1.0, 2.0], [0.5, -1.0])
    mx, my = p.moments(30.0)
    # M = r x F with the contact 30 mm below the sensor: r = (0, 0, -30).
    assert mx.tolist() == [15.0, -30.0] and my.tolist() == [-30.0, -60.0]


def test_score_table_groups_a_state_that_touches_apart_from_ones_that_miss():
    # A pin high above the asymmetric triangle's first two resting states misses
    # them (an all-zero sign matrix) and pushes the third: noise-free and
    # unperturbed, the sensor must tell the third apart and only the third.
    from pipeline.parts.part import Part
    from pipeline.sensing.profiles import score_table
    part = Part.from_vertices([(0, 0), (60, 0), (15, 35)], name="asym")
    states = {f"state {k}": {"theta": th, "y_c": y}
              for k, (th, y) in enumerate(part.stable_states(), start=1)}
    quiet = Sensor(noise_sigma=0.0, bias_x=0.0, bias_y=0.0)
    still = {"theta_sigma": 0.0, "y_halfwidth": 0.0, "mu_sigma": 0.0, "pin_halfwidth": 0.0}
    tab = score_table(part, states, 42.5, 0.15, 3.0, "minpower", quiet, trials=2, perturb=still)
    assert sorted(map(sorted, tab["groups"])) == [["state 1", "state 2"], ["state 3"]]
    assert tab["mean_scores"]["state 3"]["state 3"] == 40
    assert tab["mean_scores"]["state 1"]["state 2"] == 40  # two misses look the same
    assert tab["mean_scores"]["state 1"]["state 3"] < 40 - quiet.margin


# ---------------------------------------------------------------- sign matrix on hand-made profiles


def _timed(fx, fy, rate=200.0):
    fx = np.asarray(fx, float)
    return Profile(np.arange(fx.size) / rate, fx, np.asarray(fy, float))


def test_sign_matrix_of_sinusoids_over_one_period():
    # Over one period split into 4 regions: F_x = 1 + 0.5 sin stays positive, rises in
    # the first and last quarter and falls in between; F_y = sin is +, +, -, - and
    # changes by +1, -1, -1, +1 across the quarters.
    n = 400
    phase = 2 * np.pi * (np.arange(n) + 0.5) / n
    sensor = Sensor(window=1, regions=4, dead_zone=0.05, rate_hz=200.0)
    m = sign_matrix(_timed(1 + 0.5 * np.sin(phase), np.sin(phase)), sensor)
    assert m.tolist() == [[1, 1, 1, 1], [1, 1, -1, -1], [1, -1, -1, 1], [1, -1, -1, 1]]


def test_gradient_dead_zone_is_a_force_change_relative_to_the_peak():
    # A ramp from 1 down to 1 - 10 c over 10 regions changes by c per region: a gradient
    # sign exactly when c exceeds dead_zone x peak |F| (peak 1 here), at any sample rate.
    sensor = Sensor(window=1, regions=10, dead_zone=0.05)
    for rate, c, want in ((200.0, 0.03, 0), (200.0, 0.08, -1), (1000.0, 0.03, 0), (1000.0, 0.08, -1)):
        s = Sensor(**dict(sensor.to_dict(), rate_hz=rate))
        n = int(rate * 2)
        fx = 1.0 - 10 * c * np.arange(n) / n
        m = sign_matrix(_timed(fx, np.zeros(n), rate), s)
        assert m[2].tolist() == [want] * 10, (rate, c, m[2])
        assert m[1].tolist() == [0] * 10 and m[3].tolist() == [0] * 10


def test_slip_off_spike_does_not_move_the_dead_zone_of_other_regions():
    # The hypersensitivity this module fixes: the force falls steadily, then drops
    # sharply in the last samples (the part slipping off the pin). However big the
    # drop, regions 1-9 read 'falling'; only the last region sees the spike.
    n = 400
    base = 1.0 - 0.8 * np.arange(n) / n  # 0.08 per region: above the dead zone
    rows = []
    for window in (1, 9, 25):
        for drop in (0.0, 0.1, 0.5, 0.9):
            fx = base.copy()
            fx[-3:] -= drop * np.array([0.3, 0.7, 1.0])
            rows.append(sign_matrix(_timed(fx, 0.3 * np.ones(n)), Sensor(window=window))[2].tolist())
    assert all(r[:9] == [-1] * 9 for r in rows), rows


def test_short_contact_is_not_smoothed_across_regions():
    # 20 samples, 10 regions, a 25-sample window: F_y flips sign at mid-contact and the
    # sign matrix still sees it (the window is capped at one region's samples).
    fy = np.r_[np.ones(10), -np.ones(10)]
    m = sign_matrix(_timed(np.ones(20), fy), Sensor(window=25, regions=10))
    assert m[1].tolist() == [1] * 5 + [-1] * 5


def test_sensor_groups_are_connected_components():
    labels = ["a", "b", "c"]
    # a~c and b~c are not told apart (only a/b are): one group, even though a and b differ.
    assert sensor_groups(labels, [("a", "b")]) == [["a", "b", "c"]]
    assert sensor_groups(labels, [("a", "b"), ("b", "c")]) == [["a", "c"], ["b"]]
    assert sensor_groups(labels, [("a", "b"), ("b", "c"), ("a", "c")]) == [["a"], ["b"], ["c"]]
    assert sensor_groups(labels, []) == [["a", "b", "c"]]


# ---------------------------------------------------------------- accuracy on noisy profiles

ACCURACY_FLOOR = 0.8  # stated in the README


def test_classifier_on_noisy_hand_made_profiles():
    # Three made-up states whose F_y differ in phase; measurements add bias and noise
    # of 5 % of the peak force per sample. The verdict must be right and decided
    # in at least ACCURACY_FLOOR of the trials and never wrong.
    rate, n = 200.0, 500
    phase = np.linspace(0, 2 * np.pi, n)
    refs = {"A": _timed(1 - 0.5 * phase / np.pi, 0.6 * np.sin(phase), rate),
            "B": _timed(1 - 0.5 * phase / np.pi, 0.6 * np.sin(phase + np.pi / 2), rate),
            "C": _timed(1 - 0.5 * phase / np.pi, 0.6 * np.sin(phase + np.pi), rate)}
    sensor = Sensor(rate_hz=rate, noise_sigma=0.05, bias_x=0.03, bias_y=-0.02)
    ref_s = {k: sign_matrix(p, sensor) for k, p in refs.items()}
    rng = np.random.default_rng(5)
    right = wrong = 0
    for truth, prof in refs.items():
        for _ in range(30):
            v = classify(sign_matrix(measure(prof, sensor, rng), sensor), ref_s, sensor.margin)
            right += v["decided"] and v["best"] == truth
            wrong += v["decided"] and v["best"] != truth
    assert right >= ACCURACY_FLOOR * 90 and wrong == 0, (right, wrong)


def test_score_table_accuracy_on_the_asymmetric_triangle():
    # The asymmetric triangle at y = 25 mm (d = 0.36, 0.34, 0.18 for its resting
    # states), the config's sensor and input perturbations: synthetic noisy
    # measurements are classified right and decided in at least ACCURACY_FLOOR of
    # the trials, wrongly in at most 5 %, and every pair of states is told apart in most trials.
    from pipeline.config import load_config
    from pipeline.parts.part import Part
    from pipeline.sensing.profiles import PERTURB_DEFAULTS, score_table
    cfg = load_config()["sensing"]
    part = Part.from_vertices([(0, 0), (60, 0), (15, 35)], name="asym")
    states = {f"state {k}": {"theta": th, "y_c": y} for k, (th, y) in enumerate(part.stable_states(), 1)}
    tab = score_table(part, states, 25.0, 0.15, 3.0, "minpower", Sensor.from_config(cfg["sensor"]),
                      trials=20, perturb=dict(PERTURB_DEFAULTS, **cfg["perturb"]), seed=cfg["seed"])
    assert tab["accuracy"] >= ACCURACY_FLOOR and tab["wrong"] <= 0.05, (tab["accuracy"], tab["wrong"])
    assert tab["elements"] == 40 and len(tab["verdicts"]) == 60
    for sim in states:  # each measured column scores best against its own simulated row
        col = {row: tab["mean_scores"][row][sim] for row in states}
        assert max(col, key=col.get) == sim, col
    # Every pair is told apart most of the time: trials of one state mostly exclude
    # the other from the verdict's candidates. (Not the 90 % grouping threshold: at
    # 20 trials a pair sits near it, and kernel changes at the 1e-4 deg level or
    # another seed move it across; the sensor planner's end-to-end replay is the
    # check that matters there.)
    for truth in states:
        runs = [v for v in tab["verdicts"] if v["truth"] == truth]
        for other in states:
            if other != truth:
                excluded = sum(other not in v["candidates"] for v in runs) / len(runs)
                assert excluded >= 0.6, (truth, other, excluded)


# ---------------------------------------------------------------- planning with the sensor


def _stored_plan(finals: dict, pins=("P1",), heights=(10.0,), n_sets=None):
    """A plan shaped like a stored tight plan: per state, one branch per final arc."""
    from pipeline.planning.core.arcs import merge_arcs
    step = {"pin": pins[-1], "y_pin": heights[-1], "v_pin": 0.0, "d_range": [0.2, 0.3]}
    branches = {lab: [[dict(step, band={"start": s, "width": 5.0})] for s in starts]
                for lab, starts in finals.items()}
    sets = merge_arcs([(s, 5.0) for starts in finals.values() for s in starts])
    return {"pins": list(pins), "pin_heights_mm": list(heights), "pin_speeds": [0.0] * len(pins),
            "n_final_sets": len(sets) if n_sets is None else n_sets,
            "final_sets": [{"start": a, "width": w} for a, w in sets], "initial_states": branches}


def test_sensor_ranking_counts_final_sets_per_verdict():
    from pipeline.sensing.sensor_plan import group_arcs, sensor_rank_key, verdict_outcome, worst_sets
    groups = [["s1"], ["s2", "s3"]]
    a = _stored_plan({"s1": [10.0], "s2": [100.0], "s3": [100.0]})  # 2 sets, 1 per verdict
    b = _stored_plan({"s1": [10.0], "s2": [10.0], "s3": [200.0]})  # 2 sets, 2 for s2/s3
    c = _stored_plan({"s1": [10.0], "s2": [10.0], "s3": [10.0]})  # 1 set
    d = _stored_plan({"s1": [10.0, 250.0], "s2": [100.0], "s3": [100.0]})  # s1 branches
    assert [worst_sets(p, groups) for p in (a, b, c, d)] == [1, 2, 1, 2]
    # Worst sets per verdict first, then the stored rank (the list's order).
    stored = [b, d, a, c]
    ranked = sorted(range(4), key=lambda k: sensor_rank_key(stored[k], k, groups))
    assert [stored[k] is p for k, p in zip(ranked, (a, c, b, d))] == [True] * 4
    assert group_arcs(b, ["s2", "s3"]) == [(10.0, 5.0), (200.0, 5.0)]
    finals = {lab: group_arcs(a, [lab]) for lab in ("s1", "s2", "s3")}
    assert verdict_outcome(["s2", "s3"], "s3", finals) == "known"
    assert verdict_outcome(["s2"], "s1", finals) == "wrong"
    assert verdict_outcome(["s1", "s2"], "s1", finals) == "ambiguous"
    # Fixed pins and a sensor rank above moving pins that reach no fewer sets per verdict.
    m = _stored_plan({"s1": [10.0], "s2": [10.0], "s3": [10.0]}, pins=("P1", "P2v+2"), heights=(10.0, 5.0))
    m["pin_speeds"] = [0.0, 2.0]
    assert sensor_rank_key(a, 5, groups) < sensor_rank_key(m, 0, groups)
    assert sensor_rank_key(m, 0, groups) < sensor_rank_key(b, 1, groups)
    # A part with 2-fold symmetry: sets 180 degrees apart are one orientation.
    e = _stored_plan({"s1": [10.0], "s2": [190.0], "s3": [190.0]})
    assert worst_sets(e, [["s1", "s2", "s3"]], order=1) == 2
    assert worst_sets(e, [["s1", "s2", "s3"]], order=2) == 1


def test_friction_is_resolved_once_for_the_profiles():
    from pipeline.sensing.sensor_plan import sensing_frictions
    assert sensing_frictions({"mu_c": [0.1, 0.3]}) == ((0.1, 0.3), pytest.approx(0.2))
    assert sensing_frictions({"mu_c": 0.15}) == (0.15, 0.15)


def test_synthetic_measurement_draws_a_friction_range_uniformly(monkeypatch):
    # Over a planned range the measurements' friction spreads over the whole range
    # (as verification draws it), not around one value.
    from pipeline.sensing import profiles as sensing

    class Drawn(Exception):
        pass

    seen = []

    def record(part, theta, y_c, y_pin, mu_c, pin_radius, model):
        seen.append(mu_c)
        raise Drawn

    monkeypatch.setattr(sensing, "first_pin_rollout", record)
    rng = np.random.default_rng(0)
    for _ in range(200):
        with pytest.raises(Drawn):
            sensing.synthetic_measurement(None, {"theta": 0.0, "y_c": 10.0}, 20.0, (0.1, 0.3), 3.0,
                                          "minpower", Sensor(), sensing.PERTURB_DEFAULTS, rng)
    assert 0.1 <= min(seen) < 0.12 and 0.28 < max(seen) <= 0.3


TRI = "0,0 60,0 15,35"  # the asymmetric triangle
TRI_PLAN = ["--depth", "2", "--pins=7.5,27.5", "--mu-c", "0", "--dynamic-depth", "0"]


@pytest.fixture(scope="module")
def stored_tri(tmp_path_factory):
    """Tight plans of the asymmetric triangle on a two-pin grid, stored by
    ``pinfeed plan --out`` (as a user or the plan stage stores them): two pins
    orient it ("full"); one pin cannot (depth 1, "partial": a feeder whose
    fixed pins leave several sets, each within the tolerance)."""
    from pipeline.cli import main
    tmp = tmp_path_factory.mktemp("sense")
    cat, full, partial = tmp / "cat", tmp / "full", tmp / "partial"
    for folder, depth in ((full, "2"), (partial, "1")):
        path = folder / "plans" / "tri.json"
        plan_args = [a if a != "2" else depth for a in TRI_PLAN]
        assert main(["plan", "--vertices", TRI, "--name", "tri", "--catalog", str(cat), *plan_args,
                     "--out", str(path), "--json"]) == 0
    assert main(["catalog", "index", "--catalog", str(cat)]) == 0  # refinement shards only
    full_entry = json.loads((full / "plans" / "tri.json").read_text())["tight"][0]
    partial_entry = json.loads((partial / "plans" / "tri.json").read_text())["tight"][0]
    assert full_entry["orients"] and full_entry["recommended"]["n_final_sets"] == 1
    assert not partial_entry["orients"] and partial_entry["recommended"]["n_final_sets"] > 1
    return {"catalog": cat, "full": full, "partial": partial}


def _sense_config(**sensing):
    from pipeline.config import load_config
    cfg = load_config()
    cfg["sensing"].update(trials=20, **sensing)
    return cfg


@pytest.fixture(scope="module")
def sensed(stored_tri):
    """The sensing stage on both stored files, written where classify finds them.

    Pairs count as told apart at 75 % of the trials, not the config's 90 %: on
    this grid states 2 and 3 are told apart at the second pin in close to (at
    60 trials, under) 90 % of the trials, so at 90 % the grouping turned on
    the seed and the random stream (at 20 trials, seed 2 of the old draws and
    seed 1 of the verify-stage draws merged them; at 75 % seeds 1 to 5 at 20
    and 60 trials all tell the three states apart)."""
    from pipeline.maps.io import write_json
    from pipeline.sensing.sensor_plan import sense_part
    out = {}
    for kind in ("full", "partial"):
        res = sense_part(stored_tri[kind] / "plans" / "tri.json", _sense_config(apart_fraction=0.75),
                         log=lambda *a: None)
        write_json(res, stored_tri[kind] / "sensing" / "tri.json")
        out[kind] = res
    return out


def test_one_set_plan_needs_no_sensor_and_the_table_is_still_reported(stored_tri, sensed):
    stored = json.loads((stored_tri["full"] / "plans" / "tri.json").read_text())["tight"][0]
    res = sensed["full"]
    assert res["plan"] == stored["recommended"] and res["plan_rank"] == 1
    assert not res["sensor_needed"] and "not needed" in res["note"]
    assert res["known_for_every_state"] and res["worst_sets"] == 1
    assert res["mu_c"] == stored["mu_c"] and res["mu_c_profiles"] == stored["mu_c"]
    assert res["first_pin"] == stored["recommended"]["pins"][0]
    assert res["y_pin"] == stored["recommended"]["pin_heights_mm"][0]
    table = res["score_table"]
    assert sorted(s for g in table["groups"] for s in g) == sorted(stored["initial_states"])
    assert set(table["reference_signs"]) == set(stored["initial_states"])


def test_sensor_plan_is_a_stored_candidate_not_a_new_search(stored_tri, sensed):
    # The stored file lacks the one-set plan that a search on this grid finds
    # first (the full file's recommendation): a planner that searched again, or
    # ignored the stored file, would return it.
    full = json.loads((stored_tri["full"] / "plans" / "tri.json").read_text())["tight"][0]
    stored = json.loads((stored_tri["partial"] / "plans" / "tri.json").read_text())["tight"][0]
    res = sensed["partial"]
    assert res["plan"] == stored["plans"][res["plan_rank"] - 1]
    assert res["plan"]["pins"] != full["recommended"]["pins"]
    assert res["sensor_needed"] and res["without_sensor"]["pins"] == stored["plans"][0]["pins"]
    # The sensor tells the states apart at the chosen first pin: fewer sets per verdict.
    assert res["worst_sets"] < res["without_sensor"]["n_final_sets"]
    assert {f["pin"] for f in res["first_pins"]} == {p["pins"][0] for p in stored["plans"]}


def test_final_sets_per_verdict_hold_in_full_rollout_replay(sensed):
    # Every state of a verdict's group, replayed past the sensor plan's pins by
    # perturbed full rollouts (the verify stage's sizes, random trials and every
    # corner of the box), ends in that verdict's final sets.
    from pipeline.parts.part import Part
    from pipeline.planning.core.arcs import in_arc
    from pipeline.planning.claims.replay import replay
    from pipeline.planning.claims.trials import corner_inputs, perturbed_batch
    from pipeline.planning.core.settings import VerifySettings
    res = sensed["partial"]
    kernel = _sense_config()["sweep"]["kernel"]  # the verify stage's rollout settings
    part = Part.from_vertices(res["part"]["vertices"])
    heights, speeds = res["plan"]["pin_heights_mm"], res["plan"]["pin_speeds"]
    rng = np.random.default_rng(7)
    for group in res["groups"]:
        for label in group["states"]:
            st = res["initial_states"][label]
            sizes = VerifySettings().perturbation
            draws = [perturbed_batch(st["theta"], st["y_c"], res["mu_c"], len(heights), sizes, rng, 100),
                     corner_inputs(st["theta"], st["y_c"], res["mu_c"], len(heights), sizes)]
            th, yc, mu, offs = (np.concatenate(x) for x in zip(*draws))
            theta, _, jam, _ = replay(part, heights, speeds, th, yc, mu, offs, res["pin_radius"],
                                      res["model"], kernel["ds_max"], kernel["tol"])
            assert not any(jam), label
            inside = np.zeros(theta.size, bool)
            for s in group["final_sets"]:
                inside |= in_arc(theta, s["start"], s["width"], 1e-6)
            assert inside.all(), (label, theta[~inside])
    rows = res["verification"]["rows"]  # the stage's own end-to-end check with the sensor
    assert all(r["trials"] == 20 and r["right"] + r["wrong"] + r["ambiguous"] + r["jammed"] == 20
               for r in rows.values())
    assert all(r["wrong"] == 0 and r["jammed"] == 0 for r in rows.values())


def test_sensor_stage_without_a_verified_plan(stored_tri, tmp_path):
    from pipeline.sensing.sensor_plan import sense_part
    stored = json.loads((stored_tri["partial"] / "plans" / "tri.json").read_text())
    stored["tight"][0].update(plans=[], recommended=None, warning="no plan passed verification: test")
    path = tmp_path / "plans" / "tri.json"
    path.parent.mkdir()
    path.write_text(json.dumps(stored))
    res = sense_part(path, _sense_config(), log=lambda *a: None)
    assert not res["found"] and "no plan passed verification: test" in res["note"]
    with pytest.raises(PinfeedError, match="no stored plan at mu_c 0.2; stored: 0"):
        sense_part(path, _sense_config(), friction="0.2")


# ---------------------------------------------------------------- pinfeed sense classify


def _write_csv(path, profile, scale=1.0, t0=0.0, header=True, extra=True):
    with open(path, "w") as fh:
        if header:
            fh.write("time_s,Fx,Fy" + (",Mz" if extra else "") + "\n")
        for t, x, y in zip(profile.t, profile.fx, profile.fy):
            row = f"{float(t + t0)!r},{float(x * scale)!r},{float(y * scale)!r}"
            fh.write(row + (",0.5\n" if extra else "\n"))
    return path


def _classify_args(stored_tri, kind, *extra):
    return ["sense", "classify", "--catalog", str(stored_tri["catalog"]), "--results",
            str(stored_tri[kind]), *extra]


def test_cli_classify_reads_a_profile_and_names_the_final_orientation(stored_tri, sensed, tmp_path, capsys):
    # The noise-free simulated profile of one state, written in other units, with a
    # time offset and an extra column, must score 40/40 against that state. The
    # part is known from the stored results (the catalog holds refinements only).
    from pipeline.parts.part import Part
    from pipeline.sensing.profiles import reference_profiles
    from pipeline.sensing.sensor_plan import final_for_verdict
    res = sensed["partial"]
    part = Part.from_vertices(res["part"]["vertices"])
    sensor = Sensor.from_config(res["sensor"])
    prof = reference_profiles(part, res["initial_states"], res["y_pin"], res["mu_c_profiles"],
                              res["pin_radius"], res["model"], sensor)["state 2"]
    csv_path = _write_csv(tmp_path / "state2.csv", prof, scale=9.81, t0=12.5)
    argv = _classify_args(stored_tri, "partial", "--part", "tri", "--profile", str(csv_path))
    code, out, err = run_cli(capsys, argv + ["--json"])
    assert code == 0, err
    got = json.loads(out)
    assert {"part", "y_pin", "y_pin_source", "scores", "best", "candidates", "decided", "margin",
            "elements", "measured_signs", "final_sets", "final_known", "sensor_plan", "mu_c",
            "mu_c_profiles"} <= set(got)
    assert got["y_pin"] == res["y_pin"] and got["elements"] == 40 and got["sensor_plan"] == res["plan"]["pins"]
    assert got["mu_c"] == res["mu_c"] and got["mu_c_profiles"] == res["mu_c_profiles"]
    assert got["scores"]["state 2"] == 40 and "state 2" in got["candidates"]
    assert got["final_sets"] == final_for_verdict(res, got["candidates"])
    assert got["final_known"] == (len(got["final_sets"]) == 1)
    code, out, err = run_cli(capsys, argv)
    assert code == 0, err
    assert "verdict:" in out and "state 2: 40" in out and "final orientation" in out
    assert "profiles simulated at 0" in out
    # Another pin: no final orientation from the stored sensor plan.
    code, out, err = run_cli(capsys, argv + ["--y-pin", "-2.5", "--json"])
    assert code == 0, err
    got = json.loads(out)
    assert got["y_pin"] == -2.5 and got["final_sets"] is None and got["final_known"] is None


def _one_line_error(code, err, *words):
    assert code == 2, (code, err)
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("pinfeed: error:"), err
    for w in words:
        assert w in lines[0], (w, err)


def test_cli_classify_bad_input(stored_tri, sensed, tmp_path, capsys):
    good = _write_csv(tmp_path / "ok.csv", _timed(np.linspace(1, 0.2, 400), 0.3 * np.ones(400)),
                      header=False, extra=False)
    base = _classify_args(stored_tri, "partial")
    _one_line_error(*run_cli(capsys, base + ["--part", "tri", "--profile",
                                             str(tmp_path / "none.csv")])[::2], "no profile file")
    bad = tmp_path / "bad.csv"
    bad.write_text("t,fx,fy\n0,1,2\n0.01,abc,2\n")
    _one_line_error(*run_cli(capsys, base + ["--part", "tri", "--profile", str(bad)])[::2],
                    "line 3", "not three numbers")
    _one_line_error(*run_cli(capsys, base + ["--part", "nope", "--profile", str(good)])[::2],
                    "unknown part 'nope'", "pinfeed catalog list")
    _one_line_error(*run_cli(capsys, ["sense", "classify", "--part", "tri"])[::2], "--profile")
    old = stored_tri["partial"] / "old"  # a sensing result of the format before issue 11
    (old / "sensing").mkdir(parents=True, exist_ok=True)
    before = {k: v for k, v in sensed["partial"].items() if k not in ("mu_c_profiles", "symmetry_order")}
    (old / "sensing" / "tri.json").write_text(json.dumps(before))
    argv = ["sense", "classify", "--catalog", str(stored_tri["catalog"]), "--results", str(old),
            "--part", "tri", "--profile", str(good)]
    _one_line_error(*run_cli(capsys, argv)[::2], "not a pinfeed sensing result", "re-run the workflow")


def test_cli_classify_pin_from_the_stored_plan_or_y_pin(stored_tri, sensed, tmp_path, capsys):
    # No sensor plan stored: the sensor pin is the recommended tight plan's first
    # pin; with no verified plan either, --y-pin is required.
    import shutil
    good = _write_csv(tmp_path / "ok.csv", _timed(np.linspace(1, 0.2, 400), 0.3 * np.ones(400)))
    results = tmp_path / "results"
    shutil.copytree(stored_tri["full"] / "plans", results / "plans")
    argv = ["sense", "classify", "--part", "tri", "--profile", str(good), "--catalog",
            str(stored_tri["catalog"]), "--results", str(results)]
    code, out, err = run_cli(capsys, argv + ["--json"])
    assert code == 0, err
    got = json.loads(out)
    rec = json.loads((results / "plans" / "tri.json").read_text())["tight"][0]["recommended"]
    assert got["y_pin"] == rec["pin_heights_mm"][0] and got["first_pin"] == rec["pins"][0]
    assert "recommended tight plan" in got["y_pin_source"] and got["final_sets"] is None
    stored = json.loads((results / "plans" / "tri.json").read_text())
    stored["tight"][0].update(plans=[], recommended=None)
    (results / "plans" / "tri.json").write_text(json.dumps(stored))
    _one_line_error(*run_cli(capsys, argv)[::2], "--y-pin", "pinfeed plan --part tri")
    code, out, err = run_cli(capsys, argv + ["--y-pin", "27.5", "--json"])
    assert code == 0, err
    assert json.loads(out)["final_sets"] is None


def test_cli_module_entry_point():
    import subprocess
    import sys
    from pathlib import Path
    root = Path(__file__).resolve().parents[2]
    run = subprocess.run([sys.executable, "-m", "pipeline.cli", "sense", "classify", "--help"], cwd=root,
                         capture_output=True, text=True, timeout=120)
    assert run.returncode == 0 and "time (s), F_x, F_y" in run.stdout


def test_sensing_figures_are_written(sensed, tmp_path):
    from pipeline.present.figures.sensing import sensing_figures
    prof, scores = sensing_figures(sensed["partial"], tmp_path / "profiles.png", tmp_path / "scores.png")
    for path in (prof, scores):
        assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and path.stat().st_size > 10_000
