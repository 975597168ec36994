"""How a lidar's scan samples a turbulent wind field: the geometry both turbulence paths share.

The spectral path (:mod:`uq.physics.lidarspectral`) filters the spectral tensor with the
transfer function of a :class:`ScanGeometry`; the Monte Carlo path
(:mod:`uq.physics.turbulencesampling`) samples a generated field at the same points. The
pipeline builds the geometry from a scenario (nominal, motionless beams); the Monte Carlo
path moves the beams with the platform's true motion.

Conventions
-----------
*Mean-wind frame* (x, y, z) [m]: x along the mean horizontal wind (the direction the air
moves *to*), y horizontal and 90 deg counter-clockwise from x seen from above (to the
left, looking downwind), z up; right-handed. The earth frame of the rest of ``uq`` is
(north, east, up) with the wind direction D [deg] the meteorological direction the wind
blows *from*, clockwise from north, so (:func:`earth_to_wind_frame`)::

    x = -(cos D north + sin D east),  y = -sin D north + cos D east,  z = up

*Frozen turbulence* (Taylor's hypothesis): the turbulent velocity at point r and time t
is that of a field advected unchanged with the mean speed U along x,
``u'(r, t) = u'_0(r - U t e_x)``.

*Times* [s] are measured from the start of the scan (a beam's time is the middle of its
dwell); scans follow one another every ``scan_period`` seconds.
"""
from dataclasses import dataclass

import numpy as np


def earth_to_wind_frame(vectors, direction):
    """Rotate (north, east, up) vectors into the mean-wind frame (x downwind, y left, z up).

    Parameters
    ----------
    vectors : array_like, shape (..., 3)
        Earth-frame vectors (north, east, up) [any unit].
    direction : float
        Meteorological wind direction, "from", clockwise from north [deg].

    Returns
    -------
    ndarray, shape (..., 3)
        The same vectors as (x, y, z).

    Examples
    --------
    A wind from the west (270 deg) blows towards the east, so east is +x and north is +y:

    >>> earth_to_wind_frame([[0.0, 1.0, 0.0], [1.0, 0.0, 0.0]], 270.0).round(12) + 0.0
    array([[1., 0., 0.],
           [0., 1., 0.]])
    """
    v = np.asarray(vectors, dtype=float)
    c, s = np.cos(np.radians(direction)), np.sin(np.radians(direction))
    x = -(c * v[..., 0] + s * v[..., 1])
    y = -s * v[..., 0] + c * v[..., 1]
    return np.stack([x, y, v[..., 2]], axis=-1)


def wind_to_earth_frame(vectors, direction):
    """Inverse of :func:`earth_to_wind_frame`: (x, y, z) -> (north, east, up); shape (..., 3)."""
    v = np.asarray(vectors, dtype=float)
    c, s = np.cos(np.radians(direction)), np.sin(np.radians(direction))
    north = -c * v[..., 0] - s * v[..., 1]
    east = -s * v[..., 0] + c * v[..., 1]
    return np.stack([north, east, v[..., 2]], axis=-1)


@dataclass(frozen=True)
class ScanGeometry:
    """One scan of a motionless lidar in the mean-wind frame (module docstring).

    Attributes
    ----------
    directions : ndarray, shape (n_beams, 3)
        Unit vector of each beam, pointing away from the lidar; the radial velocity is
        ``directions[b] . u`` (positive away from the lidar).
    gate_centres : ndarray, shape (n_beams, n_gates, 3)
        Centre of each range gate relative to the reference point [m]; the reference point
        is (0, 0, 0) at ``wind.reference_height``.
    times : ndarray, shape (n_beams,)
        Mid time of each beam's dwell from the start of the scan [s].
    dwell : float
        Duration of one beam's dwell [s] (0: an instantaneous line of sight).
    scan_period : float
        Time from one scan's start to the next's [s].
    probe_offsets : ndarray, shape (n_nodes,)
        Distances along the beam from the gate centre of the probe's quadrature nodes [m]
        (one node at 0 for a point probe).
    probe_weights : ndarray, shape (n_gates, n_nodes)
        Quadrature weights of the probe weighting function at those nodes, each row
        summing to 1 (the weighting may differ per gate: a CW lidar's focus).
    reconstruction : ndarray, shape (n_gates, 3, n_beams)
        The linear operator from the scan's radial velocities to the reconstructed wind
        (x, y, z) at each gate (for a DBS the pseudo-inverse of ``directions``).
    speed : float
        Mean wind speed at the reference point [m s-1] (advects the frozen field).
    record_duration : float
        Record length [s] whose mean is removed before the variance (the record's
        high-pass); ``inf`` for no high-pass.
    """

    directions: np.ndarray
    gate_centres: np.ndarray
    times: np.ndarray
    dwell: float
    scan_period: float
    probe_offsets: np.ndarray
    probe_weights: np.ndarray
    reconstruction: np.ndarray
    speed: float
    record_duration: float = np.inf

    def __post_init__(self):
        n_beams = np.shape(self.directions)[0]
        n_gates = np.shape(self.gate_centres)[1]
        checks = (
            (np.shape(self.directions) == (n_beams, 3), "directions must be (n_beams, 3)"),
            (np.shape(self.gate_centres) == (n_beams, n_gates, 3),
             "gate_centres must be (n_beams, n_gates, 3)"),
            (np.shape(self.times) == (n_beams,), "times must be (n_beams,)"),
            (np.shape(self.probe_weights) == (n_gates, np.size(self.probe_offsets)),
             "probe_weights must be (n_gates, n_nodes)"),
            (np.shape(self.reconstruction) == (n_gates, 3, n_beams),
             "reconstruction must be (n_gates, 3, n_beams)"),
            (np.allclose(np.linalg.norm(self.directions, axis=-1), 1.0),
             "directions must be unit vectors"),
            (self.dwell >= 0 and self.scan_period > 0 and self.speed > 0
             and self.record_duration > 0, "dwell >= 0, scan_period, speed, record > 0"),
        )
        for ok, message in checks:
            if not ok:
                raise ValueError(f"ScanGeometry: {message}")

    @property
    def n_beams(self):
        """Number of beams of a scan."""
        return np.shape(self.directions)[0]

    @property
    def n_gates(self):
        """Number of range gates."""
        return np.shape(self.gate_centres)[1]

    def probe_points(self):
        """Quadrature nodes of every probe, shape (n_beams, n_gates, n_nodes, 3) [m]."""
        along = np.asarray(self.probe_offsets)[None, None, :, None]
        return (np.asarray(self.gate_centres)[:, :, None, :]
                + along * np.asarray(self.directions)[:, None, None, :])


def conical_scan(heights, half_cone=30.0, beam_duration=0.001, n_beams=4, vertical=False,
                 record=600.0, offsets=(0.0,), weights=None, speed=10.0):
    """A fixed, level conical scan (a DBS, or a VAD of many beams) from the ground.

    Beam 0 along the wind (azimuth 0 = +x), the beams counter-clockwise at equal steps,
    then the vertical beam (`vertical`); the reference point at the first height; the
    beams one after another, each `beam_duration` [s] long and averaged over it; the
    reconstruction the pseudo-inverse of the directions at every gate.

    Parameters
    ----------
    heights : float or sequence of float
        Gate heights above the lidar [m].
    half_cone : float
        Angle of the slanted beams from the vertical [deg].
    beam_duration : float
        Dwell of each beam [s].
    n_beams : int
        Slanted beams.
    vertical : bool
        Whether a vertical beam follows them.
    record : float
        Record duration [s] (``inf``: no high-pass).
    offsets : sequence of float
        Probe nodes along the beam from the gate centre [m] (one at 0: a point probe).
    weights : array, shape (n_gates, n_nodes), optional
        Their weights (default equal, summing to 1).
    speed : float
        Mean wind speed [m s-1].

    Returns
    -------
    ScanGeometry
    """
    phi, heights = np.radians(half_cone), np.atleast_1d(np.asarray(heights, float))
    azimuths = np.radians(np.arange(n_beams) * 360.0 / n_beams)
    d = np.stack([np.sin(phi) * np.cos(azimuths), np.sin(phi) * np.sin(azimuths),
                  np.full(n_beams, np.cos(phi))], -1)
    if vertical:
        d = np.vstack([d, [0.0, 0.0, 1.0]])
    slant = heights[None, :] / d[:, 2:3]
    centres = np.array([0.0, 0.0, -heights[0]]) + slant[..., None] * d[:, None, :]
    n = len(d)
    weights = (np.ones((len(heights), np.size(offsets))) / np.size(offsets)
               if weights is None else weights)
    return ScanGeometry(d, centres, (np.arange(n) + 0.5) * beam_duration, beam_duration,
                        n * beam_duration, np.asarray(offsets, float), weights,
                        np.tile(np.linalg.pinv(d)[None], (len(heights), 1, 1)), speed, record)
