"""Platform motion in a sea state: a JONSWAP wave spectrum as harmonic components with
random phases, and the platform's response per degree of freedom.

The spectrum's shape comes from wavespectra (``wavespectra.construct.frequency.jonswap``,
Hasselmann et al. 1973 [1]); it is evaluated at the mid-points ``f_j`` of
:data:`components` equal frequency bins of width df over the band, and each bin is one
wave component of amplitude ``a_j = sqrt(2 S(f_j) df)`` with its own random phase. The
spectrum is scaled so that the components carry exactly the significant wave height,
``4 sqrt(sum S(f_j) df) = Hs`` (the sea-surface variance ``m0 = sum a_j^2 / 2``).

Response: the platform moves each degree of freedom d as ``R_d a_j sin(w_j t + lag_d +
phi_j)``: a response amplitude factor R_d per metre of wave amplitude ([deg m-1] for
roll, pitch, yaw; [m m-1] for surge, sway, heave) and a phase lag, the same for every
frequency (a flat response operator: a stated simplification; a frequency-dependent RAO
would make R_d a function of f_j). All degrees of freedom share a component's phase.

References
----------
.. [1] Hasselmann, K. et al. (1973). Measurements of wind-wave growth and swell decay
   during the Joint North Sea Wave Project (JONSWAP). Dtsch. Hydrogr. Z. A8(12).
.. [2] Tucker, M. J. and Pitt, E. G. (2001). Waves in Ocean Engineering. Elsevier,
   Sec. 5.2 (random-phase synthesis of a sea state from its spectrum).
"""
import functools
import math

import numpy as np

from uq.physics.motion import DEGREES_OF_FREEDOM, MotionComponent


def jonswap_components(hs, tp, gamma, components, band, response):
    """Motion components of a JONSWAP sea (see the module docstring).

    Parameters
    ----------
    hs : float
        Significant wave height [m].
    tp : float
        Peak period [s].
    gamma : float
        Peak enhancement factor [1] (3.3 for the mean JONSWAP sea).
    components : int
        Number of frequency bins (wave components).
    band : tuple of float
        (lowest, highest) frequency [Hz].
    response : dict
        dof -> (factor [deg m-1 or m m-1], lag [rad]).

    Returns
    -------
    tuple of MotionComponent
        With random phases (``phase=None``); amplitudes in [rad] and [m].
    """
    low, high = band
    width = (high - low) / components
    frequencies, shape = _jonswap_bins(tp, gamma, components, low, high, hs)
    density = np.zeros(components) if hs == 0 else \
        shape * (hs / 4.0) ** 2 / np.sum(shape * width)  # sum S df = m0 exactly; calm: 0
    amplitudes = np.sqrt(2.0 * density * width)
    out = []
    for frequency, amplitude in zip(frequencies, amplitudes):
        gains, lags = [0.0] * len(DEGREES_OF_FREEDOM), [0.0] * len(DEGREES_OF_FREEDOM)
        for dof, (factor, lag) in response.items():
            index = DEGREES_OF_FREEDOM.index(dof)
            scale = math.radians(1.0) if index < 3 else 1.0
            gains[index], lags[index] = factor * scale * amplitude, lag
        out.append(MotionComponent(2 * math.pi * frequency, tuple(gains), tuple(lags), None))
    return tuple(out)


def band_energy(tp, gamma, components, band):
    """The sum ``S(f_j) df`` over the bins of :func:`jonswap_components` of a JONSWAP
    spectrum of unit significant height [m2]: 0 or NaN where the band holds
    none of its energy in double precision (a band far below the peak, where
    ``exp(-1.25 (fp / f)^4)`` underflows), so that no significant height can be given
    to its components."""
    low, high = band
    width = (high - low) / components
    with np.errstate(all="ignore"):
        return float(np.sum(_jonswap_bins(tp, gamma, components, low, high, 1.0)[1] * width))


@functools.lru_cache(maxsize=64)
def _jonswap_bins(tp, gamma, components, low, high, hs):
    """(mid-points f_j [Hz], wavespectra's JONSWAP S(f_j) of significant height `hs`
    [m2 s]) of the bins of :func:`jonswap_components`, read-only.

    Kept per argument: wavespectra names the significant height it scales to from the
    caller's frame (``inspect.stack()``, which reads the source of every frame of the
    stack), 0.1-0.2 s a call deep in a run; a record-mode sweep asks for the same
    spectrum for each of its records."""
    from wavespectra.construct.frequency import jonswap        # (imports dask: lazily)
    width = (high - low) / components
    frequencies = low + width * (np.arange(components) + 0.5)
    shape = np.asarray(jonswap(frequencies, fp=1.0 / tp, gamma=gamma, hs=hs).values,
                       dtype=float)
    frequencies.flags.writeable = shape.flags.writeable = False
    return frequencies, shape


def significant_height(components, dof):
    """4 sqrt(sum A^2 / 2) of one degree of freedom over the components: the significant
    height (wave: m) or significant double amplitude of its motion."""
    index = DEGREES_OF_FREEDOM.index(dof)
    return 4.0 * math.sqrt(sum(c.amplitudes[index] ** 2 for c in components) / 2.0)
