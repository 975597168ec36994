"""The probe volume compiled (numba): the weighted power-law speed along the true beams.

:mod:`uq.physics.probe` writes out the weightings and their Gauss-Legendre quadrature and
is the reference; this module evaluates the same quadrature, the same nodes and weights
(:func:`uq.physics.probe.legendre` with the count of :func:`uq.physics.probe.resolve`),
for both compiled models (:mod:`uq.physics.fused`, :mod:`uq.physics.fusedmotion`), on
element-major arrays whose last axis is the trials (unit stride: SIMD loops):

1. :func:`node_weights`: per focus F (the slant distance of a gate) and per trial whose
   probe parameters differ, the nodes ``s_p`` [m] along the beam and their weights
   ``omega_p``. Pulsed: ``s_p = L x_p``, ``L = min(F, Delta p / 2 + k sigma)``,
   ``omega_p = w_p L W_p(s_p)`` (Eq. 1 of :mod:`uq.physics.probe`, libm's erf). CW:
   ``s_p = z_R tan(x_p atan(L / z_R))``, ``L = min(c z_R, F)``, ``omega_p = w_p / 2``.
   Without errors of the probe's parameters they are computed once per scene.
2. :func:`node_heights`: the heights ``z_c + s_p b_z`` of the probe's points on each true
   beam as ``z / z_ref`` (NaN at or below the sea, as :func:`uq.physics.wind.power_law_speed`;
   1 without shear), for numpy's SIMD ``log`` and ``exp`` (the power law).
3. :func:`weighted_mean`: ``sum_p omega_p (z_p / z_ref)^alpha / sum_p omega_p``, the
   weighted U / U_ref that the models use where the point model has ``(z_c / z_ref)^alpha``.

The arithmetic follows :class:`uq.physics.probe.PulsedProbe` and
:class:`uq.physics.probe.ContinuousWaveProbe` operation by operation (only libm's erf
against scipy's and the order of the final product differ, at the last bit);
``tests/physics/test_fusedprobe.py`` checks both compiled models against the numpy
model to 1e-12 m/s.

References
----------
.. [1] Matavar, A. (2024). Wind field reconstruction from floating lidars. MSc thesis, TU
   Delft, Secs. 2.2 and 4.1.
"""
import math

import numpy as np
from numba import njit

from uq.physics import probe as probe_volume

#: Kinds of probe the kernels take (:data:`uq.physics.probe.PROBE_KINDS` without point).
PULSED, CW = 1, 2
_KIND = {"pulsed": PULSED, "cw": CW}
_SQRT_LN2 = math.sqrt(math.log(2.0))
_SQRT2 = math.sqrt(2.0)
#: The model inputs of the probe's parameters' errors (``lidar_gate_length`` ...), which
#: both compiled models take (one draw per scan, like the geometry's errors).
INPUTS = tuple(f"lidar_{name}" for name in probe_volume.PARAMETER_SCALE)

_kernel = njit(cache=True, nogil=True, error_model="numpy")


@_kernel
def node_weights(kind, first, second, cut, tail_sigmas, x, w, focus, s_out, omega_out,
                 scratch):
    """Nodes s[f, p, j] [m] and weights omega[f, p, j] of the quadrature at focus f.

    Parameters
    ----------
    kind : int
        PULSED or CW.
    first, second : ndarray, shape (m,) or (1,)
        The true parameters [SI]: gate length and pulse FWHM [m] (pulsed), or wavelength
        and beam radius at the lens [m] (CW), per trial j (length 1: the same for all).
    cut, tail_sigmas : float
        CW: the Lorentzian's cut c = sqrt(1 / t - 1); pulsed: k of the Gaussian tail.
    x, w : ndarray, shape (P,)
        Gauss-Legendre nodes and weights on [-1, 1].
    focus : ndarray, shape (F, m) or (F, 1)
        Slant distance of each focus [m] (per trial or common).
    s_out, omega_out : ndarray, shape (F, P, m')
        m' = max of the trials of the parameters and of `focus`.
    scratch : ndarray, shape (F, P + 1, m')
        Pulsed: each focus's half length; CW: its angle atan(L / z_R) and the tangents.

    A focus whose half length (pulsed: the probe's reach short of the lens) or angle
    (CW: the tails' cut short of the lens, the same angle atan(c) at every focus) equals
    an earlier one's in the same trial takes that one's erf or tan values (the same
    numbers), so that erf and tan are evaluated once per distinct rule, not per gate.
    """
    count = s_out.shape[2]
    n_nodes = x.shape[0]
    for f in range(focus.shape[0]):
        for j in range(count):
            p1 = first[j if first.shape[0] > 1 else 0]
            p2 = second[j if second.shape[0] > 1 else 0]
            distance = focus[f, j if focus.shape[1] > 1 else 0]
            if kind == PULSED:          # PulsedProbe.half_length and _node, pulsed_weight
                radius = p2 / (2.0 * _SQRT_LN2)
                reach = p1 / 2.0 + tail_sigmas * (radius / _SQRT2)
                half = reach if reach <= distance else distance
                scratch[f, 0, j] = half
                same = _earlier(scratch, f, j, half)
                if same >= 0:           # the same rule: its nodes and weights
                    for p in range(n_nodes):
                        s_out[f, p, j] = s_out[same, p, j]
                        omega_out[f, p, j] = omega_out[same, p, j]
                    continue
                h = p1 / 2.0
                for p in range(n_nodes):
                    s = half * x[p]
                    weight = (math.erf((s + h) / radius) - math.erf((s - h) / radius)) \
                        / (2.0 * p1)                                   # Eq. 1
                    s_out[f, p, j] = s
                    omega_out[f, p, j] = w[p] * half * weight
            else:                       # ContinuousWaveProbe: s = z_R tan(phi)
                rayleigh = p1 * (distance * distance) / (math.pi * (p2 * p2))
                tails = cut * rayleigh
                half = tails if tails <= distance else distance
                angle = math.atan(half / rayleigh)
                scratch[f, 0, j] = angle
                same = _earlier(scratch, f, j, angle)
                for p in range(n_nodes):
                    tangent = scratch[same, p + 1, j] if same >= 0 else \
                        math.tan(x[p] * angle)
                    scratch[f, p + 1, j] = tangent
                    s_out[f, p, j] = rayleigh * tangent
                    omega_out[f, p, j] = w[p] / 2.0


@njit(inline="always")
def _earlier(scratch, f, j, value):
    """The first focus before f whose scratch[., 0, j] equals `value` (-1 if none)."""
    for g in range(f):
        if scratch[g, 0, j] == value:
            return g
    return -1


@_kernel
def node_heights(centre, vertical, item_focus, s, reference, scaled, ratio):
    """ratio[k, p, j] = (z_c + s_p b_z) / z_ref of item k's probe points (NaN at or below
    the sea; 1 where not `scaled`, no shear).

    centre, vertical : (K, m) gate-centre heights [m] and up components b_z of the true
    beams; item_focus (K,) the focus of each item (a row of `s`, (F, P, m or 1));
    reference (m,) or (1,) [m]."""
    m = ratio.shape[2]
    for k in range(centre.shape[0]):
        f = item_focus[k]
        for p in range(ratio.shape[1]):
            if s.shape[2] > 1:
                for j in range(m):
                    height = centre[k, j] + s[f, p, j] * vertical[k, j]
                    ref = reference[j if reference.shape[0] > 1 else 0]
                    value = height / ref if scaled else 1.0
                    ratio[k, p, j] = value if height > 0 else math.nan
            else:
                offset = s[f, p, 0]
                for j in range(m):
                    height = centre[k, j] + offset * vertical[k, j]
                    ref = reference[j if reference.shape[0] > 1 else 0]
                    value = height / ref if scaled else 1.0
                    ratio[k, p, j] = value if height > 0 else math.nan


@_kernel
def weighted_mean(ratio, omega, item_focus, out):
    """out[k, j] = sum_p omega[f, p, j] ratio[k, p, j] / sum_p omega[f, p, j], f the focus
    of item k; `ratio` holds (z_p / z_ref)^alpha (NaN stays NaN), nodes in order."""
    m = ratio.shape[2]
    for k in range(ratio.shape[0]):
        f = item_focus[k]
        for j in range(m):
            out[k, j] = 0.0
        if omega.shape[2] > 1:
            norm = np.zeros(m)
            for p in range(ratio.shape[1]):
                for j in range(m):
                    out[k, j] += omega[f, p, j] * ratio[k, p, j]
                    norm[j] += omega[f, p, j]
            for j in range(m):
                out[k, j] /= norm[j]
        else:
            norm1 = 0.0
            for p in range(ratio.shape[1]):
                weight = omega[f, p, 0]
                norm1 += weight
                for j in range(m):
                    out[k, j] += weight * ratio[k, p, j]
            for j in range(m):
                out[k, j] /= norm1


def parameters(probe, errors, rows=None):
    """The probe's two true parameters [SI] as float arrays (m,) or (1,): configured plus
    scale x error (:meth:`uq.physics.probe._Probe.parameters`); `errors` maps a parameter
    name to an array (n,) or a scalar (absent: 0); `rows` selects trials."""
    values = []
    for name in probe.PARAMETERS:
        error = errors.get(name)
        if error is None or np.ndim(error) == 0:
            error = np.array([0.0 if error is None else float(error)])
        elif rows is not None:
            error = error[rows]
        scale = probe_volume.PARAMETER_SCALE.get(name, 1.0)
        values.append(np.ascontiguousarray(getattr(probe, name) + scale * np.asarray(
            error, dtype=float).reshape(-1)))
    return values


def varies(probe, errors):
    """Do the errors of the probe's own parameters vary over the trials?"""
    return any(np.ndim(errors.get(name)) and np.shape(errors[name])[0] > 1
               for name in probe.PARAMETERS)


def profile(probe, first, second, centre, vertical, focus, item_focus, reference, exponent,
            out):
    """The weighted U / U_ref of every item into out (K, m): the three kernels and numpy's
    power law between them.

    Parameters
    ----------
    probe : PulsedProbe or ContinuousWaveProbe
        With its node count (:func:`uq.physics.probe.resolve`).
    first, second : ndarray (m,) or (1,)
        Its true parameters (:func:`parameters`).
    centre, vertical : ndarray (K, m)
        Gate-centre heights [m] and b_z of the items (beam, [dwell node,] gate).
    focus : ndarray (F, m) or (F, 1)
        The distinct slant distances [m]; item_focus (K,) int64 the row of each item.
    reference : ndarray (m,) or (1,)
        Reference height [m].
    exponent : float or ndarray (m,)
        Shear exponent alpha per trial (0: no shear).
    """
    x, w = probe_volume.legendre(probe.nodes)
    x, w = np.ascontiguousarray(x), np.ascontiguousarray(w)
    m = centre.shape[1]
    wide = max(first.shape[0], second.shape[0], focus.shape[1])
    s = np.empty((focus.shape[0], len(x), wide))
    omega = np.empty_like(s)
    cut = probe_volume.cw_cut(probe.truncation) if probe.kind == "cw" else 0.0
    node_weights(_KIND[probe.kind], first, second, cut, probe_volume.PULSE_TAIL_SIGMAS, x, w,
                 focus, s, omega, np.empty((focus.shape[0], len(x) + 1, wide)))
    exponent = np.asarray(exponent, dtype=float)
    scaled = bool(np.any(exponent != 0.0))
    ratio = np.empty((centre.shape[0], len(x), m))
    node_heights(centre, vertical, item_focus, s, reference, scaled, ratio)
    if scaled:                              # (z / z_ref)^alpha, SIMD; NaN stays NaN
        np.log(ratio, out=ratio)
        ratio *= exponent if exponent.ndim == 0 else exponent[None, None, :]
        np.exp(ratio, out=ratio)
    weighted_mean(ratio, omega, item_focus, out)


def distinct_focus(focus):
    """(distinct values (F, 1), index (K,) int64) of the items' focus values (K,)."""
    values, index = np.unique(np.asarray(focus, dtype=float), return_inverse=True)
    return np.ascontiguousarray(values[:, None]), np.ascontiguousarray(index, dtype=np.int64)
