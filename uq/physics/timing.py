"""When each beam of a scan is measured: dwell, time stamp, and the dwell average.

Conventions
-----------
* The beams are measured one after another in the order of the lidar's azimuths, then
  the vertical beam; beam k dwells on ``[k D, (k + 1) D)`` for the beam duration D [s],
  so t = 0 is the start of the scan and the scan lasts ``n_beams D``.
* A beam's time stamp is the ``start``, ``mid`` (default) or ``end`` of its dwell. The
  correction models that use one INS reading per scan read it at the scan's mid time
  ``n_beams D / 2``.
* With ``dwell_average`` the radial velocity is the mean over the dwell, by
  Gauss-Legendre quadrature on nodes inside the dwell (:func:`dwell_rule`): one panel of
  the fewest nodes (at most :data:`~uq.constants.MAX_DWELL_NODES`) whose error bound
  for a sinusoid of the integrand's highest frequency (:func:`dwell_frequency`) is below
  :data:`~uq.constants.DWELL_QUADRATURE_TOLERANCE`; a dwell of more cycles than one
  panel resolves is cut into equal panels (composite Gauss-Legendre), so that the rule
  holds at any dwell length (a dwell of whole periods of a harmonic averages it to 0,
  not to what a few nodes alias it to). The count is bounded before anything is
  allocated (:data:`~uq.constants.MAX_DWELL_TOTAL_NODES`; beyond it
  :class:`DwellTooLong`).

Accuracy: for a sinusoid of angular frequency up to :func:`dwell_frequency`, the mean
over the dwell is within ``DWELL_QUADRATURE_TOLERANCE`` (absolute, per unit amplitude)
of its closed form ``(cos(phi) - cos(w D + phi)) / (w D)``, for every dwell length
(tested against the closed form, and for the sines and cosines of the attitude against
Jacobi-Anger). Not covered by the bound: the harmonics of the power law's shear in the
height of a heaving gate (relative size (heave amplitude / height)^m of order m).

References
----------
.. [1] Abramowitz, M. and Stegun, I. A. (1964). Handbook of Mathematical Functions,
   25.4.30 (Gauss-Legendre quadrature and its error term), 9.1.42-9.1.43 (Jacobi-Anger
   expansion) and 9.1.62 (``|J_m(x)| <= |x / 2|^m / m!``).
"""
import math
from dataclasses import dataclass

import numpy as np

from uq.constants import DWELL_QUADRATURE_TOLERANCE, MAX_DWELL_NODES, MAX_DWELL_TOTAL_NODES

TIMESTAMPS = {"start": 0.0, "mid": 0.5, "end": 1.0}


@dataclass(frozen=True)
class ScanTiming:
    """Timing of the beams of a scan (see the module docstring).

    Attributes
    ----------
    beam_duration : float
        D [s] per line of sight.
    timestamp : {"start", "mid", "end"}
    dwell_average : bool
    """

    beam_duration: float = 1.0
    timestamp: str = "mid"
    dwell_average: bool = False

    def stamps(self, n_beams):
        """Time stamp of each beam [s], shape (n_beams,)."""
        return (np.arange(n_beams) + TIMESTAMPS[self.timestamp]) * self.beam_duration

    def scan_mid_time(self, n_beams):
        """Mid time of the scan [s]: where one-reading-per-scan corrections read the INS."""
        return 0.5 * n_beams * self.beam_duration

    def nodes(self, n_beams, fastest=0.0):
        """Measurement times and weights: shape (n_beams, q) and (q,).

        Without ``dwell_average`` one node per beam, at its time stamp, weight 1; with it
        Gauss-Legendre nodes inside each dwell, weights summing to 1 (the mean over the
        dwell): :func:`dwell_rule` for `fastest`, the integrand's highest angular
        frequency [rad s-1] (:func:`dwell_frequency`); panel after panel, each panel's
        nodes in order. Raises :class:`DwellTooLong` before allocating beyond
        :data:`~uq.constants.MAX_DWELL_TOTAL_NODES`.
        """
        if not self.dwell_average:
            return self.stamps(n_beams)[:, None], np.ones(1)
        panels, q = dwell_rule(fastest * self.beam_duration)
        x, w = np.polynomial.legendre.leggauss(q)                  # on [-1, 1]
        starts = np.arange(n_beams) * self.beam_duration
        if panels == 1:
            return starts[:, None] + 0.5 * (x + 1) * self.beam_duration, 0.5 * w
        width = self.beam_duration / panels
        offsets = (np.arange(panels)[:, None] * width + 0.5 * (x + 1) * width).ravel()
        return starts[:, None] + offsets, np.tile(0.5 * w / panels, panels)


class DwellTooLong(ValueError):
    """The dwell average needs more nodes than :data:`~uq.constants.MAX_DWELL_TOTAL_NODES`.

    Attributes
    ----------
    nodes : int
        Nodes per dwell the rule would need.
    longest_span : float
        The largest phase span [rad] the bound allows.
    """

    def __init__(self, nodes, longest_span):
        self.nodes, self.longest_span = nodes, longest_span
        super().__init__(f"the dwell average needs {nodes:.3g} nodes per dwell; at most "
                         f"{MAX_DWELL_TOTAL_NODES} (a phase span of {longest_span:.4g} rad)")


#: Largest half sum of the angular amplitudes [rad] :func:`dwell_frequency` resolves: its
#: order grows as ~e times it (27 000 terms at the bound); the scenario layer bounds the
#: motion far below (a reach of 45 deg per rotation, 1.2 rad in all).
MAX_DWELL_HALF_AMPLITUDE = 1e4


def dwell_frequency(components, tolerance=DWELL_QUADRATURE_TOLERANCE):
    """Highest angular frequency [rad s-1] of the radial velocity over a dwell that the
    dwell average must resolve: the fastest component's w times the order M + 1.

    The beam turns with the attitude, through sines and cosines of sums of the angular
    motions; by Jacobi-Anger [1] ``exp(i A sin(w t))`` has harmonics m w of amplitude
    ``|J_m(A)| <= (A / 2)^m / m!``, and a sum of components of angular amplitudes A_k
    (roll, pitch, yaw, rad) harmonics of order m of total amplitude at most
    ``(sum A_k / 2)^m / m!``. M is the smallest order whose tail beyond it,
    ``<= (A / 2)^(M+1) / (M+1)! exp(A / 2)``, is below `tolerance`; the velocity terms
    (rates, linear in the motion) add one order. Without angular motion (translations
    only) the integrand is linear in the motion: the order is 1.

    Parameters
    ----------
    components : sequence of uq.physics.motion.MotionComponent
    tolerance : float
        Absolute, per unit amplitude [1].

    Returns
    -------
    float
        [rad s-1]; 0 without motion; inf for angular amplitudes beyond
        :data:`MAX_DWELL_HALF_AMPLITUDE` (no order resolves them).
    """
    fastest = max((c.angular_frequency for c in components), default=0.0)
    half = sum(abs(a) for c in components for a in c.amplitudes[:3]) / 2
    if not half > 0:
        return fastest
    if not half <= MAX_DWELL_HALF_AMPLITUDE:
        return math.inf                          # no order suffices (the caller refuses)
    # log of the tail bound half^(M+1) / (M+1)! exp(half), no overflow at any amplitude
    order, log_term, log_tolerance = 0, half, math.log(tolerance)
    while True:
        log_term += math.log(half) - math.log(order + 1)
        if log_term <= log_tolerance:
            break
        order += 1
    return fastest * (order + 1)


def _log_bound(phase_span, q):
    """log of the Gauss-Legendre bound of :func:`dwell_node_count` (no overflow)."""
    return (2 * q * math.log(phase_span) + 4 * math.lgamma(q + 1) - math.log(2 * q + 1)
            - 3 * math.lgamma(2 * q + 1))


def panel_span(tolerance=DWELL_QUADRATURE_TOLERANCE):
    """The largest phase span [rad] one panel of MAX_DWELL_NODES nodes averages to
    `tolerance` (the bound of :func:`dwell_node_count` solved for the span)."""
    return math.exp((math.log(tolerance) - _log_bound(1.0, MAX_DWELL_NODES))
                    / (2 * MAX_DWELL_NODES))


#: :func:`panel_span` at the model's tolerance: ~71 rad (11 periods).
PANEL_SPAN = panel_span()


def dwell_rule(phase_span, tolerance=DWELL_QUADRATURE_TOLERANCE):
    """Panels and Gauss-Legendre nodes per panel that average ``sin(w t + phase)`` over
    a dwell of ``phase_span = w D`` [rad] to within `tolerance` (absolute, per unit
    amplitude): one panel of :func:`dwell_node_count` nodes where that many (at most
    :data:`~uq.constants.MAX_DWELL_NODES`) meet the bound; else the fewest equal panels
    of at most that many nodes each that do (the mean over the dwell is the mean of the
    panels' means, each within the bound of its own span).

    Returns
    -------
    panels, q : int

    Raises
    ------
    DwellTooLong
        If ``panels q`` would exceed :data:`~uq.constants.MAX_DWELL_TOTAL_NODES` (checked
        from the span alone, before anything is allocated).
    """
    if not phase_span >= 0 or not math.isfinite(phase_span):
        raise ValueError(f"phase span {phase_span!r} [rad]; allowed: a finite number >= 0")
    span = PANEL_SPAN if tolerance == DWELL_QUADRATURE_TOLERANCE else panel_span(tolerance)
    if phase_span <= span:
        return 1, dwell_node_count(phase_span, tolerance)
    most = MAX_DWELL_TOTAL_NODES // MAX_DWELL_NODES
    panels = math.ceil(phase_span / span)
    if panels <= most and _log_bound(phase_span / panels, MAX_DWELL_NODES) > math.log(tolerance):
        panels += 1                                     # (rounding at the edge of a panel)
    if panels > most:
        raise DwellTooLong(panels * MAX_DWELL_NODES, span * most)
    return panels, dwell_node_count(phase_span / panels, tolerance)


def dwell_node_count(phase_span, tolerance=DWELL_QUADRATURE_TOLERANCE):
    """Fewest Gauss-Legendre nodes q that average ``sin(w t + phase)`` over a dwell of
    ``phase_span = w D`` [rad] to within `tolerance` (absolute, per unit amplitude); at
    most :data:`~uq.constants.MAX_DWELL_NODES` (:func:`dwell_rule` cuts a longer dwell
    into panels).

    The error of the q-node rule on [a, b] is ``(b-a)^(2q+1) (q!)^4 / ((2q+1) ((2q)!)^3)
    f^(2q)(xi)`` [1]; for the mean over the dwell of a unit sinusoid (|f^(2q)| <= w^2q)
    that is at most ``(w D)^(2q) (q!)^4 / ((2q+1) ((2q)!)^3)``.
    """
    for q in range(1, MAX_DWELL_NODES + 1):
        if dwell_error_bound(phase_span, q) <= tolerance:
            return q
    return MAX_DWELL_NODES


def dwell_error_bound(phase_span, q):
    """The bound of :func:`dwell_node_count` for q nodes (per unit amplitude; inf where
    it exceeds the largest double)."""
    try:
        return phase_span ** (2 * q) * math.factorial(q) ** 4 / (
            (2 * q + 1) * math.factorial(2 * q) ** 3)
    except OverflowError:
        return math.inf
