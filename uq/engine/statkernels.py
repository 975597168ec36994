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
  and keeps those inside it, and only these are partitioned;
* :func:`batch_pass`: all of the above for one batch, element by element while its
  column is in the cache (stored, moments, resultant, the sub-batches' endpoints),
  with the run's brackets: the values of the run's first sub-batch 4 standard
  deviations of a sample rank either side of each endpoint's rank bracket that rank in
  every later sub-batch and in the whole run, so one counting pass per sub-batch serves
  both selections, and :func:`global_pairs` selects the run's endpoints among the ~1 %
  of values kept inside (the run's selection over all values where a bracket missed).
  Every result is the exact order statistic; the brackets change only the time.

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


# --- one pass per batch: the store, the moments, the batch endpoints, the run's brackets

#: Global-bracket states of an element (:func:`batch_pass`): not yet bracketed, counting
#: (bracketed at the run's first batch), given up (the run's selection decides at the end).
GLOBAL_UNSET, GLOBAL_COUNTING, GLOBAL_OFF = 0, 1, -1


@njit(cache=True, nogil=True)
def _run_margin(rank, n):
    """Ranks either side of `rank` of n values whose values bracket the same quantile in
    any other n values drawn alike, and in the whole run: 4 standard deviations of the
    difference of two sample ranks, sqrt(2 n p (1 - p)) [1], plus 2."""
    p = (rank + 0.5) / n
    return int(_MARGIN_SIGMAS * math.sqrt(2.0 * n * p * (1.0 - p))) + 2


@njit(cache=True, nogil=True)
def symmetric_ranks(m, probability):
    """0-based ranks (low, high) of the probabilistically symmetric endpoints among m
    values, (-1, -1) without an interval (as :func:`uq.engine.statistics._symmetric_ranks`)."""
    q = int(np.floor(probability * m + 0.5))             # JCGM 101 7.7.1
    if m * (1 - probability) < 1 - 1e-9:
        return -1, -1
    r = (m - q) // 2 if (m - q) % 2 == 0 else (m - q + 1) // 2
    return r - 1, r + q - 1


@njit(cache=True, nogil=True)
def _gather(column, bracket, below, kept, values):
    """Add the values of `column` under each bracket (bracket[0:2], [2:4]) to below[0],
    below[1] and append those inside to values[0, kept[0]:], values[1, kept[1]:]. A
    counting pass (SIMD), then a gathering pass where they fit; where they do not, the
    counts go on without them and both sides are marked overflowed (kept >=
    values.shape[1]), which the callers check."""
    low_a, low_b, high_a, high_b = bracket[0], bracket[1], bracket[2], bracket[3]
    n = column.shape[0]
    b0 = b1 = i0 = i1 = 0
    for j in range(n):
        value = column[j]
        b0 += value < low_a
        i0 += value <= low_b
        b1 += value < high_a
        i1 += value <= high_b
    k0, k1 = kept[0], kept[1]
    room = values.shape[1]
    below[0] += b0
    below[1] += b1
    if k0 + i0 - b0 >= room or k1 + i1 - b1 >= room:   # both sides marked overflowed
        kept[0] = max(k0 + i0 - b0, room)
        kept[1] = max(k1 + i1 - b1, room)
        return
    for j in range(n):
        value = column[j]
        if value <= low_b and value >= low_a:
            values[0, k0] = value
            k0 += 1
        if value >= high_a and value <= high_b:
            values[1, k1] = value
            k1 += 1
    kept[0], kept[1] = k0, k1


@njit(cache=True, nogil=True)
def _from_kept(column, keep, below, kept, rank):
    """The value of `rank` among `column` from the `kept` values of its bracket with
    `below` values under it (reordered in place); all values partitioned (a copy) where
    the bracket missed the rank or overflowed `keep`: exact either way."""
    if below <= rank < below + kept and kept <= keep.shape[0]:
        return _select(keep, rank - below, 0, kept)
    return _select(column.copy(), rank, 0, column.shape[0])


@njit(cache=True, nogil=True)
def _first_pair(column, low_rank, high_rank, bracket, keep_low, keep_high):
    """As :func:`_select_two` (a sorted prefix sample brackets the ranks), and the run's
    brackets in bracket[0:4]: the values :func:`_run_margin` ranks either side of each
    rank (NaN where they are not among the kept values)."""
    n = column.shape[0]
    sample_bracket = np.array(_sample_brackets(column, n, low_rank, high_rank))
    below, kept = np.zeros(2, dtype=np.int64), np.zeros(2, dtype=np.int64)
    room = min(keep_low.shape[0], keep_high.shape[0])
    keep = np.empty((2, room))
    _gather(column, sample_bracket, below, kept, keep)
    kept[0] = kept[0] if kept[0] < room else room + 1   # overflowed: all values then
    kept[1] = kept[1] if kept[1] < room else room + 1
    values = (_from_kept(column, keep[0], below[0], kept[0], low_rank),
              _from_kept(column, keep[1], below[1], kept[1], high_rank))
    bracket[:] = np.nan
    for side, rank in enumerate((low_rank, high_rank)):
        local, margin = rank - below[side], _run_margin(rank, n)
        if kept[side] <= room and local - margin >= 0 and local + margin < kept[side]:
            bracket[2 * side] = _select(keep[side], local - margin, 0, kept[side])
            bracket[2 * side + 1] = _select(keep[side], local + margin, 0, kept[side])
    return values


@njit(cache=True, nogil=True)
def _store_column(values, e, start, stop, reference, circular, out):
    """out[i - start] = values[i, e] for i in [start, stop), unwrapped about
    reference[e] for a circular output (as :func:`transpose`)."""
    ref = reference[e] if circular else 0.0
    for i in range(start, stop):
        value = values[i, e]
        if circular:
            value = ref - _mod360(ref - value + HALF_CIRCLE_DEG) + HALF_CIRCLE_DEG
        out[i - start] = value


@njit(cache=True, nogil=True)
def _finite_copy(column, n_finite):
    """The finite values of `column` (a new array of n_finite)."""
    out = np.empty(n_finite)
    _finite(column, out)
    return out


@njit(cache=True, nogil=True)
def _segment_value(part, kept_values, below, first, end, rank):
    """The value of `rank` (-1: NaN) of `part`, whose values inside its bracket are
    kept_values[first:end] with `below` values under it (all values decide where the
    bracket missed the rank or the kept values overflowed their room)."""
    if rank < 0:
        return np.nan
    if end >= kept_values.shape[0]:                     # overflowed: not all kept
        return _select(part.copy(), rank, 0, part.shape[0])
    return _from_kept(part, kept_values[first:end], below, end - first, rank)


@njit(cache=True, nogil=True)
def _sub_batch_pair(part, n_k, probability, first, state, bracket, below, kept, values,
                    scratch):
    """The symmetric endpoints of one sub-batch `part` with n_k finite values (NaN
    without an interval), and its values counted and kept for the run's brackets: one
    pass with the run's brackets, which bracket each sub-batch's ranks too (set at the
    run's first sub-batch by :func:`_first_pair`)."""
    size = part.shape[0]
    low_rank, high_rank = symmetric_ranks(n_k, probability)
    if state[0] == GLOBAL_COUNTING:
        if n_k == size:
            below_low, below_high, kept_low, kept_high = below[0], below[1], kept[0], kept[1]
            _gather(part, bracket, below, kept, values)
            return (_segment_value(part, values[0], below[0] - below_low, kept_low, kept[0],
                                   low_rank),
                    _segment_value(part, values[1], below[1] - below_high, kept_high,
                                   kept[1], high_rank))
        state[0] = GLOBAL_OFF                          # NaN among the values: given up
    if low_rank < 0:
        return np.nan, np.nan
    if n_k < 2 * ORDER_SAMPLE:                         # few: partition them all
        finite = _finite(part, scratch[0])
        return (_select(scratch[0], low_rank, 0, finite),
                _select(scratch[0], high_rank, low_rank, finite))
    if n_k < size:                                     # NaN among them: the finite ones
        return _select_two(_finite_copy(part, n_k), n_k, low_rank, high_rank, scratch[0],
                           scratch[1])
    if first and state[0] == GLOBAL_UNSET:
        pair = _first_pair(part, low_rank, high_rank, bracket, scratch[0], scratch[1])
        if not (math.isnan(bracket[0]) or math.isnan(bracket[1]) or math.isnan(bracket[2])
                or math.isnan(bracket[3])):
            state[0] = GLOBAL_COUNTING
            _gather(part, bracket, below, kept, values)
        return pair
    return _select_two(part, n_k, low_rank, high_rank, scratch[0], scratch[1])


_PASS_SIG = types.void(
    types.Array(types.float64, 2, "A", readonly=True), types.int64, types.int64,
    types.float64[::1], types.boolean, types.boolean, types.float64[:, ::1], types.int64,
    types.int64, types.float64,
    types.int64[::1], types.float64[::1], types.float64[::1],
    types.float64[::1], types.float64[::1],
    types.int64[:, ::1], types.float64[:, ::1], types.float64[:, ::1],
    types.float64[:, ::1], types.float64[:, ::1],
    types.int64[::1], types.float64[:, ::1], types.int64[:, ::1], types.int64[:, ::1],
    types.float64[:, :, ::1], types.float64[:, ::1])


@njit(_PASS_SIG, cache=True, nogil=True)
def batch_pass(values, start, stop, reference, circular, copy, columns, offset, size,
               probability, count, mean, m2, cos_sum, sin_sum, sub_count, sub_mean,
               sub_m2, low, high, global_state, global_brackets, global_below,
               global_kept, global_values, scratch):
    """Every statistic of the batch values[start:stop] (trials, elements), element by
    element while its column is in the cache:

    * with `copy`, the column stored in columns[e, offset + start:offset + stop]
      (unwrapped for a circular output; else it is there already);
    * count[e], mean[e], m2[e]: the batch's moments (:func:`moments`);
    * cos_sum[e], sin_sum[e] += the circular resultant (:func:`resultant`);
    * with `size` > 0, per full sub-batch k of `size` trials: sub_count, sub_mean,
      sub_m2 [k, e] (the batch's own where `size` is the batch) and the probabilistically
      symmetric endpoints low, high [k, e] (NaN without an interval) at `probability`
      (:func:`_sub_batch_pair`);
    * the run's brackets of each element (global_brackets[e]: the values of its first
      sub-batch :func:`_run_margin` ranks either side of each endpoint's rank, which
      bracket that rank in every sub-batch and in the run): every value is counted
      below them or kept inside (global_below, global_kept, global_values [e, side]),
      in the same pass that selects the sub-batch's endpoints among the kept; the
      run's endpoints are then selected among these few (:func:`global_pairs`). An
      element without brackets after the run's first batch (or with NaN values) gives
      up (GLOBAL_OFF): the run's selection decides.

    scratch (2, k): the kept values of a sub-batch, k >= 2 ORDER_SAMPLE and >= size / 8.
    The results do not depend on the brackets (exact selection), only the time does."""
    m = stop - start
    first = offset + start == 0
    c = np.empty(m if circular else 0)
    s = np.empty(m if circular else 0)
    parts = m // size if size > 0 else 0
    for e in range(columns.shape[0]):
        column = columns[e, offset + start:offset + stop]
        if copy:
            _store_column(values, e, start, stop, reference, circular, column)
        count[e], mean[e], m2[e] = _column_moments(column)
        if circular:
            cos_part, sin_part = _column_resultant(column, reference[e], c, s)
            cos_sum[e] += cos_part
            sin_sum[e] += sin_part
        for k in range(parts):
            part = column[k * size:(k + 1) * size]
            if size == m:
                n_k, mean_k, m2_k = count[e], mean[e], m2[e]
            else:
                n_k, mean_k, m2_k = _column_moments(part)
            sub_count[k, e], sub_mean[k, e], sub_m2[k, e] = n_k, mean_k, m2_k
            low[k, e], high[k, e] = _sub_batch_pair(
                part, n_k, probability, first and k == 0, global_state[e:e + 1],
                global_brackets[e], global_below[e], global_kept[e], global_values[e],
                scratch)
        if global_state[e] == GLOBAL_UNSET:
            global_state[e] = GLOBAL_OFF
        if global_state[e] == GLOBAL_COUNTING and parts * size < m:   # the rest
            _gather(column[parts * size:], global_brackets[e], global_below[e],
                    global_kept[e], global_values[e])


@njit("void(float64[:, :, ::1], int64[:, ::1], int64[:, ::1], int64[::1], int64[::1], "
      "float64[::1], float64[::1], boolean[::1])", cache=True, nogil=True)
def global_pairs(global_values, global_below, global_kept, low_rank, high_rank, low,
                 high, found):
    """low[e], high[e]: the values of 0-based ranks low_rank[e], high_rank[e] of the
    run, from the values kept inside the run's brackets (:func:`batch_pass`); found[e]
    False where a rank is not among them or they overflowed (the caller selects among
    all values). The kept values are reordered in place (a multiset: later batches may
    add to them)."""
    room = global_values.shape[2]
    for e in range(global_values.shape[0]):
        found[e] = False
        if low_rank[e] < 0:
            continue
        below_low, kept_low = global_below[e, 0], global_kept[e, 0]
        below_high, kept_high = global_below[e, 1], global_kept[e, 1]
        if not (below_low <= low_rank[e] < below_low + kept_low and kept_low < room):
            continue
        if not (below_high <= high_rank[e] < below_high + kept_high and kept_high < room):
            continue
        low[e] = _select(global_values[e, 0], low_rank[e] - below_low, 0, kept_low)
        high[e] = _select(global_values[e, 1], high_rank[e] - below_high, 0, kept_high)
        found[e] = True
