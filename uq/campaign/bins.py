"""Per-bin statistics of a campaign's TI and its errors against a reference, with the
bins of ``uq golden`` (:mod:`uq.golden.binning`: 0.5 m/s wide, centred on multiples of
the width, a record on an edge in the bin above).

Records are binned by the reference's mean speed where the reference gives one (as
``uq golden`` bins by the reference), else by the lidar's corrected mean speed. Per bin
and height, over the records with a corrected TI (every flag that makes a record NaN
leaves it out), TI as a fraction:

* ``count``, ``mean``, ``std`` (ddof 1) and ``q90`` (the 90 % quantile, linear) of the
  measured and of the corrected TI;
* against the reference (:func:`uq.golden.turbulence.ti_bin_kpis`, the OWA roadmap's
  metrics): the mean bias ``MBE = mean(TI - TI_ref)``, the relative MBE (over the mean
  reference TI), the RMSE and the relative RMSE, the representative TI's error (mean +
  1.28 sd), before (measured) and after correction;
* the stated uncertainty of the corrected MBE, ``u(MBE) = sqrt(sum u_i^2) / n`` (the
  records' standard uncertainties, their errors independent from record to record: the
  sampling of one ten-minute record does not carry into the next one's beyond the
  eddies that span both, minutes against ten minutes), and the MBE the model predicts
  for the measured TI with its uncertainty likewise.
"""
import numpy as np

from uq.golden import binning, turbulence

#: The quantile of the per-bin TI statistics (the OWA roadmap's Q90).
QUANTILE = 0.9


def bin_statistics(values, speed, centres, width):
    """count, mean, std, q90 of `values` per bin of `speed` (arrays (n,)), each (m,)."""
    values = np.asarray(values, float)
    keep = np.isfinite(values) & np.isfinite(speed)
    index = binning.bin_index(np.where(keep, speed, np.nan), width)
    keys = np.rint(np.asarray(centres) / width).astype(int)
    rows = [values[(index == k) & keep] for k in keys]
    return {"count": np.array([len(r) for r in rows]),
            "mean": np.array([r.mean() if len(r) else np.nan for r in rows]),
            "std": np.array([r.std(ddof=1) if len(r) > 1 else np.nan for r in rows]),
            "q90": np.array([np.quantile(r, QUANTILE) if len(r) else np.nan for r in rows])}


def bin_sums(values, speed, centres, width):
    """``sqrt(sum values_i) / n`` per bin over the finite values (the uncertainty of a
    bin's mean from the records' variances `values`), (m,)."""
    values = np.asarray(values, float)
    keep = np.isfinite(values) & np.isfinite(speed)
    index = binning.bin_index(np.where(keep, speed, np.nan), width)
    keys = np.rint(np.asarray(centres) / width).astype(int)
    out = []
    for k in keys:
        chosen = values[(index == k) & keep]
        out.append(np.sqrt(chosen.sum()) / len(chosen) if len(chosen) else np.nan)
    return np.array(out)


def reference_metrics(reference, ti, speed, centres, width):
    """The OWA roadmap's TI metrics of `ti` against `reference` per bin
    (:func:`uq.golden.turbulence.ti_bin_kpis`, TI as fractions) and the relative RMSE."""
    stats = turbulence.ti_bin_kpis(reference, ti, speed, centres, width)
    with np.errstate(invalid="ignore", divide="ignore"):
        stats["relative_rmse"] = stats["rmse"] / stats["reference_mean"]
    return stats
