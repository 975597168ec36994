"""Least-squares intervals against the closed-form posterior of a linear-Gaussian model.

For a model linear in its parameters, y = X beta + e, the posterior under flat priors
has a closed form (Box and Tiao 1973, Sec. 2.7):

* e ~ N(0, Sigma), Sigma known: beta ~ N(beta_GLS, (X^T Sigma^-1 X)^-1);
* e ~ N(0, sigma^2 I), sigma free with a prior flat in ln sigma: beta ~ multivariate
  Student t with n - k degrees of freedom about beta_OLS, scale s^2 (X^T X)^-1, s^2 the
  residual variance.

The least-squares intervals must be these exactly, and the emcee posterior of the same
model must match them within its own Monte Carlo error (K = 5 standard errors of a
quantile from the chain's effective sample size, as in test_bayesfit).
"""
import numpy as np
import pytest
from scipy.stats import norm
from scipy.stats import t as student_t

from uq.fit.bayesfit import ProfilePosterior, posterior_summary, profile_data, sample_posterior
from uq.fit.profilefit import extra_variance, least_squares_profile
from uq.physics.profiles import PROFILES

HEIGHTS = np.array([20.0, 40.0, 60.0, 80.0, 100.0, 140.0, 180.0])
#: z scale of the linear profile's slope [m].
SCALE = 100.0
TRUTH = (9.0, 1.5)
#: Standard errors of the Monte Carlo quantiles allowed (a failure rate of ~1e-6 each).
K = 5
#: curve_fit (Levenberg-Marquardt) stops at a relative change of 1e-8 (xtol, ftol): a
#: linear model's optimum to about that, and its intervals to 1e-6 with margin.
EXACT = 1e-6
NAMES = ("intercept", "gradient")
PRIORS = {"intercept": (-100.0, 100.0, "uniform"), "gradient": (-100.0, 100.0, "uniform")}
PROBABILITIES = {"low95": 0.025, "low68": 0.16, "median": 0.5, "high68": 0.84,
                 "high95": 0.975}


def linear_profile(height, intercept, gradient):
    """U(z) = a + b (z - 100 m) / 100 m [m s-1]: linear in (a, b)."""
    return intercept + gradient * (np.asarray(height) - SCALE) / SCALE


def _linear_guess(height, speed):
    gradient, intercept = np.polyfit((height - SCALE) / SCALE, speed, 1)
    return [float(intercept), float(gradient)]


@pytest.fixture(autouse=True)
def linear(monkeypatch):
    """The linear profile as an entry of PROFILES (the fits look profiles up there)."""
    monkeypatch.setitem(PROFILES, "linear", (linear_profile, NAMES, ("m s-1", "m s-1"),
                                             _linear_guess))


def design():
    return np.column_stack([np.ones(HEIGHTS.size), (HEIGHTS - SCALE) / SCALE])


def correlated_covariance(u=0.1, rho=0.6):
    """A common error (correlation rho) plus independent ones, u each [m s-1]."""
    return u**2 * (rho + (1 - rho) * np.eye(HEIGHTS.size))


def generalised(speeds, covariance):
    """Closed-form GLS estimate and covariance."""
    X, inverse = design(), np.linalg.inv(covariance)
    cov = np.linalg.inv(X.T @ inverse @ X)
    return cov @ X.T @ inverse @ speeds, cov


def effective_samples(result):
    return result["samples"].shape[0] * result["samples"].shape[1] * result["thin"] / \
        result["tau"].max()


def assert_posterior_matches(result, centre, scale, distribution):
    """Every summary quantile of the emcee draws within K standard errors of the
    closed form: sqrt(p (1 - p) / N_eff) / density(q_p) for a quantile q_p."""
    summary = posterior_summary(result["samples"], result["names"])
    n_eff = effective_samples(result)
    for k, name in enumerate(NAMES):
        for key, p in PROBABILITIES.items():
            z = distribution.ppf(p)
            expected = centre[k] + z * scale[k]
            tolerance = K * np.sqrt(p * (1 - p) / n_eff) / distribution.pdf(z) * scale[k]
            assert abs(summary[name][key] - expected) < tolerance, (name, key)


def test_known_covariance_interval_is_the_gaussian_posterior():
    """Known correlated covariance, no scatter: least squares is the closed form exactly,
    emcee within its Monte Carlo error."""
    rng = np.random.default_rng(5)
    covariance = correlated_covariance()
    speeds = linear_profile(HEIGHTS, *TRUTH) + rng.multivariate_normal(
        np.zeros(HEIGHTS.size), covariance)
    beta, cov = generalised(speeds, covariance)
    se = np.sqrt(np.diag(cov))
    fit = least_squares_profile("linear", HEIGHTS, speeds, sigma=covariance)
    z = norm.ppf(0.975)
    np.testing.assert_allclose(fit["parameter_low"], beta - z * se, rtol=EXACT)
    np.testing.assert_allclose(fit["parameter_high"], beta + z * se, rtol=EXACT)
    assert fit["interval_basis"] == "known"
    posterior = ProfilePosterior("linear", profile_data(HEIGHTS, speeds, covariance),
                                 scatter=False, priors=PRIORS)
    assert_posterior_matches(sample_posterior(posterior, seed=7, ensembles=2), beta, se, norm)


def test_estimated_scatter_interval_is_the_student_t_posterior():
    """No covariance given, a free scatter: least squares with Student t (n - k dof) is the
    marginal posterior of a prior flat in ln sigma exactly; emcee within its error."""
    rng = np.random.default_rng(6)
    speeds = linear_profile(HEIGHTS, *TRUTH) + rng.normal(0, 0.3, HEIGHTS.size)
    X = design()
    beta = np.linalg.lstsq(X, speeds, rcond=None)[0]
    dof = HEIGHTS.size - 2
    s2 = float(np.sum((speeds - X @ beta) ** 2)) / dof
    se = np.sqrt(s2 * np.diag(np.linalg.inv(X.T @ X)))
    fit = least_squares_profile("linear", HEIGHTS, speeds)
    t = student_t.ppf(0.975, dof)
    np.testing.assert_allclose(fit["parameter_low"], beta - t * se, rtol=EXACT)
    np.testing.assert_allclose(fit["parameter_high"], beta + t * se, rtol=EXACT)
    assert fit["interval_basis"] == "residual"
    posterior = ProfilePosterior("linear", profile_data(HEIGHTS, speeds), scatter=True,
                                 priors=PRIORS)
    assert_posterior_matches(sample_posterior(posterior, seed=8, ensembles=2), beta, se,
                             student_t(dof))


def test_free_scatter_keeps_the_given_covariance():
    """Issue 27, item 1: with `scatter` and a given covariance, data exactly on the
    profile (no residual) had an interval of almost no width (the residuals' scatter
    alone). The given covariance explains such data: the interval is the known-covariance
    closed form, not narrower."""
    covariance = correlated_covariance()
    speeds = linear_profile(HEIGHTS, *TRUTH)
    beta, cov = generalised(speeds, covariance)
    fit = least_squares_profile("linear", HEIGHTS, speeds, sigma=covariance, scatter=True)
    half = norm.ppf(0.975) * np.sqrt(np.diag(cov))
    np.testing.assert_allclose(fit["parameter_high"] - fit["parameter_low"], 2 * half,
                               rtol=EXACT)
    assert fit["interval_basis"] == "known+no scatter" and fit["extra_scatter"] == 0


def test_extra_scatter_is_the_paule_mandel_root():
    """Residuals larger than the given covariance explains: the extra variance s^2 brings
    the generalised chi-square to n - k, and the interval is the closed form with
    Sigma + s^2 I and Student t quantiles."""
    rng = np.random.default_rng(9)
    covariance = correlated_covariance(u=0.05)
    speeds = linear_profile(HEIGHTS, *TRUTH) + rng.normal(0, 0.4, HEIGHTS.size)
    dof = HEIGHTS.size - 2
    fit = least_squares_profile("linear", HEIGHTS, speeds, sigma=covariance, scatter=True)
    s2 = fit["extra_scatter"] ** 2
    assert fit["interval_basis"] == "known+scatter" and s2 > 0
    total = covariance + s2 * np.eye(HEIGHTS.size)
    beta, cov = generalised(speeds, total)
    residual = speeds - design() @ beta
    # brentq's xtol is 1e-10 of the bracket: chi-square to 1e-6 of its n - k
    assert residual @ np.linalg.solve(total, residual) == pytest.approx(dof, rel=EXACT)
    half = student_t.ppf(0.975, dof) * np.sqrt(np.diag(cov))
    np.testing.assert_allclose(fit["parameter_low"], beta - half, rtol=EXACT)
    np.testing.assert_allclose(fit["parameter_high"], beta + half, rtol=EXACT)
    assert extra_variance(linear_profile, HEIGHTS, linear_profile(HEIGHTS, *TRUTH),
                          covariance, list(TRUTH), dof) == 0.0
