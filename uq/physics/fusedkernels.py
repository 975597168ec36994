"""Compiled (numba) loops of :mod:`uq.physics.fused`: the measurement model trial by trial.

Three kernels work on a block of trials; between them numpy's SIMD ``log`` and ``exp``
evaluate the power law for the whole block (:func:`uq.fused.measurement_model`):

1. :func:`angle_trig`: cos and sin of configured angle + error, by the angle-addition
   theorem with the error's sine and cosine from their Taylor polynomials. The loop
   has no calls, so it compiles to SIMD code (libm's sin/cos cost ~10 ns each, and
   numba has no vector math library here). Errors beyond :data:`SMALL_ANGLE` use libm.
2. :func:`geometry`: earth-frame unit vectors of the true beams (Eq. 1 of [1], rotated
   by the true attitude) and the ratio z / z_ref of each beam's true gate heights.
3. :func:`wind`: true radial velocities, the INS reading, the correction (Eq. 13 of
   [1]) and the reconstructed wind.

Conventions (as in :mod:`uq.physics.rotation`, :mod:`uq.physics.beams`, :mod:`uq.physics.wind`,
:mod:`uq.physics.correction`): earth frame (north, east, up); ship frame (bow, starboard, up);
body-to-earth ``Rz(heading) Ry(pitch) Rx(roll)``, pitch positive bow up, roll positive
starboard down; beams ``(sin t cos(m + a), sin t sin(m + a), cos t)``; wind direction
"from", clockwise from north; radial velocity positive away from the lidar.

References
----------
.. [1] Rubio, H. and Gottschall, J. (2022). J. Phys.: Conf. Ser. 2362 012034.
"""
import math

import numpy as np
from numba import njit

from uq.constants import HYPOT_SAFE_MAX, HYPOT_SAFE_MIN, SMALL_ANGLE

_DEG = math.pi / 180.0
# Taylor coefficients (-1)^k / (2k+1)! of sin x / x and (-1)^k / (2k)! of cos x in x^2;
# the first omitted terms at |x| = SMALL_ANGLE are below 2e-25 (see constants.py)
_S = tuple((-1) ** k / math.factorial(2 * k + 1) for k in range(8))
_C = tuple((-1) ** k / math.factorial(2 * k) for k in range(9))

# explicit signatures, any-layout arrays: one compilation (cached on disk) for the
# strided columns of the input matrix and the length-1 placeholders alike
_V, _M, _T = "float64[:]", "float64[:, :]", "float64[:, :, :]"


@njit(cache=True)
def _reading_rotation(model, trig, j, nominal):
    """Row-major body-to-earth rotation the correction believes: Rz(heading) Ry(pitch)
    Rx(roll) of the INS reading (tilt2d, full), its heading alone (yaw) or the
    configured heading (none) (:mod:`uq.physics.rotation`)."""
    if model == 0:
        ch, sh, cp, sp, cr, sr = nominal[0], nominal[1], 1.0, 0.0, 1.0, 0.0
    elif model == 1:
        ch, sh, cp, sp, cr, sr = trig[0, 0, j], trig[0, 1, j], 1.0, 0.0, 1.0, 0.0
    else:
        ch, sh = trig[0, 0, j], trig[0, 1, j]
        cp, sp, cr, sr = trig[1, 0, j], trig[1, 1, j], trig[2, 0, j], trig[2, 1, j]
    return (ch * cp, ch * sp * sr - sh * cr, -ch * sp * cr - sh * sr,
            sh * cp, sh * sp * sr + ch * cr, -sh * sp * cr + ch * sr,
            sp, -cp * sr, cp * cr)


@njit(cache=True)
def _truth(beams, profile, speed_ref, to_north, to_east, w, ship, out):
    """True radial velocities (b, g): U(z) (n_h . e_wind) + n_up w - n . u_ship."""
    for b in range(out.shape[0]):
        along = beams[b, 0] * to_north + beams[b, 1] * to_east
        moving = beams[b, 0] * ship[0] + beams[b, 1] * ship[1] + beams[b, 2] * ship[2]
        for g in range(out.shape[1]):
            out[b, g] = speed_ref * profile[b, g] * along + beams[b, 2] * w - moving


@njit(cache=True)
def _solve(operator, radial, out):
    """out (3, g) = A^+ radial: the least-squares lidar-frame wind of each gate."""
    for g in range(radial.shape[1]):
        for k in range(3):
            total = 0.0
            for b in range(radial.shape[0]):
                total += operator[k, b] * radial[b, g]
            out[k, g] = total


@njit(cache=True)
def _hypot(x, y):
    """sqrt(x^2 + y^2), libm's hypot where the squares could over- or underflow (as
    :func:`uq.complexstep.hypot`)."""
    radius = math.sqrt(x * x + y * y)
    return radius if HYPOT_SAFE_MIN < radius < HYPOT_SAFE_MAX else math.hypot(x, y)


#: The scene vector (:func:`uq.fused.scene_constants`) starts with these scalars, by
#: index; then come the azimuths' cosines and sines, the true attitude (3 x 3), the
#: least-squares operator (3 x b) and the slant ranges (b x g).
HEAD = ("n_slanted", "vertical_beam", "n_gates", "lidar_height", "wind_speed",
        "reference_height", "to_north", "to_east", "vertical_wind", "sog", "cog", "heave",
        "heading")
_HEAD = len(HEAD)


@njit(cache=True)
def _azimuths(constants):
    return constants[_HEAD:_HEAD + 2 * int(constants[0])]


@njit(cache=True)
def _attitude(constants):
    at = _HEAD + 2 * int(constants[0])
    return constants[at:at + 9].reshape(3, 3)


@njit(cache=True)
def _operator(constants):
    n_beams = int(constants[0]) + int(constants[1])
    at = _HEAD + 9 + 2 * int(constants[0])
    return constants[at:at + 3 * n_beams].reshape(3, n_beams)


@njit(cache=True)
def _slant(constants):
    n_beams = int(constants[0]) + int(constants[1])
    at = _HEAD + 9 + 2 * int(constants[0]) + 3 * n_beams
    return constants[at:at + n_beams * int(constants[2])].reshape(n_beams, int(constants[2]))


@njit(f"void({_V}, float64, int64, int64, float64[::1], float64[::1])", cache=True)
def angle_trig(error, base, start, stop, cos_out, sin_out):
    """cos and sin of ``base + error[i] * pi / 180`` for i in [start, stop) into
    out[:stop - start]; an error of length 1 is the same for every trial.

    base [rad]; error [deg].
    """
    count = stop - start
    if error.shape[0] == 1:
        angle = base + error[0] * _DEG
        cos_out[:count], sin_out[:count] = math.cos(angle), math.sin(angle)
        return
    cos_base, sin_base = math.cos(base), math.sin(base)
    for j in range(count):                        # gather the (strided) column first:
        cos_out[j] = error[start + j] * _DEG      # unit stride lets the next loop be SIMD
    for j in range(count):                        # no calls, unit stride: SIMD
        x = cos_out[j]
        x2 = x * x
        sin_x = x * (_S[0] + x2 * (_S[1] + x2 * (_S[2] + x2 * (_S[3] + x2 * (
            _S[4] + x2 * (_S[5] + x2 * (_S[6] + x2 * _S[7])))))))
        cos_x = _C[0] + x2 * (_C[1] + x2 * (_C[2] + x2 * (_C[3] + x2 * (_C[4] + x2 * (
            _C[5] + x2 * (_C[6] + x2 * (_C[7] + x2 * _C[8])))))))
        cos_out[j] = cos_base * cos_x - sin_base * sin_x          # cos(b + x)
        sin_out[j] = sin_base * cos_x + cos_base * sin_x          # sin(b + x)
    for j in range(count):                        # large errors (and NaN): libm
        x = error[start + j] * _DEG
        if not abs(x) <= SMALL_ANGLE:
            cos_out[j], sin_out[j] = math.cos(base + x), math.sin(base + x)


@njit(f"void(float64[::1], {_M}, {_M}, {_V}, int64, int64, boolean, {_T}, {_T})", cache=True)
def geometry(constants, cone, misalignment, height_error, start, rows, shear, beams, ratio):
    """True earth-frame beams into beams[j] (b, 3) and z / z_ref of their gates into
    ratio[j] (b, g) for trials start + j, j < rows; NaN at a height <= 0 (outside
    the power law). ``cone`` and ``misalignment`` hold (cos, sin) rows from
    :func:`angle_trig`. Without ``shear`` the ratio is not needed: 1 (or NaN)."""
    n_slanted, vertical_beam, n_gates = int(constants[0]), int(constants[1]), int(constants[2])
    lidar_height, reference_height = constants[3], constants[5]
    azimuths, attitude, slant = _azimuths(constants), _attitude(constants), _slant(constants)
    for j in range(rows):
        base = lidar_height + height_error[start + j if height_error.shape[0] > 1 else 0]
        for b in range(n_slanted + vertical_beam):
            if b < n_slanted:
                cos_a, sin_a = azimuths[b], azimuths[n_slanted + b]
                cos_m, sin_m = misalignment[0, j], misalignment[1, j]
                x = cone[1, j] * (cos_m * cos_a - sin_m * sin_a)          # sin t cos(m + a)
                y = cone[1, j] * (sin_m * cos_a + cos_m * sin_a)          # sin t sin(m + a)
                z = cone[0, j]
            else:
                x, y, z = 0.0, 0.0, 1.0
            for k in range(3):
                beams[j, b, k] = attitude[k, 0] * x + attitude[k, 1] * y + attitude[k, 2] * z
            for g in range(n_gates):
                height = base + slant[b, g] * beams[j, b, 2]
                if not height > 0:               # outside the model (also a NaN height)
                    ratio[j, b, g] = math.nan
                else:
                    ratio[j, b, g] = height / reference_height if shear else 1.0


@njit(f"void(float64[::1], {_T}, {_T}, int64, {_T}, {_V}, {_V}, {_T}, int64, int64, int64, "
      f"{_M}, {_M}, {_M}, {_M})", cache=True)
def wind(constants, beams, profile, rows, trig, sog_error, heave_error, noise, model, start,
         stop, speed, vertical, from_north, from_east):
    """Reconstructed wind of trials [start, stop): speed, vertical wind and the "from"
    vector (north, east) [m s-1], each (n, g) (from_* rows relative to start).

    ``profile`` (rows, b, g) is U(z) / U_ref of each beam's gates (1 row: the same for
    every trial); ``trig`` (4, 2, count) the (cos, sin) of the INS heading, pitch, roll
    and course; ``model`` 0 none, 1 yaw, 2 tilt2d, 3 full (:mod:`uq.physics.correction`).

    One long loop on purpose: split into helper functions for the per-trial truth and
    least squares it ran 1.5x slower (57 -> 87 ns per trial on floating_lidar_full),
    as the values then go through memory instead of registers.
    """
    n_slanted, vertical_beam, n_gates = int(constants[0]), int(constants[1]), int(constants[2])
    n_beams = n_slanted + vertical_beam
    speed_ref, to_north, to_east, w = constants[4], constants[6], constants[7], constants[8]
    sog0, cog0, heave0, heading0 = constants[9], constants[10], constants[11], constants[12]
    true_ship = (sog0 * math.cos(cog0), sog0 * math.sin(cog0), heave0)
    operator = _operator(constants)
    nominal = (math.cos(heading0), math.sin(heading0))
    truth = np.empty((n_beams, n_gates))             # true radial velocities of a trial
    lidar_frame = np.empty((3, n_gates))             # A^+ truth: the noise-free wind
    for i in range(start, stop):
        j = i - start
        r = j if rows > 1 else 0
        row = i if noise.shape[0] > 1 else 0
        if rows > 1:                                 # this trial's true radial velocities
            for b in range(n_beams):
                along = beams[r, b, 0] * to_north + beams[r, b, 1] * to_east
                moving = (beams[r, b, 0] * true_ship[0] + beams[r, b, 1] * true_ship[1]
                          + beams[r, b, 2] * true_ship[2])
                for g in range(n_gates):                          # U(z) (n_h . e) + n_up w
                    truth[b, g] = speed_ref * profile[r, b, g] * along + beams[r, b, 2] * w \
                        - moving
        elif i == start:                             # one truth for all: A^+ truth once
            _truth(beams[0], profile[0], speed_ref, to_north, to_east, w, true_ship, truth)
            _solve(operator, truth, lidar_frame)
        if model != 0 or i == start:             # none: the configured heading, fixed
            rotation = _reading_rotation(model, trig, j, nominal)
        sog = sog0 + sog_error[i if sog_error.shape[0] > 1 else 0]
        heave = heave0 + heave_error[i if heave_error.shape[0] > 1 else 0]
        moving = model != 0
        ship = (sog * trig[3, 0, j] if moving else 0.0, sog * trig[3, 1, j] if moving else 0.0,
                heave if model == 3 else 0.0)
        for g in range(n_gates):                     # the lidar-frame wind A^+ v
            if rows > 1:                             # v = truth + noise
                x = y = z = 0.0
                for b in range(n_beams):
                    value = truth[b, g] + noise[row, b, g]
                    x += operator[0, b] * value
                    y += operator[1, b] * value
                    z += operator[2, b] * value
            else:                                    # A^+ truth + A^+ noise
                x, y, z = lidar_frame[0, g], lidar_frame[1, g], lidar_frame[2, g]
                for b in range(n_beams):
                    x += operator[0, b] * noise[row, b, g]
                    y += operator[1, b] * noise[row, b, g]
                    z += operator[2, b] * noise[row, b, g]
            north = rotation[0] * x + rotation[1] * y + ship[0]            # Eq. 13 [1]
            east = rotation[3] * x + rotation[4] * y + ship[1]
            up = z
            if model == 3:
                north += rotation[2] * z
                east += rotation[5] * z
                up = rotation[6] * x + rotation[7] * y + rotation[8] * z + ship[2]
            speed[i, g] = _hypot(north, east)
            vertical[i, g] = up
            from_north[j, g], from_east[j, g] = -north, -east
