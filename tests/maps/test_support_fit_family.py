"""``pinfeed support fit`` as a family: the supports consistent with noisy
pushes from a known tripod. Every member explains the pushes within the
noise (its residuals recomputed here through the public rollout API), the
family text is one ``--support-family`` accepts, the true tripod itself is
within the threshold the family uses, and too few pushes is a one-line error."""
import numpy as np
import pytest
from scipy.stats import chi2

from pipeline.errors import PinfeedError
from pipeline.maps import simulate
from pipeline.maps.support_fit import Pushes, fit_support_family, statics_weights
from pipeline.parts.part import Part
from pipeline.parts.support import point_support
from pipeline.parts.support_family import parse_support_family

TRIANGLE = Part.from_vertices([(0, 0), (60, 0), (15, 35)], "asym_triangle")
MU, NOISE = 0.2, 0.5
LEGS = np.array([[-12.0, -6.0], [14.0, -5.0], [-3.0, 9.0]])


def _pushes(support, n, seed):
    rng = np.random.default_rng(seed)
    th = rng.uniform(0.0, 360.0, 4 * n)
    d = rng.choice([-1.0, 1.0], 4 * n) * rng.uniform(0.15, 0.8, 4 * n)
    res = simulate.rollout_points(TRIANGLE, th, d, np.full(4 * n, MU), 3.0, "minpower", support=support)
    ok = np.flatnonzero(res["status"] == 0)[:n]
    measured = (res["theta_f"][ok] + rng.normal(0.0, NOISE, ok.size)) % 360.0
    return Pushes(th[ok], d[ok], measured, np.full(ok.size, np.nan))


def _chi2(support, pushes):
    res = simulate.rollout_points(TRIANGLE, pushes.theta_i, pushes.d, np.full(len(pushes), MU), 3.0,
                                  "minpower", support=support)
    r = (res["theta_f"] - pushes.theta_f + 180.0) % 360.0 - 180.0
    return float(np.sum(np.square(r / NOISE)))


def test_every_member_explains_the_pushes_within_their_noise():
    truth = point_support(TRIANGLE, LEGS, statics_weights(LEGS))
    pushes = _pushes(truth, 24, seed=5)
    fit = fit_support_family(TRIANGLE, pushes, MU, 3.0, noise_deg=NOISE, starts=12, refine=2, seed=1)
    threshold = chi2.ppf(0.95, len(pushes))
    assert fit.threshold == pytest.approx(threshold)
    assert _chi2(truth, pushes) <= threshold  # the truth is among what the family stands for
    family = parse_support_family(fit.spec, TRIANGLE)
    assert len(family) == len(fit.members) >= 2
    for member in family.members:
        assert _chi2(member, pushes) <= threshold * (1 + 1e-6), member.label
    for member, reported in zip(family.members, fit.chi2):
        assert _chi2(member, pushes) == pytest.approx(reported, rel=0.02)  # the text rounds to 1 um


@pytest.mark.parametrize("n, noise", [(5, 0.5), (6, None)])
def test_fewer_pushes_than_parameters_is_one_line(n, noise):
    truth = point_support(TRIANGLE, LEGS, statics_weights(LEGS))
    pushes = _pushes(truth, n, seed=2)
    with pytest.raises(PinfeedError, match="measure at least") as err:
        fit_support_family(TRIANGLE, pushes, MU, 3.0, noise_deg=noise)
    assert "\n" not in str(err.value)


def test_bad_noise_is_one_line():
    truth = point_support(TRIANGLE, LEGS, statics_weights(LEGS))
    with pytest.raises(PinfeedError, match="noise-deg"):
        fit_support_family(TRIANGLE, _pushes(truth, 10, seed=2), MU, 3.0, noise_deg=-1.0)


def test_cli_fit_family_prints_a_family_text_and_refuses_too_few_pushes(tmp_path, capsys):
    from cli_runs import run_cli
    pushes = _pushes(point_support(TRIANGLE, LEGS, statics_weights(LEGS)), 14, 5)
    csv = tmp_path / "pushes.csv"
    csv.write_text("theta_i_deg,d,theta_f_deg\n" + "".join(
        f"{t:.4f},{d:.4f},{f:.4f}\n" for t, d, f in zip(pushes.theta_i, pushes.d, pushes.theta_f)))
    args = ["support", "fit", "--vertices", "0,0 60,0 15,35", "--name", "asym_triangle", "--pushes", str(csv),
            "--mu-c", str(MU), "--family", "--noise-deg", "1.5", "--starts", "16", "--refine", "2"]
    code, out, err = run_cli(capsys, args)
    assert code == 0, err
    text = out.split('--support-family "')[1].rstrip().rstrip('"')
    assert len(parse_support_family(text, TRIANGLE).members) >= 1
    few = tmp_path / "few.csv"
    few.write_text("theta_i_deg,d,theta_f_deg\n" + "".join(
        f"{t:.4f},{d:.4f},{f:.4f}\n" for t, d, f in list(zip(pushes.theta_i, pushes.d, pushes.theta_f))[:4]))
    code, out, err = run_cli(capsys, args[:7] + [str(few)] + args[8:])
    assert code == 2 and err.count("\n") == 1 and "pushes" in err
