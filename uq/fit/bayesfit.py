"""Bayesian wind-profile fit with emcee: posterior of the profile parameters.

Likelihood. The measured speeds y (n gates) are Gaussian about the profile f(z; theta)
with covariance

    Sigma = Sigma_meas + diag(f'(z)^2) . Sigma_z + sigma^2 I

* ``Sigma_meas``: the measurement covariance of the speeds; full when errors are common
  to the gates (INS or mounting errors), not only its diagonal;
* ``Sigma_z``: the covariance of the gates' true heights, carried into speed to first
  order through the profile's slope f'(z) (``diag(f') Sigma_z diag(f')``);
* ``sigma = exp(ln_sigma)``: a free extra scatter (turbulence), optional.

Priors are uniform within bounds (:data:`DEFAULT_PRIORS`, documented there),
log-uniform where marked, or normal ``(mean, u, "normal")`` when configured. The posterior is sampled by emcee's affine-invariant ensemble
(Foreman-Mackey et al. 2013) in several independent ensembles, each started in a small
ball about the maximum a posteriori, advanced side by side by one emcee sampler (the
stretch move per ensemble, :mod:`uq.fit.ensembles`) seeded through emcee's State
random_state.
Convergence is decided, and failure raised, from the integrated autocorrelation time
(each chain longer than 50 tau; burn-in 2 tau and thinning tau/2 derived from it) and
the rank-normalised split R-hat across ensembles (Vehtari et al. 2021, < 1.01).

A parameter with a log-uniform prior (the roughness length z0, from 1 um to 1 m) is
sampled as its logarithm: the prior is flat in ln z0, and the log-law posterior, a
curved ridge in (u*, z0), is near-Gaussian in (u*, ln z0), so the walkers mix about ten
times faster (tau ~400 -> ~40 steps on the shipped floating-lidar profile) and the tails
of ln z0 are sampled as well as the bulk. Chains and summaries are reported in the
parameter's own units.

Each posterior quantile comes with its Monte Carlo standard error (MCSE,
:func:`quantile_standard_errors`): Vehtari et al. (2021, Sec. 4.3), from the effective
sample size of the indicator I(theta <= q_p), so that slowly sampled tails get the
larger error they have.

References
----------
.. [1] Foreman-Mackey, D. et al. (2013). emcee: The MCMC Hammer. PASP 125, 306.
.. [2] Vehtari, A. et al. (2021). Rank-normalization, folding, and localization: an
   improved R-hat. Bayesian Analysis 16(2), 667-718.
.. [3] Peelle, R. W. (1987). Peelle's pertinent puzzle. Informal memorandum, Oak Ridge
   National Laboratory; see Zhao, Z. and Perey, F. G. (1992), ORNL/TM-12106.
"""
from dataclasses import dataclass

import emcee
import numpy as np
from scipy.optimize import minimize
from scipy.special import ndtri
from scipy.stats import beta as beta_distribution
from scipy.stats import norm, rankdata

from uq.constants import COMPLEX_STEP, MIN_WALKERS, VON_KARMAN
from uq.fit.ensembles import IndependentStretchMove, integrated_times, split_ensembles
from uq.fit.profilefit import least_squares_profile
from uq.physics.profiles import PROFILES

#: Prior bounds per parameter: (low, high, "uniform" | "log_uniform"). Wide enough for any
#: atmospheric profile over sea (shear -0.5 ... 1; u* up to 3 m/s; z0 from 1 um to 1 m);
#: ln_sigma from e^-10 (no scatter) to e^2 = 7.4 m/s (more than any 10-min scatter).
DEFAULT_PRIORS = {
    "reference_speed": (0.0, 60.0, "uniform"),
    "shear": (-0.5, 1.0, "uniform"),
    "friction_velocity": (0.0, 3.0, "uniform"),
    "roughness_length": (1e-6, 1.0, "log_uniform"),
    "ln_sigma": (-10.0, 2.0, "uniform"),
}
#: Chains must be longer than this many autocorrelation times [2].
TAU_FACTOR = 50
#: Largest acceptable rank-normalised split R-hat [2].
RHAT_LIMIT = 1.01
#: Relative radius of the starting ball about the MAP [1]: small against any posterior
#: width here, large enough that the walkers are not degenerate.
BALL = 1e-4
#: Probabilities of the posterior summary: the 95 % and 68 % central intervals and the
#: median, by summary key.
#: Sokal's window constant c of the integrated autocorrelation time (emcee's default) [1].
AUTOCORRELATION_WINDOW = 5
SUMMARY_PROBABILITIES = {"low95": 0.025, "low68": 0.16, "median": 0.5, "high68": 0.84,
                         "high95": 0.975}


class NotConverged(RuntimeError):
    """The chains did not converge within the allowed number of steps."""


@dataclass(frozen=True)
class ProfileData:
    """What is fitted: heights [m], speeds [m s-1] and their covariances: a full matrix
    (n, n) [m2 s-2, m2] where errors are correlated between gates, or the variances (n,)
    of independent ones (no dense matrix: a table of 10^4 rows would need 800 MB)."""

    heights: np.ndarray
    speeds: np.ndarray
    speed_covariance: np.ndarray       # (n, n) or (n,) variances [m2 s-2]
    height_covariance: np.ndarray      # (n, n) or (n,) variances [m2]


def variances(covariance):
    """The diagonal of a covariance given as a matrix or as its variances."""
    covariance = np.asarray(covariance)
    return covariance if covariance.ndim == 1 else np.diag(covariance)


def as_matrix(covariance):
    """A covariance given as a matrix or as its variances, as a matrix."""
    covariance = np.asarray(covariance)
    return np.diag(covariance) if covariance.ndim == 1 else covariance


def profile_data(heights, speeds, speed_covariance=None, height_covariance=None):
    """ProfileData with zero covariances where none are given (1-D input = std devs)."""
    heights, speeds = np.asarray(heights, float), np.asarray(speeds, float)
    return ProfileData(heights, speeds, _covariance(speed_covariance, len(heights)),
                       _covariance(height_covariance, len(heights)))


def _covariance(value, n):
    """Variances (n,) for none or standard deviations (1-D); a matrix as given."""
    if value is None:
        return np.zeros(n)
    value = np.asarray(value, float)
    return value**2 if value.ndim == 1 else value


class ProfilePosterior:
    """log posterior of (profile parameters, [ln_sigma]) given ProfileData."""

    def __init__(self, name, data, fixed=None, scatter=True, priors=None, relative=False):
        self.function, self.names, _, _ = PROFILES[name]
        self.name, self.data, self.fixed = name, data, dict(fixed or {})
        self.scatter = scatter
        self.parameter_names = tuple(self.names) + (("ln_sigma",) if scatter else ())
        self.priors = {**DEFAULT_PRIORS, **(priors or {})}
        # relative: speed_covariance is of U / f (multiplicative errors), scaled by the
        # profile at theta: Sigma = diag(f) R diag(f); an absolute covariance estimated
        # from data with multiplicative errors biases the fit low (Peelle's puzzle [3])
        self.relative = relative
        self.diagonal = all(np.ndim(c) == 1 or np.count_nonzero(c - np.diag(np.diag(c))) == 0
                            for c in (data.speed_covariance, data.height_covariance))
        self.exact_heights = not np.any(data.height_covariance)

    def model(self, heights, *parameters):
        return self.function(heights, *parameters, **self.fixed)

    def log_prior(self, theta):
        """log prior of parameter vectors theta (..., k) (0 or -inf for uniform bounds)."""
        theta = np.asarray(theta, float)
        total = np.zeros(theta.shape[:-1])
        for k, name in enumerate(self.parameter_names):
            total = total + _log_prior_density(theta[..., k], *self.priors[name])
        return total

    def covariance(self, theta):
        """Total covariance of the speeds at theta (..., k) [m2 s-2], shape (..., n, n)."""
        theta = np.asarray(theta, float)
        k = len(self.names)
        slope = self._slope(theta[..., :k])
        speed = as_matrix(self.data.speed_covariance)
        if self.relative:
            profile = self._profile(self.data.heights, theta[..., :k])
            speed = profile[..., :, None] * speed * profile[..., None, :]
        total = speed + slope[..., :, None] * as_matrix(self.data.height_covariance) \
            * slope[..., None, :]
        if self.scatter:
            total = total + np.exp(2 * theta[..., k])[..., None, None] * np.eye(
                len(self.data.heights))
        return total

    def _slope(self, parameters):
        """dU/dz at the gate heights, by complex step [s-1], shape (..., n)."""
        step = COMPLEX_STEP
        return np.imag(self._profile(self.data.heights + 1j * step, parameters)) / step

    def _profile(self, heights, parameters):
        """Profile at `heights` (n,) for parameter vectors (..., k): shape (..., n)."""
        columns = [parameters[..., j, None] for j in range(parameters.shape[-1])]
        return self.model(heights, *columns)

    def log_likelihood(self, theta):
        """Gaussian log likelihood of parameter vectors theta (..., k); -inf where the
        covariance is not positive definite or the profile is undefined."""
        theta = np.atleast_1d(np.asarray(theta, float))
        k = len(self.names)
        residual = self.data.speeds - self._profile(self.data.heights, theta[..., :k])
        if self.diagonal and not self.relative:
            return self._independent_log_likelihood(theta, residual)
        covariance = self.covariance(theta)
        result = np.full(theta.shape[:-1], -np.inf)
        usable = np.all(np.isfinite(residual), axis=-1) & np.all(np.isfinite(covariance),
                                                                   axis=(-2, -1))
        if not np.any(usable):
            return result
        eigenvalues = np.linalg.eigvalsh(covariance[usable])
        positive = np.all(eigenvalues > 0, axis=-1)
        index = np.flatnonzero(usable)[positive]
        factor = np.linalg.cholesky(covariance[index])
        whitened = np.linalg.solve(factor, residual[index][..., None])[..., 0]
        result[index] = -0.5 * np.sum(whitened**2, axis=-1) \
            - np.sum(np.log(np.diagonal(factor, axis1=-2, axis2=-1)), axis=-1) \
            - 0.5 * residual.shape[-1] * np.log(2 * np.pi)
        return result

    def gate_variances(self, parameters):
        """Variances of the speeds at the gates without the scatter [m2 s-2]: the diagonal
        of :meth:`covariance` for profile parameters (..., k), shape (..., n)."""
        speed = variances(self.data.speed_covariance)
        if self.relative:
            speed = speed * self._profile(self.data.heights, parameters) ** 2
        if self.exact_heights:                  # no slope (a second profile) to carry
            return np.broadcast_to(speed, parameters.shape[:-1] + speed.shape[-1:])
        return speed + self._slope(parameters) ** 2 * variances(self.data.height_covariance)

    def _independent_log_likelihood(self, theta, residual):
        """The same for diagonal covariances: no factorisation, O(n) per walker."""
        k = len(self.names)
        variance = self.gate_variances(theta[..., :k])
        if self.scatter:
            variance = variance + np.exp(2 * theta[..., k, None])
        with np.errstate(divide="ignore", invalid="ignore"):
            result = -0.5 * np.sum(residual**2 / variance + np.log(2 * np.pi * variance),
                                   axis=-1)
        return np.where(np.isfinite(result), result, -np.inf)

    def log_probability(self, thetas):
        """log posterior of walkers (W, k), for emcee's ``vectorize=True``; shape (W,)."""
        thetas = np.asarray(thetas, float)
        prior = self.log_prior(thetas)
        result = np.full(thetas.shape[:-1], -np.inf)
        inside = np.isfinite(prior)
        if np.any(inside):
            result[inside] = prior[inside] + self.log_likelihood(thetas[inside])
        return result

    def __call__(self, theta):
        return float(self.log_probability(np.asarray(theta, float)[None, :])[0])


def _log_prior_density(value, a, b, kind):
    """Unnormalised log density of one prior: uniform / log_uniform on [a, b] (-inf
    outside), or normal with mean a and standard deviation b."""
    if kind == "normal":
        return -0.5 * ((value - a) / b) ** 2
    inside = (a <= value) & (value <= b)
    log_density = -np.log(np.where(inside, value, 1.0)) if kind == "log_uniform" else 0.0
    return np.where(inside, log_density, -np.inf)


def maximum_a_posteriori(posterior):
    """MAP by Nelder-Mead from the least-squares fit (and the residual scatter)."""
    data = posterior.data
    start = least_squares_profile(posterior.name, data.heights, data.speeds,
                                  fixed=posterior.fixed)
    theta = list(start["parameters"])
    if posterior.scatter:
        low, _, kind = posterior.priors["ln_sigma"]
        floor = np.exp(low + 1) if kind != "normal" else np.exp(low)   # inside the prior
        theta.append(np.log(max(start["residual_std"], floor)))
    result = minimize(lambda t: -posterior(t), np.array(theta), method="Nelder-Mead",
                      options={"xatol": 1e-10, "fatol": 1e-10, "maxiter": 20000})
    return result.x


def rank_rhat(chains):
    """Rank-normalised split R-hat [2] of one parameter; chains shape (m, n) -> float.

    The larger of the bulk (rank-normalised draws) and tail (rank-normalised folded
    draws |x - median|) split R-hat.
    """
    def split_rhat(values):
        half = values.shape[1] // 2
        split = np.concatenate([values[:, :half], values[:, half:2 * half]])
        n = split.shape[1]
        within = np.mean(np.var(split, axis=1, ddof=1))
        between = n * np.var(np.mean(split, axis=1), ddof=1)
        return np.sqrt(((n - 1) / n * within + between / n) / within)

    def normalised(values):
        ranks = rankdata(values, method="average").reshape(values.shape)
        return ndtri((ranks - 3 / 8) / (values.size + 1 / 4))

    chains = np.asarray(chains, float)
    folded = np.abs(chains - np.median(chains))
    return max(split_rhat(normalised(chains)), split_rhat(normalised(folded)))


def sample_posterior(posterior, seed, walkers=MIN_WALKERS, ensembles=4, steps=500,
                     max_steps=50000):
    """Sample with several independent emcee ensembles until converged.

    The ensembles run in rounds of `steps`, all to the same length, until that length is
    above TAU_FACTOR times the largest autocorrelation time (or `max_steps`); then
    burn-in (2 tau) is dropped, the chains are thinned (tau / 2) and R-hat is taken
    across ensembles.

    Parameters
    ----------
    posterior : ProfilePosterior
    seed : int or numpy.random.Generator
        Same seed, same chains.

    Returns
    -------
    dict
        ``samples`` (ensembles, draws, parameters) after burn-in and thinning, ``chain``
        (ensembles, steps, walkers, parameters) in full, ``tau``, ``burn``, ``thin``,
        ``rhat`` per parameter, ``map``, ``names``.

    Raises
    ------
    NotConverged
        With tau, the chain length and R-hat, when either criterion fails.
    """
    if walkers < MIN_WALKERS:
        raise ValueError(f"walkers must be >= {MIN_WALKERS}, got {walkers}")
    entropy = seed.integers(2**63) if isinstance(seed, np.random.Generator) else seed
    streams = np.random.SeedSequence(entropy).spawn(ensembles + 1)
    centre = maximum_a_posteriori(posterior)
    space = SamplingSpace(posterior)
    ball = np.random.default_rng(streams[-1])
    start = np.concatenate([_starting_ball(space, space.to_sampled(centre), ball, walkers)
                            for _ in range(ensembles)])
    state = emcee.State(start, random_state=np.random.RandomState(
        np.random.MT19937(streams[0])).get_state())
    target = space.log_probability if space.transformed else \
        posterior.log_probability                       # nothing to transform: no wrapper
    sampler = emcee.EnsembleSampler(walkers * ensembles, centre.size, target, vectorize=True,
                                    moves=IndependentStretchMove(ensembles))
    chains, taus = _run_until_converged(sampler, state, ensembles, steps, max_steps, space)
    tau = np.max(taus, axis=0)
    burn, thin = int(np.ceil(2 * tau.max())), max(1, int(tau.min() / 2))
    chains = space.to_natural(np.array(chains))         # (ensembles, steps, walkers, k)
    samples = chains[:, burn::thin].reshape(len(chains), -1, centre.size)
    rhat = np.array([rank_rhat(samples[:, :, k]) for k in range(centre.size)])
    length = chains.shape[1]
    if length < TAU_FACTOR * tau.max() or np.any(rhat > RHAT_LIMIT):
        raise NotConverged(
            f"the chains did not converge: length {length} steps against {TAU_FACTOR} x tau "
            f"= {TAU_FACTOR * tau.max():.0f} (tau {np.round(tau, 1).tolist()}), rank R-hat "
            f"{np.round(rhat, 4).tolist()} (limit {RHAT_LIMIT}); allowed: more steps "
            "(max_steps), more walkers, or narrower priors")
    return {"samples": samples, "chain": chains, "tau": tau,
            "burn": burn, "thin": thin, "rhat": rhat, "map": centre,
            "names": posterior.parameter_names,
            "quantile_mcse": quantile_standard_errors(chains[:, burn::thin])}


class SamplingSpace:
    """The space the walkers move in: parameters with a log-uniform prior as their
    natural logarithm, the others as they are; for the log law, ln z0 is replaced by
    the speed at the data's central height.

    The density in the sampled space is the posterior times the Jacobian of the map
    back, ``d theta / d ln theta = theta``; with a log-uniform prior (density 1/theta)
    the two cancel and the prior is flat in ln theta.

    Log law. U(z) = (u*/kappa)(ln z - ln z0) is linear in (u*, U_c), with
    U_c = U(z_c) = (u*/kappa)(ln z_c - ln z0) the speed at z_c = exp(mean ln z) of the
    heights (Eq. 3.1 [1] of :mod:`uq.physics.profiles`). For a fixed noise the likelihood
    is then a Gaussian in (u*, U_c) whose two axes are uncorrelated (ln z - ln z_c has
    zero mean), where in (u*, ln z0) = (u*, ln z_c - kappa U_c / u*) it is a curved
    ridge: on three heights the ensemble's autocorrelation time falls from ~800 to
    ~30 steps. The target is the same posterior: the map back
    ln z0 = ln z_c - kappa U_c / u* has the Jacobian |d ln z0 / d U_c| = kappa / u*.
    """

    def __init__(self, posterior):
        self.posterior = posterior
        names = posterior.parameter_names
        self.logarithmic = np.array([posterior.priors[name][2] == "log_uniform"
                                     for name in names])
        self.centred = posterior.name == "log_law" and \
            posterior.priors["roughness_length"][2] == "log_uniform"
        if self.centred:
            self.speed_index = names.index("friction_velocity")
            self.roughness_index = names.index("roughness_length")
            self.ln_centre_height = float(np.mean(np.log(posterior.data.heights)))
        self.transformed = bool(self.logarithmic.any() or self.centred)

    def to_sampled(self, theta):
        """Parameters (..., k) in their own units -> the sampled space."""
        out = np.array(theta, float)
        out[..., self.logarithmic] = np.log(out[..., self.logarithmic])
        if self.centred:                                # U_c = (u*/kappa)(ln z_c - ln z0)
            out[..., self.roughness_index] = out[..., self.speed_index] / VON_KARMAN * (
                self.ln_centre_height - out[..., self.roughness_index])
        return out

    def to_natural(self, sampled):
        """Points (..., k) of the sampled space -> parameters in their own units."""
        out = np.array(sampled, float)
        with np.errstate(over="ignore", divide="ignore", invalid="ignore"):
            if self.centred:                            # ln z0 = ln z_c - kappa U_c / u*
                out[..., self.roughness_index] = self.ln_centre_height - VON_KARMAN * \
                    out[..., self.roughness_index] / out[..., self.speed_index]
            out[..., self.logarithmic] = np.exp(out[..., self.logarithmic])  # beyond: -inf
        return out

    def to_reported(self, sampled):
        """Points (..., k) of the sampled space -> the parameters as reported, with the
        logarithm of each log-uniform one (ln z0): the coordinates of tau's check."""
        out = self.to_natural(sampled)
        with np.errstate(divide="ignore", invalid="ignore"):
            out[..., self.logarithmic] = np.log(out[..., self.logarithmic])
        return out

    def log_jacobian(self, natural):
        """log |d theta / d point| at parameters (..., k) in their own units: ln theta of
        each logarithmic one, and ln(kappa / u*) for the log law's U_c (-inf at u* <= 0)."""
        with np.errstate(divide="ignore", invalid="ignore"):
            total = np.sum(np.log(natural[..., self.logarithmic]), axis=-1)
            if self.centred:
                speed = natural[..., self.speed_index]
                total = total + np.where(speed > 0, np.log(VON_KARMAN / np.where(
                    speed > 0, speed, 1.0)), -np.inf)
        return total

    def log_probability(self, points):
        """log density of walkers (W, k) in the sampled space, for emcee; shape (W,)."""
        if not self.transformed:                        # the posterior itself
            return self.posterior.log_probability(points)
        natural = self.to_natural(np.asarray(points, float))
        result = self.posterior.log_probability(natural)
        inside = np.isfinite(result)
        result[inside] = result[inside] + self.log_jacobian(natural[inside])
        return np.where(np.isnan(result), -np.inf, result)

    def __call__(self, point):
        return float(self.log_probability(np.asarray(point, float)[None, :])[0])


def quantile_standard_errors(chains, probabilities=SUMMARY_PROBABILITIES):
    """Monte Carlo standard error of posterior quantiles [2] (Sec. 4.3).

    For each parameter and probability p: the effective sample size S of the indicator
    I(theta <= q_p) (integrated autocorrelation time over the walkers of each
    independent ensemble, emcee's estimator), then the draws' quantiles at the
    probabilities a +- 1 sd of Beta(S p + 1, S (1 - p) + 1); the standard error is half
    their distance. Slowly mixing tails have a long indicator autocorrelation, hence a
    small S and a large error.

    Parameters
    ----------
    chains : numpy.ndarray
        (ensembles, steps, walkers, k): the draws the quantiles are taken from (after
        burn-in; thinned by tau/2, the indicator's autocorrelation is short and cheap to
        sum).
    probabilities : dict
        key -> p.

    Returns
    -------
    dict
        key -> array (k,) of standard errors, in the parameters' units.
    """
    chains = np.asarray(chains, float)
    flat = chains.reshape(-1, chains.shape[-1])
    lower, upper = norm.cdf(-1.0), norm.cdf(1.0)     # +- 1 standard deviation of a normal
    out = {key: np.full(chains.shape[-1], np.nan) for key in probabilities}
    for k in range(chains.shape[-1]):
        values = flat[:, k]
        for key, p in probabilities.items():
            quantile = np.quantile(values, p)
            size = sum(_indicator_effective_size(ensemble[..., k] <= quantile)
                       for ensemble in chains)
            a = beta_distribution.ppf([lower, upper], size * p + 1, size * (1 - p) + 1)
            ends = np.quantile(values, a)
            out[key][k] = (ends[1] - ends[0]) / 2
    return out


def _indicator_effective_size(indicator):
    """Effective sample size of an indicator series (steps, walkers) of one ensemble:
    draws / integrated autocorrelation time.

    The autocovariance is pooled over the walkers about the ensemble's mean (a walker
    that stays on one side of the quantile has no autocorrelation of its own, but it
    does add to the pooled one), and summed up to Sokal's automatic window (emcee's,
    c = 5) [1].
    """
    series = indicator.astype(float)
    series = series - series.mean()
    steps = series.shape[0]
    spectrum = np.fft.rfft(series, n=2 * steps, axis=0)
    covariance = np.fft.irfft(spectrum * np.conj(spectrum), axis=0)[:steps].sum(axis=1)
    if not covariance[0] > 0:                          # every draw on one side
        return float(series.size)
    taus = 2 * np.cumsum(covariance / covariance[0]) - 1
    tau = taus[emcee.autocorr.auto_window(taus, AUTOCORRELATION_WINDOW)]
    return series.size / max(float(tau), 1.0)


def _starting_ball(space, centre, rng, walkers):
    """Walkers in a small ball about the MAP (`centre`, in the sampled space of `space`),
    pulled towards it until each lies inside the prior's support (the MAP may sit on a
    bound, e.g. no scatter: ln_sigma low)."""
    if not np.isfinite(space(centre)):
        raise NotConverged(f"the maximum a posteriori {np.round(space.to_natural(centre), 6).tolist()} "
                           "has zero posterior density; allowed: priors that contain the data's fit")
    offsets = BALL * rng.standard_normal((walkers, centre.size)) * np.where(centre == 0, 1.0,
                                                                            np.abs(centre))
    for _ in range(60):
        bad = ~np.isfinite(space.log_probability(centre + offsets))
        if not np.any(bad):
            break
        offsets[bad] *= 0.5
    return centre + offsets


def _run_until_converged(sampler, state, ensembles, steps, max_steps, space):
    """Run the ensembles (one sampler, :mod:`uq.fit.ensembles`) in rounds of `steps`
    until their length is above TAU_FACTOR x the largest tau of any ensemble (or
    `max_steps`); returns the chains (E, steps, W, k) and tau (E, k).

    tau is per parameter the larger of the walkers' own coordinates and the parameters
    as reported (ln z0 for a log-uniform one, :meth:`SamplingSpace.to_reported`): a
    function of a well-mixed chain may still be autocorrelated longer (z0 from u* and
    U_c), and the criterion must hold for what the user reads."""
    while True:
        state = sampler.run_mcmc(state, steps, progress=False)
        chains = split_ensembles(sampler.get_chain(), ensembles)
        taus = integrated_times(chains, AUTOCORRELATION_WINDOW)
        iteration = sampler.iteration
        if iteration > TAU_FACTOR * np.max(taus) or iteration >= max_steps:
            if space.transformed:                       # only then: the check costs FFTs
                taus = np.maximum(taus, integrated_times(space.to_reported(chains),
                                                         AUTOCORRELATION_WINDOW))
            if iteration > TAU_FACTOR * np.max(taus) or iteration >= max_steps:
                return chains, taus


def posterior_summary(samples, names):
    """Median and the 68 % and 95 % central credible intervals of each parameter."""
    flat = samples.reshape(-1, samples.shape[-1])
    quantiles = np.quantile(flat, list(SUMMARY_PROBABILITIES.values()), axis=0)
    return {name: dict(zip(SUMMARY_PROBABILITIES, quantiles[:, k]))
            for k, name in enumerate(names)}
