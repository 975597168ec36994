"""Wind vector conventions and the power-law wind profile.

Conventions (also in the README and docs/scenario.md): wind direction is meteorological, the direction the
wind blows *from*, clockwise from north in [0, 360) deg. The horizontal wind vector in the
earth frame (north, east) is ``(-speed cos(direction), -speed sin(direction))``
(Rubio & Gottschall 2022, Eqs. 4-5): a wind from the north (0 deg) blows towards the
south. Vertical wind is positive upwards.

All functions work on arrays (broadcast) and are complex-step safe.

References
----------
.. [1] Rubio, H. and Gottschall, J. (2022). J. Phys.: Conf. Ser. 2362 012034.
"""
import numpy as np

from uq import complexstep
from uq.constants import FULL_CIRCLE_DEG


def wind_components(speed, direction):
    """Earth-frame horizontal wind (north, east) [m s-1] from speed and "from" direction.

    Parameters
    ----------
    speed : array_like
        Horizontal wind speed [m s-1].
    direction : array_like
        Meteorological wind direction [deg], clockwise from north, "from".

    Returns
    -------
    north, east : ndarray
        [m s-1]. Eqs. 4-5 [1].

    Examples
    --------
    A 10 m/s wind from the west (270 deg) blows to the east:

    >>> north, east = wind_components(10.0, 270.0)
    >>> round(float(north), 12), round(float(east), 12)
    (0.0, 10.0)
    """
    direction_rad = complexstep.radians(direction)
    return -speed * np.cos(direction_rad), -speed * np.sin(direction_rad)


def wind_speed(north, east):
    """Horizontal wind speed [m s-1] of earth-frame components [m s-1]."""
    return complexstep.hypot(north, east)


def wind_direction(north, east):
    """Meteorological ("from") wind direction [deg] in [0, 360) of (north, east) [m s-1].

    Inverse of :func:`wind_components`: ``atan2(-east, -north)``. (Eq. 18 of [1],
    ``atan(v/u)``, gives the direction the wind blows *to*, modulo 180 deg; this is the
    corrected form.) Undefined (returned as 0) for zero wind.

    Examples
    --------
    Wind blowing to the south comes from the north; to the east, from the west:

    >>> float(wind_direction(-5.0, 0.0)), float(wind_direction(0.0, 5.0))
    (0.0, 270.0)
    >>> import numpy as np
    >>> north, east = wind_components(8.0, np.array([10.0, 200.0, 359.0]))
    >>> np.round(wind_direction(north, east), 9)
    array([ 10., 200., 359.])
    """
    angle = complexstep.degrees(complexstep.arctan2(-east, -north))
    return complexstep.mod(angle, FULL_CIRCLE_DEG)


def wind_outputs(wind_vector, outputs):
    """The wind outputs named in `outputs` of reconstructed earth-frame wind vectors
    (..., 3, gates) [m s-1]: ``wind_speed`` [m s-1], ``wind_direction`` [deg] ("from"),
    ``vertical_wind`` [m s-1], each (..., gates)."""
    north, east, up = wind_vector[..., 0, :], wind_vector[..., 1, :], wind_vector[..., 2, :]
    result = {}
    if "wind_speed" in outputs:
        result["wind_speed"] = wind_speed(north, east)
    if "wind_direction" in outputs:
        result["wind_direction"] = wind_direction(north, east)
    if "vertical_wind" in outputs:
        result["vertical_wind"] = up
    return result


def power_law_speed(speed_ref, height, reference_height, exponent):
    """Power-law wind profile U(z) = U_ref (z / z_ref)^alpha [m s-1].

    Parameters
    ----------
    speed_ref : array_like
        Speed at `reference_height` [m s-1].
    height, reference_height : array_like
        Heights above sea level [m]. Non-positive heights are outside the model's
        domain and give NaN.
    exponent : array_like
        Shear exponent alpha [1].
    """
    height = np.asarray(height)
    valid = complexstep.real_part(height) > 0
    safe = np.where(valid, height, reference_height)
    return np.where(valid, speed_ref * (safe / reference_height) ** exponent, np.nan)
