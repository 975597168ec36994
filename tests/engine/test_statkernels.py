"""The compiled statistics loops (uq.engine.statkernels) against numpy.

Order statistics must be exact (the same values numpy.partition picks) on any input:
random, sorted, reversed, tied, with NaN and infinities. Moments and the resultant are
sums in another order than numpy's: they agree to the rounding of a sum of n terms,
n eps |x| (eps = 2.2e-16) at most, far less in practice.
"""
import numpy as np
import pytest

from uq.engine import statkernels
from uq.engine.statistics import CoMoments, _symmetric_ranks, unwrap

EPS = np.finfo(float).eps


def columns_of(rng, kind, n):
    if kind == "normal":
        return rng.normal(3.0, 2.0, n)
    if kind == "sorted":
        return np.sort(rng.normal(size=n))
    if kind == "reversed":
        return np.sort(rng.normal(size=n))[::-1].copy()
    if kind == "ties":
        return rng.integers(0, 5, n).astype(float)
    if kind == "constant":
        return np.full(n, 1.5)
    values = rng.normal(size=n)                        # non-finite values excluded
    values[rng.integers(0, n, n // 50)] = np.nan
    values[:3] = [np.inf, -np.inf, np.nan]
    return values


@pytest.mark.parametrize("short", [False, True], ids=["whole scratch", "short scratch"])
@pytest.mark.parametrize("n", [20, 39, 40, 1000, 2047, 2048, 10_000, 2**14, 70_001])
def test_order_statistics_are_exact(n, short, rng):
    """With a scratch of the values' length and with the short one the statistics use
    (scratch_length: ties and constants overflow it, and the pass falls back)."""
    kinds = ("normal", "sorted", "reversed", "ties", "constant", "nonfinite")
    columns = np.array([columns_of(rng, kind, n) for kind in kinds])
    count = np.isfinite(columns).sum(axis=1)
    ranks = np.array([_symmetric_ranks(int(c), 0.95) or (-1, -1) for c in count])
    low, high = np.empty(len(kinds)), np.empty(len(kinds))
    statkernels.select_pairs(columns, 0, n, count, ranks[:, 0].copy(), ranks[:, 1].copy(),
                             low, high,
                             np.empty((2, statkernels.scratch_length(n) if short else n)))
    for e, kind in enumerate(kinds):
        if ranks[e, 0] < 0:
            assert np.isnan(low[e]) and np.isnan(high[e])
            continue
        finite = columns[e][np.isfinite(columns[e])]
        expected = np.partition(finite, ranks[e])[ranks[e]]
        assert (low[e], high[e]) == tuple(expected), kind


def test_order_statistics_of_a_slice(rng):
    """A batch is a slice [start, stop) of the element-major store."""
    columns = rng.normal(size=(3, 50_000))
    ranks = _symmetric_ranks(20_000, 0.95)
    low, high = np.empty(3), np.empty(3)
    statkernels.select_pairs(columns, 10_000, 30_000, np.full(3, 20_000),
                             np.full(3, ranks[0]), np.full(3, ranks[1]), low, high,
                             np.empty((2, 20_000)))
    expected = np.partition(columns[:, 10_000:30_000], ranks, axis=1)[:, ranks]
    np.testing.assert_array_equal(np.stack([low, high], axis=1), expected)


def test_moments_equal_numpy(rng):
    columns = np.array([columns_of(rng, kind, 12_345) for kind in ("normal", "nonfinite")])
    columns[0] += 1e6                               # a large offset: two passes keep u
    count, mean, m2 = np.empty(2, dtype=np.int64), np.empty(2), np.empty(2)
    statkernels.moments(columns, 0, 12_345, count, mean, m2)
    for e in range(2):
        finite = columns[e][np.isfinite(columns[e])]
        assert count[e] == len(finite)
        # a sum of n terms: n eps of its largest |term| at most
        np.testing.assert_allclose(mean[e], finite.mean(), rtol=len(finite) * EPS)
        np.testing.assert_allclose(m2[e], np.sum((finite - finite.mean()) ** 2),
                                   rtol=len(finite) * EPS)


def test_transpose_unwraps_as_numpy(rng):
    values = np.mod(rng.normal(350.0, 20.0, (5000, 3)), 360.0)
    values[:4] = [[0.0, -0.0, 360.0], [1e-14, -1e-14, 359.99999999999994],
                  [np.nan, np.inf, 720.0], [180.0, 540.0, -180.0]]
    reference = np.array([0.0, 359.99999999999994, 170.0])
    out = np.empty((3, 5000))
    with np.errstate(invalid="ignore"):
        statkernels.transpose(values, reference, True, out, 0)
        np.testing.assert_array_equal(out.T, unwrap(values, reference))


def test_resultant_equals_complex_exponentials(rng):
    """The length of the mean resultant vector, from deviations about a reference
    (Taylor polynomials within SMALL_ANGLE, libm beyond), equals numpy's sum of
    exp(i theta) of the raw angles; NaN adds nothing."""
    values = np.concatenate([rng.normal(10.0, 3.0, 3000), rng.uniform(0, 360, 100), [np.nan]])
    columns = values[None, :].copy()
    cos_sum, sin_sum = np.zeros(1), np.zeros(1)
    statkernels.resultant(columns, 0, columns.shape[1], np.array([10.0]), cos_sum, sin_sum)
    expected = np.abs(np.nansum(np.exp(1j * np.deg2rad(values))))
    np.testing.assert_allclose(np.hypot(cos_sum, sin_sum), expected, rtol=len(values) * EPS)


def test_covariance_of_complete_trials_equals_numpy(rng):
    """Gate-to-gate covariance: only trials whose gates are all finite count, merged
    batch by batch (Chan et al.)."""
    values = rng.normal(size=(3000, 2, 3)) @ np.array([[1.0, 0.5, 0.2], [0, 1, 0.3], [0, 0, 1]])
    values[7, 0, 1] = np.nan
    values[9, 1, 2] = np.inf
    moments = CoMoments((2, 3))
    for start in range(0, 3000, 1024):
        moments.update(values[start:start + 1024])
    for s in range(2):
        complete = values[np.all(np.isfinite(values[:, s]), axis=1), s]
        assert moments.count[s] == len(complete) == 2999
        # sums of ~3000 products each: 3000 eps = 7e-13 relative at most
        np.testing.assert_allclose(moments.covariance()[s], np.cov(complete.T),
                                   rtol=len(complete) * EPS)

