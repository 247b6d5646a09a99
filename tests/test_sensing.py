"""Sign matrix, scores and classification of force profiles (building blocks of issue 5)."""
import numpy as np
import pytest

from pipeline.errors import PinfeedError
from pipeline.sensing import (Profile, Sensor, classify, profile_from_rollout, read_profile_csv,
                              score, sign_matrix)

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
    from pipeline.parts import Part
    from pipeline.sensing import score_table
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
