"""The measurement model of a scan in motion: each beam at its own time, attitude and
position; the INS sampled and read at the lidar's time stamps; point-wise correction.

This is :func:`uq.physics.measurement.measurement_model` for a scene with
``time_resolved`` set (:class:`uq.physics.scene.TimeResolved`); the static model is
untouched. Per trial:

1. The beams are measured one after another (:mod:`uq.physics.timing`); at each
   measurement time (the time stamp, or the quadrature nodes of the dwell) the platform
   has the attitude R(t), the lidar the position and velocity of
   :func:`uq.physics.motion.platform_kinematics` (static ship + harmonic motion + lever
   arm). The true radial velocity at gate g is ``b(t) . (u(z) - v_lidar(t))`` with the
   true beam ``b(t) = R(t) b_ship`` and the true height z of the gate point (power-law
   shear; with a probe volume, :mod:`uq.physics.probe`, the horizontal speed weighted
   along ``b(t)`` at its points' heights); with ``dwell_average`` its mean over the
   dwell. Radial noise is added.
2. The INS reports the attitude (with its rates) and the velocity of its own point. It is
   read at ``t + delta`` (clock offset delta): at each beam's time stamp for ``pointwise``,
   at the scan's mid time for the other models (whose one reading takes the
   error of the first beam's: its marginal is the error's distribution); from its samples by ``nearest`` or
   ``linear`` interpolation (:mod:`uq.physics.ins`), or exactly (continuous INS). The
   reading's errors are added: heading, pitch, roll to its Euler angles; ``cog`` turns
   the horizontal velocity, ``sog`` adds along the static course, ``heave`` to the
   vertical velocity (for a level, steady ship exactly the static model's
   ``(sog + e) (cos(cog + e), sin(cog + e))``, without its singularity at sog = 0).
3. ``pointwise``: each beam's radial velocity is freed of the lidar velocity the
   reading implies along the beam it implies, ``v_k + b_k . (v_ins + R'_k r)``, with
   ``b_k = R_k b_ship(configured)``; the wind is the least-squares solution of
   ``b_k . u = ...`` (Matavar 2024, Sec. 3.2 [1]). The other models apply their static
   formula (:mod:`uq.physics.correction`) with the one reading of the scan.

Random inputs beyond the static model's: ``motion_phases`` (n, K, 2), the unit phase
vectors of the random-phase components (:class:`uq.engine.inputs.UniformCircle`);
``ins_clock_offset`` (n,) [s]; ``ins_sample_offset`` (n,) [s], uniform over one INS
period. The model is complex-step safe, so the GUM linearises it about the static
attitude (phases at their mean, 0) with the motion's covariance (:mod:`uq.physics.motion`).

References
----------
.. [1] Matavar, A. (2024). Wind field reconstruction from floating lidars. MSc thesis,
   TU Delft, Sec. 3.2.
"""
import numpy as np

from uq import complexstep
from uq.physics import wind
from uq.physics.beams import beam_unit_vectors, least_squares_operator, slant_distances
from uq.physics.correction import (correction_rotation, pointwise_wind, removed_velocity,
                                   scan_wind)
from uq.physics.ins import bracket
from uq.physics.motion import platform_kinematics
from uq.physics.probe import PARAMETER_SCALE
from uq.physics.rotation import (attitude_from_matrix_analytic, attitude_matrix,
                                 attitude_matrix_rate, interpolate_rotation,
                                 rotation_about_vertical)
from uq.physics import modelinputs, nacelle
from uq.physics.modelinputs import MOTION, MOTION_COMPILED
from uq.physics.scene import NACELLE_OUTPUTS, SCENE_FIELDS, sample_count, with_held
from uq.physics.timing import dwell_frequency

#: The inputs a scan in motion adds to the static model's (:mod:`uq.physics.modelinputs`).
TIME_RESOLVED_INPUTS = tuple(name for name in modelinputs.names(MOTION)
                             if name not in modelinputs.names(modelinputs.STATIC))
#: Probe parameters with errors (inputs ``lidar_<parameter>``, :mod:`uq.physics.probe`).
PROBE_ERRORS = tuple(PARAMETER_SCALE)


def measurement_model(scene, outputs, scene_draws=False, compiled=True, held=None, **errors):
    """The time-resolved model for a scene or a batch of scenes (evaluated scene by
    scene); same inputs and outputs as :func:`uq.physics.measurement.measurement_model`,
    plus those of :data:`TIME_RESOLVED_INPUTS`.

    `compiled` (bool): where it applies (:func:`uq.physics.fusedmotion.applicable`: real
    inputs, wind outputs), evaluate with the compiled loops of
    :mod:`uq.physics.fusedmotion`, which give the same values to 1e-12 m/s; False forces
    the numpy arrays below. `held`: the wind speed of the same trials with these inputs
    replaced, as the output ``wind_speed_held`` (the compiled loops share the
    kinematics; here the model is evaluated twice).
    """
    if compiled:
        from uq.physics import fusedmotion    # (numba: imported only where it may apply)
        reason = fusedmotion.declined(scene, outputs, errors, scene_draws) or \
            (held is not None and fusedmotion.declined(scene, outputs, {**errors, **held},
                                                       scene_draws))
        if not reason:
            return fusedmotion.measurement_model(scene, outputs, scene_draws, held=held,
                                                 **errors)
        modelinputs.log_fallback(MOTION_COMPILED, reason)
    if held is not None:
        return with_held(measurement_model(scene, outputs, scene_draws, False, **errors),
                         measurement_model(scene, ("wind_speed",), scene_draws, False,
                                           **{**errors, **held}))
    modelinputs.check_names(MOTION, errors)
    shape = scene.shape
    if not shape:
        return single_scene(scene, outputs, **errors)
    results = {}
    # scenes that differ only in the wind (a sweep of its direction, say) share the same
    # draws: their platform, beams and INS readings are computed once
    platforms = None if scene_draws else {}
    for index in np.ndindex(*shape):
        one = _scene_at(scene, index)
        mine = {k: (v[(slice(None),) + index] if scene_draws and np.ndim(v) > 1 else v)
                for k, v in errors.items()}
        for q, value in single_scene(one, outputs, platforms=platforms, **mine).items():
            results.setdefault(q, []).append(value)
    n = max(v[0].shape[0] for v in results.values())
    return {q: np.stack([np.broadcast_to(v, (n,) + v.shape[1:]) for v in values], axis=1)
            .reshape((n,) + shape + values[0].shape[1:]) for q, values in results.items()}


def _scene_at(scene, index):
    import dataclasses
    fields = {name: np.asarray(getattr(scene, name))[index] if np.ndim(getattr(scene, name))
              else getattr(scene, name) for name in SCENE_FIELDS}
    return dataclasses.replace(scene, **{k: float(np.real(v)) if np.isrealobj(v) else v
                                         for k, v in fields.items()})


#: The scene fields the wind alone depends on; the others fix the platform and the beams.
WIND_FIELDS = ("wind_speed", "wind_direction", "vertical_wind", "shear", "reference_height")


def single_scene(scene, outputs, *, platforms=None, **errors):
    """The model for one scene (scalar fields); outputs of shape (n, g) or (n, b, g).
    `platforms`: a dict in which the wind-free part of a scene (:func:`_platform`) is
    kept for the next scene of the same draws that differs only in
    :data:`WIND_FIELDS` (the same arrays, computed once)."""
    resolved = scene.time_resolved
    n = sample_count(errors)
    err = {name: np.asarray(errors.get(name, 0.0)) for name in set(errors) | set(modelinputs.names(MOTION))}
    key = None if platforms is None else tuple(
        getattr(scene, name) for name in SCENE_FIELDS if name not in WIND_FIELDS)
    platform = None if key is None else platforms.get(key)
    if platform is None:
        platform = _platform(scene, resolved, err, n, outputs)
        if key is not None:
            platforms.clear()                # (scenes come grouped: keep the last one)
            platforms[key] = platform
    measured, heights = _measure(scene, platform, err)
    unit_vectors = scene.nominal_unit_vectors()                        # configured, (b, 3)
    horizontal = scene.horizontal_only
    rotation, velocity = platform["rotation"], platform["velocity"]
    believed, along = platform["believed"], platform["along"]
    if scene.correction == "pointwise":
        wind_vector = pointwise_wind(measured, unit_vectors, rotation, velocity, horizontal)
    elif horizontal:
        if scene.correction == "tilt2d":
            raise ValueError("tilt2d needs beams that determine the 3-D wind")
        wind_vector = pointwise_wind(measured, unit_vectors, rotation[:, None],
                                     velocity[:, None], True)
    else:
        operator = least_squares_operator(unit_vectors)
        wind_vector = scan_wind(measured, scene.correction, operator, rotation, velocity)
    pair = nacelle.level_pair(scene.azimuths) if scene.tilt != 0 and not horizontal else None
    if pair:                   # a nacelle lidar's hub-height wind: its level beams'
        wind_vector = nacelle.hub_height_wind(wind_vector, believed, measured + along, pair)
    result = _outputs(scene, outputs, wind_vector, measured + along, heights)
    if set(outputs) & set(NACELLE_OUTPUTS):
        slant = slant_distances(scene.ranges, scene.half_cone, len(scene.azimuths),
                                scene.vertical_beam)                    # (b, g)
        lidar = scene.lidar_height + np.asarray(platform["lidar_lift"])
        believed_heights = nacelle.believed_heights(lidar, slant, believed)
        extra = nacelle.nacelle_outputs(outputs, wind_vector, result, scene.heading,
                                        believed, measured + along, believed_heights,
                                        nacelle.upper_lower(scene.azimuths))
        n = max(np.shape(v)[0] for v in result.values())
        result.update({q: np.broadcast_to(v, (n,) + np.shape(v)[1:]) for q, v in extra.items()})
    return result


def _platform(scene, resolved, err, n, outputs):
    """What a scene's model computes without the wind: the phases, the platform's
    kinematics at the beams' times, the true beams and their gates' heights (:func:`
    _geometry`), and the INS reading with the correction's rotation and velocity, the
    believed beams and the velocity along them (``along``), and the lidar's lift."""
    # the motion and the INS timing vary over n_time trials (1 when none of their inputs
    # is random): the platform's kinematics are evaluated that many times, not n
    n_time = max([1] + [np.shape(err[k])[0] for k in TIME_RESOLVED_INPUTS if np.ndim(err[k])])
    phases = resolved.motion.unit_phases(_phases(err["motion_phases"], err["motion_window"],
                                                 resolved, n_time))
    phases = np.broadcast_to(phases, (n_time,) + phases.shape[1:])
    platform = _geometry(scene, resolved, phases, err)
    navigation = _navigation(scene, resolved, phases, err, n)
    unit_vectors = scene.nominal_unit_vectors()                        # configured, (b, 3)
    lidar_lift = 0.0                    # the lidar's height above its static one, as read
    if scene.correction == "pointwise":
        rotation, velocity = _pointwise_reading(navigation, resolved)
        believed = (rotation @ unit_vectors[..., None])[..., 0]        # (n, b, 3)
        along = np.sum(believed * velocity, axis=-1)[..., None]
        if set(outputs) & set(NACELLE_OUTPUTS):
            lidar_lift = _lever_arm_lift(scene, resolved, rotation)
    else:
        rotation = correction_rotation(scene.correction, navigation["heading"][:, 0],
                                       navigation["pitch"][:, 0], navigation["roll"][:, 0],
                                       scene.heading)                  # (n, 3, 3)
        velocity = removed_velocity(scene.correction, navigation["velocity"][:, 0])
        believed = (rotation[:, None] @ unit_vectors[..., None])[..., 0]   # (n, b, 3)
        along = np.sum(believed * velocity[:, None, :], axis=-1)[..., None]
    platform.update(rotation=rotation, velocity=velocity, believed=believed, along=along,
                    lidar_lift=lidar_lift)
    return platform


def _lever_arm_lift(scene, resolved, rotation):
    """How far the attitude read, (n, b, 3, 3), lifts the lidar above its height at the
    static attitude through the lever arm r: ``[(R_k - R_static) r]_up`` [m], (n, b).
    (The translation, surge to heave, is not read: the INS reports velocities.)"""
    arm = np.asarray(resolved.motion.lever_arm, dtype=float)
    static = attitude_matrix(scene.heading, scene.pitch, scene.roll) @ arm
    return (rotation @ arm)[..., 2] - static[2]




def _phases(phases, window, resolved, n):
    """The random components' unit phases, (n, K_random, 2): those of random phases (a
    sea, harmonics), then those of a record's window (:attr:`Motion.window`); zeros
    (their mean) for an input not given (the error-free reconstruction)."""
    k = len(resolved.motion.random_components)
    if not k:
        return None
    k_window = resolved.motion.window

    def part(value, size):
        if np.ndim(value):
            return np.broadcast_to(value, (n, size, 2))
        return np.zeros((n, size, 2))
    return np.concatenate([part(phases, k - k_window), part(window, k_window)], axis=-2)


def _geometry(scene, resolved, phases, err):
    """The wind-free part of :func:`_measure`: the platform's kinematics at the beams'
    quadrature times, the true beams (n, b, q, 3), the gates' heights (n, b, q, g), the
    beams' own velocity along them (n, b, q), the quadrature weights (q,) and the
    slant distances (b, g)."""
    timing, motion = resolved.timing, resolved.motion
    n_beams = scene.n_beams
    fastest = dwell_frequency(motion.components)
    times, weights = timing.nodes(n_beams, fastest)                      # (b, q), (q,)
    kin = platform_kinematics(scene, motion, phases, times[None])         # (n', b, q, ...)
    half_cone = scene.half_cone + complexstep.radians(err["lidar_half_cone"])
    misalignment = scene.misalignment + complexstep.radians(err["lidar_misalignment"])
    ship_beams = beam_unit_vectors(np.reshape(half_cone, (-1,)), np.asarray(scene.azimuths),
                                   np.reshape(misalignment, (-1,)), scene.vertical_beam,
                                   scene.tilt)
    ship_beams = ship_beams[:, :, None, :, None]                        # (n', b, 1, 3, 1)
    beams = (kin["attitude"] @ ship_beams)[..., 0]                      # (n, b, q, 3)
    slant = slant_distances(scene.ranges, scene.half_cone, len(scene.azimuths),
                            scene.vertical_beam)                        # (b, g)
    lidar_z = scene.lidar_height + np.reshape(err["lidar_height"], (-1, 1, 1)) \
        + kin["lidar_offset"][..., 2]                                   # (n, b, q)
    heights = lidar_z[..., None] + slant[:, None, :] * beams[..., 2:3]  # (n, b, q, g)
    own = np.sum(beams * kin["lidar_velocity"], axis=-1)                # (n, b, q)
    mean_height = np.einsum("...q,q->...", np.moveaxis(heights, -2, -1), weights)
    return {"beams": beams, "heights": heights, "own": own, "weights": weights,
            "slant": slant, "mean_height": mean_height}


def _measure(scene, platform, err):
    """True radial velocities plus noise, (n, b, g), and the gate heights (n, b, g), on
    the scene's :func:`_platform`."""
    beams, heights, weights = platform["beams"], platform["heights"], platform["weights"]
    speed = wind.power_law_speed(scene.wind_speed, heights, scene.reference_height,
                                 scene.shear) if scene.probe is None else \
        _probe_speed(scene, heights, beams[..., 2:3], platform["slant"][:, None, :], err)
    to_north, to_east = wind.wind_components(1.0, complexstep.degrees(scene.wind_direction))
    along_wind = beams[..., 0] * to_north + beams[..., 1] * to_east     # (n, b, q)
    radial = speed * along_wind[..., None] + (beams[..., 2] * scene.vertical_wind
                                              - platform["own"])[..., None]
    mean_radial = np.einsum("...q,q->...", np.moveaxis(radial, -2, -1), weights)  # (n, b, g)
    return mean_radial + err["lidar_radial_velocity"], platform["mean_height"]


def _probe_speed(scene, heights, vertical, focus, err):
    """The probe-weighted horizontal speed at the probe's points on the true beams at
    their own times (:mod:`uq.physics.probe`); heights (n, b, q, g), vertical (n, b, q, 1),
    focus (b, 1, g); a probe parameter's error (n,) is one per scan."""
    errors = {}
    for key in PROBE_ERRORS:
        value = np.asarray(err.get(f"lidar_{key}", 0.0))
        errors[key] = value.reshape(-1, 1, 1, 1) if value.ndim else value
    return scene.probe.average(lambda z: wind.power_law_speed(
        scene.wind_speed, z, scene.reference_height, scene.shear), heights, vertical, focus,
        errors)


def _navigation(scene, resolved, phases, err, n):
    """INS readings, each (n, k): ``heading``, ``pitch``, ``roll`` [rad] with their
    ``*_rate`` [rad s-1] and ``velocity`` (n, k, 3) [m s-1]; k = n_beams (read at the
    beams' time stamps, ``pointwise``) or 1 (at the scan's mid time)."""
    timing, ins = resolved.timing, resolved.ins
    n_beams = scene.n_beams
    stamps = timing.stamps(n_beams) if scene.correction == "pointwise" else \
        np.array([timing.scan_mid_time(n_beams)])
    n_time = np.shape(phases)[0]
    read = stamps[None, :] + np.reshape(err["ins_clock_offset"], (-1, 1))    # (n', k)
    read = np.broadcast_to(read, (n_time, read.shape[1]))
    state = ins_state(scene, resolved, phases, read, err["ins_sample_offset"], ins)
    k = np.shape(state["heading"])[-1]
    reading = {}
    for key in ("heading", "pitch", "roll"):
        error = _reading_error(err[f"ins_{key}"], k)
        reading[key] = state[key] + complexstep.radians(error)
    for key in ("heading_rate", "pitch_rate", "roll_rate"):
        reading[key] = state[key]
    reading["velocity"] = _velocity_reading(scene, state["velocity"], err, k)
    return reading


def ins_state(scene, resolved, phases, read, sample_offset, ins):
    """The INS's true (error-free) state read at `read` (n, k) [s]: interpolated from its
    samples at ``sample_offset + j / rate``, or exact for a continuous INS. Keys
    ``heading``, ``pitch``, ``roll`` [rad], their ``*_rate`` [rad s-1], ``velocity``
    (n, k, 3) [m s-1] of the INS point."""
    if ins.rate is None:
        kin = platform_kinematics(scene, resolved.motion, phases, read)
        return _state(kin)
    offset = np.broadcast_to(np.reshape(sample_offset, (-1,)), (read.shape[0],)) \
        if np.ndim(sample_offset) else np.full(read.shape[0], sample_offset)
    times, fraction = bracket(read, ins.rate, offset, ins.interpolation)    # (n, k, 2)
    kin = platform_kinematics(scene, resolved.motion, phases, times)
    first = {key: value[..., 0] if key != "attitude" else value[..., 0, :, :]
             for key, value in _state(kin).items()}
    second = {key: value[..., 1] if key != "attitude" else value[..., 1, :, :]
              for key, value in _state(kin).items()}
    if "velocity" in first:
        first["velocity"] = kin["ins_velocity"][..., 0, :]
        second["velocity"] = kin["ins_velocity"][..., 1, :]
    state = {}
    a = fraction
    for key in ("heading_rate", "pitch_rate", "roll_rate"):
        state[key] = (1 - a) * first[key] + a * second[key]
    state["velocity"] = (1 - a[..., None]) * first["velocity"] + a[..., None] * second["velocity"]
    attitude = interpolate_rotation(first["attitude"], second["attitude"], a)
    heading, pitch, roll = attitude_from_matrix_analytic(attitude)
    # the interpolated heading stays on the branch of the samples' (no 2 pi jumps)
    heading = heading + 2 * np.pi * np.round(np.real(first["heading"] - heading) / (2 * np.pi))
    state.update(heading=heading, pitch=pitch, roll=roll)
    return state


def _state(kin):
    return {"heading": kin["heading"], "pitch": kin["pitch"], "roll": kin["roll"],
            "heading_rate": kin["heading_rate"], "pitch_rate": kin["pitch_rate"],
            "roll_rate": kin["roll_rate"], "attitude": kin["attitude"],
            "velocity": kin["ins_velocity"]}


def _reading_error(error, k):
    """An INS error as (n, k): one per scan (n, 1) broadcasts to every reading."""
    error = np.asarray(error)
    if error.ndim == 0:
        return error
    return error if error.ndim == 2 else error[:, None]


def _velocity_reading(scene, velocity, err, k):
    """The INS velocity with its errors: cog turns the horizontal velocity, sog adds along
    the static course, heave adds to the vertical (see the module docstring)."""
    course = np.array([np.cos(scene.cog), np.sin(scene.cog), 0.0])
    sog = _reading_error(err["ins_sog"], k)
    v = velocity + np.asarray(sog)[..., None] * course
    turned = rotation_about_vertical(complexstep.radians(_reading_error(err["ins_cog"], k)))
    v = (turned @ v[..., None])[..., 0] if np.ndim(turned) > 2 else v @ np.asarray(turned).T
    heave = _reading_error(err["ins_heave"], k)
    return v + np.asarray(heave)[..., None] * np.array([0.0, 0.0, 1.0])


def _pointwise_reading(navigation, resolved):
    """Per-beam rotation (n, b, 3, 3) and lidar velocity (n, b, 3) the reading implies."""
    nav = navigation
    rotation = attitude_matrix(nav["heading"], nav["pitch"], nav["roll"])
    rate = attitude_matrix_rate(nav["heading"], nav["pitch"], nav["roll"],
                                nav["heading_rate"], nav["pitch_rate"], nav["roll_rate"])
    arm = np.asarray(resolved.motion.lever_arm, dtype=float)
    return rotation, nav["velocity"] + rate @ arm


def _outputs(scene, outputs, wind_vector, corrected_radial, heights):
    result = wind.wind_outputs(wind_vector, outputs)
    if "radial_velocity" in outputs:
        result["radial_velocity"] = corrected_radial
    if "gate_height" in outputs:
        result["gate_height"] = np.mean(heights[..., :len(scene.azimuths), :], axis=-2)
    n = max(np.shape(v)[0] for v in result.values())
    return {q: np.broadcast_to(v, (n,) + np.shape(v)[1:]) for q, v in result.items()}



