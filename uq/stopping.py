"""When adaptive Monte Carlo may stop: JCGM 101 7.9, and a rule that does not stop early.

Both rules look at h independent batch values of each result (mean, u, interval
endpoints) after every step and compare twice the standard deviation of their average,
2 s_y, with the numerical tolerance delta of the requested digits (JCGM 101 7.9.2).

``jcgm101`` (JCGM 101:2008, 7.9.4)
    Stop when the *estimate* 2 s_y <= delta. With few batches s_y is itself very
    uncertain: with h - 1 = 3 degrees of freedom, P(s < sigma / 2) = P(chi2_3 < 0.75) =
    14 %, and the rule is applied after every step, so a run can stop while its true
    numerical error is still well above delta.
``confident`` (this project)
    Stop when an *upper confidence bound* of the true standard deviation does:
    ``2 s_y sqrt((h - 1) / chi2_{alpha_j}(h - 1)) <= delta``, with h >= 8 batches. The
    level of the j-th check is alpha_j = alpha / (j (j + 1)), whose sum over all checks
    is alpha = 5 %; by the union bound the probability of *ever* stopping while the true
    2 sigma_y exceeds delta is at most 5 % (for batch values close to normal, which
    batches of >= 10^4 trials are). The price is a few more batches than 7.9 needs.

References
----------
.. [1] JCGM 101:2008, 7.9 (adaptive Monte Carlo procedure).
"""
import numpy as np
from scipy.stats import chi2

STOPPING_RULES = ("jcgm101", "confident")
#: Overall probability of stopping too early under ``confident`` [1].
CONFIDENT_ALPHA = 0.05
#: Fewest batches before ``confident`` may stop: below ~8 the chi-square bound on s is
#: so wide that stopping is mostly a matter of luck either way.
CONFIDENT_MIN_BATCHES = 8


def standard_error(batch_values):
    """s_y: standard deviation of the average of the h batch values (axis 0)."""
    values = np.asarray(batch_values)
    return np.std(values, axis=0, ddof=1) / np.sqrt(len(values))


def upper_bound_factor(h, check):
    """sqrt((h - 1) / chi2_{alpha_j}(h - 1)): one-sided upper confidence factor of s at the
    `check`-th look (1-based), alpha_j = alpha / (j (j + 1))."""
    alpha = CONFIDENT_ALPHA / (check * (check + 1))
    return np.sqrt((h - 1) / chi2.ppf(alpha, h - 1))


def may_stop(rule, batches, delta, check):
    """Is 2 s_y (or its upper bound) <= delta for every batch quantity and element?

    Parameters
    ----------
    rule : {"jcgm101", "confident"}
    batches : list of ndarray
        Batch values of each quantity, each of shape (h, *shape).
    delta : ndarray
        Numerical tolerance, of `shape`.
    check : int
        How many times the rule has been applied in this run, this one included.
    """
    h = len(batches[0])
    if h < 2 or (rule == "confident" and h < CONFIDENT_MIN_BATCHES):
        return False
    factor = 1.0 if rule == "jcgm101" else upper_bound_factor(h, check)
    error = np.max([2 * factor * standard_error(values) for values in batches], axis=0)
    return bool(np.all(error <= delta))
