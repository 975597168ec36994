"""The compiled sine and cosine of the time-resolved kernels
(:func:`uq.physics.fusedmotionkernels.sincos`, through ``sincos_array``)."""
from fractions import Fraction

import numpy as np

from uq.constants import HALF_PI_PARTS, SINCOS_REDUCTION_LIMIT
from uq.physics.fusedmotionkernels import sincos_array

#: pi to 50 digits (OEIS A000796).
PI_50 = Fraction("3.14159265358979323846264338327950288419716939937510")


def compiled(x):
    out = np.empty(2 * x.size)
    sincos_array(np.ascontiguousarray(x, dtype=float), out)
    return out[:x.size], out[x.size:]


def test_half_pi_parts_sum_to_half_pi():
    """The three parts' exact sum is pi/2 to 1.01e-37 (fdlibm's; the 50-digit pi leaves
    1e-50, so the bound is the parts'); the first two carry at most 33 significant bits,
    so k times them is exact for |k| < 2^20."""
    total = sum(Fraction(part) for part in HALF_PI_PARTS)
    assert abs(total - PI_50 / 2) < Fraction(101, 10**39)
    for part in HALF_PI_PARTS[:2]:
        mantissa = Fraction(part) / Fraction(2) ** int(np.frexp(part)[1])   # in [1/2, 1)
        assert (mantissa * 2**33).denominator == 1


def test_sincos_within_two_ulp_of_libm_over_the_reduction_range():
    """|x| up to the reduction limit, and small angles: within 2 machine epsilons,
    relative, of libm's (libm within 1 ulp of the true value, the polynomials ~1 ulp, and
    an ulp is between eps/2 and eps relative: 3 ulp just below a power of two is 1.5 eps;
    measured worst 1.5 eps)."""
    generator = np.random.default_rng(7)
    x = np.concatenate([generator.uniform(-1, 1, 20000) * SINCOS_REDUCTION_LIMIT,
                        generator.uniform(-10, 10, 20000), generator.normal(0, 1e-6, 2000)])
    sine, cosine = compiled(x)
    for got, reference in ((sine, np.sin(x)), (cosine, np.cos(x))):
        assert np.all(np.abs(got - reference) <= 2 * np.finfo(float).eps * np.abs(reference))


def test_beyond_the_reduction_range_and_nan_are_libm():
    x = np.array([SINCOS_REDUCTION_LIMIT * 1.001, -3e9, 1e300, np.nan])
    sine, cosine = compiled(x)
    np.testing.assert_array_equal(sine, np.sin(x))
    np.testing.assert_array_equal(cosine, np.cos(x))
