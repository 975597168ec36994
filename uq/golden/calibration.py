"""Calibration uncertainty of a verified unit per reference-wind-speed bin (seed Eqs. 2-3).

Every term is a standard uncertainty in [m s-1], per bin, and kept separate:

=============================  ==============================================================
term                           meaning
=============================  ==============================================================
``reference_calibration``      u_cal,Ref: the reference's own calibration uncertainty
``reference_classification``   u_class,Ref: the reference's classification uncertainty (Eq. 1)
``statistical``                sigma_FLS / sqrt(N) (IEC) or sigma_dev / sqrt(N) (LUSR)
``mean_deviation``             |Delta v|, the mean unit-minus-reference deviation (IEC only)
``deviation``                  u_dev: statistical and mean deviation in quadrature (Eq. 3)
``calibration``                u_cal,FLS(Ref): the three independent terms in quadrature (Eq. 2)
=============================  ==============================================================

The seed prints Eq. 2 as ``U_cal,FLS(Ref) = U_cal,Ref^2 + U_class,Ref^2 + U_dev^2``: the
left side lacks its square (the right side is a sum of variances); here
``u_cal^2 = u_cal,Ref^2 + u_class,Ref^2 + u_dev^2``.

References
----------
.. [1] S. Coll-Vinent and A. Miquel, FLS200 as a golden floating lidar, Eqs. 2-3.
.. [2] IEC 61400-12-1:2017, Annex L.
.. [3] B. Gribben et al., Lidar uncertainty standard review (LUSR), Carbon Trust.
"""
import numpy as np

FRAMEWORKS = ("iec", "lusr")


def deviation_terms(statistics, framework):
    """Statistical and mean-deviation terms of u_dev for one framework (Eq. 3 [1]).

    Parameters
    ----------
    statistics : dict of ndarray
        :func:`uq.golden.binning.bin_statistics` of the comparison.
    framework : {"iec", "lusr"}

    Returns
    -------
    statistical, mean_deviation : ndarray [m s-1]
    """
    n = np.where(statistics["n_records"] > 0, statistics["n_records"], np.nan)
    if framework == "iec":
        statistical = statistics["unit_std"] / np.sqrt(n)                 # Eq. 3, IEC
        return statistical, np.abs(statistics["deviation_mean"])           # Delta v_i
    if framework == "lusr":
        statistical = statistics["deviation_std"] / np.sqrt(n)            # Eq. 3, LUSR
        return statistical, np.zeros_like(statistical)
    raise ValueError(f"framework {framework!r}; allowed: {', '.join(FRAMEWORKS)}")


def quadrature(*terms):
    """Root sum of squares of independent standard uncertainties [m s-1] (numbers, arrays
    or xarray objects, which keep their labels)."""
    terms = [t if hasattr(t, "dims") else np.asarray(t, dtype=float) for t in terms]
    return np.sqrt(sum(t ** 2 for t in terms))


def calibration_uncertainty(reference_calibration, reference_classification, deviation):
    """u_cal,FLS(Ref) = sqrt(u_cal,Ref^2 + u_class,Ref^2 + u_dev^2) [m s-1] (Eq. 2 [1],
    square restored on the left)."""
    return quadrature(reference_calibration, reference_classification, deviation)


def stated_calibration(centres, absolute, relative):
    """Calibration uncertainty of a reference stated as an absolute part [m s-1] and a
    part relative to the wind speed [1], independent, so in quadrature:
    ``sqrt(absolute^2 + (relative * v)^2)`` at the bin centres v [m s-1]."""
    return quadrature(absolute, relative * np.asarray(centres, dtype=float))
