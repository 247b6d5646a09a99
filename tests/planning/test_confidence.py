"""Clopper-Pearson bounds against closed forms and an exact binomial sum;
the bootstrap width interval against a brute-force bootstrap."""
import math

import numpy as np
import pytest
from scipy.stats import binom

from pipeline.errors import PinfeedError
from pipeline.planning.claims.confidence import (check_confidence, share_lower_bound, share_upper_bound,
                                          width_interval)


@pytest.mark.parametrize("n", [1, 10, 598, 1092])
def test_lower_bound_with_no_failure_is_closed_form(n):
    assert share_lower_bound(n, n, 0.95) == pytest.approx(0.05 ** (1.0 / n), rel=1e-10)


@pytest.mark.parametrize("n", [1, 30, 300])
def test_upper_bound_with_no_success_is_closed_form(n):
    assert share_upper_bound(0, n, 0.95) == pytest.approx(1.0 - 0.05 ** (1.0 / n), rel=1e-9)


@pytest.mark.parametrize("k,n", [(1, 10), (1087, 1092), (5, 300), (299, 300)])
def test_bounds_solve_the_binomial_tail(k, n):
    # The lower bound p makes P(X >= k | p) = 1 - c; the upper bound makes P(X <= k | p) = 1 - c.
    lo, hi = share_lower_bound(k, n, 0.95), share_upper_bound(k, n, 0.95)
    assert binom.sf(k - 1, n, lo) == pytest.approx(0.05, abs=1e-9)
    assert binom.cdf(k, n, hi) == pytest.approx(0.05, abs=1e-9)
    assert lo < k / n < hi


def test_issue_example_five_failures_in_1092():
    # 5 failures in 1092: the failure rate may be nearly 1 % at one-sided 95 %
    # (1.1 % at the two-sided interval's 97.5 % end), about twice the 0.5 % allowed.
    assert 1.0 - share_lower_bound(1087, 1092) == pytest.approx(0.0096, abs=0.0002)
    assert 1.0 - share_lower_bound(1087, 1092, 0.975) == pytest.approx(0.0107, abs=0.0003)


@pytest.mark.parametrize("bad", [0, 1, -0.1, 1.5, "x", float("nan")])
def test_confidence_outside_unit_interval_is_one_line_error(bad):
    with pytest.raises(PinfeedError) as err:
        check_confidence(bad)
    assert "\n" not in str(err.value) and "verify.confidence" in str(err.value)


def _brute_width(sample, need, period):
    best = math.inf
    fin = [x % period for x in sample if np.isfinite(x)]
    for a in fin:  # every arc starting at a trial
        held = sorted(((b - a) % period) for b in fin)
        if len(held) >= need:
            best = min(best, held[need - 1])
    return best


def test_width_interval_matches_brute_force_bootstrap():
    rng = np.random.default_rng(3)
    finals = np.concatenate([rng.normal(30.0, 2.0, 57), [200.0, 355.0]]) % 360.0
    n_trials, required = 60, 0.9  # one jam
    lo, hi = width_interval(finals, n_trials, required, n_boot=200, seed=7)
    trials = np.concatenate([finals, [np.nan]])
    need = math.ceil(required * n_trials - 1e-9)
    boot = np.random.default_rng(7)
    widths = sorted(_brute_width(trials[boot.integers(0, n_trials, n_trials)], need, 360.0)
                    for _ in range(200))
    # inverted-CDF percentiles: the ceil(q * B)-th smallest resample
    assert lo == pytest.approx(widths[math.ceil(0.025 * 200) - 1], abs=1e-9)
    assert hi == pytest.approx(widths[math.ceil(0.975 * 200) - 1], abs=1e-9)
    assert lo <= hi


def test_width_interval_respects_symmetry_period():
    finals = np.array([1.0, 2.0, 181.5, 182.5] * 10)
    lo, hi = width_interval(finals, 40, 1.0, order=2, n_boot=50)
    assert hi <= 1.5 + 1e-9
