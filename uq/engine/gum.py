"""First-order GUM by complex-step differentiation, and its JCGM 101 validation.

The Jacobian is exact to machine precision: each input element is perturbed by an
imaginary step, ``c_k = Im f(x + i h e_k) / h`` (Squire & Trapp 1998), with no
subtractive cancellation and so no step to tune. All K perturbations go through the
model in one vectorised call of K samples. The model must be complex-step safe: analytic
operations only, or the helpers of :mod:`uq.complexstep` (``abs``, ``arctan2``, ``mod``
and comparisons on complex input silently lose the derivative).

Law of propagation (JCGM 100:2008, Eq. 13): ``u^2(y) = c^T V c`` with
``V = D R D`` (D the input standard uncertainties, R their correlation matrix).
The budget is each input's diagonal share ``sum_k c_k^2 u_k^2`` over its elements; with
correlated inputs the shares do not add up to u^2 (the cross terms are not assigned).

References
----------
.. [1] JCGM 100:2008, Evaluation of measurement data - Guide to the expression of
   uncertainty in measurement, 5.1-5.2.
.. [2] JCGM 101:2008, Supplement 1 to the GUM, clause 8 (validation) and 7.9.2
   (numerical tolerance).
.. [3] Squire, W. and Trapp, G. (1998). SIAM Review 40(1), 110-112.
"""
import numpy as np
from scipy.special import ndtri

from uq.constants import COMPLEX_STEP, COVERAGE_PROBABILITY, FULL_CIRCLE_DEG
from uq.engine.statistics import unwrap


def complex_step_jacobian(model, input_set):
    """Model value at the input means and its Jacobian.

    Parameters
    ----------
    model : callable
        ``model(**arrays) -> dict of arrays`` of shape (n, *output_shape).
    input_set : uq.engine.inputs.InputSet

    Returns
    -------
    value : dict
        Output name -> array of output_shape: f(x_mean).
    jacobian : dict
        Output name -> array (K, *output_shape), K = input_set.dimension.
    """
    means = input_set.means()
    k = input_set.dimension
    if k == 0:
        outputs = model(**_batch(input_set, means, 1), **input_set.constants)
        return {q: np.real(v[0]) for q, v in outputs.items()}, \
            {q: np.zeros((0,) + np.shape(v)[1:]) for q, v in outputs.items()}
    flat_mean = np.concatenate([means[name].reshape(-1) for name in input_set.names])
    steps = COMPLEX_STEP * np.maximum(1.0, np.abs(flat_mean))
    perturbed = flat_mean + 1j * np.diag(steps)                       # (K, K)
    arrays = {name: perturbed[:, input_set.offsets[name]:
                              input_set.offsets[name] + means[name].size]
              .reshape((k,) + input_set.shapes[name]) for name in input_set.names}
    try:
        with np.errstate(all="ignore"):     # a scene outside the model's domain: NaN
            outputs = model(**arrays, **input_set.constants)
    except TypeError as error:
        raise NotComplexStepSafe(f"the model cannot be evaluated at complex inputs ({error}); "
                                 "write it with analytic operations or uq.complexstep") from None
    # f(x_mean) from a real evaluation: the code path the Monte Carlo trials take (a
    # model may evaluate real inputs differently, e.g. compiled), so an output that
    # no input moves is bit-identical in both, as clause 8 with u = 0 requires
    with np.errstate(all="ignore"):
        nominal = model(**_batch(input_set, means, 1), **input_set.constants)
    value, jacobian = {}, {}
    for q, out in outputs.items():
        out = np.asarray(out)
        value[q] = np.real(np.asarray(nominal[q])[0])
        scale = steps.reshape((k,) + (1,) * (out.ndim - 1))
        jacobian[q] = np.imag(out) / scale if np.iscomplexobj(out) else np.zeros(out.shape)
        # outside the model's domain at the input means (f(x_mean) is NaN): no first-order
        # GUM there (a NaN output's imaginary part reads as 0, which gave u = 0)
        jacobian[q] = np.where(np.isfinite(value[q]), jacobian[q], np.nan)
    return value, jacobian


class NotComplexStepSafe(TypeError):
    """The model rejects complex input, so its exact Jacobian cannot be taken."""


def _batch(input_set, means, n):
    return {name: np.broadcast_to(means[name], (n,) + input_set.shapes[name])
            for name in input_set.names}


def combined_uncertainty(jacobian, input_set):
    """u(y) = sqrt(c^T V c) for every output element; shape output_shape."""
    u = input_set.standard_uncertainties()
    c = _columns(jacobian) * u[:, None]                              # sensitivity * u
    variance = np.einsum("ke,kl,le->e", c, input_set.correlation_matrix(), c)
    return np.sqrt(np.maximum(variance, 0.0)).reshape(jacobian.shape[1:])


def output_covariance(jacobian, input_set):
    """First-order covariance along the outputs' last axis, C = J V J^T.

    Parameters
    ----------
    jacobian : ndarray, shape (K, *S, g)
    input_set : uq.engine.inputs.InputSet

    Returns
    -------
    ndarray, shape (*S, g, g)
        Its diagonal is ``combined_uncertainty(...)**2``.
    """
    u = input_set.standard_uncertainties()
    c = jacobian * u.reshape((-1,) + (1,) * (jacobian.ndim - 1))
    return np.einsum("k...i,kl,l...j->...ij", c, input_set.correlation_matrix(), c)


def variance_budget(jacobian, input_set):
    """Each input's share c_k^2 u_k^2 summed over its elements; (n_inputs, *output_shape)."""
    u = input_set.standard_uncertainties()
    with np.errstate(over="ignore", invalid="ignore"):       # inf shares stay inf
        share = (_columns(jacobian) * u[:, None]) ** 2
    columns = np.array(input_set.column_names())
    rows = [share[columns == name].sum(axis=0) for name in input_set.names]
    return np.array(rows).reshape((len(input_set.names),) + jacobian.shape[1:])


def _columns(jacobian):
    """Jacobian (K, *output_shape) as (K, n_elements); works for K = 0 (no inputs)."""
    return jacobian.reshape(jacobian.shape[0], int(np.prod(jacobian.shape[1:])))


def numerical_tolerance(u, digits):
    """JCGM 101, 7.9.2: u = c x 10^l with `digits` significant digits in c; delta = 10^l / 2."""
    u = np.asarray(u, dtype=float)
    with np.errstate(divide="ignore", invalid="ignore"):
        exponent = np.floor(np.log10(np.where(u > 0, u, np.nan))) - (digits - 1)
    return np.where(u > 0, 0.5 * 10.0**exponent, np.where(u == 0, 0.0, np.nan))


def endpoint_differences(estimate, u, low, high, circular=False,
                         probability=COVERAGE_PROBABILITY):
    """GUM minus Monte Carlo interval endpoints, (d_low, d_high) (JCGM 101, 8.2);
    circular outputs modulo 360 deg into [-180, 180)."""
    k = ndtri((1 + probability) / 2)
    d_low = estimate - k * u - low
    d_high = estimate + k * u - high
    if circular:
        d_low, d_high = unwrap(d_low, 0.0), unwrap(d_high, 0.0)
    return d_low, d_high


def gum_interval_valid(estimate, u, low, high, digits, circular=False,
                       probability=COVERAGE_PROBABILITY):
    """JCGM 101, clause 8: is the GUM interval y +- k u within delta of Monte Carlo's?

    k = Phi^-1((1 + p) / 2) (the GUM's Gaussian coverage factor). Both endpoint
    differences must not exceed the numerical tolerance of u at `digits` digits.
    Circular outputs compare angles modulo 360 deg, which means something only while the
    GUM interval is shorter than the circle: a GUM interval of 2 k u >= 360 deg (u >= 92 deg
    at 95 %; e.g. the direction of a wind of 1e-9 m/s) cannot be validated and is False,
    whatever its wrapped endpoints. NaN anywhere gives False.
    """
    d_low, d_high = endpoint_differences(estimate, u, low, high, circular, probability)
    delta = numerical_tolerance(u, digits)
    with np.errstate(invalid="ignore"):
        valid = (np.abs(d_low) <= delta) & (np.abs(d_high) <= delta)
        if circular:
            valid &= interval_within_circle(u, probability)
    return valid


def interval_within_circle(u, probability=COVERAGE_PROBABILITY):
    """Is the GUM interval y +- k u of a circular output shorter than the circle
    (2 k u < 360 deg)? Only then can it be compared with Monte Carlo modulo 360 deg."""
    k = ndtri((1 + probability) / 2)
    with np.errstate(invalid="ignore"):
        return 2 * k * np.asarray(u) < FULL_CIRCLE_DEG
