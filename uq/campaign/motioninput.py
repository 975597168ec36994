"""Each record's platform motion from the campaign's motion file
(:class:`uq.campaign.config.MotionSpec`), on the records' periods.

* ``sea_state``: a table of Hs [m] and Tp [s] per period (a wave sensor's); the buoy's
  response (factors per metre of wave amplitude and lags) moves it
  (:func:`uq.campaign.motion.sea_state`).
* ``statistics``: a table of each degree of freedom's standard deviation or amplitude
  and period per period; a standard deviation s is a harmonic of amplitude ``s sqrt(2)``
  (:func:`uq.campaign.motion.statistics`).
* ``imu``: the log itself (:mod:`uq.campaign.imu`).

A period the file does not hold, or holds with a cell that is not a number, has no
motion (its records are NaN in the results, flagged). Tables are read as the records
are (:mod:`uq.campaign.recordsfile`: time zone, stamps, units).
"""
import numpy as np

from uq.campaign import imu, motion
from uq.campaign.config import ANGLE_UNITS, LENGTH_UNITS
from uq.campaign.recordsfile import numbers, on_grid, read_table
from uq.errors import DataFileError
from uq.physics.motion import ANGULAR

#: Peak periods a sea state may have [s]: the motion tables reach 2 Hz and the JONSWAP
#: band 4 / Tp, so Tp >= 2 s; swell beyond 30 s is no wind sea's.
TP_RANGE = (2.0, 30.0)


def load_motion(spec, times):
    """(:class:`uq.campaign.motion.MotionSet` of the records at period starts `times`
    (numpy datetime64 (n,)), the share of each record's motion power the file gives
    outside the tables' band (n,), rows of the file off the records' grid)."""
    if spec.kind == "imu":
        found, outside = imu.motion_set(spec, times)
        return found, outside, 0
    table, off = on_grid(read_table(spec.table), times)
    source = str(spec.table.file)
    if spec.kind == "sea_state":
        hs, _ = numbers(table, spec.columns["hs"], source, f"{spec.table.key}.columns.hs")
        tp, _ = numbers(table, spec.columns["tp"], source, f"{spec.table.key}.columns.tp")
        _check_range(hs, (0.0, np.inf), source, f"{spec.table.key}.columns.hs", "m")
        _check_range(tp, TP_RANGE, source, f"{spec.table.key}.columns.tp", "s")
        found = motion.sea_state(hs, tp, spec.response, spec.spectrum["gamma"],
                                 spec.spectrum["components"], spec.spectrum["band"])
    else:
        amplitude, period = {}, {}
        for dof, columns in spec.columns.items():
            factor = ANGLE_UNITS[spec.units["angle"]] if dof in ANGULAR else \
                LENGTH_UNITS[spec.units["length"]]
            key = f"{spec.table.key}.columns.{dof}"
            name = "std" if "std" in columns else "amplitude"
            values, _ = numbers(table, columns[name], source, f"{key}.{name}", factor)
            _check_range(values, (0.0, np.inf), source, f"{key}.{name}", "")
            amplitude[dof] = values * (np.sqrt(2.0) if name == "std" else 1.0)
            period[dof], _ = numbers(table, columns["period"], source, f"{key}.period")
            _check_range(period[dof], (0.0, np.inf), source, f"{key}.period", "s")
        found = motion.statistics(amplitude, period)
    return found, np.zeros(found.count), off


def _check_range(values, bounds, source, key, unit):
    finite = values[np.isfinite(values)]
    bad = finite[(finite < bounds[0]) | (finite > bounds[1])]
    if bad.size:
        allowed = f"[{bounds[0]:g}, {bounds[1]:g}] {unit}".strip() if np.isfinite(bounds[1]) \
            else f">= {bounds[0]:g} {unit}".strip()
        raise DataFileError(source, key, f"value {bad[0]:g} is out of range; allowed: "
                            f"{allowed} (a missing value left empty)")
