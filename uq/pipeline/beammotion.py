"""Where a moving platform's beams really are during a record: the lidar's displacement
and each beam's true direction at every scan and beam, in the mean-wind frame, for the
Monte Carlo records' turbulence sampling (:func:`uq.physics.turbulencesampling.
record_radial_velocities`).

Conventions
-----------
* Time: scan s of a record starts at ``s T_s``; the motion's unit phases of scan s
  (:func:`uq.pipeline.records.coherent_phases`) already hold the advance ``w s T_s``, so
  within a scan the time runs from the scan's start (:mod:`uq.physics.motion`), and a
  beam is placed at the middle of its dwell (``geometry.times``).
* Earth frame (north, east, up), ship frame (bow, starboard, up), attitude R(t) =
  static heading, pitch, roll plus the motion's yaw, pitch, roll (marine convention,
  :mod:`uq.physics.rotation`); :func:`uq.physics.motion.platform_kinematics` gives R(t)
  and the lidar's displacement from its static position,
  ``translation(t) + R(t) r - R_static r`` (r the lever arm).
* A beam's true direction is ``R(t) b_ship``, with ``b_ship = R_static^T d_nominal`` the
  configured ship-frame beam that the geometry's nominal direction ``d_nominal`` was made
  of (so that without motion the true direction is the nominal one). The beam's
  configured half-cone and misalignment are used, not their per-scan error draws.
* Both are rotated into the mean-wind frame (x downwind, y left, z up) with
  :func:`uq.physics.scangeometry.earth_to_wind_frame`.
"""
import numpy as np

from uq.physics.motion import platform_kinematics
from uq.physics.rotation import attitude_matrix
from uq.physics.scangeometry import earth_to_wind_frame, wind_to_earth_frame
from uq.physics.turbulencesampling import gate_ranges


def moving_beams(scene, unit_phases, geometry, wind_direction):
    """The lidar's displacement and the beams' true directions at every scan and beam.

    Parameters
    ----------
    scene : uq.physics.scene.Scene
        One scene (scalar fields, radians) with ``time_resolved`` motion.
    unit_phases : ndarray, shape (n_scans, K, 2)
        The unit phase vector c_k of every motion component at each scan's start
        (:meth:`uq.physics.motion.Motion.unit_phases`).
    geometry : ScanGeometry
        The nominal scan (directions in the mean-wind frame, beam mid times [s]).
    wind_direction : float
        Meteorological wind direction ("from", clockwise from north) [deg].

    Returns
    -------
    displacements, directions : ndarray, shape (n_scans, n_beams, 3)
        The lidar's displacement from its nominal position [m] and the true unit vector
        of each beam [1], mean-wind frame.
    """
    kinematics = platform_kinematics(scene, scene.time_resolved.motion, unit_phases,
                                     np.asarray(geometry.times, dtype=float)[None, :])
    static = attitude_matrix(scene.heading, scene.pitch, scene.roll)
    nominal_earth = wind_to_earth_frame(geometry.directions, wind_direction)   # (B, 3)
    ship_beams = nominal_earth @ static                   # rows: R_static^T d, (B, 3)
    true_earth = (kinematics["attitude"] @ ship_beams[:, :, None])[..., 0]    # (S, B, 3)
    return (earth_to_wind_frame(kinematics["lidar_offset"], wind_direction),
            earth_to_wind_frame(true_earth, wind_direction))


def motion_margin(geometry, position, displacements, directions):
    """A bound on how far the motion moves any probe point from its nominal place [m].

    A probe point at distance a along beam b from the lidar moves by
    ``displacement + a (d_true - d_nominal)``, at most ``|displacement| + max|a| |d_true
    - d_nominal|`` (triangle inequality); a is the gate's range from the nominal lidar
    `position` (mean-wind frame [m], shape (3,)) plus the probe's offsets.
    """
    reach = np.abs(gate_ranges(geometry, position)[..., None]
                   + np.asarray(geometry.probe_offsets)).max()
    turn = np.linalg.norm(directions - np.asarray(geometry.directions), axis=-1)
    return float(np.max(np.linalg.norm(displacements, axis=-1) + reach * turn))
