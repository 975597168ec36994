"""The one-pass kernels of long runs (uq.engine.passkernels) against numpy."""
import numpy as np

from uq.engine import passkernels
from uq.engine.statistics import _symmetric_ranks


def test_symmetric_ranks_as_the_statistics_module():
    """The compiled ranks of the probabilistically symmetric interval are those of
    :func:`uq.engine.statistics._symmetric_ranks` (JCGM 101 7.7.2), (-1, -1) where there
    is no interval."""
    for m in list(range(1, 200)) + [2047, 2048, 4095, 16384, 100_000, 524_288]:
        assert passkernels.symmetric_ranks(m, 0.95) == (_symmetric_ranks(m, 0.95) or (-1, -1))


def test_gather_counts_and_keeps_as_numpy(rng):
    """Values under each bracket counted, those inside kept (in order); with too little
    room only counted (an overflow the caller sees in the counts)."""
    column = rng.standard_normal(5000)
    bracket = np.array([-2.0, -1.8, 1.7, 1.9])
    for room in (5000, 10):
        below, kept = np.array([3, 4]), np.array([0, 0])
        values = np.full((2, room), np.nan)
        passkernels._gather(column, bracket, below, kept, values)
        for side in range(2):
            a, b = bracket[2 * side], bracket[2 * side + 1]
            inside = column[(column >= a) & (column <= b)]
            assert below[side] == 3 + side + np.count_nonzero(column < a)
            assert kept[side] == len(inside)
            if room > len(inside):
                np.testing.assert_array_equal(values[side, :len(inside)], inside)
