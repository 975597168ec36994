"""The tables' interpolation weights (uq.campaign.interpolation): exact where they claim."""
import numpy as np
import pytest

from uq.campaign.interpolation import (lagrange_weights, log_lagrange_weights,
                                       periodic_nodes, periodic_weights)


def test_periodic_weights_are_exact_to_their_degree(rng):
    angle = rng.uniform(0, 2 * np.pi, 200)
    for count in (5, 9, 11):
        top = (count - 1) // 2
        coefficients = rng.normal(size=(top + 1, 2))

        def polynomial(x):
            return sum(a * np.cos(m * x) + b * np.sin(m * x)
                       for m, (a, b) in enumerate(coefficients))
        weights = periodic_weights(angle, count)
        # exact to rounding: 1e-12 of the coefficients' size (sums of ~10 terms)
        np.testing.assert_allclose(weights @ polynomial(periodic_nodes(count)),
                                   polynomial(angle), atol=1e-12)


def test_a_truncated_degree_drops_the_higher_harmonics_only():
    angle = np.linspace(0, 2 * np.pi, 37)
    nodes = periodic_nodes(9)
    weights = periodic_weights(angle, 9, degree=2)
    low = 1.0 + 0.5 * np.cos(2 * angle) - 0.2 * np.sin(angle)
    np.testing.assert_allclose(weights @ (1.0 + 0.5 * np.cos(2 * nodes) - 0.2 * np.sin(nodes)
                                          + 0.3 * np.cos(4 * nodes)), low, atol=1e-12)


def test_an_even_count_is_refused():
    with pytest.raises(ValueError, match="odd"):
        periodic_weights(np.zeros(1), 8)


def test_cubic_lagrange_is_exact_for_cubics_and_clamps_at_the_ends(rng):
    x = rng.uniform(0.1, 2.0, 300)
    index, weights = lagrange_weights(x, 0.1, 0.1, 20)     # nodes 0.1 ... 2.0
    grid = 0.1 * (1 + np.arange(20))

    def cubic(v):
        return 2 * v ** 3 - v ** 2 + 0.5 * v - 3

    np.testing.assert_allclose((weights * cubic(grid[index])).sum(axis=1), cubic(x),
                               rtol=1e-12)
    assert index.min() >= 0 and index.max() <= 19
    np.testing.assert_allclose(weights.sum(axis=1), 1.0, rtol=1e-13)


def test_log_lagrange_is_exact_for_polynomials_of_log_x(rng):
    nodes = np.geomspace(2.0, 20.0, 4)
    x = rng.uniform(2.0, 20.0, 100)
    weights = log_lagrange_weights(x, nodes)
    np.testing.assert_allclose(weights @ np.log(nodes) ** 3, np.log(x) ** 3, rtol=1e-12)
