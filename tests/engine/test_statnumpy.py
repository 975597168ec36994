"""The statistics' numpy loops (uq.engine.statnumpy) against the compiled ones
(uq.engine.statkernels), function by function and for a whole streaming run.

Order statistics and copies must be bit-identical (both select the same value of the
same array). Sums (moments, resultant, co-moments) add the same values in another
order: each differs from the exact sum by at most (m - 1) eps sum|x| (Higham, Accuracy
and Stability of Numerical Algorithms, 2nd ed., eq. 4.4), so two of them by twice that;
the tolerances below are that bound for the data at hand.
"""
import numpy as np
import pytest

from uq.engine import statkernels, statnumpy
from uq.engine.statistics import (CoMoments, StreamingStatistics, _rank_pairs,
                                  tail_capacity)
from uq.constants import ORDER_SAMPLE

EPS = np.finfo(float).eps


def _sum_bound(values, axis=-1):
    """Twice the worst-case rounding error of a recursive sum of `values` along axis."""
    finite = np.where(np.isfinite(values), np.abs(values), 0.0)
    return 2 * values.shape[axis] * EPS * finite.sum(axis=axis)


def _columns(rng, elements, n, nan_share=0.0):
    columns = 10.0 + rng.standard_normal((elements, n))
    columns[rng.random(columns.shape) < nan_share] = np.nan
    return np.ascontiguousarray(columns)


@pytest.mark.parametrize("n, nan_share", [(100, 0.0), (5000, 0.0), (5000, 0.02), (7, 0.5)])
def test_moments(rng, n, nan_share):
    columns = _columns(rng, 6, n, nan_share)
    out = []
    for module in (statkernels, statnumpy):
        count, mean, m2 = np.empty(6, dtype=np.int64), np.empty(6), np.empty(6)
        module.moments(columns, 0, n, count, mean, m2)
        out.append((count, mean, m2))
    (c1, mean1, m21), (c2, mean2, m22) = out
    np.testing.assert_array_equal(c1, c2)
    assert np.all(np.abs(mean1 - mean2) <= _sum_bound(columns) / np.maximum(c1, 1))
    deviations = (columns - mean1[:, None]) ** 2
    assert np.all(np.abs(m21 - m22) <= _sum_bound(deviations) + 1e-300)


def _masked_moments(block):
    """The moments with every value masked by its finiteness (statnumpy's general path)."""
    finite = np.isfinite(block)
    count = finite.sum(axis=1)
    mean = np.divide(np.where(finite, block, 0.0).sum(axis=1), count,
                     out=np.zeros(len(count)), where=count > 0)
    return count, mean, (np.where(finite, block - mean[:, None], 0.0) ** 2).sum(axis=1)


@pytest.mark.parametrize("n", [0, 1, 4097])
def test_moments_of_finite_values_are_the_masked_ones_bit_for_bit(rng, n):
    """The all-finite shortcut adds the same values in the same order as the masked
    path; a finite block whose sum overflows takes the masked path (same result)."""
    columns = _columns(rng, 3, n)
    if n:
        columns[2, :2] = np.finfo(float).max              # its sum overflows to inf
    count, mean, m2 = np.empty(3, dtype=np.int64), np.empty(3), np.empty(3)
    with np.errstate(over="ignore"):                  # (the overflow is the point)
        statnumpy.moments(columns, 0, n, count, mean, m2)
        expected = _masked_moments(columns)
    for got, expected in zip((count, mean, m2), expected):
        np.testing.assert_array_equal(got, expected)


def test_resultant(rng):
    """Deviations up to +-200 deg (the kernel's polynomials near 0, libm beyond)."""
    columns = np.ascontiguousarray(rng.uniform(-200, 200, (4, 3000)))
    columns[0, 5] = np.nan
    reference = np.array([0.0, 10.0, 350.0, -5.0])
    sums = []
    for module in (statkernels, statnumpy):
        cos_sum, sin_sum = np.full(4, 1.5), np.full(4, -0.5)     # added to
        module.resultant(columns, 0, 3000, reference, cos_sum, sin_sum)
        sums.append((cos_sum, sin_sum))
    # each term differs by <= 2 eps (the polynomials' and libm's errors), plus the sums'
    bound = 3000 * 4 * EPS + _sum_bound(np.ones((4, 3000)))
    for first, second in zip(*sums):
        assert np.all(np.abs(first - second) <= bound)


@pytest.mark.parametrize("n", [50, 2 * ORDER_SAMPLE + 100, 20000])
def test_select_pairs_is_exact(rng, n):
    columns = _columns(rng, 5, n)
    columns[1, ::7] = np.nan                     # fewer finite values in one element
    columns[2] = np.sort(columns[2])             # ordered: the kernel's bracket misses
    count = np.isfinite(columns).sum(axis=1)
    ranks = _rank_pairs(count, 0.95)
    results = []
    for module in (statkernels, statnumpy):
        low, high = np.empty(5), np.empty(5)
        scratch = np.empty((2, max(statkernels.scratch_length(n), 1)))
        module.select_pairs(columns, 0, n, count.astype(np.int64), ranks[:, 0].copy(),
                            ranks[:, 1].copy(), low, high, scratch)
        results.append((low, high))
    np.testing.assert_array_equal(results[0][0], results[1][0])
    np.testing.assert_array_equal(results[0][1], results[1][1])
    finite = np.sort(columns[1][np.isfinite(columns[1])])     # the definition itself
    assert results[1][0][1] == finite[ranks[1, 0]] and results[1][1][1] == finite[ranks[1, 1]]


def test_select_pairs_without_an_interval(rng):
    columns = _columns(rng, 2, 10)
    low, high = np.zeros(2), np.zeros(2)
    statnumpy.select_pairs(columns, 0, 10, np.array([10, 10]), np.array([-1, -1]),
                           np.array([-1, -1]), low, high, np.empty((2, 0)))
    assert np.all(np.isnan(low)) and np.all(np.isnan(high))


def test_transpose_is_exact(rng):
    values = rng.uniform(-720, 720, (300, 4))
    reference = np.array([0.0, 359.0, 180.0, -90.0])
    for circular in (False, True):
        outs = []
        for module in (statkernels, statnumpy):
            out = np.zeros((4, 310))
            module.transpose(values, reference, circular, out, 10)
            outs.append(out)
        np.testing.assert_array_equal(*outs)


def test_comoments(rng):
    values = 5.0 + rng.standard_normal((400, 3, 4))
    values[3, 1, 2] = np.nan                     # an incomplete trial in scene 1
    out = []
    for module in (statkernels, statnumpy):
        count, mean = np.empty(3, dtype=np.int64), np.empty((3, 4))
        comoment = np.empty((3, 4, 4))
        module.comoments(values, count, mean, comoment)
        out.append((count, mean, comoment))
    np.testing.assert_array_equal(out[0][0], out[1][0])
    assert np.allclose(out[0][1], out[1][1], rtol=0, atol=400 * 2 * EPS * 10)
    # products of deviations of O(1), 400 of them: the sums' bound
    assert np.allclose(out[0][2], out[1][2], rtol=0, atol=_sum_bound(np.ones(400 * 9)))
    complete = CoMoments((3, 4), compiled=False)
    complete.update(values)
    assert list(complete.count) == [400, 399, 400]


@pytest.mark.parametrize("n, circular", [(3000, False), (2**17 + 3, False), (5000, True)])
def test_a_streaming_run_agrees(rng, n, circular):
    """A whole run: the compiled store (and its one-pass batches from 2^17 trials) and
    numpy's give the same endpoints bit for bit and the same moments to rounding."""
    values = 100.0 + rng.standard_normal((n, 3)) * [1.0, 5.0, 0.1]
    values[::101, 1] = np.nan
    reference = np.array([0.0, 359.0, 90.0]) if circular else None
    if circular:
        values = np.mod(values + [0.0, 259.0, -10.0], 360.0)
    results = []
    for compiled in (True, False):
        stats = StreamingStatistics((3,), tail_capacity(n) + 1, reference, expected=n,
                                    compiled=compiled)
        batches = stats.add(values, 2**12, summarize=True, summary_size=2**10)
        results.append((stats.result(), batches))
    (first, first_batches), (second, second_batches) = results
    for key in ("low", "high", "n_valid"):
        np.testing.assert_array_equal(first[key], second[key])
    # mean and u of n values ~100 with spreads up to 5: the sums' bound, relative
    assert np.allclose(first["mean"], second["mean"], rtol=4 * n * EPS, atol=0)
    assert np.allclose(first["u"], second["u"], rtol=4 * n * EPS, atol=0)
    assert len(first_batches) == len(second_batches)
    for (start, one), (other, two) in zip(first_batches, second_batches):
        assert start == other
        np.testing.assert_array_equal(one["low"], two["low"])
        np.testing.assert_array_equal(one["high"], two["high"])
