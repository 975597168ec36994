"""Reference-wind-speed bins and the per-bin statistics of a verification campaign.

Bins are ``width`` wide and centred on multiples of ``width`` (0.5 m/s: centres 4.0, 4.5,
...). A bin holds the half-open interval [centre - width/2, centre + width/2): a record
exactly on an edge belongs to the bin above it (4.25 m/s is in the 4.5 m/s bin).

References
----------
.. [1] IEC 61400-12-1:2017, Annex L (calibration of remote sensing devices).
.. [2] S. Coll-Vinent and A. Miquel, FLS200 as a golden floating lidar (seed document).
"""
import numpy as np

from uq.constants import GOLDEN_BIN_WIDTH, GOLDEN_MIN_RECORDS, GOLDEN_REQUIRED_RANGE


def bin_index(speed, width=GOLDEN_BIN_WIDTH):
    """Integer k of the bin centred on k * width that holds each speed [m s-1].

    ``floor(speed / width + 1/2)``: exact for edges that are binary fractions (0.25,
    4.75, ...), which covers every edge of the 0.5 m/s grid. NaN speeds give -1.
    """
    speed = np.asarray(speed, dtype=float)
    k = np.floor(speed / width + 0.5)
    return np.where(np.isfinite(k), k, -1).astype(int)


def bin_centres(low, high, width=GOLDEN_BIN_WIDTH):
    """Centres from `low` to `high` inclusive, multiples of `width` [m s-1]."""
    first, last = int(np.ceil(low / width - 1e-9)), int(np.floor(high / width + 1e-9))
    return width * np.arange(first, last + 1)


def bin_statistics(reference, unit, centres, width=GOLDEN_BIN_WIDTH):
    """Per-bin statistics of paired records, binned by the reference speed.

    Parameters
    ----------
    reference, unit : ndarray, shape (n,)
        Concurrent 10-min mean wind speeds [m s-1]; pairs with a NaN are left out.
    centres : ndarray, shape (m,)
        Bin centres [m s-1] (:func:`bin_centres`).

    Returns
    -------
    dict of ndarray, shape (m,)
        ``n_records``; ``reference_mean``, ``unit_mean`` [m s-1]; ``unit_std`` (sigma of
        the unit's speeds in the bin, ddof 1) [m s-1]; ``deviation_mean`` (mean of unit
        minus reference, Delta v of Eq. 3 [2]) and ``deviation_std`` (ddof 1) [m s-1].
        A bin with no record has NaN means; with one record NaN standard deviations.
    """
    reference, unit = np.asarray(reference, float), np.asarray(unit, float)
    valid = np.isfinite(reference) & np.isfinite(unit)
    k = bin_index(reference[valid], width)
    position = {int(c): i for i, c in enumerate(np.rint(np.asarray(centres) / width))}
    index = np.array([position.get(int(v), -1) for v in k], dtype=int)
    inside = index >= 0
    groups = [np.flatnonzero(inside & (index == i)) for i in range(len(centres))]
    ref, uni = reference[valid], unit[valid]
    return {"n_records": np.array([len(g) for g in groups]),
            "reference_mean": _per_group(ref, groups, np.mean),
            "unit_mean": _per_group(uni, groups, np.mean),
            "unit_std": _per_group(uni, groups, _sample_std),
            "deviation_mean": _per_group(uni - ref, groups, np.mean),
            "deviation_std": _per_group(uni - ref, groups, _sample_std)}


def sufficient_bins(n_records, centres, minimum=GOLDEN_MIN_RECORDS,
                    required=GOLDEN_REQUIRED_RANGE):
    """(sufficient, required): a bin is sufficient with at least `minimum` records;
    required bins are those with centres in `required` (inclusive) [m s-1]."""
    centres = np.asarray(centres)
    needed = (centres >= required[0] - 1e-9) & (centres <= required[1] + 1e-9)
    return np.asarray(n_records) >= minimum, needed


def _per_group(values, groups, statistic):
    return np.array([statistic(values[g]) if len(g) else np.nan for g in groups])


def _sample_std(values):
    return float(np.std(values, ddof=1)) if len(values) > 1 else np.nan
