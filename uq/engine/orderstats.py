"""Exact order statistics by sample-bracketed selection (Floyd and Rivest, 1975).

The coverage interval endpoints of JCGM 101 (7.7) are order statistics of the M output
values. ``numpy.partition`` finds them exactly, at ~10 ns per value (introselect; it
is the largest cost of the statistics of a long run). Here a sorted, evenly strided
sample of ~:data:`~uq.constants.ORDER_SAMPLE` values brackets each wanted rank between
two sample values a <= b with a wide margin; one vectorised pass counts the values
below a and keeps those in [a, b], and only these few are partitioned. When the bracket
misses the rank (rare: the margin is 4 binomial standard deviations of the sample rank,
or the values are ordered adversarially), numpy.partition decides. The result is the
exact order statistic either way, only the time differs.

References
----------
.. [1] Floyd, R. W. and Rivest, R. L. (1975). Expected time bounds for selection.
   Communications of the ACM 18(3), 165-172.
"""
import math

import numpy as np

from uq.constants import ORDER_SAMPLE

#: Binomial standard deviations of the sample rank by which a bracket is widened.
_MARGIN_SIGMAS = 4.0


def order_statistics(values, ranks):
    """The values at 0-based `ranks` of ascending order.

    Parameters
    ----------
    values : ndarray, shape (n,)
        Finite values (NaN would not be ordered).
    ranks : sequence of int
        0-based ranks, each in [0, n).

    Returns
    -------
    ndarray, shape (len(ranks),)
    """
    values = np.asarray(values)
    if len(values) < 8 * ORDER_SAMPLE:                     # small: one partition is cheap
        return np.partition(values, list(ranks))[list(ranks)]
    sample = np.sort(values[::len(values) // ORDER_SAMPLE])
    return np.array([_bracketed(values, rank, sample) for rank in ranks])


def _bracketed(values, rank, sample):
    """Exact value of 0-based `rank`, searched among the values inside a bracket."""
    low, high = _bracket(rank, len(values), sample)
    below = np.count_nonzero(values < low)
    inside = values[(values >= low) & (values <= high)]
    if below <= rank < below + len(inside):
        return np.partition(inside, rank - below)[rank - below]
    return np.partition(values, rank)[rank]               # the bracket missed: exact anyway


def _bracket(rank, n, sample):
    """Sample values (a, b) that enclose `rank` of n with a margin (+-inf at the ends)."""
    s = len(sample)
    p = (rank + 0.5) / n
    margin = _MARGIN_SIGMAS * math.sqrt(s * p * (1.0 - p)) + 1.0
    first, last = math.floor(p * s - margin), math.ceil(p * s + margin)
    low = sample[first] if first >= 0 else -np.inf
    high = sample[last] if last < s else np.inf
    return low, high
