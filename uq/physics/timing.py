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
  Gauss-Legendre quadrature on nodes inside the dwell; the node count is the smallest
  whose error bound for the fastest motion component is below
  :data:`~uq.constants.DWELL_QUADRATURE_TOLERANCE` (:func:`dwell_node_count`).

References
----------
.. [1] Abramowitz, M. and Stegun, I. A. (1964). Handbook of Mathematical Functions,
   25.4.30 (Gauss-Legendre quadrature and its error term).
"""
import math
from dataclasses import dataclass

import numpy as np

from uq.constants import DWELL_QUADRATURE_TOLERANCE, MAX_DWELL_NODES

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
        dwell), q from :func:`dwell_node_count` for the fastest angular frequency [rad s-1].
        """
        if not self.dwell_average:
            return self.stamps(n_beams)[:, None], np.ones(1)
        q = dwell_node_count(fastest * self.beam_duration)
        x, w = np.polynomial.legendre.leggauss(q)                  # on [-1, 1]
        starts = np.arange(n_beams) * self.beam_duration
        return starts[:, None] + 0.5 * (x + 1) * self.beam_duration, 0.5 * w


def dwell_node_count(phase_span, tolerance=DWELL_QUADRATURE_TOLERANCE):
    """Fewest Gauss-Legendre nodes q that average ``sin(w t + phase)`` over a dwell of
    ``phase_span = w D`` [rad] to within `tolerance` (absolute, per unit amplitude).

    The error of the q-node rule on [a, b] is ``(b-a)^(2q+1) (q!)^4 / ((2q+1) ((2q)!)^3)
    f^(2q)(xi)`` [1]; for the mean over the dwell of a unit sinusoid (|f^(2q)| <= w^2q)
    that is at most ``(w D)^(2q) (q!)^4 / ((2q+1) ((2q)!)^3)``.
    """
    for q in range(1, MAX_DWELL_NODES + 1):
        bound = phase_span ** (2 * q) * math.factorial(q) ** 4 / (
            (2 * q + 1) * math.factorial(2 * q) ** 3)
        if bound <= tolerance:
            return q
    return MAX_DWELL_NODES


def dwell_error_bound(phase_span, q):
    """The bound of :func:`dwell_node_count` for q nodes (per unit amplitude)."""
    return phase_span ** (2 * q) * math.factorial(q) ** 4 / (
        (2 * q + 1) * math.factorial(2 * q) ** 3)
