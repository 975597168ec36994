"""Compiled (numba) loops of :mod:`uq.physics.fusedmotion`: the time-resolved measurement
model on blocks of trials.

Every loop runs over the trials of a block innermost, on rows of block scratch arrays
with unit stride and no calls, so that it compiles to SIMD code; what varies between
beams, dwell nodes, motion components and degrees of freedom is the outer loops. Two
kernels per block, and numpy's SIMD ``log`` and ``exp`` between them for the power law:

1. :func:`kinematics`: the random phases of the block, the true beams (with geometry
   errors), and at every measurement time (a beam's time stamp or a node of its dwell)
   the platform's motion, attitude and velocity, the true beam in the earth frame, the
   gate heights (as z / z_ref for the power law) and the parts of the radial velocity.
2. :func:`reconstruct`: the measured radial velocities (the dwell mean plus noise), the
   INS reading(s) (continuous, or interpolated between its samples: nearest, or linear
   with the attitude by slerp), the correction (point-wise least squares, or one reading
   per scan under ``none``, ``yaw``, ``tilt2d``, ``full``) and the wind.

Sines and cosines come from :func:`sincos`: Cody-Waite reduction by k pi / 2 and the
Taylor polynomials of sin and cos on [-pi/4, pi/4], SIMD; libm beyond
:data:`~uq.constants.SINCOS_REDUCTION_LIMIT` (and for NaN) in a second pass.

The motion at a time t is ``x_d(t) = sum_k A_dk [sin(w_k t + psi_dk) c_k1 + cos(...) c_k2]``
(:mod:`uq.physics.motion`); the sines and cosines of ``w_k t + psi_dk`` at the
measurement times and INS read times are the same for every trial (tables of
:mod:`uq.physics.fusedmotion`). A trial reads the INS at ``t + s`` with its own time
shift s (clock offset, or the INS sample's time): the motion there is that at t with the
phase vectors turned by ``w_k s``, ``c' = (c1 cos ws - c2 sin ws, c1 sin ws + c2 cos ws)``,
since ``sin(a + ws) c1 + cos(a + ws) c2 = sin(a) c1' + cos(a) c2'``.

Rotations are applied as the product of the elementary ones, ``Rz(heading) Ry(pitch)
Rx(roll) x`` (:mod:`uq.physics.rotation`: roll about the bow, then pitch about the
starboard axis, then heading about the vertical), and their time derivative by the
product rule on the three factors (the lever-arm velocity), written from those
definitions and not from the numpy code's expanded matrices.

References
----------
.. [1] Cody, W. J. and Waite, W. (1980). Software Manual for the Elementary Functions.
   Prentice-Hall, Ch. 8 (argument reduction).
.. [2] Abramowitz, M. and Stegun, I. A. (1964). Handbook of Mathematical Functions,
   4.3.65-66 (sin, cos), 4.4.40 (arcsin).
.. [3] Matavar, A. (2024). Wind field reconstruction from floating lidars. MSc thesis,
   TU Delft, Sec. 3.2 (point-wise correction).
"""
import functools
import math

import numpy as np
from numba import njit

from uq.constants import (HALF_PI_PARTS, HYPOT_SAFE_MAX, HYPOT_SAFE_MIN,
                          SINCOS_REDUCTION_LIMIT, SLERP_SERIES_LIMIT)
from uq.physics.kernelbase import (COS_TAYLOR, DEG as _DEG, FULL, NONE, POINTWISE, SIN_TAYLOR,
                                   YAW, horner as _horner, inverse2 as _inverse2,
                                   row_layout)

_TWO_OVER_PI = 2.0 / math.pi
_P1, _P2, _P3 = HALF_PI_PARTS
# the Taylor coefficients of sine and cosine (kernelbase): on |x| <= pi/4 the first
# omitted terms, x^16/17! = 6e-17 (against sin x >= 0.7 x) and x^18/18! = 2e-18, are below
# half an ulp [2]
_SIN, _COS = SIN_TAYLOR, COS_TAYLOR
# arcsin s / s = sum binom(2k, k) / (4^k (2k + 1)) s^2k [2], to s^50: the first omitted
# term at s^2 = SLERP_SERIES_LIMIT = 0.25 is 5e-19
_ASIN = tuple(math.comb(2 * k, k) / (4 ** k * (2 * k + 1)) for k in range(26))
# sin x / x and (1 - cos x) / x^2 = sum (-1)^k x^2k / (2k+2)! for the Rodrigues formula;
# x <= arcsin(sqrt(0.25)) = 0.52: the first omitted terms are below 1e-22
_SINC = tuple((-1) ** k / math.factorial(2 * k + 1) for k in range(10))
_COSC = tuple((-1) ** k / math.factorial(2 * k + 2) for k in range(10))

#: The scene vector (:func:`uq.physics.fusedmotion.scene_plan`): these scalars by index
#: (``level_first``, ``level_second``: the beams of a tilted mount's horizontal solve, the
#: two beams of a 2-beam mount or the level pair at clock 90 and 270; -1: none).
HEAD = ("n_beams", "n_gates", "n_nodes", "n_slanted", "model", "ins_mode", "rate",
        "heading", "pitch", "roll", "lidar_height", "wind_speed", "reference_height", "shear",
        "to_north", "to_east", "vertical_wind", "ship_north", "ship_east", "ship_up",
        "level_cos", "level_sin", "course_cos", "course_sin", "arm_bow", "arm_starboard",
        "arm_up", "static_arm_up", "half_cone", "misalignment", "moves_yaw", "has_arm", "probe",
        "mounted", "tilt_cos", "tilt_sin", "level_first", "level_second")
(_N_BEAMS, _N_GATES, _N_NODES, _N_SLANTED, _MODEL, _INS_MODE, _RATE, _HEADING, _PITCH, _ROLL,
 _LIDAR_HEIGHT, _WIND_SPEED, _REFERENCE_HEIGHT, _SHEAR, _TO_NORTH, _TO_EAST, _VERTICAL_WIND,
 _SHIP_NORTH, _SHIP_EAST, _SHIP_UP, _LEVEL_COS, _LEVEL_SIN, _COURSE_COS, _COURSE_SIN,
 _ARM_BOW, _ARM_STARBOARD, _ARM_UP, _STATIC_ARM_UP, _HALF_CONE, _MISALIGNMENT, _MOVES_YAW,
 _HAS_ARM, _PROBE, _MOUNTED, _TILT_COS, _TILT_SIN, _LEVEL_FIRST, _LEVEL_SECOND) = \
    range(len(HEAD))

#: Correction models: the codes NONE ... POINTWISE of
#: :class:`uq.physics.modelinputs.Correction` (:mod:`uq.physics.kernelbase`); INS modes.
CONTINUOUS, NEAREST, LINEAR = range(3)
#: Per-trial INS inputs of :func:`reconstruct`, in the order of ``has`` (which are given).
INPUTS = ("ins_heading", "ins_pitch", "ins_roll", "ins_sog", "ins_cog", "ins_heave",
          "ins_clock_offset", "ins_sample_offset")
_CLOCK, _OFFSET = 6, 7

#: Rows of a platform state (states[i], (rows, trials)): the six degrees of freedom's
#: values and rates (roll, pitch, yaw, surge, sway, heave) and the attitude's (cos, sin)
#: of heading, pitch and roll.
STATE_BLOCKS = (("value", 6), ("rate", 6), ("trig", 6))
_STATE, STATE_ROWS = row_layout(STATE_BLOCKS)
_VALUE, _RATE_ROW, _TRIG = _STATE["value"], _STATE["rate"], _STATE["trig"]
#: Rows of the block scratch ``work`` (rows, trials), one block after another: temporaries
#: (an angle, its sine and cosine, the clock shift, the lidar's height, a flag), the true
#: beam's cone and misalignment (cos, sin), the believed beam, the lidar velocity along it,
#: the measured radial velocity, the two INS samples of a linear interpolation (matrices,
#: fraction, rates, velocity), one INS reading (the (cos, sin) of heading, pitch, roll;
#: velocity) and the INS errors of one reading (heading, pitch, roll [rad]; sog [m s-1];
#: cog as (cos, sin); heave [m s-1]).
WORK_BLOCKS = (("angle", 1), ("sine", 1), ("cosine", 1), ("shift", 1), ("lidar_z", 1),
               ("big", 1), ("cone", 2), ("misalignment", 2), ("beam", 3), ("along", 1),
               ("measured", 1), ("matrix1", 9), ("matrix2", 9), ("fraction", 1),
               ("rates1", 3), ("velocity1", 3), ("read_trig", 6), ("read_velocity", 3),
               ("error", 3), ("sog", 1), ("cog", 2), ("heave", 1))
WORK, WORK_ROWS = row_layout(WORK_BLOCKS)
(_ANGLE, _SINE, _COSINE, _SHIFT, _LIDAR_Z, _BIG, _CONE, _MIS, _BEAM, _ALONG, _MEASURED,
 _MATRIX1, _MATRIX2, _FRACTION, _RATES1, _VELOCITY1, _READ_TRIG, _READ_VELOCITY, _ERROR,
 _SOG, _COG, _HEAVE) = (WORK[name] for name, _ in WORK_BLOCKS)


_helper = njit(cache=True, nogil=True, error_model="numpy")
#: Compile-time notes (cold first runs), kept by every kernel here:
#: - numba compiles a jitted callee once per distinct *literal* argument (a module-level
#:   int or a True/False written at the call), so row numbers and flags are passed as
#:   values (np.int64(...), a comparison), one compile per helper;
#: - a row is copied by a loop, not ``a[i, :n] = b[k, :n]``: an array-to-array slice
#:   assignment compiles numba's shape-mismatch error (its message built from strings,
#:   ~1.7 s of CPU on the first run) though the shapes here always agree.
#: How the kernels' helpers are compiled (as in :mod:`uq.physics.fusedkernels`): the
#: small ones (trig, rotations, the rotation-group interpolation) as functions of their
#: own that LLVM inlines where it pays, not numba's ``inline="always"``, which re-runs
#: numba's front end on the helper at every call site; the four per-trial helpers of
#: the SIMD loops (the truth at a node, the INS velocity and its errors, the point-wise
#: reading) stay inlined by numba, whose constant arguments then prune their branches.
#: Cold compile of the motion kernels: 33 s of CPU time before, 23 s after; the kernels'
#: CPU time unchanged (2^18 point-wise scans 0.19-0.20 s both ways, floating_lidar_full
#: 0.16 s, floating_lidar_waves 0.89-0.93 s; numba 0.68).
_called = njit(nogil=True, error_model="numpy")
_inline = njit(inline="always", error_model="numpy")


def _kernel(signature):
    return njit(signature, cache=True, nogil=True, error_model="numpy")


@_called
def _head(consts):
    """The scalars of :data:`HEAD` as a tuple: values, not memory, so that loops reading
    them need no alias checks against the arrays they write."""
    return (consts[0], consts[1], consts[2], consts[3], consts[4], consts[5], consts[6], consts[7], consts[8], consts[9], consts[10], consts[11], consts[12], consts[13], consts[14], consts[15], consts[16], consts[17], consts[18], consts[19], consts[20], consts[21], consts[22], consts[23], consts[24], consts[25], consts[26], consts[27], consts[28], consts[29], consts[30], consts[31], consts[32], consts[33], consts[34], consts[35], consts[36], consts[37])


@_called
def sincos(x):
    """(sin x, cos x): x - k pi/2 in three parts (Cody-Waite [1]), the Taylor polynomials
    on [-pi/4, pi/4] and the quadrant k mod 4. Within ~1 ulp for |x| <=
    SINCOS_REDUCTION_LIMIT; no calls, so a loop over it is SIMD code."""
    k = math.floor(x * _TWO_OVER_PI + 0.5)
    r = ((x - k * _P1) - k * _P2) - k * _P3
    r2 = r * r
    s = r * _horner(_SIN, r2)
    c = _horner(_COS, r2)
    quadrant = int(k) & 3
    sine = c if quadrant & 1 else s
    cosine = s if quadrant & 1 else c
    sine = -sine if quadrant & 2 else sine
    cosine = -cosine if (quadrant + 1) & 2 else cosine
    return sine, cosine


@_called
def _trig(x, exact):
    """(sin x, cos x) from :func:`sincos`, or libm (`exact`: the second pass)."""
    if exact:
        return math.sin(x), math.cos(x)
    return sincos(x)


@_helper
def sincos_rows(work, angle, sine, cosine, count):
    """work[sine], work[cosine] = sin, cos of work[angle] (rows; trials < count)."""
    for j in range(count):
        work[sine, j], work[cosine, j] = sincos(work[angle, j])
    for j in range(count):                 # beyond the reduction (and NaN): libm
        x = work[angle, j]
        if not abs(x) <= SINCOS_REDUCTION_LIMIT:
            work[sine, j], work[cosine, j] = math.sin(x), math.cos(x)


@njit(cache=True, nogil=True, error_model="numpy")
def sincos_array(x, out):
    """sin and cos of x into out[:n] and out[n:] (for the tests of :func:`sincos`;
    compiled on its first call, not at import: no run pays for it)."""
    n = x.shape[0]
    work = np.empty((3, n))
    work[0] = x
    sincos_rows(work, 0, 1, 2, n)
    out[:n] = work[1]
    out[n:] = work[2]


@_called
def rotate(ch, sh, cp, sp, cr, sr, x, y, z):
    """``Rz(heading) Ry(pitch) Rx(roll) (x, y, z)``: ship frame to earth frame."""
    y1 = cr * y + sr * z                 # Rx(roll) = [[1, 0, 0], [0, c, s], [0, -s, c]]
    z1 = cr * z - sr * y
    x2 = cp * x - sp * z1                # Ry(pitch) = [[c, 0, -s], [0, 1, 0], [s, 0, c]]
    z2 = sp * x + cp * z1
    return ch * x2 - sh * y1, sh * x2 + ch * y1, z2   # Rz = [[c, -s, 0], [s, c, 0], [0, 0, 1]]


@_called
def rotate_rate(ch, sh, cp, sp, cr, sr, dh, dp, dr, x, y, z):
    """``d/dt [Rz(h) Ry(p) Rx(r)] (x, y, z)`` for rates (dh, dp, dr) [rad s-1]: the velocity
    of a point fixed at (x, y, z) in the ship frame (the product rule on the factors)."""
    y1 = cr * y + sr * z                 # u = Rx x, du = Rx' x dr
    z1 = cr * z - sr * y
    dy1 = (cr * z - sr * y) * dr         # d/dr (c y + s z) = -s y + c z
    dz1 = (-sr * z - cr * y) * dr        # d/dr (c z - s y) = -s z - c y
    x2 = cp * x - sp * z1                # v = Ry u, dv = Ry' u dp + Ry du
    dx2 = (-sp * x - cp * z1) * dp - sp * dz1
    dz2 = (cp * x - sp * z1) * dp + cp * dz1
    return ((-sh * x2 - ch * y1) * dh + (ch * dx2 - sh * dy1),
            (ch * x2 - sh * y1) * dh + (sh * dx2 + ch * dy1), dz2)


@_helper
def _phases(components, sources, phases, window, start, count, c):
    """c[0, k], c[1, k] (trials < count) = the unit phase vector of component k: fixed, or
    from the inputs ``motion_phases`` / ``motion_window`` (column sources[k, 1])."""
    for k in range(components.shape[0]):
        source, column = sources[k, 0], sources[k, 1]
        if source == 0:
            c[0, k, :count] = components[k, 1]
            c[1, k, :count] = components[k, 2]
            continue
        data = phases if source == 1 else window
        if data.shape[0] == 1:
            c[0, k, :count] = data[0, column, 0]
            c[1, k, :count] = data[0, column, 1]
        else:
            for j in range(count):
                c[0, k, j] = data[start + j, column, 0]
                c[1, k, j] = data[start + j, column, 1]


@_helper
def _turn_phases(components, c, work, count, turned):
    """turned = c with every component's phase advanced by w_k work[_SHIFT] (the motion at
    t + shift from the tables at t)."""
    for k in range(components.shape[0]):
        w = components[k, 0]
        for j in range(count):
            work[_ANGLE, j] = w * work[_SHIFT, j]
        sincos_rows(work, np.int64(_ANGLE), np.int64(_SINE), np.int64(_COSINE), count)
        for j in range(count):
            c1, c2 = c[0, k, j], c[1, k, j]
            cosine, sine = work[_COSINE, j], work[_SINE, j]
            turned[0, k, j] = c1 * cosine - c2 * sine
            turned[1, k, j] = c1 * sine + c2 * cosine


@_helper
def _motion(pairs, amplitudes, table, column, c, state, count):
    """Values and rates of the moving degrees of freedom (rows _VALUE, _RATE_ROW of state;
    the others stay 0) at one time: table[0, p, column], table[1, p, column] = sin,
    cos(w t + lag) of pair p = (component, dof); amplitudes[p] = (A, A w). Summed in the
    order of the components."""
    for p in range(pairs.shape[0]):
        d = pairs[p, 1]
        state[_VALUE + d, :count] = 0.0
        state[_RATE_ROW + d, :count] = 0.0
    for p in range(pairs.shape[0]):
        k, d = pairs[p, 0], pairs[p, 1]
        a, aw = amplitudes[p, 0], amplitudes[p, 1]
        s, co = table[0, p, column], table[1, p, column]
        for j in range(count):
            c1, c2 = c[0, k, j], c[1, k, j]
            state[_VALUE + d, j] += a * (s * c1 + co * c2)
            state[_RATE_ROW + d, j] += aw * (co * c1 - s * c2)


@_helper
def _geometry_angle(base, error, start, count, work, row):
    """work[row], work[row + 1] = cos, sin of base + error [deg] (error (n or 1,))."""
    for j in range(count):
        work[_ANGLE, j] = base + error[start + j if error.shape[0] > 1 else 0] * _DEG
    sincos_rows(work, np.int64(_ANGLE), row + 1, row, count)


@_helper
def _geometry(consts, azimuths, beams, cone_error, misalignment_error, height_error, start,
              count, work, ship_beams):
    """The true beams in the ship frame, ship_beams (b, 3, trials): configured geometry +
    errors [deg] (:mod:`uq.physics.beams`); and the lidar's height without its motion,
    work[_LIDAR_Z] = lidar_height + error [m]."""
    n_beams, n_slanted = int(consts[_N_BEAMS]), int(consts[_N_SLANTED])
    if cone_error.shape[0] == 1 and misalignment_error.shape[0] == 1 and \
            cone_error[0] == 0.0 and misalignment_error[0] == 0.0:
        for b in range(n_beams):
            for i in range(3):
                ship_beams[b, i, :count] = beams[b, i]
    else:
        cone, mis = np.int64(_CONE), np.int64(_MIS)   # not literals: one compile, not two
        _geometry_angle(consts[_HALF_CONE], cone_error, start, count, work, cone)
        _geometry_angle(consts[_MISALIGNMENT], misalignment_error, start, count, work, mis)
        for b in range(n_beams):
            if consts[_MOUNTED] > 0:         # clock positions about a tilted boresight
                _mounted_beams(consts, azimuths, b, count, work, ship_beams)
            elif b < n_slanted:
                cos_a, sin_a = azimuths[b, 0], azimuths[b, 1]
                for j in range(count):
                    sin_cone, cos_m, sin_m = work[_CONE + 1, j], work[_MIS, j], work[_MIS + 1, j]
                    ship_beams[b, 0, j] = sin_cone * (cos_m * cos_a - sin_m * sin_a)
                    ship_beams[b, 1, j] = sin_cone * (sin_m * cos_a + cos_m * sin_a)
                    ship_beams[b, 2, j] = work[_CONE, j]
            else:
                ship_beams[b, 0, :count] = 0.0
                ship_beams[b, 1, :count] = 0.0
                ship_beams[b, 2, :count] = 1.0
    height = consts[_LIDAR_HEIGHT]
    for j in range(count):
        work[_LIDAR_Z, j] = height + height_error[start + j if height_error.shape[0] > 1 else 0]


@_helper
def _mounted_beams(consts, azimuths, b, count, work, ship_beams):
    """Beam b of a tilted mount in the ship frame, ship_beams[b] (3, trials), from the
    cone's and misalignment's rows (:func:`uq.physics.beams.mounted_unit_vectors`):
    ``Rz(m) [cos(a) d + sin(a) (cos(phi) e_up + sin(phi) e_starboard)]``, d = (sin tau, 0,
    cos tau), e_up = (-cos tau, 0, sin tau)."""
    cos_phi, sin_phi = azimuths[b, 0], azimuths[b, 1]
    cos_t, sin_t = consts[_TILT_COS], consts[_TILT_SIN]
    for j in range(count):
        cos_a, sin_a = work[_CONE, j], work[_CONE + 1, j]
        cos_m, sin_m = work[_MIS, j], work[_MIS + 1, j]
        bow = cos_a * sin_t - sin_a * cos_phi * cos_t
        starboard = sin_a * sin_phi
        ship_beams[b, 0, j] = cos_m * bow - sin_m * starboard
        ship_beams[b, 1, j] = sin_m * bow + cos_m * starboard
        ship_beams[b, 2, j] = cos_a * cos_t + sin_a * cos_phi * sin_t


@_helper
def _attitude_trig(consts, state, work, count, yaw):
    """The (cos, sin) of the attitude's heading (with `yaw`; else the static heading's),
    pitch and roll at a node from :func:`sincos` into the state's rows, each angle in a
    loop of its own (no calls, few arrays: SIMD), for :func:`_truth_at`'s first pass."""
    for i in range(3 if yaw else 2):
        base, dof = (_PITCH, _ROLL, _HEADING)[i], (1, 0, 2)[i]
        row = (_TRIG + 2, _TRIG + 4, _TRIG)[i]
        angle = consts[base]
        for j in range(count):
            work[_ANGLE, j] = angle + state[_VALUE + dof, j]
        for j in range(count):
            sine, cosine = sincos(work[_ANGLE, j])
            state[row, j] = cosine
            state[row + 1, j] = sine
    if not yaw:
        state[_TRIG, :count] = consts[_LEVEL_COS]
        state[_TRIG + 1, :count] = consts[_LEVEL_SIN]


@_inline
def _truth_at(head, state, work, ship_beams, parts, b, node, j, exact, yaw):
    """The true beam and radial-velocity parts of trial j at a node (see
    :func:`kinematics`); the attitude's (cos, sin) from the state's rows
    (:func:`_attitude_trig`), or with `exact` from libm into them; work[_BIG, j] bounds
    the angles' size (for the libm pass)."""
    heading = head[_HEADING] + state[_VALUE + 2, j]
    pitch = head[_PITCH] + state[_VALUE + 1, j]
    roll = head[_ROLL] + state[_VALUE, j]
    if exact:
        if yaw:
            sh, ch = _trig(heading, exact)
        else:                                   # cos, sin of the static heading
            ch, sh = head[_LEVEL_COS], head[_LEVEL_SIN]
        sp, cp = _trig(pitch, exact)
        sr, cr = _trig(roll, exact)
        state[_TRIG, j], state[_TRIG + 1, j], state[_TRIG + 2, j] = ch, sh, cp
        state[_TRIG + 3, j], state[_TRIG + 4, j], state[_TRIG + 5, j] = sp, cr, sr
    else:                                       # sincos's, SIMD (_attitude_trig)
        ch, sh, cp = state[_TRIG, j], state[_TRIG + 1, j], state[_TRIG + 2, j]
        sp, cr, sr = state[_TRIG + 3, j], state[_TRIG + 4, j], state[_TRIG + 5, j]
    work[_BIG, j] = abs(pitch) + abs(roll) + (abs(heading) if yaw else 0.0)
    bx, by, bz = rotate(ch, sh, cp, sp, cr, sr, ship_beams[b, 0, j], ship_beams[b, 1, j],
                        ship_beams[b, 2, j])
    surge, sway = state[_RATE_ROW + 3, j], state[_RATE_ROW + 4, j]
    level_c, level_s = head[_LEVEL_COS], head[_LEVEL_SIN]
    vn = head[_SHIP_NORTH] + (level_c * surge - level_s * sway)
    ve = head[_SHIP_EAST] + (level_s * surge + level_c * sway)
    vu = head[_SHIP_UP] + state[_RATE_ROW + 5, j]
    arm_up = 0.0
    if head[_HAS_ARM] > 0:             # the lidar at R r from the INS, moving with R' r
        arm_x, arm_y, arm_z = head[_ARM_BOW], head[_ARM_STARBOARD], head[_ARM_UP]
        arm_up = rotate(ch, sh, cp, sp, cr, sr, arm_x, arm_y, arm_z)[2]
        dx, dy, dz = rotate_rate(ch, sh, cp, sp, cr, sr, state[_RATE_ROW + 2, j],
                                 state[_RATE_ROW + 1, j], state[_RATE_ROW, j],
                                 arm_x, arm_y, arm_z)
        vn, ve, vu = vn + dx, ve + dy, vu + dz
    work[_MEASURED, j] = work[_LIDAR_Z, j] + ((state[_VALUE + 5, j] + arm_up)
                                              - head[_STATIC_ARM_UP])
    work[_BEAM + 2, j] = bz
    parts[0, node, j] = bx * head[_TO_NORTH] + by * head[_TO_EAST]
    parts[1, node, j] = bz * head[_VERTICAL_WIND] - (bx * vn + by * ve + bz * vu)


_V, _CV, _M, _CM, _T, _CT = ("float64[:]", "float64[::1]", "float64[:, :]",
                             "float64[:, ::1]", "float64[:, :, :]", "float64[:, :, ::1]")
_IM = "int64[:, ::1]"


@_kernel(f"void({_CV}, {_IM}, {_CM}, {_CM}, {_IM}, {_T}, {_T}, {_CT}, {_CM}, {_CM}, {_CM}, "
         f"{_V}, {_V}, {_V}, int64, int64, {_CM}, {_CT}, {_CT}, {_CT}, {_CT}, {_CT}, {_CM})")
def kinematics(consts, pairs, amplitudes, components, sources, phases, window, node_table,
               azimuths, beams, slant, cone_error, misalignment_error, height_error, start,
               count, work, c, states, ship_beams, parts, ratio, vertical):
    """The truth of trials [start, start + count) at every measurement time.

    Writes ``c`` (2, K, trials), the unit phases; ``parts[0, node]`` = ``n_h . e_wind`` and
    ``parts[1, node]`` = ``n_up w - n . v_lidar`` of the true earth-frame beam n at the
    node (b * n_nodes + q), so that the radial velocity there is ``U(z) parts[0] +
    parts[1]``; ``ratio[node, g]`` = z / z_ref of the gates (1 without shear; NaN at a
    height <= 0, outside the power law) for numpy's log and exp. With one state per beam
    (``states`` (b, STATE_ROWS, trials): the point-wise readings are at the nodes) the
    platform state of beam b is kept in states[b]; else states[0] is scratch. With a
    probe volume (HEAD ``probe``) ``ratio[node, g]`` is the gate centre's height [m]
    itself and ``vertical[node]`` the true beam's up component b_z, for
    :mod:`uq.physics.fusedprobe`.
    """
    head = _head(consts)
    n_beams, n_gates, n_nodes = int(consts[_N_BEAMS]), int(consts[_N_GATES]), int(consts[_N_NODES])
    _phases(components, sources, phases, window, start, count, c)
    _geometry(consts, azimuths, beams, cone_error, misalignment_error, height_error, start,
              count, work, ship_beams)
    reference, shear, yaw = consts[_REFERENCE_HEIGHT], consts[_SHEAR] != 0.0, consts[_MOVES_YAW] > 0
    probe = consts[_PROBE] > 0
    for b in range(n_beams):
        state = states[b if states.shape[0] > 1 else 0]
        state[:_TRIG, :count] = 0.0                   # degrees of freedom that do not move
        for q in range(n_nodes):
            node = b * n_nodes + q
            _motion(pairs, amplitudes, node_table, node, c, state, count)
            _attitude_trig(consts, state, work, count, yaw)
            for j in range(count):
                _truth_at(head, state, work, ship_beams, parts, b, node, j, False, yaw)
            for j in range(count):                    # beyond the reduction (and NaN): libm
                if not work[_BIG, j] <= SINCOS_REDUCTION_LIMIT:
                    _truth_at(head, state, work, ship_beams, parts, b, node, j, True, yaw)
            if probe:                                 # the probe's quadrature: heights
                for j in range(count):
                    vertical[node, j] = work[_BEAM + 2, j]
                for g in range(n_gates):
                    distance = slant[b, g]
                    for j in range(count):
                        ratio[node, g, j] = work[_MEASURED, j] + distance * work[_BEAM + 2, j]
                continue
            for g in range(n_gates):
                distance = slant[b, g]
                for j in range(count):
                    height = work[_MEASURED, j] + distance * work[_BEAM + 2, j]
                    if not height > 0:                  # outside the model (also NaN)
                        ratio[node, g, j] = math.nan
                    else:
                        ratio[node, g, j] = height / reference if shear else 1.0


@_called
def _slerp_one(work, j, exact):
    """The attitude a fraction of the way from sample 1 to sample 2 on the rotation group,
    ``R1 exp(a log(R1^T R2))`` (:func:`uq.physics.rotation.interpolate_rotation`), as the
    (cos, sin) of its heading, pitch and roll into the reading's rows. The factors theta /
    sin theta, sin x / x and (1 - cos x) / x^2 from their series, or libm (`exact`)."""
    a00, a01, a02 = work[_MATRIX1, j], work[_MATRIX1 + 1, j], work[_MATRIX1 + 2, j]
    a10, a11, a12 = work[_MATRIX1 + 3, j], work[_MATRIX1 + 4, j], work[_MATRIX1 + 5, j]
    a20, a21, a22 = work[_MATRIX1 + 6, j], work[_MATRIX1 + 7, j], work[_MATRIX1 + 8, j]
    b00, b01, b02 = work[_MATRIX2, j], work[_MATRIX2 + 1, j], work[_MATRIX2 + 2, j]
    b10, b11, b12 = work[_MATRIX2 + 3, j], work[_MATRIX2 + 4, j], work[_MATRIX2 + 5, j]
    b20, b21, b22 = work[_MATRIX2 + 6, j], work[_MATRIX2 + 7, j], work[_MATRIX2 + 8, j]
    # the skew part of R1^T R2 (rel[i][k] = sum_l R1[l][i] R2[l][k]): sin(theta) axis
    r21 = a02 * b01 + a12 * b11 + a22 * b21
    r12 = a01 * b02 + a11 * b12 + a21 * b22
    r02 = a00 * b02 + a10 * b12 + a20 * b22
    r20 = a02 * b00 + a12 * b10 + a22 * b20
    r10 = a01 * b00 + a11 * b10 + a21 * b20
    r01 = a00 * b01 + a10 * b11 + a20 * b21
    ax, ay, az = 0.5 * (r21 - r12), 0.5 * (r02 - r20), 0.5 * (r10 - r01)
    s2 = ax * ax + ay * ay + az * az
    a = work[_FRACTION, j]
    if exact and s2 > 0:
        over = math.asin(math.sqrt(s2)) / math.sqrt(s2)
    else:
        over = _horner(_ASIN, s2)
    vx, vy, vz = ax * over * a, ay * over * a, az * over * a     # the rotation vector
    x2 = vx * vx + vy * vy + vz * vz
    if exact and x2 > 0:
        x = math.sqrt(x2)
        half = math.sin(0.5 * x) / x
        f1, f2 = math.sin(x) / x, 2.0 * half * half
    else:
        f1, f2 = _horner(_SINC, x2), _horner(_COSC, x2)
    # columns of I + f1 [v]x + f2 [v]x^2, with [v]x^2 = v v^T - |v|^2 I
    c00, c10, c20 = 1.0 + f2 * (vx * vx - x2), f1 * vz + f2 * vx * vy, f2 * vx * vz - f1 * vy
    c01, c11, c21 = f2 * vx * vy - f1 * vz, 1.0 + f2 * (vy * vy - x2), f1 * vx + f2 * vy * vz
    c02, c12, c22 = f1 * vy + f2 * vx * vz, f2 * vy * vz - f1 * vx, 1.0 + f2 * (vz * vz - x2)
    m00 = a00 * c00 + a01 * c10 + a02 * c20
    m10 = a10 * c00 + a11 * c10 + a12 * c20
    m20 = a20 * c00 + a21 * c10 + a22 * c20
    m21 = a20 * c01 + a21 * c11 + a22 * c21
    m22 = a20 * c02 + a21 * c12 + a22 * c22
    # R = Rz Ry Rx: R[2, 0] = sin p, (R[0, 0], R[1, 0]) = cos p (cos h, sin h),
    # (R[2, 1], R[2, 2]) = cos p (-sin r, cos r) (|pitch| < 90 deg)
    horizontal = math.sqrt(m00 * m00 + m10 * m10)
    across = math.sqrt(m21 * m21 + m22 * m22)
    work[_READ_TRIG, j], work[_READ_TRIG + 1, j] = m00 / horizontal, m10 / horizontal
    work[_READ_TRIG + 2, j] = math.sqrt((1.0 - m20) * (1.0 + m20))
    work[_READ_TRIG + 3, j] = m20
    work[_READ_TRIG + 4, j], work[_READ_TRIG + 5, j] = m22 / across, -m21 / across
    work[_BIG, j] = s2


@_helper
def _slerp(work, count):
    series = count < 0                    # False, not a literal: one compile, not two
    for j in range(count):
        _slerp_one(work, j, series)
    for j in range(count):                # a large rotation between samples: libm
        if not work[_BIG, j] <= SLERP_SERIES_LIMIT:
            _slerp_one(work, j, not series)


@_helper
def _attitude_rows(consts, state, work, count, row, with_errors):
    """The (cos, sin) of the heading, pitch and roll of a state's values (plus the error
    rows of a reading, `with_errors`) into work[row .. row + 5]."""
    for i in range(3):
        base, dof = (_HEADING, _PITCH, _ROLL)[i], 2 - i
        for j in range(count):
            work[_ANGLE, j] = consts[base] + state[_VALUE + dof, j]
        if with_errors:
            for j in range(count):
                work[_ANGLE, j] += work[_ERROR + i, j]
        sincos_rows(work, np.int64(_ANGLE), row + 2 * i + 1, row + 2 * i, count)


@_helper
def _sample_matrix(consts, state, work, count, row):
    """The attitude of an INS sample (its values in state) as a row-major matrix."""
    _attitude_rows(consts, state, work, count, np.int64(_READ_TRIG), count < 0)  # (False)
    for j in range(count):
        ch, sh = work[_READ_TRIG, j], work[_READ_TRIG + 1, j]
        cp, sp = work[_READ_TRIG + 2, j], work[_READ_TRIG + 3, j]
        cr, sr = work[_READ_TRIG + 4, j], work[_READ_TRIG + 5, j]
        x0, x1, x2 = rotate(ch, sh, cp, sp, cr, sr, 1.0, 0.0, 0.0)      # the columns
        y0, y1, y2 = rotate(ch, sh, cp, sp, cr, sr, 0.0, 1.0, 0.0)
        z0, z1, z2 = rotate(ch, sh, cp, sp, cr, sr, 0.0, 0.0, 1.0)
        work[row, j], work[row + 1, j], work[row + 2, j] = x0, y0, z0
        work[row + 3, j], work[row + 4, j], work[row + 5, j] = x1, y1, z1
        work[row + 6, j], work[row + 7, j], work[row + 8, j] = x2, y2, z2


@_inline
def _ins_velocity(head, state, j):
    """The INS's true velocity (north, east, up) [m s-1]: the ship's plus the
    translational motion's rates turned by the static heading."""
    surge, sway = state[_RATE_ROW + 3, j], state[_RATE_ROW + 4, j]
    level_c, level_s = head[_LEVEL_COS], head[_LEVEL_SIN]
    return (head[_SHIP_NORTH] + (level_c * surge - level_s * sway),
            head[_SHIP_EAST] + (level_s * surge + level_c * sway),
            head[_SHIP_UP] + state[_RATE_ROW + 5, j])


@_inline
def _velocity_errors(head, work, j, vn, ve, vu):
    """A velocity reading with its errors (rows _SOG, _COG, _HEAVE: zero, (1, 0) and zero
    when not given): sog along the static course, cog turns, heave adds."""
    sog = work[_SOG, j]
    vn, ve = vn + sog * head[_COURSE_COS], ve + sog * head[_COURSE_SIN]
    ce, se = work[_COG, j], work[_COG + 1, j]
    return ce * vn - se * ve, se * vn + ce * ve, vu + work[_HEAVE, j]


@_helper
def _sample_times(stamp, clock, offset, rate, second, mode, start, count, work):
    """The time shift from the stamp to the INS sample a read at stamp + delta uses
    (work[_SHIFT], the first or the `second` sample), with the fraction of the second
    (work[_FRACTION]) (:func:`uq.physics.ins.bracket`)."""
    for j in range(count):
        delta = clock[start + j if clock.shape[0] > 1 else 0]
        zero = offset[start + j if offset.shape[0] > 1 else 0]
        position = (stamp + delta - zero) * rate           # in sample periods
        if mode == NEAREST:
            index = math.floor(position + 0.5)
            work[_FRACTION, j] = 0.0
        else:
            index = math.floor(position)
            work[_FRACTION, j] = position - index
        work[_SHIFT, j] = (zero + (index + second) / rate) - stamp


@_helper
def _error_rows(errors, has, start, count, k, work):
    """The errors of reading k into the rows _ERROR (heading, pitch, roll [rad]), _SOG,
    _COG ((cos, sin)) and _HEAVE; rows of errors not given keep their neutral values."""
    for i in range(6):
        if not has[i]:
            continue
        error = errors[i]
        col = k if error.shape[1] > 1 else 0
        row = (_ERROR, _ERROR + 1, _ERROR + 2, _SOG, _ANGLE, _HEAVE)[i]
        scale = 1.0 if i == 3 or i == 5 else _DEG
        if error.shape[0] == 1:
            work[row, :count] = error[0, col] * scale
        else:
            for j in range(count):
                work[row, j] = error[start + j, col] * scale
        if i == 4:
            sincos_rows(work, np.int64(_ANGLE), np.int64(_COG + 1), np.int64(_COG), count)


@_helper
def _reading(consts, pairs, amplitudes, components, read_table, stamps, k, c, turned,
             errors, has, start, count, state, work):
    """The INS reading of read point k (the beam k for ``pointwise``, else the scan's mid
    time) for trials [start, start + count), as :func:`uq.physics.timeresolved.ins_state`
    and its reading errors: the motion's values and rates there in `state` (rates
    interpolated for ``linear``) and the errors in work's rows; for ``linear`` also the
    (cos, sin) of the read attitude with its errors (rows _READ_TRIG) and the read velocity
    with its errors (_READ_VELOCITY), which :func:`_read_rows` writes otherwise. Returns
    whether those rows were written."""
    head = _head(consts)
    mode, rate, stamp = int(consts[_INS_MODE]), consts[_RATE], stamps[k]
    _error_rows(errors, has, start, count, k, work)
    if mode == CONTINUOUS:                  # c turned by w delta beforehand (reconstruct)
        _motion(pairs, amplitudes, read_table, k, c, state, count)
    else:                                   # the INS samples at offset + i / rate
        clock, offset = errors[_CLOCK][:, 0], errors[_OFFSET][:, 0]
        _sample_times(stamp, clock, offset, rate, np.int64(0), mode, start, count, work)
        _turn_phases(components, c, work, count, turned)
        _motion(pairs, amplitudes, read_table, k, turned, state, count)
        if mode == LINEAR:                  # keep the first sample; then the second
            _sample_matrix(consts, state, work, count, np.int64(_MATRIX1))
            for j in range(count):
                work[_VELOCITY1, j], work[_VELOCITY1 + 1, j], work[_VELOCITY1 + 2, j] = \
                    _ins_velocity(head, state, j)
            for i in range(3):
                for j in range(count):      # (a loop, not a slice: the notes above)
                    work[_RATES1 + i, j] = state[_RATE_ROW + 2 - i, j]
            _sample_times(stamp, clock, offset, rate, np.int64(1), mode, start, count, work)
            _turn_phases(components, c, work, count, turned)
            _motion(pairs, amplitudes, read_table, k, turned, state, count)
            _sample_matrix(consts, state, work, count, np.int64(_MATRIX2))
            for j in range(count):          # rates and velocity linearly, with errors
                a = work[_FRACTION, j]
                for i in range(3):
                    state[_RATE_ROW + 2 - i, j] = (1 - a) * work[_RATES1 + i, j] \
                        + a * state[_RATE_ROW + 2 - i, j]
                vn, ve, vu = _ins_velocity(head, state, j)
                vn = (1 - a) * work[_VELOCITY1, j] + a * vn
                ve = (1 - a) * work[_VELOCITY1 + 1, j] + a * ve
                vu = (1 - a) * work[_VELOCITY1 + 2, j] + a * vu
                work[_READ_VELOCITY, j], work[_READ_VELOCITY + 1, j], \
                    work[_READ_VELOCITY + 2, j] = _velocity_errors(head, work, j, vn, ve, vu)
            _slerp(work, count)
            for i in range(3):              # (cos, sin) of the slerp's angle + error
                if has[i]:
                    sincos_rows(work, _ERROR + i, np.int64(_SINE), np.int64(_COSINE), count)
                    row = _READ_TRIG + 2 * i
                    for j in range(count):
                        co, si = work[row, j], work[row + 1, j]
                        ce, se = work[_COSINE, j], work[_SINE, j]
                        work[row, j], work[row + 1, j] = co * ce - si * se, si * ce + co * se
            return True
    return False


@_helper
def _read_rows(consts, state, work, count):
    """The (cos, sin) of a reading's attitude with its errors (rows _READ_TRIG) and its
    velocity with its errors (_READ_VELOCITY), from the state :func:`_reading` left."""
    head = _head(consts)
    _attitude_rows(consts, state, work, count, np.int64(_READ_TRIG), count >= 0)  # (True)
    for j in range(count):
        vn, ve, vu = _ins_velocity(head, state, j)
        work[_READ_VELOCITY, j], work[_READ_VELOCITY + 1, j], work[_READ_VELOCITY + 2, j] = \
            _velocity_errors(head, work, j, vn, ve, vu)


#: Where the point-wise loop takes a reading's attitude from: its angles (sines and
#: cosines in the loop), the rows of :func:`_reading` (linear interpolation), or the
#: truth's state at the same time (readings at the nodes, no attitude errors).
FROM_ANGLES, FROM_ROWS, FROM_STATE = range(3)


@_inline
def _pointwise_at(head, state, work, nx, ny, nz, j, exact, heading_varies, source):
    """Beam k's reading for trial j (point-wise): the beam it implies, ``R_read n_k``, into
    rows _BEAM and the lidar velocity along it into _ALONG (see :data:`FROM_ANGLES`)."""
    if source == FROM_ROWS:
        ch, sh = work[_READ_TRIG, j], work[_READ_TRIG + 1, j]
        cp, sp = work[_READ_TRIG + 2, j], work[_READ_TRIG + 3, j]
        cr, sr = work[_READ_TRIG + 4, j], work[_READ_TRIG + 5, j]
        vn, ve, vu = (work[_READ_VELOCITY, j], work[_READ_VELOCITY + 1, j],
                      work[_READ_VELOCITY + 2, j])
    else:
        if source == FROM_STATE:
            ch, sh = state[_TRIG, j], state[_TRIG + 1, j]
            cp, sp = state[_TRIG + 2, j], state[_TRIG + 3, j]
            cr, sr = state[_TRIG + 4, j], state[_TRIG + 5, j]
        else:
            heading = (head[_HEADING] + state[_VALUE + 2, j]) + work[_ERROR, j]
            pitch = (head[_PITCH] + state[_VALUE + 1, j]) + work[_ERROR + 1, j]
            roll = (head[_ROLL] + state[_VALUE, j]) + work[_ERROR + 2, j]
            if heading_varies:
                sh, ch = _trig(heading, exact)
            else:
                ch, sh = head[_LEVEL_COS], head[_LEVEL_SIN]
            sp, cp = _trig(pitch, exact)
            sr, cr = _trig(roll, exact)
            work[_BIG, j] = abs(pitch) + abs(roll) + (abs(heading) if heading_varies else 0.0)
        vn, ve, vu = _ins_velocity(head, state, j)
        vn, ve, vu = _velocity_errors(head, work, j, vn, ve, vu)
    if head[_HAS_ARM] > 0:                  # the lever arm's velocity, R' r
        dx, dy, dz = rotate_rate(ch, sh, cp, sp, cr, sr, state[_RATE_ROW + 2, j],
                                 state[_RATE_ROW + 1, j], state[_RATE_ROW, j],
                                 head[_ARM_BOW], head[_ARM_STARBOARD], head[_ARM_UP])
        vn, ve, vu = vn + dx, ve + dy, vu + dz
    bx, by, bz = rotate(ch, sh, cp, sp, cr, sr, nx, ny, nz)
    work[_BEAM, j], work[_BEAM + 1, j], work[_BEAM + 2, j] = bx, by, bz
    work[_ALONG, j] = bx * vn + by * ve + bz * vu


@_helper
def _pointwise(consts, state, work, normal, nx, ny, nz, count, heading_varies, source):
    """:func:`_pointwise_at` for the block's trials (one SIMD loop per case, then libm
    where an angle is beyond the reduction), and ``B^T B`` accumulated."""
    _pointwise_rows(consts, state, work, nx, ny, nz, count, heading_varies, source)
    for j in range(count):
        bx, by, bz = work[_BEAM, j], work[_BEAM + 1, j], work[_BEAM + 2, j]
        normal[0, j] += bx * bx
        normal[1, j] += bx * by
        normal[2, j] += bx * bz
        normal[3, j] += by * by
        normal[4, j] += by * bz
        normal[5, j] += bz * bz


@_helper
def _pointwise_from_state(head, state, work, nx, ny, nz, count):
    """:func:`_pointwise_at` from the truth's state without a lever arm, written out in
    one loop of locals (the same operations in the same order: bit for bit its result),
    which LLVM makes SIMD code where the inlined helper stayed scalar: the bench's
    point-wise scan 93 -> 40 ns per trial in :func:`reconstruct`."""
    level_c, level_s = head[_LEVEL_COS], head[_LEVEL_SIN]
    ship_n, ship_e, ship_u = head[_SHIP_NORTH], head[_SHIP_EAST], head[_SHIP_UP]
    course_c, course_s = head[_COURSE_COS], head[_COURSE_SIN]
    for j in range(count):
        ch, sh = state[_TRIG, j], state[_TRIG + 1, j]
        cp, sp = state[_TRIG + 2, j], state[_TRIG + 3, j]
        cr, sr = state[_TRIG + 4, j], state[_TRIG + 5, j]
        surge, sway = state[_RATE_ROW + 3, j], state[_RATE_ROW + 4, j]
        vn = ship_n + (level_c * surge - level_s * sway)          # _ins_velocity
        ve = ship_e + (level_s * surge + level_c * sway)
        vu = ship_u + state[_RATE_ROW + 5, j]
        sog = work[_SOG, j]                                       # _velocity_errors
        vn, ve = vn + sog * course_c, ve + sog * course_s
        ce, se = work[_COG, j], work[_COG + 1, j]
        vn, ve, vu = ce * vn - se * ve, se * vn + ce * ve, vu + work[_HEAVE, j]
        bx, by, bz = rotate(ch, sh, cp, sp, cr, sr, nx, ny, nz)
        work[_BEAM, j], work[_BEAM + 1, j], work[_BEAM + 2, j] = bx, by, bz
        work[_ALONG, j] = bx * vn + by * ve + bz * vu


@_helper
def _pointwise_rows(consts, state, work, nx, ny, nz, count, heading_varies, source):
    """:func:`_pointwise_at` for the block's trials: the read rotation of (nx, ny, nz)
    into rows _BEAM, the lidar velocity along it into _ALONG."""
    head = _head(consts)
    if source == FROM_STATE and head[_HAS_ARM] == 0:
        _pointwise_from_state(head, state, work, nx, ny, nz, count)
        return
    for j in range(count):                  # (one inlined copy, `source` a value: LLVM
        _pointwise_at(head, state, work, nx, ny, nz, j, False, heading_varies, source)
    if source == FROM_ANGLES:               # unswitches the loop on it)
        for j in range(count):
            if not work[_BIG, j] <= SINCOS_REDUCTION_LIMIT:
                _pointwise_at(head, state, work, nx, ny, nz, j, True, heading_varies,
                              FROM_ANGLES)


@_helper
def _store_reading(consts, state, work, normal, row, count, heading_varies, source):
    """A point-wise reading of a tilted mount into normal[row ..]: the believed beam
    (rows _BEAM; the velocity along it enters the corrected radial velocity that
    :func:`reconstruct` keeps) and, for the shear exponent's believed heights alone
    (HEAD mounted 2), the lidar's lift ``[(R_read - R_static) r]_up`` into row + 4
    through the lever arm r (:func:`uq.physics.timeresolved._lever_arm_lift`; 0 without
    one)."""
    for j in range(count):                  # (a loop, not three slices: their views
        normal[row, j] = work[_BEAM, j]     # cost more than the copy of a block)
        normal[row + 1, j] = work[_BEAM + 1, j]
        normal[row + 2, j] = work[_BEAM + 2, j]
    if consts[_MOUNTED] < 2:                # the lift is the shear's alone (HEAD mounted 2)
        return
    normal[row + 4, :count] = 0.0
    if consts[_HAS_ARM] > 0:
        for j in range(count):              # (kept while the arm's rows are made)
            normal[row + 3, j] = work[_ALONG, j]
        _pointwise_rows(consts, state, work, consts[_ARM_BOW], consts[_ARM_STARBOARD],
                        consts[_ARM_UP], count, heading_varies, source)
        for j in range(count):              # the reading's rotation of the arm
            normal[row + 4, j] = work[_BEAM + 2, j] - consts[_STATIC_ARM_UP]
        for j in range(count):              # the beam's rows back for the least squares
            work[_BEAM, j], work[_BEAM + 1, j] = normal[row, j], normal[row + 1, j]
            work[_BEAM + 2, j], work[_ALONG, j] = normal[row + 2, j], normal[row + 3, j]


@_helper
def _factor(normal, count):
    """The Cholesky factor L of B^T B (rows 0-5 of `normal`, symmetric positive definite
    when the beams span the space), overwriting it: (l00, l10, l20, l11, l21, l22)."""
    for j in range(count):
        l00 = math.sqrt(normal[0, j])
        l10, l20 = normal[1, j] / l00, normal[2, j] / l00
        l11 = math.sqrt(normal[3, j] - l10 * l10)
        l21 = (normal[4, j] - l20 * l10) / l11
        l22 = math.sqrt(normal[5, j] - l20 * l20 - l21 * l21)
        normal[0, j], normal[1, j], normal[2, j] = l00, l10, l20
        normal[3, j], normal[4, j], normal[5, j] = l11, l21, l22


@_helper
def _substitute(normal, row, n_gates, count, out):
    """out[:, g] = (L L^T)^-1 r of each gate's right-hand side r = B^T v (rows row + 3 g
    .. row + 3 g + 2 of `normal`), with the factor of :func:`_factor` in rows 0-5."""
    for g in range(n_gates):
        first = row + 3 * g
        for j in range(count):
            l00, l10, l20 = normal[0, j], normal[1, j], normal[2, j]
            l11, l21, l22 = normal[3, j], normal[4, j], normal[5, j]
            y0 = normal[first, j] / l00
            y1 = (normal[first + 1, j] - l10 * y0) / l11
            y2 = (normal[first + 2, j] - l20 * y0 - l21 * y1) / l22
            x2 = y2 / l22
            x1 = (y1 - l21 * x2) / l11
            out[0, g, j] = (y0 - l10 * x1 - l20 * x2) / l00
            out[1, g, j] = x1
            out[2, g, j] = x2


@_helper
def _vertical_factor(normal, count):
    """The last row of (B^T B)^-1 (rows 0-5 of `normal`, as :func:`_factor` reads them),
    overwriting rows 0-2: the up component of the least squares alone, where a tilted
    mount's level pair gives north and east. By cofactors (C13, C23, C33) / det: one
    division per trial where the Cholesky factor and its substitution take three square
    roots and seven (the systems are well conditioned: a 15 deg half-cone's B^T B has
    condition number ~28)."""
    for j in range(count):
        a, b, c = normal[0, j], normal[1, j], normal[2, j]
        d, e, f = normal[3, j], normal[4, j], normal[5, j]
        c13, c23, c33 = b * e - c * d, b * c - a * e, a * d - b * b
        scale = 1.0 / (c * c13 + e * c23 + f * c33)      # det, along the last column
        normal[0, j], normal[1, j], normal[2, j] = c13 * scale, c23 * scale, c33 * scale


@_helper
def _substitute_vertical(normal, row, n_gates, count, out):
    """out[2, g] = the up component of (B^T B)^-1 r of each gate's right-hand side
    r = B^T v (rows row + 3 g .. row + 3 g + 2 of `normal`), with the last row of the
    inverse from :func:`_vertical_factor` in rows 0-2."""
    for g in range(n_gates):
        first = row + 3 * g
        for j in range(count):
            out[2, g, j] = normal[0, j] * normal[first, j] + normal[1, j] * \
                normal[first + 1, j] + normal[2, j] * normal[first + 2, j]


@_helper
def _scan_reading(consts, model, work, count):
    """The rows of the scan's one reading as the correction model believes it: ``none``
    the configured heading and no velocity, ``yaw`` the read heading alone (level
    attitude); ``tilt2d`` and ``full`` the reading as read."""
    if model == NONE:
        work[_READ_TRIG, :count] = consts[_LEVEL_COS]
        work[_READ_TRIG + 1, :count] = consts[_LEVEL_SIN]
        for i in range(3):
            work[_READ_VELOCITY + i, :count] = 0.0
    if model == NONE or model == YAW:
        work[_READ_TRIG + 2, :count], work[_READ_TRIG + 3, :count] = 1.0, 0.0
        work[_READ_TRIG + 4, :count], work[_READ_TRIG + 5, :count] = 1.0, 0.0


@_helper
def _scan_vertical(consts, model, work, normal, row, n_gates, count, out):
    """out[2, g] of :func:`_scan_correction` alone (the same operations: bit for bit its
    up component), where a tilted mount's level pair gives north and east: with ``full``
    the read attitude's up row applied to the lidar-frame wind plus the read vertical
    velocity, else the lidar-frame vertical wind."""
    _scan_reading(consts, model, work, count)
    for g in range(n_gates):
        first = row + 3 * g
        if model == FULL:
            for j in range(count):
                cp, sp = work[_READ_TRIG + 2, j], work[_READ_TRIG + 3, j]
                cr, sr = work[_READ_TRIG + 4, j], work[_READ_TRIG + 5, j]
                x, y, z = normal[first, j], normal[first + 1, j], normal[first + 2, j]
                z1 = cr * z - sr * y                            # rotate's up row
                out[2, g, j] = (sp * x + cp * z1) + work[_READ_VELOCITY + 2, j]
        else:
            for j in range(count):
                out[2, g, j] = normal[first + 2, j]


@_helper
def _scan_correction(consts, model, work, normal, row, n_gates, count, out):
    """Eq. 13 of Rubio and Gottschall (2022) with the scan's one reading
    (:mod:`uq.physics.correction`): ``none`` turns by the configured heading, ``yaw`` by
    the read heading, ``tilt2d`` applies the read attitude to the horizontal lidar-frame
    components, ``full`` to all three; the read velocity is added (horizontal; with the
    vertical for ``full``; nothing for ``none``); the vertical wind of all but ``full`` is
    the lidar-frame one. The lidar-frame wind of gate g is in rows row + 3 g .. + 2 of
    `normal`."""
    _scan_reading(consts, model, work, count)
    full = model == FULL
    for g in range(n_gates):
        for j in range(count):
            ch, sh = work[_READ_TRIG, j], work[_READ_TRIG + 1, j]
            cp, sp = work[_READ_TRIG + 2, j], work[_READ_TRIG + 3, j]
            cr, sr = work[_READ_TRIG + 4, j], work[_READ_TRIG + 5, j]
            x, y, z = normal[row + 3 * g, j], normal[row + 1 + 3 * g, j], \
                normal[row + 2 + 3 * g, j]
            north, east, up = rotate(ch, sh, cp, sp, cr, sr, x, y, z if full else 0.0)
            out[0, g, j] = north + work[_READ_VELOCITY, j]
            out[1, g, j] = east + work[_READ_VELOCITY + 1, j]
            out[2, g, j] = up + work[_READ_VELOCITY + 2, j] if full else z


@_helper
def _held_rows(work, held_noise, start, count, b, g, pointwise, operator, normal, row, keep):
    """The held right-hand side of beam b, gate g (:func:`reconstruct`): the dwell mean
    in work[_MEASURED] plus the held noise, corrected point-wise by the reading's beam
    and velocity along it (rows _BEAM, _ALONG), or through A^+, into rows row .. row + 2
    (the operations of the main side's, in its order); and a tilted mount's kept beam's
    corrected (one reading per scan: measured) radial velocity into row `keep` (-1:
    none), as the main side keeps its own."""
    beam = b if held_noise.shape[1] > 1 else 0
    gate = g if held_noise.shape[2] > 1 else 0
    per_trial = held_noise.shape[0] > 1
    if keep >= 0:
        for j in range(count):
            measured = work[_MEASURED, j] + held_noise[start + j if per_trial else 0, beam,
                                                       gate]
            normal[keep, j] = measured + work[_ALONG, j] if pointwise else measured
    if pointwise:
        for j in range(count):
            noise = held_noise[start + j if per_trial else 0, beam, gate]
            corrected = (work[_MEASURED, j] + noise) + work[_ALONG, j]
            normal[row, j] += work[_BEAM, j] * corrected
            normal[row + 1, j] += work[_BEAM + 1, j] * corrected
            normal[row + 2, j] += work[_BEAM + 2, j] * corrected
    else:
        o0, o1, o2 = operator[0, b], operator[1, b], operator[2, b]
        for j in range(count):
            measured = work[_MEASURED, j] + held_noise[start + j if per_trial else 0, beam,
                                                       gate]
            normal[row, j] += o0 * measured
            normal[row + 1, j] += o1 * measured
            normal[row + 2, j] += o2 * measured


@_helper
def _level_wind_fixed(consts, beams, normal, measured, n_gates, count, out):
    """:func:`_level_wind` for ``none`` without the shear exponent: the believed beams
    are the configured ones turned by the configured heading, the same in every trial,
    and no velocity is removed (``c_k = v_k``), so the 2 x 2 system and its inverse are
    made once per block, not per trial (the same operations on the same values: its
    result bit for bit, up to the sign of a zero)."""
    level_a, level_b = int(consts[_LEVEL_FIRST]), int(consts[_LEVEL_SECOND])
    ch, sh = consts[_LEVEL_COS], consts[_LEVEL_SIN]     # _scan_reading's rows for none
    ax, ay, az = rotate(ch, sh, 1.0, 0.0, 1.0, 0.0, beams[level_a, 0], beams[level_a, 1],
                        beams[level_a, 2])
    bx, by, bz = rotate(ch, sh, 1.0, 0.0, 1.0, 0.0, beams[level_b, 0], beams[level_b, 1],
                        beams[level_b, 2])
    two = int(consts[_N_BEAMS]) == 2
    for g in range(n_gates):                # (the inverse, loop-invariant, is hoisted)
        c_first, c_second = measured + level_a * n_gates + g, measured + level_b * n_gates + g
        if two:
            for j in range(count):
                out[0, g, j], out[1, g, j] = _horizontal_solve(
                    ax, ay, bx, by, normal[c_first, j], normal[c_second, j])
                out[2, g, j] = 0.0
        else:
            for j in range(count):
                out[0, g, j], out[1, g, j] = _level_pair_solve(
                    ax, ay, az, bx, by, bz, normal[c_first, j], normal[c_second, j],
                    out[2, g, j])


@_called
def _horizontal_solve(n00, n01, n10, n11, c0, c1):
    """2 beams: the horizontal least squares ``b_k,h . u_h = c_k`` (w = 0 assumed) of the
    believed beams' horizontal parts (n00, n01), (n10, n11) and the corrected radial
    velocities c0, c1: (north, east) [m s-1]."""
    i00, i01, i10, i11 = _inverse2(n00 * n00 + n10 * n10, n00 * n01 + n10 * n11,
                                   n00 * n01 + n10 * n11, n01 * n01 + n11 * n11)
    r0 = n00 * c0 + n10 * c1
    r1 = n01 * c0 + n11 * c1
    return i00 * r0 + i01 * r1, i10 * r0 + i11 * r1


@_called
def _level_pair_solve(n00, n01, n02, n10, n11, n12, c0, c1, up):
    """The level pair: the hub-height horizontal wind ``b_k,h . u_h = c_k - b_k,up w``
    with the 3-D solve's w `up`: (north, east) [m s-1]."""
    i00, i01, i10, i11 = _inverse2(n00, n01, n10, n11)
    r0 = c0 - n02 * up
    r1 = c1 - n12 * up
    return i00 * r0 + i01 * r1, i10 * r0 + i11 * r1


@_helper
def _level_wind(consts, model, beams, work, normal, stored, measured, n_gates, count, out):
    """A tilted (nacelle) mount's horizontal wind of trials [0, count), at the end of
    :func:`reconstruct` (whose `normal` then holds the kept beams' believed beams from
    row `stored` (point-wise; 5 rows per beam) and their corrected radial velocities from
    row `measured` (k g + gate; one reading per scan: the measured ones, corrected here);
    its `work` the scan's reading; `out` the 3-D solve's wind, of the main side or the
    held noise's).

    Each beam's believed earth-frame beam ``b_k`` (the point-wise reading's, or the
    scan's rotation of the configured beam as the correction model believes it) and
    its corrected radial velocity ``c_k = v_k + b_k . s`` (s: the velocity the model
    removes). 2 beams (HEAD level_first, level_second 0 and 1): the horizontal least
    squares ``b_k,h . u_h = c_k``, w = 0 assumed; with the level pair: the hub-height
    horizontal wind ``b_k,h . u_h = c_k - b_k,up w`` with the w of `out`
    (:mod:`uq.physics.nacelle`); other layouts keep `out`. Inside :func:`reconstruct`
    and on as few rows as it can (the inverse of each 2 x 2 system made again per gate,
    not kept): a pass of its own per block read its rows back from beyond the cache
    (a speed target of the bench). Loops over the trials innermost (SIMD)."""
    n_beams = int(consts[_N_BEAMS])
    level_a, level_b = int(consts[_LEVEL_FIRST]), int(consts[_LEVEL_SECOND])
    keep_all = consts[_MOUNTED] > 1         # the shear's beams too, and their lift
    if model == NONE and not keep_all:      # the same believed beams in every trial
        if level_a >= 0:
            _level_wind_fixed(consts, beams, normal, measured, n_gates, count, out)
        return
    if model != POINTWISE:                  # the scan's reading (_scan_correction's rows)
        full = model == FULL
        for b in range(n_beams):
            if not (keep_all or b == level_a or b == level_b):
                continue
            nx, ny, nz = beams[b, 0], beams[b, 1], beams[b, 2]
            row = stored + 5 * b
            for j in range(count):
                bx, by, bz = rotate(work[_READ_TRIG, j], work[_READ_TRIG + 1, j],
                                    work[_READ_TRIG + 2, j], work[_READ_TRIG + 3, j],
                                    work[_READ_TRIG + 4, j], work[_READ_TRIG + 5, j],
                                    nx, ny, nz)
                vu = work[_READ_VELOCITY + 2, j] if full else 0.0
                normal[row, j], normal[row + 1, j], normal[row + 2, j] = bx, by, bz
                normal[row + 3, j] = bx * work[_READ_VELOCITY, j] + \
                    by * work[_READ_VELOCITY + 1, j] + bz * vu
            for g in range(n_gates):        # corrected: c = v + b . s
                corrected = measured + b * n_gates + g
                for j in range(count):
                    normal[corrected, j] = normal[corrected, j] + normal[row + 3, j]
            if keep_all:                    # the scan's reading lifts no beam
                normal[row + 4, :count] = 0.0
    if level_a < 0:
        return
    first, second = stored + 5 * level_a, stored + 5 * level_b
    # the last beam's believed beam is still in work's rows _BEAM (point-wise, no lift)
    last = model == POINTWISE and level_b == n_beams - 1 and not keep_all
    rows = work if last else normal
    second = _BEAM if last else second
    for g in range(n_gates):
        c_first, c_second = measured + level_a * n_gates + g, measured + level_b * n_gates + g
        if n_beams == 2:                    # the horizontal normal equations
            for j in range(count):
                out[0, g, j], out[1, g, j] = _horizontal_solve(
                    normal[first, j], normal[first + 1, j], rows[second, j],
                    rows[second + 1, j], normal[c_first, j], normal[c_second, j])
                out[2, g, j] = 0.0
        else:
            for j in range(count):
                out[0, g, j], out[1, g, j] = _level_pair_solve(
                    normal[first, j], normal[first + 1, j], normal[first + 2, j],
                    rows[second, j], rows[second + 1, j], rows[second + 2, j],
                    normal[c_first, j], normal[c_second, j], out[2, g, j])


@_kernel(f"void({_CV}, {_IM}, {_CM}, {_CM}, {_CT}, {_CV}, {_CM}, {_CM}, {_CV}, "
         f"UniTuple({_M}, 8), int64[::1], {_T}, int64, int64, {_CM}, {_CT}, {_CT}, {_CT}, "
         f"{_CT}, {_CT}, {_CM}, {_CT}, {_T}, {_CT})")
def reconstruct(consts, pairs, amplitudes, components, read_table, stamps, beams, operator,
                weights, errors, has, noise, start, count, work, c, turned, states, parts,
                profile, normal, out, held_noise, held_out):
    """The reconstructed wind of trials [start, start + count).

    ``profile[node, g]`` is U(z) / U_ref at the gates (numpy's power law applied to the
    ratio of :func:`kinematics`); ``errors`` the INS inputs of :data:`INPUTS`, each (n or
    1, k or 1), ``has`` which are given; ``states`` one per beam when the point-wise
    readings are the truth's nodes (from :func:`kinematics`), else one of scratch;
    ``normal`` (6 + 3 g, trials) scratch for the least squares (a tilted mount's
    (HEAD mounted): 5 b + b g more for :func:`_level_wind`, and b g more with a held
    side). Writes ``out[0, g]`` north, ``out[1, g]`` east, ``out[2, g]`` up [m s-1].

    With a ``held_out`` of 3 rows (0 rows otherwise), also the wind of the same trials
    with the radial noise ``held_noise`` (shaped as ``noise``) in place of ``noise`` and
    every other input the same: the same reading, so the same believed beams and
    least-squares factor, with a second right-hand side (the last 3 g rows of
    ``normal``; a tilted mount's held corrected velocities beside its own) accumulated
    beside the first, in the same order of operations as a call with ``held_noise`` as
    its noise (so bit for bit its result).
    """
    n_beams, n_gates, n_nodes = int(consts[_N_BEAMS]), int(consts[_N_GATES]), int(consts[_N_NODES])
    model, mode, speed_ref = int(consts[_MODEL]), int(consts[_INS_MODE]), consts[_WIND_SPEED]
    if model < NONE or model > POINTWISE:             # (tilt2d is the default branch)
        raise ValueError("unknown correction model code (see uq.physics.modelinputs)")
    at_nodes = states.shape[0] > 1
    phases = c
    if mode == CONTINUOUS and has[_CLOCK]:            # read at t + delta: turn the phases
        clock = errors[_CLOCK]
        for j in range(count):
            work[_SHIFT, j] = clock[start + j if clock.shape[0] > 1 else 0, 0]
        _turn_phases(components, c, work, count, turned)
        phases = turned
    for i in range(3):                                # neutral errors
        work[_ERROR + i, :count] = 0.0
    work[_SOG, :count], work[_HEAVE, :count] = 0.0, 0.0
    work[_COG, :count], work[_COG + 1, :count] = 1.0, 0.0
    if not at_nodes:
        states[0, :_TRIG, :count] = 0.0
    if model != NONE and model != POINTWISE:          # one reading per scan
        mid = np.int64(0)                               # (not a literal: one compile)
        if not _reading(consts, pairs, amplitudes, components, read_table, stamps, mid, phases,
                        turned, errors, has, start, count, states[0], work):
            _read_rows(consts, states[0], work, count)
    heading_varies = consts[_MOVES_YAW] > 0 or has[0]
    # a tilted mount (rows of `normal` beyond the least squares'): its horizontal solve
    # (:func:`_level_wind`, after the least squares) keeps the measured radial velocity
    # and, point-wise, the believed beam and the velocity along it of the beams it
    # solves with; for the shear exponent (HEAD mounted 2, :func:`mounted_wind`) every
    # beam's, and the lidar's believed lift
    held = held_out.shape[0] > 0
    stored = 6 + 3 * n_gates if consts[_MOUNTED] > 0 else 0     # a tilted mount's rows:
    measured = stored + 5 * n_beams                 # 5 per beam, then the corrected radial
    measured_held = measured + n_beams * n_gates    # velocities (b, g), then the held ones'
    second = 6 + 3 * n_gates if stored == 0 else \
        measured_held + (n_beams * n_gates if held else 0)   # the held right-hand sides
    level_a, level_b = int(consts[_LEVEL_FIRST]), int(consts[_LEVEL_SECOND])
    keep_all = consts[_MOUNTED] > 1
    level = stored > 0 and level_a >= 0     # a tilted mount's horizontal solve replaces
    alone = level and n_beams == 2          # the 3-D one's (north, east); with 2 beams it
    #                                         alone (their B^T B is singular). One reading
    # per scan: the lidar-frame sums A^+ v it needs: none with 2 beams, the vertical alone
    # with the level pair (unless `full`, whose up turns all three)
    sums = 0 if alone else (1 if level and model != FULL else 3)    # (point-wise: unused)
    normal[:6 + 3 * n_gates, :count] = 0.0          # the sums, not a tilted mount's kept
    #                                                 rows (each is written before read)
    if held:
        normal[second:second + 3 * n_gates, :count] = 0.0   # the held right-hand sides' sums
    for b in range(n_beams):
        kept = stored > 0 and (keep_all or b == level_a or b == level_b)
        last = not keep_all and b == n_beams - 1          # (its beam stays in work's rows)
        if model == POINTWISE:          # this beam's own reading: the beam and velocity it implies
            state = states[b if at_nodes else 0]
            if at_nodes:                # the truth's motion is the reading's: errors only
                _error_rows(errors, has, start, count, b, work)
                source = FROM_ANGLES if has[0] or has[1] or has[2] else FROM_STATE
            else:
                written = _reading(consts, pairs, amplitudes, components, read_table, stamps,
                                   b, phases, turned, errors, has, start, count, state, work)
                source = FROM_ROWS if written else FROM_ANGLES
            _pointwise(consts, state, work, normal, beams[b, 0], beams[b, 1], beams[b, 2],
                       count, heading_varies, source)
            if kept and not last:       # a tilted mount's: the believed beam (and lift)
                _store_reading(consts, state, work, normal, stored + 5 * b, count,
                               heading_varies, source)
        beam = b if noise.shape[1] > 1 else 0
        for g in range(n_gates):
            work[_MEASURED, :count] = 0.0                # the dwell mean of the truth
            for q in range(n_nodes):
                node, weight = b * n_nodes + q, weights[q]
                for j in range(count):
                    work[_MEASURED, j] += weight * (speed_ref * profile[node, g, j]
                                                    * parts[0, node, j] + parts[1, node, j])
            if held:                    # the same dwell mean, the held noise
                _held_rows(work, held_noise, start, count, b, g, model == POINTWISE,
                           operator, normal, second + 3 * g,
                           measured_held + b * n_gates + g if kept else -1)
            gate = g if noise.shape[2] > 1 else 0
            if noise.shape[0] > 1:
                for j in range(count):
                    work[_MEASURED, j] += noise[start + j, beam, gate]
            else:
                for j in range(count):
                    work[_MEASURED, j] += noise[0, beam, gate]
            if kept:                    # a tilted mount's: the corrected radial velocity
                row = measured + b * n_gates + g                 # (or, one reading per
                if model == POINTWISE:                          # scan, the measured one)
                    for j in range(count):
                        normal[row, j] = work[_MEASURED, j] + work[_ALONG, j]
                else:
                    for j in range(count):
                        normal[row, j] = work[_MEASURED, j]
            if model == POINTWISE:
                for j in range(count):
                    corrected = work[_MEASURED, j] + work[_ALONG, j]
                    normal[6 + 3 * g, j] += work[_BEAM, j] * corrected
                    normal[7 + 3 * g, j] += work[_BEAM + 1, j] * corrected
                    normal[8 + 3 * g, j] += work[_BEAM + 2, j] * corrected
            elif sums == 3:                             # A^+ v: the lidar-frame wind
                o0, o1, o2 = operator[0, b], operator[1, b], operator[2, b]
                for j in range(count):
                    normal[6 + 3 * g, j] += o0 * work[_MEASURED, j]
                    normal[7 + 3 * g, j] += o1 * work[_MEASURED, j]
                    normal[8 + 3 * g, j] += o2 * work[_MEASURED, j]
            elif sums == 1:                             # its vertical alone
                o2 = operator[2, b]
                for j in range(count):
                    normal[8 + 3 * g, j] += o2 * work[_MEASURED, j]
    if model == POINTWISE and level and not alone:     # (their B^T B is singular);
        _vertical_factor(normal, count)                # with the pair: w alone
    elif model == POINTWISE and not alone:
        _factor(normal, count)
    for side in range(2 if held else 1):    # the wind, then the held noise's (the same
        row = np.int64(6) if side == 0 else np.int64(second)       # factor, the held
        into = out if side == 0 else held_out                        # right-hand sides)
        if model == POINTWISE:
            if level and not alone:         # the level pair's: the 3-D solve's w alone
                _substitute_vertical(normal, row, n_gates, count, into)
            elif not alone:
                _substitute(normal, row, n_gates, count, into)
        elif alone:                         # 2 beams: _level_wind's solve is all
            _scan_reading(consts, model, work, count)
        elif level:                         # the level pair's: the 3-D solve's w alone
            _scan_vertical(consts, model, work, normal, row, n_gates, count, into)
        else:
            _scan_correction(consts, model, work, normal, row, n_gates, count, into)
        if stored:
            _level_wind(consts, model, beams, work, normal, stored,
                        measured if side == 0 else measured_held, n_gates, count, into)



@_kernel(f"void({_CT}, int64, {_CM}, {_CM})")
def wind_speed(out, count, speed, vertical):
    """speed[g, j] = |(north, east)| (sqrt(x^2 + y^2); libm's hypot where the squares could
    over- or underflow), vertical[g, j] = up, for the block's trials j < count."""
    for g in range(out.shape[1]):
        for j in range(count):
            north, east = out[0, g, j], out[1, g, j]
            speed[g, j] = math.sqrt(north * north + east * east)
            vertical[g, j] = out[2, g, j]
        for j in range(count):
            radius = speed[g, j]
            if not HYPOT_SAFE_MIN < radius < HYPOT_SAFE_MAX:
                speed[g, j] = math.hypot(out[0, g, j], out[1, g, j])


#: The layout vector of :func:`mounted_wind` (int64): the upper and lower beams (-1:
#: none; :mod:`uq.physics.nacelle`) and whether the shear exponent is wanted.
MOUNTED_LAYOUT = ("upper", "lower", "want_shear")


def mounted_wind(consts, layout, slant, normal, count, out, shear, speed, vertical):
    """A tilted mount's shear exponent and wind speed of trials [0, count), after
    :func:`reconstruct` (HEAD mounted 2: `normal` then holds every beam's believed beam,
    lift and corrected radial velocities c_k, from row 6 + 3 g; `out` the hub-height wind
    of :func:`_level_wind`): ``shear[g, j] = ln(U_up / U_down) /
    ln(z_up / z_down)``, ``U_k = c_k / (b_k,h . e)`` at the believed heights ``z_k =
    lidar height + lift_k + slant b_k,up`` (NaN where a ratio is not positive); then the
    speed and the vertical wind as :func:`wind_speed` (in this call: one call less per
    block, whose dispatch costs ~1 us)."""
    n_beams, n_gates = int(consts[_N_BEAMS]), int(consts[_N_GATES])
    upper, lower = layout[0], layout[1]
    stored = 6 + 3 * n_gates
    measured = stored + 5 * n_beams
    if layout[2] > 0:
        for g in range(n_gates):
            _shear_rows(consts, normal, stored, measured + upper * n_gates + g,
                        measured + lower * n_gates + g, stored + 5 * upper,
                        stored + 5 * lower, slant[upper, g], slant[lower, g], out, g, count,
                        shear)
    wind_speed(out, count, speed, vertical)


@_helper
def _shear_rows(consts, normal, stored, m_upper, m_lower, upper, lower, slant_upper,
                slant_lower, out, g, count, shear):
    """shear[g, :count] from the upper and lower beams' rows (:func:`mounted_wind`)."""
    height = consts[_LIDAR_HEIGHT]
    for j in range(count):
        shear[g, j] = _shear_exponent(
            out[0, g, j], out[1, g, j], normal[upper, j], normal[upper + 1, j],
            normal[lower, j], normal[lower + 1, j], normal[m_upper, j], normal[m_lower, j],
            (height + normal[upper + 4, j]) + slant_upper * normal[upper + 2, j],
            (height + normal[lower + 4, j]) + slant_lower * normal[lower + 2, j])


@_called
def _shear_exponent(north, east, upper_north, upper_east, lower_north, lower_east,
                    c_upper, c_lower, z_upper, z_lower):
    """``ln(U_up / U_down) / ln(z_up / z_down)``, ``U_k = c_k / (b_k,h . e)``; NaN where a
    ratio is not positive (:func:`uq.physics.nacelle.shear_exponent`)."""
    speed = math.sqrt(north * north + east * east)
    along_upper = (upper_north * north + upper_east * east) / speed
    along_lower = (lower_north * north + lower_east * east) / speed
    ratio_speed = (c_upper / along_upper) / (c_lower / along_lower)
    ratio_height = z_upper / z_lower
    if ratio_speed > 0 and ratio_height > 0:
        return math.log(ratio_speed) / math.log(ratio_height)
    return math.nan


@functools.cache
def compiled_mounted_wind():
    """:func:`mounted_wind` compiled on first use (a tilted mount's run alone pays it)."""
    return _kernel(f"void({_CV}, int64[::1], {_CM}, {_CM}, int64, {_CT}, {_CM}, {_CM}, "
                   f"{_CM})")(mounted_wind)
