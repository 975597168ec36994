"""Compiled kernel of the spectral path: the beam pairs' sums over the (k2, k3) plane.

For each k1 node i, each gate g and each pair p = (b, d) of beams,
:func:`pair_sums` accumulates::

    S[g, p, i] = sum_{j, m} n_b Phi(k) n_d P_gb(k . n_b) conj(P_gd(k . n_d))
                 sinc^2(k1 U D / 2) W2[g, p, j] W3[g, p, m],      k = (k1_i, k2_j, k3_m)

the smooth part of Eq. (3) of :mod:`uq.physics.lidarspectral` times the Filon weights of
its k2 and k3 phases (:mod:`uq.physics.spectralquadrature`); the k1 sum with the record's
weights is left to the caller. ``n_b Phi n_d`` is Eq. (2) of :mod:`uq.physics.
spectraltensor` unpacked (``m = n A``: ``E(k0)/(4 pi k0^4) (k0^2 m_b . m_d - (m_b . k0)(m_d
. k0))``), with the eddy lifetime from :mod:`uq.physics.turbulencebox`'s table (relative
error 3.4e-6) and its asymptotes; the transfer P of each gate from a table on ``|kappa|``
(``P(-kappa) = conj P(kappa)``: the weighting is real), linear between nodes, `tail`
beyond it. Where `tail` is 0 a point whose every beam sees ``|k . n_b|`` beyond the
table, and a pair with one such beam, add exactly nothing and are skipped (a pulsed
probe's table ends where its transfer is below 1e-8: most of the high wavenumbers).

One pass over the points in a fixed order: the sums do not depend on threads or on
anything but the arguments (a record-mode run's numbers are the same whichever process
computes them). The numpy reference it is tested against: ``tests/physics/
test_spectralkernels.py``.

References
----------
.. [1] Mann, J. (1994). The spatial structure of neutral atmospheric surface-layer
   turbulence. J. Fluid Mech. 273:141-168.
"""
import math

import numpy as np
from numba import njit

from uq.constants import VON_KARMAN_EXPONENT

#: 4 pi [1] (the von Karman spectrum's normalisation).
FOUR_PI = 4.0 * math.pi


@njit(cache=True, nogil=True)
def _lifetime(kl, anisotropy, table_start, table_step, table_values):
    """beta(kL) from the log-log table and its asymptotes (turbulencebox.eddy_lifetime)."""
    n_nodes = table_values.size
    position = (math.log(kl) - table_start) / table_step
    inside = min(max(position, 0.0), n_nodes - 1.0)
    index = min(max(int(math.floor(inside)), 0), n_nodes - 2)
    frac = inside - index
    log_beta = (1.0 - frac) * table_values[index] + frac * table_values[index + 1]
    log_beta -= min(position, 0.0) * table_step
    log_beta -= (2.0 / 3.0) * max(position - (n_nodes - 1.0), 0.0) * table_step
    return anisotropy * math.exp(log_beta)


@njit(cache=True, nogil=True)
def _transfer(table, g, kappa, step, tail):
    """P_g(kappa) from gate g's table on |kappa| (conjugate for kappa < 0)."""
    a = abs(kappa) / step
    n = table.shape[1]
    if a >= n - 1:
        return complex(tail, 0.0)
    i = int(a)
    f = a - i
    value = (1.0 - f) * table[g, i] + f * table[g, i + 1]
    return value if kappa >= 0.0 else value.conjugate()


_PAIR_SIGNATURE = ("void(float64[::1], float64[::1], float64[::1], float64, float64, "
                   "float64, float64, float64, float64[::1], float64[:, ::1], int64[::1], "
                   "int64[::1], complex128[:, ::1], float64, float64, float64, "
                   "complex128[:, :, ::1], complex128[:, :, ::1], complex128[:, :, ::1])")


@njit(_PAIR_SIGNATURE, cache=True, nogil=True)
def pair_sums(k1, k2, k3, alpha_epsilon, length_scale, anisotropy, table_start, table_step,
              table_values, directions, first, second, transfer, kappa_step, tail,
              dwell_length, w2, w3, out):
    """``out[g, p, i] += S[g, p, i]`` of the module docstring.

    Parameters
    ----------
    k1, k2, k3 : float64 arrays
        The rules' nodes [rad m-1] (k1 > 0; k1^2 + k2^2 > 0 at every node).
    alpha_epsilon, length_scale, anisotropy : float
        Mann's alpha eps^(2/3) [m4/3 s-2], L [m], Gamma [1].
    table_start, table_step, table_values
        The eddy lifetime's table (turbulencebox._TABLE).
    directions : float64 array (B, 3)
        Unit vectors of the beams.
    first, second : int64 arrays (n_pairs,)
        The pairs' beams b and d.
    transfer : complex128 array (G, n_table)
        Each gate's transfer at ``|kappa| = t kappa_step``, t = 0, 1, ...
    kappa_step, tail : float
        The table's step [rad m-1] and the transfer beyond it [1].
    dwell_length : float
        U D [m]: the dwell's advection (0: an instant).
    w2, w3 : complex128 arrays (G, n_pairs, n2), (G, n_pairs, n3)
        Filon weights of the pairs' k2 and k3 phases.
    out : complex128 array (G, n_pairs, n1)
    """
    n_beams, n_gates, n_pairs = directions.shape[0], transfer.shape[0], first.size
    energy_scale = alpha_epsilon * length_scale ** (5.0 / 3.0)
    m_vec = np.empty((n_beams, 3))
    along = np.empty(n_beams)
    passes = np.empty(n_beams, dtype=np.bool_)
    reach = (transfer.shape[1] - 1) * kappa_step if tail == 0.0 else np.inf
    probe = np.empty((n_gates, n_beams), dtype=np.complex128)
    inner = np.empty((n_gates, n_pairs), dtype=np.complex128)
    for i in range(k1.size):
        a = k1[i]
        x = 0.5 * a * dwell_length
        dwell = 1.0 if x == 0.0 else (math.sin(x) / x) ** 2
        for j in range(k2.size):
            b = k2[j]
            inner[:, :] = 0.0
            for m in range(k3.size):
                c = k3[m]
                seen = 0
                for n in range(n_beams):
                    kappa = a * directions[n, 0] + b * directions[n, 1] + c * directions[n, 2]
                    along[n] = kappa
                    passes[n] = abs(kappa) < reach
                    seen += passes[n]
                if seen == 0:
                    continue
                ksq = a * a + b * b + c * c
                beta = _lifetime(math.sqrt(ksq) * length_scale, anisotropy, table_start,
                                 table_step, table_values)
                k30 = c + beta * a                    # Eq. 3.14 [1]
                k0sq = a * a + b * b + k30 * k30
                khsq = a * a + b * b
                kh = math.sqrt(khsq)
                c1 = beta * a * a * (k0sq - 2.0 * k30 * k30 + beta * a * k30) / (ksq * khsq)
                c2 = b * k0sq / (khsq * kh) * (math.atan(k30 / kh) - math.atan(c / kh))
                z1 = c1 - b / a * c2
                z2 = b / a * c1 + c2
                ratio = k0sq / ksq
                kl = math.sqrt(k0sq) * length_scale
                energy = energy_scale * kl ** 4 / (1.0 + kl * kl) ** VON_KARMAN_EXPONENT
                factor = energy / (FOUR_PI * k0sq * k0sq) * dwell
                for n in range(n_beams):
                    if not passes[n]:
                        continue
                    d0, d1, d2 = directions[n, 0], directions[n, 1], directions[n, 2]
                    third = z1 * d0 + z2 * d1 + ratio * d2
                    m_vec[n, 0], m_vec[n, 1], m_vec[n, 2] = d0, d1, third
                    for g in range(n_gates):
                        probe[g, n] = _transfer(transfer, g, along[n], kappa_step, tail)
                    along[n] = d0 * a + d1 * b + third * k30
                for p in range(n_pairs):
                    u, v = first[p], second[p]
                    if not (passes[u] and passes[v]):
                        continue
                    dot = (m_vec[u, 0] * m_vec[v, 0] + m_vec[u, 1] * m_vec[v, 1]
                           + m_vec[u, 2] * m_vec[v, 2])
                    projection = factor * (k0sq * dot - along[u] * along[v])
                    for g in range(n_gates):
                        inner[g, p] += (projection * probe[g, u] * probe[g, v].conjugate()
                                        * w3[g, p, m])
            for g in range(n_gates):
                for p in range(n_pairs):
                    out[g, p, i] += inner[g, p] * w2[g, p, j]


_VECTOR_SIGNATURE = ("void(float64[::1], float64[::1], float64[::1], float64[::1], float64, "
                     "float64, float64, float64, float64, float64[::1], float64[:, ::1], "
                     "float64[:, :, ::1], float64[::1], float64, float64, float64[:, :, ::1], "
                     "complex128[:, ::1], float64, float64, float64[:, ::1])")


@njit(_VECTOR_SIGNATURE, cache=True, nogil=True)
def vector_sums(k1, k2, k3, weight, alpha_epsilon, length_scale, anisotropy, table_start,
                table_step, table_values, directions, centres, times, speed, dwell_length,
                reconstruction, transfer, kappa_step, tail, out):
    """``out[g, c] += sum_p w_p G_c Phi G_c^H`` at the points (k1_p, k2_p, k3_p) (weights
    `weight` [m3 with the record's high-pass]): Eq. (2)-(3) of
    :mod:`uq.physics.lidarspectral` by the vectors ``G_c = sum_b R_gcb n_b P_gb(k . n_b)
    sinc(k1 U D / 2) exp(i (k . r_bg - k1 U t_b))``, their phases at the points.

    Parameters
    ----------
    k1, k2, k3, weight : float64 arrays (P,)
        The points [rad m-1] (k1^2 + k2^2 > 0) and their weights.
    directions : (B, 3); centres : (G, B, 3) [m]; times : (B,) [s]
    speed, dwell_length : float
        U [m s-1] and U D [m].
    reconstruction : (G, 3, B)
    transfer, kappa_step, tail
        As :func:`pair_sums`.
    out : float64 array (G, 3)
    """
    n_beams, n_gates = directions.shape[0], centres.shape[0]
    energy_scale = alpha_epsilon * length_scale ** (5.0 / 3.0)
    vector = np.empty((3, 3), dtype=np.complex128)
    for p in range(k1.size):
        a, b, c = k1[p], k2[p], k3[p]
        ksq = a * a + b * b + c * c
        beta = _lifetime(math.sqrt(ksq) * length_scale, anisotropy, table_start, table_step,
                         table_values)
        k30 = c + beta * a                            # Eq. 3.14 [1]
        k0sq = a * a + b * b + k30 * k30
        khsq = a * a + b * b
        kh = math.sqrt(khsq)
        c1 = beta * a * a * (k0sq - 2.0 * k30 * k30 + beta * a * k30) / (ksq * khsq)
        c2 = b * k0sq / (khsq * kh) * (math.atan(k30 / kh) - math.atan(c / kh))
        z1 = c1 - b / a * c2
        z2 = b / a * c1 + c2
        ratio = k0sq / ksq
        kl = math.sqrt(k0sq) * length_scale
        energy = energy_scale * kl ** 4 / (1.0 + kl * kl) ** VON_KARMAN_EXPONENT
        x = 0.5 * a * dwell_length
        dwell = 1.0 if x == 0.0 else math.sin(x) / x
        factor = energy / (FOUR_PI * k0sq * k0sq) * weight[p]
        for g in range(n_gates):
            vector[:, :] = 0.0
            for n in range(n_beams):
                d0, d1, d2 = directions[n, 0], directions[n, 1], directions[n, 2]
                probe = _transfer(transfer, g, a * d0 + b * d1 + c * d2, kappa_step, tail)
                if probe == 0.0:
                    continue
                phase = (a * centres[g, n, 0] + b * centres[g, n, 1] + c * centres[g, n, 2]
                         - a * speed * times[n])
                t = probe * dwell * complex(math.cos(phase), math.sin(phase))
                for comp in range(3):
                    r = reconstruction[g, comp, n] * t
                    vector[comp, 0] += r * d0
                    vector[comp, 1] += r * d1
                    vector[comp, 2] += r * d2
            for comp in range(3):        # G Phi G^H with q = G A (MannTensor.quadratic_form)
                g0, g1 = vector[comp, 0], vector[comp, 1]
                q2 = z1 * g0 + z2 * g1 + ratio * vector[comp, 2]
                norm = abs(g0) ** 2 + abs(g1) ** 2 + abs(q2) ** 2
                along = abs(g0 * a + g1 * b + q2 * k30) ** 2
                out[g, comp] += factor * (k0sq * norm - along)
