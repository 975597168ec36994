"""Spectral models of atmospheric turbulence: Mann's sheared spectral tensor and Kaimal's spectra.

Conventions
-----------
Mean-wind frame of :mod:`uq.physics.scangeometry` (x downwind, y left, z up); wavenumbers
``k = (k1, k2, k3)`` [rad m-1]; a field ``u'(r) = integral exp(i k . r) dZ(k)`` with
``<dZ_i(k) dZ_j*(k)> = Phi_ij(k) d^3k``, so ``sigma_i^2 = integral Phi_ii d^3k`` (no 2 pi
factors). One-sided frequency spectra ``S(f)`` [m2 s-2 Hz-1], ``sigma^2 = integral_0^inf S df``.

Mann (1994, 1998) [1, 2]. The isotropic von Karman tensor ``Phi_iso(k) = E(k) / (4 pi k^4)
(k^2 delta_ij - k_i k_j)`` with the energy spectrum (Eq. 2.6 of [1])::

    E(k) = alpha eps^(2/3) L^(5/3) (k L)^4 / (1 + (k L)^2)^(17/6)              (1)

is distorted by the mean shear during the eddy lifetime ``tau(k) = Gamma (dU/dz)^-1 (kL)^(-2/3)
/ sqrt(2F1(1/3, 17/6; 4/3; -(kL)^-2))`` (Eq. 3.13 of [1]); with ``beta = (dU/dz) tau`` the
wave vector at the start of the distortion is ``k0 = (k1, k2, k3 + beta k1)`` and
(Eq. 3.16 of [1], Eq. 12-13 of [2])::

    Phi(k) = A(k) Phi_iso(k0) A(k)^T,   A = [[1, 0, zeta1], [0, 1, zeta2], [0, 0, k0^2/k^2]]  (2)

    C1 = beta k1^2 (k0^2 - 2 k30^2 + beta k1 k30) / (k^2 (k1^2 + k2^2))
    C2 = k2 k0^2 / (k1^2 + k2^2)^(3/2) [atan(k30 / kh) - atan(k3 / kh)],  kh = sqrt(k1^2 + k2^2)
    zeta1 = C1 - k2 C2 / k1,  zeta2 = k2 C1 / k1 + C2

The printed ``C2`` has ``atan(beta k1 kh / (k0^2 - k30 k1 beta))``: it equals the difference
of the two arctangents (the integral over the lifetime it comes from) only where the
denominator is positive; the difference is used here, valid everywhere. ``Gamma = 0``
is the isotropic tensor. The tensor is even in ``k`` (so is ``C2``: odd in k1 times odd).

The scale ``alpha eps^(2/3)`` is set by the stated intensity: ``sigma_u^2`` of the point
field is ``alpha eps^(2/3) L^(2/3) s_u(Gamma)``, where ``s_u`` is the sheared tensor's
integral ``integral Phi_11 d^3k`` at unit ``alpha eps^(2/3)`` and ``L`` (computed once per
Gamma by the quadrature of :mod:`uq.physics.lidarspectral`), not the isotropic
``(1/3) B(5/2, 1/3)`` [1, Eq. 2.8]: the shear moves energy into u.

Kaimal (IEC 61400-1:2005 Annex B.2, Eqs. B.12-B.13 [3]; Ed. 4: Annex C)::

    f S_k(f) / sigma_k^2 = 4 f L_k / U / (1 + 6 f L_k / U)^(5/3)                    (3)
    Coh(r, f) = exp(-12 sqrt((f r / U)^2 + (0.12 r / L_c)^2))                       (4)

with ``r`` the separation projected on the plane normal to the mean wind. The standard
applies (4) to u; here it is applied to each component alike and the components are
uncorrelated (no u-w cross-spectrum), stated.

References
----------
.. [1] Mann, J. (1994). The spatial structure of neutral atmospheric surface-layer
   turbulence. J. Fluid Mech. 273, 141-168.
.. [2] Mann, J. (1998). Wind field simulation. Probab. Eng. Mech. 13(4), 269-282.
.. [3] IEC 61400-1:2005. Wind turbines - Part 1: Design requirements, Annex B (Ed. 4,
   2019: Annex C).
"""
import functools
from dataclasses import dataclass

import numpy as np
from scipy import special

from uq.constants import (IEC_COHERENCE_DECREMENT, IEC_COHERENCE_LENGTH_FACTOR,
                          IEC_COHERENCE_SCALE_RATIO, IEC_KAIMAL_LENGTH_FACTORS,
                          IEC_KAIMAL_SIGMA_RATIOS, MANN_ANISOTROPY, MANN_LENGTH_FACTOR,
                          IEC_SCALE_HEIGHT, IEC_SCALE_PARAMETER, IEC_SCALE_SLOPE,
                          SPECTRAL_ANGLE_NODES, SPECTRAL_K1_PER_DECADE, SPECTRAL_K_DECADES,
                          SPECTRAL_RADIUS_DECADES, SPECTRAL_RADIUS_PER_DECADE,
                          VON_KARMAN_EXPONENT)

#: Models of the ``turbulence`` section.
TURBULENCE_MODELS = ("mann", "kaimal")
#: k1 nodes of the quadrature that :func:`point_variances` evaluates at once (a work size,
#: not physics: ~2.5 MB of temporaries per node of the standard grid).
K1_PER_BLOCK = 12


def iec_scale_parameter(height):
    """Turbulence scale parameter Lambda_1 [m] at hub `height` [m], IEC 61400-1 Eq. (B.1) [3]."""
    return np.where(np.asarray(height) <= IEC_SCALE_HEIGHT, IEC_SCALE_SLOPE * height,
                    IEC_SCALE_PARAMETER)


def iec_mann_parameters(height):
    """IEC 61400-1 Annex B.1 defaults (L [m], Gamma [1]) of the Mann model at `height` [m]."""
    return MANN_LENGTH_FACTOR * float(iec_scale_parameter(height)), MANN_ANISOTROPY


def von_karman_energy(k, length_scale, alpha_epsilon=1.0):
    """Von Karman energy spectrum E(k) [m3 s-2], Eq. (1) (Eq. 2.6 of [1]): the one
    implementation (:func:`uq.physics.turbulencebox.von_karman_energy_spectrum` calls it).

    Parameters
    ----------
    k : array_like, or an array of any namespace (numpy, CuPy)
        Wavenumber magnitude [rad m-1].
    length_scale : float
        L [m].
    alpha_epsilon : float
        alpha eps^(2/3) [m^(4/3) s-2].
    """
    kl = (k if hasattr(k, "shape") else np.asarray(k, dtype=float)) * length_scale
    return (alpha_epsilon * length_scale ** (5.0 / 3.0) * kl ** 4
            / (1.0 + kl * kl) ** VON_KARMAN_EXPONENT)               # Eq. 2.6 [1]


def isotropic_variance_factor():
    """``sigma^2 / (alpha eps^(2/3) L^(2/3))`` [1] of each component of the isotropic von
    Karman field: ``(2/3) integral E = (1/3) B(5/2, 1/3)`` (Eq. 2.8 of [1])."""
    return special.beta(2.5, 1.0 / 3.0) / 3.0


def mann_eddy_lifetime(k, length_scale, anisotropy):
    """Non-dimensional eddy lifetime beta = Gamma (kL)^(-2/3) / sqrt(2F1(1/3, 17/6; 4/3;
    -(kL)^-2)) [1] (Eq. 3.13 of [1], times dU/dz). Even in k; ~Gamma c / (kL) as kL -> 0."""
    kl = np.asarray(k, dtype=float) * length_scale
    hyper = special.hyp2f1(1.0 / 3.0, 17.0 / 6.0, 4.0 / 3.0, -kl ** -2.0)
    return anisotropy * kl ** (-2.0 / 3.0) / np.sqrt(hyper)


@dataclass(frozen=True)
class MannTensor:
    """Mann's (1998) uniform-shear spectral tensor, Eq. (2) of the module docstring.

    Attributes
    ----------
    length_scale : float
        L [m].
    anisotropy : float
        Gamma [1] (0: isotropic von Karman).
    alpha_epsilon : float
        alpha eps^(2/3) [m^(4/3) s-2].
    """

    length_scale: float
    anisotropy: float
    alpha_epsilon: float = 1.0

    def __post_init__(self):
        if not (self.length_scale > 0 and self.anisotropy >= 0 and self.alpha_epsilon > 0):
            raise ValueError("MannTensor: length_scale > 0, anisotropy >= 0, alpha_epsilon > 0")

    def distortion(self, k1, k2, k3):
        """The energy factor ``E(k0) / (4 pi k0^4)`` [m5 s-2], ``k0`` (3 arrays) and the
        non-trivial entries (zeta1, zeta2, k0^2/k^2) of A, Eq. (2); arrays broadcast.
        Requires ``k1^2 + k2^2 > 0`` where Gamma > 0."""
        k1, k2, k3 = np.broadcast_arrays(*(np.asarray(v, dtype=float) for v in (k1, k2, k3)))
        ksq = k1 * k1 + k2 * k2 + k3 * k3
        if self.anisotropy == 0:
            zero = np.zeros_like(ksq)
            energy = von_karman_energy(np.sqrt(ksq), self.length_scale, self.alpha_epsilon)
            return energy / (4 * np.pi * ksq * ksq), (k1, k2, k3), (zero, zero, zero + 1.0)
        beta = mann_eddy_lifetime(np.sqrt(ksq), self.length_scale, self.anisotropy)
        k30 = k3 + beta * k1                                         # Eq. 3.14 [1]
        k0sq = k1 * k1 + k2 * k2 + k30 * k30
        khsq = k1 * k1 + k2 * k2
        kh = np.sqrt(khsq)
        c1 = beta * k1 * k1 * (k0sq - 2 * k30 * k30 + beta * k1 * k30) / (ksq * khsq)
        # Eq. 3.16 [1]: the lifetime integral, as a difference of arctangents (any branch)
        c2 = k2 * k0sq / khsq ** 1.5 * (np.arctan(k30 / kh) - np.arctan(k3 / kh))
        zeta1 = c1 - k2 / k1 * c2
        zeta2 = k2 / k1 * c1 + c2
        energy = von_karman_energy(np.sqrt(k0sq), self.length_scale, self.alpha_epsilon)
        return energy / (4 * np.pi * k0sq * k0sq), (k1, k2, k30), (zeta1, zeta2, k0sq / ksq)

    def matrix(self, k1, k2, k3):
        """Phi_ij(k) [m5 s-2], shape (..., 3, 3), Eq. (2)."""
        factor, k0, (zeta1, zeta2, ratio) = self.distortion(k1, k2, k3)
        shape = np.shape(factor)
        a = np.zeros(shape + (3, 3))
        a[..., 0, 0] = a[..., 1, 1] = 1.0
        a[..., 0, 2], a[..., 1, 2], a[..., 2, 2] = zeta1, zeta2, ratio
        k0v = np.stack(k0, axis=-1)
        k0sq = np.sum(k0v * k0v, axis=-1)
        projector = k0sq[..., None, None] * np.eye(3) - k0v[..., :, None] * k0v[..., None, :]
        return factor[..., None, None] * (a @ projector @ np.swapaxes(a, -1, -2))

    def quadratic_form(self, vectors, k1, k2, k3):
        """``g Phi(k) g^H`` [m5 s-2 x |g|^2] for complex row vectors `vectors` (..., 3): with
        ``q = g A``, ``E(k0)/(4 pi k0^4) (k0^2 |q|^2 - |q . k0|^2)`` (Eq. 2)."""
        factor, k0, (zeta1, zeta2, ratio) = self.distortion(k1, k2, k3)
        g = np.asarray(vectors)
        q = (g[..., 0], g[..., 1], zeta1 * g[..., 0] + zeta2 * g[..., 1] + ratio * g[..., 2])
        k0sq = k0[0] ** 2 + k0[1] ** 2 + k0[2] ** 2
        norm = sum(np.abs(c) ** 2 for c in q)
        along = np.abs(q[0] * k0[0] + q[1] * k0[1] + q[2] * k0[2]) ** 2
        return factor * (k0sq * norm - along)


@dataclass(frozen=True)
class KaimalSpectra:
    """IEC 61400-1 Kaimal spectra of (u, v, w) and exponential coherence, Eqs. (3)-(4).

    Attributes
    ----------
    sigmas : tuple of 3 float
        Standard deviations of (u, v, w) [m s-1].
    lengths : tuple of 3 float
        Integral scale parameters L_k of (u, v, w) [m].
    coherence_length : float
        L_c [m] of Eq. (4).
    speed : float
        Mean wind speed U [m s-1] (hub height).
    """

    sigmas: tuple
    lengths: tuple
    coherence_length: float
    speed: float

    @classmethod
    def iec(cls, intensity, speed, length_u, sigma_ratios=IEC_KAIMAL_SIGMA_RATIOS):
        """The IEC model of intensity sigma_u / U [1] at `speed` [m s-1] whose u length is
        `length_u` = 8.1 Lambda_1 [m]; v, w and L_c scaled by Table B.1 [3]."""
        scale = length_u / IEC_KAIMAL_LENGTH_FACTORS[0]
        sigmas = tuple(intensity * speed * r for r in sigma_ratios)
        lengths = tuple(f * scale for f in IEC_KAIMAL_LENGTH_FACTORS)
        return cls(sigmas, lengths, IEC_COHERENCE_LENGTH_FACTOR * scale, speed)

    def spectrum(self, component, frequency):
        """One-sided S_k(f) [m2 s-2 Hz-1] of component 0, 1, 2 at `frequency` [Hz], Eq. (3)."""
        tau = self.lengths[component] / self.speed
        f = np.asarray(frequency, dtype=float)
        return self.sigmas[component] ** 2 * 4 * tau / (1 + 6 * f * tau) ** (5.0 / 3.0)

    def coherence(self, separation, frequency):
        """Coh(r, f) [1] of Eq. (4) at across-wind separation r [m] and frequency [Hz]."""
        r, f = np.asarray(separation, dtype=float), np.asarray(frequency, dtype=float)
        return np.exp(-IEC_COHERENCE_DECREMENT * np.sqrt(
            (f * r / self.speed) ** 2 + (IEC_COHERENCE_SCALE_RATIO * r
                                         / self.coherence_length) ** 2))


def kaimal_exponential_integral(order, b):
    """``E_p(b) = integral_1^inf t^-p exp(-b t) dt`` for p in (1, 2), b > 0, from
    ``E_(p-1)(b) = b^(p-2) Gamma(2-p, b)`` and ``E_p = (exp(-b) - b E_(p-1)) / (p - 1)``
    (Abramowitz and Stegun 5.1.14, 6.5.3)."""
    a = 2.0 - order
    lower = b ** (order - 2.0) * special.gamma(a) * special.gammaincc(a, b)
    return (np.exp(-b) - b * lower) / (order - 1.0)



# --- quadrature over wavenumber space ------------------------------------------------------

def _log_nodes(decades, per_decade):
    """Gauss-Legendre nodes and weights in log10, one panel per decade: (u, w) with
    ``integral g(10^u) du = sum w g(10^u)`` over ``decades`` (low, high)."""
    x, w = np.polynomial.legendre.leggauss(per_decade)
    edges = np.arange(decades[0], decades[1])
    u = (edges[:, None] + (x[None, :] + 1.0) / 2.0).ravel()
    return u, np.tile(w / 2.0, len(edges))


@dataclass(frozen=True)
class WavenumberGrid:
    """Quadrature of ``integral f(k) d^3k`` over the half space k1 > 0 (doubled: the
    integrands of the spectral path are real and even in k), in log k1 and, per k1, polar
    coordinates ``(k2, k3) = rho (cos phi, sin phi)`` with ``rho = s 10^u``, ``s = sqrt(k1^2
    + L^-2)`` (the scale where Phi is largest), ``u`` on ``radius_decades`` and phi
    trapezoidal (periodic)::

        integral f d^3k = 2 integral integral integral f k1 rho^2 (ln 10)^2 du1 du dphi

    Attributes
    ----------
    length_scale : float
        L [m] (the grid is in units of 1 / L).
    k_decades, radius_decades : tuple
        Decades of k1 L and of rho / s.
    k1_per_decade, radius_per_decade, angle_nodes : int
    """

    length_scale: float
    k_decades: tuple = SPECTRAL_K_DECADES
    radius_decades: tuple = SPECTRAL_RADIUS_DECADES
    k1_per_decade: int = SPECTRAL_K1_PER_DECADE
    radius_per_decade: int = SPECTRAL_RADIUS_PER_DECADE
    angle_nodes: int = SPECTRAL_ANGLE_NODES

    def k1(self):
        """k1 nodes [rad m-1] and their weights in ``d k1`` (including the factor 2)."""
        u, w = _log_nodes(self.k_decades, self.k1_per_decade)
        k1 = 10.0 ** u / self.length_scale
        return k1, 2.0 * w * np.log(10.0) * k1

    def cross_section(self, k1):
        """(k2, k3, weight) of the (k2, k3) plane at each of `k1` (shape (n,)): arrays
        (n, n_rho * n_phi) [rad m-1], weights in ``d k2 d k3``."""
        u, w = _log_nodes(self.radius_decades, self.radius_per_decade)
        phi = 2 * np.pi * np.arange(self.angle_nodes) / self.angle_nodes
        scale = np.sqrt(np.asarray(k1) ** 2 + self.length_scale ** -2)[:, None, None]
        rho = scale * 10.0 ** u[None, :, None]
        weight = (w * np.log(10.0))[None, :, None] * rho ** 2 * (2 * np.pi / self.angle_nodes)
        k2 = rho * np.cos(phi)[None, None, :]
        k3 = rho * np.sin(phi)[None, None, :]
        n = len(k1)
        weight = np.broadcast_to(weight, k2.shape)
        return k2.reshape(n, -1), k3.reshape(n, -1), weight.reshape(n, -1)


def point_variances(tensor, grid=None, spectral_filter=None):
    """``integral Phi_ii(k) H(k1) d^3k`` [m2 s-2] of (u, v, w) at a point, shape (3,).

    Parameters
    ----------
    tensor : MannTensor
    grid : WavenumberGrid, optional
        Default: the standard grid at the tensor's L.
    spectral_filter : callable, optional
        ``H(k1)`` [1] (e.g. a record's high-pass), of an array of k1 [rad m-1].
    """
    k1, w1, per_k1 = point_spectra(tensor, grid)
    h = np.ones_like(k1) if spectral_filter is None else spectral_filter(k1)
    return np.einsum("ni,n->i", per_k1, w1 * h)


def point_spectra(tensor, grid=None):
    """The (u, v, w) spectra at a point along k1, ``integral Phi_ii(k) dk2 dk3``, on the
    grid's k1 nodes: (k1 [rad m-1] (n,), their weights [rad m-1] (n,), the spectra
    [m3 s-2] (n, 3)); :func:`point_variances` is their weighted sum (a filter ``H(k1)``
    applied node by node)."""
    grid = grid or WavenumberGrid(tensor.length_scale)
    k1, w1 = grid.k1()
    # A few k1 at a time: the (k1, k2, k3, 3, 3) tensor of the whole grid is ~0.2 GB of
    # temporaries (the peak of a ``uq golden`` run); each k1's sum is the same either way.
    per_k1 = np.concatenate([_diagonal_per_k1(tensor, grid, k1[start:start + K1_PER_BLOCK])
                             for start in range(0, len(k1), K1_PER_BLOCK)])
    return k1, w1, per_k1


def _diagonal_per_k1(tensor, grid, k1):
    """``integral Phi_ii(k) dk2 dk3`` [m3 s-2] at each of `k1` (shape (n,)), shape (n, 3)."""
    k2, k3, w23 = grid.cross_section(k1)
    k1b = np.broadcast_to(k1[:, None], k2.shape)
    diagonal = np.einsum("...ii->...i", tensor.matrix(k1b, k2, k3))
    return np.einsum("nqi,nq->ni", diagonal, w23)


@functools.lru_cache(maxsize=64)
def mann_variance_factors(anisotropy):
    """``sigma_i^2 / (alpha eps^(2/3) L^(2/3))`` [1] of (u, v, w) of the sheared tensor at
    `anisotropy` Gamma, by quadrature (:func:`point_variances` at L = 1)."""
    return tuple(float(v) for v in point_variances(MannTensor(1.0, float(anisotropy))))


def mann_tensor_for_intensity(intensity, speed, length_scale, anisotropy):
    """The Mann tensor whose point sigma_u / U equals `intensity` [1] at `speed` [m s-1]:
    ``alpha eps^(2/3) = (I U)^2 / (L^(2/3) s_u(Gamma))`` (module docstring)."""
    s_u = mann_variance_factors(float(anisotropy))[0]
    alpha_epsilon = (intensity * speed) ** 2 / (length_scale ** (2.0 / 3.0) * s_u)
    return MannTensor(float(length_scale), float(anisotropy), float(alpha_epsilon))
