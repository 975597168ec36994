"""Compiled (numba) loops of the Monte Carlo statistics (:mod:`uq.engine.statistics`).

The model's outputs arrive trial-major, (trials, elements); every statistic is a pass
over one element's values. :func:`transpose` copies a chunk once into element-major
order (unwrapping circular outputs on the way), and everything after reads contiguous
columns that stay in the cache:

* :func:`moments`: count, mean and sum of squared deviations of the finite values of a
  batch, two passes, each summed in :data:`LANES` interleaved partial sums (a fixed
  order, so the same on every machine and for every chunk size, and a shorter
  dependency chain than one running sum);
* :func:`resultant`: sums of cos and sin of each circular value's deviation from its
  reference (the circular standard deviation), from Taylor polynomials in a loop
  without calls, libm beyond :data:`~uq.constants.SMALL_ANGLE`;
* :func:`comoments`: count, mean and co-moment matrix of the complete trials of a batch
  along the last axis (the gate-to-gate covariance);
* :func:`select_pairs`: the two order statistics of the probabilistically symmetric
  interval of each element, exact, by sample-bracketed selection (Floyd and Rivest
  1975; as :mod:`uq.engine.orderstats`): one pass counts the values below each bracket
  and keeps those inside it, and only these are partitioned (the one-pass batches of
  long runs: :mod:`uq.engine.passkernels`).

References
----------
.. [1] Floyd, R. W. and Rivest, R. L. (1975). Expected time bounds for selection.
   Communications of the ACM 18(3), 165-172.
.. [2] Chan, T. F., Golub, G. H. and LeVeque, R. J. (1983). Algorithms for computing the
   sample variance. The American Statistician 37(3), 242-247.
"""
import math

import numpy as np
from numba import njit, types

from uq.constants import FULL_CIRCLE_DEG, HALF_CIRCLE_DEG, ORDER_SAMPLE, SMALL_ANGLE

#: Interleaved partial sums of :func:`moments` and :func:`resultant` [1]: four break the
#: add-latency chain (4 cycles) of one running sum; their order is fixed.
LANES = 4
#: Binomial standard deviations of a sample rank by which a bracket is widened [1] (as
#: :mod:`uq.engine.orderstats`).
_MARGIN_SIGMAS = 4.0
_DEG = math.pi / 180.0
_S = tuple((-1) ** k / math.factorial(2 * k + 1) for k in range(8))
_C = tuple((-1) ** k / math.factorial(2 * k) for k in range(9))

_SIG = types.void(types.Array(types.float64, 2, "A", readonly=True),
                  types.Array(types.float64, 1, "C"), types.boolean,
                  types.Array(types.float64, 2, "C"), types.int64)


@njit(inline="always")
def _mod360(x):
    """numpy.mod(x, 360): x, x - 360 or x + 360 where x is within a turn of [0, 360)
    (each exact or rounded as numpy's fmod-and-add rounds it), Python's float % (the
    same sign rule) elsewhere; fmod costs ~30 ns."""
    if 0.0 <= x < FULL_CIRCLE_DEG:
        return x
    if FULL_CIRCLE_DEG <= x < 2 * FULL_CIRCLE_DEG:
        return x - FULL_CIRCLE_DEG
    if -FULL_CIRCLE_DEG < x < 0.0:
        return x + FULL_CIRCLE_DEG
    return x % FULL_CIRCLE_DEG


@njit(_SIG, cache=True, nogil=True)
def transpose(values, reference, circular, out, offset):
    """out[e, offset + i] = values[i, e], unwrapped about reference[e] into
    (reference - 180, reference + 180] for a circular output (as
    :func:`uq.engine.statistics.unwrap`). Tiles of 64 trials keep the writes of all
    elements in the cache."""
    m, elements = values.shape
    for start in range(0, m, 64):
        stop = min(m, start + 64)
        for e in range(elements):
            ref = reference[e] if circular else 0.0
            for i in range(start, stop):
                value = values[i, e]
                if circular:
                    value = ref - _mod360(ref - value + HALF_CIRCLE_DEG) + HALF_CIRCLE_DEG
                out[e, offset + i] = value


@njit(cache=True, nogil=True)
def _column_moments(column):
    """(count, mean, m2) of the finite values of the 1-D `column`: two passes, each
    summed in :data:`LANES` interleaved partial sums, lane j % LANES (a fixed order).
    A non-finite value adds +0.0 instead of being skipped: the same sums (a partial
    sum that starts at +0.0 is never -0.0), and a loop without branches (SIMD)."""
    n = column.shape[0]
    body = n - n % LANES
    s0 = s1 = s2 = s3 = 0.0
    finite = 0
    for j in range(0, body, LANES):
        v0, v1, v2, v3 = column[j], column[j + 1], column[j + 2], column[j + 3]
        f0, f1, f2, f3 = (math.isfinite(v0), math.isfinite(v1), math.isfinite(v2),
                          math.isfinite(v3))
        s0 += v0 if f0 else 0.0
        s1 += v1 if f1 else 0.0
        s2 += v2 if f2 else 0.0
        s3 += v3 if f3 else 0.0
        finite += f0 + f1 + f2 + f3
    total = 0.0
    for j in range(body, n):
        if math.isfinite(column[j]):
            total += column[j]
            finite += 1
    total += (s0 + s1) + (s2 + s3)
    centre = total / finite if finite else 0.0
    s0 = s1 = s2 = s3 = 0.0
    for j in range(0, body, LANES):
        d0, d1 = column[j] - centre, column[j + 1] - centre
        d2, d3 = column[j + 2] - centre, column[j + 3] - centre
        s0 += d0 * d0 if math.isfinite(column[j]) else 0.0
        s1 += d1 * d1 if math.isfinite(column[j + 1]) else 0.0
        s2 += d2 * d2 if math.isfinite(column[j + 2]) else 0.0
        s3 += d3 * d3 if math.isfinite(column[j + 3]) else 0.0
    square = 0.0
    for j in range(body, n):
        if math.isfinite(column[j]):
            square += (column[j] - centre) * (column[j] - centre)
    return finite, centre, square + ((s0 + s1) + (s2 + s3))


@njit("void(float64[:, ::1], int64, int64, int64[::1], float64[::1], float64[::1])",
      cache=True, nogil=True)
def moments(columns, start, stop, count, mean, m2):
    """Count, mean and sum of squared deviations of the finite values of
    columns[e, start:stop], for every element e."""
    for e in range(columns.shape[0]):
        count[e], mean[e], m2[e] = _column_moments(columns[e, start:stop])


@njit(cache=True, nogil=True)
def _column_resultant(column, ref, c, s):
    """(sum cos d, sum sin d) of the finite deviations d = value - ref [deg] of
    `column`, as :func:`resultant` adds them (c, s: scratch of its length)."""
    n = column.shape[0]
    for j in range(n):                   # no calls: SIMD
        x = (column[j] - ref) * _DEG
        x2 = x * x
        s[j] = x * (_S[0] + x2 * (_S[1] + x2 * (_S[2] + x2 * (_S[3] + x2 * (
            _S[4] + x2 * (_S[5] + x2 * (_S[6] + x2 * _S[7])))))))
        c[j] = _C[0] + x2 * (_C[1] + x2 * (_C[2] + x2 * (_C[3] + x2 * (_C[4] + x2 * (
            _C[5] + x2 * (_C[6] + x2 * (_C[7] + x2 * _C[8])))))))
    sums = np.zeros(2 * LANES)
    for j in range(n):
        x = (column[j] - ref) * _DEG
        if not math.isfinite(x):
            continue                     # as numpy.nansum: NaN trials add nothing
        if abs(x) > SMALL_ANGLE:         # libm beyond the polynomials' range
            c[j], s[j] = math.cos(x), math.sin(x)
        lane = j % LANES
        sums[lane] += c[j]
        sums[LANES + lane] += s[j]
    return (sums[0] + sums[1]) + (sums[2] + sums[3]), (sums[4] + sums[5]) + (sums[6] + sums[7])


@njit("void(float64[:, ::1], int64, int64, float64[::1], float64[::1], float64[::1])",
      cache=True, nogil=True)
def resultant(columns, start, stop, reference, cos_sum, sin_sum):
    """Add sum cos(d) and sum sin(d) of the finite values' deviations d = value -
    reference [deg] of columns[e, start:stop] to cos_sum[e], sin_sum[e]: the length of
    the mean resultant vector, invariant to the rotation by the reference."""
    n = stop - start
    c = np.empty(n)
    s = np.empty(n)
    for e in range(columns.shape[0]):
        cos_part, sin_part = _column_resultant(columns[e, start:stop], reference[e], c, s)
        cos_sum[e] += cos_part
        sin_sum[e] += sin_part


@njit("float64(float64[::1], int64, int64, int64)", cache=True, nogil=True)
def _select(values, rank, low, high):
    """The value of 0-based `rank` of values[low:high] (reordered in place): Hoare's
    selection with a median-of-three pivot."""
    while high - low > 1:
        mid = (low + high - 1) // 2
        a, b, c = values[low], values[mid], values[high - 1]
        pivot = max(min(a, b), min(max(a, b), c))
        i, j = low, high - 1
        while i <= j:
            while values[i] < pivot:
                i += 1
            while values[j] > pivot:
                j -= 1
            if i <= j:
                values[i], values[j] = values[j], values[i]
                i += 1
                j -= 1
        if rank <= j:
            high = j + 1
        elif rank >= i:
            low = i
        else:
            return values[rank]
    return values[rank]


@njit(cache=True, nogil=True)
def _bracket(rank, n, sample):
    """Sample values (a, b) that enclose `rank` of n with a margin (+-inf at the ends):
    order statistics of the (unsorted) sample, by selection (reordering it)."""
    s = sample.shape[0]
    p = (rank + 0.5) / n
    margin = _MARGIN_SIGMAS * math.sqrt(s * p * (1.0 - p)) + 1.0
    first, last = math.floor(p * s - margin), math.ceil(p * s + margin)
    return (_select(sample, first, 0, s) if first >= 0 else -np.inf), \
        (_select(sample, last, 0, s) if last < s else np.inf)


@njit(cache=True, nogil=True)
def _sample_brackets(column, n_finite, low_rank, high_rank):
    """(low_a, low_b, high_a, high_b): brackets of the two ranks of n_finite values from
    the first ~4 sqrt(n) values of `column` (at most ORDER_SAMPLE), a sample of them."""
    size = min(ORDER_SAMPLE, max(32, int(4.0 * math.sqrt(n_finite))), column.shape[0])
    sample = column[:size].copy()
    low_a, low_b = _bracket(low_rank, n_finite, sample)
    high_a, high_b = _bracket(high_rank, n_finite, sample)
    return low_a, low_b, high_a, high_b


@njit(cache=True, nogil=True)
def _select_two(column, n_finite, low_rank, high_rank, keep_low, keep_high):
    """The values of 0-based ranks low_rank < high_rank among the n_finite (all) values
    of `column`. The column's first ~4 sqrt(n) values (at most ORDER_SAMPLE; the trials
    are exchangeable, so a prefix is a sample, and reading it touches few cache lines)
    bracket each rank; one streaming pass counts the values below each bracket and keeps
    those inside (in keep_low, keep_high: ~4 % of the values, at most their length);
    only the kept values are partitioned. Where a bracket misses its rank or its values
    overflow the buffer (rare; or an ordered column), all values are partitioned (in a
    fresh array): exact either way."""
    n = column.shape[0]
    low_a, low_b, high_a, high_b = _sample_brackets(column, n_finite, low_rank, high_rank)
    below_low = below_high = kept_low = kept_high = 0
    last_low, last_high = keep_low.shape[0] - 1, keep_high.shape[0] - 1
    for j in range(n):              # branch-free: every value is written, kept by the count
        value = column[j]
        below_low += value < low_a
        below_high += value < high_a
        keep_low[min(kept_low, last_low)] = value
        kept_low += (value >= low_a) & (value <= low_b)
        keep_high[min(kept_high, last_high)] = value
        kept_high += (value >= high_a) & (value <= high_b)
    if below_low <= low_rank < below_low + kept_low and kept_low <= last_low:
        low = _select(keep_low, low_rank - below_low, 0, kept_low)
    else:
        low = _select(column.copy(), low_rank, 0, n)
    if below_high <= high_rank < below_high + kept_high and kept_high <= last_high:
        high = _select(keep_high, high_rank - below_high, 0, kept_high)
    else:
        high = _select(column.copy(), high_rank, 0, n)
    return low, high


@njit(cache=True, nogil=True)
def _finite(column, out):
    """Copy the finite values of `column` into out; their number."""
    n = 0
    for j in range(column.shape[0]):
        if math.isfinite(column[j]):
            out[n] = column[j]
            n += 1
    return n


@njit("void(float64[:, ::1], int64, int64, int64[::1], int64[::1], int64[::1], "
      "float64[::1], float64[::1], float64[:, ::1])", cache=True, nogil=True)
def select_pairs(columns, start, stop, count, low_rank, high_rank, low, high, scratch):
    """low[e], high[e]: the order statistics of 0-based ranks low_rank[e] <
    high_rank[e] among the count[e] finite values of columns[e, start:stop] (NaN where
    the ranks are -1: too few values); the ranks are those of the count,
    :func:`uq.engine.statistics._symmetric_ranks`. `scratch` (2, k) is the caller's,
    reused (no fresh pages per call), k >= 2 ORDER_SAMPLE (:func:`scratch_length`)."""
    n = stop - start
    keep_low, keep_high = scratch[0], scratch[1]
    for e in range(columns.shape[0]):
        if low_rank[e] < 0:
            low[e], high[e] = np.nan, np.nan
            continue
        column = columns[e, start:stop]
        if count[e] < 2 * ORDER_SAMPLE:            # few: partition them all
            finite = _finite(column, keep_low)
            low[e] = _select(keep_low, low_rank[e], 0, finite)
            high[e] = _select(keep_low, high_rank[e], low_rank[e], finite)
            continue
        if count[e] < n:                           # NaN among them: the finite ones
            finite_values = np.empty(count[e])
            _finite(column, finite_values)
            column = finite_values
        low[e], high[e] = _select_two(column, count[e], low_rank[e], high_rank[e],
                                      keep_low, keep_high)


def scratch_length(n):
    """Values per side of the scratch :func:`select_pairs` needs for n values: room for
    the kept values of a bracket (~4 % of n at most n >= 2^14, twice that here) and for
    2 ORDER_SAMPLE values partitioned whole; an overflow is detected (exact anyway)."""
    return max(2 * ORDER_SAMPLE, n // 8)


@njit(cache=True, nogil=True)
def _complete_comoments(values, s, mean, comoment):
    """mean[s] and comoment[s] of values[:, s, :] (m, g), every trial complete: each sum
    runs over the trials in order from 0.0, as in :func:`comoments`, four sums per pass
    in registers (independent chains) instead of g sums in memory."""
    m, g = values.shape[0], values.shape[2]
    for a0 in range(0, g, 4):
        a1, a2, a3 = min(a0 + 1, g - 1), min(a0 + 2, g - 1), min(a0 + 3, g - 1)
        t0 = t1 = t2 = t3 = 0.0
        for i in range(m):
            t0 += values[i, s, a0]
            t1 += values[i, s, a1]
            t2 += values[i, s, a2]
            t3 += values[i, s, a3]
        for a, total in ((a0, t0), (a1, t1), (a2, t2), (a3, t3)):
            mean[s, a] = total / m
    pairs = np.empty((g * (g + 1) // 2, 2), dtype=np.int64)
    p = 0
    for a in range(g):
        for b in range(a, g):
            pairs[p, 0], pairs[p, 1] = a, b
            p += 1
    last = pairs.shape[0] - 1
    for p0 in range(0, pairs.shape[0], 4):
        p1, p2, p3 = min(p0 + 1, last), min(p0 + 2, last), min(p0 + 3, last)
        a0, b0, a1, b1 = pairs[p0, 0], pairs[p0, 1], pairs[p1, 0], pairs[p1, 1]
        a2, b2, a3, b3 = pairs[p2, 0], pairs[p2, 1], pairs[p3, 0], pairs[p3, 1]
        c0, d0, c1, d1 = mean[s, a0], mean[s, b0], mean[s, a1], mean[s, b1]
        c2, d2, c3, d3 = mean[s, a2], mean[s, b2], mean[s, a3], mean[s, b3]
        t0 = t1 = t2 = t3 = 0.0
        for i in range(m):
            t0 += (values[i, s, a0] - c0) * (values[i, s, b0] - d0)
            t1 += (values[i, s, a1] - c1) * (values[i, s, b1] - d1)
            t2 += (values[i, s, a2] - c2) * (values[i, s, b2] - d2)
            t3 += (values[i, s, a3] - c3) * (values[i, s, b3] - d3)
        for q, total in ((p0, t0), (p1, t1), (p2, t2), (p3, t3)):
            comoment[s, pairs[q, 0], pairs[q, 1]] = total
            comoment[s, pairs[q, 1], pairs[q, 0]] = total


@njit(types.void(types.Array(types.float64, 3, "A", readonly=True), types.int64[::1],
                 types.float64[:, ::1], types.float64[:, :, ::1]), cache=True, nogil=True)
def comoments(values, count, mean, comoment):
    """For values (m, S, g): per s, the count of trials whose g values are all finite,
    their mean (g) and the sum of products of their deviations (g, g), two passes. Each
    sum runs over the trials in order from 0.0 (the same sums in any loop order); the
    completeness test is skipped where every trial is complete."""
    m, scenes, g = values.shape
    complete = np.empty(m, dtype=np.bool_)
    sums = np.empty(g)
    for s in range(scenes):
        n = 0
        for i in range(m):
            ok = True
            for a in range(g):
                ok = ok and math.isfinite(values[i, s, a])
            complete[i] = ok
            n += ok
        count[s] = n
        if n == m and m > 0:             # every trial complete: sums in registers
            _complete_comoments(values, s, mean, comoment)
            continue
        sums[:] = 0.0
        for i in range(m):
            if complete[i]:
                for a in range(g):
                    sums[a] += values[i, s, a]
        for a in range(g):
            mean[s, a] = sums[a] / n if n else 0.0
        for a in range(g):
            sums[:] = 0.0
            centre = mean[s, a]
            for i in range(m):
                if complete[i]:
                    deviation = values[i, s, a] - centre
                    for b in range(a, g):
                        sums[b] += deviation * (values[i, s, b] - mean[s, b])
            for b in range(a, g):
                comoment[s, a, b] = sums[b]
                comoment[s, b, a] = sums[b]
