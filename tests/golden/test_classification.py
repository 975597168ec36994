"""Sensitivity slopes and seed Eq. 1 against hand-computed values."""
import numpy as np
import pytest

from uq.golden.classification import (class_number, class_number_uncertainty,
                                      per_variable_uncertainty, percentage_deviation,
                                      sensitivity)


def test_percentage_deviation():
    np.testing.assert_allclose(percentage_deviation([10.2, 4.9, 1.0], [10.0, 5.0, 0.0]),
                               [2.0, -2.0, np.nan])


def test_sensitivity_hand_computed():
    """x = 0..3, y = 0, 2, 1, 3: Sxx = Syy = 5, Sxy = 4, so slope 0.8, intercept 0.3,
    R^2 = 16/25; residuals -0.3, 0.9, -0.9, 0.3 give SSres 1.8 and se sqrt(1.8/2/5); with
    2 degrees of freedom t = 0.8/se = 1.8856 has the closed-form tail
    P(|T| > t) = 1 - t / sqrt(t^2 + 2) = 0.2."""
    s = sensitivity([0, 1, 2, 3], [0, 2, 1, 3])
    assert (s.slope, s.intercept, s.r_squared) == pytest.approx((0.8, 0.3, 0.64))
    assert s.slope_standard_error == pytest.approx(np.sqrt(0.18))
    assert s.p_value == pytest.approx(0.2)
    assert not s.significant and s.n_records == 4


def test_exact_line_is_significant_and_degenerate_input_is_nan():
    s = sensitivity([0.0, 0.1, 0.2, 0.3, np.nan], [1.0, 0.5, 0.0, -0.5, 3.0])
    assert s.slope == pytest.approx(-5.0) and s.significant and s.n_records == 4
    for x, y in (([1.0, 1.0, 1.0], [0.0, 1.0, 2.0]), ([0.0, 1.0], [0.0, 1.0])):
        flat = sensitivity(x, y)
        assert np.isnan(flat.slope) and not flat.significant


def test_eq1_per_variable():
    """v = 10 m/s; slopes -2 %/unit shear and 0.5 %/% TI; the SMC means differ by 0.05
    and 2: sqrt(0.1^2 + 1^2) % of 10 m/s."""
    u = per_variable_uncertainty([10.0, 5.0], [-2.0, 0.5], [[0.15, 0.1], [8.0, 6.0]],
                                 [[0.10, 0.1], [6.0, 6.0]])
    np.testing.assert_allclose(u, [0.1 * np.sqrt(1.01), 0.0])


def test_class_route():
    np.testing.assert_allclose(class_number_uncertainty([10.0], 2.0), [0.2 / np.sqrt(3)])
    assert class_number([-2.0, 0.5], [(0.0, 0.4), (0.0, 20.0)]) == pytest.approx(
        np.sqrt(0.4 ** 2 + 5.0 ** 2))
    assert class_number([], []) == 0.0
