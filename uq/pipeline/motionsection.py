"""Scenario keys of time-resolved motion: the ``motion`` section, ``lidar.lever_arm``,
``lidar.scan``, ``ins.rate``, ``ins.interpolation``, ``ins.clock_offset`` and the INS
errors' ``correlation_time``; and the :class:`uq.physics.scene.TimeResolved` they build.

Absent, the scenario is today's static model, bit for bit (none of these keys enters the
validated settings unless given).

.. code-block:: yaml

    motion:                      # on top of the static attitude and velocity of `ship`
      roll:  {amplitude: 5.0, period: 5.0, phase: random}   # deg, s, deg or random
      pitch: {amplitude: 3.0, period: 6.0, phase: 90}
      heave: {amplitude: 1.0, period: 8.0}                  # surge, sway, heave in m
    lidar:
      lever_arm: [0.0, 0.0, 2.0]   # m, (bow, starboard, up) from the INS to the lidar
      scan: {beam_duration: 1.0, timestamp: mid, dwell_average: false}
    ins:
      rate: 10                     # Hz (absent: a continuous INS)
      interpolation: linear        # nearest | linear
      clock_offset: {dist: normal, u: 0.02}                 # s
      sog: {dist: normal, u: 0.1, correlation_time: 2.0}    # s, Gauss-Markov
    correction: pointwise
"""
import math

import numpy as np

from uq.physics.ins import INTERPOLATIONS, InsSampling
from uq.physics.motion import DEGREES_OF_FREEDOM, Motion, MotionComponent
from uq.physics.scene import TimeResolved
from uq.physics.timing import TIMESTAMPS, ScanTiming

HARMONIC_KEYS = ("amplitude", "period", "phase")
SCAN_KEYS = ("beam_duration", "timestamp", "dwell_average")
SCAN_DEFAULTS = {"beam_duration": 1.0, "timestamp": "mid", "dwell_average": False}
ANGULAR_DOFS = ("roll", "pitch", "yaw")
#: Largest motion amplitude [deg] (rotations) accepted: beyond it the platform capsizes
#: in the model's Euler angles (the static tilt limit is 89 deg).
MAX_ANGULAR_AMPLITUDE_DEG = 45.0


def validate_motion(check, value):
    """The validated ``motion`` section (degrees and seconds, as in the file)."""
    check.mapping(value, "motion")
    check.keys(value, "motion", DEGREES_OF_FREEDOM)
    out = {}
    for dof in DEGREES_OF_FREEDOM:
        if dof in value:
            out[dof] = _harmonic(check, value[dof], f"motion.{dof}", dof in ANGULAR_DOFS)
    return out


def _harmonic(check, value, key, angular):
    check.mapping(value, key)
    check.keys(value, key, HARMONIC_KEYS)
    for name in ("amplitude", "period"):
        if name not in value:
            check.fail(f"{key}.{name}", "missing; a harmonic needs amplitude and period "
                       "(phase defaults to random)")
    high = MAX_ANGULAR_AMPLITUDE_DEG if angular else None
    phase = value.get("phase", "random")
    return {"amplitude": check.number(value["amplitude"], f"{key}.amplitude", low=0.0,
                                      high=high),
            "period": check.number(value["period"], f"{key}.period", low=0.0, low_open=True),
            "phase": "random" if phase == "random" else check.number(
                phase, f"{key}.phase", low=-360.0, high=360.0)}


def validate_lever_arm(check, value):
    items = check.number_list(value, "lidar.lever_arm")
    if len(items) != 3:
        check.fail("lidar.lever_arm", f"{len(items)} values; allowed: [bow, starboard, up] "
                   "in m")
    return items


def validate_scan(check, value):
    check.mapping(value, "lidar.scan")
    check.keys(value, "lidar.scan", SCAN_KEYS)
    s = {**SCAN_DEFAULTS, **value}
    return {"beam_duration": check.number(s["beam_duration"], "lidar.scan.beam_duration",
                                          low=0.0, low_open=True),
            "timestamp": check.choice(s["timestamp"], "lidar.scan.timestamp",
                                      tuple(TIMESTAMPS)),
            "dwell_average": check.boolean(s["dwell_average"], "lidar.scan.dwell_average")}


def validate_ins_timing(check, value, out):
    """``ins.rate`` and ``ins.interpolation`` into `out` (only when given)."""
    if "rate" in value:
        out["rate"] = check.number(value["rate"], "ins.rate", low=0.0, low_open=True)
    if "interpolation" in value:
        out["interpolation"] = check.choice(value["interpolation"], "ins.interpolation",
                                            INTERPOLATIONS)


def is_time_resolved(settings):
    """Does the scenario need the time-resolved model? (``lidar.scan`` alone does not:
    without motion every beam sees the same platform; it times the Gauss-Markov INS
    errors of the static model.)"""
    ins, lidar = settings["ins"], settings["lidar"]
    return bool(settings.get("motion")) or "lever_arm" in lidar or \
        settings["correction"] == "pointwise" or "rate" in ins or "clock_offset" in ins


def time_resolved(settings):
    """The :class:`TimeResolved` of validated settings, or None for a static scan."""
    if not is_time_resolved(settings):
        return None
    lidar, ins = settings["lidar"], settings["ins"]
    components = tuple(_component(dof, spec) for dof, spec in
                       (settings.get("motion") or {}).items())
    motion = Motion(components, tuple(lidar.get("lever_arm", (0.0, 0.0, 0.0))))
    scan = {**SCAN_DEFAULTS, **lidar.get("scan", {})}
    return TimeResolved(motion, ScanTiming(**scan),
                        InsSampling(ins.get("rate"), ins.get("interpolation", "linear")))


def _component(dof, spec):
    index = DEGREES_OF_FREEDOM.index(dof)
    scale = math.radians(1.0) if dof in ANGULAR_DOFS else 1.0
    amplitudes = [0.0] * len(DEGREES_OF_FREEDOM)
    amplitudes[index] = spec["amplitude"] * scale
    phase = None if spec["phase"] == "random" else math.radians(spec["phase"])
    return MotionComponent(2 * math.pi / spec["period"], tuple(amplitudes),
                           (0.0,) * len(DEGREES_OF_FREEDOM), phase)


def random_phase_count(settings):
    """Components of the motion with a random phase (each a Monte Carlo input)."""
    return sum(spec["phase"] == "random" for spec in (settings.get("motion") or {}).values())


def beam_stamps(settings, n_beams):
    """Time stamps of the beams [s] (for the Gauss-Markov correlation of INS errors)."""
    scan = {**SCAN_DEFAULTS, **settings["lidar"].get("scan", {})}
    return ScanTiming(**scan).stamps(n_beams)


__all__ = ["validate_motion", "time_resolved", "np"]
