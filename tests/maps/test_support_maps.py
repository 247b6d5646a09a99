

@pytest.mark.parametrize("support", ["tripod", "points:-12,-8,3 15,-9,1 -6,12,1"])
def test_point_support_rollouts_converge_in_the_step(support):
    """Spec section 4 for a point support, whose power has kinks (pivots):
    tightening the step control 1000x (tol 1e-7 -> 1e-10, ds_max 0.1 -> 0.02)
    moves theta_f by less than 0.05 degree, statuses equal."""
    th = np.arange(0.0, 360.0, 15.0) + 0.37
    a = simulate.compute_map(PART, th, D, 0.4, R_PIN, threads=1, support=support)
    b = simulate.compute_map(PART, th, D, 0.4, R_PIN, threads=1, support=support, tol=1e-10,
                             ds_max=0.02)
    np.testing.assert_array_equal(a.status.values, b.status.values)
    ok = a.status.values == 0
    assert ok.sum() >= 30
    assert np.abs(circular_diff(a.theta_f.values[ok], b.theta_f.values[ok])).max() < 0.05
