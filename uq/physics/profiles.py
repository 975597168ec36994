"""Vertical profiles of the mean horizontal wind speed: pure functions with units.

Each profile is a function ``f(height, *parameters)`` and an entry of :data:`PROFILES`
(parameter names, units, a first guess from data) so that fits can use any of them.

References
----------
.. [1] Emeis, S. (2018). Wind Energy Meteorology, 2nd ed., Springer, Sec. 3.1
   (logarithmic profile) and 3.2 (power law).
"""
import numpy as np

from uq.constants import VON_KARMAN
from uq.physics.wind import power_law_speed


def power_law_profile(height, reference_speed, shear, reference_height=100.0):
    """U(z) = U_ref (z / z_ref)^alpha [m s-1]; NaN for z <= 0 [1].

    Parameters
    ----------
    height : array_like
        [m] above the surface.
    reference_speed : array_like
        U_ref at `reference_height` [m s-1].
    shear : array_like
        Power-law exponent alpha [1].
    reference_height : float
        z_ref [m].
    """
    return power_law_speed(reference_speed, height, reference_height, shear)


def log_law_profile(height, friction_velocity, roughness_length):
    """U(z) = (u* / kappa) ln(z / z0) [m s-1], neutral surface layer [1]; NaN for z <= z0.

    Parameters
    ----------
    height : array_like
        [m] above the surface.
    friction_velocity : array_like
        u* [m s-1].
    roughness_length : array_like
        z0 [m], > 0.
    """
    height = np.asarray(height)
    valid = np.real(height) > np.real(roughness_length)
    safe = np.where(valid, height, 2 * np.real(roughness_length) + 1.0)
    return np.where(valid, friction_velocity / VON_KARMAN * np.log(safe / roughness_length),
                    np.nan)


def _power_law_guess(height, speed, reference_height=100.0):
    """U_ref from interpolation at z_ref and alpha from a log-log line."""
    slope = np.polyfit(np.log(height), np.log(speed), 1)[0]
    return [float(np.interp(reference_height, height, speed)), float(slope)]


def _log_law_guess(height, speed):
    """u* and z0 from the straight line U = b ln z + a (b = u*/kappa, z0 = e^(-a/b))."""
    slope, intercept = np.polyfit(np.log(height), speed, 1)     # U = b ln z + a
    return [float(slope * VON_KARMAN), float(np.exp(-intercept / slope))]


#: name -> (function, parameter names, parameter units, first guess from (heights,
#: speeds, **fixed)); the keyword arguments of a function not in its names are fixed.
PROFILES = {
    "power_law": (power_law_profile, ("reference_speed", "shear"), ("m s-1", "1"),
                  _power_law_guess),
    "log_law": (log_law_profile, ("friction_velocity", "roughness_length"), ("m s-1", "m"),
                _log_law_guess),
}
