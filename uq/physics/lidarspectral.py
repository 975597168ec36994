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
transforms; for a CW lidar's Lorentzian cut at the lens alone the closed form of
:func:`lens_cut_lorentzian_transfer`, complex as the cut is one-sided) and ``sinc x =
sin x / x``.
The reconstruction R (n_gates, 3, n_beams) gives component c of scan m (start m T_s)::

    u_c[m] = int exp(-i k1 U m T_s) G_c(k) . dZ(k),   G_cj = sum_b R_gcb n_bj T_bg   (2)

so ``<u_c[m] u_c[m']> = int |...|`` and the record of N = floor(T_rec / T_s) scans,
reduced to its variance about its own mean, ``s^2 = (1/N) sum (u_c[m] - mean)^2``, has::

    <s^2> = int G_c Phi G_c^H (1 - |D_N(f)|^2) d^3k,   f = k1 U / (2 pi)          (3)
    D_N(f) = (1/N) sum_m exp(2 pi i f m T_s),  |D_N|^2 = sin^2(pi f N T_s) / (N sin(pi f T_s))^2

exactly (``<mean^2> = int ... |D_N|^2``): |D_N|^2 peaks at every multiple of the scan
rate, the scans' aliasing, which removes 1/N of the variance above it. N = 1 gives 0; ``T_rec = inf`` no
high-pass. The true point variance over the record is (3) with ``G = e_c`` at r = 0 and the
same scan times (the reference point sampled once a scan). The horizontal speed, linearised
for the wind along x, has ``var(Vh) = var(u_x) + O(sigma^4 / U^2)``.

The integrand of (3) is real (Phi is real symmetric, ``T(-k) = T(k)*``) and even in k, so
it is integrated over k1 > 0 and doubled.

Numerics, and the error each result carries
-------------------------------------------
*A few beams* (at most ``PAIR_BEAMS``: a DBS, a nacelle lidar). Eq. (3) is a sum over beam
pairs, ``var_c = sum_bd R_gcb R_gcd C_bd``, and each ``C_bd`` integrates a smooth function
(``n_b Phi n_d``, the probes' transfers, the dwell) times ``exp(i k . delta_bd)``, ``delta_bd
= r_bg - r_dg - U (t_b - t_d) e_x``. Two beams of a 30 deg DBS 200 m up are 231 m apart,
and no grid fixed in advance resolves ``cos(k1 231 m)`` (the former log-polar grid read
the u-variance ratio 1.7-1.9 % low there). Here k is on a Cartesian product of composite
Gauss-Legendre rules (:mod:`uq.physics.spectralquadrature`: panels geometric in |k_i|,
``per_decade`` a decade, ``order`` nodes each, k1 from 0 and k2, k3 of both signs, from 0
to ``10^3 / L``, or ``10^6 / L`` for a probe that passes every wavenumber), and each
pair's phase is integrated exactly against the smooth part's interpolating polynomial
(Filon weights in k2 and k3, then in k1 together with the record's high-pass,
:func:`~uq.physics.spectralquadrature.record_weights`): the error no longer grows with
the separation or the record's length. The (k2, k3) sums run in a compiled kernel
(:mod:`uq.physics.spectralkernels`).

*Many beams* (a VAD's lines of sight): the vector ``G_c`` per point on the log-polar grid
of :class:`~uq.physics.spectraltensor.WavenumberGrid` (log k1, and per k1 log-polar (k2,
k3) about ``sqrt(k1^2 + L^-2)``), its phases evaluated at the nodes; a full circle of
beams averages the phases out (measured: a CW VAD at 40-100 m changes by < 2e-3 when the
grid's nodes are doubled in any direction).

*The field at the reference point* (``true``): the 1-D spectra ``integral Phi_ii dk2
dk3`` on the log-polar cross-section at the nodes of a composite rule in k1 from 0 to
``10^6 / L``, integrated with the record's high-pass weights.

*Error*: every variance is computed twice, on the rules above and on the same panels with
two nodes fewer in every direction (``SpectralVariances.lidar_error``, ``true_error``: the
difference, one refinement); as the finer rule converges much faster, the difference
overstates its error (measured for a pulsed DBS at 40-300 m: 3-5 times the change from
two more nodes). Where a ratio's estimated relative error exceeds
:data:`~uq.constants.SPECTRAL_TOLERANCE` the rules are refined (more nodes, then more
panels), up to ``SPECTRAL_REFINEMENTS`` times; a result still above it has ``converged``
False (a record-mode run says so on stderr and in its variables' attributes).

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
import functools
from dataclasses import dataclass

import numpy as np
from scipy import integrate, special

from uq.constants import (KAIMAL_FREQUENCY_DECADES, SPECTRAL_REFINEMENTS,
                          SPECTRAL_TOLERANCE)
from uq.physics.probe import pulse_radius
from uq.physics.spectralquadrature import (PanelRule, geometric_edges, record_scans,
                                           record_weights, mean_window, symmetric_edges)
from uq.physics.spectraltensor import (KaimalSpectra, MannTensor, WavenumberGrid,
                                       kaimal_exponential_integral)

#: Most beams for which the Mann path sums over beam pairs with Filon weights (B (B + 1)
#: / 2 pairs per point); beyond, the vectors G_c on the log-polar grid (module docstring).
PAIR_BEAMS = 8
#: Least relative error the beam-pair sums claim [1]: the difference from two nodes
#: fewer can vanish by chance where it changes sign (a pulsed DBS's w at 200 m: 2e-5 of
#: it, where two more nodes moved it by 1.3e-4); the refinements of the convergence study
#: moved the ratios by at most 3e-4 (tests/physics/test_lidarspectral.py).
PAIR_ERROR_FLOOR = 5e-4
#: k1 values of the log-polar grid evaluated together (memory ~ chunk x n_rho x n_phi x 9
#: complex per gate: 8 x 72 x 48 x 9 x 16 B = 4 MB).
_K1_CHUNK = 8
#: Nodes of a tabulated transfer function (:class:`ProbeTransfer`) on [0, reach] [1]:
#: linear interpolation between them is within ~1e-6 of a transfer that varies on
#: reach / 20 (the pulsed Gaussian; reach = 8.6 / r_p).
TRANSFER_TABLE_NODES = 2**14 + 1
#: |transfer| below which a table ends (its tail beyond is 0) [1]: its square, 1e-16,
#: is what a beam pair keeps of the tensor there.
TRANSFER_FLOOR = 1e-8


@dataclass(frozen=True)
class SpectralVariances:
    """The record variances of the spectral path, with their numerical errors.

    Attributes
    ----------
    lidar : ndarray, shape (n_gates, 3)
        Expected record variance of the reconstructed (u_x, u_y, u_z) at each gate [m2 s-2].
    true : ndarray, shape (3,)
        Expected record variance of (u_x, u_y, u_z) of the field at the reference point,
        sampled once a scan, same high-pass [m2 s-2].
    lidar_error, true_error : ndarray, shapes (n_gates, 3), (3,)
        Estimates of their quadrature errors [m2 s-2] (module docstring: the difference
        from one refinement, an overstatement).
    converged : bool
        Whether every ratio's estimated relative error is within the tolerance it was
        computed to.
    """

    lidar: np.ndarray
    true: np.ndarray
    lidar_error: np.ndarray = None
    true_error: np.ndarray = None
    converged: bool = True

    def intensity(self, speed):
        """(lidar (n_gates,), true) turbulence intensities sqrt(var_u) / U [1]."""
        return np.sqrt(self.lidar[:, 0]) / speed, float(np.sqrt(self.true[0])) / speed

    def ratio(self):
        """u-variance ratio var_lidar / var_true [1], shape (n_gates,)."""
        return self.lidar[:, 0] / self.true[0]

    def ratios(self):
        """The lidar's (u, v, w) variance ratios to the field's at the reference point
        [1], shape (n_gates, 3): u along the mean wind, v lateral, w vertical."""
        return self.lidar / self.true

    def ratio_errors(self):
        """Estimated errors of :meth:`ratios` [1], shape (n_gates, 3): ``|r| (e_lidar /
        |lidar| + e_true / true)`` (zero where no error was estimated)."""
        lidar_error = np.zeros_like(self.lidar) if self.lidar_error is None \
            else self.lidar_error
        true_error = np.zeros_like(self.true) if self.true_error is None else self.true_error
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.abs(lidar_error / self.true) + np.abs(self.ratios()) * true_error / self.true


# --- filters and transfer functions ----------------------------------------------------------

def record_filter(frequency, scan_period, record_duration):
    """``1 - |D_N(f)|^2`` [1], Eq. (3): the variance about the record's mean of a series
    sampled every `scan_period` [s] over `record_duration` [s] (inf: 1)."""
    n = record_scans(scan_period, record_duration)
    if n == 0:
        return np.ones_like(np.asarray(frequency, dtype=float))
    return 1.0 - mean_window(frequency, scan_period, n)


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


def _lorentzian_tail(kappa, rayleigh, start):
    """``I = integral_a^inf (z / pi) / (z^2 + s^2) exp(-i kappa s) ds`` [1], a = `start`
    [m], z = `rayleigh` [m]: with ``z / (z^2 + s^2) = (1 / 2i) (1 / (s - iz) - 1 / (s +
    iz))`` and ``integral_a^inf exp(-i kappa s) / (s - c) ds = exp(-i kappa c) E1(i kappa
    (a - c))`` (kappa > 0; the path turned onto the imaginary axis)::

        I = exp(-i kappa a) / (2 pi i) [g(kappa z + i kappa a) - g(-kappa z + i kappa a)],
        g(w) = exp(w) E1(w)

    conjugate for kappa < 0; ``(1/pi) (pi/2 - atan(a / z))`` (the tail's mass) at 0."""
    kappa = np.asarray(kappa, dtype=float)
    k = np.abs(kappa)
    mass = (np.pi / 2 - np.arctan(start / rayleigh)) / np.pi
    with np.errstate(all="ignore"):
        w1 = k * rayleigh + 1j * k * start
        w2 = -k * rayleigh + 1j * k * start
        value = np.exp(-1j * k * start) / (2j * np.pi) * (
            np.exp(w1) * special.exp1(w1) - np.exp(w2) * special.exp1(w2))
    value = np.where(k == 0, mass, value)
    return np.where(kappa < 0, np.conj(value), value)


def lens_cut_lorentzian_transfer(kappa, rayleigh, focus, far=np.inf):
    """Fourier transform ``integral W(s) exp(i kappa s) ds`` [1] of a CW lidar's weighting
    cut at the lens alone: the Lorentzian ``(z_R / pi) / (z_R^2 + s^2)`` on ``s >= -F``
    (there is no beam behind the lens), normalised there (its mass ``1/2 + atan(F /
    z_R) / pi``); complex (the cut is one-sided).

    ``= (exp(-z_R |kappa|) - I(kappa; F) - conj I(kappa; far)) / mass`` with ``I``
    the transform of a far tail (:func:`_lorentzian_tail`): `far` [m] < inf drops the
    weighting beyond ``s = far`` without renormalising it (the records' probe
    quadrature, :func:`uq.pipeline.turbulencesection.probe_quadrature`, which reads the
    field only that far: the tail's weight is then a field of zero fluctuation).

    Parameters
    ----------
    kappa : array_like
        Wavenumber along the beam [rad m-1].
    rayleigh, focus : float
        z_R and the focus distance F from the lens [m].
    far : float
        Where the weighting ends beyond the focus [m] (inf: nowhere).
    """
    mass = 0.5 + np.arctan(focus / rayleigh) / np.pi
    value = lorentzian_transfer(kappa, rayleigh) - _lorentzian_tail(kappa, rayleigh, focus)
    if np.isfinite(far):
        value = value - np.conj(_lorentzian_tail(kappa, rayleigh, far))
    return value / mass


def cut_lorentzian_transfer(kappa, rayleigh, half_length, nodes=1024):
    """Fourier transform [1] of the CW weighting cut symmetrically at ``|s| <= half_length``
    (Eq. 3 of :mod:`uq.physics.probe`, the per-scan wind profile's weighting): with ``s =
    z_R tan(theta)``, ``What = (1 / 2a) int_{-a}^{a} cos(kappa z_R tan theta) d theta``, ``a
    = atan(L / z_R)`` (Gauss-Legendre in theta; tested against
    :func:`lorentzian_transfer` as the cut goes to infinity)."""
    x, w = special.roots_legendre(nodes)       # Newton iteration: O(n), unlike leggauss
    a = np.arctan(half_length / rayleigh)
    s = rayleigh * np.tan(a * x)
    return np.cos(np.multiply.outer(np.asarray(kappa, dtype=float), s)) @ (w / 2.0)


@dataclass(frozen=True)
class ProbeTransfer:
    """Each gate's probe transfer ``What_g(kappa)`` [1], tabulated on ``|kappa| = t step``
    (``What(-kappa) = What(kappa)*``: the weighting is real), linear between nodes,
    `tail` beyond the table. Callable: ``transfer(kappa) -> (n_gates, *kappa.shape)``.

    Attributes
    ----------
    table : ndarray, complex, shape (n_gates, n)
    step : float
        [rad m-1].
    tail : float
        The transfer beyond the table (0: decayed; 1: a point probe) [1].
    """

    table: np.ndarray
    step: float
    tail: float = 0.0

    @property
    def n_gates(self):
        return self.table.shape[0]

    @property
    def reach(self):
        """The table's last |kappa| [rad m-1] (inf for a point probe's table of ones)."""
        return np.inf if self.tail != 0.0 else self.step * (self.table.shape[1] - 1)

    def __call__(self, kappa):
        kappa = np.asarray(kappa, dtype=float)
        a = np.abs(kappa).ravel()
        nodes = self.step * np.arange(self.table.shape[1])
        rows = [np.interp(a, nodes, row.real, right=self.tail)
                + 1j * np.interp(a, nodes, row.imag, right=0.0) for row in self.table]
        out = np.stack(rows).reshape((self.n_gates,) + kappa.shape)
        out = np.where(kappa < 0, np.conj(out), out)
        return out.real if not np.iscomplexobj(self.table) or not np.any(out.imag) else out


def point_transfer(n_gates):
    """The transfer of a point probe at each of `n_gates` gates (1 everywhere)."""
    return ProbeTransfer(np.ones((n_gates, 2), dtype=complex), 1.0, tail=1.0)


def tabulate_transfer(function, n_gates, reach, nodes=TRANSFER_TABLE_NODES):
    """A :class:`ProbeTransfer` of `function` (``kappa -> (n_gates, *kappa.shape)``) on
    ``[0, reach]`` [rad m-1], `nodes` nodes, 0 beyond."""
    kappa = np.linspace(0.0, reach, nodes)
    table = np.asarray(function(kappa), dtype=complex).reshape(n_gates, nodes)
    return ProbeTransfer(table, reach / (nodes - 1), tail=0.0)


def transfer_reach(function, n_gates, start, floor=TRANSFER_FLOOR):
    """The |kappa| [rad m-1] beyond which `function`'s magnitude stays below `floor` for
    every gate (looked for on a geometric grid from `start`, doubling up to 1e6 start);
    inf if it never falls."""
    kappa = start * np.geomspace(1.0, 1e6, 241)
    values = np.abs(np.asarray(function(kappa))).reshape(n_gates, -1).max(axis=0)
    above = np.flatnonzero(values >= floor)
    if above.size and above[-1] == kappa.size - 1:
        return np.inf
    return float(kappa[above[-1] + 1]) if above.size else float(kappa[0])


def as_transfer(transfer, n_gates, length_scale):
    """`transfer` as a :class:`ProbeTransfer`: itself, or a callable tabulated up to its
    reach (:func:`transfer_reach` from 1e-3 / L); a callable that never decays is taken
    for a point probe's (1 everywhere) if it is 1 at 0, else refused."""
    if isinstance(transfer, ProbeTransfer):
        return transfer
    reach = transfer_reach(transfer, n_gates, 1e-3 / length_scale)
    if np.isfinite(reach):
        return tabulate_transfer(transfer, n_gates, reach)
    far = np.asarray(transfer(np.array([0.0, 1e3 / length_scale])))
    if np.allclose(far, 1.0):
        return point_transfer(n_gates)
    raise ValueError("lidarspectral: a probe transfer that does not decay must be 1 "
                     "everywhere (a point probe)")


def quadrature_transfer(geometry, points=4097):
    """``What_g(kappa) = sum_i w_gi cos(kappa s_i)`` from the geometry's probe quadrature
    (symmetric nodes: real and even), as a :class:`ProbeTransfer`.

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
        return point_transfer(geometry.n_gates)
    limit = offsets.size / (np.max(offsets) - np.min(offsets))
    kappa_table = np.linspace(0.0, limit, points)
    table = weights @ np.exp(1j * np.multiply.outer(offsets, kappa_table))   # (G, points)
    return ProbeTransfer(table, limit / (points - 1), tail=0.0)


def probe_transfer_for(probe, focus):
    """The Fourier transform of a ``uq`` probe's weighting at each gate, for
    :func:`mann_lidar_variances`: a :class:`ProbeTransfer`.

    Parameters
    ----------
    probe : uq.physics.probe.PulsedProbe, ContinuousWaveProbe or None
        None: a point probe (1 everywhere).
    focus : array_like, shape (n_gates,)
        Slant distance F of each gate from the lens [m] (a CW lidar's focus).

    Notes
    -----
    The pulsed weighting is taken uncut (the cut at the lens matters only within a gate
    length of it). The CW weighting is the Lorentzian cut at the lens alone
    (:func:`lens_cut_lorentzian_transfer`): ``lidar.probe.truncation``, the far-tail cut
    that keeps the per-scan wind profile's quadrature finite, is no part of the
    turbulence paths (it moved a CW VAD's u-variance ratio by 4-9 %).
    """
    focus = np.atleast_1d(np.asarray(focus, dtype=float))
    if probe is None:
        return point_transfer(len(focus))
    if probe.kind == "pulsed":
        r_p = pulse_radius(probe.pulse_fwhm)
        reach = 2 * np.sqrt(np.log(1 / TRANSFER_FLOOR)) / r_p        # exp(-k^2 r_p^2/4)
        return tabulate_transfer(lambda k: np.broadcast_to(
            pulsed_transfer(k, probe.gate_length, probe.pulse_fwhm)[None],
            (len(focus),) + np.shape(k)), len(focus), reach)
    rayleigh = np.asarray(probe.rayleigh(focus), dtype=float)
    reach = np.log(1 / TRANSFER_FLOOR) / np.min(rayleigh)            # exp(-z_R kappa)
    return tabulate_transfer(lambda k: np.stack([
        lens_cut_lorentzian_transfer(k, z, f) for z, f in zip(rayleigh, focus)]),
        len(focus), reach)


# --- the Mann path ---------------------------------------------------------------------------

@dataclass(frozen=True)
class PairResolution:
    """The Cartesian rules of the beam-pair sums (module docstring).

    Attributes
    ----------
    per_decade : int
        Panels a decade of |k_i|.
    order : int
        Gauss-Legendre nodes a panel (the error estimate drops two).
    low : float
        kL of the first geometric edge (the panel [0, low / L] before it) [1].
    """

    per_decade: int = 2
    order: int = 6
    low: float = 1e-3

    def refined(self):
        """The next resolution of the refinement: two nodes more a panel, then one panel
        more a decade."""
        if self.order < 8:
            return PairResolution(self.per_decade, self.order + 2, self.low)
        return PairResolution(self.per_decade + 1, self.order, self.low)

    def rules(self, length_scale, high, order=None):
        """(k1, k2, k3) rules up to ``high / L`` (kL) [rad m-1]."""
        order = order or self.order
        edges = geometric_edges(self.low / length_scale, high / length_scale, self.per_decade)
        return (PanelRule(edges, order), PanelRule(symmetric_edges(edges), order),
                PanelRule(symmetric_edges(edges), order))


def mann_lidar_variances(geometry, tensor, probe_transfer=None, resolution=None,
                         tolerance=SPECTRAL_TOLERANCE, refinements=SPECTRAL_REFINEMENTS):
    """Expected record variances of the reconstructed wind and of the point field, Eq. (3),
    with their numerical errors (module docstring).

    Parameters
    ----------
    geometry : uq.physics.scangeometry.ScanGeometry
        The scan (mean-wind frame); its speed advects the field, its scan period and
        record duration set the high-pass.
    tensor : uq.physics.spectraltensor.MannTensor
        The spectral tensor (alpha eps^(2/3) sets the scale: see
        :func:`~uq.physics.spectraltensor.mann_tensor_for_intensity`).
    probe_transfer : ProbeTransfer or callable, optional
        ``kappa [rad m-1] -> (n_gates, *kappa.shape)`` [1], the Fourier transform of each
        gate's range weighting (:func:`probe_transfer_for`); default the geometry's
        probe quadrature (:func:`quadrature_transfer`).
    resolution : PairResolution or WavenumberGrid, optional
        The first rules tried (default :class:`PairResolution` for a few beams, the
        standard :class:`~uq.physics.spectraltensor.WavenumberGrid` for many).
    tolerance : float
        Largest estimated relative error of a ratio before the rules are refined [1].
    refinements : int
        Most refinements.

    Returns
    -------
    SpectralVariances
    """
    transfer = as_transfer(probe_transfer or quadrature_transfer(geometry),
                           geometry.n_gates, tensor.length_scale)
    true, true_error = mann_point_variances(geometry, tensor)
    by_pairs = geometry.n_beams <= PAIR_BEAMS
    level = resolution or (PairResolution() if by_pairs else WavenumberGrid(tensor.length_scale))
    for attempt in range(refinements + 1):
        if by_pairs:
            lidar, error = _pair_variances(geometry, tensor, transfer, level)
        else:
            lidar, error = _vector_variances(geometry, tensor, transfer, level)
        result = SpectralVariances(lidar, true, error, true_error)
        if _relative_error(lidar, error, true) <= tolerance:
            return result
        if attempt < refinements:
            level = level.refined() if by_pairs else _refined_polar(level)
    return SpectralVariances(lidar, true, error, true_error, converged=False)


def _relative_error(lidar, error, true):
    """The largest estimated relative error of the lidar's variances [1]: each against
    itself, or against 5 % of the field's where it is smaller (a component the lidar
    hardly sees, or assumes zero)."""
    return float(np.max(error / np.maximum(np.abs(lidar), 0.05 * true)))


def _pair_variances(geometry, tensor, transfer, resolution):
    """The lidar's variances (n_gates, 3) and their error estimate by beam pairs on the
    Cartesian rules of `resolution` and on the same panels with two nodes fewer.

    The rules reach ``|k_i| <= 10^3 / L`` (a probe's table reaching further: to it, at
    most ``10^6 / L``). A point probe passes every wavenumber: its pairs that are
    colocated (``|delta| <= L / 10^3``: a beam with itself, or beams at one place and
    instant) are the point tensor's 1-D spectra integrated to ``10^6 / L``
    (:func:`_colocated_pairs`), and the others decorrelate beyond ``100 / |delta|``,
    where the rules stop (the tail's cross term is ~ (k L)^(-2/3) / (k |delta|) of the
    variance: < 1e-3)."""
    length = tensor.length_scale
    first, second, delta = _pair_separations(geometry)
    colocated = None
    if np.isfinite(transfer.reach):
        high = max(1e3, min(1e6, transfer.reach * length))
    else:
        distance = np.linalg.norm(delta, axis=-1)                           # (G, P)
        colocated = distance <= length * 1e-3
        apart = distance[~colocated]
        high = 1e3 if apart.size == 0 else float(np.clip(100 * length / apart.min(), 10, 1e3))
    fine = _pair_sum(geometry, tensor, transfer, resolution.rules(length, high), colocated)
    coarse = _pair_sum(geometry, tensor, transfer, resolution.rules(
        length, high, max(1, resolution.order - 2)), colocated, coarse=True)
    return fine, np.maximum(np.abs(fine - coarse), PAIR_ERROR_FLOOR * np.abs(fine))


def _pair_separations(geometry):
    """The beam pairs (b <= d: two index arrays) and their separations ``delta = r_bg -
    r_dg - U (t_b - t_d) e_x`` [m], shape (n_gates, n_pairs, 3) (Eq. (1), Taylor)."""
    centres = np.asarray(geometry.gate_centres, dtype=float)                # (B, G, 3)
    times = np.asarray(geometry.times, dtype=float)
    first, second = np.triu_indices(geometry.n_beams)
    delta = np.moveaxis(centres[first] - centres[second], 0, 1).copy()      # (G, P, 3)
    delta[..., 0] -= geometry.speed * (times[first] - times[second])
    return first, second, delta


def _colocated_pairs(geometry, tensor, first, second, coarse=False):
    """``n_b M n_d`` [m2 s-2] (n_pairs,) with ``M_ij = integral Phi_ij(k) sinc^2(k1 U D / 2)
    (1 - |D_N|^2) d^3k``: a pair of point probes at one place and instant (the point
    tensor's 1-D spectra, :func:`mann_point_variances`'s rule, with the dwell)."""
    directions = np.asarray(geometry.directions, dtype=float)
    matrix = _point_matrix(geometry, tensor, order=4 if coarse else 6,
                           cross_section=(8, 48) if coarse else (12, 64))
    return np.einsum("pi,ij,pj->p", directions[first], matrix, directions[second])


def _pair_sum(geometry, tensor, transfer, rules, colocated=None, coarse=False):
    """``var_c = sum_bd R_gcb R_gcd C_bd`` (n_gates, 3), Eq. (2)-(3), each ``C_bd`` with
    the Filon weights of its separation (module docstring); `colocated` (n_gates,
    n_pairs) pairs of point probes taken from the 1-D spectra instead."""
    rule1, rule2, rule3 = rules
    first, second, delta = _pair_separations(geometry)
    if colocated is None or not colocated.all():
        pairs = _filon_pairs(geometry, tensor, transfer, rules, first, second, delta)
    else:
        pairs = np.zeros(delta.shape[:2])
    if colocated is not None and colocated.any():
        same = _colocated_pairs(geometry, tensor, first, second, coarse)
        pairs = np.where(colocated, same[None, :], pairs)
    matrix = np.zeros((geometry.n_gates, geometry.n_beams, geometry.n_beams))
    matrix[:, first, second] = pairs
    matrix[:, second, first] = pairs
    reconstruction = np.asarray(geometry.reconstruction, dtype=float)
    return np.einsum("gcb,gbd,gcd->gc", reconstruction, matrix, reconstruction)


def spectral_sums():
    """The module whose ``pair_sums`` and ``vector_sums`` the spectral path calls: the
    compiled :mod:`uq.physics.spectralkernels`, or, while a first run after an install
    finds them missing from numba's cache (:func:`uq.compileguard.cached_kernels`), their
    numpy equivalents :mod:`uq.physics.spectralsums` (the same numbers to rounding)."""
    from uq.compileguard import cached_kernels
    from uq.physics import spectralsums
    return cached_kernels("uq.physics.spectralkernels") or spectralsums


def _filon_pairs(geometry, tensor, transfer, rules, first, second, delta):
    """``C_bd`` (n_gates, n_pairs) [m2 s-2]: the kernel's (k2, k3) sums
    (:func:`uq.physics.spectralkernels.pair_sums`) with the record's Filon weights in k1,
    doubled (k1 > 0)."""
    from uq.physics import turbulencebox
    rule1, rule2, rule3 = rules
    w2 = np.ascontiguousarray(rule2.filon(delta[..., 1]))
    w3 = np.ascontiguousarray(rule3.filon(delta[..., 2]))
    sums = np.zeros((geometry.n_gates, first.size, rule1.size), dtype=complex)
    table = turbulencebox._TABLE
    spectral_sums().pair_sums(
        rule1.nodes, rule2.nodes, rule3.nodes, tensor.alpha_epsilon, tensor.length_scale,
        tensor.anisotropy, float(table[0][0]), float(table[0][1] - table[0][0]),
        np.ascontiguousarray(table[1]), np.ascontiguousarray(geometry.directions, dtype=float),
        first.astype(np.int64), second.astype(np.int64),
        np.ascontiguousarray(transfer.table, dtype=complex), float(transfer.step),
        float(transfer.tail), geometry.speed * geometry.dwell, w2, w3, sums)
    weights = record_weights(rule1, delta[..., 0], geometry.speed, geometry.scan_period,
                             geometry.record_duration)                     # (G, P, n1)
    return 2.0 * np.einsum("gpi,gpi->gp", sums, weights).real             # k1 > 0, doubled


def _refined_polar(grid):
    """The log-polar grid with twice the nodes in k1 and the polar radius, 1.5 times the
    angles."""
    return WavenumberGrid(grid.length_scale, grid.k_decades, grid.radius_decades,
                          2 * grid.k1_per_decade, 2 * grid.radius_per_decade,
                          3 * grid.angle_nodes // 2)


def _coarse_polar(grid):
    """The log-polar grid of the error estimate: 2/3 of the k1 nodes, 3/4 of the radial
    nodes and of the angles (the standard grid's (12, 8, 48) -> (8, 6, 36))."""
    return WavenumberGrid(grid.length_scale, grid.k_decades, grid.radius_decades,
                          max(2, 2 * grid.k1_per_decade // 3),
                          max(2, 3 * grid.radius_per_decade // 4),
                          max(8, 3 * grid.angle_nodes // 4))


def _vector_variances(geometry, tensor, transfer, grid):
    """The lidar's variances by the vectors G_c on the log-polar `grid`, and the
    difference from its coarser version (module docstring)."""
    fine = _vector_sum(geometry, tensor, transfer, grid)
    coarse = _vector_sum(geometry, tensor, transfer, _coarse_polar(grid))
    return fine, np.abs(fine - coarse)


def _vector_sum(geometry, tensor, transfer, grid):
    """Eq. (2)-(3) on the log-polar grid: ``var_c = int G_c Phi G_c^H`` with the phases
    at the nodes (:func:`uq.physics.spectralkernels.vector_sums`), a few k1 at a time."""
    from uq.physics import turbulencebox
    sums = spectral_sums()
    k1_all, w1_all = grid.k1()
    highpass = record_filter(k1_all * geometry.speed / (2 * np.pi), geometry.scan_period,
                             geometry.record_duration)
    out = np.zeros((geometry.n_gates, 3))
    table = turbulencebox._TABLE
    centres = np.ascontiguousarray(np.moveaxis(np.asarray(geometry.gate_centres, float), 1, 0))
    for start in range(0, len(k1_all), _K1_CHUNK):
        k1 = k1_all[start:start + _K1_CHUNK]
        k2, k3, w23 = grid.cross_section(k1)
        weight = (w23 * (w1_all * highpass)[start:start + _K1_CHUNK, None]).ravel()
        sums.vector_sums(
            np.ascontiguousarray(np.broadcast_to(k1[:, None], k2.shape).ravel()),
            np.ascontiguousarray(k2.ravel()), np.ascontiguousarray(k3.ravel()), weight,
            tensor.alpha_epsilon, tensor.length_scale, tensor.anisotropy, float(table[0][0]),
            float(table[0][1] - table[0][0]), np.ascontiguousarray(table[1]),
            np.ascontiguousarray(geometry.directions, dtype=float), centres,
            np.ascontiguousarray(geometry.times, dtype=float), float(geometry.speed),
            float(geometry.speed * geometry.dwell),
            np.ascontiguousarray(geometry.reconstruction, dtype=float),
            np.ascontiguousarray(transfer.table, dtype=complex), float(transfer.step),
            float(transfer.tail), out)
    return out


def mann_point_variances(geometry, tensor, per_decade=2, order=6):
    """The field's variances at the reference point over a record of `geometry` (its
    scans' high-pass, sampled once a scan) [m2 s-2], shape (3,), and their error
    estimate (module docstring): the 1-D spectra on a log-polar cross-section (12 radial
    nodes a decade, 64 angles) at the nodes of a composite rule in k1 up to ``10^6 / L``,
    against the standard cross-section (8, 48) and two nodes fewer a panel (measured:
    the finer's own error is ~3e-4 of v's variance, the estimate 1e-3)."""
    fine = np.diag(_point_matrix(geometry, tensor, per_decade, order, (12, 64), dwell=False))
    coarse = np.diag(_point_matrix(geometry, tensor, per_decade, order - 2, (8, 48),
                                   dwell=False))
    return fine, np.abs(fine - coarse)


def _point_matrix(geometry, tensor, per_decade=2, order=6, cross_section=(12, 64),
                  dwell=True):
    """``M_ij = integral Phi_ij(k) (1 - |D_N|^2) [sinc^2(k1 U D / 2)] d^3k`` [m2 s-2],
    shape (3, 3): ``2 sum_j F_ij(k1_j) Re V_j(0)`` from the 1-D spectra at the rule's
    nodes (the record's weights; the dwell where `dwell`)."""
    length = tensor.length_scale
    rule = PanelRule(geometric_edges(1e-6 / length, 1e6 / length, per_decade), order)
    spectra = tensor.alpha_epsilon * np.asarray(_unit_spectra(
        length, tensor.anisotropy, per_decade, order, cross_section))      # (n, 3, 3)
    weights = record_weights(rule, 0.0, geometry.speed, geometry.scan_period,
                             geometry.record_duration).real
    if dwell:
        weights = weights * np.sinc(rule.nodes * geometry.speed * geometry.dwell
                                    / (2 * np.pi)) ** 2
    return 2.0 * np.einsum("n,nij->ij", weights, spectra)


@functools.lru_cache(maxsize=16)
def _unit_spectra(length, anisotropy, per_decade, order, cross_section):
    """The 1-D cross-spectra (n, 3, 3) of the tensor of unit alpha eps^(2/3) at the
    nodes of :func:`_point_matrix`'s rule (a function of L and Gamma alone: kept per
    process)."""
    tensor = MannTensor(length, anisotropy)
    rule = PanelRule(geometric_edges(1e-6 / length, 1e6 / length, per_decade), order)
    grid = WavenumberGrid(length, radius_per_decade=cross_section[0],
                          angle_nodes=cross_section[1])
    out = np.concatenate([_one_dimensional_spectra(tensor, grid, rule.nodes[s:s + 12])
                          for s in range(0, rule.size, 12)])
    out.flags.writeable = False
    return out


def _one_dimensional_spectra(tensor, grid, k1):
    """``integral Phi_ij(k1, k2, k3) dk2 dk3`` [m3 s-2] at each of `k1`, shape (n, 3, 3)."""
    k2, k3, w23 = grid.cross_section(k1)
    k1b = np.broadcast_to(k1[:, None], k2.shape)
    distortion = [np.ravel(v) for v in _flatten(tensor.distortion(k1b, k2, k3))]
    matrix = _projected(np.eye(3), np.eye(3), distortion, pairs=True)          # (P, 3, 3)
    return np.einsum("nqij,nq->nij", matrix.reshape(k2.shape + (3, 3)), w23)


def _flatten(distortion):
    """(factor, k0 components, zetas) of MannTensor.distortion as a flat list of arrays."""
    factor, k0, zetas = distortion
    return [factor, *k0, *zetas]


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

#: Gauss-Legendre nodes a panel of the Kaimal path's frequency rule (two fewer for the
#: error estimate) and panels a decade of the first rule [1].
KAIMAL_ORDER = 8
KAIMAL_PANELS_PER_DECADE = 2
#: Most frequencies the Kaimal path evaluates its pair sums at while it splits its
#: panels (a point probe's cross terms decay only with the spectrum) [1].
KAIMAL_MAX_NODES = 4096


def kaimal_lidar_variances(geometry, spectra, order=KAIMAL_ORDER,
                           tolerance=SPECTRAL_TOLERANCE):
    """Expected record variances for IEC Kaimal spectra and coherence, Eq. (4), with
    their error estimates.

    The frequency rule of each gate is adaptive: panels geometric in f L_u / U over
    :data:`~uq.constants.KAIMAL_FREQUENCY_DECADES`, each split in two while the
    difference between its `order`-node and (`order` - 2)-node sums of Eq. (4)'s
    integrand is above its share of the tolerance (the cosines of the probe points' lags
    are resolved where the integrand is not negligible, nowhere else), up to
    :data:`KAIMAL_MAX_NODES` frequencies; then the record's weights on the final panels
    (:func:`~uq.physics.spectralquadrature.record_weights`). The error estimate is the
    difference between the two rules on the final panels. The field's variances: the
    spectra on 4 panels a decade, and beyond in closed form.

    Parameters
    ----------
    geometry : ScanGeometry
    spectra : uq.physics.spectraltensor.KaimalSpectra
    order : int
        Gauss-Legendre nodes a panel.
    tolerance : float
        The relative error estimate of a variance the panels are split to [1].

    Returns
    -------
    SpectralVariances
    """
    scale = geometry.speed / spectra.lengths[0]
    low, high = (10.0 ** d * scale for d in KAIMAL_FREQUENCY_DECADES)
    true = _kaimal_true(geometry, spectra, PanelRule(geometric_edges(low, high, 4), order))
    true_c = _kaimal_true(geometry, spectra, PanelRule(geometric_edges(low, high, 4),
                                                       order - 2))
    edges = geometric_edges(low, high, KAIMAL_PANELS_PER_DECADE)
    lidar, error = np.zeros((geometry.n_gates, 3)), np.zeros((geometry.n_gates, 3))
    for g in range(geometry.n_gates):
        integrand = _KaimalIntegrand(geometry, spectra, g)
        final = _adapted_edges(integrand, edges, order, 0.5 * tolerance * np.maximum(
            0.05 * true, 0.0))
        lidar[g] = _kaimal_lidar(geometry, PanelRule(final, order), integrand)
        error[g] = np.abs(lidar[g] - _kaimal_lidar(geometry, PanelRule(final, order - 2),
                                                   integrand))
    return SpectralVariances(lidar, true, error, np.abs(true - true_c),
                             converged=_relative_error(lidar, error, true) <= tolerance)


def _adapted_edges(integrand, edges, order, floor):
    """Panel edges split in two while a panel's `order`- and (`order` - 2)-node sums of
    `integrand` (frequency -> (3,)) differ by more than its share of half the tolerance
    times ``max(|total|, floor)`` (:func:`kaimal_lidar_variances`)."""
    from uq.constants import SPECTRAL_TOLERANCE
    x, w = np.polynomial.legendre.leggauss(order)
    xc, wc = np.polynomial.legendre.leggauss(order - 2)
    panels = {}

    def panel(a, b):
        if (a, b) not in panels:
            c, h = (a + b) / 2, (b - a) / 2
            panels[a, b] = (h * w @ integrand(c + h * x), h * wc @ integrand(c + h * xc))
        return panels[a, b]
    while True:
        pairs = list(zip(edges[:-1], edges[1:]))
        parts = [panel(a, b) for a, b in pairs]
        total = sum(p[0] for p in parts)
        allowed = 0.5 * SPECTRAL_TOLERANCE * np.maximum(np.abs(total), floor)
        errors = np.array([np.max(np.abs(p[0] - p[1]) / allowed) for p in parts])
        if errors.sum() <= 1.0 or integrand.evaluated >= KAIMAL_MAX_NODES:
            return edges
        edges = np.union1d(edges, [(a + b) / 2 for (a, b), e in zip(pairs, errors)
                                   if e > 1.0 / len(pairs)])


def _kaimal_true(geometry, spectra, rule):
    """The field's variances (3,) of Eq. (4) with the record's weights on `rule`, and the
    spectra beyond it in closed form, ``integral_F^inf S_j df = sigma_j^2 (1 + 6 F L_j /
    U)^(-2/3)`` (Eq. 3 of :mod:`uq.physics.spectraltensor`), less the 1/N the scans
    alias."""
    weights = record_weights(rule, 0.0, geometry.speed, geometry.scan_period,
                             geometry.record_duration).real
    spectrum = np.stack([spectra.spectrum(j, rule.nodes) for j in range(3)])   # (3, F)
    scans = record_scans(geometry.scan_period, geometry.record_duration)
    tail = np.array([spectra.sigmas[j] ** 2 * (1 + 6 * rule.edges[-1] * spectra.lengths[j]
                                               / spectra.speed) ** (-2.0 / 3.0)
                     for j in range(3)]) * (1.0 - 1.0 / scans if scans else 1.0)
    return spectrum @ weights + tail


def _kaimal_lidar(geometry, rule, integrand):
    """One gate's variances (3,) of Eq. (4) with the record's weights on `rule`."""
    weights = record_weights(rule, 0.0, geometry.speed, geometry.scan_period,
                             geometry.record_duration).real
    return weights @ integrand(rule.nodes)


class _KaimalIntegrand:
    """Eq. (4)'s integrand of gate `gate` without the high-pass, ``(n_freq, 3)`` at given
    frequencies [m2 s-2 Hz-1], each frequency's value kept (the adaptive rule asks for
    some twice)."""

    def __init__(self, geometry, spectra, gate):
        self.spectra, self.dwell = spectra, geometry.dwell
        points = geometry.probe_points()                                    # (B, G, n, 3)
        directions = np.asarray(geometry.directions, dtype=float)
        weights = np.asarray(geometry.probe_weights)[gate]
        # only the nodes the gate weights: where the gates' nodes sit side by side
        # (their foci differ) the others' weights are zero, and their pairs add nothing
        kept = np.tile(weights != 0, directions.shape[0])
        p = points[:, gate].reshape(-1, 3)[kept]                             # (P, 3)
        tau = (np.repeat(np.asarray(geometry.times, float), points.shape[2])[kept]
               - p[:, 0] / geometry.speed)
        self.across = np.hypot(p[:, None, 1] - p[None, :, 1], p[:, None, 2] - p[None, :, 2])
        self.lag = tau[:, None] - tau[None, :]
        # a[c, p, j] = R_gcb n_bj w_gi
        self.a = np.einsum("cb,bj,i->cbij", np.asarray(geometry.reconstruction)[gate],
                           directions, weights).reshape(3, -1, 3)[:, kept]
        self.values = {}
        self.evaluated = 0

    def __call__(self, frequencies):
        frequencies = np.asarray(frequencies, dtype=float)
        for f in frequencies:
            if f in self.values:
                continue
            spectrum = np.array([self.spectra.spectrum(j, f) for j in range(3)])
            kernel = self.spectra.coherence(self.across, f) * np.cos(2 * np.pi * f * self.lag)
            pair = np.einsum("cpj,pq,cqj->cj", self.a, kernel, self.a)       # (3, 3)
            self.values[f] = pair @ spectrum * np.sinc(f * self.dwell) ** 2
            self.evaluated += 1
        return np.stack([self.values[f] for f in frequencies])


def lidar_variances(geometry, model, probe_transfer=None):
    """The spectral path for either model (:func:`mann_lidar_variances` for a
    :class:`MannTensor`, :func:`kaimal_lidar_variances` for :class:`KaimalSpectra`), with
    the numerical error of each variance (:class:`SpectralVariances`)."""
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
