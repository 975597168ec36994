"""Seed Eqs. 2-3 against hand-computed values (the small dataset of test_golden_binning)."""
import numpy as np
import pytest

from test_binning import SMALL
from uq.golden.binning import bin_statistics
from uq.golden.calibration import (calibration_uncertainty, deviation_terms, quadrature,
                                   stated_calibration)

STATS = bin_statistics(**SMALL, centres=np.array([4.0, 4.5, 5.0, 5.5]))


def test_iec_deviation_term():
    """IEC: sigma_FLS / sqrt(N) and |Delta v|: bin 4.0 sqrt(0.02/2) = 0.1 and 0.05;
    bin 5.0 sqrt(0.125/2) = 0.25 and 0.1."""
    statistical, mean = deviation_terms(STATS, "iec")
    np.testing.assert_allclose(statistical[[0, 2]], [0.1, 0.25])
    np.testing.assert_allclose(mean[[0, 2]], [0.05, 0.1])
    np.testing.assert_allclose(quadrature(statistical, mean)[[0, 2]],
                               [np.sqrt(0.0125), np.sqrt(0.0725)])


def test_lusr_deviation_term():
    """LUSR: sigma_dev / sqrt(N): sqrt(0.045/2) = 0.15 and sqrt(0.08/2) = 0.2."""
    statistical, mean = deviation_terms(STATS, "lusr")
    np.testing.assert_allclose(statistical[[0, 2]], [0.15, 0.2])
    np.testing.assert_array_equal(mean[[0, 2]], 0.0)


def test_one_record_and_empty_bins_have_no_deviation_term():
    for framework in ("iec", "lusr"):
        statistical, _ = deviation_terms(STATS, framework)
        assert np.isnan(statistical[1]) and np.isnan(statistical[3])


def test_eq2_sum_of_variances():
    assert calibration_uncertainty(0.1, 0.0, np.sqrt(0.0125)) == pytest.approx(0.15)
    assert calibration_uncertainty(0.06, 0.08, 0.0) == pytest.approx(0.1)


def test_stated_calibration_absolute_and_relative_in_quadrature():
    np.testing.assert_allclose(stated_calibration([4.0, 10.0], 0.03, 0.004), [0.034, 0.05])


def test_unknown_framework():
    with pytest.raises(ValueError, match="allowed: iec, lusr"):
        deviation_terms(STATS, "gum")
