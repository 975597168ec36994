"""The spectral path: the variance a lidar reports over a record, from the spectral tensor.

The analogue of the GUM for turbulence ("seconds, not minutes"): the expected record
variance of each reconstructed wind component is the spectral tensor filtered by the
lidar's transfer function.

Derivation
----------
Frame, times and frozen turbulence as in :mod:`uq.physics.scangeometry`:
``u'(r, t) = integral exp(i (k . r - k1 U t)) dZ(k)``. Beam b of a scan (unit vector n_b,
gate centre r_bg of gate g, mid-dwell time t_b, dwell d, range weighting W_g) measures::

    v_b = (1/d) int_{t_b-d/2}^{t_b+d/2} int W_g(s) n_b . u'(r_bg + s n_b, t) ds dt
        = int T_bg(k) n_b . dZ(k),
    T_bg(k) = What_g(k . n_b) exp(i (k . r_bg - k1 U t_b)) sinc(k1 U d / 2)        (1)

with ``What_g(kappa) = int W_g(s) exp(i kappa s) ds`` (for the pulsed weighting
``sinc(kappa Dp/2) exp(-kappa^2 r_p^2 / 4)``, the rectangle's and the Gaussian's
transforms; for the uncut Lorentzian ``exp(-z_R |kappa|)``) and ``sinc x = sin x / x``.
The reconstruction R (n_gates, 3, n_beams) gives component c of scan m (start m T_s)::

    u_c[m] = int exp(-i k1 U m T_s) G_c(k) . dZ(k),   G_cj = sum_b R_gcb n_bj T_bg   (2)

so ``<u_c[m] u_c[m']> = int |...|`` and the record of N = floor(T_rec / T_s) scans,
reduced to its variance about its own mean, ``s^2 = (1/N) sum (u_c[m] - mean)^2``, has::

    <s^2> = int G_c Phi G_c^H (1 - |D_N(f)|^2) d^3k,   f = k1 U / (2 pi)          (3)
    D_N(f) = (1/N) sum_m exp(2 pi i f m T_s),  |D_N|^2 = sin^2(pi f N T_s) / (N sin(pi f T_s))^2

exactly (``<mean^2> = int ... |D_N|^2``); the variance of one sample is the full integral
whatever the sampling, so there is no aliasing term. N = 1 gives 0; ``T_rec = inf`` no
high-pass. The true point variance over the record is (3) with ``G = e_c`` at r = 0 and the
same scan times (the reference point sampled once a scan). The horizontal speed, linearised
for the wind along x, has ``var(Vh) = var(u_x) + O(sigma^4 / U^2)``.

The integrand of (3) is real (Phi is real symmetric) and even in k, so it is integrated
over k1 > 0 and doubled (:class:`~uq.physics.spectraltensor.WavenumberGrid`: log k1, and
per k1 log-polar (k2, k3) about ``sqrt(k1^2 + L^-2)``, which follows the tensor's energy
down to the small-k region where the shear's eddy lifetime ~ 1/(kL) stretches k30).
Numerics: for a few beams ``G Phi G^H = sum_bd R_gcb R_gcd Re(T_b T_d*) n_b Phi n_d``, with
the beam-pair projections of Phi shared by all gates; for many (a VAD) the vectors G_c.
Grid points holding less than :data:`~uq.constants.SPECTRAL_PRUNE` of the field's trace
are left out of the lidar's sum (bounded in the constant's note). The ratio
var_lidar / var_true of the tests' DBS is converged to 1.5e-3 (a grid with twice the nodes
and wider ranges); about 0.1 s CPU per gate and 0.3 s for the tensor on 2 loaded cores
(``scripts/bench_spectral.py``).

Kaimal (IEC) has no tensor: with the components uncorrelated, each with spectrum S_j and
the coherence Coh(r_perp, f) between points, frozen turbulence puts the point p = (beam,
probe node) at the delay ``tau_p = t_b - x_p / U`` behind the reference plane, and::

    <s^2> = int_0^inf sum_j S_j(f) (1 - |D_N|^2) sinc^2(pi f d)
            sum_{p,q} a_pj a_qj Coh(|r_perp,p - r_perp,q|, f) cos(2 pi f (tau_p - tau_q)) df   (4)

with ``a_pj = R_gcb n_bj w_gi`` (probe quadrature weight w_gi of node i).

Closed forms (the tests check (3) and (4) against them)
--------------------------------------------------------
*Staring CW beam along the wind, Kaimal u* (point in y, z; uncut Lorentzian of half width
Gamma_CW = z_R, the Rayleigh length; L = L_u = 8.1 Lambda_1, the Kaimal length of u; no
high-pass): the beam sees u through ``|What(k1)|^2 = exp(-2 Gamma_CW k1)``, ``k1 = 2 pi f /
U``; with ``x = 6 f L / U``, ``S df / sigma^2 = (2/3) (1 + x)^(-5/3) dx``::

    F = var_lidar / sigma_u^2 = (2/3) int_0^inf (1+x)^(-5/3) exp(-b x) dx
      = (2/3) e^b E_{5/3}(b),   b = 2 pi Gamma_CW / (3 L)                           (5)

*Block average over a scan of T_s* (Kaimal u; record without high-pass):
``var/sigma^2 = int S sinc^2(pi f T_s) df / sigma^2``; with ``(1+x)^(-5/3) = int_0^inf
s^(2/3) e^(-s(1+x)) ds / Gamma(5/3)`` and ``int_0^inf e^(-s x) sin^2(c x) / x^2 dx = c
atan(2c/s) - (s/4) ln(1 + 4 c^2 / s^2)`` (differentiate twice in c)::

    var/sigma^2 = 2 / (3 c^2 Gamma(5/3)) int_0^inf s^(2/3) e^-s [c atan(2c/s)
                  - (s/4) ln(1 + 4c^2/s^2)] ds,   c = pi T_s U / (6 L)              (6)

*Harmonic platform velocity* ``v_L(t) = Re(A exp(i (omega t + psi)))`` (A complex [m s-1],
wind frame; a surge of amplitude a has |A| = a omega), psi uniform: the lidar measures
``n . (u - v_L)``, so component c errs by ``-Re(C_c exp(i (omega m T_s + psi)))``,
``C_c = sum_b R_gcb (n_b . A) exp(i omega t_b)``, whose record variance is::

    var = |C_c|^2 / 2 (1 - |D_N(omega / 2 pi)|^2)                                   (7)

DBS, u from the two beams in the wind's plane (``u = (v_1 - v_3) / (2 sin phi)``), surge
along x: ``C = aw (e^{i w t_1} + e^{i w t_3}) / 2``, ``|C| = a w |cos(w (t_3 - t_1) / 2)|``.
VAD (LS fit of a full revolution, uniform in time, beam along the wind at t = 0, period
T_s), surge along x: ``C = a w mean(2 cos^2(Omega t) e^{i w t})``, ``Omega = 2 pi / T_s``;
with ``x = pi T_s / T``::

    |C| = a w |sin x| |1/x + x / (x^2 - 4 pi^2)|                                    (8)

References
----------
.. [1] Mann, J. (1994). J. Fluid Mech. 273, 141-168; Mann, J. (1998). Probab. Eng. Mech.
   13(4), 269-282.
.. [2] Sathe, A., Mann, J., Gottschall, J. and Courtney, M. S. (2011). Can wind lidars
   measure turbulence? J. Atmos. Oceanic Technol. 28, 853-868 (Eqs. 4-14: the same
   filtering for a pulsed DBS and a CW VAD, simultaneous beams, no high-pass).
.. [3] IEC 61400-1:2005, Annex B (Kaimal spectrum and exponential coherence).
.. [4] Abramowitz, M. and Stegun, I. A. (1964), 5.1.4, 6.5.3 (generalised exponential
   integral), 4.4.34 (arctangent).
"""
from dataclasses import dataclass

import numpy as np
from scipy import integrate, special

from uq.constants import (KAIMAL_FREQUENCY_DECADES, KAIMAL_FREQUENCY_PER_DECADE,
                          SPECTRAL_PRUNE)
from uq.physics.probe import pulse_radius
from uq.physics.spectraltensor import (KaimalSpectra, MannTensor, WavenumberGrid,
                                       kaimal_exponential_integral, mann_variance_factors,
                                       _log_nodes)

#: Most beams for which the Mann path sums over beam pairs (B^2 work per point) rather than
#: forming each component's vector (9 B per point); the two agree (tested).
_PAIR_BEAMS = 8
#: k1 values of the wavenumber grid evaluated together (memory ~ chunk x n_rho x n_phi x 9
#: complex per gate: 8 x 72 x 48 x 9 x 16 B = 4 MB).
_K1_CHUNK = 8


@dataclass(frozen=True)
class SpectralVariances:
    """The record variances of the spectral path.

    Attributes
    ----------
    lidar : ndarray, shape (n_gates, 3)
        Expected record variance of the reconstructed (u_x, u_y, u_z) at each gate [m2 s-2].
    true : ndarray, shape (3,)
        Expected record variance of (u_x, u_y, u_z) of the field at the reference point,
        sampled once a scan, same high-pass [m2 s-2].
    """

    lidar: np.ndarray
    true: np.ndarray

    def intensity(self, speed):
        """(lidar (n_gates,), true) turbulence intensities sqrt(var_u) / U [1]."""
        return np.sqrt(self.lidar[:, 0]) / speed, float(np.sqrt(self.true[0])) / speed

    def ratio(self):
        """u-variance ratio var_lidar / var_true [1], shape (n_gates,)."""
        return self.lidar[:, 0] / self.true[0]


# --- filters ---------------------------------------------------------------------------------

def record_scans(scan_period, record_duration):
    """Scans N = floor(T_rec / T_s) in a record (at least 1); 0 means no high-pass (inf)."""
    if not np.isfinite(record_duration):
        return 0
    return max(1, int(np.floor(record_duration / scan_period + 1e-9)))


def record_filter(frequency, scan_period, record_duration):
    """``1 - |D_N(f)|^2`` [1], Eq. (3): the variance about the record's mean of a series
    sampled every `scan_period` [s] over `record_duration` [s] (inf: 1)."""
    f = np.abs(np.asarray(frequency, dtype=float))
    n = record_scans(scan_period, record_duration)
    if n == 0:
        return np.ones_like(f)
    x = np.pi * f * scan_period
    denominator = n * np.sin(x)
    small = np.abs(denominator) < 1e-12 * n
    ratio = np.where(small, 1.0, np.sin(n * x) / np.where(small, 1.0, denominator))
    return 1.0 - ratio ** 2


def pulsed_transfer(kappa, gate_length, pulse_fwhm):
    """Fourier transform of the (uncut) pulsed weighting [1]: ``sinc(kappa Dp / 2)
    exp(-kappa^2 r_p^2 / 4)``, `kappa` [rad m-1], lengths [m] (Eq. 1 of
    :mod:`uq.physics.probe`: a rectangle convolved with a Gaussian of variance r_p^2/2)."""
    kappa = np.asarray(kappa, dtype=float)
    r_p = pulse_radius(pulse_fwhm)
    return np.sinc(kappa * gate_length / (2 * np.pi)) * np.exp(-(kappa * r_p) ** 2 / 4)


def lorentzian_transfer(kappa, rayleigh):
    """Fourier transform ``exp(-z_R |kappa|)`` [1] of the uncut Lorentzian of half width
    `rayleigh` z_R [m] (a CW lidar's weighting without truncation)."""
    return np.exp(-rayleigh * np.abs(np.asarray(kappa, dtype=float)))


def quadrature_transfer(geometry, points=4097):
    """``What_g(kappa) = sum_i w_gi cos(kappa s_i)`` from the geometry's probe quadrature
    (symmetric nodes: real and even), as a function of an array kappa [rad m-1] ->
    (n_gates, *kappa.shape); tabulated once on ``|kappa| <= kappa_max`` and interpolated.

    An n-node Gauss-Legendre rule on ``[-h, h]`` resolves ``cos(kappa s)`` only for
    ``kappa h <~ n``: beyond ``kappa_max = n / (2 h)`` the transform is set to 0. The rule
    that integrates a wind profile (``lidar.probe`` picks 10-20 nodes) stops well before
    the weighting's transform has decayed (a 16-node pulsed rule: kappa_max = 0.1 rad/m,
    where What = 0.5), so this default underestimates what a probe passes; give the
    weighting's own transform (:func:`probe_transfer_for`) wherever the probe is known.
    A single node (a point probe) is 1 everywhere."""
    offsets = np.asarray(geometry.probe_offsets, dtype=float)
    weights = np.asarray(geometry.probe_weights, dtype=float)
    if offsets.size == 1:
        total = np.sum(weights, axis=1)
        return lambda kappa: total.reshape((-1,) + (1,) * np.ndim(kappa)) * np.cos(
            np.asarray(kappa)[None] * offsets[0])
    limit = offsets.size / (np.max(offsets) - np.min(offsets))
    kappa_table = np.linspace(0.0, limit, points)
    table = weights @ np.cos(np.multiply.outer(offsets, kappa_table))        # (G, points)

    def transfer(kappa):
        a = np.abs(np.asarray(kappa, dtype=float))
        return np.stack([np.interp(a, kappa_table, row, right=0.0) for row in table])
    return transfer


def cut_lorentzian_transfer(kappa, rayleigh, half_length, nodes=1024):
    """Fourier transform [1] of the CW weighting cut at ``|s| <= half_length`` (Eq. 3 of
    :mod:`uq.physics.probe`): with ``s = z_R tan(theta)``, ``What = (1 / 2a) int_{-a}^{a}
    cos(kappa z_R tan theta) d theta``, ``a = atan(L / z_R)`` (Gauss-Legendre in theta;
    tested against :func:`lorentzian_transfer` as the cut goes to infinity)."""
    x, w = special.roots_legendre(nodes)       # Newton iteration: O(n), unlike leggauss
    a = np.arctan(half_length / rayleigh)
    s = rayleigh * np.tan(a * x)
    return np.cos(np.multiply.outer(np.asarray(kappa, dtype=float), s)) @ (w / 2.0)


def probe_transfer_for(probe, focus, points=4097):
    """The Fourier transform of a ``uq`` probe's weighting at each gate, for
    :func:`mann_lidar_variances`: ``kappa -> (n_gates, *kappa.shape)`` [1].

    Parameters
    ----------
    probe : uq.physics.probe.PulsedProbe, ContinuousWaveProbe or None
        None: a point probe (1 everywhere).
    focus : array_like, shape (n_gates,)
        Slant distance F of each gate [m] (a CW lidar's focus; the pulsed weighting is
        taken uncut: the cut at the lens matters only within a gate length of it).
    """
    focus = np.atleast_1d(np.asarray(focus, dtype=float))
    if probe is None:
        return lambda kappa: np.ones((len(focus),) + np.shape(kappa))
    if probe.kind == "pulsed":
        return lambda kappa: np.broadcast_to(
            pulsed_transfer(kappa, probe.gate_length, probe.pulse_fwhm)[None],
            (len(focus),) + np.shape(kappa))
    rayleigh = probe.rayleigh(focus)
    half = probe.half_length(focus)
    limit = 40.0 / np.min(rayleigh)               # exp(-40): nothing passes beyond
    table_k = np.linspace(0.0, limit, points)
    table = np.stack([cut_lorentzian_transfer(table_k, z, h) for z, h in zip(rayleigh, half)])

    def transfer(kappa):
        a = np.abs(np.asarray(kappa, dtype=float))
        return np.stack([np.interp(a, table_k, row, right=0.0) for row in table])
    return transfer


# --- the Mann path ---------------------------------------------------------------------------

def mann_lidar_variances(geometry, tensor, probe_transfer=None, grid=None):
    """Expected record variances of the reconstructed wind and of the point field, Eq. (3).

    Parameters
    ----------
    geometry : uq.physics.scangeometry.ScanGeometry
        The scan (mean-wind frame); its speed advects the field, its scan period and
        record duration set the high-pass.
    tensor : uq.physics.spectraltensor.MannTensor
        The spectral tensor (alpha eps^(2/3) sets the scale: see
        :func:`~uq.physics.spectraltensor.mann_tensor_for_intensity`).
    probe_transfer : callable, optional
        ``kappa [rad m-1] -> (n_gates, *kappa.shape)`` [1], the Fourier transform of each
        gate's range weighting (:func:`pulsed_transfer`, :func:`lorentzian_transfer`);
        default the geometry's probe quadrature (:func:`quadrature_transfer`).
    grid : WavenumberGrid, optional
        Default: the standard grid at the tensor's L.

    Returns
    -------
    SpectralVariances
    """
    grid = grid or WavenumberGrid(tensor.length_scale)
    transfer = probe_transfer or quadrature_transfer(geometry)
    directions = np.asarray(geometry.directions, dtype=float)               # (B, 3)
    centres = np.asarray(geometry.gate_centres, dtype=float)                # (B, G, 3)
    times = np.asarray(geometry.times, dtype=float)
    reconstruction = np.asarray(geometry.reconstruction, dtype=float)       # (G, 3, B)
    k1_all, w1_all = grid.k1()
    speed = geometry.speed
    highpass = record_filter(k1_all * speed / (2 * np.pi), geometry.scan_period,
                             geometry.record_duration)
    # a few beams: sum over beam pairs (B^2 per point, tensor projections shared by the
    # gates); many (a VAD's lines of sight): the vector G_c per gate (9 B per point)
    by_pairs = geometry.n_beams <= _PAIR_BEAMS
    pairs = np.zeros((geometry.n_gates, geometry.n_beams, geometry.n_beams))
    direct = np.zeros((geometry.n_gates, 3))
    # steering[g, b, 3c + j] = R_gcb n_bj
    steering = np.einsum("gcb,bj->gbcj", reconstruction, directions).reshape(
        geometry.n_gates, geometry.n_beams, 9)
    true = np.zeros(3)
    trace = tensor.alpha_epsilon * tensor.length_scale ** (2 / 3) * sum(
        mann_variance_factors(tensor.anisotropy))
    for start in range(0, len(k1_all), _K1_CHUNK):
        k1 = k1_all[start:start + _K1_CHUNK]
        k2, k3, w23 = grid.cross_section(k1)
        k1b = np.broadcast_to(k1[:, None], k2.shape)
        weight = (w23 * (w1_all * highpass)[start:start + _K1_CHUNK, None]).ravel()
        distortion = [np.ravel(v) for v in _flatten(tensor.distortion(k1b, k2, k3))]
        diagonal = weight[:, None] * _projected(np.eye(3), np.eye(3), distortion)  # (P, 3)
        true += diagonal.sum(axis=0)
        # points whose weighted trace of Phi is below SPECTRAL_PRUNE of the field's total
        # trace are left out of the lidar's sum: each point adds at most (sum_b |R_gcb|)^2
        # w tr(Phi) to var_c (|n_b Phi n_d| <= the largest eigenvalue <= the trace), and
        # the points left out hold 3e-6 of the trace (IEC Mann field, measured)
        keep = diagonal.sum(axis=1) > SPECTRAL_PRUNE * trace
        weight, distortion = weight[keep], [v[keep] for v in distortion]
        k1b, k2, k3 = k1b.ravel()[keep], k2.ravel()[keep], k3.ravel()[keep]
        kvec = np.stack([k1b, k2, k3], axis=-1)                          # (P, 3)
        dwell = np.sinc(kvec[:, 0] * speed * geometry.dwell / (2 * np.pi))
        probe = transfer(kvec @ directions.T) * dwell[:, None]            # (G, P, B)
        delay = np.outer(kvec[:, 0] * speed, times)                      # (P, B)
        if by_pairs:
            beam_pairs = weight[:, None, None] * _projected(directions, directions, distortion,
                                                            pairs=True)  # (P, B, B)
        for g in range(geometry.n_gates):
            angle = kvec @ centres[:, g].T - delay
            real, imaginary = probe[g] * np.cos(angle), probe[g] * np.sin(angle)
            if by_pairs:       # Re(T_b T_d*) = X_b X_d + Y_b Y_d, Eq. (1)
                pairs[g] += (np.einsum("pbd,pb,pd->bd", beam_pairs, real, real)
                             + np.einsum("pbd,pb,pd->bd", beam_pairs, imaginary, imaginary))
            else:              # G_c = sum_b R_gcb n_b T_b, Eq. (2), then G Phi G^H
                vectors = ((real + 1j * imaginary) @ steering[g]).reshape(-1, 3, 3)
                direct[g] += weight @ _form(vectors, *_flat(distortion))
    # Eq. (2)-(3): var_c = sum_bd R_gcb R_gcd <(n_b . dZ T_b)(n_d . dZ T_d)*>
    lidar = np.einsum("gcb,gbd,gcd->gc", reconstruction, pairs, reconstruction) + direct
    return SpectralVariances(lidar, true)


def _flatten(distortion):
    """(factor, k0 components, zetas) of MannTensor.distortion as a flat list of arrays."""
    factor, k0, zetas = distortion
    return [factor, *k0, *zetas]


def _flat(distortion):
    """The (factor, k0, zetas) arguments of :func:`_form` from a flattened distortion,
    each (P, 1) to broadcast over the components."""
    factor, k01, k02, k03, zeta1, zeta2, ratio = (v[:, None] for v in distortion)
    return factor, (k01, k02, k03), (zeta1, zeta2, ratio)


def _form(vectors, factor, k0, zetas):
    """``g Phi g^H`` [m5 s-2] for complex rows g (..., 3): with ``q = g A``,
    ``E(k0)/(4 pi k0^4) (k0^2 |q|^2 - |q . k0|^2)`` (MannTensor.quadratic_form, unpacked)."""
    zeta1, zeta2, ratio = zetas
    g0, g1, g2 = (vectors[..., j] for j in range(3))
    q2 = zeta1 * g0 + zeta2 * g1 + ratio * g2
    k0sq = k0[0] ** 2 + k0[1] ** 2 + k0[2] ** 2
    norm = np.abs(g0) ** 2 + np.abs(g1) ** 2 + np.abs(q2) ** 2
    along = np.abs(g0 * k0[0] + g1 * k0[1] + q2 * k0[2]) ** 2
    return factor * (k0sq * norm - along)


def _projected(left, right, distortion, pairs=False):
    """``l Phi(k) r^T`` for rows of `left` and `right` (each (B, 3)) at every point: the
    diagonal (P, B) or, with `pairs`, every pair (P, B, B) [m5 s-2]. With ``m = n A``,
    ``n Phi n'^T = E(k0)/(4 pi k0^4) (k0^2 m . m' - (m . k0)(m' . k0))`` (Eq. 2 of
    :mod:`uq.physics.spectraltensor`)."""
    factor, k01, k02, k03, zeta1, zeta2, ratio = distortion

    def rows(n):
        third = zeta1[:, None] * n[:, 0] + zeta2[:, None] * n[:, 1] + ratio[:, None] * n[:, 2]
        m = np.stack([np.broadcast_to(n[:, 0], third.shape),
                      np.broadcast_to(n[:, 1], third.shape), third], axis=-1)  # (P, B, 3)
        return m, m[..., 0] * k01[:, None] + m[..., 1] * k02[:, None] + m[..., 2] * k03[:, None]
    (ml, al), (mr, ar) = rows(np.asarray(left, float)), rows(np.asarray(right, float))
    k0sq = (k01 ** 2 + k02 ** 2 + k03 ** 2)
    if pairs:
        dot = np.einsum("pbj,pdj->pbd", ml, mr)
        return factor[:, None, None] * (k0sq[:, None, None] * dot - al[:, :, None] * ar[:, None, :])
    return factor[:, None] * (k0sq[:, None] * np.sum(ml * mr, axis=-1) - al * ar)


# --- the Kaimal path -------------------------------------------------------------------------

def kaimal_lidar_variances(geometry, spectra, frequency_decades=KAIMAL_FREQUENCY_DECADES,
                           per_decade=KAIMAL_FREQUENCY_PER_DECADE):
    """Expected record variances for IEC Kaimal spectra and coherence, Eq. (4).

    Parameters
    ----------
    geometry : ScanGeometry
    spectra : uq.physics.spectraltensor.KaimalSpectra
    frequency_decades : tuple
        Decades of f L_u / U of the frequency quadrature.
    per_decade : int
        Gauss-Legendre nodes per decade.

    Returns
    -------
    SpectralVariances
    """
    u, w = _log_nodes(frequency_decades, per_decade)
    f = 10.0 ** u * geometry.speed / spectra.lengths[0]
    df = w * np.log(10.0) * f
    common = df * record_filter(f, geometry.scan_period, geometry.record_duration)
    spectrum = np.stack([spectra.spectrum(j, f) for j in range(3)])          # (3, F)
    true = spectrum @ common
    common = common * np.sinc(f * geometry.dwell) ** 2
    points = geometry.probe_points()                                          # (B, G, n, 3)
    directions = np.asarray(geometry.directions, dtype=float)
    n_nodes = points.shape[2]
    lidar = np.zeros((geometry.n_gates, 3))
    for g in range(geometry.n_gates):
        # only the nodes gate g weights: where the gates' nodes sit side by side (their
        # foci differ) the others' weights are zero, and their pairs add nothing
        kept = np.tile(np.asarray(geometry.probe_weights)[g] != 0, directions.shape[0])
        p = points[:, g].reshape(-1, 3)[kept]                                # (P, 3)
        tau = (np.repeat(np.asarray(geometry.times, float), n_nodes)[kept]
               - p[:, 0] / geometry.speed)
        across = np.hypot(p[:, None, 1] - p[None, :, 1], p[:, None, 2] - p[None, :, 2])
        lag = tau[:, None] - tau[None, :]
        # a[c, p, j] = R_gcb n_bj w_gi
        a = np.einsum("cb,bj,i->cbij", np.asarray(geometry.reconstruction)[g], directions,
                      np.asarray(geometry.probe_weights)[g]).reshape(3, -1, 3)[:, kept]
        for k, fk in enumerate(f):
            kernel = spectra.coherence(across, fk) * np.cos(2 * np.pi * fk * lag)
            pair = np.einsum("cpj,pq,cqj->cj", a, kernel, a)                # (3, 3)
            lidar[g] += pair @ (spectrum[:, k] * common[k])
    return SpectralVariances(lidar, true)


def lidar_variances(geometry, model, probe_transfer=None):
    """The spectral path for either model (:func:`mann_lidar_variances` for a
    :class:`MannTensor`, :func:`kaimal_lidar_variances` for :class:`KaimalSpectra`)."""
    if isinstance(model, MannTensor):
        return mann_lidar_variances(geometry, model, probe_transfer)
    if isinstance(model, KaimalSpectra):
        return kaimal_lidar_variances(geometry, model)
    raise TypeError(f"lidar_variances: unknown turbulence model {type(model).__name__}")


# --- motion and closed forms ----------------------------------------------------------------

def harmonic_motion_variance(geometry, velocity_amplitude, period):
    """Expected record variance of each reconstructed component [m2 s-2] from a harmonic
    platform velocity, Eq. (7), shape (n_gates, 3); uncorrelated with the turbulence.

    Parameters
    ----------
    geometry : ScanGeometry
    velocity_amplitude : array_like, shape (3,)
        Complex amplitude A of the platform velocity in the mean-wind frame [m s-1] (a
        surge of amplitude a [m] along x: ``(a omega, 0, 0)``).
    period : float
        Period T of the motion [s].
    """
    omega = 2 * np.pi / period
    along = np.asarray(geometry.directions, float) @ np.asarray(velocity_amplitude)  # (B,)
    c = np.einsum("gcb,b->gc", np.asarray(geometry.reconstruction),
                  along * np.exp(1j * omega * np.asarray(geometry.times)))
    return np.abs(c) ** 2 / 2 * record_filter(1.0 / period, geometry.scan_period,
                                               geometry.record_duration)


def dbs_surge_variance(amplitude, period, beam_delay):
    """Record variance [m2 s-2] of a DBS u from a surge of `amplitude` a [m] and `period`
    T [s] along the wind, u from the two beams in the wind's plane `beam_delay` [s] apart
    (Eq. 7 with ``|C| = a omega |cos(omega dt / 2)|``; long record)."""
    omega = 2 * np.pi / period
    return (amplitude * omega * np.cos(omega * beam_delay / 2)) ** 2 / 2


def vad_surge_variance(amplitude, period, scan_period):
    """Record variance [m2 s-2] of a VAD u from a surge of `amplitude` a [m], `period` T
    [s] along the wind; one revolution of `scan_period` T_s [s] per scan, Eq. (8)."""
    omega = 2 * np.pi / period
    x = np.pi * scan_period / period
    factor = np.sin(x) * (1 / x + x / (x * x - 4 * np.pi ** 2))
    return (amplitude * omega * factor) ** 2 / 2


def staring_cw_kaimal_ratio(rayleigh, length_u):
    """``F = (2/3) e^b E_{5/3}(b)``, ``b = 2 pi Gamma_CW / (3 L)``, Eq. (5): the u-variance
    ratio [1] of a CW beam staring along the wind (uncut Lorentzian of half width
    `rayleigh` [m]) in a Kaimal field of u length `length_u` [m] (no high-pass)."""
    b = 2 * np.pi * rayleigh / (3 * length_u)
    return 2.0 / 3.0 * np.exp(b) * kaimal_exponential_integral(5.0 / 3.0, b)


def kaimal_block_average_ratio(block, speed, length_u):
    """``var(block mean) / sigma_u^2`` [1] of a Kaimal u averaged over `block` T_s [s] at
    `speed` [m s-1], u length `length_u` [m], Eq. (6) (no high-pass)."""
    c = np.pi * block * speed / (6 * length_u)

    def integrand(s):
        return s ** (2 / 3) * np.exp(-s) * (c * np.arctan2(2 * c, s)
                                            - s / 4 * np.log1p(4 * c * c / (s * s)))
    value = integrate.quad(integrand, 0, np.inf, limit=200, epsabs=0, epsrel=1e-11)[0]
    return 2 / (3 * c * c * special.gamma(5 / 3)) * value
