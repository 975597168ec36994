"""Streaming Monte Carlo statistics in bounded memory.

* Mean and standard deviation: chunk moments merged with Chan, Golub & LeVeque's
  pairwise update [2], stable for 10^8 and more samples.
* Coverage intervals (JCGM 101:2008, 7.7 [1]): the interval endpoints are order
  statistics of rank about (1 - p) M / 2 and (1 + p) M / 2, so only the
  ``M - q + 1`` smallest and largest values (q = round(p M)) are kept: 5 % of the
  samples on each side at p = 0.95, exact, not an approximation. The probabilistically
  symmetric and the shortest intervals both follow from them. While every value is
  stored, the symmetric endpoints of each batch (JCGM 101 7.9's standard errors) and of
  the run are selected among the values inside brackets set at the run's first batch
  (:func:`uq.engine.statkernels.batch_pass`): one pass per batch, ~1 % of the values
  partitioned, the exact order statistics.
* Circular outputs (directions [deg]) are unwrapped into ``reference +- 180`` before
  anything else; the reference is the model value at the input means. Their mean and
  interval endpoints are then wrapped to [0, 360). The circular standard deviation
  ``sqrt(-2 ln R)`` is reported beside the standard deviation of the unwrapped values
  (the two agree to 0.1 % while the spread is below 3 deg).

Non-finite samples (a model outside its domain) are counted and excluded.

References
----------
.. [1] JCGM 101:2008, Evaluation of measurement data - Supplement 1 to the GUM -
   Propagation of distributions using a Monte Carlo method.
.. [2] Chan, T. F., Golub, G. H. and LeVeque, R. J. (1983). Algorithms for computing the
   sample variance. The American Statistician 37(3), 242-247.
"""
import functools
from concurrent.futures import ThreadPoolExecutor

import numpy as np

from uq.constants import (COVERAGE_PROBABILITY, FULL_CIRCLE_DEG, HALF_CIRCLE_DEG,
                          ONE_PASS_MIN_TRIALS, STORED_VALUES)
from uq.cpus import usable_cpus
from uq.engine.orderstats import order_statistics
from uq.engine.statnumpy import unwrap  # noqa: F401 (public here, as before)

INTERVALS = ("symmetric", "shortest")


def _kernels(compiled=True):
    """:mod:`uq.engine.statkernels`, imported when a statistic is first computed, not
    with this module: its kernels have explicit signatures, so numba compiles them
    (first run after an install, ~5 s) or loads them on import, which a command that
    only reads a scenario (``uq fit``, ``uq check``) must not pay. Not `compiled`: the
    same loops in numpy (:mod:`uq.engine.statnumpy`), nothing compiled."""
    if not compiled:
        from uq.engine import statnumpy
        return statnumpy
    from uq.engine import statkernels
    return statkernels


def _pass_kernels():
    """:mod:`uq.engine.passkernels`, imported at the first long run's statistics (their
    compile, ~2 s after an install, is for runs of ONE_PASS_MIN_TRIALS and more)."""
    from uq.engine import passkernels
    return passkernels


def circular_mean_deg(values, axis=0):
    """Direction of the mean unit vector of angles [deg], in (-180, 180]; the mean of 350
    and 10 deg is 0, not 180."""
    radians = np.deg2rad(values)
    return np.rad2deg(np.arctan2(np.mean(np.sin(radians), axis=axis),
                                 np.mean(np.cos(radians), axis=axis)))


def tail_capacity(n, probability=COVERAGE_PROBABILITY, kind="shortest"):
    """Order statistics to keep on each side for `n` samples (JCGM 101, 7.7).

    The shortest interval may need any of the M - q + 1 extreme values; the
    probabilistically symmetric one only ranks r and r + q, i.e. about half of them
    (r + 1 per side), which halves the memory of huge runs.
    """
    if kind == "symmetric":
        ranks = _symmetric_ranks(n, probability)
        return max(1, ranks[0] + 2) if ranks else 1
    return max(1, n - _coverage_count(n, probability) + 1)


def _coverage_count(m, probability):
    """q of JCGM 101:2008, 7.7.1: pM if integer, else int(pM + 1/2)."""
    return int(np.floor(probability * m + 0.5))


def coverage_interval(smallest, largest, m, probability=COVERAGE_PROBABILITY,
                      kind="symmetric"):
    """Coverage interval from the extreme order statistics of M values.

    Parameters
    ----------
    smallest : ndarray
        Ascending; at least the M - q smallest values.
    largest : ndarray
        Ascending; at least the M - q largest values.
    m : int
        Number of values M.
    kind : {"symmetric", "shortest"}
        Probabilistically symmetric (7.7.2) or shortest (7.7.3) interval.

    Returns
    -------
    low, high : float
        NaN if M < 1 / (1 - p) (too few values for the interval: JCGM 101, 7.2.2) or if
        fewer extreme values were kept than the ranks need.
    """
    q = _coverage_count(m, probability)
    if m * (1 - probability) < 1 - 1e-9:
        return np.nan, np.nan
    if kind == "symmetric":
        r = (m - q) // 2 if (m - q) % 2 == 0 else (m - q + 1) // 2
        if len(smallest) < r or len(largest) < m - (r + q) + 1:
            return np.nan, np.nan
        return smallest[r - 1], largest[len(largest) - (m - (r + q)) - 1]
    if min(len(smallest), len(largest)) < m - q:
        return np.nan, np.nan
    lows = smallest[:m - q]                         # ranks 1 .. M - q
    highs = largest[len(largest) - (m - q):]        # ranks q + 1 .. M
    best = int(np.argmin(highs - lows))
    return lows[best], highs[best]


class Moments:
    """Streaming count, mean and sum of squared deviations per element (Chan et al.)."""

    def __init__(self, shape):
        self.shape = tuple(shape)
        self.count = np.zeros(shape, dtype=np.int64)
        self.mean = np.zeros(shape)
        self.m2 = np.zeros(shape)

    def update(self, values, valid=None):
        """Add the entries of `values` (m, *shape) where `valid` (default: where finite)."""
        self.merge(*_batch_moments(values, self.shape, valid))

    def merge(self, count, mean, m2):
        """Add a batch given by its count, mean and sum of squared deviations."""
        total = self.count + count
        delta = mean - self.mean
        weight = np.divide(count, total, out=np.zeros(self.shape), where=total > 0)
        self.mean = self.mean + delta * weight
        with np.errstate(over="ignore", invalid="ignore"):   # reported by propagate
            self.m2 = self.m2 + m2 + delta**2 * self.count * weight
        self.count = total

    def variance(self):
        """Sample variance (ddof 1); NaN below two values."""
        return np.divide(self.m2, self.count - 1, out=np.full(self.shape, np.nan),
                         where=self.count > 1)


def _batch_moments(values, shape, valid=None):
    """(count, mean, m2) of `values` (m, *shape) over its entries where `valid`."""
    with np.errstate(invalid="ignore", over="ignore"):      # inf - inf: the slow path
        total = values.sum(axis=0)
    if valid is None and np.all(np.isfinite(total)):
        # every value finite (a non-finite one makes its sum non-finite): no masks
        deviation = values - total / len(values)
        return np.full(shape, len(values)), total / len(values), \
            np.einsum("i...,i...->...", deviation, deviation)
    valid = np.isfinite(values) if valid is None else valid
    count = valid.sum(axis=0)
    safe = np.where(valid, values, 0.0)
    mean = np.divide(safe.sum(axis=0), count, out=np.zeros(shape), where=count > 0)
    m2 = np.sum(np.where(valid, values - mean, 0.0) ** 2, axis=0)
    return count, mean, m2


class CoMoments:
    """Streaming covariance along the last axis: count, mean and co-moment matrix.

    For values of shape (m, *S, g) it keeps, per leading element, the mean (*S, g) and
    the sum of products of deviations (*S, g, g), merged chunk by chunk with the pairwise
    update of Chan et al. [2] (C = C_a + C_b + d d^T n_a n_b / n). A trial counts only
    when all g of its values are finite (complete cases).
    """

    def __init__(self, shape, compiled=True):
        self.shape = tuple(shape)
        self.compiled = compiled
        self.count = np.zeros(shape[:-1], dtype=np.int64)
        self.mean = np.zeros(shape)
        self.comoment = np.zeros(self.shape + self.shape[-1:])

    def update(self, values):
        """Add the trials of `values` (m, *shape) whose g values are all finite (the
        batch's count, mean and co-moments by :func:`uq.engine.statkernels.comoments`)."""
        values = np.asarray(values, dtype=float)
        g = self.shape[-1]
        rows = values.reshape(len(values), -1, g)
        count = np.empty(rows.shape[1], dtype=np.int64)
        mean, comoment = np.empty(rows.shape[1:]), np.empty(rows.shape[1:] + (g,))
        _kernels(self.compiled).comoments(rows, count, mean, comoment)
        count = count.reshape(self.count.shape)
        mean = mean.reshape(self.shape)
        comoment = comoment.reshape(self.comoment.shape)
        total = self.count + count
        weight = np.divide(count, total, out=np.zeros(count.shape), where=total > 0)
        delta = mean - self.mean
        self.comoment = self.comoment + comoment + (self.count * weight)[..., None, None] \
            * delta[..., :, None] * delta[..., None, :]
        self.mean = self.mean + delta * weight[..., None]
        self.count = total

    def covariance(self):
        """Sample covariance (ddof 1), shape (*S, g, g); NaN below two complete trials."""
        scale = np.where(self.count > 1, self.count - 1, np.nan)
        return self.comoment / scale[..., None, None]


#: Threads that share the order statistics of the elements (the cores this process may
#: use, at most 4: the selections are passes over memory).
STATISTICS_THREADS = min(4, usable_cpus())
#: Samples per element handed to the tails at once when the store spills (the tails'
#: copies and masks are then a few MB, not copies of the whole 64 MB store).
_SPILL_VALUES = 2**18
#: Fewest elements per thread worth a thread's hand-over (~20 us).
_MIN_PART = 2


def element_parts(size, threads=None):
    """Contiguous slices of `size` elements, one per thread (one slice when too few)."""
    threads = max(1, min(threads or STATISTICS_THREADS, size // _MIN_PART))
    bounds = np.linspace(0, size, threads + 1).astype(int)
    return [slice(a, b) for a, b in zip(bounds[:-1], bounds[1:])]


@functools.cache
def _pool():
    return ThreadPoolExecutor(max_workers=STATISTICS_THREADS,
                              thread_name_prefix="uq-statistics")


def in_parallel(calls):
    """Run ``(function, *arguments)`` calls of compiled kernels that release the GIL,
    each on its own elements, and wait for all (the first on this thread). Every call
    writes only its own outputs, so the result does not depend on the threads."""
    if len(calls) == 1:
        calls[0][0](*calls[0][1:])
        return
    futures = [_pool().submit(function, *arguments) for function, *arguments in calls[1:]]
    calls[0][0](*calls[0][1:])
    for future in futures:
        future.result()


class StreamingStatistics:
    """Mean, standard deviation and coverage intervals of an array-valued output.

    Values are kept element-major (one contiguous column per element, unwrapped for a
    circular output) until `stored_values` are held: the moments, the circular
    resultant and the order statistics are then passes over contiguous columns in the
    compiled loops of :mod:`uq.engine.statkernels`. Beyond the budget only the tails
    the coverage interval needs are kept.

    Parameters
    ----------
    shape : tuple
        Shape of one sample of the output.
    capacity : int
        Order statistics kept per side and element (:func:`tail_capacity` of the
        largest sample count that will be seen).
    reference : ndarray or None
        For circular outputs, the unwrapping reference [deg], of `shape`.
    stored_values : int
        Values kept whole, over all elements.
    expected : int, optional
        Samples that will be added (the store is sized for them at once).
    compiled : bool
        The compiled loops (default); False: the same statistics in numpy
        (:mod:`uq.engine.statnumpy`, equal to rounding), nothing compiled.
    """

    def __init__(self, shape, capacity, reference=None, stored_values=STORED_VALUES,
                 expected=None, compiled=True):
        self.shape = tuple(shape)
        self.compiled = compiled
        self.capacity = int(capacity)
        self.reference = None if reference is None else \
            np.array(np.broadcast_to(reference, shape), dtype=float).reshape(-1)   # writeable
        self.moments = Moments(shape)
        self.size = int(np.prod(shape))
        self._cos, self._sin = np.zeros(self.size), np.zeros(self.size)   # resultant
        self._low = self._high = None              # the tails, once the budget is spent
        self._budget = int(stored_values)
        room = self._budget // max(self.size, 1)
        self._columns = np.empty((self.size, min(int(expected), room) if expected else 0))
        self._count = 0                            # samples held in _columns
        self._scratch = []                         # per part of the elements
        self._expected = int(expected) if expected else 0
        self._run = None                           # the run's brackets (_RunBrackets)
        self._off = None                           # brackets off (the tails decide)
        self._candidates = None                    # the tails' candidates (2, size, m)

    @property
    def _loops(self):
        """The statistics' loops: compiled, or numpy's (:func:`_kernels`)."""
        return _kernels(self.compiled)

    @property
    def _stored(self):
        """Are all values still kept (else only the tails)?"""
        return self._low is None

    def update(self, values, moments=None):
        """Add samples of shape (m, *shape) as one batch (`moments` is ignored: they
        are computed from the element-major copy)."""
        self.add(values, max(len(values), 1))

    def add(self, values, batch_size, summarize=False, kind="symmetric", summary_size=None):
        """Add samples (m, *shape) batch by batch: each batch's moments are merged in
        order (so the result does not depend on how the samples were chunked, when
        chunks start on batch boundaries). With `summarize`, returns the mean, u, low
        and high of every full batch, ``[(start, summary), ...]`` (JCGM 101, 7.9), or of
        every full sub-batch of `summary_size` (a divisor of `batch_size`): more, smaller
        batches for the standard errors, with the same merges, hence the same results."""
        values = np.asarray(values, dtype=float)
        m = len(values)
        flat = values.reshape(m, self.size)          # (a view where the layout allows)
        if self._stored and max(self._count + m, self._expected) * self.size > self._budget:
            # a run that will outgrow the store: the tails from now on (from its first
            # values where it says so), not a store grown past its budget and then spilled
            self._spill()
        if kind == "symmetric" and self._expected >= ONE_PASS_MIN_TRIALS and self.compiled:
            return self._add_in_one_pass(flat, batch_size, summarize,
                                         min(summary_size or batch_size, batch_size))
        if self._run is not None:
            self._run.counted = -1                   # values the run's brackets missed
        columns, offset = self._room(m)
        circular = self.reference is not None
        if not circular and flat.strides[0] == flat.itemsize:  # element-major (the
            columns[:, offset:offset + m] = flat.T      # compiled models'): row copies
        else:
            self._loops.transpose(flat, self.reference if circular else _NO_REFERENCE,
                                  circular, columns, offset)
        summaries = []
        count, mean, m2 = (np.empty(self.size, dtype=np.int64), np.empty(self.size),
                           np.empty(self.size))
        for start in range(0, m, batch_size):
            stop = min(m, start + batch_size)
            self._loops.moments(columns, offset + start, offset + stop, count, mean, m2)
            self.moments.merge(count.reshape(self.shape), mean.reshape(self.shape),
                               m2.reshape(self.shape))
            if circular:
                self._loops.resultant(columns, offset + start, offset + stop,
                                      self.reference, self._cos, self._sin)
            if summarize:
                summaries.extend(self._summaries(columns, offset, start, stop, (count, mean, m2),
                                                 kind, summary_size or batch_size, batch_size))
        if self._stored:
            self._count += m
            if self._count * self.size > self._budget:
                self._spill()
        else:
            self._add_to_tails(columns[:, :m])
        return summaries

    def _add_in_one_pass(self, flat, batch_size, summarize, size):
        """:meth:`add` of a long run whose interval is probabilistically symmetric: one
        compiled pass per batch and element (:func:`passkernels.batch_pass`) stores the
        column, takes its moments and the endpoints of its sub-batches. While every
        value is stored, the same pass counts the values around the run's endpoints
        (:class:`_RunBrackets`), so that :meth:`result` selects among a few per cent of
        the values; once only the tails are kept, the column goes to a scratch block and
        a second compiled pass hands the tails the values that pass them
        (:meth:`_add_to_tails`)."""
        m = len(flat)
        stored = self._stored
        columns, offset = self._room(m)
        circular = self.reference is not None
        reference = self.reference if circular else _NO_REFERENCE
        copy = flat.strides[0] == flat.itemsize      # element-major: copied in the pass
        if not copy:                                 # trial-major: tiles of trials
            self._loops.transpose(flat, reference, circular, columns, offset)
        if stored and self._run is None:
            # (the values stored at most: the room is a fraction of the store's)
            self._run = _RunBrackets(self.size, min(self._expected or m,
                                                    self._budget // max(self.size, 1)))
        run = self._run if stored else self._no_brackets()
        size = size if summarize else 0
        count, mean, m2 = (np.empty(self.size, dtype=np.int64), np.empty(self.size),
                           np.empty(self.size))
        length = self._loops.scratch_length(size)
        if len(self._scratch) != 1 or self._scratch[0].shape[1] < length:
            self._scratch = [np.empty((2, length))]
        summaries = []
        for start in range(0, m, batch_size):
            stop = min(m, start + batch_size)
            parts = (stop - start) // size if size else 0
            sub = (np.empty((parts, self.size), dtype=np.int64),
                   np.empty((parts, self.size)), np.empty((parts, self.size)))
            low, high = np.empty((parts, self.size)), np.empty((parts, self.size))
            run.make_room(stop - start)
            _pass_kernels().batch_pass(flat, start, stop, reference, circular, copy, columns,
                                  offset, size, COVERAGE_PROBABILITY, count, mean, m2,
                                  self._cos, self._sin, *sub, low, high,
                                  run.state, run.brackets, run.below, run.kept, run.values,
                                  self._scratch[0])
            run.counted += stop - start if run.counted >= 0 else 0
            self.moments.merge(count.reshape(self.shape), mean.reshape(self.shape),
                               m2.reshape(self.shape))
            summaries.extend((start + k * size, self._sub_summary(*sub, low, high, k))
                             for k in range(parts))
        if not stored:
            self._add_candidates(columns, m)
            return summaries
        self._count += m
        if self._count * self.size > self._budget:
            self._spill()
        return summaries

    def _no_brackets(self):
        """Run brackets that are off for every element (:func:`passkernels.batch_pass`
        then selects each sub-batch's endpoints alone): the tails decide the run's."""
        if self._off is None:
            self._off = _RunBrackets(self.size, 0)
            self._off.state[:] = _pass_kernels().GLOBAL_OFF
        return self._off

    def _sub_summary(self, count, mean, m2, low, high, k):
        """Mean, u, low and high of sub-batch k (rows k of the arrays), of `shape`."""
        with np.errstate(invalid="ignore", divide="ignore"):
            u = np.sqrt(np.where(count[k] > 1, m2[k] / np.maximum(count[k] - 1, 1), np.nan))
        return {"mean": np.where(count[k] > 0, mean[k], np.nan).reshape(self.shape),
                "u": u.reshape(self.shape), "low": low[k].reshape(self.shape),
                "high": high[k].reshape(self.shape)}

    def _summaries(self, columns, offset, start, stop, moments, kind, size, batch_size):
        """``[(start, summary), ...]`` of the full sub-batches of `size` of the batch
        [start, stop) (a partial batch, at the end of a run, may hold some), or of the
        batch itself (with its own `moments`) where `size` is the batch's and it is full."""
        if size >= batch_size:
            return [] if stop - start < batch_size else \
                [(start, self._summary(columns, offset + start, offset + stop, *moments, kind))]
        count, mean, m2 = (np.empty_like(m) for m in moments)
        out = []
        for first in range(start, stop - size + 1, size):
            self._loops.moments(columns, offset + first, offset + first + size, count, mean,
                                m2)
            out.append((first, self._summary(columns, offset + first, offset + first + size,
                                             count, mean, m2, kind)))
        return out

    def _room(self, m):
        """(columns, offset) to write m more samples into: the store (grown by
        doubling), or a scratch block once only the tails are kept."""
        if not self._stored:
            if self._columns.shape[1] < m:
                self._columns = np.empty((self.size, m))
            return self._columns, 0
        need = self._count + m
        if need > self._columns.shape[1]:
            grown = np.empty((self.size, max(need, 2 * self._columns.shape[1])))
            grown[:, :self._count] = self._columns[:, :self._count]
            self._columns = grown
        return self._columns, self._count

    def _summary(self, columns, start, stop, count, mean, m2, kind):
        """Mean, u, low and high of one batch, of `shape`."""
        with np.errstate(invalid="ignore", divide="ignore"):
            u = np.sqrt(np.where(count > 1, m2 / np.maximum(count - 1, 1), np.nan))
        low, high = self._endpoints(columns, start, stop, count, kind)
        return {"mean": np.where(count > 0, mean, np.nan).reshape(self.shape),
                "u": u.reshape(self.shape), "low": low.reshape(self.shape),
                "high": high.reshape(self.shape)}

    def _endpoints(self, columns, start, stop, count, kind, probability=COVERAGE_PROBABILITY):
        """Coverage interval of every element from columns[:, start:stop]."""
        size = columns.shape[0]
        low, high = np.empty(size), np.empty(size)
        if kind == "symmetric":
            ranks = _rank_pairs(count, probability)
            parts = element_parts(size)
            length = self._loops.scratch_length(stop - start)
            if len(self._scratch) != len(parts) or self._scratch[0].shape[1] < length:
                self._scratch = [np.empty((2, length)) for _ in parts]
            count = np.ascontiguousarray(count, dtype=np.int64)
            low_rank, high_rank = ranks[:, 0].copy(), ranks[:, 1].copy()
            in_parallel([(self._loops.select_pairs, columns[part], start, stop, count[part],
                          low_rank[part], high_rank[part], low[part], high[part], scratch)
                         for part, scratch in zip(parts, self._scratch)])
            return low, high
        for j in range(size):
            column = columns[j, start:stop]
            column = np.sort(column[np.isfinite(column)])
            low[j], high[j] = coverage_interval(column, column, len(column), probability, kind)
        return low, high

    def _run_endpoints(self, count, probability):
        """Symmetric endpoints of the run: among the values kept around the run's
        brackets where they hold the ranks (every value finite and counted), else by
        selection among all stored values (exact either way)."""
        count = np.ascontiguousarray(count, dtype=np.int64)
        ranks = _rank_pairs(count, probability)
        low, high = np.full(self.size, np.nan), np.full(self.size, np.nan)
        found = np.zeros(self.size, dtype=bool)
        run = self._run
        if run is not None and run.counted == self._count:
            usable = (run.state == _pass_kernels().GLOBAL_COUNTING) & (count == self._count)
            low_rank = np.where(usable, ranks[:, 0], -1).astype(np.int64)
            _pass_kernels().global_pairs(run.values, run.below, run.kept, low_rank,
                                    ranks[:, 1].copy(), low, high, found)
        missing = np.flatnonzero(~found)
        if len(missing):
            low[missing], high[missing] = self._endpoints(
                np.ascontiguousarray(self._columns[missing, :self._count]), 0, self._count,
                count[missing], "symmetric", probability)
        return low, high

    def _spill(self):
        """Hand the stored values to the tails (the memory bound of long runs)."""
        self._low = [_Tail(self.capacity) for _ in range(self.size)]
        self._high = [_Tail(self.capacity) for _ in range(self.size)]      # holds -values
        self._run = None                            # the tails decide from now on
        for start in range(0, self._count, _SPILL_VALUES):   # bounded temporaries
            self._add_to_tails(self._columns[:, start:min(self._count,
                                                          start + _SPILL_VALUES)])
        self._columns = np.empty((self.size, 0))

    def _symmetric(self, j, m, probability):
        """JCGM 101 7.7.2 endpoints of element j from the tails (NaN when they hold too
        few values, as in coverage_interval)."""
        ranks = _symmetric_ranks(m, probability)
        if not ranks:
            return np.nan, np.nan
        low_values, high_values = self._low[j].values(), -self._high[j].values()
        high_index = ranks[1] - (m - len(high_values))      # the high tail's top ranks
        if ranks[0] >= len(low_values) or high_index < 0:
            return np.nan, np.nan
        return (order_statistics(low_values, [ranks[0]])[0],
                order_statistics(high_values, [high_index])[0])

    def _extremes(self, j):
        """(smallest, largest) kept values of element j from the tails, each ascending."""
        return np.sort(self._low[j].values()), np.sort(-self._high[j].values())

    def _add_to_tails(self, columns):
        """Hand the values of `columns` (size, m), element by element in trial order,
        to the tails they pass; as in the moments, no NaN and no +-inf (NaN passes no
        comparison: only the few values that do are checked for an infinity)."""
        for j, column in enumerate(columns):
            below = column[column < self._low[j].threshold]
            below = below[np.isfinite(below)]
            if below.size:
                self._low[j].add(below)
            above = column[column > -self._high[j].threshold]
            above = above[np.isfinite(above)]
            if above.size:
                self._high[j].add(-above)

    def _add_candidates(self, columns, m):
        """:meth:`_add_to_tails` of columns[:, :m] (`columns` C-contiguous) by one
        compiled pass (:func:`passkernels.tail_candidates`, without the GIL): the same
        values handed to the same tails in the same order."""
        size = columns.shape[0]
        if self._candidates is None or self._candidates.shape[2] < m:
            self._candidates = np.empty((2, size, m))
        low_threshold = np.array([tail.threshold for tail in self._low])
        high_threshold = np.array([tail.threshold for tail in self._high])
        low_count, high_count = np.empty(size, dtype=np.int64), np.empty(size, dtype=np.int64)
        _pass_kernels().tail_candidates(columns, m, low_threshold, high_threshold,
                                        self._candidates[0], self._candidates[1],
                                        low_count, high_count)
        for j in range(size):
            if low_count[j]:
                self._low[j].add(self._candidates[0, j, :low_count[j]])
            if high_count[j]:
                self._high[j].add(self._candidates[1, j, :high_count[j]])

    def result(self, probability=COVERAGE_PROBABILITY, kind="symmetric"):
        """dict of arrays of `shape`: mean, u, low, high, n_valid (and circular_std)."""
        count = self.moments.count
        u = np.sqrt(self.moments.variance())
        mean = np.where(count > 0, self.moments.mean, np.nan)
        if self._stored and kind == "symmetric":
            low, high = self._run_endpoints(count.reshape(-1), probability)
        elif self._stored:
            low, high = self._endpoints(self._columns, 0, self._count,
                                        count.reshape(-1), kind, probability)
        else:
            low, high = np.full(self.size, np.nan), np.full(self.size, np.nan)
            for j, m in enumerate(count.reshape(-1)):
                if kind == "symmetric":
                    low[j], high[j] = self._symmetric(j, int(m), probability)
                else:
                    low[j], high[j] = coverage_interval(*self._extremes(j), int(m),
                                                        probability, kind)
        out = {"mean": mean, "u": u, "low": low.reshape(self.shape),
               "high": high.reshape(self.shape), "n_valid": count}
        if self.reference is not None:
            length = np.hypot(self._cos, self._sin).reshape(self.shape) / np.maximum(count, 1)
            with np.errstate(divide="ignore"):
                out["circular_std"] = np.rad2deg(np.sqrt(-2 * np.log(np.minimum(length, 1.0))))
            for key in ("mean", "low", "high"):
                out[key] = np.mod(out[key], FULL_CIRCLE_DEG)
        return out


#: The reference of an output that is not circular (the kernels take an array).
_NO_REFERENCE = np.zeros(0)


class _RunBrackets:
    """The run's brackets of the symmetric endpoints, per element (filled by
    :func:`uq.engine.statkernels.batch_pass`): the run's (``brackets``, (elements, 4),
    set at its first sub-batch),
    the values counted below them (``below``, (elements, 2)), the values kept inside
    (``values``, (elements, 2, room); ``kept`` counts them, on past the room: an
    overflow), the state of each element, and the trials counted (``counted``; -1 once
    values went by without being counted). ~1-5 % of the values fall inside (the
    brackets span 4 standard deviations of a sample rank either side of it): the room
    is an eighth of the stored values (grown where needed), so at most an eighth more
    memory than the store."""

    #: Room for the kept values, as a fraction of the trials, and at least.
    ROOM_FRACTION, MIN_ROOM = 0.125, 64

    def __init__(self, size, expected):
        self.brackets = np.full((size, 4), np.nan)
        self.state = np.zeros(size, dtype=np.int64)
        self.below = np.zeros((size, 2), dtype=np.int64)
        self.kept = np.zeros((size, 2), dtype=np.int64)
        self.values = np.empty((size, 2, int(self.ROOM_FRACTION * expected) + self.MIN_ROOM))
        self.counted = 0

    def make_room(self, m):
        """Room for m more trials' kept values (grown by doubling; an overflow is
        detected, and exact anyway)."""
        need = int(self.kept.max(initial=0) + self.ROOM_FRACTION * m) + self.MIN_ROOM
        if need > self.values.shape[2]:
            grown = np.empty(self.values.shape[:2] + (max(need, 2 * self.values.shape[2]),))
            used = min(int(self.kept.max()), self.values.shape[2])
            grown[:, :, :used] = self.values[:, :, :used]
            self.values = grown


class _Tail:
    """The `capacity` smallest values seen, kept lazily in one preallocated buffer.

    Once `capacity` values are kept, their maximum is a threshold no later value at or
    above can pass (there are already `capacity` values below it). Candidates below it
    are appended to the buffer, which is compacted in place (``ndarray.partition``) only
    when it holds 1.25 x capacity: a partition per ~capacity / 4 candidates instead of
    one per batch. After the first batches few values pass, so the cost per trial falls
    to a comparison. The buffer grows by doubling up to 2 x capacity and is never
    reallocated after: no fragmentation of the heap over 10^8 trials.
    """

    def __init__(self, capacity):
        self.capacity = max(int(capacity), 1)
        self.buffer = np.empty(min(self.capacity, 1024))
        self.size = 0
        self.threshold = np.inf

    def add(self, values):
        if len(values) > self.capacity:
            values = np.partition(values, self.capacity - 1)[:self.capacity]
        if self.size + len(values) > 2 * self.capacity:
            self._compact()                     # size <= capacity: the values now fit
        end = self.size + len(values)
        if end > len(self.buffer):
            grown = np.empty(min(max(end, 2 * len(self.buffer)), 2 * self.capacity))
            grown[:self.size] = self.buffer[:self.size]
            self.buffer = grown
        self.buffer[self.size:end] = values
        self.size = end
        if self.size >= self.capacity + self.capacity // 4:
            self._compact()

    def values(self):
        self._compact()
        return self.buffer[:self.size].copy()

    def _compact(self):
        if self.size > self.capacity:
            self.buffer[:self.size].partition(self.capacity - 1)     # in place
            self.size = self.capacity
        if self.size == self.capacity:
            self.threshold = self.buffer[:self.size].max()


#: Up to this many columns a batch's endpoints come from bracketed selection, column by
#: column (2-4x faster than numpy.partition per column, but a Python loop over them).
_SELECTION_COLUMNS = 8


def _rank_pairs(counts, probability):
    """(elements, 2) int64 ranks of :func:`_symmetric_ranks` per element's count ((-1, -1)
    where there is no interval), computed once per distinct count."""
    counts = np.asarray(counts).reshape(-1)
    distinct, where = np.unique(counts, return_inverse=True)
    pairs = np.array([_symmetric_ranks(int(c), probability) or (-1, -1) for c in distinct],
                     dtype=np.int64).reshape(-1, 2)
    return pairs[where.reshape(-1)]


def _symmetric_ranks(m, probability):
    """0-based ranks of the probabilistically symmetric endpoints among M sorted values
    (those :func:`coverage_interval` picks); () when M is too small for an interval."""
    q = _coverage_count(m, probability)
    if m * (1 - probability) < 1 - 1e-9:
        return ()
    r = (m - q) // 2 if (m - q) % 2 == 0 else (m - q + 1) // 2
    return (r - 1, r + q - 1)


def batch_statistics(values, reference=None, probability=COVERAGE_PROBABILITY,
                     kind="symmetric"):
    """Mean, u, low, high of one batch of shape (m, *shape) (for JCGM 101, 7.9).

    One sort of the whole batch (vectorised over elements). Circular outputs are
    unwrapped about `reference` and *not* wrapped back: batch values are only compared
    with each other, and a wrap at 0/360 deg between batches would fake a huge spread.
    """
    values = np.asarray(values, dtype=float)
    if reference is not None:
        values = unwrap(values, reference)
    shape = values.shape[1:]
    flat = values.reshape(len(values), -1)
    moments = Moments(flat.shape[1:])
    moments.update(flat)
    low, high = np.full(flat.shape[1], np.nan), np.full(flat.shape[1], np.nan)
    ranks = _symmetric_ranks(len(flat), probability)
    if kind == "symmetric" and ranks and np.all(moments.count == len(flat)):
        # all values finite: just the two order statistics (JCGM 101 7.7.2); by bracketed
        # selection for a few columns, else one partition vectorised over the columns
        if flat.shape[1] <= _SELECTION_COLUMNS:
            picked = np.array([order_statistics(np.ascontiguousarray(column), ranks)
                               for column in flat.T])
            low, high = picked[:, 0].copy(), picked[:, 1].copy()  # not views of the batch
        else:
            picked = np.partition(flat, ranks, axis=0)
            low, high = picked[ranks[0]].copy(), picked[ranks[1]].copy()
    else:
        for j, m in enumerate(moments.count):
            column = np.sort(flat[:, j][np.isfinite(flat[:, j])])   # -inf would sort first
            low[j], high[j] = coverage_interval(column, column, int(m), probability, kind)
    mean = np.where(moments.count > 0, moments.mean, np.nan)
    return {"mean": mean.reshape(shape), "u": np.sqrt(moments.variance()).reshape(shape),
            "low": low.reshape(shape), "high": high.reshape(shape),
            "moments": (moments.count.reshape(shape), moments.mean.reshape(shape),
                        moments.m2.reshape(shape))}
