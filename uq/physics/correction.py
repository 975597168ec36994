"""Motion-corrected DBS wind reconstruction: the four correction models.

The lidar measures radial velocities in its own (ship-fixed) frame. The correction uses
the navigation data the INS reports (which carry errors) and the lidar's configured
(nominal) geometry, and returns the earth-frame wind (north, east, up) [m s-1].

Correction models (``model``):

``none``
    No motion correction: lidar frame assumed level and at the scene's nominal heading;
    ship velocity not removed. ``u = Rz(heading_nominal) A^+ v``.
``yaw``
    Rubio & Gottschall (2022) case i: heading plus horizontal ship velocity,
    ``u = Rz(heading) A^+ v + (sog cos cog, sog sin cog, 0)`` (Eq. 16 [1]).
``tilt2d``
    Their Eq. 13 as written: the full rotation applied to the horizontal DBS components
    only, ``u_h = [R(heading, pitch, roll) P A^+ v]_h + s_h`` with ``P = diag(1, 1, 0)``;
    the lidar-frame vertical component is dropped from the rotation.
``full``
    The full rotation applied to all three lidar-frame components, plus the ship
    velocity including heave: ``u = R A^+ v + (sog cos cog, sog sin cog, heave)``.
``pointwise``
    Each beam corrected with the INS attitude and velocity (lever arm included) read at
    its own time stamp, then least squares (:func:`pointwise_wind`); needs the
    time-resolved model (:mod:`uq.physics.timeresolved`).

The vertical wind of ``none``, ``yaw`` and ``tilt2d`` is the lidar-frame vertical
component (no heave or tilt correction); that of ``full`` is the corrected one.

INS correlation
---------------
Navigation arrays have shape (..., 1) for ``scan`` (one reading for all beams) or
(..., n_beams) for ``beam`` (each beam corrected point-wise with its own reading,
Matavar 2024, Sec. 3.2 [2]). Point-wise correction: beam i's radial velocity is freed
of the ship motion along the direction the correction believes the beam points,
``b_i = v_i + n_i . s_i`` with ``n_i = R_i n_i^lidar``, and the wind is the least-squares
solution of ``n_i . u = b_i``. With all readings equal this is exactly the scan formula
above (least squares commutes with a common rotation); the tests check it. For
``tilt2d`` the point-wise ``full`` estimate is then projected as in Eq. 13 with the
attitude and ship velocity of the beams' mean reading.

To first order, point-wise correction with independent readings gives exactly the
variance of Rubio & Gottschall's Eqs. 8 and 19 (independent radial-velocity errors
``dv_i = dn_i . (u - s) - n_i . ds_i``), which is why ``beam`` is the physical model
that their analytic model approximates.

References
----------
.. [1] Rubio, H. and Gottschall, J. (2022). J. Phys.: Conf. Ser. 2362 012034.
.. [2] Matavar, A. (2024). Wind field reconstruction from floating lidars. MSc thesis,
   TU Delft.
"""
import numpy as np

from uq.physics.modelinputs import Correction
from uq.physics.rotation import apply_matrix, attitude_matrix, rotation_about_vertical

#: The scenario's names of the models of :class:`~uq.physics.modelinputs.Correction`.
CORRECTION_MODELS = tuple(model.key for model in Correction)
#: The models of a static scan (``pointwise`` needs the time-resolved model).
STATIC_CORRECTION_MODELS = tuple(model.key for model in Correction
                                 if model != Correction.POINTWISE)

#: What each correction model does to the lidar-frame wind, and exactly which platform
#: velocity it removes (the results' ``correction_description`` attribute and the scenario
#: reference). "Per scan": one INS reading for all beams, taken at the scan's mid time when
#: the platform moves during the scan (``motion``). The INS reports the velocity of its own
#: point; the lidar, a lever arm r away, moves at that velocity plus omega x r (R'(t) r).
#: Only ``pointwise`` adds omega x r; the per-scan models remove the INS point's velocity.
CORRECTION_DESCRIPTIONS = {
    "none": "no motion correction: the wind is reconstructed in a frame assumed level at "
            "the nominal heading; no platform velocity is removed",
    "yaw": "per scan: rotates the wind by the INS heading and removes the INS's horizontal "
           "velocity (sog, cog); no pitch or roll, no vertical velocity, no lever-arm "
           "velocity omega x r",
    "tilt2d": "per scan: Rubio & Gottschall (2022) Eq. 13, the INS rotation (heading, "
              "pitch, roll) applied to the horizontal lidar-frame components only, and "
              "the INS's horizontal velocity removed; vertical wind uncorrected; no "
              "lever-arm velocity omega x r",
    "full": "per scan: the INS rotation (heading, pitch, roll) applied to all three "
            "lidar-frame components and the INS's velocity removed, heave included; the "
            "velocity of the INS's own point: the lever arm's omega x r is not removed",
    "pointwise": "per beam: each beam corrected with the INS attitude and velocity read at "
                 "its own time stamp, the lidar's velocity taken as the INS's plus the "
                 "lever arm's omega x r at that time, then least squares",
}


def describe_corrections(models):
    """``"model: what it removes; ..."`` for each of `models` (the results' attribute
    ``correction_description``)."""
    return "; ".join(f"{model}: {CORRECTION_DESCRIPTIONS[model]}" for model in models)


def correction_rotation(model, heading, pitch, roll, nominal_heading):
    """Lidar-to-earth rotation the correction model believes [rad in, (..., 3, 3) out]."""
    if model == "none":
        return rotation_about_vertical(np.asarray(nominal_heading) + 0 * heading)
    if model == "yaw":
        return rotation_about_vertical(heading)
    return attitude_matrix(heading, pitch, roll)


def believed_motion(model, navigation, nominal_heading=0.0):
    """(rotation (..., k, 3, 3), ship velocity (..., k, 3)) that correction `model`
    believes from the INS `navigation` (:func:`correction_rotation`,
    :func:`correction_ship_velocity`)."""
    nav = navigation
    return (correction_rotation(model, nav["heading"], nav["pitch"], nav["roll"],
                                nominal_heading),
            correction_ship_velocity(model, nav["sog"], nav["cog"], nav["heave"]))


def correction_ship_velocity(model, sog, cog, heave):
    """Ship velocity (north, east, up) [m s-1] the model removes; shape (..., 3)."""
    zero = 0 * sog
    if model == "none":
        return np.stack([zero, zero, zero], axis=-1)
    vertical = heave + zero if model == "full" else zero + 0 * heave
    return np.stack(np.broadcast_arrays(sog * np.cos(cog), sog * np.sin(cog), vertical),
                    axis=-1)


def reconstruct_wind(radial_velocity, model, lidar_unit_vectors, operator, navigation,
                     nominal_heading=0.0, horizontal_only=False, believed=None):
    """Earth-frame wind from radial velocities under a correction model.

    Parameters
    ----------
    radial_velocity : ndarray, shape (..., n_beams, n_gates)
        Measured radial velocities [m s-1].
    model : {"none", "yaw", "tilt2d", "full"}
    lidar_unit_vectors : ndarray, shape (*S, n_beams, 3)
        Nominal beam vectors in the lidar/ship frame (S: scenes, may be empty).
    operator : ndarray, shape (*S, 3, n_beams)
        Least-squares operator of `lidar_unit_vectors`
        (:func:`uq.beams.least_squares_operator`).
    navigation : dict of ndarray, each shape (..., k)
        INS readings ``heading``, ``pitch``, ``roll`` [rad], ``sog`` [m s-1], ``cog``
        [rad], ``heave`` [m s-1]; k = 1 (scan) or n_beams (beam, point-wise).
    nominal_heading : float or ndarray
        Heading assumed by ``none`` [rad], broadcastable to the navigation arrays.
    horizontal_only : bool
        Two beams of a nacelle lidar: w = 0 assumed, the horizontal wind from the earth-
        frame beams the model believes (:func:`uq.physics.nacelle.horizontal_least_squares`);
        `operator` is not used. ``tilt2d`` (Eq. 13 on a 3-D DBS wind) is refused.
    believed : tuple, optional
        ``(rotation, ship velocity)`` of :func:`believed_motion` for the same `model`,
        `navigation` and `nominal_heading`, where the caller has them already.

    Returns
    -------
    ndarray, shape (..., 3, n_gates)
        Wind (north, east, up) [m s-1].

    Examples
    --------
    A level four-beam DBS at rest (28 deg half-cone) in a 10 m/s wind from the north
    measures ``n . u`` on each beam; ``full`` reconstructs the wind exactly:

    >>> import numpy as np
    >>> from uq.physics.beams import beam_unit_vectors, least_squares_operator
    >>> beams = beam_unit_vectors(np.deg2rad(28.0), np.deg2rad([0, 90, 180, 270]), 0.0,
    ...                           False)
    >>> wind = np.array([-10.0, 0.0, 0.0])                  # blowing to the south
    >>> radial = (beams @ wind)[:, None]                      # (beams, 1 gate)
    >>> still = {k: np.zeros(1) for k in ("heading", "pitch", "roll", "sog", "cog", "heave")}
    >>> np.round(reconstruct_wind(radial, "full", beams, least_squares_operator(beams),
    ...                           still)[:, 0], 12) + 0.0
    array([-10.,   0.,   0.])
    """
    nav = navigation
    rotation, ship = believed or believed_motion(model, nav, nominal_heading)
    if horizontal_only:
        if model == "tilt2d":
            raise ValueError("tilt2d needs beams that determine the 3-D wind")
        return _pointwise_correction(radial_velocity, lidar_unit_vectors, rotation, ship, True)
    if rotation.shape[-3] == 1 and ship.shape[-2] == 1:    # one reading for all beams
        return _scan_correction(radial_velocity, model, operator, rotation[..., 0, :, :],
                                ship[..., 0, :])
    wind = _pointwise_correction(radial_velocity, lidar_unit_vectors, rotation, ship)
    if model != "tilt2d":
        return wind
    mean = {key: np.mean(value, axis=-1) for key, value in nav.items()}
    mean_rotation = attitude_matrix(mean["heading"], mean["pitch"], mean["roll"])
    mean_ship = correction_ship_velocity(model, mean["sog"], mean["cog"], mean["heave"])
    lidar_relative = np.swapaxes(mean_rotation, -1, -2) @ (wind - mean_ship[..., :, None])
    return _horizontal_rotation(mean_rotation, lidar_relative, mean_ship)


def _scan_correction(radial_velocity, model, operator, rotation, ship_velocity):
    """Eq. 13 [1]: u = R P u_lidar + s, with one navigation reading per scan."""
    if rotation.size == 9:
        # one rotation for every sample (no heading or attitude error): folded into the
        # least-squares operator, one matrix product per sample instead of two
        return apply_matrix(_earth_operator(model, rotation.reshape(3, 3), operator),
                            radial_velocity) + ship_velocity[..., :, None]
    lidar_wind = apply_matrix(operator, radial_velocity)        # Eqs. 14-15, (..., 3, g)
    if model == "full":
        return apply_matrix(rotation, lidar_wind) + ship_velocity[..., :, None]
    return _horizontal_rotation(rotation, lidar_wind, ship_velocity)


def _earth_operator(model, rotation, operator):
    """Radial velocities -> earth-frame wind for a fixed rotation, shape (*S, 3, b):
    ``R A^+`` (full) or the horizontal rows ``R_hh A^+_h`` over the lidar-frame
    vertical row (Eq. 13 [1], as :func:`_horizontal_rotation`)."""
    if model == "full":
        return rotation @ operator
    horizontal = rotation[:2, :2] @ operator[..., :2, :]
    return np.concatenate([horizontal, operator[..., 2:3, :]], axis=-2)


def _horizontal_rotation(rotation, lidar_wind, ship_velocity):
    """Eq. 13 [1] on the horizontal lidar components; keeps the lidar-frame vertical.

    ``[R P u]_h = R[:2, :2] u_h`` since P = diag(1, 1, 0) drops the third column of R.
    """
    earth = apply_matrix(rotation[..., :2, :2], lidar_wind[..., :2, :]) \
        + ship_velocity[..., :2, None]
    vertical = np.broadcast_to(lidar_wind[..., 2:3, :], earth.shape[:-2] + (1, earth.shape[-1]))
    return np.concatenate([earth, vertical], axis=-2)


def scan_wind(radial_velocity, model, operator, rotation, ship_velocity):
    """Wind from one reading per scan given as a rotation (the model's, from
    :func:`correction_rotation`, shape (..., 3, 3)) and the ship velocity the model
    removes (:func:`removed_velocity`, shape (..., 3)); shape (..., 3, n_gates)."""
    return _scan_correction(radial_velocity, model, operator, rotation, ship_velocity)


def removed_velocity(model, velocity):
    """The part of an INS velocity (..., 3) [m s-1] a correction model removes: none of
    it (``none``), the horizontal (``yaw``, ``tilt2d``), all of it (``full``,
    ``pointwise``); as :func:`correction_ship_velocity` does from sog, cog and heave."""
    velocity = np.asarray(velocity)
    if model == "none":
        return 0 * velocity
    if model in ("full", "pointwise"):
        return velocity
    return velocity * np.array([1.0, 1.0, 0.0])


def pointwise_wind(radial_velocity, lidar_unit_vectors, rotation, ship_velocity,
                   horizontal_only=False):
    """Least squares on point-wise corrected beams, each with its own reading (Matavar
    2024, Sec. 3.2 [2]).

    Parameters
    ----------
    radial_velocity : ndarray, shape (..., b, g) [m s-1]
    lidar_unit_vectors : ndarray, shape (b, 3)
        Configured beams in the lidar frame.
    rotation : ndarray, shape (..., b, 3, 3)
        Each beam's lidar-to-earth rotation as read.
    ship_velocity : ndarray, shape (..., b, 3)
        Each beam's lidar velocity as read [m s-1].
    horizontal_only : bool
        w = 0 assumed, the horizontal wind alone (a 2-beam nacelle lidar).

    Returns
    -------
    ndarray, shape (..., 3, g)
    """
    return _pointwise_correction(radial_velocity, lidar_unit_vectors, rotation, ship_velocity,
                                 horizontal_only)


def _pointwise_correction(radial_velocity, lidar_unit_vectors, rotation, ship_velocity,
                          horizontal_only=False):
    """Least squares on point-wise corrected beams, each with its own reading (with
    `horizontal_only`, w = 0 and the horizontal components alone)."""
    beams = (rotation @ lidar_unit_vectors[..., None])[..., 0]     # (..., b, 3)
    ship_along_beam = np.sum(beams * ship_velocity, axis=-1)       # (..., b)
    corrected = radial_velocity + ship_along_beam[..., None]       # (..., b, g)
    if horizontal_only:
        from uq.physics.nacelle import horizontal_least_squares
        return horizontal_least_squares(beams, corrected)
    beams_t = np.swapaxes(beams, -1, -2)                           # (..., 3, b)
    return np.linalg.solve(beams_t @ beams, beams_t @ corrected)
