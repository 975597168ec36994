"""Bracketed selection against a full sort (the order statistics are exact)."""
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from uq.constants import ORDER_SAMPLE
from uq.engine.orderstats import _bracket, order_statistics

LARGE = 8 * ORDER_SAMPLE          # from here on the bracket is used


@pytest.mark.parametrize("n", [1, 7, LARGE - 1, LARGE, 3 * LARGE + 5, 2**19])
def test_equals_the_sorted_values_at_any_rank(n, rng):
    values = rng.standard_normal(n)
    ranks = sorted({0, n // 40, n // 2, n - 1 - n // 40, n - 1})
    assert np.array_equal(order_statistics(values, ranks), np.sort(values)[ranks])


@pytest.mark.parametrize("order", ["sorted", "reversed", "sawtooth", "ties", "constant"])
def test_adversarial_orders_and_ties_stay_exact(order, rng):
    """Sorted or periodic values defeat the strided sample; the fallback keeps it exact."""
    n = 4 * LARGE
    values = {"sorted": np.sort(rng.standard_normal(n)),
              "reversed": np.sort(rng.standard_normal(n))[::-1].copy(),
              "sawtooth": np.tile(np.arange(n // 16, dtype=float), 16),   # period = stride
              "ties": rng.integers(0, 5, n).astype(float),
              "constant": np.full(n, 2.5)}[order]
    ranks = (int(0.025 * n), int(0.975 * n))
    assert np.array_equal(order_statistics(values, ranks), np.sort(values)[list(ranks)])


def test_the_bracket_holds_the_rank_of_a_random_sample(rng):
    """4 binomial sigmas: a bracket misses in well under 1 % of random samples."""
    n, misses = 2**15, 0
    for _ in range(200):
        values = rng.standard_normal(n)
        sample = np.sort(values[::n // ORDER_SAMPLE])
        for rank in (int(0.025 * n), int(0.975 * n)):
            low, high = _bracket(rank, n, sample)
            below = np.count_nonzero(values < low)
            misses += not below <= rank < below + np.count_nonzero((values >= low) & (values <= high))
    assert misses <= 2          # expected ~400 x 6e-5; a broken bracket misses most


@settings(max_examples=30, deadline=None)
@given(st.integers(LARGE, 3 * LARGE), st.floats(0, 1), st.integers(0, 2**32 - 1))
def test_property_any_rank(n, where, seed):
    values = np.random.default_rng(seed).standard_cauchy(n)      # heavy tails
    rank = min(int(where * n), n - 1)
    assert order_statistics(values, [rank])[0] == np.sort(values)[rank]
