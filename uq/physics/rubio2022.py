"""Rubio & Gottschall (2022) analytic GUM model of ship-based lidar, as published.

The paper propagates INS errors (yaw, or pitch and roll; sog; cog) into each beam's
radial velocity (Eqs. 8 and 12), treats the beams as independent, and propagates those
radial-velocity uncertainties through the 4-beam DBS reconstruction (Eqs. 19-20). It does
not propagate the INS errors through the correction step (Eq. 16), and it leaves out
radial-velocity noise, half-cone and misalignment errors, vertical wind, heave and shear
(its Sec. 2.3). :mod:`uq.physics.measurement` is the physical model that does all of that; this
module exists so the two can be compared.

Angles are in radians, speeds in [m s-1]. Beams are N, E, S, W: azimuths 0, 90, 180,
270 deg from the lidar's reference beam. Case i: the lidar's reference beam points at
``gamma`` (clockwise from north) = ship heading + misalignment. Case ii: no yaw; the
angles are the paper's (delta positive bow down, beta positive starboard down), from the
exact mapping of the marine pitch and roll (:func:`uq.rotation.rubio2022_angles_from_attitude`);
the second-order yaw that the different rotation order leaves (-1.75 deg at 10 deg
pitch and roll) has no place in case ii and is dropped, as in the paper.

Misprints in the printed equations (each re-derived here and verified in the tests
against complex-step derivatives of Eqs. 6, 7, 16-18 and of the case ii reconstruction)
---------------------------------------------------------------------------------------
* Eq. 18 ``Theta = atan(v/u)`` gives the direction the wind blows *to*, modulo 180 deg.
  Corrected: ``Theta = atan2(-v, -u)`` (consistent with Eqs. 4-5).
* Eqs. 19-20 print ``u^2 = sum_{i=0}^{n} (U_i dVh/dv_i)``. Corrected:
  ``u^2 = sum_{i=1}^{n} (u_i dVh/dv_i)^2`` (the square is missing; n beams, from 1).
* A.3 ``dv/dsog``: the ``cos(cog)`` term has the wrong sign. Corrected:
  ``-sin(cog)[...E...] - cos(cog)[cos(delta) cos(phi) sin(theta) + sin(delta) cos(theta)]``
  (it must reduce to Eq. 10, ``-sin(theta) cos(cog - phi)``, at zero tilt).
* A.6 and A.8 ``dVh/dv_E``, ``dVh/dv_W``: ``cos(cog - gamma)`` must be
  ``sin(cog - gamma)``: ``dVh/dv_E = (v_E - v_W + 2 sin(theta) sin(cog - gamma) sog) /
  (4 Vh sin^2(theta))``, and A.8 is its negative.
* A.9 and A.11: the sign of the ``sin(beta) sin(cog) sin(delta)`` term is wrong.
  Corrected: ``2 sin(theta) sog (cos(cog) cos(delta) - sin(beta) sin(cog) sin(delta))``.
* A.15 ``dTheta/dv_S = sin(Theta + gamma) / (2 Vh sin(theta))``. Corrected:
  ``-sin(Theta - gamma) / (2 Vh sin(theta))``, the negative of A.13.
* Table B1 lists u_theta = 0.1 deg, but Eqs. 8 and 12 have no half-cone term; the model
  as published ignores it, and so does this module.

Eqs. 9-11, A.1, A.2, A.4, A.5, A.7, A.10, A.12, A.13, A.14, A.16-A.20 are correct as
printed in the plain-text extraction (the LaTeX extraction garbles several of them).

References
----------
.. [1] Rubio, H. and Gottschall, J. (2022). Development of an uncertainty model for
   ship-based lidar measurements. J. Phys.: Conf. Ser. 2362 012034.
"""
import numpy as np

from uq.physics.rotation import rubio2022_angles_from_attitude

#: Beam azimuths of the paper's lidar, N, E, S, W [rad].
RUBIO2022_AZIMUTHS = np.deg2rad([0.0, 90.0, 180.0, 270.0])


def rubio2022_radial_velocity_case_i(speed, direction, sog, cog, yaw, half_cone, azimuth):
    """Motion-affected radial velocity, case i (yaw only) [m s-1]. Eq. 6 [1]."""
    return -np.sin(half_cone) * (speed * np.cos(direction - azimuth - yaw)
                                 + sog * np.cos(cog - azimuth - yaw))          # Eq. 6


def rubio2022_radial_velocity_uncertainty_case_i(speed, direction, sog, cog, yaw,
                                                 half_cone, azimuth, u_yaw, u_sog, u_cog):
    """Radial-velocity standard uncertainty, case i [m s-1]. Eqs. 8-11 [1].

    u_yaw, u_cog [rad], u_sog [m s-1]: standard uncertainties of the INS readings.
    """
    s = np.sin(half_cone)
    d_yaw = -s * (speed * np.sin(direction - azimuth - yaw)
                  + np.sin(cog - azimuth - yaw) * sog)                          # Eq. 9
    d_sog = -s * np.cos(cog - azimuth - yaw)                                    # Eq. 10
    d_cog = s * np.sin(cog - azimuth - yaw) * sog                               # Eq. 11
    return np.sqrt((u_yaw * d_yaw) ** 2 + (u_sog * d_sog) ** 2 + (u_cog * d_cog) ** 2)  # Eq. 8


def _tilted_beam(half_cone, azimuth, delta, beta):
    """North and east components of the case ii tilted beam (brackets of Eq. 7)."""
    st, ct = np.sin(half_cone), np.cos(half_cone)
    north = np.cos(delta) * st * np.cos(azimuth) + np.sin(delta) * ct
    east = (st * (np.cos(beta) * np.sin(azimuth) - np.sin(beta) * np.sin(delta) * np.cos(azimuth))
            + np.sin(beta) * np.cos(delta) * ct)
    return north, east


def rubio2022_radial_velocity_case_ii(speed, direction, sog, cog, delta, beta, half_cone,
                                      azimuth):
    """Motion-affected radial velocity, case ii (pitch and roll) [m s-1]. Eq. 7 [1]."""
    north, east = _tilted_beam(half_cone, azimuth, delta, beta)
    return ((-speed * np.cos(direction) - np.cos(cog) * sog) * north
            - (speed * np.sin(direction) + np.sin(cog) * sog) * east)            # Eq. 7


def rubio2022_radial_velocity_uncertainty_case_ii(speed, direction, sog, cog, delta, beta,
                                                  half_cone, azimuth, u_delta, u_beta,
                                                  u_sog, u_cog):
    """Radial-velocity standard uncertainty, case ii [m s-1]. Eqs. 12, A.1-A.4 [1]."""
    st, ct = np.sin(half_cone), np.cos(half_cone)
    sb, cb, sd, cd = np.sin(beta), np.cos(beta), np.sin(delta), np.cos(delta)
    sp, cp = np.sin(azimuth), np.cos(azimuth)
    north, east = _tilted_beam(half_cone, azimuth, delta, beta)
    cross = speed * np.sin(direction) + np.sin(cog) * sog
    along = -speed * np.cos(direction) - np.cos(cog) * sog
    d_beta = cross * (cb * (sd * cp * st - cd * ct) + sb * sp * st)             # A.1
    d_delta = (-cross * (-sb * ct * sd - sb * cp * st * cd)
               + along * (ct * cd - cp * st * sd))                              # A.2
    d_sog = -np.sin(cog) * east - np.cos(cog) * north                           # A.3 corrected
    d_cog = -np.cos(cog) * sog * east + np.sin(cog) * sog * north               # A.4
    return np.sqrt((u_beta * d_beta) ** 2 + (u_delta * d_delta) ** 2
                   + (u_sog * d_sog) ** 2 + (u_cog * d_cog) ** 2)               # Eq. 12


def rubio2022_reconstruction(radial, sog, cog, half_cone, yaw=0.0, delta=0.0, beta=0.0):
    """Corrected horizontal wind (north, east) from N, E, S, W radial velocities.

    Eqs. 13-16 [1] with ``R = Ryaw(yaw) Rroll(beta) Rpitch(delta)`` applied to the
    horizontal DBS components (case i: delta = beta = 0; case ii: yaw = 0).

    Parameters
    ----------
    radial : array_like, shape (..., 4)
        Radial velocities of the N, E, S, W beams [m s-1].
    """
    radial = np.asarray(radial)
    a = (radial[..., 0] - radial[..., 2]) / (2 * np.sin(half_cone))            # Eq. 14
    b = (radial[..., 1] - radial[..., 3]) / (2 * np.sin(half_cone))            # Eq. 15
    north_tilt = np.cos(delta) * a                                              # Rpitch, Rroll
    east_tilt = np.cos(beta) * b - np.sin(beta) * np.sin(delta) * a
    north = np.cos(yaw) * north_tilt - np.sin(yaw) * east_tilt + sog * np.cos(cog)  # Eq. 16
    east = np.sin(yaw) * north_tilt + np.cos(yaw) * east_tilt + sog * np.sin(cog)
    return north, east


def rubio2022_wind_sensitivities_case_i(radial, speed, direction, sog, cog, yaw, half_cone):
    """dVh/dv_i [1] and dTheta/dv_i [rad s m-1] for N, E, S, W; case i. A.5-A.8, A.13-A.16.

    Returns arrays of shape (..., 4). `speed` and `direction` are the reconstructed
    values (exact at the nominal point for case i).
    """
    radial = np.asarray(radial)
    d_ns = radial[..., 0] - radial[..., 2]
    d_ew = radial[..., 1] - radial[..., 3]
    s = np.sin(half_cone)
    denominator = 4 * speed * s**2
    d_north = (d_ns + 2 * s * np.cos(cog - yaw) * sog) / denominator            # A.5
    d_east = (d_ew + 2 * s * np.sin(cog - yaw) * sog) / denominator             # A.6 corrected
    speed_sens = np.stack([d_north, d_east, -d_north, -d_east], axis=-1)       # A.7, A.8
    t_north = np.sin(direction - yaw) / (2 * speed * s)                         # A.13
    t_east = -np.cos(direction - yaw) / (2 * speed * s)                         # A.14
    direction_sens = np.stack([t_north, t_east, -t_north, -t_east], axis=-1)   # A.15 corr., A.16
    return speed_sens, direction_sens


def rubio2022_wind_sensitivities_case_ii(radial, speed, direction, sog, cog, delta, beta,
                                         half_cone):
    """dVh/dv_i and dTheta/dv_i for N, E, S, W; case ii. A.9-A.12, A.17-A.20 [1]."""
    radial = np.asarray(radial)
    d_ns = radial[..., 0] - radial[..., 2]
    d_ew = radial[..., 1] - radial[..., 3]
    s = np.sin(half_cone)
    sb, cb, sd, cd = np.sin(beta), np.cos(beta), np.sin(delta), np.cos(delta)
    denominator = 4 * speed * s**2
    d_north = (2 * s * sog * (np.cos(cog) * cd - sb * np.sin(cog) * sd)        # A.9 corrected
               - sb * cb * sd * d_ew + d_ns * (sb**2 * sd**2 + cd**2)) / denominator
    d_east = (2 * cb * np.sin(cog) * s * sog
              - sb * cb * sd * d_ns + cb**2 * d_ew) / denominator               # A.10
    speed_sens = np.stack([d_north, d_east, -d_north, -d_east], axis=-1)       # A.11, A.12
    t_north = (np.sin(direction) * cd + np.cos(direction) * sb * sd) / (2 * speed * s)  # A.17
    t_east = -np.cos(direction) * cb / (2 * speed * s)                          # A.18
    direction_sens = np.stack([t_north, t_east, -t_north, -t_east], axis=-1)   # A.19, A.20
    return speed_sens, direction_sens


def rubio2022_combined_uncertainty(sensitivities, radial_uncertainty):
    """Eqs. 19-20 [1], corrected: ``sqrt(sum_i (u_i * c_i)^2)`` over the beams (last axis)."""
    return np.sqrt(np.sum((np.asarray(radial_uncertainty) * sensitivities) ** 2, axis=-1))


def rubio2022_scene_uncertainty(scene, speed, u_heading, u_pitch, u_roll, u_sog, u_cog):
    """The paper's model for a :class:`uq.physics.scene.Scene` (or a batch of scenes).

    Parameters
    ----------
    scene : uq.physics.scene.Scene
        Numeric fields scalars or arrays of the batch shape S.
    speed : float or ndarray, shape S
        True horizontal wind speed at the gate [m s-1].
    u_heading, u_pitch, u_roll, u_cog : float
        Standard uncertainties of the INS angles [rad].
    u_sog : float
        [m s-1].

    Returns
    -------
    dict
        ``wind_speed`` [m s-1], ``wind_direction`` [deg], shape S; ``radial_velocity``
        [m s-1], shape (*S, n_beams) in the scene's beam order (NaN for a vertical beam).
        NaN for the scenes outside the model (:func:`rubio2022_domain_mask`).
    """
    shape = np.broadcast(speed, np.empty(scene.shape)).shape
    order = _beam_order(scene)
    # Eqs. A.5-A.20 divide by Vh: the model has no value for a calm (Vh = 0)
    inside = rubio2022_domain_mask(scene) & (np.asarray(speed) > 0) & np.ones(shape, dtype=bool)
    result = {"wind_speed": np.full(shape, np.nan), "wind_direction": np.full(shape, np.nan),
              "radial_velocity": np.full(shape + (scene.n_beams,), np.nan)}
    if not inside.any():
        return result
    column = lambda value: np.asarray(value)[..., None]      # noqa: E731  against the beams
    speed, direction, sog, cog, cone = (column(v) for v in (
        speed, scene.wind_direction, scene.sog, scene.cog, scene.half_cone))
    with np.errstate(divide="ignore", invalid="ignore"):      # masked out below
        u_radial, sens = _paper_case(scene, speed, direction, sog, cog, cone, column,
                                     u_heading, u_pitch, u_roll, u_sog, u_cog)
    mask = lambda value: np.where(inside, np.broadcast_to(value, shape), np.nan)  # noqa: E731
    result["wind_speed"] = mask(rubio2022_combined_uncertainty(sens[0], u_radial))
    result["wind_direction"] = mask(np.rad2deg(rubio2022_combined_uncertainty(sens[1], u_radial)))
    result["radial_velocity"][..., order] = np.where(inside[..., None], u_radial, np.nan)
    return result


def _paper_case(scene, speed, direction, sog, cog, cone, column, u_heading, u_pitch,
                u_roll, u_sog, u_cog):
    """Case i or ii of the paper for the scene's correction."""
    if scene.correction == "yaw":
        return _case_i(speed, direction, sog, cog, cone,
                                 column(scene.heading + scene.misalignment),
                                 u_heading, u_sog, u_cog)
    _, delta, beta = rubio2022_angles_from_attitude(0.0, scene.pitch, scene.roll)
    return _case_ii(speed, direction, sog, cog, cone, column(delta), column(beta),
                    u_pitch, u_roll, u_sog, u_cog)


def _case_i(speed, direction, sog, cog, cone, yaw, u_heading, u_sog, u_cog):
    """Radial-velocity u (Eq. 8) and wind sensitivities (A.5-A.8, A.13-A.16), case i."""
    args = (speed, direction, sog, cog, yaw, cone, RUBIO2022_AZIMUTHS)
    radial = rubio2022_radial_velocity_case_i(*args)
    u_radial = rubio2022_radial_velocity_uncertainty_case_i(*args, u_heading, u_sog, u_cog)
    sens = rubio2022_wind_sensitivities_case_i(radial, speed[..., 0], direction[..., 0],
                                               sog[..., 0], cog[..., 0], yaw[..., 0],
                                               cone[..., 0])
    return u_radial, sens


def _case_ii(speed, direction, sog, cog, cone, delta, beta, u_pitch, u_roll, u_sog, u_cog):
    """Radial-velocity u (Eq. 12) and wind sensitivities (A.9-A.12, A.17-A.20), case ii."""
    args = (speed, direction, sog, cog, delta, beta, cone, RUBIO2022_AZIMUTHS)
    radial = rubio2022_radial_velocity_case_ii(*args)
    u_radial = rubio2022_radial_velocity_uncertainty_case_ii(*args, u_pitch, u_roll, u_sog,
                                                              u_cog)
    sog, cog, cone, delta, beta = (v[..., 0] for v in (sog, cog, cone, delta, beta))
    north, east = rubio2022_reconstruction(radial, sog, cog, cone, delta=delta, beta=beta)
    speed_rec, direction_rec = np.hypot(north, east), np.arctan2(-east, -north)   # Eq. 17-18
    sens = rubio2022_wind_sensitivities_case_ii(radial, speed_rec, direction_rec, sog, cog,
                                                delta, beta, cone)
    return u_radial, sens


def rubio2022_domain(scene):
    """Which case of the paper covers a single scene: "i", "ii" or None (outside).

    Case i: correction ``yaw``, no pitch or roll. Case ii: correction ``tilt2d`` with the
    lidar's reference beam pointing north (heading + misalignment = 0). Both need the
    four N, E, S, W beams (a vertical beam does not change the horizontal DBS wind).
    Vertical wind, heave and shear are ignored, as in the paper (Sec. 2.3).
    """
    if not bool(rubio2022_domain_mask(scene)):
        return None
    return "i" if scene.correction == "yaw" else "ii"


def rubio2022_domain_mask(scene):
    """Per scene of a batch: is it inside the paper's model (:func:`rubio2022_domain`)?

    Returns
    -------
    ndarray of bool, shape S
    """
    if _beam_order(scene) is None or scene.correction not in ("yaw", "tilt2d") \
            or getattr(scene, "tilt", 0) != 0:          # (a nacelle lidar: outside)
        return np.zeros(scene.shape, dtype=bool)
    if scene.correction == "yaw":
        return (np.asarray(scene.pitch) == 0) & (np.asarray(scene.roll) == 0) \
            & np.ones(scene.shape, dtype=bool)
    yaw = np.mod(np.asarray(scene.heading + scene.misalignment), 2 * np.pi)
    return np.isclose(np.sin(yaw), 0) & (np.cos(yaw) > 0) & np.ones(scene.shape, dtype=bool)


def _beam_order(scene):
    """Indices of the N, E, S, W beams in the scene's beam list, or None."""
    azimuths = np.mod(np.asarray(scene.azimuths), 2 * np.pi)
    if len(azimuths) != 4:
        return None
    order = []
    for target in RUBIO2022_AZIMUTHS:
        match = np.flatnonzero(np.isclose(np.cos(azimuths - target), 1.0, atol=1e-12))
        if match.size != 1:
            return None
        order.append(int(match[0]))
    return np.array(order)
