"""The nominal scene of one measurement (or a batch of scenes): what the ship, the lidar
and the wind truly are, in SI units and radians.

Conventions (as in the README): earth frame (north, east, up); angles clockwise from
north; wind direction meteorological ("from"); ship attitude in the marine convention of
:mod:`uq.physics.rotation` (heading clockwise from north, pitch positive bow up, roll
positive starboard down).
"""
from dataclasses import dataclass

import numpy as np

from uq.physics.beams import beam_unit_vectors
from uq.physics.ins import InsSampling
from uq.physics.modelinputs import navigation_keys
from uq.physics.motion import Motion
from uq.physics.timing import ScanTiming

SCENE_FIELDS = ("wind_speed", "wind_direction", "vertical_wind", "shear", "reference_height",
                "sog", "cog", "heading", "pitch", "roll", "heave", "lidar_height",
                "half_cone", "misalignment")
OUTPUTS = ("wind_speed", "wind_direction", "vertical_wind", "radial_velocity", "gate_height")
#: The outputs of a tilted (nacelle) mount (:mod:`uq.physics.nacelle`): the wind direction
#: relative to the rotor axis (the static heading) [deg] and the power-law exponent from
#: the upper and lower beams [1].
NACELLE_OUTPUTS = ("yaw_misalignment", "shear_exponent")
#: Every per-trial output a scenario may request.
ALL_OUTPUTS = OUTPUTS + NACELLE_OUTPUTS
#: The wind speed of a second evaluation with some inputs held (``held`` of
#: :func:`uq.physics.measurement.measurement_model`): the same trials' speed with those
#: inputs replaced, e.g. the motion alone (``wind_speed_motion_ti``) [m s-1].
HELD_WIND_SPEED = "wind_speed_held"


def with_held(result, second):
    """`result` (outputs of a model call) with the wind speed of the `second` evaluation
    (its inputs held) as :data:`HELD_WIND_SPEED`, as many trials as `result` has."""
    speed = second["wind_speed"]
    n = max(np.shape(v)[0] for v in result.values())
    return {**result, HELD_WIND_SPEED: np.broadcast_to(speed, (n,) + np.shape(speed)[1:])}
#: The outputs the compiled model (:mod:`uq.physics.fused`) computes: those of OUTPUTS.
COMPILED_OUTPUTS = OUTPUTS
#: What the INS reports with an error, and the angles among them (:mod:`uq.physics.modelinputs`).
NAVIGATION = navigation_keys()
ANGULAR_NAVIGATION = navigation_keys(angular_only=True)


@dataclass(frozen=True)
class Scene:
    """Nominal (true) scene of one measurement, SI units and radians.

    Attributes
    ----------
    wind_speed : float
        Horizontal wind speed at `reference_height` [m s-1].
    wind_direction : float
        Meteorological direction ("from"), clockwise from north [rad].
    vertical_wind : float
        [m s-1], positive up.
    shear : float
        Power-law exponent [1].
    reference_height : float
        [m] above sea level.
    sog, cog, heading, pitch, roll, heave : float
        True ship motion: [m s-1], [rad] x4 (marine convention, :mod:`uq.physics.rotation`),
        [m s-1].
    lidar_height : float
        [m] above sea level.
    ranges : tuple of float
        Range-gate heights above a level lidar [m].
    half_cone, misalignment : float
        Configured geometry [rad].
    azimuths : tuple of float
        Slanted-beam azimuths from the reference beam [rad].
    vertical_beam : bool
    correction : str
        One of :data:`uq.physics.correction.CORRECTION_MODELS`.
    time_resolved : TimeResolved or None
        Motion during the scan, scan timing and the INS as a sampled series; None is the
        static model (every beam at the same instant and attitude).
    probe : uq.physics.probe.PulsedProbe, ContinuousWaveProbe or None
        The range weighting of the radial velocities along each beam; None is the
        point-wise measurement at the gate centre.
    tilt : float
        Mount tilt of the boresight from the deck's vertical towards the bow [rad]
        (``lidar.mount.tilt``); 0 is the upward lidar. For tilt > 0 `azimuths` are clock
        positions about the boresight (0 up, pi/2 starboard, pi down) and `ranges`
        preview distances along it (:mod:`uq.physics.beams`).
    """

    wind_speed: float
    wind_direction: float
    vertical_wind: float
    shear: float
    reference_height: float
    sog: float
    cog: float
    heading: float
    pitch: float
    roll: float
    heave: float
    lidar_height: float
    ranges: tuple
    half_cone: float
    misalignment: float
    azimuths: tuple
    vertical_beam: bool
    correction: str
    time_resolved: object = None
    probe: object = None
    tilt: float = 0.0

    @property
    def shape(self):
        """Shape S of a batch of scenes (``()`` for one scene)."""
        return np.broadcast(*[getattr(self, name) for name in SCENE_FIELDS]).shape

    def field(self, name, trailing=0):
        """A numeric field shaped ``S + (1,) * trailing``, to broadcast against data of
        shape (..., *S, *trailing)."""
        value = np.asarray(getattr(self, name))
        return value if value.ndim == 0 else np.reshape(value, self.shape + (1,) * trailing)

    @property
    def n_beams(self):
        return len(self.azimuths) + int(self.vertical_beam)

    def nominal_unit_vectors(self):
        """Configured beam vectors in the ship frame, shape (n_beams, 3)."""
        return beam_unit_vectors(self.half_cone, np.asarray(self.azimuths),
                                 self.misalignment, self.vertical_beam, self.tilt)

    @property
    def horizontal_only(self):
        """True where the beams see only the horizontal wind and w = 0 is assumed: a
        tilted mount with two beams (e.g. a nacelle lidar's clock positions 90 and 270)."""
        return self.tilt != 0 and self.n_beams == 2

    def gate_heights(self):
        """Nominal measurement heights above sea level [m], shape (*S, n_gates): the
        lidar's height plus the gate's range along the boresight's vertical,
        ``range cos(tilt)`` (the range itself for the upward lidar)."""
        ranges = np.asarray(self.ranges, dtype=float)
        if self.tilt != 0:
            ranges = ranges * np.cos(self.tilt)
        return self.field("lidar_height", 1) + ranges


@dataclass(frozen=True)
class TimeResolved:
    """What makes a scan time-resolved (see :mod:`uq.physics.timeresolved`).

    Attributes
    ----------
    motion : uq.physics.motion.Motion
        Harmonic components and the lever arm.
    timing : uq.physics.timing.ScanTiming
    ins : uq.physics.ins.InsSampling
    """

    motion: Motion = Motion()
    timing: ScanTiming = ScanTiming()
    ins: InsSampling = InsSampling()


def sample_count(errors):
    """Number of trials n of a call of the measurement model: the leading axis of its
    error arrays (1 when every error is a scalar)."""
    sizes = {np.shape(value)[0] for value in errors.values() if np.ndim(value) > 0}
    return max(sizes) if sizes else 1
