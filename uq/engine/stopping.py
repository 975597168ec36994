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

**GUM validated** (this project, ``stop_when_gum_valid``). Sampling to the requested
digits only to confirm the GUM wastes trials when the GUM is plainly right. JCGM 101
clause 8 validates the GUM interval when both endpoint differences |d| <= delta. Here a
run may stop as soon as that verdict is *decided despite the Monte Carlo noise*:
``|d| + 2 f s_e <= delta`` for both endpoints e, with s_e the standard error of the
endpoint from its batch values and f the same upper confidence factor as ``confident``
(f = 1 under ``jcgm101``). The reported Monte Carlo results then carry their (larger)
numerical error, which the result records; the GUM result is the one to use.

References
----------
.. [1] JCGM 101:2008, 7.9 (adaptive Monte Carlo procedure), 8 (validation).
"""
import numpy as np
from scipy.stats import chi2
from scipy.stats import t as student_t

STOPPING_RULES = ("jcgm101", "confident")
#: What may end a Monte Carlo run; its index is the CF flag value of ``mc_stopped_by``.
STOPPED_BY = ("digits", "gum validated", "sample limit", "fixed n")
#: Overall probability of stopping too early under ``confident`` [1].
CONFIDENT_ALPHA = 0.05
#: Fewest batches before ``confident`` may stop: below ~8 the chi-square bound on s is
#: so wide that stopping is mostly a matter of luck either way.
CONFIDENT_MIN_BATCHES = 8


def standard_error(batch_values):
    """s_y: standard deviation of the average of the h batch values (axis 0)."""
    values = np.asarray(batch_values)
    return np.std(values, axis=0, ddof=1) / np.sqrt(len(values))


def coverage_factor(h):
    """Factor on the standard error s_y of h batches for a 95 % statement about the
    true value: JCGM 101 7.9's 2 where the batches are many, Student's t_{0.975}(h - 1)
    where they are few (s_y is then itself uncertain: t_{0.975}(3) = 3.18); NaN < 2."""
    if h < 2:
        return np.nan
    return max(2.0, float(student_t.ppf(0.975, h - 1)))


def upper_bound_factor(h, check):
    """sqrt((h - 1) / chi2_{alpha_j}(h - 1)): one-sided upper confidence factor of s at the
    `check`-th look (1-based), alpha_j = alpha / (j (j + 1))."""
    alpha = CONFIDENT_ALPHA / (check * (check + 1))
    return np.sqrt((h - 1) / chi2.ppf(alpha, h - 1))


def _factor(rule, h, check):
    """None when the rule may not stop yet with h batches, else its factor on 2 s."""
    if h < 2 or (rule == "confident" and h < CONFIDENT_MIN_BATCHES):
        return None
    return 1.0 if rule == "jcgm101" else upper_bound_factor(h, check)


def gum_validated(rule, differences, endpoint_batches, delta, check):
    """Is the clause-8 validation of the GUM decided in its favour despite the noise?

    Parameters
    ----------
    differences : tuple of ndarray
        (d_low, d_high), GUM minus Monte Carlo endpoints, each of the output's shape.
    endpoint_batches : tuple of ndarray
        Batch values of the low and high endpoints, each of shape (h, *shape).
    delta : ndarray
        Numerical tolerance of the GUM u at the requested digits.
    """
    factor = _factor(rule, len(endpoint_batches[0]), check)
    if factor is None:
        return False
    with np.errstate(invalid="ignore"):
        return bool(all(np.all(np.abs(d) + 2 * factor * standard_error(b) <= delta)
                        for d, b in zip(differences, endpoint_batches)))


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
    factor = _factor(rule, len(batches[0]), check)
    if factor is None:
        return False
    error = np.max([2 * factor * standard_error(values) for values in batches], axis=0)
    return bool(np.all(error <= delta))
