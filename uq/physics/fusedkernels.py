"""Compiled (numba) loops of :mod:`uq.physics.fused`: the measurement model trial by trial.

The loops run over a *rectangle* of scenes x trials (scenes ``[s0, s1)``, trials
``[t0, t1)``); :func:`power_near` evaluates the power law between them
(:func:`uq.physics.fused.measurement_model`):

1. :func:`ins_trig`: cos and sin of each INS angle *error* (heading, pitch, roll, course),
   from their Taylor polynomials, once per trial and beam reading. With common draws the
   scenes of a batch share them (the work that depends only on the draws); each scene
   then adds its own angle by the addition theorem, four multiplications. The loop has
   no calls, so it compiles to SIMD code (libm's sin/cos cost ~10 ns each, and numba has
   no vector math library here). Errors beyond :data:`SMALL_ANGLE` use libm.
2. :func:`geometry`: earth-frame unit vectors of the true beams (Eq. 1 of [1], rotated
   by the true attitude) and the ratio z / z_ref of each beam's true gate heights, per
   scene (no geometry error: the truth is common to all trials) or per trial.
3. :func:`wind`: true radial velocities, the INS reading, the correction (Eq. 13 of
   [1]; or point-wise, each beam with its own reading, when an INS error has one value
   per beam) and the outputs: the reconstructed wind, the motion-corrected radial
   velocities and the mean true gate heights.

Every kernel is compiled for float64 (Monte Carlo) and complex128 (complex-step GUM:
the same arithmetic carries the imaginary perturbation; comparisons use real parts).

Conventions (as in :mod:`uq.physics.rotation`, :mod:`uq.physics.beams`, :mod:`uq.physics.wind`,
:mod:`uq.physics.correction`): earth frame (north, east, up); ship frame (bow, starboard, up);
body-to-earth ``Rz(heading) Ry(pitch) Rx(roll)``, pitch positive bow up, roll positive
starboard down; beams ``(sin t cos(m + a), sin t sin(m + a), cos t)``; wind direction
"from", clockwise from north; radial velocity positive away from the lidar.

References
----------
.. [1] Rubio, H. and Gottschall, J. (2022). J. Phys.: Conf. Ser. 2362 012034.
.. [2] Matavar, A. (2024). Wind field reconstruction from floating lidars. MSc thesis,
   TU Delft (point-wise correction, Sec. 3.2).
"""
import functools
import math

import numpy as np
from numba import njit, types

from uq.constants import (HYPOT_SAFE_MAX, HYPOT_SAFE_MIN, POWER_SERIES_MAX_EXPONENT,
                          SMALL_ANGLE)
from uq.physics.kernelbase import (DEG as _DEG, FULL, NONE, TILT2D, YAW, hypot as _hypot,
                                   inverse2 as _inverse2, taylor_cos_sin)

#: Columns of the scene table (:func:`uq.physics.fused.scene_table`), one row per scene:
#: these scalars, then the cosines and the sines of TRIG, then the row of the scene's
#: (half-cone, misalignment) in the geometry table: the cosines and sines of the slanted
#: beams' azimuths, the least-squares operator A^+ (3 x b), the slant distances (b x g)
#: and the configured ship-frame beams (b x 3) (:func:`_geometry_offsets`).
TABLE = ("lidar_height", "wind_speed", "reference_height", "shear", "wind_direction",
         "vertical_wind", "sog", "cog", "heave", "heading", "pitch", "roll", "half_cone",
         "misalignment")
(_LIDAR_HEIGHT, _SPEED, _REFERENCE, _SHEAR, _DIRECTION, _VERTICAL, _SOG, _COG, _HEAVE,
 _HEADING, _PITCH, _ROLL, _HALF_CONE, _MISALIGNMENT) = range(len(TABLE))
#: Angles whose cos and sin follow the scalars (cosines, then sines): numpy's float64
#: cos and sin are libm's, computed once per scene for the whole batch.
TRIG = ("heading", "pitch", "roll", "cog", "wind_direction", "half_cone", "misalignment")
_COS = len(TABLE)
_SIN = _COS + len(TRIG)
(_T_HEADING, _T_PITCH, _T_ROLL, _T_COG, _T_DIRECTION, _T_HALF_CONE,
 _T_MISALIGNMENT) = range(len(TRIG))
#: The column of the scene's row in the geometry table, and the scene table's width.
_GEOMETRY_ROW = _SIN + len(TRIG)
TABLE_WIDTH = _GEOMETRY_ROW + 1
#: The structure vector (int64): beams, gates, correction model and wanted outputs.
STRUCTURE = ("n_slanted", "vertical_beam", "n_gates", "model", "want_speed", "want_direction",
             "want_vertical", "want_radial", "want_height")
#: The INS errors, in the order of the ``ins`` tuple; the angles among them (degrees).
INS_ORDER = ("heading", "pitch", "roll", "sog", "cog", "heave")
_INS_ANGLES = (0, 1, 2, 4)          # heading, pitch, roll, cog in INS_ORDER
#: The table columns of the INS angles' true values (heading, pitch, roll, cog: the
#: first four of TRIG, in that order).
_READING_BASES = tuple(TABLE.index(name) for name in TRIG[:4])
#: The geometry errors, in the order of the ``geo`` tuple.
GEO_ORDER = ("half_cone", "misalignment", "height")


#: How the kernels' helpers are compiled: as functions of their own that LLVM inlines
#: into the kernel (the small ones: the same machine code, the same numbers), not numba's
#: ``inline="always"``, which re-runs numba's front end on the helper at every call site
#: and made the first compile 2-3x longer (wind_scan: 19.7 s of CPU time against 7-9 s,
#: a whole cold ``uq run rubio2022_case_i`` 115 s against 34 s; numba 0.68).
#: The two helpers called once per trial with arrays (the true radial velocities and gate
#: heights) stay inlined by numba: as calls they cost ~4 % on floating_lidar_full.
_helper = njit(nogil=True)


def _signature(kind, dtype):
    """The explicit signature of a kernel for float64 or complex128 numbers, any-layout
    arrays: one compilation (cached on disk) for strided views and length-1
    placeholders alike."""
    a3, a4 = types.Array(dtype, 3, "A"), types.Array(dtype, 4, "A")
    c1, c3 = types.Array(dtype, 1, "C"), types.Array(dtype, 3, "C")
    table = types.Array(types.float64, 2, "C")
    ints = types.Array(types.int64, 1, "C")
    ins, geo = types.UniTuple(a3, 6), types.UniTuple(a3, 3)
    i8, b1 = types.int64, types.boolean
    if kind == "trig":
        return types.void(ins, table, i8, i8, i8, i8, b1, c3, c3, c1)
    if kind == "power":
        return types.void(types.Array(types.float64, 2, "C"),
                          types.Array(types.float64, 1, "A"))
    if kind == "geometry":
        return types.void(table, table, ints, geo, i8, i8, i8, i8, b1, a3, a3,
                          types.Array(types.float64, 1, "C"))
    wind = (table, table, ints, ins, a3, c3, c3, a3, a3, a3, i8, i8, i8, i8, b1, b1,
            a3, a3, a3, a3, a4, a3)
    if kind == "wind_mounted":              # and the shear exponent
        return types.void(*wind, a3)
    return types.void(*wind)


@_helper
def _angle(base, cos_base, sin_base, x, cos_x, sin_x):
    """cos and sin of base + x [rad]: the addition theorem with the error's (cos_x,
    sin_x) from :func:`~uq.physics.kernelbase.taylor_cos_sin` where |x| <= SMALL_ANGLE,
    libm beyond (and for NaN)."""
    if abs(x) <= SMALL_ANGLE:
        return cos_base * cos_x - sin_base * sin_x, sin_base * cos_x + cos_base * sin_x
    return np.cos(base + x), np.sin(base + x)


@_helper
def _fixed(base, cos_base, sin_base, x):
    """cos and sin of base + x for an error x constant over trials: where x is 0, the
    scene's own from the table (base + 0 is base), or (1, +0) for a zero base (+-0 + 0
    is +0: libm's cos and sin of it); else libm."""
    if x == 0.0:
        if base != 0.0:
            return cos_base, sin_base
        return 1.0, 0.0
    return np.cos(base + x), np.sin(base + x)


@_helper
def _pick(array, i, s, k):
    """Element (i, s, k) of an error array whose axes of length 1 broadcast."""
    return array[i if array.shape[0] > 1 else 0, s if array.shape[1] > 1 else 0,
                 k if array.shape[2] > 1 else 0]


@_helper
def _readings(error, a, base, cos_base, sin_base, s, t0, count, tr0, cos_trig, sin_trig,
              cos_out, sin_out):
    """cos and sin of INS angle a (base + error) of scene s for trials [t0, t0 + count)
    into out[a, k, j]: the addition theorem on the error's Taylor terms (rows tr0 + j of
    :func:`ins_trig`, shared by the scenes that share the draws) in a loop without calls
    (SIMD), then libm for errors beyond SMALL_ANGLE (and NaN); an error constant over
    trials takes libm once. (Indices, not views: a view costs two atomic reference
    counts, more than the loop for a few trials per scene.)"""
    for k in range(error.shape[2]):
        if error.shape[0] == 1:
            cos_fixed, sin_fixed = _fixed(base, cos_base, sin_base,
                                          _pick(error, 0, s, k) * _DEG)
            for j in range(count):
                cos_out[a, k, j], sin_out[a, k, j] = cos_fixed, sin_fixed
            continue
        for j in range(count):                 # no calls, unit stride: SIMD
            cos_x, sin_x = cos_trig[a, k, tr0 + j], sin_trig[a, k, tr0 + j]
            cos_out[a, k, j] = cos_base * cos_x - sin_base * sin_x      # cos(b + x)
            sin_out[a, k, j] = sin_base * cos_x + cos_base * sin_x      # sin(b + x)
        for j in range(count):                 # large errors (and NaN): libm
            x = _pick(error, t0 + j, s, k) * _DEG
            if not abs(x) <= SMALL_ANGLE:
                cos_out[a, k, j], sin_out[a, k, j] = np.cos(base + x), np.sin(base + x)


def ins_trig(ins, table, s0, s1, t0, t1, per_scene, cos_out, sin_out, scratch):
    """cos and sin of the INS angle errors (heading, pitch, roll, course) of trials
    [t0, t1) into out[a, k, row] (a in that order, k the reading); the row is the
    trial's within [t0, t1), and with `per_scene` (independent draws per scene)
    (s - s0) (t1 - t0) + (i - t0). Errors constant over trials are skipped (the wind
    kernel takes libm for them). `scratch` holds at least t1 - t0 values."""
    count = t1 - t0
    for a in range(4):
        error = ins[_INS_ANGLES[a]]
        if error.shape[0] == 1:
            continue
        scenes = s1 - s0 if per_scene else 1
        for index in range(scenes):
            s = s0 + index
            for k in range(error.shape[2]):
                at = index * count
                for j in range(count):            # gather the (strided) column first:
                    scratch[j] = _pick(error, t0 + j, s, k) * _DEG   # unit stride: SIMD
                for j in range(count):            # no calls, unit stride: SIMD
                    cos_x, sin_x = taylor_cos_sin(scratch[j])
                    cos_out[a, k, at + j] = cos_x
                    sin_out[a, k, at + j] = sin_x


@_helper
def _geometry_offsets(n_slanted, n_beams, n_gates):
    """Columns of the operator, slant distances and configured beams in a row of the
    geometry table (the azimuths' cos and sin come first), and the row's length."""
    operator = 2 * n_slanted
    slant = operator + 3 * n_beams
    units = slant + n_beams * n_gates
    return operator, slant, units, units + 3 * n_beams


def geometry_offsets(n_slanted, n_beams, n_gates):
    """:func:`_geometry_offsets` for Python."""
    return _geometry_offsets.py_func(n_slanted, n_beams, n_gates)


#: First columns of the cosines and of the sines of TRIG in the scene table.
TRIG_COS, TRIG_SIN = _COS, _SIN
_TRIG_FIELDS = tuple(TABLE.index(name) for name in TRIG)


@njit("void(float64[:, ::1], intp[::1], float64[:, ::1])", cache=True, nogil=True)
def fill_table(fields, index, out):
    """The scene table row by row (sequential writes): the scalars (fields, one row per
    TABLE name), libm's cos and sin of TRIG, and the scene's row of the geometry table."""
    for s in range(out.shape[0]):
        for c in range(len(TABLE)):
            out[s, c] = fields[c, s]
        for k in range(len(TRIG)):
            angle = fields[_TRIG_FIELDS[k], s]
            out[s, _COS + k] = math.cos(angle)
            out[s, _SIN + k] = math.sin(angle)
        out[s, _GEOMETRY_ROW] = index[s]


@_helper
def _attitude(table, s):
    """The scene's true body-to-earth rotation Rz(heading) Ry(pitch) Rx(roll), row-major
    (the expressions of :func:`uq.physics.rotation.attitude_matrix`)."""
    return _rotation(FULL, table[s, _COS + _T_HEADING], table[s, _SIN + _T_HEADING],
                     table[s, _COS + _T_PITCH], table[s, _SIN + _T_PITCH],
                     table[s, _COS + _T_ROLL], table[s, _SIN + _T_ROLL], 1.0, 0.0)


@_helper
def _angle_block(error, s, t0, count, base, cos_base, sin_base, out, row):
    """cos and sin of base + error [deg] of trials [t0, t0 + count) of scene s into
    out[row, :count], out[row + 1, :count]: the errors' Taylor polynomials and the
    addition theorem in loops without calls (SIMD), libm beyond SMALL_ANGLE (and for
    NaN); an error constant over trials takes libm once."""
    if error.shape[0] == 1:
        cos_fixed, sin_fixed = _fixed(base, cos_base, sin_base, _pick(error, 0, s, 0) * _DEG)
        for j in range(count):
            out[row, j], out[row + 1, j] = cos_fixed, sin_fixed
        return
    for j in range(count):                        # gather the (strided) column first:
        out[row, j] = _pick(error, t0 + j, s, 0) * _DEG    # unit stride: SIMD next
    for j in range(count):                        # no calls, unit stride: SIMD
        cos_x, sin_x = taylor_cos_sin(out[row, j])
        out[row, j] = cos_base * cos_x - sin_base * sin_x          # cos(b + x)
        out[row + 1, j] = sin_base * cos_x + cos_base * sin_x      # sin(b + x)
    for j in range(count):                        # large errors (and NaN): libm
        x = _pick(error, t0 + j, s, 0) * _DEG
        if not abs(x) <= SMALL_ANGLE:
            out[row, j], out[row + 1, j] = np.cos(base + x), np.sin(base + x)


def geometry(table, shapes, structure, geo, s0, s1, t0, t1, per_trial, beams, ratio, shear):
    """:func:`_geometry` of an upward lidar (beams on the cone about the deck's vertical)."""
    _geometry(table, shapes, structure, geo, s0, s1, t0, t1, per_trial, beams, ratio, shear,
              False)


def geometry_mounted(table, shapes, structure, geo, s0, s1, t0, t1, per_trial, beams, ratio,
                     shear):
    """:func:`_geometry` of a tilted mount (beams at clock positions about the boresight)."""
    _geometry(table, shapes, structure, geo, s0, s1, t0, t1, per_trial, beams, ratio, shear,
              True)


@_helper
def _mounted_beam(cos_cone, sin_cone, cos_m, sin_m, cos_clock, sin_clock, cos_tilt,
                  sin_tilt):
    """Ship-frame beam of a tilted mount (:func:`uq.physics.beams.mounted_unit_vectors`):
    ``Rz(m) [cos(a) d + sin(a) (cos(phi) e_up + sin(phi) e_starboard)]`` with the
    boresight d = (sin tau, 0, cos tau) and e_up = (-cos tau, 0, sin tau)."""
    bow = cos_cone * sin_tilt - sin_cone * cos_clock * cos_tilt
    starboard = sin_cone * sin_clock
    up = cos_cone * cos_tilt + sin_cone * cos_clock * sin_tilt
    return cos_m * bow - sin_m * starboard, sin_m * bow + cos_m * starboard, up


@_helper
def _geometry(table, shapes, structure, geo, s0, s1, t0, t1, per_trial, beams, ratio, shear,
              mounted):
    """True earth-frame beams into beams[row] (b, 3), z / z_ref of their gates into
    ratio[row] (b, g) and the scene's shear exponent into shear[row]; NaN at a height
    <= 0 (outside the power law). Rows: with `per_trial`, (s - s0) (t1 - t0) + (i - t0)
    for the trials of the rectangle; else one row per scene, s - s0, with the errors of
    trial t0 (constant over trials). Without shear the ratio is not needed: 1 (or NaN).
    `mounted` (a constant of each kernel): the beams of a tilted mount, whose mount's
    (cos, sin) of the tilt follow the geometry row (:func:`_geometry_offsets`).
    """
    n_slanted, n_gates = structure[0], structure[2]
    n_beams = n_slanted + structure[1]
    _, slant, _, row_end = _geometry_offsets(n_slanted, n_beams, n_gates)
    count = t1 - t0 if per_trial else 1
    zero = np.zeros(1, beams.dtype)[0]            # 0 of the number type (not 0 x data)
    trig = np.full((4, count), zero)              # cos, sin of half-cone, misalignment
    cone_error, misalignment_error, height_error = geo[0], geo[1], geo[2]
    row = 0
    for s in range(s0, s1):
        _angle_block(cone_error, s, t0, count, table[s, _HALF_CONE],
                     table[s, _COS + _T_HALF_CONE], table[s, _SIN + _T_HALF_CONE], trig, 0)
        _angle_block(misalignment_error, s, t0, count, table[s, _MISALIGNMENT],
                     table[s, _COS + _T_MISALIGNMENT], table[s, _SIN + _T_MISALIGNMENT],
                     trig, 2)
        reference, exponent = table[s, _REFERENCE], table[s, _SHEAR]
        shape = int(table[s, _GEOMETRY_ROW])
        attitude = _attitude(table, s)
        for j in range(count):
            cos_t, sin_t, cos_m, sin_m = trig[0, j], trig[1, j], trig[2, j], trig[3, j]
            base = table[s, _LIDAR_HEIGHT] + _pick(height_error, t0 + j, s, 0)
            for b in range(n_beams):
                if mounted:
                    x, y, z = _mounted_beam(cos_t, sin_t, cos_m, sin_m, shapes[shape, b],
                                            shapes[shape, n_slanted + b],
                                            shapes[shape, row_end], shapes[shape, row_end + 1])
                elif b < n_slanted:
                    cos_a, sin_a = shapes[shape, b], shapes[shape, n_slanted + b]
                    x = sin_t * (cos_m * cos_a - sin_m * sin_a)       # sin t cos(m + a)
                    y = sin_t * (sin_m * cos_a + cos_m * sin_a)       # sin t sin(m + a)
                    z = cos_t
                else:
                    x, y, z = zero, zero, zero + 1.0
                for k in range(3):
                    beams[row, b, k] = attitude[3 * k] * x + attitude[3 * k + 1] * y + \
                        attitude[3 * k + 2] * z
                for g in range(n_gates):
                    height = base + shapes[shape, slant + b * n_gates + g] * beams[row, b, 2]
                    if not height.real > 0:      # outside the model (also a NaN height)
                        ratio[row, b, g] = np.nan
                    elif exponent != 0.0:
                        ratio[row, b, g] = height / reference
                    else:
                        ratio[row, b, g] = 1.0
            shear[row] = exponent
            row += 1


@_helper
def _beam_rotation(model, cos_read, sin_read, j, b, heading_error, pitch_error, roll_error,
                   cos_nominal, sin_nominal):
    """:func:`_rotation` of beam b's own INS reading (point-wise: the (cos, sin) of its
    heading, pitch and roll in cos_read/sin_read[0:3, k, j], k = b where that error is
    drawn per beam, else 0) for trial column j."""
    kh = b if heading_error.shape[2] > 1 else 0
    kp = b if pitch_error.shape[2] > 1 else 0
    kr = b if roll_error.shape[2] > 1 else 0
    return _rotation(model, cos_read[0, kh, j], sin_read[0, kh, j], cos_read[1, kp, j],
                     sin_read[1, kp, j], cos_read[2, kr, j], sin_read[2, kr, j],
                     cos_nominal, sin_nominal)


@_helper
def _believed_beam(rot, units, b, normal):
    """normal[b] = rot units[b]: beam b's unit vector (lidar frame) in the earth frame the
    correction believes (rot row-major, from :func:`_rotation`)."""
    for k in range(3):
        normal[b, k] = rot[3 * k] * units[b, 0] + rot[3 * k + 1] * units[b, 1] \
            + rot[3 * k + 2] * units[b, 2]


@_helper
def _rotation(model, ch, sh, cp, sp, cr, sr, cos_nominal, sin_nominal):
    """Row-major body-to-earth rotation the correction believes: Rz(heading) Ry(pitch)
    Rx(roll) of the INS reading (tilt2d, full), its heading alone (yaw) or the
    configured heading (none) (:mod:`uq.physics.rotation`)."""
    if model == NONE:
        ch, sh, cp, sp, cr, sr = cos_nominal, sin_nominal, 1.0, 0.0, 1.0, 0.0
    elif model == YAW:
        cp, sp, cr, sr = 1.0, 0.0, 1.0, 0.0
    return (ch * cp, ch * sp * sr - sh * cr, -ch * sp * cr - sh * sr,
            sh * cp, sh * sp * sr + ch * cr, -sh * sp * cr + ch * sr,
            sp, -cp * sr, cp * cr)


@_helper
def _solve3(m, rhs):
    """Solution of the 3 x 3 system m x = rhs (Gaussian elimination with partial
    pivoting on the real parts, as LAPACK's gesv; m and rhs are overwritten)."""
    for c in range(3):
        pivot = c
        for r in range(c + 1, 3):
            if abs(m[r, c].real) > abs(m[pivot, c].real):
                pivot = r
        if pivot != c:
            for k in range(3):
                m[c, k], m[pivot, k] = m[pivot, k], m[c, k]
            rhs[c], rhs[pivot] = rhs[pivot], rhs[c]
        for r in range(c + 1, 3):
            factor = m[r, c] / m[c, c]
            for k in range(c, 3):
                m[r, k] -= factor * m[c, k]
            rhs[r] -= factor * rhs[c]
    rhs[2] = rhs[2] / m[2, 2]
    rhs[1] = (rhs[1] - m[1, 2] * rhs[2]) / m[1, 1]
    rhs[0] = (rhs[0] - m[0, 1] * rhs[1] - m[0, 2] * rhs[2]) / m[0, 0]


#: :func:`_solve3` inlined by numba into :func:`_pointwise_solve` (called from a helper
#: that numba inlines, LLVM no longer inlined it: the upward point-wise kernel 4-8 %
#: slower).
_solve3_inlined = njit(inline="always")(_solve3.py_func)


@njit(inline="always")
def _normal_matrix(normal, n_beams, gram, zero):
    """``B^T B`` (3, 3) of the believed earth-frame beams B (rows of normal, (b, 3)) into
    gram: the point-wise least squares' matrix [2], one per reading (every gate's)."""
    for k in range(3):
        for m in range(3):
            total = zero
            for b in range(n_beams):
                total += normal[b, k] * normal[b, m]
            gram[k, m] = total


@njit(inline="always")
def _pointwise_solve(gram, matrix, rhs):
    """The point-wise least squares of one gate [2]: the wind u [m s-1] of the normal
    equations ``B^T B u = B^T c`` with B^T B in gram (:func:`_normal_matrix`) and
    ``B^T c`` in rhs (3,) [m s-1] (c the corrected radial velocities), by :func:`_solve3`
    on a copy (matrix, (3, 3)); returns (north, east, up).

    :func:`_normal_matrix` and this are the upward and the tilted mounts' point-wise
    kernels' one least squares, inlined by numba (``B^T c`` summed by the caller, with c
    in registers: through an array, or a helper called per gate, the upward kernel took
    4-50 % more CPU time)."""
    for k in range(3):
        for m in range(3):
            matrix[k, m] = gram[k, m]
    _solve3_inlined(matrix, rhs)
    return rhs[0], rhs[1], rhs[2]


@_helper
def _mean_reading(error, base, i, s, zero):
    """The mean over the beams' readings of an INS angle, base + error [rad]."""
    total = zero
    for k in range(error.shape[2]):
        total += base + _pick(error, i, s, k) * _DEG
    return total / error.shape[2]


@_helper
def _tilt2d_mean(heading_error, pitch_error, roll_error, cog_error, sog_error, base, sog0,
                 i, s, zero, mean, cos_nominal, sin_nominal):
    """tilt2d's mean reading over the beams (Eq. 13 [1]): its rotation and the ship's
    velocity (north, east) it implies; `mean` (5,) scratch."""
    mean[0] = _mean_reading(heading_error, base[0], i, s, zero)
    mean[1] = _mean_reading(pitch_error, base[1], i, s, zero)
    mean[2] = _mean_reading(roll_error, base[2], i, s, zero)
    mean[3] = _mean_reading(cog_error, base[3], i, s, zero)
    total = zero
    for k in range(sog_error.shape[2]):
        total += sog0 + _pick(sog_error, i, s, k)
    mean[4] = total / sog_error.shape[2]
    rotation = _rotation(FULL, np.cos(mean[0]), np.sin(mean[0]), np.cos(mean[1]),
                         np.sin(mean[1]), np.cos(mean[2]), np.sin(mean[2]),
                         cos_nominal, sin_nominal)
    return rotation, (mean[4] * np.cos(mean[3]), mean[4] * np.sin(mean[3]))


@_helper
def _tilt2d_project(mean_rot, mean_ship, north, east, up):
    """tilt2d's wind from the point-wise least squares u (Eq. 13 [1]): R_m^T (u - s_m),
    then its horizontal part rotated back by the mean reading R_m and s_m added."""
    d0, d1, d2 = north - mean_ship[0], east - mean_ship[1], up
    x = mean_rot[0] * d0 + mean_rot[3] * d1 + mean_rot[6] * d2
    y = mean_rot[1] * d0 + mean_rot[4] * d1 + mean_rot[7] * d2
    up = mean_rot[2] * d0 + mean_rot[5] * d1 + mean_rot[8] * d2
    return (mean_rot[0] * x + mean_rot[1] * y + mean_ship[0],
            mean_rot[3] * x + mean_rot[4] * y + mean_ship[1], up)


@njit(inline="always")
def _gate_heights(table, s, shapes, shape, beams, r, height_error, n_slanted, n_gates,
                  at_slant, out):
    """Mean true height of the slanted beams at each gate [m] (as the numpy model:
    lidar height + error, plus slant distance x the true beam's up component)."""
    base = table[s, _LIDAR_HEIGHT] + height_error
    for g in range(n_gates):
        total = base + shapes[shape, at_slant + g] * beams[r, 0, 2]
        for b in range(1, n_slanted):
            total += base + shapes[shape, at_slant + b * n_gates + g] * beams[r, b, 2]
        out[g] = total / n_slanted


@njit(inline="always")
def _true_radials(beams, profile, r, speed_ref, w, to_north, to_east, true_ship, n_beams,
                  n_gates, truth):
    """The true radial velocities of the truth's row r (:func:`geometry`) into truth
    (b, g): ``U(z) (n_h . e) + n_up w - n . v_ship`` [m s-1] (Eq. 2 of [1])."""
    for b in range(n_beams):
        along_wind = beams[r, b, 0] * to_north + beams[r, b, 1] * to_east
        moving = beams[r, b, 0] * true_ship[0] + beams[r, b, 1] * true_ship[1] + \
            beams[r, b, 2] * true_ship[2]
        for g in range(n_gates):
            truth[b, g] = speed_ref * profile[r, b, g] * along_wind + beams[r, b, 2] * w - moving


@_helper
def _wind(table, shapes, structure, ins, noise, cos_trig, sin_trig, beams, profile, height_error,
          s0, s1, t0, t1, per_scene, per_trial, speed, vertical, from_north, from_east,
          radial, gate_height, pointwise):
    """The outputs of scenes [s0, s1) x trials [t0, t1), into element-major arrays
    (S, g, n) and, for the radial velocities, (S, b, g, n): each element's trials are
    contiguous, as the statistics read them.

    ``beams`` and ``profile`` (U(z) / U_ref of each beam's gates) are rows of
    :func:`geometry`: one per trial of the rectangle (`per_trial`) or one per scene
    (row s: the truth common to all trials). ``cos_trig``, ``sin_trig`` are the INS
    angle errors of :func:`ins_trig` (rows per trial, or per scene and trial with
    `per_scene`). Where an INS error has one value per beam (``beam`` correlation or a
    correlation time) each beam is corrected with its own reading, then least squares
    (point-wise, [2]; ``tilt2d`` then projects as Eq. 13 of [1] with the mean reading,
    as :func:`uq.physics.correction.reconstruct_wind`); otherwise Eq. 13 of [1] with one
    reading. ``from_north``, ``from_east`` get the "from" vector (the direction is then
    taken by numpy's SIMD arctan2). Model: the codes NONE, YAW, TILT2D, FULL of
    :class:`uq.physics.modelinputs.Correction` (any other: ValueError).

    `pointwise` is a constant of each of the two kernels (:func:`wind_scan`,
    :func:`wind_pointwise`), so each compiles only its own branch.

    One long loop on purpose: split into helper functions for the per-trial truth and
    least squares it ran 1.5x slower (57 -> 87 ns per trial on floating_lidar_full),
    as the values then go through memory instead of registers; even an inlined helper
    that stores the outputs (speed, vertical, direction) cost 17 % (CPU time of 2^19
    trials, 0.175 s against 0.150 s), so the stores stay written out in both branches.
    The true radial velocities, which go through memory anyway (``truth``), are one
    inlined helper (:func:`_true_radials`) at no measurable cost.
    """
    n_slanted, vertical_beam, n_gates, model = structure[0], structure[1], structure[2], \
        structure[3]
    if model != NONE and model != YAW and model != TILT2D and model != FULL:
        raise ValueError("unknown correction model code (see uq.physics.modelinputs)")
    want_speed, want_direction, want_vertical = structure[4], structure[5], structure[6]
    want_radial, want_height = structure[7], structure[8]
    n_beams = n_slanted + vertical_beam
    at_operator, at_slant, at_units, _ = _geometry_offsets(n_slanted, n_beams, n_gates)
    # the tuple's arrays as locals once (an array taken from a tuple in a loop is an
    # atomic reference count each time)
    heading_error, pitch_error, roll_error = ins[0], ins[1], ins[2]
    sog_error, cog_error, heave_error = ins[3], ins[4], ins[5]
    has_noise = noise.shape[2] > 1                  # (absent: a (1, 1, 1) placeholder)
    zero = np.zeros(1, beams.dtype)[0]               # 0 of the kernel's number type
    truth = np.full((n_beams, n_gates), zero)        # true radial velocities of a trial
    lidar_frame = np.full((3, n_gates), zero)        # A^+ truth: the noise-free wind
    heights = np.full(n_gates, zero)                 # mean true gate heights
    count = t1 - t0
    cos_read = np.full((4, n_beams, count), zero)    # (cos, sin) of the readings' angles
    sin_read = np.full((4, n_beams, count), zero)
    base = np.empty(4)
    operator = np.empty((3, n_beams))                # the scene's A^+ and configured beams
    units = np.empty((n_beams, 3))
    normal = np.full((n_beams, 3), zero)             # point-wise: believed earth beams
    along = np.full(n_beams, zero)                   # ... the ship velocity along them
    mean = np.full(6, zero)                          # ... and the mean reading (tilt2d)
    matrix = np.full((3, 3), zero)
    gram = np.full((3, 3), zero)                     # B^T B of a reading
    rhs = np.full(3, zero)
    one = zero + 1.0
    mean_rot = _rotation(FULL, one, zero, one, zero, one, zero, 1.0, 0.0)
    mean_ship = (zero, zero)
    for s in range(s0, s1):
        speed_ref, w = table[s, _SPEED], table[s, _VERTICAL]
        to_north = -table[s, _COS + _T_DIRECTION]       # wind "from": it blows to -e
        to_east = -table[s, _SIN + _T_DIRECTION]
        sog0, cog0, heave0, heading0 = table[s, _SOG], table[s, _COG], table[s, _HEAVE], table[s, _HEADING]
        true_ship = (sog0 * table[s, _COS + _T_COG], sog0 * table[s, _SIN + _T_COG], heave0)
        cos_nominal, sin_nominal = table[s, _COS + _T_HEADING], table[s, _SIN + _T_HEADING]
        shape = int(table[s, _GEOMETRY_ROW])
        for b in range(n_beams):             # copies, not views (reference counts)
            for k in range(3):
                operator[k, b] = shapes[shape, at_operator + k * n_beams + b]
                units[b, k] = shapes[shape, at_units + 3 * b + k]
        base[0], base[1], base[2], base[3] = heading0, table[s, _PITCH], table[s, _ROLL], cog0
        tr0 = (s - s0) * count if per_scene else 0
        _readings(heading_error, 0, heading0, table[s, _COS + _T_HEADING],
                  table[s, _SIN + _T_HEADING], s, t0, count, tr0, cos_trig, sin_trig,
                  cos_read, sin_read)
        _readings(pitch_error, 1, table[s, _PITCH], table[s, _COS + _T_PITCH],
                  table[s, _SIN + _T_PITCH], s, t0, count, tr0, cos_trig, sin_trig,
                  cos_read, sin_read)
        _readings(roll_error, 2, table[s, _ROLL], table[s, _COS + _T_ROLL],
                  table[s, _SIN + _T_ROLL], s, t0, count, tr0, cos_trig, sin_trig,
                  cos_read, sin_read)
        _readings(cog_error, 3, cog0, table[s, _COS + _T_COG], table[s, _SIN + _T_COG], s,
                  t0, count, tr0, cos_trig, sin_trig, cos_read, sin_read)
        if not per_trial:                    # one truth for all trials: A^+ truth once
            r = s
            _true_radials(beams, profile, r, speed_ref, w, to_north, to_east, true_ship,
                          n_beams, n_gates, truth)
            for g in range(n_gates):
                for k in range(3):
                    total = zero
                    for b in range(n_beams):
                        total += operator[k, b] * truth[b, g]
                    lidar_frame[k, g] = total
            if want_height:
                _gate_heights(table, s, shapes, shape, beams, r, _pick(height_error, t0, s, 0), n_slanted,
                              n_gates, at_slant, heights)
        noise_s = s if noise.shape[1] > 1 else 0
        for i in range(t0, t1):
            j = i - t0
            noise_i = i if noise.shape[0] > 1 else 0
            if per_trial:                           # this trial's true radial velocities
                r = (s - s0) * count + j
                _true_radials(beams, profile, r, speed_ref, w, to_north, to_east, true_ship,
                              n_beams, n_gates, truth)
                if want_height:
                    _gate_heights(table, s, shapes, shape, beams, r, _pick(height_error, i, s, 0), n_slanted,
                                  n_gates, at_slant, heights)
            if want_height:
                for g in range(n_gates):
                    gate_height[s, g, i] = heights[g]
            if not pointwise:
                # ---- one reading per scan: Eq. 13 [1]
                if model == NONE:                    # none: the configured heading, fixed
                    rot = _rotation(NONE, one, zero, one, zero, one, zero, cos_nominal,
                                    sin_nominal)
                    cc, sc = zero, zero
                else:
                    rot = _rotation(model, cos_read[0, 0, j], sin_read[0, 0, j],
                                    cos_read[1, 0, j], sin_read[1, 0, j], cos_read[2, 0, j],
                                    sin_read[2, 0, j], cos_nominal, sin_nominal)
                    cc, sc = cos_read[3, 0, j], sin_read[3, 0, j]
                sog = sog0 + _pick(sog_error, i, s, 0)
                heave = heave0 + _pick(heave_error, i, s, 0)
                moving = model != NONE
                ship = (sog * cc if moving else zero, sog * sc if moving else zero,
                        heave if model == FULL else zero)
                for g in range(n_gates):                 # the lidar-frame wind A^+ v
                    if per_trial:                        # v = truth + noise
                        x = y = z = zero
                        for b in range(n_beams):
                            value = truth[b, g] + noise[noise_i, noise_s, b * n_gates + g] \
                                if has_noise else truth[b, g]
                            x += operator[0, b] * value
                            y += operator[1, b] * value
                            z += operator[2, b] * value
                    else:                                # A^+ truth + A^+ noise
                        x, y, z = lidar_frame[0, g], lidar_frame[1, g], lidar_frame[2, g]
                        if has_noise:
                            for b in range(n_beams):
                                value = noise[noise_i, noise_s, b * n_gates + g]
                                x += operator[0, b] * value
                                y += operator[1, b] * value
                                z += operator[2, b] * value
                    north = rot[0] * x + rot[1] * y + ship[0]                # Eq. 13 [1]
                    east = rot[3] * x + rot[4] * y + ship[1]
                    up = z
                    if model == FULL:
                        north += rot[2] * z
                        east += rot[5] * z
                        up = rot[6] * x + rot[7] * y + rot[8] * z + ship[2]
                    if want_speed:
                        speed[s, g, i] = _hypot(north, east)
                    if want_vertical:
                        vertical[s, g, i] = up
                    if want_direction:
                        from_north[s, g, i], from_east[s, g, i] = -north, -east
                if want_radial:        # measured + (R n_lidar) . ship: motion-free radial
                    for b in range(n_beams):
                        e0 = rot[0] * units[b, 0] + rot[1] * units[b, 1] + rot[2] * units[b, 2]
                        e1 = rot[3] * units[b, 0] + rot[4] * units[b, 1] + rot[5] * units[b, 2]
                        e2 = rot[6] * units[b, 0] + rot[7] * units[b, 1] + rot[8] * units[b, 2]
                        removed = e0 * ship[0] + e1 * ship[1] + e2 * ship[2]
                        for g in range(n_gates):
                            measured = truth[b, g] + noise[noise_i, noise_s, b * n_gates + g] \
                                if has_noise else truth[b, g]
                            radial[s, b, g, i] = measured + removed
                continue
            # ---- a reading per beam: point-wise correction, then least squares [2]
            for b in range(n_beams):
                if model == NONE:
                    rot = _rotation(NONE, 1.0, 0.0, 1.0, 0.0, 1.0, 0.0, cos_nominal,
                                    sin_nominal)
                else:
                    rot = _beam_rotation(model, cos_read, sin_read, j, b, heading_error, pitch_error,
                                         roll_error, cos_nominal, sin_nominal)
                _believed_beam(rot, units, b, normal)
                if model == NONE:
                    along[b] = zero
                else:
                    kc = b if cog_error.shape[2] > 1 else 0
                    sog = sog0 + _pick(sog_error, i, s, b)
                    heave = heave0 + _pick(heave_error, i, s, b) if model == FULL else zero
                    along[b] = normal[b, 0] * (sog * cos_read[3, kc, j]) + \
                        normal[b, 1] * (sog * sin_read[3, kc, j]) + normal[b, 2] * heave
            if want_radial:
                for b in range(n_beams):
                    for g in range(n_gates):
                        measured = truth[b, g] + noise[noise_i, noise_s, b * n_gates + g] \
                            if has_noise else truth[b, g]
                        radial[s, b, g, i] = measured + along[b]
            if not (want_speed or want_direction or want_vertical):
                continue
            _normal_matrix(normal, n_beams, gram, zero)   # the least squares' B^T B
            if model == TILT2D:                      # tilt2d: the mean reading (Eq. 13 [1])
                mean_rot, mean_ship = _tilt2d_mean(heading_error, pitch_error, roll_error,
                                                   cog_error, sog_error, base, sog0, i, s,
                                                   zero, mean, cos_nominal, sin_nominal)
            for g in range(n_gates):
                for k in range(3):
                    total = zero
                    for b in range(n_beams):
                        total += normal[b, k] * (
                            (truth[b, g] + noise[noise_i, noise_s, b * n_gates + g] if has_noise
                             else truth[b, g]) + along[b])
                    rhs[k] = total
                north, east, up = _pointwise_solve(gram, matrix, rhs)
                if model == TILT2D:
                    north, east, up = _tilt2d_project(mean_rot, mean_ship, north, east, up)
                if want_speed:
                    speed[s, g, i] = _hypot(north, east)
                if want_vertical:
                    vertical[s, g, i] = up
                if want_direction:
                    from_north[s, g, i], from_east[s, g, i] = -north, -east


def wind_scan(table, shapes, structure, ins, noise, cos_trig, sin_trig, beams, profile,
              height_error, s0, s1, t0, t1, per_scene, per_trial, speed, vertical, from_north,
              from_east, radial, gate_height):
    """:func:`_wind` with one INS reading per scan (every INS error (n, s, 1))."""
    _wind(table, shapes, structure, ins, noise, cos_trig, sin_trig, beams, profile, height_error,
          s0, s1, t0, t1, per_scene, per_trial, speed, vertical, from_north, from_east,
          radial, gate_height, False)


def wind_pointwise(table, shapes, structure, ins, noise, cos_trig, sin_trig, beams,
                   profile, height_error, s0, s1, t0, t1, per_scene, per_trial, speed,
                   vertical, from_north, from_east, radial, gate_height):
    """:func:`_wind` with a reading per beam for some INS error (point-wise)."""
    _wind(table, shapes, structure, ins, noise, cos_trig, sin_trig, beams, profile, height_error,
          s0, s1, t0, t1, per_scene, per_trial, speed, vertical, from_north, from_east,
          radial, gate_height, True)


#: The structure vector of a tilted mount's kernels: STRUCTURE, then whether the shear
#: exponent is wanted and the beam indices of the level pair (clock 90 and 270) and of
#: the upper and lower beams (-1: none; :mod:`uq.physics.nacelle`).
MOUNTED_STRUCTURE = STRUCTURE + ("want_shear", "level_first", "level_second", "upper",
                                 "lower")


@_helper
def _reading_operator(n_beams, model, level_a, level_b, operator, normal, along, rot, ship,
                      inverse, zero, reading, offset):
    """A tilted mount's wind of one reading as a linear map of the measured radial
    velocities v (b,) [m s-1]: ``(north, east, up) = reading v + offset``, into reading
    (3, b) and offset (3,) [m s-1] (:func:`_wind_mounted`'s reconstruction, the same
    equations folded into one operator, so that a trial costs a 3 x b product as the
    upward lidar's Eq. 13 [1]; within a few ulp of evaluating them in turn).

    2 beams: ``(B_h^T B_h)^-1 B_h^T (v + along)`` with `inverse` that 2 x 2 inverse, w = 0.
    Else Eq. 13 [1]: the reading's rotation `rot` (row-major) of the configured beams'
    ``A^+ v`` (`operator`, (3, b)), horizontal (all three for ``full``), plus the ship
    velocity `ship` removed; with the level pair (beams level_a, level_b >= 0) the
    hub-height wind ``u_h = N^-1 (c_pair - n_pair,up w)`` (`inverse` = N^-1 of the pair's
    believed horizontal parts) with ``c = v + along`` and w that of Eq. 13.
    """
    if n_beams == 2:
        for b in range(2):
            reading[0, b] = inverse[0] * normal[b, 0] + inverse[1] * normal[b, 1]
            reading[1, b] = inverse[2] * normal[b, 0] + inverse[3] * normal[b, 1]
            reading[2, b] = zero
        for k in range(2):
            offset[k] = reading[k, 0] * along[0] + reading[k, 1] * along[1]
        offset[2] = zero
        return
    full = model == FULL
    for b in range(n_beams):                           # Eq. 13 [1]: R A^+ v
        o0, o1, o2 = operator[0, b], operator[1, b], operator[2, b]
        reading[0, b] = rot[0] * o0 + rot[1] * o1 + (rot[2] * o2 if full else zero)
        reading[1, b] = rot[3] * o0 + rot[4] * o1 + (rot[5] * o2 if full else zero)
        reading[2, b] = rot[6] * o0 + rot[7] * o1 + rot[8] * o2 if full else o2 + zero
    offset[0], offset[1] = ship[0] + zero, ship[1] + zero
    offset[2] = ship[2] + zero if full else zero
    if level_a < 0:
        return
    up_a, up_b = normal[level_a, 2], normal[level_b, 2]
    for b in range(n_beams):                           # N^-1 (e_pair - n_pair,up w row)
        pair_a = (1.0 if b == level_a else 0.0) - up_a * reading[2, b]
        pair_b = (1.0 if b == level_b else 0.0) - up_b * reading[2, b]
        reading[0, b] = inverse[0] * pair_a + inverse[1] * pair_b
        reading[1, b] = inverse[2] * pair_a + inverse[3] * pair_b
    pair_a = along[level_a] - up_a * offset[2]
    pair_b = along[level_b] - up_b * offset[2]
    offset[0] = inverse[0] * pair_a + inverse[1] * pair_b
    offset[1] = inverse[2] * pair_a + inverse[3] * pair_b


@_helper
def _folded_trials(folded, reading, noise, has_noise, s, noise_s, t0, t1, n_beams, n_gates,
                   want_speed, want_vertical, want_direction, rows, speed, vertical,
                   from_north, from_east):
    """The outputs of trials [t0, t1) of scene s whose wind at gate g is ``folded[:, g] +
    reading e_g`` (e_g the trial's radial noise at the gate, (b,)): ``none``'s tilted
    mount with the truth common to the trials (:func:`_wind_mounted`). Loops over the
    trials innermost on the rows (3, t1 - t0) of scratch, without calls (SIMD), the sums
    in the order of the trial-by-trial loop (the same numbers)."""
    count = t1 - t0
    for g in range(n_gates):
        for k in range(3):
            value = folded[k, g]
            for j in range(count):
                rows[k, j] = value
        for b in range(n_beams * has_noise):
            m0, m1, m2 = reading[0, b], reading[1, b], reading[2, b]
            column = b * n_gates + g
            if noise.shape[0] > 1:
                for j in range(count):
                    value = noise[t0 + j, noise_s, column]
                    rows[0, j] += m0 * value
                    rows[1, j] += m1 * value
                    rows[2, j] += m2 * value
            else:
                value = noise[0, noise_s, column]
                for j in range(count):
                    rows[0, j] += m0 * value
                    rows[1, j] += m1 * value
                    rows[2, j] += m2 * value
        if want_speed:
            for j in range(count):
                speed[s, g, t0 + j] = np.sqrt(rows[0, j] * rows[0, j] + rows[1, j] * rows[1, j])
            for j in range(count):                      # where the squares could over- or
                if not HYPOT_SAFE_MIN < speed[s, g, t0 + j].real < HYPOT_SAFE_MAX:  # underflow
                    speed[s, g, t0 + j] = _hypot(rows[0, j], rows[1, j])
        if want_vertical:
            for j in range(count):
                vertical[s, g, t0 + j] = rows[2, j]
        if want_direction:
            for j in range(count):
                from_north[s, g, t0 + j] = -rows[0, j]
                from_east[s, g, t0 + j] = -rows[1, j]


@_helper
def _wind_mounted(table, shapes, structure, ins, noise, cos_trig, sin_trig, beams, profile,
                  height_error, s0, s1, t0, t1, per_scene, per_trial, speed, vertical,
                  from_north, from_east, radial, gate_height, shear_out, pointwise):
    """:func:`_wind` of a tilted (nacelle) mount (:mod:`uq.physics.nacelle`), with the
    structure of :data:`MOUNTED_STRUCTURE` and the shear exponent into shear_out (S, g, n).

    Each beam's believed earth-frame beam (the reading of the scan, or its own) and the
    corrected radial velocity ``c_k = v_k + b_k . s`` (s: the ship velocity the model
    removes). 2 beams: the horizontal least squares of ``b_k,h . u_h = c_k``, w = 0
    assumed. 3 or more: the wind of :func:`_wind` (Eq. 13 of [1] on the configured beams'
    A^+ v, or the point-wise least squares [2]), then with the level pair the hub-height
    horizontal wind ``b_k,h . u_h = c_k - b_k,up w`` of those two beams. The shear
    exponent ``ln(U_up / U_down) / ln(z_up / z_down)``, ``U_k = c_k / (b_k,h . e)`` at the
    believed heights ``z_k = lidar height + slant b_k,up`` (NaN where a ratio is not
    positive).

    The scan's reading and the 2-beam least squares are linear in the measured radial
    velocities v: their equations are folded into one operator per reading
    (:func:`_reading_operator`), so that a trial costs a 3 x b product, as the upward
    lidar's Eq. 13 [1]; ``none``'s reading (the configured heading) is the scene's, and
    with the truth common to the trials its image is taken once per scene, a trial then
    adding the operator's product with its noise alone (as :func:`_wind`'s ``A^+``).
    """
    n_beams, n_gates, model = structure[0], structure[2], structure[3]
    if model != NONE and model != YAW and model != TILT2D and model != FULL:
        raise ValueError("unknown correction model code (see uq.physics.modelinputs)")
    want_speed, want_direction, want_vertical = structure[4], structure[5], structure[6]
    want_radial, want_height, want_shear = structure[7], structure[8], structure[9]
    level_a, level_b, upper, lower = structure[10], structure[11], structure[12], structure[13]
    at_operator, at_slant, at_units, _ = _geometry_offsets(n_beams, n_beams, n_gates)
    heading_error, pitch_error, roll_error = ins[0], ins[1], ins[2]
    sog_error, cog_error, heave_error = ins[3], ins[4], ins[5]
    has_noise = noise.shape[2] > 1
    zero = np.zeros(1, beams.dtype)[0]
    truth = np.full((n_beams, n_gates), zero)
    heights = np.full(n_gates, zero)
    count = t1 - t0
    reads = 1 if model == NONE else count            # (none reads no INS)
    cos_read = np.full((4, n_beams, reads), zero)
    sin_read = np.full((4, n_beams, reads), zero)
    base = np.empty(4)
    operator = np.empty((3, n_beams))
    units = np.empty((n_beams, 3))
    normal = np.full((n_beams, 3), zero)             # believed earth-frame beams
    along = np.full(n_beams, zero)                   # ... the removed velocity along them
    corrected = np.full(n_beams, zero)               # c_k of one gate
    mean = np.full(6, zero)
    matrix = np.full((3, 3), zero)
    gram = np.full((3, 3), zero)                     # B^T B of a reading
    rhs = np.full(3, zero)
    one = zero + 1.0
    rot = _rotation(FULL, one, zero, one, zero, one, zero, 1.0, 0.0)
    mean_rot = rot
    mean_ship = (zero, zero)
    ship = (zero, zero, zero)
    inverse = (zero, zero, zero, zero)
    # the scan's reading, or two beams': the wind is one linear map of the measured radial
    # velocities v (:func:`_reading_operator`), once per reading (none's: per scene)
    linear = n_beams == 2 or not pointwise
    reading = np.full((3, n_beams), zero)
    offset = np.full(3, zero)
    folded = np.full((3, n_gates), zero)             # none's map of the scene's truth
    # ... whose trials then differ by their noise alone: rows over the trials
    rows_only = linear and model == NONE and not per_trial and not want_radial \
        and not want_shear
    rows = np.full((3, t1 - t0 if rows_only else 1), zero)
    for s in range(s0, s1):
        speed_ref, w = table[s, _SPEED], table[s, _VERTICAL]
        to_north = -table[s, _COS + _T_DIRECTION]       # wind "from": it blows to -e
        to_east = -table[s, _SIN + _T_DIRECTION]
        sog0, cog0, heave0 = table[s, _SOG], table[s, _COG], table[s, _HEAVE]
        true_ship = (sog0 * table[s, _COS + _T_COG], sog0 * table[s, _SIN + _T_COG], heave0)
        cos_nominal, sin_nominal = table[s, _COS + _T_HEADING], table[s, _SIN + _T_HEADING]
        lidar_height = table[s, _LIDAR_HEIGHT]
        shape = int(table[s, _GEOMETRY_ROW])
        for b in range(n_beams):
            for k in range(3):
                operator[k, b] = shapes[shape, at_operator + k * n_beams + b]
                units[b, k] = shapes[shape, at_units + 3 * b + k]
        base[0], base[1], base[2], base[3] = table[s, _HEADING], table[s, _PITCH], \
            table[s, _ROLL], cog0
        tr0 = (s - s0) * count if per_scene else 0
        if model != NONE:
            _readings(heading_error, 0, base[0], cos_nominal, sin_nominal, s, t0, count, tr0,
                      cos_trig, sin_trig, cos_read, sin_read)
            _readings(pitch_error, 1, base[1], table[s, _COS + _T_PITCH],
                      table[s, _SIN + _T_PITCH], s, t0, count, tr0, cos_trig, sin_trig,
                      cos_read, sin_read)
            _readings(roll_error, 2, base[2], table[s, _COS + _T_ROLL],
                      table[s, _SIN + _T_ROLL], s, t0, count, tr0, cos_trig, sin_trig,
                      cos_read, sin_read)
            _readings(cog_error, 3, cog0, table[s, _COS + _T_COG], table[s, _SIN + _T_COG],
                      s, t0, count, tr0, cos_trig, sin_trig, cos_read, sin_read)
        if not per_trial:
            _true_radials(beams, profile, s, speed_ref, w, to_north, to_east, true_ship,
                          n_beams, n_gates, truth)
            if want_height:
                _gate_heights(table, s, shapes, shape, beams, s, _pick(height_error, t0, s, 0),
                              n_beams, n_gates, at_slant, heights)
        noise_s = s if noise.shape[1] > 1 else 0
        for i in range(t0, t1):
            j = i - t0
            noise_i = i if noise.shape[0] > 1 else 0
            if per_trial:
                r = (s - s0) * count + j
                _true_radials(beams, profile, r, speed_ref, w, to_north, to_east, true_ship,
                              n_beams, n_gates, truth)
                if want_height:
                    _gate_heights(table, s, shapes, shape, beams, r,
                                  _pick(height_error, i, s, 0), n_beams, n_gates, at_slant,
                                  heights)
            if want_height:
                for g in range(n_gates):
                    gate_height[s, g, i] = heights[g]
            # the believed beams and the velocity removed along them (each beam's own
            # reading; a scan's reading is the same for every beam: k = 1, computed for
            # the first beam; none's: the configured heading, the scene's first trial's)
            for b in range(n_beams):
                if (model == NONE and i > t0) or (b > 0 and not pointwise):
                    pass                        # the same rotation and ship velocity
                elif model == NONE:
                    rot = _rotation(NONE, one, zero, one, zero, one, zero, cos_nominal,
                                    sin_nominal)
                    ship = (zero, zero, zero)
                else:
                    rot = _beam_rotation(model, cos_read, sin_read, j, b, heading_error, pitch_error,
                                         roll_error, cos_nominal, sin_nominal)
                    kc = b if cog_error.shape[2] > 1 else 0
                    sog = sog0 + _pick(sog_error, i, s, b)
                    ship = (sog * cos_read[3, kc, j], sog * sin_read[3, kc, j],
                            heave0 + _pick(heave_error, i, s, b) if model == FULL else zero)
                if model == NONE and i > t0:
                    continue                    # none's believed beams: the scene's
                _believed_beam(rot, units, b, normal)
                along[b] = normal[b, 0] * ship[0] + normal[b, 1] * ship[1] + \
                    normal[b, 2] * ship[2]
            if not (model == NONE and i > t0):  # the 2 x 2 inverses of the believed beams
                if n_beams == 2:                # the horizontal normal equations
                    h00 = normal[0, 0] * normal[0, 0] + normal[1, 0] * normal[1, 0]
                    h01 = normal[0, 0] * normal[0, 1] + normal[1, 0] * normal[1, 1]
                    h11 = normal[0, 1] * normal[0, 1] + normal[1, 1] * normal[1, 1]
                    inverse = _inverse2(h00, h01, h01, h11)
                elif level_a >= 0:              # the level pair's horizontal parts
                    inverse = _inverse2(normal[level_a, 0], normal[level_a, 1],
                                        normal[level_b, 0], normal[level_b, 1])
                if linear:                      # the reading's wind: one linear map of v
                    _reading_operator(n_beams, model, level_a, level_b, operator, normal,
                                      along, rot, ship, inverse, zero, reading, offset)
                    if model == NONE and not per_trial:     # ... and of the scene's truth
                        for g in range(n_gates):
                            for k in range(3):
                                total = offset[k]
                                for b in range(n_beams):
                                    total += reading[k, b] * truth[b, g]
                                folded[k, g] = total
                        if rows_only:           # every trial of the scene at once
                            _folded_trials(folded, reading, noise, has_noise, s, noise_s,
                                           t0, t1, n_beams, n_gates, want_speed,
                                           want_vertical, want_direction, rows, speed,
                                           vertical, from_north, from_east)
                            if want_height:
                                for g in range(n_gates):
                                    gate_height[s, g, t0:t1] = heights[g]
                            break
            if not linear:                      # the point-wise least squares' B^T B
                _normal_matrix(normal, n_beams, gram, zero)
            if pointwise and model == TILT2D and n_beams > 2:   # the mean reading, Eq. 13 [1]
                mean_rot, mean_ship = _tilt2d_mean(heading_error, pitch_error, roll_error,
                                                   cog_error, sog_error, base, sog0, i, s,
                                                   zero, mean, cos_nominal, sin_nominal)
            for g in range(n_gates):
                north = east = up = zero
                if linear and model == NONE and not per_trial:  # the truth's part: folded
                    north, east, up = folded[0, g], folded[1, g], folded[2, g]
                    if has_noise:
                        for b in range(n_beams):
                            value = noise[noise_i, noise_s, b * n_gates + g]
                            north += reading[0, b] * value
                            east += reading[1, b] * value
                            up += reading[2, b] * value
                elif linear:                    # (north, east, up) = reading v + offset
                    north, east, up = offset[0], offset[1], offset[2]
                    for b in range(n_beams):
                        value = truth[b, g] + noise[noise_i, noise_s, b * n_gates + g] \
                            if has_noise else truth[b, g]
                        north += reading[0, b] * value
                        east += reading[1, b] * value
                        up += reading[2, b] * value
                if want_radial or want_shear or not linear:     # c_k = v_k + b_k . s
                    for b in range(n_beams):
                        measured = truth[b, g] + noise[noise_i, noise_s, b * n_gates + g] \
                            if has_noise else truth[b, g]
                        corrected[b] = measured + along[b]
                        if want_radial:
                            radial[s, b, g, i] = corrected[b]
                if not linear:                  # point-wise least squares [2]
                    for k in range(3):
                        total = zero
                        for b in range(n_beams):
                            total += normal[b, k] * corrected[b]
                        rhs[k] = total
                    north, east, up = _pointwise_solve(gram, matrix, rhs)
                    if model == TILT2D:
                        north, east, up = _tilt2d_project(mean_rot, mean_ship, north, east,
                                                          up)
                    if level_a >= 0:            # the hub-height wind of the level beams
                        r0 = corrected[level_a] - normal[level_a, 2] * up
                        r1 = corrected[level_b] - normal[level_b, 2] * up
                        north = inverse[0] * r0 + inverse[1] * r1
                        east = inverse[2] * r0 + inverse[3] * r1
                if n_beams == 2:                # w = 0 (not 0 x a NaN)
                    up = zero
                if want_speed:
                    speed[s, g, i] = _hypot(north, east)
                if want_vertical:
                    vertical[s, g, i] = up
                if want_direction:
                    from_north[s, g, i], from_east[s, g, i] = -north, -east
                if want_shear:
                    shear_out[s, g, i] = _shear_exponent(
                        north, east, normal, corrected, lidar_height,
                        shapes[shape, at_slant + upper * n_gates + g],
                        shapes[shape, at_slant + lower * n_gates + g], upper, lower)


@_helper
def _shear_exponent(north, east, normal, corrected, lidar_height, slant_upper, slant_lower,
                    upper, lower):
    """``ln(U_up / U_down) / ln(z_up / z_down)`` with ``U_k = c_k / (b_k,h . e)`` and the
    believed heights ``z_k`` (:func:`uq.physics.nacelle.shear_exponent`); NaN where a
    ratio is not positive."""
    speed = np.sqrt(north * north + east * east)
    along_upper = (normal[upper, 0] * north + normal[upper, 1] * east) / speed
    along_lower = (normal[lower, 0] * north + normal[lower, 1] * east) / speed
    ratio_speed = (corrected[upper] / along_upper) / (corrected[lower] / along_lower)
    ratio_height = (lidar_height + slant_upper * normal[upper, 2]) / \
        (lidar_height + slant_lower * normal[lower, 2])
    if ratio_speed.real > 0 and ratio_height.real > 0:
        return np.log(ratio_speed) / np.log(ratio_height)
    return np.nan + 0 * ratio_speed


def wind_mounted_scan(table, shapes, structure, ins, noise, cos_trig, sin_trig, beams,
                      profile, height_error, s0, s1, t0, t1, per_scene, per_trial, speed,
                      vertical, from_north, from_east, radial, gate_height, shear_out):
    """:func:`_wind_mounted` with one INS reading per scan."""
    _wind_mounted(table, shapes, structure, ins, noise, cos_trig, sin_trig, beams, profile,
                  height_error, s0, s1, t0, t1, per_scene, per_trial, speed, vertical,
                  from_north, from_east, radial, gate_height, shear_out, False)


def wind_mounted_pointwise(table, shapes, structure, ins, noise, cos_trig, sin_trig, beams,
                           profile, height_error, s0, s1, t0, t1, per_scene, per_trial, speed,
                           vertical, from_north, from_east, radial, gate_height, shear_out):
    """:func:`_wind_mounted` with a reading per beam (point-wise)."""
    _wind_mounted(table, shapes, structure, ins, noise, cos_trig, sin_trig, beams, profile,
                  height_error, s0, s1, t0, t1, per_scene, per_trial, speed, vertical,
                  from_north, from_east, radial, gate_height, shear_out, True)


#: Half an ulp of 1.0: the series' truncation bound of :func:`power_near`, and room for
#: its terms.
_HALF_ULP, _MAX_TERMS = 2.0 ** -53, 64
#: Leading mantissa bits that pick a value's reference x0 in :func:`power_near`: x0 is the
#: midpoint of the 2^-6-wide interval of mantissas the value is in, so |x / x0 - 1| <=
#: 2^-7 / (1 + 2^-7) = 1 / 129.
_GRID_BITS = 6
_POWER_DEVIATION = 1.0 / (2 ** (_GRID_BITS + 1) + 1)
_MANTISSA_BITS, _EXPONENT_MASK, _INFINITE_EXPONENT = 52, 0x7FF, 0x7FF
#: Slots of a call's table of references (their x0^a and 1 / x0).
_POWER_SLOTS = 1024


def power_near(values, exponent):
    """values[i, :] ** exponent[i] in place: x^a = exp(a log x), as numpy's log and exp
    give it (NaN for NaN or x < 0, 0 or inf at x = 0), for the ratios z / z_ref of a
    power-law profile, in ~4 ns a value instead of libm's ~12. Each x takes its
    reference x0 from its own bits (its binary exponent and its leading
    :data:`_GRID_BITS` mantissa bits, then the midpoint of that interval), so the
    result depends on x and a alone (not on the other rows: a scene in a batch gives
    the bits of the scene alone). x^a = x0^a (libm, once per reference and exponent in
    a call) times the binomial series of (1 + d)^a, d = x / x0 - 1, |d| <= 1/129,
    summed to within half an ulp (:func:`binomial_terms`) in a loop without calls
    (SIMD). Zero, negative and non-finite values, and exponents with |a| > 1
    (:data:`~uq.constants.POWER_SERIES_MAX_EXPONENT`), take libm's log and exp.

    values : (rows, k) float64, C-contiguous; exponent : (rows,) [1]."""
    rows, k = values.shape
    flat = values.reshape(rows * k)
    bits = flat.view(np.int64)
    deviation, scale, total = np.empty(rows * k), np.empty(rows * k), np.empty(rows * k)
    reference = np.empty(1)
    reference_bits = reference.view(np.int64)
    # x0^a and 1 / x0 by reference, in slots of the reference's key (a collision,
    # exponents 2^10 apart, recomputes); stamped with the run of rows they belong to
    powers, inverses = np.empty(_POWER_SLOTS), np.empty(_POWER_SLOTS)
    references = np.empty(_POWER_SLOTS)
    keys, stamps = np.full(_POWER_SLOTS, -1, np.int64), np.zeros(_POWER_SLOTS, np.int64)
    coefficients = np.empty(_MAX_TERMS)
    shift = _MANTISSA_BITS - _GRID_BITS
    midpoint = 1 << (shift - 1)
    generation = 0
    first = 0
    while first < rows:                               # runs of rows of one exponent
        a = exponent[first]
        last = first + 1
        while last < rows and exponent[last] == a:
            last += 1
        generation += 1
        usable = abs(a) <= POWER_SERIES_MAX_EXPONENT
        # (views indexed from 0: numba then knows no index is negative, and the loops
        # over them compile to SIMD code)
        run_flat, run_bits = flat[first * k:last * k], bits[first * k:last * k]
        run_deviation, run_scale = deviation[first * k:last * k], scale[first * k:last * k]
        run_total = total[first * k:last * k]
        for index in range(run_flat.shape[0]):
            word = run_bits[index]
            biased = (word >> _MANTISSA_BITS) & _EXPONENT_MASK
            if not usable or word <= 0 or biased == 0 or biased == _INFINITE_EXPONENT:
                run_deviation[index] = 0.0            # x <= 0, subnormal, inf, NaN: libm
                run_scale[index] = _exact_power(run_flat[index], a)
                continue
            key = word >> shift                       # the exponent and the grid bits
            slot = key & (_POWER_SLOTS - 1)
            if keys[slot] != key or stamps[slot] != generation:
                reference_bits[0] = (key << shift) | midpoint
                powers[slot] = math.exp(a * math.log(reference[0]))
                inverses[slot] = 1.0 / reference[0]
                references[slot] = reference[0]
                keys[slot], stamps[slot] = key, generation
            run_deviation[index] = (run_flat[index] - references[slot]) * inverses[slot]
            run_scale[index] = powers[slot]
        terms = binomial_terms(a, _POWER_DEVIATION, coefficients)
        run_total[:] = coefficients[terms - 1]
        for term in range(terms - 2, -1, -1):         # Horner, value by value
            c = coefficients[term]
            for index in range(run_total.shape[0]):
                run_total[index] = run_total[index] * run_deviation[index] + c
        for index in range(run_total.shape[0]):
            run_flat[index] = run_scale[index] * run_total[index]
        first = last


@_helper
def binomial_terms(exponent, deviation, coefficients):
    """The binomial coefficients C(a, 0 .. K-1) of (1 + d)^a into coefficients[:K] and
    K: the fewest terms after which the remainder's bound, |C(a, K)| d^K / (1 - d) (for
    |a| <= 1 the coefficients' magnitudes do not grow after C(a, 1)), over the least
    value of the sum, 1 - d, is within half an ulp. |d| <= deviation < 1."""
    coefficients[0] = 1.0
    terms = 1
    bound = abs(exponent) * deviation / (1.0 - deviation) ** 2
    while bound > _HALF_ULP and terms < coefficients.shape[0]:
        coefficients[terms] = coefficients[terms - 1] * (exponent - terms + 1) / terms
        terms += 1
        bound = abs(coefficients[terms - 1] * (exponent - terms + 1) / terms) * \
            deviation ** terms / (1.0 - deviation) ** 2
    return terms


@njit(inline="always")
def _exact_power(x, exponent):
    """x ** exponent as numpy's exp(a log x) gives it (log 0 = -inf, log x<0 = NaN)."""
    if x > 0:
        return math.exp(exponent * math.log(x))
    if x == 0:
        return math.exp(exponent * -math.inf)
    return math.nan


#: The kernels, each with its kind of signature.
_KERNELS = {"ins_trig": (ins_trig, "trig"), "geometry": (geometry, "geometry"),
            "wind_scan": (wind_scan, "wind"), "wind_pointwise": (wind_pointwise, "wind"),
            "geometry_mounted": (geometry_mounted, "geometry"),
            "wind_mounted_scan": (wind_mounted_scan, "wind_mounted"),
            "wind_mounted_pointwise": (wind_mounted_pointwise, "wind_mounted"),
            "power_near": (power_near, "power")}
#: The kernels' names (each compiled for float64 and complex128 by :func:`compiled`).
KERNEL_NAMES = tuple(_KERNELS)
#: Those of a tilted mount, which runs them in float64 alone (its complex step, the
#: GUM, is the numpy model's: :func:`uq.physics.fused.declined`).
MOUNTED_KERNEL_NAMES = ("geometry_mounted", "wind_mounted_scan", "wind_mounted_pointwise")
#: The kernels compiled for float64 alone (:func:`power_near` is not called with complex
#: numbers: a complex step's profile takes numpy's log and exp).
REAL_KERNEL_NAMES = MOUNTED_KERNEL_NAMES + ("power_near",)


@functools.cache
def compiled(dtype):
    """The kernels compiled for float64 or complex128 (the complex-step GUM), by name:
    each kernel is compiled (or loaded from numba's on-disk cache) on first use, so a
    Monte Carlo run never compiles the complex kernels, nor a scan-wise run the
    point-wise one."""
    return _Kernels(types.complex128 if np.dtype(dtype).kind == "c" else types.float64)


class _Kernels(dict):
    """name -> compiled kernel of one number type, each compiled when first asked for."""

    def __init__(self, number):
        super().__init__()
        self.number = number

    def __missing__(self, name):
        function, kind = _KERNELS[name]
        self[name] = njit(_signature(kind, self.number), cache=True, nogil=True)(function)
        return self[name]
