"""The ship-lidar measurement model: true scene -> measured radial velocities -> wind.

One function, :func:`measurement_model`, is the model the Monte Carlo engine and the GUM
propagate. Its random inputs are *errors* (deviations from the nominal scene), declared
with their units and shapes in :mod:`uq.physics.modelinputs` (the rows whose models
include ``static``): the INS errors ``ins_heading`` ... ``ins_heave`` (n, k) [deg, m s-1],
the geometry errors ``lidar_half_cone``, ``lidar_misalignment`` (n,) [deg] and
``lidar_height`` (n,) [m], the radial-velocity noise ``lidar_radial_velocity``
(n, beams, gates) [m s-1], and the probe's parameters' errors ``lidar_gate_length`` ...
(n,) in scenario units. A name the model does not implement is refused (ValueError).

k = 1 when INS errors are shared by the beams of a scan (``scan``) and k = n_beams when
each beam has its own reading (``beam``). Missing inputs are zero.

By default every scene of a batch sees the same draws (common random numbers). With
``scene_draws=True`` the errors carry the scene axes instead, shape (n, *S, ...) (INS
errors (n, *S, k)): independent draws per scene, as for the records of a measurement
campaign (:mod:`uq.golden.campaign`).

A height error moves every range gate with the lidar: the reconstruction still believes
the configured heights, so under shear it reads the wind of another height.

The *true* radial velocities use the true attitude and ship velocity, the true
geometry (configured + error), and the true wind at each beam's true height (power-law
shear; the heights follow from the attitude). Reconstruction uses the INS readings
(true + error) and the configured geometry, under the chosen correction model
(:mod:`uq.physics.correction`).

The function is vectorised over samples and complex-step safe, so the GUM Jacobian is
exact (:mod:`uq.engine.gum`). It is also vectorised over *scenes*: the numeric fields of a
:class:`Scene` may be arrays of one common shape S (a batch of scenes that share their
structure: beams, gates, correction). Outputs then have shape (n, *S, ...), and every
scene sees the same error draws (common random numbers). Quantities that do not depend
on the errors (nominal beam vectors, least-squares operator, slant distances) are
computed once per scene, not per sample.

With a probe volume (``scene.probe``, :mod:`uq.physics.probe`) the horizontal wind
speed in each true radial velocity is its weighted mean along the true beam (a
quadrature; the compiled models evaluate the same quadrature, :mod:`uq.physics.fusedprobe`,
and leave a probe's complex step to this model).

The output ``gate_height`` is the mean true height of the slanted beams at each range
gate [m]: the height the reconstructed horizontal wind belongs to, which a tilted lidar
or a half-cone error moves away from the nominal ``lidar_height + range``.
"""
import numpy as np

from uq import complexstep

from uq.physics import probe as probe_volume
from uq.physics import wind
from uq.physics.beams import beam_unit_vectors, least_squares_operator, slant_distances
from uq.physics.correction import believed_motion, reconstruct_wind
from uq.physics.rotation import attitude_matrix, rotate_vectors
from uq.physics import modelinputs
from uq.physics.modelinputs import STATIC, STATIC_COMPILED
from uq.physics import nacelle
from uq.physics.scene import (ANGULAR_NAVIGATION, NACELLE_OUTPUTS, NAVIGATION, OUTPUTS,
                              sample_count, with_held)

def true_wind(scene, heights, trailing=1):
    """True wind (north, east, up) [m s-1] at `heights` [m] of shape (..., *S, *T) with
    `trailing` = len(T) dimensions after the scenes'; shape heights.shape + (3,)."""
    field = lambda name: scene.field(name, trailing)       # noqa: E731
    speed = wind.power_law_speed(field("wind_speed"), heights, field("reference_height"),
                                 field("shear"))
    north, east = wind.wind_components(speed, complexstep.degrees(field("wind_direction")))
    up = np.zeros_like(north) + field("vertical_wind")
    return np.stack([north, east, up], axis=-1)


def beam_heights(scene, beams_earth, height_error=0.0):
    """True height above sea level of every beam's range gates [m].

    The lidar places gate g at the slant distance ``range_g / cos(half_cone)`` along its
    (configured) cone; the true height follows from the true earth-frame beam and the
    lidar's true height (configured + `height_error`).

    Parameters
    ----------
    beams_earth : ndarray, shape (..., *S, n_beams, 3)
    height_error : float or ndarray, shape (n, *S) or (n, *1)
        True minus configured lidar height [m].

    Returns
    -------
    ndarray, shape (..., *S, n_beams, n_gates)
    """
    slant = slant_distances(scene.ranges, scene.half_cone, len(scene.azimuths),
                            scene.vertical_beam)                        # (*S, b, g)
    lidar = scene.field("lidar_height", 2) + np.asarray(height_error)[..., None, None]
    return lidar + slant * beams_earth[..., 2:3]


def true_radial_velocity(scene, beams_earth, ship_velocity, height_error=0.0, probe=None,
                         probe_errors=None):
    """Radial velocities of the true wind seen from the moving lidar [m s-1].

    Parameters
    ----------
    scene : Scene
    beams_earth : ndarray, shape (..., *S, n_beams, 3)
        True earth-frame beam unit vectors.
    ship_velocity : ndarray, shape (*S, 3)
        True ship velocity (north, east, up) [m s-1].
    height_error : float or ndarray
        True minus configured lidar height [m] (:func:`beam_heights`).
    probe : uq.physics.probe.PulsedProbe or ContinuousWaveProbe, optional
        Range weighting along the beams (with its node count); None: at the gate centre.
    probe_errors : dict, optional
        Errors of the probe's parameters (scenario units), each (n, *S, 1, 1) or scalar.

    Returns
    -------
    radial : ndarray, shape (..., n_beams, n_gates)
        ``n . (u_wind(z) - u_ship)`` (Eq. 2 of Rubio & Gottschall 2022, point-wise; with
        a probe the horizontal speed is its weighted mean along the true beam,
        :mod:`uq.physics.probe`).
    wind_only : ndarray, shape (..., n_beams, n_gates)
        ``n . u_wind(z)``, the motion-free radial wind.
    """
    heights = beam_heights(scene, beams_earth, height_error)            # (..., *S, b, g)
    field = lambda name, trailing: scene.field(name, trailing)          # noqa: E731
    profile = lambda z: wind.power_law_speed(field("wind_speed", 2), z,     # noqa: E731
                                             field("reference_height", 2), field("shear", 2))
    if probe is None:
        speed = profile(heights)
    else:                     # the weighted speed at the probe's points on the true beams
        slant = slant_distances(scene.ranges, scene.half_cone, len(scene.azimuths),
                                scene.vertical_beam)                    # focus, ([*S], b, g)
        speed = probe.average(profile, heights, beams_earth[..., 2:3], slant, probe_errors)
    # n . u(z) = U(z) (n_h . e_wind) + n_up w: the direction of the horizontal wind is the
    # same at every height, so only its speed is evaluated per beam and gate (no stacked
    # (..., b, g, 3) wind vectors)
    to_north, to_east = wind.wind_components(1.0, complexstep.degrees(
        field("wind_direction", 1)))                                    # (*S, 1)
    north, east, up = (beams_earth[..., k] for k in range(3))           # (..., *S, b)
    along_wind = north * to_north + east * to_east
    ship = np.asarray(ship_velocity)[..., None, :]                      # (*S, 1, 3)
    ship_along = north * ship[..., 0] + east * ship[..., 1] + up * ship[..., 2]
    wind_only = speed * along_wind[..., None] + (up * field("vertical_wind", 1))[..., None]
    return wind_only - ship_along[..., None], wind_only


def measurement_model(scene, outputs=OUTPUTS, scene_draws=False, compiled=True, held=None,
                      **errors):
    """Propagate errors through measurement and correction; see the module docstring.

    `scene_draws` (bool): the errors carry the scene axes (independent draws per scene).
    `compiled` (bool): where it applies (:func:`uq.fused.applicable`: one scene, real
    errors, wind outputs), evaluate with the compiled loop of :mod:`uq.physics.fused`, which
    gives the same values to 1e-12; False forces the numpy arrays below. A time-resolved
    scene passes it on (:func:`uq.physics.timeresolved.measurement_model`).
    `held` (dict, optional): inputs by name -> value (a scalar) that replace the given
    ones in a second evaluation of the same trials, whose wind speed is the output
    :data:`~uq.physics.scene.HELD_WIND_SPEED` (e.g. every error but the motion at its
    mean: the motion alone, with the same draws of the motion). The compiled
    time-resolved model shares the platform's kinematics between the two.

    Returns
    -------
    dict
        ``wind_speed`` [m s-1], ``wind_direction`` [deg], ``vertical_wind`` [m s-1], each
        shape (n, *S, n_gates); ``radial_velocity`` [m s-1] (n, *S, n_beams, n_gates), the
        motion-corrected radial velocity along the beam the correction believes in.
    """
    if scene.probe is not None:     # a probe volume: its quadrature's node count, once
        scene = probe_volume.resolve(scene)
    if scene.time_resolved is not None:       # motion within the scan: its own model
        from uq.physics import timeresolved
        return timeresolved.measurement_model(scene, outputs, scene_draws, compiled=compiled,
                                              held=held, **errors)
    if held is not None:                      # a second evaluation, nothing to share
        result = measurement_model(scene, outputs, scene_draws, compiled, **errors)
        return with_held(result, measurement_model(scene, ("wind_speed",), scene_draws,
                                                   compiled, **{**errors, **held}))
    if compiled:
        from uq.physics import fused  # (numba: imported only where it may apply)
        result = fused.evaluate(scene, outputs, scene_draws, errors)
        if result is not None:                  # None: a call the compiled loop does not take
            return result
        modelinputs.log_fallback(STATIC_COMPILED, fused.declined(scene, outputs, errors, scene_draws))
    modelinputs.check_names(STATIC, errors)
    n = sample_count(errors)
    scenes = scene.shape if scene_draws else (1,) * len(scene.shape)
    err = {name: _error_shape(np.asarray(errors.get(name, 0.0)), name, scenes, scene_draws)
           for name in modelinputs.names(STATIC)}
    measured, navigation, beams_earth = _measure(scene, err, (n,) + scenes)
    unit_vectors = scene.nominal_unit_vectors()
    operator = None if scene.horizontal_only else least_squares_operator(unit_vectors)
    believed = believed_motion(scene.correction, navigation, scene.field("heading", 1))
    wind_vector = reconstruct_wind(measured, scene.correction, unit_vectors, operator,
                                   navigation, scene.field("heading", 1),
                                   horizontal_only=scene.horizontal_only, believed=believed)
    result = _outputs(scene, outputs, wind_vector, measured, believed, unit_vectors)
    if "gate_height" in outputs:
        result["gate_height"] = _gate_height(scene, beams_earth, err["lidar_height"])
    return _full_shape(result, (n,) + scene.shape, scene.n_beams)


def _error_shape(value, name, scenes, scene_draws):
    """An error array shaped to broadcast against (n, *S, ...): the scene axes follow the
    sample axis, as ones (common draws) or as given (`scene_draws`)."""
    if value.ndim == 0:          # a missing error stays a scalar: no per-sample rotations
        return value if not name.startswith("ins_") else value + np.zeros((1,) * (
            len(scenes) + 2))
    if scene_draws:
        return value
    if name.startswith("ins_"):                      # INS errors to shape (n, *1, k)
        value = value[:, None] if value.ndim == 1 else value
    return value.reshape(value.shape[:1] + scenes + value.shape[1:])


def _full_shape(result, leading, n_beams):
    """Outputs broadcast to leading + (gates,) or leading + (beams, gates): a scene value
    an output does not depend on (e.g. heave for the true wind) still gives it the axis."""
    return {q: np.broadcast_to(v, leading + ((n_beams,) if q == "radial_velocity" else ())
                               + v.shape[-1:]) for q, v in result.items()}


#: Errors of the probe's parameters (model inputs ``lidar_<parameter>``, scenario units).
PROBE_ERRORS = tuple(probe_volume.PARAMETER_SCALE)

def _measure(scene, err, batch):
    """True radial velocities plus noise, and the INS readings (true + error)."""
    # Without geometry errors the true beams, and so the true radial velocities, are the
    # same for every sample: computed once per scene, shape (*S, b, 3), not (n, *S, b, 3).
    geometry_errors = np.ndim(err["lidar_half_cone"]) + np.ndim(err["lidar_misalignment"])
    zero = np.zeros(batch) if geometry_errors else 0.0                     # (n, *1)
    half_cone = scene.half_cone + complexstep.radians(err["lidar_half_cone"]) + zero
    misalignment = scene.misalignment + complexstep.radians(err["lidar_misalignment"]) + zero
    true_beams = beam_unit_vectors(half_cone, np.asarray(scene.azimuths), misalignment,
                                   scene.vertical_beam, scene.tilt)        # ([n], *S, b, 3)
    attitude = attitude_matrix(scene.heading, scene.pitch, scene.roll)    # (*S, 3, 3)
    beams_earth = rotate_vectors(attitude, true_beams)
    probe_errors = {key: _trailing(err[f"lidar_{key}"], 2) for key in PROBE_ERRORS}
    radial, _ = true_radial_velocity(scene, beams_earth, _ship_velocity(scene),
                                     err["lidar_height"], scene.probe, probe_errors)
    measured = radial + err["lidar_radial_velocity"]
    navigation = {}
    for key in NAVIGATION:
        error = err[f"ins_{key}"]
        error = complexstep.radians(error) if key in ANGULAR_NAVIGATION else error
        navigation[key] = scene.field(key, 1) + error                     # (n, *S, k)
    return measured, navigation, beams_earth


def _trailing(value, count):
    """`value` with `count` axes of length one appended (a scalar stays a scalar)."""
    value = np.asarray(value)
    return value if value.ndim == 0 else value.reshape(value.shape + (1,) * count)


def _gate_height(scene, beams_earth, height_error):
    """Mean true height of the slanted beams per gate [m], shape ([n], *S, n_gates)."""
    slanted = len(scene.azimuths)
    heights = beam_heights(scene, beams_earth, height_error)
    return np.mean(heights[..., :slanted, :], axis=-2)


def _ship_velocity(scene):
    """True ship velocity (north, east, up) [m s-1], shape (*S, 3)."""
    sog, cog, heave = np.broadcast_arrays(scene.sog, scene.cog, scene.heave)
    return np.stack([sog * np.cos(cog), sog * np.sin(cog), heave], axis=-1)


def _outputs(scene, outputs, wind_vector, measured, believed, unit_vectors):
    nacelle_wanted = set(outputs) & set(NACELLE_OUTPUTS)
    pair = nacelle.level_pair(scene.azimuths) if scene.tilt != 0 and \
        not scene.horizontal_only else None
    if "radial_velocity" in outputs or nacelle_wanted or pair:
        corrected, beams = _corrected_radial(measured, believed, unit_vectors,
                                             bool(nacelle_wanted or pair))
    if pair:                   # a nacelle lidar's hub-height wind: its level beams'
        wind_vector = nacelle.hub_height_wind(wind_vector, beams, corrected, pair)
    result = wind.wind_outputs(wind_vector, outputs)
    if "radial_velocity" in outputs:
        result["radial_velocity"] = corrected
    if nacelle_wanted:
        slant = slant_distances(scene.ranges, scene.half_cone, len(scene.azimuths),
                                scene.vertical_beam)                    # (*S, b, g)
        heights = scene.field("lidar_height", 2) + slant * beams[..., 2:3]  # believed
        result.update(nacelle.nacelle_outputs(
            outputs, wind_vector, result, scene.field("heading", 1), beams, corrected,
            heights, nacelle.upper_lower(scene.azimuths)))
    return result


def _corrected_radial(measured, believed, unit_vectors, beams_wanted=True):
    """Radial velocity freed of the believed ship motion, along the believed beam, and
    the believed earth-frame beams (n, *S, b, 3) (None unless `beams_wanted`); `believed`:
    the correction's rotation and ship velocity
    (:func:`uq.physics.correction.believed_motion`)."""
    rotation, ship = believed
    # the ship velocity along each beam, (R u) . s = sum_j u_j (R^T s)_j: R^T s once per
    # reading (n, *S, k), component by component, then a product per beam
    along_ship = 0.0
    for j in range(3):
        turned = rotation[..., 0, j] * ship[..., 0] + rotation[..., 1, j] * ship[..., 1] \
            + rotation[..., 2, j] * ship[..., 2]
        along_ship = along_ship + turned * unit_vectors[..., j]
    corrected = measured + along_ship[..., None]
    if not beams_wanted:
        return corrected, None
    # R u by columns, (n, *S, k|b, 3): the stacked 3 x 3 products of ``R @ u`` written
    # out (numpy's matmul loops per 3 x 3 matrix: 2x slower on a sweep's numpy model)
    beams = (rotation[..., 0] * unit_vectors[..., 0:1] + rotation[..., 1] * unit_vectors[..., 1:2]
             + rotation[..., 2] * unit_vectors[..., 2:3])
    return corrected, np.broadcast_to(beams, corrected.shape[:-1] + (3,))


def true_values(scene, outputs=OUTPUTS):
    """The wind the lidar should measure at each nominal gate height.

    Parameters
    ----------
    scene : Scene
    outputs : iterable of str
        The quantities wanted (the radial velocities, the costly ones, only if named).

    Returns
    -------
    dict
        ``wind_speed``, ``wind_direction`` [deg], ``vertical_wind``, shape (*S, n_gates);
        ``radial_velocity`` (*S, n_beams, n_gates): the motion-free radial wind along the
        true beams at their true heights; ``gate_height`` [m], the nominal gate heights
        ``lidar_height + range`` at which the true wind is given.
    """
    wind_vector = true_wind(scene, scene.gate_heights())
    north, east = wind_vector[..., 0], wind_vector[..., 1]
    truth = {"gate_height": scene.gate_heights() + 0.0 * north,
             "wind_speed": wind.wind_speed(north, east),
             "wind_direction": wind.wind_direction(north, east),
             "vertical_wind": wind_vector[..., 2]}
    if "yaw_misalignment" in outputs:       # the wind's direction from the rotor axis
        truth["yaw_misalignment"] = nacelle.yaw_misalignment(truth["wind_direction"],
                                                             scene.field("heading", 1))
    if "shear_exponent" in outputs:         # the power law's exponent of the scene
        truth["shear_exponent"] = scene.field("shear", 1) + 0.0 * north
    if "radial_velocity" in outputs:
        attitude = attitude_matrix(scene.heading, scene.pitch, scene.roll)
        beams_earth = scene.nominal_unit_vectors() @ np.swapaxes(attitude, -1, -2)
        _, truth["radial_velocity"] = true_radial_velocity(scene, beams_earth,
                                                           np.zeros(scene.shape + (3,)))
    return _full_shape(truth, scene.shape, scene.n_beams)
