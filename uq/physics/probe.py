"""Probe volume: the range weighting of a radial velocity along its beam, and its quadrature.

A lidar does not measure the radial velocity at the gate centre but its weighted mean along
the beam (Matavar 2024 [1], Eqs. 2.13 and 2.22)::

    v_r = integral W(s) n . v(x_c + s n) ds,        integral W(s) ds = 1.

Conventions
-----------
* ``s`` [m]: distance along the beam from the gate centre, positive away from the lidar.
* ``F`` [m]: slant distance of the gate centre from the lens, the configured
  ``range / cos(half_cone)`` (``range`` for the vertical beam); the focus of a CW lidar.
* Every weighting is cut symmetrically at the lens, ``|s| <= F``, and renormalised to 1:
  nothing returns from behind the lidar, and a symmetric cut keeps the weighting centred
  on the gate, so a linear wind profile still gives its gate-centre value (OpenFAST's lidar
  module [3] ends its symmetric sum at the lens in the same way). The cut matters only
  where the probe reaches the lens (a CW lidar far out, a pulsed one at its first gates).
* Along the beam only the horizontal wind speed varies (power-law shear): the beam, the
  vertical wind and the lidar's velocity are the same at every point of the probe (the
  light's round trip, ~1 us, is instantaneous against the platform's motion [1, Sec.
  2.2.1]). So the weighted radial velocity is ``U_w (b_h . e_wind) + b_z w - b . v_lidar``
  with ``U_w = integral W(s) U(z_c + s b_z) ds``: the weighted horizontal speed at the
  heights of the probe's points on the *true* (tilted, moving) beam ``b``, whose up
  component is ``b_z``. This module computes ``U_w`` (:meth:`PulsedProbe.average`).

Pulsed lidar [1, Sec. 2.2.3]. The pulse, in range, is ``P(s) = exp(-s^2 / r_p^2) /
(sqrt(pi) r_p)`` (Eq. 2.18), whose full width at half maximum is ``Delta r = 2 sqrt(ln 2)
r_p`` (Eq. 2.20 with ``r_p = c sigma_p / 2``), so ``r_p = Delta r / (2 sqrt(ln 2))``. The
range gate is a rectangle of length ``Delta p`` and height ``1 / Delta p``. Their
convolution (the first line of Eq. 2.23), with the Gaussian's distribution function
``(1 + erf(s / r_p)) / 2``::

    W_p(s) = [erf((s + Delta p / 2) / r_p) - erf((s - Delta p / 2) / r_p)] / (2 Delta p)  (1)

integrates to 1 (the rectangle's area times the pulse's) and, as the density of the sum
of a uniform and a Gaussian variable, has the variance of the two added::

    Var W_p = Delta p^2 / 12 + r_p^2 / 2 = Delta p^2 / 12 + Delta r^2 / (8 ln 2).       (2)

The second line of the printed Eq. 2.23 divides the arguments by ``sqrt(2) r_p``: that is
the distribution function of a Gaussian of variance ``r_p^2``, twice the pulse's
``r_p^2 / 2`` (its variance is ``Delta p^2 / 12 + Delta r^2 / (4 ln 2)``). The focusing
factor of Eq. 4.3 is left out: a pulsed lidar's beam is collimated, and the gate's
weighting alone is what "is generally done" [1, Sec. 4.1.1]. With the cut at the lens the
mass and second moment follow in closed form (:func:`pulsed_moments`).

Continuous-wave lidar, focused at F. On the axis the intensity of a Gaussian beam falls
as ``w0^2 / w(s)^2 = 1 / (1 + (s / z_R)^2)`` [1, Sec. 4.1.1, Eq. 2.9], a Lorentzian of
half width ``z_R``, the Rayleigh length of the focus. A beam of 1/e^2 intensity radius
``a`` at the lens focused at F has the waist ``w0 = lambda F / (pi a)`` and so ``z_R = pi
w0^2 / lambda = lambda F^2 / (pi a^2)`` (Eq. 2.11; the far-field approximation ``F << pi
a^2 / lambda``, 1.6 km for the typical CW lidar; Sonnenschein and Horrigan [4]). The
Lorentzian's variance is infinite, so its tails are part of the model: they are cut where
``W`` falls below ``t W(0)``, ``|s| <= c z_R`` with ``c = sqrt(1 / t - 1)``, and at the lens;
with the half length ``L = min(c z_R, F)`` and ``c_e = L / z_R``::

    W_c(s) = 1 / (2 z_R atan(c_e)) / (1 + (s / z_R)^2),   |s| <= L,                     (3)
    Var W_c = z_R^2 (c_e - atan(c_e)) / atan(c_e).                                     (4)

Under a power law ``U(z) = U_c (z / z_c)^alpha`` and ``z = z_c + s b_z``, Taylor's series
to second order and the zero first moment of a symmetric weighting give the relative bias
of the weighted speed (:func:`second_order_bias`)::

    U_w / U_c - 1 = alpha (alpha - 1) Var(W) b_z^2 / (2 z_c^2) + O((sqrt(Var) b_z / z_c)^4).  (5)

Quadrature: an n-node Gauss-Legendre rule (nodes ``x_i``, weights ``w_i`` on [-1, 1]).

* Pulsed: nodes ``s_i = L x_i`` on ``[-L, L]``, ``L = min(F, Delta p / 2 + k sigma)``
  (``sigma = r_p / sqrt(2)`` the pulse's standard deviation, ``k`` the two-sided Gaussian
  quantile of :data:`~uq.constants.PULSE_TAIL_MASS`: a numerical cut, not the model's),
  weights proportional to ``w_i W_p(s_i)``.
* CW: ``s = z_R tan(phi)`` turns (3) into the uniform density on ``[-atan c_e, atan c_e]``
  (the "tan" rule of [1, Sec. 4.1.1]): nodes ``s_i = z_R tan(x_i atan c_e)``, weights
  ``w_i / 2``.

Both rules are symmetric, so a linear profile is integrated exactly (to rounding) for any
n. The node count is the fewest for which the weighted speed of the scene's power law is
within :data:`~uq.constants.PROBE_QUADRATURE_TOLERANCE` (relative) of a
:data:`~uq.constants.PROBE_REFERENCE_NODES`-node rule, for the nominal static geometry of
every beam and gate (:func:`node_count`); ``tests/physics/test_probe.py`` checks the
chosen rules against brute-force adaptive integration.

All functions are vectorised and complex-step safe in the probe's parameters (the GUM
differentiates through them); node counts are taken from real parts.

References
----------
.. [1] Matavar, A. (2024). Wind field reconstruction from floating lidars. MSc thesis, TU
   Delft, Secs. 2.2 and 4.1.
.. [2] Abramowitz, M. and Stegun, I. A. (1964). Handbook of Mathematical Functions,
   25.4.29-30 (Gauss-Legendre quadrature), 7.1 (error function), 26.2 (normal
   distribution).
.. [3] OpenFAST, InflowWind lidar module, ``modules/inflowwind/src/Lidar.f90``
   (``Lidar_CalcOutput``: continuous-wave and pulsed weighting, truncation).
.. [4] Sonnenschein, C. M. and Horrigan, F. A. (1971). Signal-to-noise relationships for
   coaxial systems that heterodyne backscatter from the atmosphere. Appl. Opt. 10(7),
   1600-1604.
"""
import dataclasses
import functools
import math
from typing import ClassVar

import numpy as np
from scipy import special

from uq.constants import (MAX_PROBE_NODES, PROBE_QUADRATURE_TOLERANCE, PROBE_REFERENCE_NODES,
                          PULSE_TAIL_MASS)

#: Kinds of probe (``lidar.probe.kind``); ``point`` is the gate centre alone (no probe).
PROBE_KINDS = ("point", "pulsed", "cw")
#: Scenario unit of each probe parameter, as its size in SI units [m per unit]:
#: gate length and pulse FWHM in m, wavelength in um, beam radius at the lens in mm.
PARAMETER_SCALE = {"gate_length": 1.0, "pulse_fwhm": 1.0, "wavelength": 1e-6,
                   "beam_radius": 1e-3}
#: ``sqrt(ln 2)``: a Gaussian exp(-s^2 / r^2) is at half its peak at s = r sqrt(ln 2).
_SQRT_LN2 = math.sqrt(math.log(2.0))
#: Two-sided Gaussian quantile k of PULSE_TAIL_MASS: P(|g| > k sigma) = PULSE_TAIL_MASS.
PULSE_TAIL_SIGMAS = math.sqrt(2.0) * float(special.erfcinv(PULSE_TAIL_MASS))


# --- weighting functions (closed forms) -------------------------------------------------

def pulse_radius(pulse_fwhm):
    """``r_p = Delta r / (2 sqrt(ln 2))`` [m] of a pulse of FWHM `pulse_fwhm` [m] (Eq. 2.20)."""
    return pulse_fwhm / (2.0 * _SQRT_LN2)


def pulsed_weight(s, gate_length, pulse_fwhm):
    """Pulsed range weighting W_p(s) [m-1], Eq. (1) of the module docstring (uncut).

    Parameters
    ----------
    s : array_like
        Distance from the gate centre along the beam [m].
    gate_length, pulse_fwhm : array_like
        Range-gate length Delta p and pulse FWHM Delta r [m].
    """
    r_p = pulse_radius(pulse_fwhm)
    half = gate_length / 2.0
    # Eq. (1): rectangle of length Delta p convolved with exp(-s^2/r_p^2)/(sqrt(pi) r_p)
    return (special.erf((s + half) / r_p) - special.erf((s - half) / r_p)) / (2.0 * gate_length)


def pulsed_moments(half_length, gate_length, pulse_fwhm):
    """Mass and second moment of W_p on ``|s| <= half_length`` [1], [m^2].

    ``W_p(s) = (Phi((s + h) / sigma) - Phi((s - h) / sigma)) / (2 h)`` with ``h = Delta p /
    2``, ``sigma = r_p / sqrt(2)`` and Phi the standard normal distribution function;
    integrated by parts with the antiderivatives ``J0 = x Phi + phi``, ``J1 = ((x^2 - 1) Phi
    + x phi) / 2`` and ``J2 = (x^3 Phi + (x^2 + 2) phi) / 3`` of ``x^k Phi(x)`` [2, 26.2].

    Returns
    -------
    mass, second : ndarray
        ``integral W_p`` and ``integral s^2 W_p`` over ``[-half_length, half_length]``.
    """
    half_length = np.asarray(half_length, dtype=float)
    h = np.asarray(gate_length, dtype=float) / 2.0
    sigma = pulse_radius(np.asarray(pulse_fwhm, dtype=float)) / math.sqrt(2.0)

    def primitive(s, shift, power):
        """Antiderivative of s^power Phi((s + shift) / sigma) at s."""
        x = (s + shift) / sigma
        cdf, pdf = special.ndtr(x), np.exp(-x * x / 2.0) / math.sqrt(2.0 * math.pi)
        j0 = x * cdf + pdf
        if power == 0:
            return sigma * j0
        j1 = ((x * x - 1.0) * cdf + x * pdf) / 2.0
        j2 = (x ** 3 * cdf + (x * x + 2.0) * pdf) / 3.0
        # s = sigma x - shift: s^2 = sigma^2 x^2 - 2 sigma shift x + shift^2; ds = sigma dx
        return sigma * (sigma ** 2 * j2 - 2.0 * sigma * shift * j1 + shift ** 2 * j0)

    def moment(power):
        total = 0.0
        for shift, sign in ((h, 1.0), (-h, -1.0)):
            total = total + sign * (primitive(half_length, shift, power)
                                    - primitive(-half_length, shift, power))
        return total / (2.0 * h)

    return moment(0), moment(2)


def pulsed_variance(gate_length, pulse_fwhm, focus=np.inf):
    """Variance [m^2] of the pulsed weighting cut at the lens (``|s| <= focus``) and
    renormalised; Eq. (2) of the module docstring for an infinite `focus`."""
    if np.all(np.isinf(focus)):
        # Eq. (2): the rectangle's Delta p^2 / 12 plus the pulse's r_p^2 / 2
        return gate_length ** 2 / 12.0 + pulse_radius(pulse_fwhm) ** 2 / 2.0
    mass, second = pulsed_moments(focus, gate_length, pulse_fwhm)
    return second / mass


def rayleigh_length(wavelength, beam_radius, focus):
    """Rayleigh length ``z_R = lambda F^2 / (pi a^2)`` [m] of a Gaussian beam of 1/e^2
    radius `beam_radius` a [m] at the lens focused at `focus` F [m], wavelength [m]
    (waist ``w0 = lambda F / (pi a)``, Eq. 2.11 of [1]; far field, F << pi a^2 / lambda)."""
    return wavelength * focus ** 2 / (np.pi * beam_radius ** 2)


def cw_cut(truncation):
    """``c = sqrt(1 / t - 1)`` [1]: the Lorentzian falls to `truncation` t of its peak at
    ``|s| = c z_R``."""
    return math.sqrt(1.0 / truncation - 1.0)


def cw_half_length(rayleigh, truncation, focus):
    """Half length L [m] of the cut CW weighting: ``min(c z_R, F)`` (tails and lens)."""
    tails = cw_cut(truncation) * rayleigh
    return np.where(np.real(tails) <= np.real(focus), tails, focus)


def cw_weight(s, rayleigh, half_length):
    """CW range weighting W_c(s) [m-1], Eq. (3): the Lorentzian of half width `rayleigh`
    z_R [m], cut at ``|s| <= half_length`` [m] and renormalised."""
    scaled = np.arctan(half_length / rayleigh)
    inside = np.abs(np.real(s)) <= np.real(half_length)
    return np.where(inside, 1.0 / (2.0 * rayleigh * scaled) / (1.0 + (s / rayleigh) ** 2), 0.0)


def cw_variance(rayleigh, half_length):
    """Variance [m^2] of the cut CW weighting, Eq. (4): ``z_R^2 (c_e - atan c_e) / atan
    c_e`` with ``c_e = L / z_R`` (from ``x^2 / (1 + x^2) = 1 - 1 / (1 + x^2)``)."""
    c = half_length / rayleigh
    return rayleigh ** 2 * (c - np.arctan(c)) / np.arctan(c)


def second_order_bias(shear, variance, vertical, height):
    """Relative bias ``alpha (alpha - 1) Var b_z^2 / (2 z^2)`` [1] of a probe-weighted
    power-law speed, Eq. (5) of the module docstring (second order in the probe's extent).

    Parameters
    ----------
    shear : array_like
        Power-law exponent alpha [1].
    variance : array_like
        Variance of the weighting along the beam [m^2].
    vertical : array_like
        Up component of the beam b_z = cos(zenith angle) [1].
    height : array_like
        Height of the gate centre [m].
    """
    return shear * (shear - 1.0) * variance * vertical ** 2 / (2.0 * height ** 2)


# --- probes and their quadrature ------------------------------------------------------------

@functools.lru_cache(maxsize=2 * PROBE_REFERENCE_NODES)
def legendre(nodes):
    """Gauss-Legendre nodes and weights on [-1, 1] [2, 25.4.29] (numpy's, symmetric to the
    last bit), computed once per count."""
    x, w = np.polynomial.legendre.leggauss(nodes)
    x.flags.writeable = w.flags.writeable = False
    return x, w


class _Probe:
    """What the probes share: the weighted mean of a profile along the beam."""

    #: Names of the probe's parameters (scenario keys of ``lidar.probe``).
    PARAMETERS: ClassVar = ()
    kind: ClassVar = ""

    def parameters(self, errors=None):
        """The true parameters [SI]: configured plus the error (file units, scaled by
        :data:`PARAMETER_SCALE`); `errors` maps a parameter name to an array that
        broadcasts against the heights."""
        errors = errors or {}
        return {name: getattr(self, name) + PARAMETER_SCALE.get(name, 1.0)
                * errors.get(name, 0.0) for name in self.PARAMETERS}

    def average(self, profile, heights, vertical, focus, errors=None, nodes=None):
        """The weighted mean ``integral W(s) profile(heights + s vertical) ds``.

        Parameters
        ----------
        profile : callable
            Horizontal wind speed [m s-1] at an array of heights [m].
        heights : ndarray
            Heights of the gate centres on the true beams [m], shape (..., n_gates).
        vertical : ndarray
            Up component b_z [1] of each true beam, broadcasting against `heights`.
        focus : ndarray
            Slant distance F of each gate centre [m], broadcasting against `heights`.
        errors : dict, optional
            Parameter errors (file units), each broadcasting against `heights`.
        nodes : int, optional
            Gauss-Legendre nodes; default the probe's :attr:`nodes`.

        Returns
        -------
        ndarray
            The weighted speed [m s-1], the shape of ``heights + vertical + focus``.
        """
        count = nodes or self.nodes
        if not count:
            raise ValueError("the probe has no node count; use uq.physics.probe.resolve")
        x, w = legendre(count)
        params = self.parameters(errors)
        total = norm = 0.0
        for node, weight in zip(x, w):     # one node at a time: memory of the point model
            s, omega = self._node(node, weight, focus, params)
            total = total + omega * profile(heights + s * vertical)
            norm = norm + omega
        return total / norm

    def average_at_once(self, profile, heights, vertical, focus, nodes):
        """:meth:`average` with every node at once (a trailing node axis: memory times
        `nodes`; for the few geometries of :func:`node_count`) and the configured
        parameters; `profile` takes heights of shape (..., nodes)."""
        x, w = legendre(nodes)
        s, omega = self._node(x, w, np.asarray(focus)[..., None], self.parameters())
        values = profile(np.asarray(heights)[..., None] + s * np.asarray(vertical)[..., None])
        return np.sum(omega * values, axis=-1) / np.sum(omega, axis=-1)

    def with_nodes(self, nodes, error=0.0):
        """The probe with its node count (and the estimated relative error) set."""
        return dataclasses.replace(self, nodes=int(nodes), quadrature_error=float(error))


@dataclasses.dataclass(frozen=True)
class PulsedProbe(_Probe):
    """A range-gated pulsed lidar: weighting Eq. (1), cut at the lens.

    Attributes
    ----------
    gate_length : float
        Range-gate length Delta p [m].
    pulse_fwhm : float
        Full width at half maximum Delta r of the pulse in range [m].
    nodes : int
        Gauss-Legendre nodes per beam and gate (0: not chosen yet, :func:`resolve`).
    quadrature_error : float
        Relative error of the rule estimated by :func:`node_count` [1].
    """

    gate_length: float
    pulse_fwhm: float
    nodes: int = 0
    quadrature_error: float = 0.0
    PARAMETERS: ClassVar = ("gate_length", "pulse_fwhm")
    kind: ClassVar = "pulsed"

    def half_length(self, focus, params=None):
        """Half length [m] of the quadrature's interval: ``min(F, Delta p / 2 + k sigma)``."""
        params = params or self.parameters()
        sigma = pulse_radius(params["pulse_fwhm"]) / math.sqrt(2.0)
        reach = params["gate_length"] / 2.0 + PULSE_TAIL_SIGMAS * sigma
        # |s| <= F: cut at the lens; the Gaussian tail beyond k sigma is a numerical cut
        return np.where(np.real(reach) <= np.real(focus), reach, focus)

    def _node(self, node, weight, focus, params):
        half = self.half_length(focus, params)
        s = half * node
        return s, weight * half * pulsed_weight(s, params["gate_length"], params["pulse_fwhm"])

    def variance(self, focus=np.inf):
        """Variance of the weighting as cut at the lens [m^2] (:func:`pulsed_variance`)."""
        return pulsed_variance(self.gate_length, self.pulse_fwhm, focus)

    def describe(self):
        return (f"pulsed: W(s) = [erf((s + dp/2)/r_p) - erf((s - dp/2)/r_p)] / (2 dp), "
                f"r_p = dr / (2 sqrt(ln 2)), range-gate length dp = {self.gate_length:g} m, "
                f"pulse FWHM dr = {self.pulse_fwhm:g} m; cut at the lens (|s| <= F) and "
                "renormalised")


@dataclasses.dataclass(frozen=True)
class ContinuousWaveProbe(_Probe):
    """A focused continuous-wave lidar: weighting Eq. (3), focus at the gate centre.

    Attributes
    ----------
    wavelength : float
        Laser wavelength lambda [m].
    beam_radius : float
        1/e^2 intensity radius a of the beam at the lens [m].
    truncation : float
        t [1]: the Lorentzian's tails are cut where it falls below t times its peak.
    nodes : int
        Gauss-Legendre nodes per beam and gate (0: not chosen yet, :func:`resolve`).
    quadrature_error : float
        Relative error of the rule estimated by :func:`node_count` [1].
    """

    wavelength: float
    beam_radius: float
    truncation: float
    nodes: int = 0
    quadrature_error: float = 0.0
    PARAMETERS: ClassVar = ("wavelength", "beam_radius")
    kind: ClassVar = "cw"

    def rayleigh(self, focus, params=None):
        """Rayleigh length z_R [m] of the focus at each `focus` [m]."""
        params = params or self.parameters()
        return rayleigh_length(params["wavelength"], params["beam_radius"], focus)

    def half_length(self, focus, params=None):
        """Half length L = min(c z_R, F) [m] of the cut weighting."""
        return cw_half_length(self.rayleigh(focus, params), self.truncation, focus)

    def _node(self, node, weight, focus, params):
        rayleigh = self.rayleigh(focus, params)
        angle = np.arctan(cw_half_length(rayleigh, self.truncation, focus) / rayleigh)
        # s = z_R tan(phi), phi uniform on [-atan c_e, atan c_e]: Eq. (3) in phi
        return rayleigh * np.tan(node * angle), weight / 2.0

    def variance(self, focus):
        """Variance of the cut weighting at `focus` [m^2], Eq. (4)."""
        rayleigh = self.rayleigh(focus)
        return cw_variance(rayleigh, cw_half_length(rayleigh, self.truncation, focus))

    def describe(self):
        c = cw_cut(self.truncation)
        return (f"cw: W(s) = 1 / (2 z_R atan(c_e)) / (1 + (s/z_R)^2), z_R = lambda F^2 / "
                f"(pi a^2), wavelength lambda = {self.wavelength / PARAMETER_SCALE['wavelength']:g}"
                f" um, beam radius at the lens a = "
                f"{self.beam_radius / PARAMETER_SCALE['beam_radius']:g} mm; the Lorentzian "
                f"(infinite variance) is truncated where W < {self.truncation:g} W(0), i.e. "
                f"|s| <= {c:.4g} z_R, and at the lens (|s| <= F), c_e = min({c:.4g}, F/z_R), "
                "and renormalised")


def node_count(probe, heights, vertical, focus, shear, tolerance=PROBE_QUADRATURE_TOLERANCE):
    """Fewest Gauss-Legendre nodes whose weighted power-law speed is within `tolerance`
    (relative) of the :data:`~uq.constants.PROBE_REFERENCE_NODES`-node rule at every
    given geometry, at that node count and the next (two in a row, so that a rule whose
    error merely crosses zero is not taken).

    Each geometry is followed from one node up until it meets the tolerance; the largest
    count any needs is then checked at every geometry (the error of a Gauss rule need not
    fall monotonically), going on up if one misses. Where
    :data:`~uq.constants.MAX_PROBE_NODES` do not meet the tolerance they are used, and the
    error returned says by how much they miss (the results' ``probe_quadrature_error``).

    Parameters
    ----------
    probe : PulsedProbe or ContinuousWaveProbe
    heights, vertical, focus, shear : array_like
        Gate-centre height [m], up component of the beam [1], slant distance [m] and
        power-law exponent [1]; broadcast together (real parts are used). Geometries
        outside the model (a probe point at or below the sea) are left out.
    tolerance : float

    Returns
    -------
    nodes : int
        At most :data:`~uq.constants.MAX_PROBE_NODES`.
    error : float
        The largest relative error of that rule against the reference [1].
    """
    columns = np.broadcast_arrays(*(np.real(np.asarray(v, dtype=complex)).astype(float)
                                    for v in (heights, vertical, focus, shear)))
    rows = np.unique(np.stack([c.ravel() for c in columns], axis=1), axis=0)
    probe = dataclasses.replace(probe, nodes=0)

    def rule(n, where):
        z, b, f, alpha = (rows[where, k] for k in range(4))
        return probe.average_at_once(lambda height: _relative_power_law(
            height, z[:, None], alpha[:, None]), z, b, f, n)

    def error(n, where):
        return np.abs(rule(n, where) / reference[where] - 1.0)

    reference = rule(PROBE_REFERENCE_NODES, slice(None))
    active = np.flatnonzero(np.isfinite(reference))
    if not active.size:
        return 1, 0.0
    everywhere = active
    needed, previous = 1, error(1, active)
    while active.size and needed < MAX_PROBE_NODES:     # each geometry on its own
        following = error(needed + 1, active)
        met = (previous <= tolerance) & (following <= tolerance)
        active, previous = active[~met], following[~met]
        needed += 1 if active.size else 0
    for n in range(needed, MAX_PROBE_NODES):             # all of them at one count
        at_n = error(n, everywhere)
        if max(at_n.max(), error(n + 1, everywhere).max()) <= tolerance:
            return n, float(at_n.max())
    return MAX_PROBE_NODES, float(error(MAX_PROBE_NODES, everywhere).max())


def _relative_power_law(height, centre, shear):
    """``(z / z_c)^alpha`` [1]; NaN at or below the sea (z <= 0)."""
    valid = height > 0
    return np.where(valid, np.where(valid, height, centre) / centre, np.nan) ** shear


def nominal_geometry(scene):
    """Heights of the gate centres [m], up components of the beams [1] and slant
    distances [m] of a scene's configured beams at its static attitude, each broadcasting
    to (*S, n_beams, n_gates)."""
    from uq.physics.beams import slant_distances
    from uq.physics.rotation import attitude_matrix, rotate_vectors
    attitude = attitude_matrix(scene.heading, scene.pitch, scene.roll)
    beams = rotate_vectors(attitude, scene.nominal_unit_vectors())           # (*S, b, 3)
    slant = slant_distances(scene.ranges, scene.half_cone, len(scene.azimuths),
                            scene.vertical_beam)                             # ([*S], b, g)
    vertical = beams[..., 2:3]
    lidar = scene.field("lidar_height", 2)
    return lidar + slant * vertical, vertical, slant


def resolve(scene, tolerance=PROBE_QUADRATURE_TOLERANCE):
    """The scene with its probe's node count chosen (:func:`node_count`) for its nominal
    static geometry and shear; the scene itself when it has no probe or one already
    resolved. A batch of scenes gets the largest count any of them needs."""
    probe = scene.probe
    if probe is None or probe.nodes:
        return scene
    heights, vertical, slant = nominal_geometry(scene)
    nodes, error = node_count(probe, heights, vertical, slant, scene.field("shear", 2),
                              tolerance)
    return dataclasses.replace(scene, probe=probe.with_nodes(nodes, error))
