"""The measurement model fused into one compiled loop over trials (numba).

:func:`uq.measurement.measurement_model` is written with numpy array operations: every
step (beam vectors, heights, the power law, radial velocities, the correction) makes a
pass over arrays of shape (trials, beams, gates). For plain Monte Carlo those passes,
not the arithmetic, set the speed. This module computes the same quantities trial by
trial in a single compiled loop, so each trial's intermediate values stay in registers.

It is a second, independent implementation of the physics (scalar code, written from
the conventions of :mod:`uq.rotation`, :mod:`uq.beams`, :mod:`uq.wind` and
:mod:`uq.correction`, not from the array code); ``tests/test_fused.py`` checks that the
two agree to 1e-12 for every correction model and error source. The numpy model stays
the reference: it alone runs complex-step (the GUM Jacobian), batches of scenes
(vectorised sweeps), point-wise correction (``ins.correlation: beam``), independent
draws per scene, and the outputs ``radial_velocity`` and ``gate_height``;
:func:`applicable` says when the fused loop is used.

Conventions (as in the modules named above): earth frame (north, east, up); ship frame
(bow, starboard, up); body-to-earth ``Rz(heading) Ry(pitch) Rx(roll)``, pitch positive
bow up, roll positive starboard down; beams ``(sin t cos(m + a), sin t sin(m + a), cos t)``;
wind direction "from", clockwise from north; radial velocity positive away from the lidar.

References
----------
.. [1] Rubio, H. and Gottschall, J. (2022). J. Phys.: Conf. Ser. 2362 012034.
.. [2] Lam, S. K., Pitrou, A. and Seibert, S. (2015). Numba: a LLVM-based Python JIT
   compiler. Proc. LLVM-HPC 2015.
"""
import dataclasses
import math

import numpy as np
from numba import njit

from .correction import CORRECTION_MODELS
from .measurement import NAVIGATION, SCENE_FIELDS

#: Outputs the fused loop computes; any other requested output uses the numpy model.
FUSED_OUTPUTS = ("wind_speed", "wind_direction", "vertical_wind")
_DEG = math.pi / 180.0
_RAD_TO_DEG = 180.0 / math.pi
_ERRORS = ("lidar_half_cone", "lidar_misalignment", "lidar_height") + tuple(
    f"ins_{key}" for key in NAVIGATION)


def applicable(scene, outputs, errors, scene_draws=False):
    """Can the fused loop evaluate this call of the measurement model?

    One scene (no batch of scenes), common draws, only :data:`FUSED_OUTPUTS`, real
    errors, one INS reading per scan (``scan``) and radial noise of shape (n, beams,
    gates) if any.
    """
    if np.prod(scene.shape) != 1 or scene_draws or not set(outputs) <= set(FUSED_OUTPUTS):
        return False
    if any(np.iscomplexobj(value) for value in errors.values()):
        return False
    if any(np.ndim(errors.get(f"ins_{key}", 0.0)) > 1 and np.shape(errors[f"ins_{key}"])[1:] != (1,)
           for key in NAVIGATION):
        return False                                  # one reading per beam (``beam``)
    noise = errors.get("lidar_radial_velocity")
    return noise is None or np.ndim(noise) == 3


def measurement_model(scene, outputs, **errors):
    """The fused equivalent of :func:`uq.measurement.measurement_model` (same inputs,
    degrees for angular errors; same outputs, each shape (n, *S, n_gates) for a batch
    of S = one scene, e.g. (1,))."""
    shape = scene.shape
    scene = dataclasses.replace(scene, **{name: float(np.ravel(getattr(scene, name))[0])
                                          for name in SCENE_FIELDS})
    n = max([len(np.atleast_1d(v)) for v in errors.values()] + [1])
    columns = [_column(errors.get(name)) for name in _ERRORS]
    noise = errors.get("lidar_radial_velocity")
    noise = np.zeros((1, scene.n_beams, len(scene.ranges))) if noise is None \
        else np.require(noise, dtype=float, requirements="W")
    speed, direction, vertical = (np.empty((n, len(scene.ranges))) for _ in range(3))
    _trials(_scene_constants(scene), *columns, noise,
            CORRECTION_MODELS.index(scene.correction), "wind_direction" in outputs,
            speed, direction, vertical)
    result = {"wind_speed": speed, "wind_direction": direction, "vertical_wind": vertical}
    return {q: result[q].reshape((n,) + shape + (len(scene.ranges),)) for q in outputs}


def _column(value):
    """An error as a float array (any stride) of length n (per trial) or 1 (absent or
    constant: the loop then reads element 0)."""
    if value is None:
        return np.zeros(1)
    value = np.asarray(value, dtype=float)
    value = value if value.ndim == 1 else np.atleast_1d(value).ravel()
    return value if value.flags.writeable else value.copy()    # one signature: writable


def _scene_constants(scene):
    """The scene as one float vector (numba takes no dataclass); layout in _unpack."""
    from .beams import least_squares_operator, slant_distances
    from .rotation import attitude_matrix
    azimuths = np.asarray(scene.azimuths, dtype=float)
    operator = least_squares_operator(scene.nominal_unit_vectors())           # (3, b)
    slant = slant_distances(scene.ranges, scene.half_cone, len(azimuths),
                            scene.vertical_beam)                             # (b, g)
    head = [len(azimuths), int(scene.vertical_beam), len(scene.ranges), scene.half_cone,
            scene.misalignment, scene.lidar_height, scene.wind_speed, scene.reference_height,
            scene.shear, -math.cos(scene.wind_direction), -math.sin(scene.wind_direction),
            scene.vertical_wind, scene.sog, scene.cog, scene.heave, scene.heading,
            scene.pitch, scene.roll]
    attitude = attitude_matrix(scene.heading, scene.pitch, scene.roll)
    return np.concatenate([np.asarray(head, dtype=float), np.cos(azimuths),
                           np.sin(azimuths), attitude.ravel(),
                           operator.ravel(), slant.ravel()])


@njit(cache=True)
def _at(column, i):
    return column[i] if column.shape[0] > 1 else column[0]


@njit(cache=True)
def _attitude(heading, pitch, roll, out):
    """Rz(heading) Ry(pitch) Rx(roll) (:mod:`uq.rotation`), written out, into out (3, 3)."""
    ch, sh = math.cos(heading), math.sin(heading)
    cp, sp = math.cos(pitch), math.sin(pitch)
    cr, sr = math.cos(roll), math.sin(roll)
    out[0, 0], out[0, 1], out[0, 2] = ch * cp, ch * sp * sr - sh * cr, -ch * sp * cr - sh * sr
    out[1, 0], out[1, 1], out[1, 2] = sh * cp, sh * sp * sr + ch * cr, -sh * sp * cr + ch * sr
    out[2, 0], out[2, 1], out[2, 2] = sp, -cp * sr, cp * cr


@njit(cache=True)
def _earth_beams(half_cone, misalignment, azimuths, vertical_beam, attitude, out):
    """Earth-frame unit vectors of the true beams into out (b, 3) (Eq. 1 [1], rotated)."""
    sin_cone, cos_cone = math.sin(half_cone), math.cos(half_cone)
    cos_m, sin_m = math.cos(misalignment), math.sin(misalignment)
    n_slanted = azimuths.shape[0] // 2            # (cos a_1 .. cos a_k, sin a_1 .. sin a_k)
    for b in range(n_slanted + vertical_beam):
        if b < n_slanted:
            cos_a, sin_a = azimuths[b], azimuths[n_slanted + b]
            x = sin_cone * (cos_m * cos_a - sin_m * sin_a)        # cos(m + a)
            y = sin_cone * (sin_m * cos_a + cos_m * sin_a)        # sin(m + a)
            z = cos_cone
        else:
            x, y, z = 0.0, 0.0, 1.0
        for k in range(3):
            out[b, k] = attitude[k, 0] * x + attitude[k, 1] * y + attitude[k, 2] * z


@njit(cache=True)
def _true_radial(beams, heights_base, slant, wind, ship, out):
    """Motion-including radial velocity of the true wind at each beam's true heights
    into out (b, g): U(z) (n_h . e_wind) + n_up w - n . u_ship (power-law shear; NaN
    at a height <= 0, outside the model)."""
    speed_ref, reference_height, shear, to_north, to_east, w = wind
    for b in range(out.shape[0]):
        along = beams[b, 0] * to_north + beams[b, 1] * to_east
        moving = beams[b, 0] * ship[0] + beams[b, 1] * ship[1] + beams[b, 2] * ship[2]
        for g in range(out.shape[1]):
            height = heights_base + slant[b, g] * beams[b, 2]
            # U (z / z_ref)^alpha as exp(alpha ln(z / z_ref)): ~20 % cheaper than pow
            if not height > 0:                   # outside the model (also NaN height)
                speed = np.nan
            elif shear == 0.0:
                speed = speed_ref
            else:
                speed = speed_ref * math.exp(shear * math.log(height / reference_height))
            out[b, g] = speed * along + beams[b, 2] * w - moving


@njit(cache=True)
def _correct(truth, noise, operator, rotation, ship, full, g, out):
    """Eq. 13 [1] for gate g with one reading: out = (north, east, up) of R P A^+ v + s
    (``full``: R A^+ v + s with heave), v = true radial velocity + noise."""
    x = y = z = 0.0                                       # A^+ v, the lidar-frame wind
    for b in range(truth.shape[0]):
        radial = truth[b, g] + noise[b, g]
        x += operator[0, b] * radial
        y += operator[1, b] * radial
        z += operator[2, b] * radial
    out[0] = rotation[0, 0] * x + rotation[0, 1] * y + ship[0]
    out[1] = rotation[1, 0] * x + rotation[1, 1] * y + ship[1]
    out[2] = z
    if full:
        out[0] += rotation[0, 2] * z
        out[1] += rotation[1, 2] * z
        out[2] = rotation[2, 0] * x + rotation[2, 1] * y + rotation[2, 2] * z + ship[2]


@njit(cache=True)
def _reading(model, heading, pitch, roll, sog, cog, heave, nominal_heading, rotation, ship):
    """The rotation and ship velocity the correction model believes (:mod:`uq.correction`):
    none 0 (nominal heading, no ship velocity), yaw 1, tilt2d 2, full 3."""
    if model == 0:
        _attitude(nominal_heading, 0.0, 0.0, rotation)
    elif model == 1:
        _attitude(heading, 0.0, 0.0, rotation)
    else:
        _attitude(heading, pitch, roll, rotation)
    moving = model != 0
    ship[0] = sog * math.cos(cog) if moving else 0.0
    ship[1] = sog * math.sin(cog) if moving else 0.0
    ship[2] = heave if model == 3 else 0.0


_A1, _A3 = "float64[:]", "float64[:, :, :]"
_OUT = "float64[:, :]"


# one explicit signature with any-layout arrays: strided views of the input matrix and
# length-1 placeholders compile once, not once per combination of layouts
@njit(f"void(float64[::1], {_A1}, {_A1}, {_A1}, {_A1}, {_A1}, {_A1}, {_A1}, {_A1}, {_A1}, {_A3}, "
      f"int64, boolean, {_OUT}, {_OUT}, {_OUT})", cache=True)
def _trials(constants, d_cone, d_misalignment, d_height, d_heading, d_pitch, d_roll, d_sog,
            d_cog, d_heave, noise, model, want_direction, speed, direction, vertical):
    """The loop over trials; angular errors in degrees. Writes speed, direction [deg]
    in [0, 360) and vertical wind, each (n, g)."""
    n_slanted, vertical_beam, n_gates = int(constants[0]), int(constants[1]), int(constants[2])
    n_beams = n_slanted + vertical_beam
    cone0, misalignment0, lidar_height = constants[3], constants[4], constants[5]
    wind = (constants[6], constants[7], constants[8], constants[9], constants[10],
            constants[11])                 # speed, reference height, shear, unit wind, w
    sog0, cog0, heave0 = constants[12], constants[13], constants[14]
    heading0, pitch0, roll0 = constants[15], constants[16], constants[17]
    at = 18
    azimuths = constants[at:at + 2 * n_slanted]          # their cosines, then sines
    attitude = constants[at + 2 * n_slanted:at + 2 * n_slanted + 9].reshape(3, 3)
    at += 2 * n_slanted + 9
    operator = constants[at:at + 3 * n_beams].reshape(3, n_beams)
    slant = constants[at + 3 * n_beams:at + 3 * n_beams + n_beams * n_gates].reshape(
        n_beams, n_gates)
    true_ship = np.array([sog0 * math.cos(cog0), sog0 * math.sin(cog0), heave0])
    beams, truth = np.empty((n_beams, 3)), np.empty((n_beams, n_gates))
    rotation, ship, earth = np.zeros((3, 3)), np.zeros(3), np.zeros(3)
    fixed_geometry = d_cone.shape[0] == 1 and d_misalignment.shape[0] == 1
    fixed_truth = fixed_geometry and d_height.shape[0] == 1
    fixed_reading = max(d_heading.shape[0], d_pitch.shape[0], d_roll.shape[0], d_sog.shape[0],
                        d_cog.shape[0], d_heave.shape[0]) == 1       # no INS error: once
    if fixed_truth:
        _earth_beams(cone0 + d_cone[0] * _DEG, misalignment0 + d_misalignment[0] * _DEG,
                     azimuths, vertical_beam, attitude, beams)
        _true_radial(beams, lidar_height + d_height[0], slant, wind, true_ship, truth)
    for i in range(speed.shape[0]):
        if not fixed_truth:
            _earth_beams(cone0 + _at(d_cone, i) * _DEG,
                         misalignment0 + _at(d_misalignment, i) * _DEG, azimuths,
                         vertical_beam, attitude, beams)
            _true_radial(beams, lidar_height + _at(d_height, i), slant, wind, true_ship, truth)
        if i == 0 or not fixed_reading:
            _reading(model, heading0 + _at(d_heading, i) * _DEG,
                     pitch0 + _at(d_pitch, i) * _DEG, roll0 + _at(d_roll, i) * _DEG,
                     sog0 + _at(d_sog, i), cog0 + _at(d_cog, i) * _DEG,
                     heave0 + _at(d_heave, i), heading0, rotation, ship)
        row = i if noise.shape[0] > 1 else 0
        for g in range(n_gates):
            _correct(truth, noise[row], operator, rotation, ship, model == 3, g, earth)
            speed[i, g] = math.sqrt(earth[0] * earth[0] + earth[1] * earth[1])
            vertical[i, g] = earth[2]
            if want_direction:
                angle = math.atan2(-earth[1], -earth[0]) * _RAD_TO_DEG % 360.0
                direction[i, g] = angle - 360.0 if angle >= 360.0 else angle
