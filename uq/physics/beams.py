"""Beam geometry of a Doppler-beam-swinging (DBS) lidar and its least-squares inversion.

A slanted beam with half-cone angle theta (from the lidar's vertical) and azimuth phi
(clockwise from the lidar's reference beam), on a lidar whose reference beam points at
`misalignment` clockwise from the bow, has the ship-frame unit vector (Eq. 1 of [1])::

    n = (sin(theta) cos(m + phi), sin(theta) sin(m + phi), cos(theta))

in (bow, starboard, up). An optional vertical beam is (0, 0, 1). Radial velocity is
positive away from the lidar: ``v_r = n . (u_wind - u_lidar)``.

Tilted mount (``lidar.mount.tilt`` tau > 0, a nacelle lidar at tau = 90 deg)
---------------------------------------------------------------------------
The boresight d is tilted from the deck's vertical towards the bow by tau; the beams open
by the half-cone alpha about d, at *clock positions* phi about it: 0 = up, 90 = starboard
(to the right looking along the boresight), 180 = down, 270 = port, i.e. clockwise as
seen looking along the boresight::

    d = (sin tau, 0, cos tau),  e_up = (-cos tau, 0, sin tau),  e_starboard = (0, 1, 0)
    n = Rz(m) [cos(alpha) d + sin(alpha) (cos(phi) e_up + sin(phi) e_starboard)]

with the misalignment m turning the whole head about the deck's vertical (clockwise seen
from above; at tau = 90 the boresight's azimuth from the bow). This frame is the upward
(tau = 0) lidar's frame turned about the starboard axis by tau, with the clock position
phi = 180 deg - (today's azimuth): today's azimuths run clockwise *seen from above*, i.e.
counter-clockwise seen along an upward boresight, so the clock convention is their mirror
image and no family of frames continuous in tau joins the two. ``tilt: 0`` keeps today's
azimuths exactly (the contract: bit for bit); any tau > 0 reads them as clock positions.
The range gates of a tilted mount are preview distances along the boresight, so the
slant distance is ``range / cos(alpha)`` as for the upward lidar's heights
(:func:`slant_distances`).

References
----------
.. [1] Rubio, H. and Gottschall, J. (2022). J. Phys.: Conf. Ser. 2362 012034.
"""
import numpy as np


def beam_unit_vectors(half_cone, azimuths, misalignment=0.0, vertical_beam=False, tilt=0.0):
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
    tilt : float
        Mount tilt tau from the deck's vertical towards the bow [rad]; 0: today's upward
        lidar (this function's first formula, bit for bit); > 0: `azimuths` are clock
        positions about the tilted boresight (:func:`mounted_unit_vectors`).

    Returns
    -------
    ndarray, shape (..., n_beams, 3)
        Slanted beams first, in the order of `azimuths`, then the vertical beam.
    """
    if tilt != 0:
        if vertical_beam:
            raise ValueError("a tilted mount has no vertical beam")
        return mounted_unit_vectors(half_cone, azimuths, misalignment, tilt)
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


def mounted_unit_vectors(half_cone, clock_positions, misalignment, tilt):
    """Ship-frame unit vectors of a tilted mount's beams (module docstring).

    Parameters
    ----------
    half_cone : array_like, shape (...)
        Opening angle alpha from the boresight [rad].
    clock_positions : array_like, shape (n_beams,)
        phi about the boresight, 0 up, pi/2 starboard, pi down [rad].
    misalignment : array_like, shape (...)
        Turn of the head about the deck's vertical, clockwise seen from above [rad].
    tilt : float
        tau, boresight from the deck's vertical towards the bow [rad].

    Returns
    -------
    ndarray, shape (..., n_beams, 3)
        (bow, starboard, up).
    """
    alpha = np.asarray(half_cone)[..., None]
    m = np.asarray(misalignment)[..., None]
    phi = np.asarray(clock_positions, dtype=float)
    cos_a, sin_a = np.cos(alpha), np.sin(alpha)
    sin_t, cos_t = np.sin(tilt), np.cos(tilt)
    # n = cos(a) d + sin(a) (cos(phi) e_up + sin(phi) e_starboard) in the unturned head
    bow = cos_a * sin_t - sin_a * np.cos(phi) * cos_t
    starboard = sin_a * np.sin(phi)
    up = cos_a * cos_t + sin_a * np.cos(phi) * sin_t
    cos_m, sin_m = np.cos(m), np.sin(m)
    # Rz(m), clockwise seen from above (uq.physics.rotation.rotation_about_vertical)
    return np.stack(np.broadcast_arrays(cos_m * bow - sin_m * starboard,
                                        sin_m * bow + cos_m * starboard, up + 0 * m), axis=-1)


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
