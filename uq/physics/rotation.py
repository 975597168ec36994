"""Frames, rotations and the ship attitude convention.

Frames
------
* Earth frame: axes (north, east, up). This is the frame of Rubio & Gottschall (2022),
  Eq. 1 (x north, y east, z up), in which a beam of half-cone angle theta and azimuth
  phi (clockwise from north) has the unit vector
  ``(sin(theta) cos(phi), sin(theta) sin(phi), cos(theta))``.
* Ship (body) frame: axes (bow, starboard, up of the deck). With the ship level and
  heading north it coincides with the earth frame.

Both triads are left-handed (north x east = down); every matrix below is nevertheless a
proper rotation (orthogonal, determinant +1) in these coordinates, and its sense is fixed
by what it does to named directions, which the tests pin.

Attitude (marine convention)
----------------------------
* heading psi: bow azimuth, clockwise from north [0, 360).
* pitch: positive bow up.
* roll: positive starboard down.

Body-to-earth matrix ``R = Rz(heading) @ Ry(pitch) @ Rx(roll)``: roll first about the bow
axis, then pitch about the (rolled) starboard axis, then heading about the vertical; the
usual aircraft/ship Tait-Bryan order. A vector in the ship frame, ``x_ship``, is
``R @ x_ship`` in the earth frame.

Rubio & Gottschall (2022) angles
--------------------------------
Their yaw gamma is clockwise (the heading of the lidar's reference beam). Their case ii
rotation is ``R_roll(beta) @ R_pitch(delta)`` (Eq. 7), where, read off Eq. 7,
``R_pitch(delta) = Ry(-delta)`` (delta positive *bow down*, their Sec. 3.3) and
``R_roll(beta) = Rx(beta)`` (beta positive starboard down). The order differs from the
marine one, so the exact mapping goes through the matrix, with the yaw in front:
``Rz(heading) Ry(pitch) Rx(roll) = Rz(gamma) Rx(beta) Ry(-delta)``; see
:func:`rubio2022_angles_from_attitude` and :func:`attitude_from_rubio2022_angles`.

All functions take angles in radians and broadcast over leading dimensions; they are
complex-step safe (only sin/cos/arithmetic are used).

References
----------
.. [1] Rubio, H. and Gottschall, J. (2022). Development of an uncertainty model for
   ship-based lidar measurements. J. Phys.: Conf. Ser. 2362 012034.
"""
import numpy as np


def _matrix(rows):
    """Nested lists of broadcastable arrays (or numbers) as one array (..., 3, 3): each
    element written into its slot (no broadcast copies of constant entries).

    The array is a view of element-major memory (9, ...): each element's values are
    contiguous, so writing them here and reading ``m[..., i, j]`` in the callers'
    element-wise products run at memory speed, not at a stride of 9 values (measured on
    a sweep's numpy model, 6.3e5 matrices per call: 3.5x faster here, 1.9x in the
    motion correction). Same values; operations that need (..., 3, 3) contiguous copy."""
    elements = [np.asarray(e) for row in rows for e in row]
    shape = np.broadcast_shapes(*(e.shape for e in elements))
    out = np.empty((9,) + shape, dtype=np.result_type(*elements, 0.0))
    for index, element in enumerate(elements):
        out[index] = element
    return np.moveaxis(out.reshape((3, 3) + shape), (0, 1), (-2, -1))


def rotation_about_vertical(angle):
    """Rotation that turns a vector clockwise (seen from above) by `angle` [rad].

    A horizontal vector with azimuth phi gets azimuth phi + angle.

    Returns
    -------
    ndarray, shape (..., 3, 3)
    """
    c, s = np.cos(angle), np.sin(angle)
    return _matrix([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def rotation_pitch(pitch):
    """Pitch rotation about the starboard axis; positive pitch lifts the bow [rad].

    The bow unit vector (1, 0, 0) becomes (cos p, 0, sin p).
    """
    c, s = np.cos(pitch), np.sin(pitch)
    return _matrix([[c, 0.0, -s], [0.0, 1.0, 0.0], [s, 0.0, c]])


def rotation_roll(roll):
    """Roll rotation about the bow axis; positive roll lowers starboard [rad].

    The starboard unit vector (0, 1, 0) becomes (0, cos r, -sin r).
    """
    c, s = np.cos(roll), np.sin(roll)
    return _matrix([[1.0, 0.0, 0.0], [0.0, c, s], [0.0, -s, c]])


def attitude_matrix(heading, pitch, roll):
    """Body-to-earth rotation ``Rz(heading) @ Ry(pitch) @ Rx(roll)`` (marine convention).

    Parameters
    ----------
    heading, pitch, roll : array_like
        [rad]; heading clockwise from north, pitch positive bow up, roll positive
        starboard down. Broadcast together.

    Returns
    -------
    ndarray, shape (..., 3, 3)
    """
    # the product written out (one stack instead of two 3 x 3 matrix products per sample;
    # tests check it against the product of the three elementary rotations)
    ch, sh = np.cos(heading), np.sin(heading)
    cp, sp = np.cos(pitch), np.sin(pitch)
    cr, sr = np.cos(roll), np.sin(roll)
    return _matrix([[ch * cp, ch * sp * sr - sh * cr, -ch * sp * cr - sh * sr],
                    [sh * cp, sh * sp * sr + ch * cr, -sh * sp * cr + ch * sr],
                    [sp, -cp * sr, cp * cr]])


def attitude_from_matrix(matrix):
    """Invert :func:`attitude_matrix`: (heading, pitch, roll) [rad] of a rotation.

    Valid for |pitch| < 90 deg. Heading is returned in [0, 2 pi).
    """
    m = np.asarray(matrix)
    pitch = np.arcsin(np.clip(m[..., 2, 0], -1.0, 1.0))
    heading = np.mod(np.arctan2(m[..., 1, 0], m[..., 0, 0]), 2 * np.pi)
    roll = np.arctan2(-m[..., 2, 1], m[..., 2, 2])
    return heading, pitch, roll


def rubio2022_rotation(delta, beta, gamma=0.0):
    """Rubio & Gottschall (2022) rotation ``R_yaw(gamma) @ R_roll(beta) @ R_pitch(delta)``.

    delta [rad] is their pitch (positive bow down), beta [rad] their roll (positive
    starboard down), gamma [rad] their yaw (clockwise). Case ii (Eq. 7 [1]) is gamma = 0.
    """
    return rotation_about_vertical(gamma) @ rotation_roll(beta) @ rotation_pitch(-delta)


def rubio2022_angles_from_attitude(heading, pitch, roll):
    """Exact Rubio & Gottschall (2022) angles (gamma, delta, beta) of a marine attitude [rad].

    ``rubio2022_rotation(delta, beta, gamma) == attitude_matrix(heading, pitch, roll)``.
    To first order gamma = heading, delta = -pitch and beta = roll. The orders of the
    rotations differ (theirs: pitch first, then roll about the earth's north axis), so a
    combined pitch and roll leaves a second-order yaw: gamma - heading = -1.75 deg at
    pitch = roll = 10 deg.
    """
    m = attitude_matrix(heading, pitch, roll)
    # row 2 of Rz(g) Rx(b) Ry(-d) is (-cos b sin d, -sin b, cos b cos d)
    beta = np.arcsin(np.clip(-m[..., 2, 1], -1.0, 1.0))
    delta = np.arctan2(-m[..., 2, 0], m[..., 2, 2])
    # column 1 is (-sin g cos b, cos g cos b, -sin b)
    gamma = np.mod(np.arctan2(-m[..., 0, 1], m[..., 1, 1]), 2 * np.pi)
    return gamma, delta, beta


def attitude_from_rubio2022_angles(gamma, delta, beta):
    """Inverse of :func:`rubio2022_angles_from_attitude`: marine (heading, pitch, roll) [rad]."""
    return attitude_from_matrix(rubio2022_rotation(delta, beta, gamma))


def rotate_vectors(matrix, vectors):
    """``matrix @ v`` for every vector v along the last axis of `vectors`.

    Parameters
    ----------
    matrix : ndarray, shape (*S, 3, 3)
    vectors : ndarray, shape (..., *S, k, 3)
        k vectors per matrix (e.g. the beams of a scan).

    Returns
    -------
    ndarray, shape (..., *S, k, 3)
    """
    matrix, vectors = np.asarray(matrix), np.asarray(vectors)
    if matrix.ndim == 2:
        # one matrix for all: a single BLAS product, ~3x faster than a stacked matmul
        return np.tensordot(vectors, matrix, axes=([-1], [1]))
    return np.einsum("...ij,...kj->...ki", matrix, vectors)


def apply_matrix(matrix, vectors):
    """``matrix @ vectors`` for stacks of small matrices, broadcasting their stack axes.

    Measured with numpy 2.4 on 6.4e5 stacked 3 x 3 matrices: the sum over j written out
    as j broadcast products is 1.2x faster than einsum (one vector per matrix) and
    matmul (g >= 2), 6x faster than einsum where the vectors broadcast over the
    matrices' trials; larger matrices take einsum (g = 1) or matmul. A single matrix (no
    per-sample attitude) goes through one BLAS product, ~10x faster still. Same values
    up to the order of additions.

    Parameters
    ----------
    matrix : ndarray, shape (..., i, j)
    vectors : ndarray, shape (..., j, g)

    Returns
    -------
    ndarray, shape (..., i, g)
    """
    matrix, vectors = np.asarray(matrix), np.asarray(vectors)
    if matrix.size == matrix.shape[-2] * matrix.shape[-1]:
        # one matrix for all samples (no per-sample attitude): a single BLAS product
        single = matrix.reshape(matrix.shape[-2:])
        product = np.swapaxes(np.tensordot(vectors, single, axes=([-2], [1])), -1, -2)
        return product.reshape(np.broadcast_shapes(matrix.shape[:-2], vectors.shape[:-2])
                               + product.shape[-2:])
    if matrix.shape[-1] <= 3:
        # the sum over j written out: (..., i, 1) x (..., 1, g) products, j of them
        # (einsum's generic loop is 6x slower where the vectors broadcast over the
        # matrices' trials; matmul loops per small matrix)
        product = matrix[..., :, 0, None] * vectors[..., 0:1, :]
        for j in range(1, matrix.shape[-1]):
            product += matrix[..., :, j, None] * vectors[..., j:j + 1, :]
        return product
    if vectors.shape[-1] == 1:
        return np.einsum("...ij,...jg->...ig", matrix, vectors)
    return np.matmul(matrix, vectors)


def attitude_matrix_rate(heading, pitch, roll, heading_rate, pitch_rate, roll_rate):
    """Time derivative of :func:`attitude_matrix` [rad s-1 -> (..., 3, 3) per s].

    ``dR/dt = dR/dheading heading' + dR/dpitch pitch' + dR/droll roll'``, written out
    from the same product; the velocity of a point fixed at ``x_ship`` in the ship frame
    is ``(dR/dt) @ x_ship`` in the earth frame (the lever-arm velocity omega x r, without
    forming omega in these left-handed triads). Complex-step safe.
    """
    ch, sh = np.cos(heading), np.sin(heading)
    cp, sp = np.cos(pitch), np.sin(pitch)
    cr, sr = np.cos(roll), np.sin(roll)
    dh, dp, dr = heading_rate, pitch_rate, roll_rate
    # d/dheading: ch -> -sh, sh -> ch
    row0 = [-sh * cp * dh - ch * sp * dp,
            (-sh * sp * sr - ch * cr) * dh + ch * cp * sr * dp + (ch * sp * cr + sh * sr) * dr,
            (sh * sp * cr - ch * sr) * dh - ch * cp * cr * dp + (ch * sp * sr - sh * cr) * dr]
    row1 = [ch * cp * dh - sh * sp * dp,
            (ch * sp * sr - sh * cr) * dh + sh * cp * sr * dp + (sh * sp * cr - ch * sr) * dr,
            (-ch * sp * cr - sh * sr) * dh - sh * cp * cr * dp + (sh * sp * sr + ch * cr) * dr]
    row2 = [cp * dp, sp * sr * dp - cp * cr * dr, -sp * cr * dp - cp * sr * dr]
    return _matrix([row0, row1, row2])


def attitude_from_matrix_analytic(matrix):
    """:func:`attitude_from_matrix` for complex-step arguments: (heading, pitch, roll)
    [rad] with the first-order imaginary parts carried (no clipping; heading not
    wrapped). Valid for |pitch| < 90 deg."""
    from uq import complexstep
    m = np.asarray(matrix)
    pitch = np.arcsin(m[..., 2, 0])
    heading = complexstep.arctan2(m[..., 1, 0], m[..., 0, 0])
    roll = complexstep.arctan2(-m[..., 2, 1], m[..., 2, 2])
    return heading, pitch, roll


def interpolate_rotation(start, end, fraction):
    """Rotation a `fraction` of the way from `start` to `end` on the rotation group
    (spherical linear interpolation, slerp): ``start @ exp(fraction log(start^T end))``.

    Parameters
    ----------
    start, end : ndarray, shape (..., 3, 3)
    fraction : array_like, shape (...)
        0 gives `start`, 1 gives `end`.

    The rotation vector comes from the skew part of ``start^T end`` (angle below 90 deg
    between INS samples, so arcsin is exact); the small-angle factors use their series,
    so the interpolation is analytic (complex-step safe) down to equal rotations.
    """
    relative = np.swapaxes(start, -1, -2) @ end
    skew = 0.5 * (relative - np.swapaxes(relative, -1, -2))
    axis_sin = np.stack([skew[..., 2, 1], skew[..., 0, 2], skew[..., 1, 0]], axis=-1)
    sin2 = np.sum(axis_sin * axis_sin, axis=-1)              # sin^2 theta
    angle_over_sin = _angle_over_sin(sin2)                   # theta / sin theta
    rotation_vector = axis_sin * angle_over_sin[..., None] * np.asarray(fraction)[..., None]
    return start @ rotation_from_vector(rotation_vector)


def rotation_from_vector(vector):
    """Rodrigues: the rotation by |v| about v (v in the frame's own coordinates; the sense
    is that of the skew matrix ``[v]_x``, consistent with :func:`interpolate_rotation`)."""
    v = np.asarray(vector)
    angle2 = np.sum(v * v, axis=-1)
    a, b = _sin_over_angle(angle2), _one_minus_cos_over_angle2(angle2)
    zero = np.zeros_like(v[..., 0])
    k = _matrix([[zero, -v[..., 2], v[..., 1]], [v[..., 2], zero, -v[..., 0]],
                 [-v[..., 1], v[..., 0], zero]])
    eye = np.eye(3, dtype=k.dtype)
    return eye + a[..., None, None] * k + b[..., None, None] * (k @ k)


#: Squared angle [rad^2] below which the small-angle factors use their series: the first
#: omitted terms are ~x^6/5040 = 2e-22 relative at x^2 = 1e-6, far below an ulp; the
#: closed forms above it have no cancellation (1 - cos x is written 2 sin^2(x/2)).
_SERIES_LIMIT = 1e-6


def _series_or(closed, series, x2):
    x2 = np.asarray(x2)
    small = np.real(x2) < _SERIES_LIMIT
    safe = np.where(small, _SERIES_LIMIT, x2)
    return np.where(small, series(x2), closed(safe))


def _angle_over_sin(sin2):
    """theta / sin theta from sin^2 theta (theta < 90 deg)."""
    return _series_or(lambda s2: np.arcsin(np.sqrt(s2)) / np.sqrt(s2),
                      lambda s2: 1 + s2 / 6 + 3 * s2**2 / 40, sin2)


def _sin_over_angle(x2):
    return _series_or(lambda a2: np.sin(np.sqrt(a2)) / np.sqrt(a2),
                      lambda a2: 1 - a2 / 6 + a2**2 / 120, x2)


def _one_minus_cos_over_angle2(x2):
    """(1 - cos x) / x^2 = (sin(x/2) / (x/2))^2 / 2, without cancellation."""
    return 0.5 * _sin_over_angle(np.asarray(x2) / 4) ** 2
