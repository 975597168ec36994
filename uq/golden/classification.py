"""Classification uncertainty: sensitivity slopes and seed Eq. 1.

The sensitivity of a unit to an environmental variable x is the slope m [% per unit of
x] of the ordinary least-squares line of the percentage deviation
``100 (v_unit - v_ref) / v_ref`` against x, over the records whose reference speed lies in
the required bins (4-16 m/s). Its significance is the two-sided t-test of m = 0
(``scipy.stats.linregress``).

Two routes turn slopes into a standard uncertainty per bin, both in [m s-1]:

* **per variable** (Eq. 1 [1]), for a specific measurement campaign (SMC):
  ``u_class,i = (v_i / 100) sqrt(sum_j (m_j |x_SMC,j,i - x_ver,j,i|)^2)``, with the bin
  means of x in the SMC and in the verification campaign, v_i the bin centre;
* **class number**: a deviation bounded by +-k % with no preferred value inside is a
  rectangular distribution, so ``u_class,i = (k / sqrt(3)) v_i / 100`` [2].
  :func:`class_number` derives k from the slopes and the ranges of the variables: the
  deviation swings by |m_j| (x_max - x_min) over a variable's range, so its largest
  departure from the middle of the range is half that; independent variables combine in
  quadrature. This is this tool's reading of the class-number logic of IEC 61400-12-1
  Annex L; a published class number may be given instead.

References
----------
.. [1] S. Coll-Vinent and A. Miquel, FLS200 as a golden floating lidar, Eq. 1.
.. [2] IEC 61400-12-1:2017, Annex L; JCGM 100:2008, 4.3.7 (rectangular distribution).
"""
from dataclasses import dataclass

import numpy as np
from scipy import stats

from uq.constants import GOLDEN_SIGNIFICANCE

PERCENT = 100.0
RECTANGULAR_DIVISOR = np.sqrt(3.0)       # JCGM 100:2008, 4.3.7: u = a / sqrt(3)


@dataclass(frozen=True)
class Sensitivity:
    """OLS slope of the percentage deviation against one variable.

    Attributes: ``slope`` [% per unit of x], ``intercept`` [%], ``slope_standard_error``,
    ``p_value`` (two-sided, m = 0), ``r_squared`` [1], ``n_records``, ``significant``.
    """

    slope: float
    intercept: float
    slope_standard_error: float
    p_value: float
    r_squared: float
    n_records: int
    significant: bool


def percentage_deviation(unit, reference):
    """``100 (unit - reference) / reference`` [%]; NaN where the reference is not > 0."""
    unit, reference = np.asarray(unit, float), np.asarray(reference, float)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(reference > 0, PERCENT * (unit - reference) / reference, np.nan)


def sensitivity(variable, deviation_percent, significance=GOLDEN_SIGNIFICANCE):
    """:class:`Sensitivity` of the deviation [%] to `variable`; pairs with a NaN are left
    out. Fewer than 3 pairs, or a constant variable, give NaN and not significant."""
    x, y = np.asarray(variable, float), np.asarray(deviation_percent, float)
    keep = np.isfinite(x) & np.isfinite(y)
    x, y = x[keep], y[keep]
    if len(x) < 3 or np.ptp(x) == 0:
        return Sensitivity(np.nan, np.nan, np.nan, np.nan, np.nan, int(len(x)), False)
    fit = stats.linregress(x, y)
    return Sensitivity(float(fit.slope), float(fit.intercept), float(fit.stderr),
                       float(fit.pvalue), float(fit.rvalue ** 2), int(len(x)),
                       bool(fit.pvalue < significance))


def per_variable_uncertainty(centres, slopes, smc_means, verification_means):
    """Eq. 1 [1]: classification uncertainty per bin [m s-1].

    Parameters
    ----------
    centres : ndarray, shape (m,)
        Bin centres v_i [m s-1].
    slopes : ndarray, shape (M,)
        Sensitivity slopes m_j [% per unit of x_j] of the variables used.
    smc_means, verification_means : ndarray, shape (M, m)
        Bin means of each variable in the SMC and in the verification campaign.
    """
    slopes = np.asarray(slopes, float)[:, None]
    spread = slopes * np.abs(np.asarray(smc_means, float) - np.asarray(verification_means,
                                                                          float))
    relative = np.sqrt(np.sum(spread ** 2, axis=0))                        # [%]
    return np.asarray(centres, float) / PERCENT * relative                 # Eq. 1 [1]


def class_number_uncertainty(centres, class_number):
    """Class route: ``(k / sqrt(3)) % of v_i`` [m s-1] [2]."""
    return class_number / RECTANGULAR_DIVISOR * np.asarray(centres, float) / PERCENT


def class_number(slopes, ranges):
    """Class number k [%] from slopes [% per unit] and ranges (low, high) of the variables:
    ``sqrt(sum_j (|m_j| (high_j - low_j) / 2)^2)`` (see the module docstring)."""
    half_swings = [abs(m) * (high - low) / 2.0 for m, (low, high) in zip(slopes, ranges)]
    return float(np.sqrt(np.sum(np.square(half_swings)))) if half_swings else 0.0
