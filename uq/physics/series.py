"""A measured motion record as motion components: its Fourier series, each trial a
random window of it.

The record (equally spaced samples of roll, pitch, yaw [rad] and surge, sway, heave [m])
is written exactly as its discrete Fourier series over the record length T (the record
repeats with period T: its end joins its start):
``x_d(t) = mean_d + sum_k A_dk sin(w_k t + lag_dk)``, ``w_k = 2 pi k / T``. The mean of
each degree of freedom is removed (the static attitude and position are ``ship``'s); the
`components` harmonics with the most motion (summed over the degrees of freedom, each
relative to its own variance) are kept, the rest dropped (their share of the variance is
returned). Rates are the series' analytic derivatives.

A trial reads the record from a random start tau, uniform over [0, T): every component's
phase moves by ``w_k tau`` together, ``c_k = (cos w_k tau, sin w_k tau)``
(:class:`WindowStart`). Over tau these have mean 0, covariance I/2 and no covariance
between components (``w_k = 2 pi k / T``), exactly the moments of independent random
phases: the GUM's linearisation is the same as for a sea of random phases.

References
----------
.. [1] Oppenheim, A. V. and Schafer, R. W. (2010). Discrete-Time Signal Processing, 3rd
   ed., Sec. 8.1 (the discrete Fourier series of a periodic sequence).
"""
import math

import numpy as np
from scipy.special import ndtr

from uq.physics.motion import DEGREES_OF_FREEDOM, MotionComponent


def series_components(times, values, components):
    """Motion components of a record.

    Parameters
    ----------
    times : ndarray, shape (N,)
        Equally spaced sample times [s].
    values : dict
        dof -> ndarray (N,) [rad for roll, pitch, yaw; m for surge, sway, heave].
    components : int
        Harmonics kept.

    Returns
    -------
    components : tuple of MotionComponent
        With ``phase=0`` (the record as recorded; :class:`WindowStart` moves them).
    kept : float
        Share of the motion's variance the kept harmonics hold (relative variances
        averaged over the degrees of freedom).
    """
    times = np.asarray(times, dtype=float)
    n = times.size
    step = (times[-1] - times[0]) / (n - 1)
    length = n * step                                      # the record's period T
    spectra = {d: np.fft.rfft(np.asarray(v, float) - np.mean(v)) for d, v in values.items()}
    power = {d: np.abs(s[1:]) ** 2 for d, s in spectra.items()}
    total = sum(p / max(p.sum(), np.finfo(float).tiny) for p in power.values())
    order = np.argsort(total)[::-1][:components]
    kept = float(total[order].sum() / max(total.sum(), np.finfo(float).tiny))
    out = []
    for index in sorted(order):
        k = index + 1                                      # harmonic number (0: the mean)
        scale = 1.0 if (n % 2 == 0 and k == n // 2) else 2.0
        amplitudes, lags = [0.0] * 6, [0.0] * 6
        for dof, spectrum in spectra.items():
            d = DEGREES_OF_FREEDOM.index(dof)
            coefficient = spectrum[k] * np.exp(-2j * np.pi * k * times[0] / length)
            amplitudes[d] = scale * abs(coefficient) / n
            lags[d] = float(np.angle(coefficient)) + math.pi / 2   # cos -> sin
        out.append(MotionComponent(2 * math.pi * k / length, tuple(amplitudes),
                                   tuple(lags), 0.0))
    return tuple(out), kept


class WindowStart:
    """The unit phase vectors of a record's harmonics read from a random start tau,
    uniform over the record length: ``c_k = (cos w_k tau, sin w_k tau)`` for all k from
    one draw (a joint distribution of shape (K, 2) for :class:`uq.engine.inputs.Input`;
    only the first normal score is used). Mean 0, standard deviation 1/sqrt(2) and no
    correlation between any two coordinates (see the module docstring): the GUM's view.
    """

    joint_size = 2

    def __init__(self, angular_frequencies, length):
        self.angular_frequencies = np.asarray(angular_frequencies, dtype=float)
        self.length = float(length)

    def mean(self):
        return 0.0

    def std(self):
        return 1.0 / math.sqrt(2.0)

    def transform(self, scores):
        """(n, K, 2) normal scores -> (n, K, 2) phase vectors from tau = T Phi(z_00)."""
        tau = self.length * ndtr(scores[:, 0, 0])
        angle = tau[:, None] * self.angular_frequencies[None, :]
        return np.stack([np.cos(angle), np.sin(angle)], axis=-1)

    def __repr__(self):
        return f"WindowStart({len(self.angular_frequencies)} harmonics, T={self.length:g} s)"
