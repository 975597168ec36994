"""Independent ensembles in one emcee sampler: the stretch move per ensemble, and the
integrated autocorrelation time against emcee's own estimator.

Monte Carlo tolerances: with N_eff = draws / tau effective samples, a mean is within
K sd / sqrt(N_eff) and a variance within K sqrt(2 / N_eff) relative (its Gaussian
sampling error), K = 5.
"""
import emcee
import numpy as np

from uq.fit.ensembles import IndependentStretchMove, integrated_times, split_ensembles

K = 5


def ar1_chains(phi, shape, seed):
    """AR(1) series x_t = phi x_(t-1) + e_t along axis 1 of `shape` (E, steps, W, k)."""
    rng = np.random.default_rng(seed)
    noise = rng.standard_normal(shape)
    out = np.empty(shape)
    out[:, 0] = noise[:, 0] / np.sqrt(1 - phi**2)
    for t in range(1, shape[1]):
        out[:, t] = phi * out[:, t - 1] + noise[:, t]
    return out


def test_integrated_times_are_emcees_estimator_per_ensemble():
    """A second implementation: emcee.autocorr.integrated_time (one FFT per walker) of
    each ensemble, to rounding (1e-12 relative: FFT round-off only)."""
    chains = ar1_chains(0.9, (3, 1500, 16, 2), seed=1)
    chains[2, :, :, 1] *= 1e3                           # the scale must not matter
    expected = [emcee.autocorr.integrated_time(ensemble, c=5, tol=0) for ensemble in chains]
    np.testing.assert_allclose(integrated_times(chains, 5), expected, rtol=1e-12)


def test_split_ensembles_takes_consecutive_walkers():
    chain = np.arange(5 * 6 * 2).reshape(5, 6, 2)       # (steps, E x W, k), E = 3, W = 2
    chains = split_ensembles(chain, 3)
    assert chains.shape == (3, 5, 2, 2)
    np.testing.assert_array_equal(chains[1], chain[:, 2:4])


class RecordingModel:
    """The parts of emcee's Model a move uses: the vectorised log density (recording
    what it was asked) and the random state."""

    def __init__(self, log_prob_fn, seed):
        self.asked = []
        self.random = np.random.RandomState(seed)
        self._log_prob_fn = log_prob_fn

    def log_prob_fn(self, points):
        self.asked.append(np.array(points))
        return self._log_prob_fn(points)


def test_each_ensemble_proposes_from_its_own_walkers_only():
    """Ensemble 1's walkers are NaN: had ensemble 0 drawn a partner there, its proposals
    would be NaN. Rows of a call are ensemble-major (half of each ensemble's walkers)."""
    ensembles, walkers, dimension = 2, 8, 3
    coords = np.random.default_rng(0).normal(size=(ensembles * walkers, dimension))
    coords[walkers:] = np.nan
    state = emcee.State(coords, log_prob=np.zeros(ensembles * walkers))
    model = RecordingModel(lambda x: -0.5 * np.sum(x**2, axis=1), seed=1)
    for _ in range(20):
        state, _ = IndependentStretchMove(ensembles).propose(model, state)
    for asked in model.asked:
        assert np.all(np.isfinite(asked[:walkers // 2]))
        assert np.all(np.isnan(asked[walkers // 2:]))
    assert np.all(np.isfinite(state.coords[:walkers]))


def test_independent_ensembles_sample_a_correlated_gaussian():
    """Four ensembles of 32 walkers on a 3-D Gaussian (correlations 0.9 and -0.3, scales 1 to 100):
    mean and covariance of each ensemble within K Monte Carlo errors of the truth, and
    the ensembles' chains differ (independent streams)."""
    scales = np.array([1.0, 10.0, 100.0])
    correlation = np.array([[1.0, 0.9, 0.0], [0.9, 1.0, -0.3], [0.0, -0.3, 1.0]])
    covariance = correlation * np.outer(scales, scales)
    precision = np.linalg.inv(covariance)
    ensembles, walkers, steps = 4, 32, 3000

    def log_density(points):
        return -0.5 * np.einsum("ni,ij,nj->n", points, precision, points)

    start = np.random.default_rng(2).normal(size=(ensembles * walkers, 3)) * scales
    sampler = emcee.EnsembleSampler(ensembles * walkers, 3, log_density, vectorize=True,
                                    moves=IndependentStretchMove(ensembles))
    sampler.run_mcmc(emcee.State(start, random_state=np.random.RandomState(3).get_state()),
                     steps)
    chains = split_ensembles(sampler.get_chain(), ensembles)
    taus = integrated_times(chains, 5)
    assert np.all(steps > 50 * taus)
    burn = int(np.ceil(2 * taus.max()))
    for ensemble, tau in zip(chains, taus):
        draws = ensemble[burn:].reshape(-1, 3)
        effective = len(draws) / tau.max()
        np.testing.assert_array_less(np.abs(draws.mean(axis=0)),
                                     K * scales / np.sqrt(effective))
        np.testing.assert_array_less(np.abs(np.var(draws, axis=0) / scales**2 - 1),
                                     K * np.sqrt(2 / effective))
        upper = np.triu_indices(3, 1)                   # the three correlations
        sample_correlation = np.corrcoef(draws.T)[upper]
        # sd of a sample correlation r: (1 - r^2) / sqrt(N_eff)
        np.testing.assert_array_less(np.abs(sample_correlation - correlation[upper]),
                                     K * (1 - correlation[upper]**2) / np.sqrt(effective))
    assert not np.allclose(chains[0, -1], chains[1, -1])
