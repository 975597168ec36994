"""Compiled (numba) one-pass batches of long Monte Carlo runs
(:class:`uq.engine.statistics.StreamingStatistics`, from
:data:`~uq.constants.ONE_PASS_MIN_TRIALS` trials; imported then, so that shorter runs and
a cold start do not compile it).

:func:`batch_pass` takes one batch element by element while its column is in the cache:
stored, moments and circular resultant (:mod:`uq.engine.statkernels`' helpers, the same
sums), and the probabilistically symmetric endpoints of its sub-batches (JCGM 101 7.9's
standard errors), with the run's brackets: the values of the run's first sub-batch 4
standard deviations of a sample rank either side of each endpoint's rank [1] bracket
that rank in every later sub-batch and in the whole run, so one counting pass per
sub-batch serves both selections, and :func:`global_pairs` selects the run's endpoints
among the ~1 % of values kept inside (the run's selection over all values where a
bracket missed). Every result is the exact order statistic; the brackets change only
the time.

References
----------
.. [1] Floyd, R. W. and Rivest, R. L. (1975). Expected time bounds for selection.
   Communications of the ACM 18(3), 165-172.
"""
import math

import numpy as np
from numba import njit, types

from uq.constants import HALF_CIRCLE_DEG, ORDER_SAMPLE
from uq.engine.statkernels import (_MARGIN_SIGMAS, _column_moments, _column_resultant,
                                   _finite, _mod360, _sample_brackets, _select,
                                   _select_two)

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


@njit("void(float64[:, ::1], int64, float64[::1], float64[::1], float64[:, ::1], "
      "float64[:, ::1], int64[::1], int64[::1])", cache=True, nogil=True)
def tail_candidates(columns, m, low_threshold, high_threshold, low, high, low_count,
                    high_count):
    """The values of columns[e, :m] that pass element e's tails
    (:class:`uq.engine.statistics._Tail`), in trial order: those below
    low_threshold[e] into low[e, :low_count[e]], the negated values of those above
    -high_threshold[e] (the high tail keeps -values) into high[e, :high_count[e]]. As in
    the moments, no NaN (it passes no comparison) and no +-inf."""
    for e in range(columns.shape[0]):
        below, above = low_threshold[e], -high_threshold[e]
        a = b = 0
        for j in range(m):
            value = columns[e, j]
            if value < below and value != -np.inf:
                low[e, a] = value
                a += 1
            if value > above and value != np.inf:
                high[e, b] = -value
                b += 1
        low_count[e], high_count[e] = a, b


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
