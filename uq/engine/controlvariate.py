"""The GUM linearisation as a control variate for the Monte Carlo mean and variance.

For each trial, the first-order model ``L = c . (x - x_mean)`` (c: the exact complex-step
Jacobian of :mod:`uq.engine.gum`) is evaluated beside the model output Y. Its mean is zero and
its variance is known exactly, ``Var L = c^T V c = u_GUM^2``. Writing
``Var Y = Var L + (Var Y - Var L)``, only the bracket is estimated by sampling, from the
*same* trials:

    u_cv^2 = u_GUM^2 + S^2(Y) - S^2(L),        mean_cv = mean(Y) - mean(L)

The bracket equals ``Var R + 2 Cov(L, R)`` with ``R = Y - L`` the non-linear remainder,
so its sampling error vanishes as the model becomes linear; for a nearly linear model
a given accuracy of u takes far fewer trials. Coverage intervals are still the plain
Monte Carlo quantiles (the distribution of L is not known in general). The error of the
estimate is reported honestly from its spread over independent batches.

References
----------
.. [1] Glasserman, P. (2003). Monte Carlo Methods in Financial Engineering, Sec. 4.1
   (control variates with known mean), Springer.
.. [2] JCGM 100:2008, Eq. 13 (the law of propagation of uncertainty, exact for L).
"""
import numpy as np

from uq.engine.statistics import Moments


def input_columns(values, input_set):
    """Input deviations from their means as columns, shape (n, K) in the Jacobian's order."""
    means = input_set.means()
    columns = [(values[name] - means[name]).reshape(len(values[name]), -1)
               for name in input_set.names]
    return np.concatenate(columns, axis=1) if columns else np.zeros((0, 0))


def linear_deviation(jacobian, columns):
    """``L = c . (x - x_mean)`` per trial, shape (n, *output_shape)."""
    k = jacobian.shape[0]
    flat = columns @ jacobian.reshape(k, -1)
    return flat.reshape((len(columns),) + jacobian.shape[1:])


def masked_variance(values, valid):
    """Sample variance (ddof 1) and mean over axis 0 of the entries where `valid`."""
    moments = Moments(values.shape[1:])
    moments.update(values, valid)
    return moments.variance(), moments.mean


def controlled_u(u_gum, variance_y, variance_l):
    """u_cv = sqrt(u_GUM^2 + S^2(Y) - S^2(L)), clipped at 0 (a negative estimate of a
    variance that is truly >= 0 means the non-linear part is below sampling noise)."""
    return np.sqrt(np.maximum(u_gum**2 + variance_y - variance_l, 0.0))
