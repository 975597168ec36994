"""The INS as a sampled time series: sample times, interpolation to a beam's time, and
the Gauss-Markov correlation of its errors between beams.

Conventions
-----------
* The INS samples at ``rate`` [Hz]: at times ``offset + j / rate`` (j integer), where the
  offset, uniform over one INS period, is drawn per trial: the INS clock is not aligned
  with the beams. ``rate`` None is a continuous INS (read exactly at any time).
* The lidar reads the INS at its own time stamps; the two clocks differ by the clock
  offset delta [s] (an error distribution): the reading for a beam stamped t is the INS
  at ``t + delta`` (delta > 0: the INS clock runs ahead of the lidar's).
* ``nearest``: the sample nearest to the read time; ``linear``: between the two samples
  around it, positions and velocities linearly, the attitude on the rotation group
  (:func:`uq.physics.rotation.interpolate_rotation`).
* Errors: each INS error (heading, pitch, roll, sog, cog, heave) with a
  ``correlation_time`` tau is a Gauss-Markov process between the beams of a scan, with
  correlation ``exp(-|t_k - t_l| / tau)`` between beams k and l (:func:`gauss_markov_
  correlation`); tau -> 0 gives independent readings per beam (``ins.correlation:
  beam``), tau -> infinity one error per scan (``scan``).

Interpolation errors (tested): for a sinusoid of amplitude A and angular frequency w
sampled every h = 1 / rate, the largest error of ``linear`` is ``A w^2 h^2 / 8`` and of
``nearest`` ``A w h / 2`` (to leading order in w h).
"""
from dataclasses import dataclass

import numpy as np

INTERPOLATIONS = ("nearest", "linear")


@dataclass(frozen=True)
class InsSampling:
    """How the INS is sampled and read.

    Attributes
    ----------
    rate : float or None
        [Hz]; None: continuous.
    interpolation : {"nearest", "linear"}
    """

    rate: float = None
    interpolation: str = "linear"


def bracket(read_times, rate, offset, interpolation):
    """INS samples that a read at `read_times` uses, and their weights.

    Parameters
    ----------
    read_times : ndarray, shape (n, *T) [s]
    rate : float [Hz]
    offset : ndarray, shape (n,) [s], in [0, 1 / rate)
    interpolation : {"nearest", "linear"}

    Returns
    -------
    times : ndarray, shape (n, *T, 2)
        The two sample times [s] (equal for ``nearest``).
    fraction : ndarray, shape (n, *T)
        Weight of the second sample (0 for ``nearest``); complex-step safe: carries the
        derivative of the read time and the offset.
    """
    read_times = np.asarray(read_times)
    offset = np.asarray(offset).reshape(np.shape(offset) + (1,) * (read_times.ndim - 1))
    position = (read_times - offset) * rate                  # in sample periods
    if interpolation == "nearest":
        index = np.floor(np.real(position) + 0.5)
        fraction = 0.0 * position
        first = second = offset + index / rate
    else:
        index = np.floor(np.real(position))
        fraction = position - index
        first, second = offset + index / rate, offset + (index + 1) / rate
    return np.stack(np.broadcast_arrays(first, second), axis=-1), fraction


def gauss_markov_correlation(times, correlation_time):
    """Correlation matrix ``exp(-|t_k - t_l| / tau)`` of a Gauss-Markov (first-order
    autoregressive) process at `times` [s]; tau [s] > 0, or inf (fully correlated).
    tau = 0 gives the identity (independent)."""
    times = np.asarray(times, dtype=float)
    gaps = np.abs(times[:, None] - times[None, :])
    if correlation_time == 0:
        return np.eye(len(times))
    with np.errstate(invalid="ignore"):
        return np.where(gaps == 0, 1.0, np.exp(-gaps / correlation_time))
