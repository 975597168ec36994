"""Numbers a golden-lidar report states, read off a finished Dataset.

:func:`reference_comparison` answers the case-study question of the seed (Coll-Vinent &
Miquel): for a unit verified against two references (a mast and a golden lidar), how do
the deviation terms and the calibration uncertainties compare, bin by bin, and which
classification terms does the chain keep? Means are over the required bins (4-16 m/s)
that are sufficient in both comparisons.
"""
import numpy as np


def thin_bins(ds):
    """[(comparison, height, [(bin centre, records), ...])] of required bins with too
    few records."""
    out = []
    required = ds["required"].values
    for key in ds["comparison"].values:
        for height in ds["height"].values:
            c = ds.sel(comparison=key, height=height)
            thin = required & ~c["sufficient"].values.astype(bool)
            if thin.any():
                out.append((str(key), float(height),
                            [(float(b), int(n)) for b, n in zip(ds["bin"].values[thin],
                                                                 c["n_records"].values[thin])]))
    return out


def reference_comparison(ds, unit, golden, mast):
    """Rows (one per height and framework) comparing the unit's deviation term and
    calibration uncertainty against the golden lidar and against the mast [m s-1]."""
    key_golden, key_mast = f"{unit}-{golden}", f"{unit}-{mast}"
    rows = []
    for height in ds["height"].values:
        both = ds["required"].values & _sufficient(ds, key_golden, height) & \
            _sufficient(ds, key_mast, height)
        for framework in ds["framework"].values:
            g = ds.sel(comparison=key_golden, height=height, framework=framework).isel(
                bin=np.flatnonzero(both))
            m = ds.sel(comparison=key_mast, height=height, framework=framework).isel(
                bin=np.flatnonzero(both))
            rows.append({
                "height": float(height), "framework": str(framework), "bins": int(both.sum()),
                "deviation_golden": float(g["deviation"].mean()),
                "deviation_mast": float(m["deviation"].mean()),
                "bins_deviation_smaller": int((g["deviation"] < m["deviation"]).sum()),
                "calibration_golden": float(g["calibration"].mean()),
                "calibration_mast": float(m["calibration"].mean()),
                "bins_calibration_smaller": int((g["calibration"] < m["calibration"]).sum()),
                "golden_classification": float(g["reference_classification"].mean()),
                "unit_classification": float(g["classification"].mean()),
                "unit_classification_mast": float(m["classification"].mean())})
    return rows


def chain_roles(ds):
    """(unit, golden, mast) of the first unit verified against a reference that is itself
    verified against another (the seed's Fig. 1), or None."""
    units, references = list(ds["unit"].values), list(ds["reference"].values)
    for unit, golden in zip(units, references):
        if golden in units:
            mast = references[units.index(golden)]
            if f"{unit}-{mast}" in ds["comparison"].values:
                return str(unit), str(golden), str(mast)
    return None


def _sufficient(ds, key, height):
    return ds.sel(comparison=key, height=height)["sufficient"].values.astype(bool)
