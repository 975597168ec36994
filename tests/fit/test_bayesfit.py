"""Bayesian profile fit: against curve_fit and generalised least squares, reproducibility,
convergence diagnostics and loud failure.

Monte Carlo tolerances come from the chain: with N_eff = draws / tau effective samples,
the standard error of a p-quantile of a normal posterior of width s is
sqrt(p (1 - p) / N_eff) / phi(z_p) * s, and of a variance sqrt(2 / N_eff) relative; K = 5
of them.
"""
import numpy as np
import pytest
from scipy.stats import norm

from uq.fit.bayesfit import (NotConverged, ProfilePosterior, posterior_summary, profile_data,
                         rank_rhat, sample_posterior)
from uq.fit.profilefit import least_squares_profile
from uq.physics.profiles import power_law_profile

HEIGHTS = np.array([20.0, 40.0, 60.0, 80.0, 100.0, 140.0, 180.0])
FIXED = {"reference_height": 100.0}
SIGMA = 0.1
K = 5


@pytest.fixture(scope="module")
def independent():
    rng = np.random.default_rng(1)
    speeds = power_law_profile(HEIGHTS, 9.0, 0.12) + rng.normal(0, SIGMA, HEIGHTS.size)
    data = profile_data(HEIGHTS, speeds, speed_covariance=np.full(HEIGHTS.size, SIGMA))
    posterior = ProfilePosterior("power_law", data, fixed=FIXED, scatter=False)
    return speeds, sample_posterior(posterior, seed=3)


def effective_samples(result):
    return result["samples"].shape[0] * result["samples"].shape[1] * result["thin"] / \
        result["tau"].max()


def test_flat_priors_reproduce_curve_fit_intervals(independent):
    speeds, result = independent
    fit = least_squares_profile("power_law", HEIGHTS, speeds, sigma=np.full(HEIGHTS.size, SIGMA),
                                fixed=FIXED)
    summary = posterior_summary(result["samples"], result["names"])
    n_eff = effective_samples(result)
    for k, name in enumerate(("reference_speed", "shear")):
        centre, width = fit["parameters"][k], fit["standard_errors"][k]
        for key, p in (("low95", 0.025), ("low68", 0.16), ("median", 0.5), ("high68", 0.84),
                       ("high95", 0.975)):
            expected = centre + norm.ppf(p) * width
            tolerance = K * np.sqrt(p * (1 - p) / n_eff) / norm.pdf(norm.ppf(p)) * width
            assert abs(summary[name][key] - expected) < tolerance, (name, key)


def test_convergence_diagnostics(independent):
    _, result = independent
    assert result["chain"].shape[2] >= 32                     # walkers
    assert result["chain"].shape[1] > 50 * result["tau"].max()
    assert np.all(result["rhat"] < 1.01)
    assert result["burn"] >= 2 * result["tau"].max() and result["thin"] >= 1


def test_same_seed_same_chain_and_loud_failure():
    rng = np.random.default_rng(5)
    speeds = power_law_profile(HEIGHTS, 7.0, 0.2) + rng.normal(0, SIGMA, HEIGHTS.size)
    data = profile_data(HEIGHTS, speeds, speed_covariance=np.full(HEIGHTS.size, SIGMA))
    posterior = ProfilePosterior("power_law", data, fixed=FIXED, scatter=False)
    with pytest.raises(NotConverged, match="did not converge") as failure:
        sample_posterior(posterior, seed=9, steps=100, max_steps=100, ensembles=2)
    assert "tau" in str(failure.value) and "R-hat" in str(failure.value)
    a = sample_posterior(posterior, seed=9, steps=1500, ensembles=2)
    b = sample_posterior(posterior, seed=9, steps=1500, ensembles=2)
    np.testing.assert_array_equal(a["chain"], b["chain"])


def test_common_errors_use_the_full_covariance():
    """A systematic error common to every gate (sd 0.3 m/s) cannot average out over the
    gates: with the full covariance the posterior of U_ref widens to the generalised
    least-squares width sqrt((J^T Sigma^-1 J)^-1), computed here independently."""
    rng = np.random.default_rng(2)
    speeds = power_law_profile(HEIGHTS, 9.0, 0.12) + rng.normal(0, SIGMA, HEIGHTS.size) + 0.2
    covariance = SIGMA**2 * np.eye(HEIGHTS.size) + 0.3**2
    data = profile_data(HEIGHTS, speeds, speed_covariance=covariance)
    result = sample_posterior(ProfilePosterior("power_law", data, fixed=FIXED, scatter=False),
                              seed=4)
    centre = result["map"]
    jacobian = np.column_stack([power_law_profile(HEIGHTS, 1.0, centre[1]),
                                centre[0] * np.log(HEIGHTS / 100.0)
                                * power_law_profile(HEIGHTS, 1.0, centre[1])])
    gls = np.linalg.inv(jacobian.T @ np.linalg.solve(covariance, jacobian))
    sampled = np.cov(result["samples"].reshape(-1, 2).T)
    tolerance = K * np.sqrt(2 / effective_samples(result))
    np.testing.assert_allclose(np.diag(sampled), np.diag(gls), rtol=tolerance)
    assert np.sqrt(gls[0, 0]) > 0.25                       # the common 0.3 m/s dominates


def test_rank_rhat_separates_mixed_from_stuck_chains():
    rng = np.random.default_rng(0)
    mixed = rng.standard_normal((4, 1000))
    stuck = mixed + np.array([0.0, 0.0, 0.0, 1.0])[:, None]
    assert rank_rhat(mixed) < 1.01
    assert rank_rhat(stuck) > 1.05


def test_diagonal_shortcut_equals_the_full_factorisation():
    """Independent errors take an O(n) path; it must give the Cholesky path's numbers."""
    rng = np.random.default_rng(8)
    speeds = power_law_profile(HEIGHTS, 9.0, 0.12) + rng.normal(0, SIGMA, HEIGHTS.size)
    data = profile_data(HEIGHTS, speeds, speed_covariance=np.full(HEIGHTS.size, SIGMA),
                        height_covariance=np.full(HEIGHTS.size, 2.0))
    posterior = ProfilePosterior("power_law", data, fixed=FIXED, scatter=True)
    thetas = np.column_stack([rng.uniform(8, 10, 50), rng.uniform(0, 0.3, 50),
                              rng.uniform(-4, 0, 50)])
    assert posterior.diagonal
    fast = posterior.log_probability(thetas)
    posterior.diagonal = False
    np.testing.assert_allclose(fast, posterior.log_probability(thetas), rtol=1e-12)


def test_relative_covariance_scales_with_the_profile():
    """Sigma(theta) = diag(f) R diag(f): at any theta the relative path's covariance is
    the absolute one built by hand from the profile values."""
    rng = np.random.default_rng(4)
    speeds = power_law_profile(HEIGHTS, 9.0, 0.12) + rng.normal(0, SIGMA, HEIGHTS.size)
    relative = 0.01**2 * (0.5 * np.eye(HEIGHTS.size) + 0.5)
    data = profile_data(HEIGHTS, speeds, speed_covariance=relative)
    posterior = ProfilePosterior("power_law", data, fixed=FIXED, scatter=False, relative=True)
    theta = np.array([8.5, 0.2])
    f = power_law_profile(HEIGHTS, *theta)
    np.testing.assert_allclose(posterior.covariance(theta), np.outer(f, f) * relative,
                               rtol=1e-12)
