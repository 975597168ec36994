"""Reconstruction of a nacelle (tilted-mount) lidar: horizontal wind, yaw misalignment and
the vertical shear exponent at each preview distance.

The beams' geometry is that of :mod:`uq.physics.beams` (``lidar.mount.tilt``; clock
positions 0 up, 90 starboard, 180 down, 270 port about the boresight). What each layout
reconstructs, and what it assumes:

2 beams (clock positions 90 and 270: horizontal, +-alpha about the boresight)
    The horizontal wind (north, east) is the least-squares solution of
    ``b_k,h . u_h = c_k`` (b_k the earth-frame beam the correction believes, c_k the
    corrected radial velocity) with **w = 0 assumed**: two beams see no more than two
    components. The output ``vertical_wind`` is that assumed 0.
4 beams (0, 90, 180, 270: up, right, down, left)
    w is the full least squares of :mod:`uq.physics.beams` and
    :mod:`uq.physics.correction`, ``b_k . u = c_k``, assuming the wind is the same at the
    four points (**no shear**: under shear the least squares reads the difference of the
    upper and lower beams as w). The **hub-height** horizontal wind is then that of the
    two level beams (90 and 270, at hub height on a level nacelle) with that w,
    ``b_k,h . u_h = c_k - b_k,up w`` (:func:`hub_height_wind`): the four beams' mean
    would carry the curvature of the profile, ``(U(z_up) + U(z_down)) / 2 < U(hub)``
    (-0.1 m/s at 300 m preview for alpha = 0.14, 10 m/s). In a uniform wind both are the
    full least squares' exactly. The **shear exponent** is read from the upper and lower beams
    assuming **w = 0**: their horizontal speeds ``U_k = c_k / (b_k,h . e)`` (e the unit
    vector of the reconstructed horizontal wind) at their heights ``z_k``::

        alpha_shear = ln(U_up / U_down) / ln(z_up / z_down)            # power law

    The up/down difference measures either w or the shear, not both (their radial
    velocities differ by ``(U_up - U_down) cos(a) cos(gamma) + 2 w sin(a)`` for a level
    nacelle lidar), so each output states its assumption.

Heights of the points are tracked as the correction knows them: ``none`` believes the
level, nominal beams; the corrections with an attitude (``full``, ``pointwise``, ...)
take the earth-frame beam they believe and, for ``pointwise``, the lidar's height lifted
by the lever arm at the attitude read (:func:`believed_heights`).

``wind_direction`` of a nacelle lidar is, as for any lidar, the meteorological direction
("from", clockwise from north) of the reconstructed horizontal wind; ``yaw_misalignment``
is ``wind_direction`` minus the rotor axis (the static heading ``ship.heading``), wrapped
into [-180, 180) deg: positive when the wind comes from starboard of the bow.

References
----------
.. [1] Matavar, A. (2024). Wind field reconstruction from floating lidars. MSc thesis,
   TU Delft, Secs. 3.1.3, 5.1-5.2.
.. [2] Graefe, M., Pettas, V., Gottschall, J. and Cheng, P. W. (2023). Quantification and
   mitigation of nacelle-based lidar measurement uncertainty on floating wind turbines.
   Wind Energ. Sci. 8, 925-946.
"""
import numpy as np

from uq import complexstep
from uq.constants import FULL_CIRCLE_DEG


def horizontal_least_squares(beams_earth, corrected):
    """Horizontal wind with w = 0 assumed: least squares of ``b_k,h . u_h = c_k``.

    Parameters
    ----------
    beams_earth : ndarray, shape (..., b, 3)
        Earth-frame beams the correction believes (north, east, up).
    corrected : ndarray, shape (..., b, g)
        Corrected radial velocities [m s-1].

    Returns
    -------
    ndarray, shape (..., 3, g)
        (north, east, 0) [m s-1].
    """
    horizontal = beams_earth[..., :2]                                  # (..., b, 2)
    transposed = np.swapaxes(horizontal, -1, -2)
    solved = np.linalg.solve(transposed @ horizontal, transposed @ corrected)   # (..., 2, g)
    zero = np.zeros_like(solved[..., :1, :])
    return np.concatenate([solved, zero], axis=-2)


def level_pair(clock_positions):
    """Indices of the two level beams (clock 90 and 270), or None (not both there)."""
    found = [k for k, phi in enumerate(clock_positions) if abs(np.cos(phi)) < 1e-9]
    return tuple(found) if len(found) == 2 else None


def hub_height_wind(wind_vector, beams_earth, corrected, pair):
    """The horizontal wind of the level beams `pair` with the vertical wind of
    `wind_vector` (the full least squares): ``b_k,h . u_h = c_k - b_k,up w``.

    Parameters
    ----------
    wind_vector : ndarray, shape (..., 3, g)
    beams_earth : ndarray, shape (..., b, 3)
        Believed earth-frame beams.
    corrected : ndarray, shape (..., b, g)
    pair : tuple of int

    Returns
    -------
    ndarray, shape (..., 3, g)
        (north, east) of the level beams, up of `wind_vector`.
    """
    index = list(pair)
    beams = beams_earth[..., index, :]                                    # (..., 2, 3)
    vertical = wind_vector[..., 2:3, :]                                   # (..., 1, g)
    rhs = corrected[..., index, :] - beams[..., 2:3] * vertical           # (..., 2, g)
    horizontal = np.linalg.solve(beams[..., :2], rhs)                    # (..., 2, g)
    vertical = np.broadcast_to(vertical, horizontal.shape[:-2] + vertical.shape[-2:])
    return np.concatenate([horizontal, vertical], axis=-2)


def upper_lower(clock_positions):
    """Indices of the upper and lower beams: those nearest clock 0 (up) and 180 (down).

    Parameters
    ----------
    clock_positions : sequence of float, [rad]

    Returns
    -------
    tuple of int or None
        None where no two beams differ in height (e.g. the 2-beam 90/270 layout).
    """
    vertical = np.cos(np.asarray(clock_positions, dtype=float))
    upper, lower = int(np.argmax(vertical)), int(np.argmin(vertical))
    if vertical[upper] - vertical[lower] < 1e-9:   # level beams: cos 90 = 6e-17 to rounding
        return None
    return upper, lower


def believed_heights(lidar_height, slant, beams_earth):
    """Heights of the gate points as the correction believes them [m].

    Parameters
    ----------
    lidar_height : array_like, shape (...) or (..., b)
        Lidar height the correction believes [m].
    slant : ndarray, shape (b, g)
        Distance along each beam [m] (:func:`uq.physics.beams.slant_distances`).
    beams_earth : ndarray, shape (..., b, 3)

    Returns
    -------
    ndarray, shape (..., b, g)
    """
    lidar = np.asarray(lidar_height)
    lidar = lidar[..., None] if lidar.ndim and lidar.shape[-1] == beams_earth.shape[-2] \
        else lidar[..., None, None]
    return lidar + slant * beams_earth[..., 2:3]


def shear_exponent(wind_vector, beams_earth, corrected, heights, pair):
    """Power-law exponent from the upper and lower beams, w = 0 assumed (module docstring).

    Parameters
    ----------
    wind_vector : ndarray, shape (..., 3, g)
        Reconstructed wind (north, east, up) [m s-1]: its horizontal direction.
    beams_earth : ndarray, shape (..., b, 3)
        Believed earth-frame beams.
    corrected : ndarray, shape (..., b, g)
        Corrected radial velocities [m s-1].
    heights : ndarray, shape (..., b, g)
        Believed heights of the points [m] (:func:`believed_heights`).
    pair : tuple of int
        (upper, lower) beam indices (:func:`upper_lower`).

    Returns
    -------
    ndarray, shape (..., g)
        alpha [1]; NaN where a speed or height is not positive (outside the power law).
    """
    north, east = wind_vector[..., 0, :], wind_vector[..., 1, :]
    speed = np.sqrt(north * north + east * east)
    upper, lower = pair
    speeds = []
    for k in (upper, lower):
        along = (beams_earth[..., k, 0:1] * north + beams_earth[..., k, 1:2] * east) / speed
        speeds.append(corrected[..., k, :] / along)      # U_k = c_k / (b_k,h . e)
    ratio_speed = speeds[0] / speeds[1]
    ratio_height = heights[..., upper, :] / heights[..., lower, :]
    valid = (complexstep.real_part(ratio_speed) > 0) & (complexstep.real_part(ratio_height) > 0)
    safe = lambda x: np.where(valid, x, 2.0)                # noqa: E731 (log of 2: finite)
    return np.where(valid, np.log(safe(ratio_speed)) / np.log(safe(ratio_height)), np.nan)


def yaw_misalignment(wind_direction, heading):
    """Wind direction relative to the rotor axis [deg], in [-180, 180).

    Parameters
    ----------
    wind_direction : array_like
        Meteorological wind direction ("from", clockwise from north) [deg].
    heading : array_like
        Rotor axis: the static heading of the bow, clockwise from north [rad].

    Examples
    --------
    >>> import numpy as np
    >>> float(yaw_misalignment(350.0, np.deg2rad(10.0)))
    -20.0
    """
    half = FULL_CIRCLE_DEG / 2
    relative = wind_direction - complexstep.degrees(heading) + half
    return complexstep.mod(relative, FULL_CIRCLE_DEG) - half


def nacelle_outputs(outputs, wind_vector, wind_result, heading, beams_earth, corrected,
                    heights, pair):
    """The outputs of :data:`uq.physics.scene.NACELLE_OUTPUTS` named in `outputs`.

    `wind_result` holds ``wind_direction`` when it was computed (else it is computed
    here); `heading` [rad] broadcasts against (..., g); the other arrays as
    :func:`shear_exponent`. Returns a dict of (..., g) arrays.
    """
    from uq.physics import wind
    result = {}
    if "yaw_misalignment" in outputs:
        direction = wind_result.get("wind_direction")
        if direction is None:
            direction = wind.wind_direction(wind_vector[..., 0, :], wind_vector[..., 1, :])
        result["yaw_misalignment"] = yaw_misalignment(direction, heading)
    if "shear_exponent" in outputs:
        result["shear_exponent"] = shear_exponent(wind_vector, beams_earth, corrected,
                                                  heights, pair)
    return result
