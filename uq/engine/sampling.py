"""Random and quasi-random draws, in fixed-size blocks with their own streams.

Every sample of a run belongs to a block of :data:`uq.constants.RNG_BLOCK_SIZE` samples.
Block b draws from its own generator, ``numpy.random.default_rng(SeedSequence(seed,
spawn_key=(b,)))``, so a sample's value depends only on (seed, its index), never on how
many blocks are evaluated together: results are identical for every chunk size.

Methods
-------
``mc``
    Independent draws from numpy's default Generator (PCG64).
``lhs``
    Latin hypercube (scipy.stats.qmc.LatinHypercube), stratified within each block.
``sobol``
    Scrambled Sobol' points (scipy.stats.qmc.Sobol), a new independent scrambling for
    each block of 2^16 points (a power of two, so each block is a balanced net). Blocks
    are independent randomised-QMC replicates: their spread is an honest estimate of the
    error (Owen 1997), which a single long sequence cannot give.

Every method returns standard normal scores ``z`` of shape (block_size, dimension);
inputs are obtained from them by inverse CDFs (:mod:`uq.engine.inputs`), so each works with
every distribution. mc draws ``z`` directly; lhs and sobol map uniforms through the
normal inverse CDF.
"""
import math

import numpy as np
from scipy.special import ndtri
from scipy.stats import qmc

from uq.constants import RNG_BLOCK_SIZE

SAMPLING_METHODS = ("mc", "lhs", "sobol")
#: ``none``: no sampling, the GUM (and the paper's model) only, for large planning grids.
PROPAGATION_METHODS = SAMPLING_METHODS + ("none",)


def block_generator(seed, block):
    """Independent generator of block `block` for the run seeded with `seed` (int)."""
    return np.random.default_rng(np.random.SeedSequence(seed, spawn_key=(block,)))


def normal_scores(method, seed, block, dimension, block_size=RNG_BLOCK_SIZE, out=None,
                  rows=None):
    """Standard normal scores of one block, shape (block_size, dimension).

    Parameters
    ----------
    method : {"mc", "lhs", "sobol"}
    seed : int
        Entropy of the run.
    block : int
        Block index, >= 0.
    dimension : int
        Number of scalar random inputs.
    out : ndarray, optional
        C-contiguous float64 (rows, dimension) to draw into (no copy).
    rows : int, optional
        Only the first `rows` rows of the block (the same values as in the whole
        block: the generator's stream and the Sobol' sequence are sequential; a Latin
        hypercube is drawn whole, its strata span the block).
    """
    rows = block_size if rows is None else int(rows)
    out = np.empty((rows, dimension)) if out is None else out
    if dimension == 0:
        return out
    if method == "mc":
        return block_generator(seed, block).standard_normal(out=out)
    if method == "lhs":
        engine = qmc.LatinHypercube(dimension, rng=block_generator(seed, block))
        return ndtri(engine.random(block_size)[:rows], out=out)
    if method == "sobol":
        engine = qmc.Sobol(dimension, scramble=True, rng=block_generator(seed, block))
        points = engine.random_base2(max(0, math.ceil(math.log2(rows))))   # balanced prefix
        return ndtri(points[:rows], out=out)
    raise ValueError(f"unknown sampling method {method!r}; allowed: {SAMPLING_METHODS}")


def new_seed():
    """Fresh entropy for a run without a seed (recorded so the run can be repeated)."""
    return int(np.random.SeedSequence().entropy % (2**63))
