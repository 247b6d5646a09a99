"""``pinfeed support fit`` (issue 25): pushes generated from a known support
(rollouts through the public API) are explained by the fitted support, which
recovers every leg (the light one too) and predicts held-out pushes; noisy
pushes still beat uniform pressure by far and pin down the heavy leg; the
search's feasibility helpers; the CSV and every bad input."""
import json

import numpy as np
import pytest

from cli_runs import run_cli

from pipeline.errors import PinfeedError
from pipeline.maps import simulate
from pipeline.maps.support_fit import (Pushes, _into_outline, _nearest_weights, fit_support,
                                       read_pushes, statics_weights)
from pipeline.parts.part import Part
from pipeline.parts.support import boundary_distance, point_support

TRIANGLE = Part.from_vertices([(0, 0), (60, 0), (15, 35)], "asym_triangle")
QUAD = Part.from_vertices([(0, 0), (50, 0), (45, 30), (5, 25)], "quad")
MU = 0.2


def _true_support(part, points):
    pts = np.array(points, float)
    return point_support(part, pts, statics_weights(pts))


def _pushes(part, support, n, seed, noise=0.0):
    """``n`` pushes that push the part, theta_f from a rollout on ``support``."""
    rng = np.random.default_rng(seed)
    th = rng.uniform(0.0, 360.0, 4 * n)
    d = rng.choice([-1.0, 1.0], 4 * n) * rng.uniform(0.15, 0.8, 4 * n)
    res = simulate.rollout_points(part, th, d, np.full(4 * n, MU), 3.0, "minpower", support=support)
    ok = np.flatnonzero(res["status"] == 0)[:n]
    measured = (res["theta_f"][ok] + rng.normal(0.0, noise, ok.size)) % 360.0
    return Pushes(th[ok], d[ok], measured, np.full(ok.size, np.nan))


def _held_out_rms(part, fitted, truth) -> float:
    held = _pushes(part, truth, 30, seed=99)
    pred = simulate.rollout_points(part, held.theta_i, held.d, np.full(len(held), MU), 3.0, "minpower",
                                   support=fitted)
    r = (pred["theta_f"] - held.theta_f + 180.0) % 360.0 - 180.0
    return float(np.sqrt(np.mean(r * r)))


@pytest.mark.parametrize("part, legs", [
    (TRIANGLE, [(-2.86, 1.27), (5.15, 5.15), (6.33, -4.51)]),
    (QUAD, [(-12.0, -6.0), (14.0, -4.0), (2.0, 9.0)]),
])
def test_fit_recovers_a_known_tripod(part, legs):
    truth = _true_support(part, legs)
    fit = fit_support(part, _pushes(part, truth, 40, seed=1), MU, 3.0, starts=16)
    d = fit.to_dict()
    assert d["rms_deg"] < 0.05 and d["uniform_rms_deg"] > 2.0
    assert _held_out_rms(part, fit.support, truth) < 0.1
    for leg, w in zip(truth.points, truth.weights):  # every leg, the light one (6 %) too
        assert np.hypot(*(fit.support.points - leg).T).min() < 0.02 * part.a, (leg, w)
    np.testing.assert_allclose(np.sort(fit.support.weights), np.sort(truth.weights), atol=0.01)
    assert np.hypot(*(fit.support.weights @ fit.support.points)) < 1e-6 * part.a  # statics


def test_fit_on_noisy_pushes_beats_uniform():
    truth = _true_support(TRIANGLE, [(-2.86, 1.27), (5.15, 5.15), (6.33, -4.51)])
    fit = fit_support(TRIANGLE, _pushes(TRIANGLE, truth, 40, seed=2, noise=1.0), MU, 3.0, starts=16)
    d = fit.to_dict()
    assert 0.6 < d["rms_deg"] < 1.3 and d["uniform_rms_deg"] > 8.0  # about the noise, not below it
    assert _held_out_rms(TRIANGLE, fit.support, truth) < 1.0
    heavy = int(np.argmax(truth.weights))  # the leg carrying 68 % of the weight is pinned down
    assert np.hypot(*(fit.support.points - truth.points[heavy]).T).min() < 0.05 * TRIANGLE.a


def test_statics_weights():
    w = statics_weights(np.array([[-1.0, -1.0], [2.0, -1.0], [-1.0, 2.0]]))
    np.testing.assert_allclose(w, [1 / 3, 1 / 3, 1 / 3], atol=1e-9)
    assert statics_weights(np.array([[1.0, 1.0], [2.0, 1.0], [1.0, 2.0]])) is None  # centroid outside


def test_search_feasibility_helpers():
    verts = np.asarray(TRIANGLE.vertices, float) - np.mean(TRIANGLE.vertices, axis=0)
    inside = np.array([[0.0, 0.0], [5.0, 1.0]])
    moved_pts, moved = _into_outline(verts, np.vstack([inside, [[30.0, -20.0]]]))
    np.testing.assert_allclose(moved_pts[:2], inside)  # points inside stay
    np.testing.assert_allclose(moved[:2], 0.0)
    assert moved[2] > 0 and boundary_distance(verts, moved_pts[2:])[0] < 1e-9  # onto the edge
    assert abs(moved[2] - np.hypot(*(moved_pts[2] - [30.0, -20.0]))) < 1e-9
    off = np.array([[1.0, 1.0], [2.0, 1.0], [1.0, 2.0]])  # cannot balance: weights still sum 1
    w = _nearest_weights(off)
    assert np.all(w >= 0) and abs(w.sum() - 1) < 1e-12 and np.hypot(*(w @ off)) > 1.0


def _csv(tmp_path, text, name="pushes.csv"):
    path = tmp_path / name
    path.write_text(text)
    return path


def test_cli_fit_and_csv(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    truth = _true_support(TRIANGLE, [(-2.86, 1.27), (5.15, 5.15), (6.33, -4.51)])
    p = _pushes(TRIANGLE, truth, 24, seed=3)
    rows = "\n".join(f"{a:.6f},{b:.6f},{c:.6f},{MU}" for a, b, c in zip(p.theta_i, p.d, p.theta_f))
    path = _csv(tmp_path, "# from the test\ntheta_i_deg,d,theta_f_deg,mu_c\n" + rows + "\n")
    back = read_pushes(path)
    np.testing.assert_allclose(back.theta_f, p.theta_f, atol=1e-6)
    code, out, err = run_cli(capsys, ["support", "fit", "--vertices", "0,0 60,0 15,35", "--pushes",
                                      str(path), "--starts", "16", "--refine", "2", "--json", "--out", "fit.json"])
    assert code == 0, err
    shown = json.loads(out)
    assert shown["support"].startswith("points:") and len(shown["residuals_deg"]) == 24
    assert shown["rms_deg"] < 0.5 < shown["uniform_rms_deg"]
    stored = json.loads((tmp_path / "fit.json").read_text())
    assert stored["settings"]["starts"] == 16 and stored["settings"]["refine"] == 2 and stored["pinfeed_version"]
    code, out, _ = run_cli(capsys, ["rollout", "--vertices", "0,0 60,0 15,35", "--theta-i",
                                    f"{p.theta_i[0]:.6f}", "--d", f"{p.d[0]:.6f}", "--mu-c", str(MU),
                                    "--pin-radius", "3", "--support", shown["support"], "--json"])
    assert code == 0  # the fitted support is a --support spec
    assert abs((json.loads(out)[0]["theta_f"] - p.theta_f[0] + 180) % 360 - 180) < 1.0


@pytest.mark.parametrize("text, words", [
    (None, "not found"),
    ("", "is empty"),
    ("theta_i_deg,d\n1,0.3\n", "no column theta_f_deg"),
    ("theta_i_deg,d,theta_f_deg\n", "no pushes"),
    ("theta_i_deg,d,theta_f_deg\n10,0.3\n", "2 fields"),
    ("theta_i_deg,d,theta_f_deg\n10,abc,20\n", "is not a number"),
    ("theta_i_deg,d,theta_f_deg\n10,nan,20\n", "not finite"),
    ("theta_i_deg,d,theta_f_deg,mu_c\n10,0.3,20,-0.1\n", "negative"),
    ("theta_i_deg,d,theta_f_deg\n10,0.3,20\n20,0.3,25\n", "cannot fix"),
])
def test_bad_pushes_are_one_line(tmp_path, capsys, monkeypatch, text, words):
    monkeypatch.chdir(tmp_path)
    path = tmp_path / "missing.csv" if text is None else _csv(tmp_path, text)
    code, _, err = run_cli(capsys, ["support", "fit", "--vertices", "0,0 60,0 15,35", "--pushes", str(path),
                                    "--mu-c", "0.2"])
    assert code == 2
    lines = err.strip().splitlines()
    assert len(lines) == 1 and words in lines[0], err


def test_bad_settings():
    p = Pushes(np.arange(10.0), np.full(10, 0.3), np.arange(10.0), np.full(10, np.nan))
    for kwargs, words in (({"n_points": 2}, "3 to 12"), ({"starts": 0}, "--starts"), ({"refine": 0}, "--refine"),
                          ({"mu_c": None}, "--mu-c or a mu_c column"), ({"mu_c": -1.0}, ">= 0")):
        args = dict(mu_c=0.2, pin_radius=3.0, **{k: v for k, v in kwargs.items() if k != "mu_c"})
        if "mu_c" in kwargs:
            args["mu_c"] = kwargs["mu_c"]
        with pytest.raises(PinfeedError, match=words):
            fit_support(TRIANGLE, p, **args)
