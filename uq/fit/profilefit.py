"""Least-squares fit of a wind profile, with confidence and prediction intervals.

The reference for the Bayesian fit: ``scipy.optimize.curve_fit`` (Levenberg-Marquardt)
gives the parameters and their covariance; the bands follow from the delta method,
``var f(z) = g(z)^T C g(z)`` with g the exact (complex-step) gradient of the profile with
respect to the parameters:

* confidence band of the mean profile: ``f +- t_{(1+p)/2, n-k} sqrt(g^T C g)`` (the
  normal quantile when the speeds' uncertainties are given, i.e. known);
* prediction band of a new measurement: ``f +- t sqrt(g^T C g + s^2)``, s^2 the residual
  variance (or the given measurement variance when ``sigma`` is absolute);
* the interval of a parameter: ``p +- t se(p)``, except for the roughness length z0,
  which enters the profile as ln z0: ``exp(ln z0 +- t se(z0) / z0)`` (positive).

What the intervals rest on (``interval_basis`` of the result) is one of three:

* ``known``: the speeds' given covariance (``sigma``) explains the data; normal quantiles.
  For a linear model this is the flat-prior posterior of Gaussian data exactly.
* ``residual``: no covariance given; the scatter is estimated from the residuals with
  n - k degrees of freedom and the quantiles are Student t's. For a linear model this
  is the marginal posterior of the parameters with a prior flat in ln sigma [3].
* ``known+scatter``: the covariance is given and an extra scatter s is free (``scatter``):
  s^2 is the Paule-Mandel estimate [4], the extra variance s^2 I that brings the
  generalised chi-square to its n - k degrees of freedom (zero where the covariance
  already explains the residuals); the intervals use Sigma + s^2 I, with Student t
  quantiles where s > 0 (estimated) and normal ones where s = 0.

For a model linear in its parameters these are the textbook regression intervals
exactly (the tests check it); for the power law they are first-order, as in Matavar
(2024, App. A.11), who used Matlab's nlinfit.

References
----------
.. [1] Seber, G. A. F. and Wild, C. J. (2003). Nonlinear Regression, Wiley, Sec. 5.1.
.. [2] Matavar, A. (2024). Wind field reconstruction from floating lidars. MSc thesis,
   TU Delft, App. A.11.
.. [3] Box, G. E. P. and Tiao, G. C. (1973). Bayesian Inference in Statistical Analysis,
   Addison-Wesley, Sec. 2.7 (the multivariate t posterior of linear regression).
.. [4] Paule, R. C. and Mandel, J. (1982). Consensus values and weighting factors. J. Res.
   Natl. Bur. Stand. 87(5), 377-385.
"""
import numpy as np
from scipy.optimize import brentq, curve_fit
from scipy.stats import t as student_t

from uq.constants import COMPLEX_STEP
from uq.physics.profiles import PROFILES

#: Prediction probability of Matavar (2024, App. A.11): the 68 % prediction interval.
DEFAULT_PREDICTION = 0.68
#: Parameters that are positive by definition and enter the profile through their
#: logarithm (the roughness length: U = u*/kappa ln(z/z0)); their confidence interval is
#: the delta method on ln p, which is the scale the profile is linear in, and stays > 0.
LOGARITHMIC_PARAMETERS = ("roughness_length",)


#: Bases of the least-squares intervals -> what a person reads (``interval_basis``).
INTERVAL_BASES = {
    "known": "the speeds' given covariance; normal quantiles",
    "residual": "a scatter estimated from the residuals; Student t, n - k dof",
    "known+scatter": "the given covariance + an extra scatter estimated from the residuals "
                     "(Paule-Mandel); Student t, n - k dof",
    "known+no scatter": "the given covariance (it explains the residuals: extra scatter 0); "
                        "normal quantiles",
}


def least_squares_profile(name, heights, speeds, sigma=None, fixed=None, confidence=0.95,
                          prediction=DEFAULT_PREDICTION, grid=None, scatter=False):
    """Fit profile `name` of :data:`uq.physics.profiles.PROFILES` by least squares.

    Parameters
    ----------
    name : str
    heights, speeds : array_like, shape (n,)
        [m], [m s-1].
    sigma : array_like, shape (n,) or (n, n), optional
        Standard uncertainties of the speeds [m s-1], or their covariance matrix
        [m2 s-2] (generalised least squares, as ``curve_fit`` takes it), taken as
        absolute; without them the scatter is estimated from the residuals.
    fixed : dict, optional
        Fixed keyword arguments of the profile (e.g. ``reference_height``).
    confidence, prediction : float
        Probabilities of the confidence and prediction intervals.
    grid : array_like, optional
        Heights of the bands [m] (default: `heights`).
    scatter : bool
        With `sigma`: an extra scatter s (s^2 I added to the covariance) is free and
        estimated (Paule-Mandel, see the module's docstring).

    Returns
    -------
    dict
        ``parameters``, ``standard_errors``, ``parameter_low``/``high`` (confidence),
        ``covariance``, ``names``, ``units``, ``dof``, ``residual_std`` [m s-1], ``grid``,
        ``fit``, ``confidence_low``/``high``, ``prediction_low``/``high`` [m s-1],
        ``extra_scatter`` [m s-1] (0 without `scatter`, NaN without `sigma`) and
        ``interval_basis`` (a key of :data:`INTERVAL_BASES`).
    """
    function, names, units, guess = PROFILES[name]
    fixed = dict(fixed or {})
    heights, speeds = np.asarray(heights, float), np.asarray(speeds, float)
    dof = len(heights) - len(names)
    if dof < 1:
        raise ValueError(f"{len(heights)} points cannot fit {len(names)} parameters with a "
                         "residual: need at least one more point")

    def model(z, *parameters):
        return function(z, *parameters, **fixed)

    absolute = sigma is not None
    start = guess(heights, speeds, **fixed)
    extra = np.nan
    if absolute and scatter:
        extra = extra_variance(model, heights, speeds, sigma, start, dof)
        sigma = _with_scatter(sigma, extra)
    elif absolute:
        extra = 0.0
    parameters, covariance = curve_fit(model, heights, speeds, p0=start,
                                       sigma=sigma, absolute_sigma=absolute)
    residuals = speeds - model(heights, *parameters)
    residual_variance = float(np.sum(residuals**2) / dof)
    grid = heights if grid is None else np.asarray(grid, float)
    gradient = parameter_gradient(model, grid, parameters)
    mean_variance = np.einsum("gk,kl,gl->g", gradient, covariance, gradient)
    noise = np.interp(grid, heights, _variances(sigma)) if absolute else residual_variance
    basis = "residual" if not absolute else "known" if not scatter else \
        "known+scatter" if extra > 0 else "known+no scatter"
    # known (absolute) variances: normal quantiles; an estimated scatter: Student t, n - k
    quantile_dof = dof if basis in ("residual", "known+scatter") else np.inf
    t_confidence = student_t.ppf((1 + confidence) / 2, quantile_dof)
    t_prediction = student_t.ppf((1 + prediction) / 2, quantile_dof)
    errors = np.sqrt(np.diag(covariance))
    low, high = parameter_interval(names, parameters, errors, t_confidence)
    fit = model(grid, *parameters)
    return {"names": names, "units": units, "parameters": parameters, "standard_errors": errors,
            "parameter_low": low, "parameter_high": high,
            "covariance": covariance, "dof": dof, "residual_std": np.sqrt(residual_variance),
            "grid": grid, "fit": fit,
            "confidence_low": fit - t_confidence * np.sqrt(mean_variance),
            "confidence_high": fit + t_confidence * np.sqrt(mean_variance),
            "prediction_low": fit - t_prediction * np.sqrt(mean_variance + noise),
            "prediction_high": fit + t_prediction * np.sqrt(mean_variance + noise),
            "extra_scatter": np.sqrt(extra), "interval_basis": basis}


def extra_variance(model, heights, speeds, sigma, start, dof):
    """Paule-Mandel extra variance s^2 [m2 s-2] [4]: the s^2 >= 0 at which the
    generalised least-squares chi-square with covariance Sigma + s^2 I equals `dof`;
    0 where chi^2(0) <= dof (the given covariance explains the residuals).

    chi^2(s^2) falls with s^2 and is at most RSS_OLS / s^2 (Sigma + s^2 I >= s^2 I), so
    a root lies below 2 RSS_OLS / dof.
    """
    def excess(variance):
        weights = _with_scatter(sigma, variance)
        parameters, _ = curve_fit(model, heights, speeds, p0=start, sigma=weights,
                                  absolute_sigma=True)
        residual = speeds - model(heights, *parameters)
        matrix = _as_covariance(weights)
        return float(residual @ np.linalg.solve(matrix, residual)) - dof

    if excess(0.0) <= 0:
        return 0.0
    ordinary, _ = curve_fit(model, heights, speeds, p0=start)
    upper = 2 * float(np.sum((speeds - model(heights, *ordinary)) ** 2)) / dof
    return float(brentq(excess, 0.0, upper, xtol=upper * 1e-10))


def _with_scatter(sigma, variance):
    """curve_fit's sigma (standard deviations (n,) or a covariance (n, n)) with an extra
    variance on every point."""
    sigma = np.asarray(sigma, float)
    if sigma.ndim == 2:
        return sigma + variance * np.eye(len(sigma))
    return np.sqrt(sigma**2 + variance)


def _as_covariance(sigma):
    """A covariance matrix from curve_fit's sigma (standard deviations or a matrix)."""
    sigma = np.asarray(sigma, float)
    return sigma if sigma.ndim == 2 else np.diag(sigma**2)


def parameter_interval(names, parameters, errors, quantile):
    """Confidence interval of each parameter by the delta method: value +- quantile x
    standard error, on the logarithmic scale for the parameters of
    :data:`LOGARITHMIC_PARAMETERS` (``exp(ln p +- quantile x se / p)``), whose
    interval must stay positive; returns (low, high)."""
    parameters, errors = np.asarray(parameters, float), np.asarray(errors, float)
    low, high = parameters - quantile * errors, parameters + quantile * errors
    for k, name in enumerate(names):
        if name in LOGARITHMIC_PARAMETERS and parameters[k] > 0:
            spread = quantile * errors[k] / parameters[k]     # se of ln p, delta method
            low[k], high[k] = parameters[k] * np.exp(-spread), parameters[k] * np.exp(spread)
    return low, high


def _variances(sigma):
    """Variances of the speeds from standard uncertainties (n,) or a covariance (n, n)."""
    sigma = np.asarray(sigma, float)
    return np.diag(sigma) if sigma.ndim == 2 else sigma**2


def parameter_gradient(model, heights, parameters):
    """d model / d parameters at `heights` by complex step, shape (n_heights, k)."""
    columns = []
    for k in range(len(parameters)):
        shifted = np.array(parameters, dtype=complex)
        step = COMPLEX_STEP * max(1.0, abs(parameters[k]))
        shifted[k] += 1j * step
        columns.append(np.imag(model(heights, *shifted)) / step)
    return np.stack(columns, axis=-1)
