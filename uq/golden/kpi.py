"""Floating-lidar acceptance KPIs (Carbon Trust OWA roadmap, as reproduced in IEA Wind
RP 18) and their verdicts.

* Wind speed: slope of the regression of the unit on the reference **through the origin**,
  ``m = sum(x y) / sum(x^2)``, and its R^2. R^2 is ``1 - SS_res / SS_tot`` with the
  residuals of that line and the *centred* total sum of squares ``sum((y - mean y)^2)``:
  the uncentred form ``1 - SS_res / sum(y^2)`` of a line through the origin is close to 1
  for any positive data and would pass a poor unit.
* Wind direction: two-parameter least squares (slope and offset) of the unit on the
  reference, and its R^2. Directions are degrees clockwise from north, "from", in
  [0, 360). Wrap-around: the unit's direction is moved by whole turns to within
  +-180 deg of the reference's (350 and 10 deg differ by 20, not 340), so the pair lies
  near the line y = x across north.
* Coverage: every required bin (4-16 m/s) holds enough records; availability is the
  fraction of the campaign's 10-min periods with a valid record of the unit, at least
  (inclusive) the configured bounds.

The regressions use every paired record with both values finite (no speed filter).

Verdict per KPI: ``best practice`` inside the best-practice bound, ``minimum`` inside the
minimum bound only, ``fail`` otherwise, ``no data`` when it cannot be computed.
"""
import numpy as np

from uq.constants import (FULL_CIRCLE_DEG, HALF_CIRCLE_DEG, KPI_DIRECTION_OFFSET_DEG,
                         KPI_DIRECTION_R2, KPI_DIRECTION_SLOPE, KPI_SPEED_R2,
                         KPI_SPEED_SLOPE)

BEST, MINIMUM, FAIL, NO_DATA = "best practice", "minimum", "fail", "no data"


def slope_through_origin(reference, unit):
    """(slope, R^2, n) of ``unit = m reference`` [1]; pairs with a NaN are left out."""
    x, y = _pairs(reference, unit)
    if len(x) < 2 or not np.any(x):
        return np.nan, np.nan, len(x)
    slope = np.sum(x * y) / np.sum(x * x)
    return float(slope), _r_squared(y, slope * x), len(x)


def unwrap_to_reference(reference, unit):
    """The unit's direction moved by whole turns to within +-180 deg of the reference's."""
    reference, unit = np.asarray(reference, float), np.asarray(unit, float)
    difference = np.mod(unit - reference + HALF_CIRCLE_DEG, FULL_CIRCLE_DEG) - HALF_CIRCLE_DEG
    return reference + difference


def direction_regression(reference, unit):
    """(slope, offset [deg], R^2, n) of ``unit = m reference + c`` after wrap-around."""
    x, y = _pairs(reference, unit)
    if len(x) < 3 or np.ptp(x) == 0:
        return np.nan, np.nan, np.nan, len(x)
    x = np.mod(x, FULL_CIRCLE_DEG)
    y = unwrap_to_reference(x, y)
    slope, offset = np.polyfit(x, y, 1)
    return float(slope), float(offset), _r_squared(y, slope * x + offset), len(x)


def band_verdict(value, bands):
    """Verdict of a value against ((best low, high), (minimum low, high))."""
    if not np.isfinite(value):
        return NO_DATA
    for verdict, (low, high) in zip((BEST, MINIMUM), bands):
        if low <= value <= high:
            return verdict
    return FAIL


def lower_bound_verdict(value, bounds):
    """Verdict of a value that must exceed (best, minimum)."""
    if not np.isfinite(value):
        return NO_DATA
    return BEST if value > bounds[0] else MINIMUM if value > bounds[1] else FAIL


def at_least_verdict(value, bounds):
    """Verdict of a value that must reach (best, minimum), bounds inclusive
    (availability "at least 90 %")."""
    if not np.isfinite(value):
        return NO_DATA
    return BEST if value >= bounds[0] else MINIMUM if value >= bounds[1] else FAIL


def upper_bound_verdict(value, bounds):
    """Verdict of a magnitude that must stay below (best, minimum)."""
    if not np.isfinite(value):
        return NO_DATA
    return BEST if abs(value) < bounds[0] else MINIMUM if abs(value) < bounds[1] else FAIL


def speed_kpis(reference, unit):
    """Wind-speed KPIs: dict of values and verdicts."""
    slope, r2, n = slope_through_origin(reference, unit)
    return {"speed_slope": slope, "speed_r_squared": r2, "speed_n_records": n,
            "speed_slope_verdict": band_verdict(slope, KPI_SPEED_SLOPE),
            "speed_r_squared_verdict": lower_bound_verdict(r2, KPI_SPEED_R2)}


def direction_kpis(reference, unit):
    """Wind-direction KPIs: dict of values and verdicts."""
    slope, offset, r2, n = direction_regression(reference, unit)
    return {"direction_slope": slope, "direction_offset": offset,
            "direction_r_squared": r2, "direction_n_records": n,
            "direction_slope_verdict": band_verdict(slope, KPI_DIRECTION_SLOPE),
            "direction_offset_verdict": upper_bound_verdict(offset, KPI_DIRECTION_OFFSET_DEG),
            "direction_r_squared_verdict": lower_bound_verdict(r2, KPI_DIRECTION_R2)}


def coverage_verdict(sufficient, required):
    """``best practice`` when every required bin is sufficient, else ``fail``."""
    required = np.asarray(required, bool)
    return BEST if np.all(np.asarray(sufficient, bool)[required]) else FAIL


def availability(valid, expected):
    """Fraction [1] of the `expected` 10-min periods with a `valid` record."""
    return float(valid) / expected if expected else np.nan


def _pairs(reference, unit):
    x, y = np.asarray(reference, float), np.asarray(unit, float)
    keep = np.isfinite(x) & np.isfinite(y)
    return x[keep], y[keep]


def _r_squared(y, fitted):
    total = np.sum((y - np.mean(y)) ** 2)
    return float(1.0 - np.sum((y - fitted) ** 2) / total) if total > 0 else np.nan
