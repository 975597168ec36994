"""The loops of :mod:`uq.engine.statkernels` in numpy: the Monte Carlo statistics with
nothing compiled.

A run whose kernels are not in numba's on-disk cache yet (the first run after an
install, ``uq run``'s default) computes its statistics here while the kernels compile
in another process for later runs; ``uq.run(..., model="numpy")`` too. Each function
takes the same arguments and writes the same outputs as its namesake in
:mod:`uq.engine.statkernels`:

* :func:`transpose`, :func:`select_pairs`: the same values, bit for bit (a copy, an
  unwrap by the same expression, exact order statistics by ``numpy.partition``);
* :func:`moments`, :func:`resultant`, :func:`comoments`: the same sums of the same
  values in numpy's (pairwise) order instead of the kernels' interleaved one, and the
  cosine and sine from libm instead of the kernels' polynomials near zero: equal to
  rounding (~1e-16 relative; ``tests/engine/test_statnumpy.py``).

No one-pass batches (:mod:`uq.engine.passkernels`): a long run's statistics take the
store-then-select path, whose results the one-pass batches reproduce.
"""
import numpy as np

from uq.constants import FULL_CIRCLE_DEG, HALF_CIRCLE_DEG


def unwrap(values, reference):
    """Angles [deg] moved by whole turns into (reference - 180, reference + 180]."""
    return reference - np.mod(reference - values + HALF_CIRCLE_DEG, FULL_CIRCLE_DEG) \
        + HALF_CIRCLE_DEG


#: Values per side of the scratch :func:`select_pairs` needs: none (numpy's partition
#: makes its own copies; the argument is kept for the kernels' call signature).
SCRATCH = 0


def scratch_length(n):
    """The scratch :func:`select_pairs` needs for n values: none."""
    return SCRATCH


def transpose(values, reference, circular, out, offset):
    """out[e, offset + i] = values[i, e], unwrapped about reference[e] into
    (reference - 180, reference + 180] for a circular output."""
    m = values.shape[0]
    out[:, offset:offset + m] = (unwrap(values, reference) if circular else values).T


def moments(columns, start, stop, count, mean, m2):
    """Count, mean and sum of squared deviations of the finite values of
    columns[e, start:stop], for every element e (mean 0 where none is finite, as the
    kernel's)."""
    block = columns[:, start:stop]
    total = block.sum(axis=1)
    if np.isfinite(total).all():
        # every value finite (a non-finite one makes its row's sum non-finite): the
        # sums below without their masks, the same additions in the same order
        count[:] = block.shape[1]
        mean[:] = total / block.shape[1] if block.shape[1] else 0.0
        m2[:] = ((block - mean[:, None]) ** 2).sum(axis=1)
        return
    finite = np.isfinite(block)
    count[:] = finite.sum(axis=1)
    total = np.where(finite, block, 0.0).sum(axis=1)
    mean[:] = np.divide(total, count, out=np.zeros(len(count)), where=count > 0)
    m2[:] = (np.where(finite, block - mean[:, None], 0.0) ** 2).sum(axis=1)


def resultant(columns, start, stop, reference, cos_sum, sin_sum):
    """Add sum cos(d) and sum sin(d) of the finite deviations d = value - reference
    [deg] of columns[e, start:stop] to cos_sum[e], sin_sum[e]."""
    radians = np.deg2rad(columns[:, start:stop] - reference[:, None])
    finite = np.isfinite(radians)
    cos_sum += np.where(finite, np.cos(radians), 0.0).sum(axis=1)
    sin_sum += np.where(finite, np.sin(radians), 0.0).sum(axis=1)


def select_pairs(columns, start, stop, count, low_rank, high_rank, low, high, scratch):
    """low[e], high[e]: the order statistics of 0-based ranks low_rank[e] <
    high_rank[e] among the count[e] finite values of columns[e, start:stop] (NaN where
    the ranks are -1). Elements whose values are all finite and share their ranks are
    partitioned together."""
    block = columns[:, start:stop]
    n = block.shape[1]
    whole = (count == n) & (low_rank >= 0)
    for ranks in {(int(a), int(b)) for a, b in zip(low_rank[whole], high_rank[whole])}:
        rows = np.flatnonzero(whole & (low_rank == ranks[0]) & (high_rank == ranks[1]))
        picked = np.partition(block[rows], ranks, axis=1)
        low[rows], high[rows] = picked[:, ranks[0]], picked[:, ranks[1]]
    for e in np.flatnonzero(~whole):
        if low_rank[e] < 0:
            low[e] = high[e] = np.nan
            continue
        values = block[e][np.isfinite(block[e])]
        picked = np.partition(values, (low_rank[e], high_rank[e]))
        low[e], high[e] = picked[low_rank[e]], picked[high_rank[e]]


def comoments(values, count, mean, comoment):
    """For values (m, S, g): per s, the count of trials whose g values are all finite,
    their mean (g) and the sum of products of their deviations (g, g)."""
    complete = np.all(np.isfinite(values), axis=2)                 # (m, S)
    count[:] = complete.sum(axis=0)
    kept = np.where(complete[..., None], values, 0.0)
    totals = kept.sum(axis=0)                                      # (S, g)
    mean[:] = np.divide(totals, count[:, None], out=np.zeros(totals.shape),
                        where=count[:, None] > 0)
    deviation = np.where(complete[..., None], values - mean, 0.0)
    comoment[:] = np.einsum("msa,msb->sab", deviation, deviation)
