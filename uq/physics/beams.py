"""Beam geometry of a Doppler-beam-swinging (DBS) lidar and its least-squares inversion.

A slanted beam with half-cone angle theta (from the lidar's vertical) and azimuth phi
(clockwise from the lidar's reference beam), on a lidar whose reference beam points at
`misalignment` clockwise from the bow, has the ship-frame unit vector (Eq. 1 of [1])::

    n = (sin(theta) cos(m + phi), sin(theta) sin(m + phi), cos(theta))

in (bow, starboard, up). An optional vertical beam is (0, 0, 1). Radial velocity is
positive away from the lidar: ``v_r = n . (u_wind - u_lidar)``.

References
----------
.. [1] Rubio, H. and Gottschall, J. (2022). J. Phys.: Conf. Ser. 2362 012034.
"""
import numpy as np


def beam_unit_vectors(half_cone, azimuths, misalignment=0.0, vertical_beam=False):
    """Ship-frame unit vectors of the beams.

    Parameters
    ----------
    half_cone : array_like, shape (...)
        Half-cone angle from the lidar's vertical [rad].
    azimuths : array_like, shape (n_slanted,)
        Beam azimuths, clockwise from the lidar's reference beam [rad].
    misalignment : array_like, shape (...)
        Angle from the bow to the reference beam, clockwise [rad].
    vertical_beam : bool
        Append a vertical beam (unaffected by half-cone and misalignment).

    Returns
    -------
    ndarray, shape (..., n_beams, 3)
        Slanted beams first, in the order of `azimuths`, then the vertical beam.
    """
    half_cone = np.asarray(half_cone)[..., None]
    misalignment = np.asarray(misalignment)[..., None]
    azimuths = np.asarray(azimuths, dtype=float)
    # cos(m + phi), sin(m + phi) by the addition theorems: two sines and cosines per
    # misalignment instead of two per beam (the trigonometry dominates per-sample beams)
    cos_m, sin_m = np.cos(misalignment), np.sin(misalignment)
    cos_phi, sin_phi = np.cos(azimuths), np.sin(azimuths)
    sin_cone = np.sin(half_cone)
    vectors = np.stack(np.broadcast_arrays(sin_cone * (cos_m * cos_phi - sin_m * sin_phi),
                                           sin_cone * (sin_m * cos_phi + cos_m * sin_phi),
                                           np.cos(half_cone)), axis=-1)
    if vertical_beam:
        up = np.zeros(vectors.shape[:-2] + (1, 3), dtype=vectors.dtype)
        up[..., 2] = 1.0
        vectors = np.concatenate([vectors, up], axis=-2)
    return vectors


def least_squares_operator(unit_vectors):
    """Pseudo-inverse that maps radial velocities to the wind vector.

    For beams with rows ``n_i`` the least-squares wind is ``u = A^+ v`` with
    ``A = [n_i]``; for the 4-beam DBS this is the classical
    ``u = (v_N - v_S) / (2 sin theta)`` etc. (Eqs. 14-15 of [1]).

    Parameters
    ----------
    unit_vectors : ndarray, shape (..., n_beams, 3)
        Needs at least three beams that span three dimensions.

    Returns
    -------
    ndarray, shape (..., 3, n_beams)

    Raises
    ------
    ValueError
        If the beams do not determine all three wind components.
    """
    a = np.asarray(unit_vectors, dtype=float)
    if a.shape[-2] < 3 or np.any(np.linalg.matrix_rank(a) < 3):
        raise ValueError("the beams do not determine the 3-D wind: need >= 3 beams "
                         "that are not coplanar")
    return np.linalg.pinv(a)


def slant_distances(range_heights, half_cone, n_slanted, vertical_beam):
    """Distance along each beam to each range gate [m].

    Range gates are given as heights above a level lidar; the lidar places the gate of a
    slanted beam at the slant distance ``h / cos(half_cone)`` using its configured
    (nominal) half-cone, and that of the vertical beam at ``h``.

    Parameters
    ----------
    range_heights : array_like, shape (n_gates,)
        [m].
    half_cone : array_like, shape S
        Configured half-cone [rad] (S: scenes, may be empty).

    Returns
    -------
    ndarray, shape (*S, n_beams, n_gates)
    """
    heights = np.asarray(range_heights, dtype=float)
    cone = np.asarray(half_cone)[..., None, None]
    slanted = np.broadcast_to(heights / np.cos(cone), cone.shape[:-2] + (n_slanted, heights.size))
    if vertical_beam:
        vertical = np.broadcast_to(heights, cone.shape[:-2] + (1, heights.size))
        return np.concatenate([slanted, vertical], axis=-2)
    return np.array(slanted)
