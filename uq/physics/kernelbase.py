"""What both compiled models share (:mod:`uq.physics.fusedkernels`,
:mod:`uq.physics.fusedmotionkernels`): the degree factor, the Taylor coefficients of sine
and cosine, Horner's rule, the guarded hypot, the 2 x 2 inverse, the correction codes and
the layout of scratch rows.

Every function here is ``inline="always"``: numba copies it into each kernel that calls
it, so the kernels stay loops without calls (SIMD code).

References
----------
.. [1] Abramowitz, M. and Stegun, I. A. (1964). Handbook of Mathematical Functions,
   4.3.65-4.3.66 (the Taylor series of sine and cosine).
"""
import math

import numpy as np
from numba import njit

from uq.constants import HYPOT_SAFE_MAX, HYPOT_SAFE_MIN
from uq.physics.modelinputs import Correction

#: Radians per degree [rad deg-1] (the kernels take angular errors in degrees).
DEG = math.pi / 180.0
#: Taylor coefficients (-1)^k / (2k+1)! of sin x / x and (-1)^k / (2k)! of cos x, in
#: powers of x^2 [1]; on |x| <= pi/4 the first omitted terms are below 1e-18 (x^17/17!
#: and x^18/18!), at |x| <= SMALL_ANGLE below 2e-25 (see uq/constants.py).
SIN_TAYLOR = tuple((-1) ** k / math.factorial(2 * k + 1) for k in range(8))
COS_TAYLOR = tuple((-1) ** k / math.factorial(2 * k) for k in range(9))
#: The correction models' codes (:class:`uq.physics.modelinputs.Correction`) as the plain
#: integers the kernels compare with (numba freezes module globals as constants).
NONE, YAW, TILT2D, FULL, POINTWISE = (int(model) for model in Correction)


@njit(inline="always")
def horner(coefficients, x):
    """sum_k coefficients[k] x^k by Horner's rule (a tuple: unrolled by numba)."""
    total = 0.0
    for k in range(len(coefficients) - 1, -1, -1):
        total = total * x + coefficients[k]
    return total


@njit(inline="always")
def taylor_cos_sin(x):
    """(cos x, sin x) of a small angle x [rad] from their Taylor polynomials, written out
    with constant indices (the static model's form; :func:`horner` gives the same
    numbers)."""
    s, c = SIN_TAYLOR, COS_TAYLOR
    x2 = x * x
    sin_x = x * (s[0] + x2 * (s[1] + x2 * (s[2] + x2 * (s[3] + x2 * (
        s[4] + x2 * (s[5] + x2 * (s[6] + x2 * s[7])))))))
    cos_x = c[0] + x2 * (c[1] + x2 * (c[2] + x2 * (c[3] + x2 * (c[4] + x2 * (
        c[5] + x2 * (c[6] + x2 * (c[7] + x2 * c[8])))))))
    return cos_x, sin_x


@njit(inline="always")
def inverse2(a00, a01, a10, a11):
    """The inverse of the 2 x 2 matrix ``[[a00, a01], [a10, a11]]`` as (i00, i01, i10, i11)
    (Cramer's rule: one division; the systems the kernels solve, the level beams'
    horizontal parts and the 2-beam normal equations, have condition numbers of
    ~cot(half-cone) and its square, so the solution is within ~1e-14 relative of
    LAPACK's pivoted elimination). A zero determinant divides as the caller's error
    model says (inlined: the caller's)."""
    scale = 1.0 / (a00 * a11 - a01 * a10)
    return a11 * scale, -a01 * scale, -a10 * scale, a00 * scale


@njit(inline="always")
def hypot(x, y):
    """sqrt(x^2 + y^2); for real input libm's hypot where the squares could over- or
    underflow (as :func:`uq.complexstep.hypot`; complex input: the complex step)."""
    radius = np.sqrt(x * x + y * y)
    if x.imag == 0.0 and y.imag == 0.0 and not HYPOT_SAFE_MIN < radius.real < HYPOT_SAFE_MAX:
        radius = math.hypot(x.real, y.real)
    return radius


def row_layout(blocks):
    """Start rows of named blocks of a scratch array laid one after another.

    Parameters
    ----------
    blocks : sequence of (str, int)
        Each block's name and its number of rows (>= 1), in order; names unique.

    Returns
    -------
    starts : dict
        name -> first row.
    total : int
        Rows of the whole array.

    Examples
    --------
    >>> row_layout([("angle", 1), ("matrix", 9), ("velocity", 3)])
    ({'angle': 0, 'matrix': 1, 'velocity': 10}, 13)
    """
    starts, row = {}, 0
    for name, rows in blocks:
        if name in starts or rows < 1:
            raise ValueError(f"scratch block {name!r}: a name used twice or {rows} rows")
        starts[name] = row
        row += rows
    return starts, row


def overlapping(blocks, starts):
    """Pairs of blocks of a layout whose rows overlap (none for :func:`row_layout`)."""
    spans = [(starts[name], starts[name] + rows, name) for name, rows in blocks]
    return [(a[2], b[2]) for i, a in enumerate(spans) for b in spans[i + 1:]
            if a[0] < b[1] and b[0] < a[1]]
