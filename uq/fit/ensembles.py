"""Independent emcee ensembles advanced side by side by one sampler.

A fit runs several independent ensembles (R-hat is taken across them). Run as separate
emcee samplers, each step of each ensemble pays emcee's fixed cost per step and per
walker (a Python loop over the walkers to accept and to unpack the log densities): on a
3-row table, ~0.35 ms of each 0.45 ms step, three quarters of the sampling time.
:class:`IndependentStretchMove` is an emcee move (its documented extension point,
:class:`emcee.moves.Move`) that holds E ensembles of W walkers in one sampler of E x W
walkers and moves each ensemble with the stretch move of Goodman and Weare [1] in
emcee's red-blue form [2], proposing from its own walkers only: the ensembles stay
independent Markov chains, each with the law of emcee's :class:`~emcee.moves.StretchMove`,
and one call of the vectorised log density and one vectorised accept serve all of them.

Walker w of ensemble e is walker ``e * W + w`` of the sampler.

:func:`integrated_times` is emcee's integrated autocorrelation time
(:func:`emcee.autocorr.integrated_time`, Sokal's window) of each ensemble, vectorised
over the walkers (emcee loops over them, one FFT each).

References
----------
.. [1] Goodman, J. and Weare, J. (2010). Ensemble samplers with affine invariance.
   Communications in Applied Mathematics and Computational Science 5(1), 65-80.
.. [2] Foreman-Mackey, D. et al. (2013). emcee: The MCMC Hammer. PASP 125, 306
   (Algorithm 3, the parallel stretch move).
"""
import emcee
import numpy as np

#: Scale a of the stretch move's g(z) ~ 1/sqrt(z) on [1/a, a]: Goodman and Weare's and
#: emcee's default [1, 2].
STRETCH_SCALE = 2.0


class IndependentStretchMove(emcee.moves.Move):
    """The stretch move [1] with the red-blue split [2], per independent ensemble.

    Parameters
    ----------
    ensembles : int
        E: the sampler's walkers are E ensembles of W = walkers / E each.
    scale : float
        a of the stretch distribution (> 1).
    """

    def __init__(self, ensembles, scale=STRETCH_SCALE):
        self.ensembles, self.scale = int(ensembles), float(scale)

    def propose(self, model, state):
        """Move every walker once (each ensemble's two halves in turn); returns the new
        :class:`emcee.State` and the accepted flags (E x W,)."""
        random, ensembles = model.random, self.ensembles
        total, dimension = state.coords.shape
        coords = np.array(state.coords, float).reshape(ensembles, -1, dimension)
        log_prob = np.array(state.log_prob, float).reshape(ensembles, -1)
        walkers = coords.shape[1]
        order = np.argsort(random.rand(ensembles, walkers), axis=1)   # a random split
        halves = (order[:, :walkers // 2], order[:, walkers // 2:])
        accepted = np.zeros((ensembles, walkers), bool)
        for active, complement in (halves, halves[::-1]):
            proposal, log_factor = self._proposal(coords, active, complement, random)
            new = np.asarray(model.log_prob_fn(proposal.reshape(-1, dimension)),
                             float).reshape(active.shape)
            old = np.take_along_axis(log_prob, active, axis=1)
            accept = log_factor + new - old > np.log(random.rand(*active.shape))
            ensemble, position = np.nonzero(accept)
            walker = active[ensemble, position]
            coords[ensemble, walker] = proposal[ensemble, position]
            log_prob[ensemble, walker] = new[ensemble, position]
            accepted[ensemble, walker] = True
        state.coords = coords.reshape(total, dimension)
        state.log_prob = log_prob.reshape(total)
        return state, accepted.reshape(total)

    def _proposal(self, coords, active, complement, random):
        """Y = X_j + z (X_k - X_j) for each active walker k, X_j drawn from its own
        ensemble's complementary half, z ~ g(z) (Eq. 10 [1]); log of the acceptance
        factor z^(d - 1) (Eq. 7 [1])."""
        a = self.scale
        z = ((a - 1.0) * random.rand(*active.shape) + 1.0) ** 2 / a   # inverse CDF of g
        pick = random.randint(complement.shape[1], size=active.shape)
        partner = np.take_along_axis(complement, pick, axis=1)
        walkers = np.take_along_axis(coords, active[..., None], axis=1)
        partners = np.take_along_axis(coords, partner[..., None], axis=1)
        proposal = partners - (partners - walkers) * z[..., None]
        return proposal, (coords.shape[-1] - 1.0) * np.log(z)


def split_ensembles(chain, ensembles):
    """A sampler's chain (steps, E x W, k) as E ensembles' chains (E, steps, W, k)."""
    steps, total, dimension = chain.shape
    return np.moveaxis(chain.reshape(steps, ensembles, total // ensembles, dimension), 1, 0)


def integrated_times(chains, window=5):
    """Integrated autocorrelation time of each ensemble and parameter [steps]:
    :func:`emcee.autocorr.integrated_time` with ``c=window, tol=0`` (the walkers'
    normalised autocorrelation functions averaged, summed up to Sokal's window) [2].

    Parameters
    ----------
    chains : numpy.ndarray
        (E, steps, W, k).
    window : float
        Sokal's c.

    Returns
    -------
    numpy.ndarray
        (E, k).
    """
    ensembles, steps, _, dimension = chains.shape
    size = 2 * 2 ** int(np.ceil(np.log2(steps)))        # emcee's zero padding
    lags = np.arange(steps)
    out = np.empty((ensembles, dimension))
    for e in range(ensembles):                           # bounded memory: one at a time
        for k in range(dimension):
            series = chains[e, :, :, k]
            series = series - series.mean(axis=0)
            spectrum = np.fft.rfft(series, n=size, axis=0)
            acf = np.fft.irfft(spectrum * np.conj(spectrum), n=size, axis=0)[:steps]
            with np.errstate(divide="ignore", invalid="ignore"):
                mean_acf = np.mean(acf / acf[0], axis=1)
            taus = 2.0 * np.cumsum(mean_acf) - 1.0
            out[e, k] = taus[np.argmin(lags < window * taus)]   # emcee's auto_window
    return out
