"""Wind profiles and their least-squares fit, against closed forms.

Independent reference: the log law U = (u*/kappa) ln(z/z0) is the straight line
U = a + b ln z (b = u*/kappa, a = -b ln z0), so its fitted profile and both bands must be
the textbook ordinary-least-squares ones (Seber & Wild 2003), whatever the
parametrisation; the delta method is exact for a reparametrised linear model.
"""
import numpy as np
import pytest
from scipy.stats import t as student_t

from uq.constants import VON_KARMAN
from uq.fit.profilefit import least_squares_profile
from uq.physics.profiles import log_law_profile, power_law_profile

HEIGHTS = np.array([20.0, 40.0, 60.0, 80.0, 100.0, 140.0, 180.0])


def test_profiles_closed_forms_and_domain():
    assert power_law_profile(100.0, 8.0, 0.14) == pytest.approx(8.0)
    assert power_law_profile(200.0, 8.0, 0.14) == pytest.approx(8.0 * 2**0.14)
    assert np.isnan(power_law_profile(0.0, 8.0, 0.14))
    assert log_law_profile(np.e * 0.01, 0.4, 0.01) == pytest.approx(0.4 / VON_KARMAN)
    assert np.isnan(log_law_profile(0.005, 0.4, 0.01))        # below z0


@pytest.mark.parametrize("name, truth, fixed", [
    ("power_law", (9.0, 0.12), {"reference_height": 100.0}),
    ("log_law", (0.35, 0.0002), {})])
def test_exact_data_give_the_parameters(name, truth, fixed):
    function = power_law_profile if name == "power_law" else log_law_profile
    speeds = function(HEIGHTS, *truth, **fixed)
    fit = least_squares_profile(name, HEIGHTS, speeds, fixed=fixed)
    np.testing.assert_allclose(fit["parameters"], truth, rtol=1e-7)   # LM tolerance 1.5e-8
    assert fit["residual_std"] < 1e-7


def test_log_law_bands_are_the_ordinary_least_squares_bands():
    rng = np.random.default_rng(11)
    speeds = log_law_profile(HEIGHTS, 0.4, 0.0005) + rng.normal(0, 0.2, HEIGHTS.size)
    grid = np.array([30.0, 100.0, 250.0])
    fit = least_squares_profile("log_law", HEIGHTS, speeds, grid=grid, confidence=0.95,
                                prediction=0.68)
    x = np.column_stack([np.ones_like(HEIGHTS), np.log(HEIGHTS)])
    coefficients, *_ = np.linalg.lstsq(x, speeds, rcond=None)
    dof = HEIGHTS.size - 2
    s2 = np.sum((speeds - x @ coefficients) ** 2) / dof
    inverse = np.linalg.inv(x.T @ x)
    x0 = np.column_stack([np.ones_like(grid), np.log(grid)])
    leverage = np.einsum("gk,kl,gl->g", x0, inverse, x0)
    mean = x0 @ coefficients
    half_ci = student_t.ppf(0.975, dof) * np.sqrt(s2 * leverage)
    half_pi = student_t.ppf(0.84, dof) * np.sqrt(s2 * (1 + leverage))
    # both are exact; 1e-6 relative is the optimiser's convergence, not the formulas
    np.testing.assert_allclose(fit["fit"], mean, rtol=1e-6)
    np.testing.assert_allclose(fit["confidence_high"] - fit["fit"], half_ci, rtol=1e-6)
    np.testing.assert_allclose(fit["prediction_high"] - fit["fit"], half_pi, rtol=1e-6)
    assert fit["parameters"][0] == pytest.approx(coefficients[1] * VON_KARMAN, rel=1e-6)
    assert fit["parameters"][1] == pytest.approx(np.exp(-coefficients[0] / coefficients[1]),
                                                 rel=1e-5)


def test_too_few_points_is_refused():
    with pytest.raises(ValueError, match="at least one more point"):
        least_squares_profile("power_law", [40.0, 80.0], [7.0, 8.0],
                              fixed={"reference_height": 100.0})
