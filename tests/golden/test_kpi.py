"""KPIs against hand-computed values; wrap-around of directions."""
import numpy as np
import pytest

from uq.golden.kpi import (BEST, FAIL, MINIMUM, NO_DATA, at_least_verdict, band_verdict,
                           coverage_verdict,
                           direction_kpis, direction_regression, lower_bound_verdict,
                           slope_through_origin, unwrap_to_reference, upper_bound_verdict)


def test_slope_through_origin_hand_computed():
    """x = 1, 2, 3; y = 1.1, 1.9, 3.2: m = 14.5 / 14; R^2 with the centred total sum of
    squares: 1 - 0.0421429 / 2.2466667."""
    slope, r2, n = slope_through_origin([1, 2, 3, np.nan], [1.1, 1.9, 3.2, 5.0])
    assert slope == pytest.approx(14.5 / 14) and n == 3
    residuals = np.array([1.1, 1.9, 3.2]) - 14.5 / 14 * np.array([1, 2, 3])
    total = np.sum((np.array([1.1, 1.9, 3.2]) - 6.2 / 3) ** 2)
    assert r2 == pytest.approx(1 - np.sum(residuals ** 2) / total)
    assert r2 == pytest.approx(0.981242, abs=1e-6)


@pytest.mark.parametrize("reference, unit, expected", [
    (350.0, 10.0, 370.0), (10.0, 350.0, -10.0), (359.0, 1.0, 361.0), (180.0, 0.0, 0.0),
    (90.0, 95.0, 95.0)])
def test_unwrap_across_north(reference, unit, expected):
    assert unwrap_to_reference(reference, unit) == pytest.approx(expected)


def test_direction_regression_across_north():
    """A constant +2 deg offset straddling 0/360: slope 1, offset 2, R^2 1; without the
    unwrapping the pairs (355, 357) and (359, 1) would wreck the line."""
    reference = np.array([350.0, 355.0, 359.0, 5.0, 10.0, 90.0, 180.0, 270.0])
    unit = np.mod(reference + 2.0, 360.0)
    slope, offset, r2, n = direction_regression(reference, unit)
    assert (slope, offset, r2) == pytest.approx((1.0, 2.0, 1.0)) and n == 8
    kpis = direction_kpis(reference, unit)
    assert kpis["direction_offset_verdict"] == BEST
    assert kpis["direction_slope_verdict"] == BEST


def test_verdict_bounds():
    bands = ((0.98, 1.02), (0.97, 1.03))
    assert band_verdict(1.02, bands) == BEST              # bounds inclusive
    assert band_verdict(1.025, bands) == MINIMUM
    assert band_verdict(0.96, bands) == FAIL
    assert band_verdict(np.nan, bands) == NO_DATA
    assert lower_bound_verdict(0.985, (0.98, 0.97)) == BEST
    assert lower_bound_verdict(0.98, (0.98, 0.97)) == MINIMUM   # "> 0.98": strict
    assert upper_bound_verdict(-4.9, (5.0, 10.0)) == BEST
    assert upper_bound_verdict(5.0, (5.0, 10.0)) == MINIMUM     # "< 5": strict
    assert upper_bound_verdict(12.0, (5.0, 10.0)) == FAIL
    assert at_least_verdict(0.90, (0.90, 0.85)) == BEST         # "at least": inclusive
    assert at_least_verdict(0.86, (0.90, 0.85)) == MINIMUM
    assert at_least_verdict(0.80, (0.90, 0.85)) == FAIL


def test_coverage_verdict():
    assert coverage_verdict([True, False, True], [True, False, True]) == BEST
    assert coverage_verdict([True, False, True], [True, True, True]) == FAIL
