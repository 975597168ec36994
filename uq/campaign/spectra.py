"""A ten-minute record's variances and their spread, from the spectral path's terms per
wavenumber (:class:`uq.campaign.adapter.SpectralTerms`).

A record of N scans, one horizontal speed a scan, reduced to its variance about its own
mean ``s^2 = (1/N) sum (u_m - mean)^2`` (Eq. 3 of :mod:`uq.physics.lidarspectral`):

* expected value: ``<s^2> = sum_j S_j (1 - |D_N(f_j)|^2)``, S_j the k1 node's term and
  ``f_j = k1_j U / (2 pi)`` (Taylor), the record's high-pass :func:`high_pass`;
* the lidar's filtering factor of the u-variance ``F = <s^2>_lidar / <s^2>_point``
  (Sathe et al. 2011), the point being u at the reference point sampled once a scan;
* the spread of s^2 from one record to the next. The field is Gaussian (Mann's field is
  a Gaussian process, and so is the lidar's linear reconstruction of it), so for the
  covariance C of the N scans (Toeplitz, ``C_mn = R((m - n) T_s)``, ``R(tau) = sum_j S_j
  cos(k1_j U tau)``: the terms are the even integrand's) and the centring P = I - 11^T/N::

      <s^2> = tr(P C) / N,   var(s^2) = 2 tr((P C)^2) / N^2

  (the variance of a Gaussian quadratic form, e.g. Priestley 1981, Eq. 5.3.21). White
  per-scan errors of variance sigma^2 add sigma^2 I to C: ``tr(PC) += (N - 1) sigma^2``
  and ``tr((PC)^2) += 2 sigma^2 tr(P C_t) + (N - 1) sigma^4``. The spread is carried as
  the dimensionless ``spread = tr((P C_t)^2) / (N <s^2>_t)^2`` of the turbulence alone
  (its ``2 spread`` is the squared coefficient of variation of s^2; it does not depend
  on the intensity).
* the platform's motion adds to each scan an error b independent of the turbulence,
  harmonics of random phase of covariance ``C_b = sum_k V_k cos(w_k (m - n) T_s)`` (V_k
  a harmonic's variance in one scan). The cross terms of ``s^2`` are exact whatever b's
  distribution: ``var(2 a^T P b / N) = 4 tr(P C_t P C_b) / N^2 = (4 / N) <s^2>_t sum_k
  V_k q(f_k)`` with the turbulence's *cross response* ``q(f) = sum_mn (P C_t P)_mn cos(2
  pi f (m - n) T_s) / tr(P C_t)`` (:func:`cross_response`; 1 for white turbulence), and
  ``4 sigma^2 V_m / N`` with the scan errors.
* the motion's own sample variance ``S_b = b^T P b / N`` spreads too: sampled once a scan
  the harmonics fold into the band below half the scan rate, where some fall within
  1 / T of each other or of zero. For harmonics ``b_m = sum_k a_k cos(theta_k m + phi_k)``
  (``theta_k = 2 pi f_k T_s``, ``a_k^2 = 2 V_k``) of independent uniform phases, with
  ``D(theta) = (1/N) sum_m e^(i theta m)``, ``alpha_kl = D(theta_k + theta_l) - D_k D_l``
  and ``beta_kl = D(theta_k - theta_l) - D_k conj(D_l)``, the monomials of the phases are
  uncorrelated and exactly::

      var(S_b) = sum_k V_k^2 |alpha_kk|^2 / 2 + sum_{k<l} 2 V_k V_l (|alpha_kl|^2 + |beta_kl|^2)

  (:func:`phase_variance`; its mean ``sum_k V_k (1 - |D_k|^2)`` is the record's
  high-pass). A Gaussian process of the same covariance would give 3 to 40 times more
  (measured for the shipped sea states). Motion measured record by record (an IMU log)
  is what it was: no such term.

The distribution of s^2 (a weighted sum of chi-square variables) is taken as a scaled
chi-square with the same mean and variance (Satterthwaite 1946; Box 1954):
``s^2 ~ <s^2> chi2_nu / nu``, ``nu = 2 <s^2>^2 / var(s^2)``.

References
----------
.. [1] Priestley, M. B. (1981). Spectral Analysis and Time Series. Academic Press.
.. [2] Satterthwaite, F. E. (1946). Biometrics Bulletin 2(6), 110-114; Box, G. E. P.
   (1954). Ann. Math. Statist. 25(2), 290-302.
.. [3] Sathe, A., Mann, J., Gottschall, J. and Courtney, M. S. (2011). J. Atmos. Oceanic
   Technol. 28, 853-868.
"""
import numpy as np
from scipy import interpolate

from uq.campaign.adapter import record_high_pass

#: Upper end of the fine k1 grid of :func:`scan_covariance`, in units of ``1 / (U T_s)``
#: [1]: above it the cosine turns by more than 10 rad between two scans, so those
#: wavenumbers add to the covariance at lag 0 only (measured: moving the cut from 10 to
#: 40 changes the spread by < 1e-3 of itself).
FINE_CUT = 10.0
#: Points of the fine grid per period of ``cos(k1 U tau)`` at the longest lag [1].
FINE_POINTS_PER_PERIOD = 16
#: Lags of one block of the covariance's cosine transform (memory: block x the fine
#: grid's points, ~FINE_CUT x FINE_POINTS_PER_PERIOD x N / 2 pi: 12 MB at N = 600).
LAG_BLOCK = 512


def high_pass(terms):
    """``1 - |D_N(f)|^2`` [1] at each node of `terms` (the record's own, Eq. 3): the
    node's share of it in the spectral path's rule where the terms carry it
    (:attr:`uq.campaign.adapter.SpectralTerms.high_pass`), else its value at the node."""
    if terms.high_pass is not None:
        return terms.high_pass
    return record_high_pass(terms.frequency, terms.scan_period, terms.record_duration)


def record_variances(terms):
    """(lidar, point) expected record variances [m2 s-2] of u (the record's high-pass)."""
    h = high_pass(terms)
    return float(np.sum(terms.lidar * h)), float(np.sum(terms.point * h))


def filtering_factor(terms):
    """The lidar's filtering factor of the record's u-variance, ``F`` [1]."""
    lidar, point = record_variances(terms)
    return lidar / point


def point_fraction(terms):
    """The point's record variance over its variance without the high-pass [1]: how much
    of the field's sigma_u^2 a ten-minute record of the point keeps."""
    return record_variances(terms)[1] / float(np.sum(terms.point))


def scan_covariance(terms, n_scans):
    """Covariance [m2 s-2] of the lidar's u between scans m - n = 0 ... N - 1 apart,
    ``R(k T_s) = integral s(k1) cos(k1 U k T_s) dk1``, shape (N,).

    The spectral path's k1 nodes (12 a decade) do not resolve ``cos(k1 U tau)`` at lags
    of minutes (``U tau`` of kilometres): summed on them, R at large lags is noise of the
    size of the nodes' terms, and the spread of s^2 comes out ~20 % high (measured
    against a dense grid). So the one-sided density ``s = 2 term / weight`` (the weights
    hold the factor 2 of the even integrand) is interpolated (a monotone cubic of log s
    against log k1, Fritsch and Carlson 1980: exact for the power laws of the spectrum's
    ranges, smooth at its knee) onto a
    uniform grid of :data:`FINE_POINTS_PER_PERIOD` points per period of the longest lag's
    cosine, up to ``k_c = FINE_CUT / (U T_s)``, for the lags of one scan and more (the
    wavenumbers above k_c turn the cosine by more than 10 rad between two scans: they
    are uncorrelated from scan to scan); R(0) is the nodes' own sum, the spectral path's
    variance."""
    lags = np.arange(n_scans) * terms.scan_period
    cut = FINE_CUT / (terms.speed * terms.scan_period)
    step = 2.0 * np.pi / (FINE_POINTS_PER_PERIOD * terms.speed * max(lags[-1], terms.scan_period))
    fine = step * (0.5 + np.arange(int(np.ceil(cut / step))))          # midpoints
    lidar = np.asarray(terms.lidar, float)
    positive = lidar > 0
    density = np.zeros(fine.size)
    if np.count_nonzero(positive) > 1:
        nodes = np.log(terms.k1[positive])
        inside = (fine >= terms.k1[positive][0]) & (fine <= terms.k1[positive][-1])
        curve = interpolate.PchipInterpolator(nodes, np.log(2.0 * lidar[positive]
                                                            / terms.weight[positive]))
        density[inside] = np.exp(curve(np.log(fine[inside])))
    weights = density * step
    covariance = np.concatenate([np.cos(np.multiply.outer(lags[i:i + LAG_BLOCK],
                                                          fine * terms.speed)) @ weights
                                 for i in range(0, lags.size, LAG_BLOCK)])
    covariance[0] = np.sum(lidar)                  # the variance: the nodes' own sum
    return covariance


def variance_spread(terms, n_scans):
    """``tr((P C_t)^2) / (N <s^2>_t)^2`` [1] of the lidar's turbulence over a record of
    `n_scans` scans (module docstring): the squared coefficient of variation of s^2 is
    twice this."""
    return toeplitz_spread(scan_covariance(terms, n_scans))


def toeplitz_spread(first):
    """``tr((P C)^2) / tr(P C)^2`` of the symmetric Toeplitz C of first row `first`
    (N,), in O(N): with the row sums ``r_i``, ``tr(PC) = N R_0 - sum r / N`` and
    ``tr((PC)^2) = sum C_ij^2 - 2 sum r_i^2 / N + (sum r)^2 / N^2``, ``sum C_ij^2 = N R_0^2
    + 2 sum_k (N - k) R_k^2``."""
    first = np.asarray(first, float)
    n = first.size
    cumulative = np.cumsum(first)
    rows = cumulative + cumulative[::-1] - first[0]          # r_i (C symmetric Toeplitz)
    squares = n * first[0] ** 2 + 2.0 * np.sum((n - np.arange(1, n)) * first[1:] ** 2)
    total = rows.sum()
    trace = n * first[0] - total / n
    return float((squares - 2.0 * np.sum(rows ** 2) / n + total ** 2 / n ** 2) / trace ** 2)


def variance_of_variance(lidar_variance, spread, noise_variance, n_scans, motion_cross=0.0,
                         motion_variance=0.0, motion_phase=0.0):
    """``var(s^2)`` [m4 s-4] of a record whose turbulence has the expected s^2
    `lidar_variance` and the :func:`variance_spread` `spread`, with white per-scan errors
    of variance `noise_variance`, and the motion's terms (module docstring):
    `motion_cross` ``sum_k V_k q(f_k)`` [m2 s-2], `motion_variance` its record variance
    [m2 s-2], `motion_phase` the spread of its own sample variance :func:`phase_variance`
    [m4 s-4]; arrays broadcast."""
    n = np.asarray(n_scans, float)
    t1 = n * lidar_variance                                  # tr(P C_t) = N <s^2>_t
    t2 = spread * t1 ** 2
    return (2.0 / n ** 2 * (t2 + 2.0 * noise_variance * t1 + (n - 1.0) * noise_variance ** 2)
            + 4.0 / n * (lidar_variance * motion_cross + noise_variance * motion_variance)
            + motion_phase)


def scan_mean(theta, n_scans):
    """``D(theta) = (1/N) sum_{m<N} e^(i theta m)`` (closed form; 1 at theta = 0 mod 2 pi)."""
    theta = np.asarray(theta, float)
    half = np.sin(theta / 2.0)
    small = np.abs(half) < 1e-12
    ratio = np.sin(n_scans * theta / 2.0) / (n_scans * np.where(small, 1.0, half))
    return np.where(small, 1.0, ratio) * np.exp(0.5j * theta * (n_scans - 1))


def phase_variance(variance, frequency, scan_period, n_scans):
    """``var(S_b)`` [m4 s-4] of the motion's sample variance over a record of harmonics of
    independent random phases (module docstring): their variances in a scan `variance`
    [m2 s-2] and frequencies [Hz], each (..., K)."""
    v = np.asarray(variance, float)
    theta = 2.0 * np.pi * np.asarray(frequency, float) * scan_period
    d = scan_mean(theta, n_scans)
    alpha = scan_mean(theta[..., :, None] + theta[..., None, :], n_scans) \
        - d[..., :, None] * d[..., None, :]
    beta = scan_mean(theta[..., :, None] - theta[..., None, :], n_scans) \
        - d[..., :, None] * np.conj(d[..., None, :])
    pair = v[..., :, None] * v[..., None, :]
    diagonal = np.einsum("...kk->...k", pair * np.abs(alpha) ** 2)
    off = 2.0 * pair * (np.abs(alpha) ** 2 + np.abs(beta) ** 2)
    upper = np.triu(np.ones(off.shape[-2:], bool), 1)
    return diagonal.sum(axis=-1) / 2.0 + np.sum(np.where(upper, off, 0.0), axis=(-2, -1))


def cross_response(covariance, scan_period, frequency):
    """The cross response q(f) [1] (module docstring) of the Toeplitz C of first row
    `covariance` (N,) [m2 s-2] at `frequency` [Hz] (any shape), in O(N) a frequency:
    ``sum_mn (PCP)_mn cos(w (m - n)) = sum C cos - (2 / N) Re(conj(E) sum_m r_m e^(i w m))
    + S |E|^2 / N^2``, E = sum_m e^(i w m), r the row sums, S their sum."""
    first = np.asarray(covariance, float)
    n = first.size
    lags = np.arange(n)
    cumulative = np.cumsum(first)
    rows = cumulative + cumulative[::-1] - first[0]
    total = rows.sum()
    trace = n * first[0] - total / n
    omega = 2.0 * np.pi * np.asarray(frequency, float)[..., None] * scan_period
    phase = np.exp(1j * omega * lags)                               # (..., N)
    toeplitz_sum = n * first[0] + 2.0 * np.sum((n - lags[1:]) * first[1:]
                                               * np.cos(omega * lags[1:]), axis=-1)
    sums = phase.sum(axis=-1)
    mixed = np.real(np.conj(sums) * (phase @ rows))
    return (toeplitz_sum - 2.0 * mixed / n + total * np.abs(sums) ** 2 / n ** 2) / trace


def folded(frequency, scan_period):
    """`frequency` [Hz] folded into [0, 1 / (2 T_s)]: the cross response is even and
    periodic with the scan rate (scans sample the motion once a scan)."""
    rate = 1.0 / scan_period
    f = np.mod(np.asarray(frequency, float), rate)
    return np.minimum(f, rate - f)


def degrees_of_freedom(mean, variance):
    """Satterthwaite's ``nu = 2 mean^2 / variance`` [1] (module docstring)."""
    return 2.0 * np.asarray(mean, float) ** 2 / np.asarray(variance, float)
