"""Compiled kernels of a record's turbulence: the colouring of a Mann box's white noise
by the spectral factor, and the sampling of a box along the beams.

The same arithmetic as the numpy reference (:func:`uq.physics.turbulencebox.
mann1998_spectral_factor` applied as ``u_k = i C(k) n_k sqrt(N dk)``, and
:func:`uq.physics.turbulencesampling.sample_velocity` projected on the beams) in one pass
over the cells or the probe points, without the reference's temporaries: the factor's
nine entries of a slab (72 MB per 2^20 cells) and the eight corners' gathers of each
point. They agree with the reference to rounding (``tests/physics/
test_turbulencekernels.py``); the order of the sums differs, so not bit for bit.

Both kernels carry explicit signatures and numba's on-disk cache: they compile once, on
first import (``uq warmup`` imports them), about 2 s each.

Conventions: those of :mod:`uq.physics.turbulencebox` (box, wavenumbers, Fourier
convention, the eddy lifetime's table) and :mod:`uq.physics.turbulencesampling` (frozen
field, trilinear interpolation, periodic box along x, and along y and z where
``periodic_yz``; a beam's radial velocity is the probe-weighted mean over its dwell of
``d . u'``).

References
----------
.. [1] Mann, J. (1994). The spatial structure of neutral atmospheric surface-layer
   turbulence. J. Fluid Mech. 273:141-168.
.. [2] Mann, J. (1998). Wind field simulation. Prob. Eng. Mech. 13(4):269-282.
"""
import math

import numpy as np
from numba import njit

from uq.constants import VON_KARMAN_EXPONENT

#: 4 pi [1] (the von Karman spectrum's normalisation in the factor's amplitude).
FOUR_PI = 4.0 * math.pi

@njit(cache=True)
def _zetas(k1, k2, k3, k30, k0sq, ksq, beta):
    """zeta_1, zeta_2 of Mann (1994) Sec. 3.2 [1] (the branch of turbulencebox)."""
    khsq = k1 * k1 + k2 * k2
    if khsq == 0.0:                          # k along z: zeta multiplies zero there
        return 0.0, 0.0
    kh = math.sqrt(khsq)
    c1 = beta * k1 * k1 * (k0sq - 2.0 * k30 * k30 + beta * k1 * k30) / (ksq * khsq)
    c2 = k2 * k0sq / (khsq * kh) * (math.atan(k30 / kh) - math.atan(k3 / kh))
    if k1 == 0.0:                            # limit k1 -> 0
        return -beta, 0.0
    return c1 - k2 / k1 * c2, k2 / k1 * c1 + c2


@njit(cache=True)
def _trilinear_dot(u, v, w, x, y, z, d0, d1, d2):
    """d . (u, v, w) at cell coordinates (x, y, z), trilinear, indices wrapped."""
    nx, ny, nz = u.shape
    fx, fy, fz = math.floor(x), math.floor(y), math.floor(z)
    ax, ay, az = x - fx, y - fy, z - fz
    i0, j0, m0 = int(fx) % nx, int(fy) % ny, int(fz) % nz
    i1, j1, m1 = (i0 + 1) % nx, (j0 + 1) % ny, (m0 + 1) % nz
    total = 0.0
    for ci in range(2):
        i = i1 if ci else i0
        wi = ax if ci else 1.0 - ax
        for cj in range(2):
            j = j1 if cj else j0
            wj = ay if cj else 1.0 - ay
            for cm in range(2):
                m = m1 if cm else m0
                wm = az if cm else 1.0 - az
                value = d0 * u[i, j, m] + d1 * v[i, j, m] + d2 * w[i, j, m]
                total += (wi * wj * wm) * value
    return total

@njit(cache=True)
def _k2_partners(k2):
    """Per k2 index: the index of its negative, where a later one holds it exactly
    (computed with it); -2 where an earlier one holds its negative (skipped); else -1."""
    n = k2.size
    partner = np.full(n, -1, dtype=np.int64)
    for j in range(n):
        if partner[j] != -1 or k2[j] == 0.0:
            continue
        for other in range(j + 1, n):
            if partner[other] == -1 and k2[other] == -k2[j]:
                partner[j], partner[other] = other, -2
                break
    return partner


@njit(cache=True)
def _factor_scalars(a, b, c, ksq, energy_scale, length_scale, anisotropy, table_start,
                    table_step, table_values):
    """The scalars of C(k) at k = (a, b, c) [rad m-1], ``ksq`` = |k|^2 > 0
    (``energy_scale`` = alpha eps^(2/3) L^(5/3) [m3 s-2]): beta [1],
    k30 [rad m-1], zeta_1, zeta_2, the amplitude sqrt(E(k0) / (4 pi)) / k0^2 and the
    ratio k0^2 / k^2 (Mann 1994 Sec. 3.2-3.3 [1])."""
    n_nodes = table_values.size
    # eddy lifetime: log-log table and its asymptotes (turbulencebox)
    position = (math.log(math.sqrt(ksq) * length_scale) - table_start) / table_step
    inside = min(max(position, 0.0), n_nodes - 1.0)
    index = min(max(int(math.floor(inside)), 0), n_nodes - 2)
    frac = inside - index
    log_beta = (1.0 - frac) * table_values[index] + frac * table_values[index + 1]
    log_beta -= min(position, 0.0) * table_step
    log_beta -= (2.0 / 3.0) * max(position - (n_nodes - 1.0), 0.0) * table_step
    beta = anisotropy * math.exp(log_beta)
    k30 = c + beta * a                        # k at the start of the distortion [1]
    k0sq = a * a + b * b + k30 * k30
    z1, z2 = _zetas(a, b, c, k30, k0sq, ksq, beta)
    kl = math.sqrt(k0sq) * length_scale
    energy = energy_scale * kl ** 4 / (1.0 + kl ** 2) ** VON_KARMAN_EXPONENT  # von Karman [1]
    return beta, k30, z1, z2, math.sqrt(energy / FOUR_PI) / k0sq, k0sq / ksq


@njit(cache=True)
def _colour_cell(n0, n1, n2, i, j, m, a, b, k30, z1, z2, ratio, factor):
    """``n[:, i, j, m] <- factor C(k) n[:, i, j, m]`` from the factor's scalars."""
    x0, x1, x2 = n0[i, j, m], n1[i, j, m], n2[i, j, m]
    u0 = (b * z1) * x0 + (k30 - a * z1) * x1 + (-b) * x2     # C(k), Sec. 3 [2]
    u1 = (-k30 + b * z2) * x0 + (-a * z2) * x1 + a * x2
    u2 = (ratio * b) * x0 + (-ratio * a) * x1
    n0[i, j, m] = factor * u0
    n1[i, j, m] = factor * u1
    n2[i, j, m] = factor * u2


_COLOUR_SIGNATURE = ("void(complex128[:, :, ::1], complex128[:, :, ::1], "
                     "complex128[:, :, ::1], float64[::1], float64[::1], float64[::1], "
                     "float64, float64, float64, float64, float64, float64, float64[::1])")


@njit(_COLOUR_SIGNATURE, cache=True)
def mann_colour(n0, n1, n2, k1, k2, k3, alpha_epsilon, length_scale, anisotropy, scale,
                table_start, table_step, table_values):
    """Colour the noise spectra of a slab in place: ``n <- i scale C(k) n`` (Mann 1998,
    Sec. 3 [2]), with ``C`` of :func:`uq.physics.turbulencebox.mann1998_spectral_factor`
    (eddy lifetime from its table, the k1 = 0 and k1 = k2 = 0 limits of the zetas, zero
    at k = 0).

    The factor's scalars (the eddy lifetime, the zetas, the amplitude) are even in k2
    but for zeta_2, which is odd: they are computed once for a k2 and its negative
    where the slab has both (:func:`_k2_partners`), bit for bit what the other would
    compute (only signs differ, and a sign is exact in IEEE arithmetic).

    Parameters
    ----------
    n0, n1, n2 : complex128 arrays, shape (n1, n2, n3)
        Spectra of the three components' white noise on the slab's wavenumbers.
    k1, k2, k3 : float64 arrays, shapes (n1,), (n2,), (n3,)
        The slab's wavenumbers [rad m-1].
    alpha_epsilon, length_scale, anisotropy : float
        alpha eps^(2/3) [m4/3 s-2], L [m], Gamma [1].
    scale : float
        sqrt(N dk) [m-3/2] (the box's normalisation).
    table_start, table_step, table_values
        The eddy lifetime's table: first node and step of log(kL), log(beta / Gamma) at
        the nodes.
    """
    partner = _k2_partners(k2)
    energy_scale = alpha_epsilon * length_scale ** (5.0 / 3.0)
    for i in range(n0.shape[0]):
        a = k1[i]
        for j in range(n0.shape[1]):
            if partner[j] == -2:                    # done with its partner
                continue
            b = k2[j]
            for m in range(n0.shape[2]):
                c = k3[m]
                ksq = a * a + b * b + c * c
                if ksq == 0.0:
                    n0[i, j, m] = 0.0
                    n1[i, j, m] = 0.0
                    n2[i, j, m] = 0.0
                    continue
                beta, k30, z1, z2, amplitude, ratio = _factor_scalars(
                    a, b, c, ksq, energy_scale, length_scale, anisotropy, table_start,
                    table_step, table_values)
                factor = 1j * scale * amplitude
                _colour_cell(n0, n1, n2, i, j, m, a, b, k30, z1, z2, ratio, factor)
                if partner[j] >= 0:                 # -b: z2 odd, the rest even
                    _colour_cell(n0, n1, n2, i, partner[j], m, a, -b, k30, z1, -z2, ratio,
                                 factor)


_SAMPLE_SIGNATURE = ("int64(float64[:, :, ::1], float64[:, :, ::1], float64[:, :, ::1], "
                     "float64[::1], float64[::1], boolean, float64[:, :, :, ::1], "
                     "float64[:, :, ::1], float64[:, :, ::1], float64[:, :, ::1], "
                     "float64[:, ::1], float64[::1], float64[:, ::1], float64, "
                     "float64[:, :, ::1])")


@njit(_SAMPLE_SIGNATURE, cache=True)
def radial_samples(u, v, w, origin, spacing, periodic_yz, fixed, anchor, directions,
                   along, times, dwell, weights, speed, out):
    """Radial velocity of the frozen field along every beam of every scan, into `out`.

    Point ``n`` of gate ``g`` of beam ``b`` in scan ``s`` is ``fixed[b, g, n] +
    anchor[s, b] + along[b, g, n] directions[s, b]`` [m]; it sees ``directions[s, b] .
    u'_0(p - U (times[s, b] + dwell[j]) e_x)`` (trilinear), averaged over the dwell's
    nodes ``j`` and weighted by ``weights[g, n]`` (nodes of zero weight are skipped).

    Parameters
    ----------
    u, v, w : float64 arrays, shape (nx, ny, nz)
        The box's components [m s-1].
    origin, spacing : float64 arrays, shape (3,)
        The box's origin and cell size [m].
    periodic_yz : bool
        Whether y and z wrap (Mann) or a point must lie inside (Kaimal).
    fixed : float64 array, shape (n_beams, n_gates, n_nodes, 3)
    anchor, directions : float64 arrays, shape (n_scans, n_beams, 3)
    along : float64 array, shape (n_beams, n_gates, n_nodes)
    times : float64 array, shape (n_scans, n_beams)
        Mid time of each beam's dwell [s].
    dwell : float64 array, shape (n_dwell,)
        Offsets of the dwell's nodes from its mid time [s].
    weights : float64 array, shape (n_gates, n_nodes)
    speed : float
        U [m s-1].
    out : float64 array, shape (n_scans, n_beams, n_gates)
        Radial velocities [m s-1].

    Returns
    -------
    int
        Points outside a box that is not periodic in y and z (0 where all are inside;
        those points are not sampled).
    """
    nx, ny, nz = u.shape
    outside = 0
    n_dwell = dwell.size
    for s in range(anchor.shape[0]):
        for b in range(anchor.shape[1]):
            d0, d1, d2 = directions[s, b, 0], directions[s, b, 1], directions[s, b, 2]
            for g in range(weights.shape[0]):
                total = 0.0
                for n in range(weights.shape[1]):
                    weight = weights[g, n]
                    if weight == 0.0:
                        continue
                    p0 = fixed[b, g, n, 0] + anchor[s, b, 0] + along[b, g, n] * d0
                    p1 = fixed[b, g, n, 1] + anchor[s, b, 1] + along[b, g, n] * d1
                    p2 = fixed[b, g, n, 2] + anchor[s, b, 2] + along[b, g, n] * d2
                    radial = 0.0
                    for j in range(n_dwell):
                        x = (p0 - speed * (times[s, b] + dwell[j]) - origin[0]) / spacing[0]
                        y = (p1 - origin[1]) / spacing[1]
                        z = (p2 - origin[2]) / spacing[2]
                        if not periodic_yz and (y < 0 or y > ny - 1 or z < 0 or z > nz - 1):
                            outside += 1
                            continue
                        radial += _trilinear_dot(u, v, w, x, y, z, d0, d1, d2)
                    total += weight * (radial / n_dwell)
                out[s, b, g] = total
    return outside
