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
      # or a list of harmonics for one degree of freedom, each with its own phase:
      # pitch: [{amplitude: 3.0, period: 25.0}, {amplitude: 1.0, period: 8.0}]
      spectrum: {kind: jonswap, hs: 2.0, tp: 8.0, gamma: 3.3, components: 32,
                 band: [0.0625, 0.5]}                       # m, s, 1, 1, Hz
      response:                  # per metre of wave amplitude: deg/m or m/m; lag in deg
        roll: {factor: 2.0, lag: 90}
        heave: {factor: 1.0}
      series:                    # a measured record; each trial reads a random window
        file: buoy.csv           # CSV, relative to the scenario file
        time: time               # column [s], equally spaced
        columns: {roll: roll_deg, pitch: pitch_deg, heave: heave_m}   # dof -> column
        components: 128          # Fourier harmonics kept
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
import functools
import math
from pathlib import Path

import numpy as np

from uq.physics.ins import INTERPOLATIONS, InsSampling
from uq.physics.motion import DEGREES_OF_FREEDOM, Motion, MotionComponent
from uq.physics.scene import TimeResolved
from uq.errors import ScenarioError
from uq.physics.series import WindowStart, series_components
from uq.physics.timing import (TIMESTAMPS, DwellTooLong, ScanTiming, dwell_frequency,
                               dwell_rule)
from uq.physics.waves import band_energy, jonswap_components
from uq.constants import (MAX_DWELL_TOTAL_NODES, MAX_SERIES_BYTES,
                          MAX_SERIES_ROWS, MAX_WAVE_COMPONENTS, MIN_MOTION_PERIOD)

HARMONIC_KEYS = ("amplitude", "period", "phase")
SPECTRUM_KEYS = ("kind", "hs", "tp", "gamma", "components", "band")
SPECTRUM_KINDS = ("jonswap",)
RESPONSE_KEYS = ("factor", "lag")
SERIES_KEYS = ("file", "time", "columns", "components")
#: What a motion record is, in messages about the file.
SERIES_KIND = "a CSV motion record"
#: Fewest samples of a motion record [1]: a Fourier series of fewer says little.
MIN_SERIES_SAMPLES = 16
#: Largest relative spread of a record's sampling intervals [1]: the Fourier series
#: assumes equal spacing; clock jitter of 1 % of the interval is tolerated.
SERIES_SPACING_TOLERANCE = 0.01
#: Widest sampling interval of a motion record [s]: a record must resolve the
#: wave-driven motion of a platform (periods down to ~2 s: 1 s is its Nyquist interval).
#: A wider one is most likely a time column in milliseconds (100 at 10 Hz).
MAX_SERIES_STEP = 1.0
#: Longest period [s] of the strongest roll, pitch or heave in a record that passes
#: without a warning: wave-driven motion has periods of 2-30 s (swell up to ~25 s);
#: longer is a drift, or a time column in milliseconds.
MAX_WAVE_PERIOD = 30.0
WAVE_DOFS = ("roll", "pitch", "heave")
#: Default band of a spectrum, in multiples of its peak frequency 1/tp [1]: the JONSWAP
#: (gamma 3.3) energy outside [0.5, 4] fp is below 1e-3 of the total (the f^-5 tail).
SPECTRUM_BAND = (0.5, 4.0)
SCAN_KEYS = ("beam_duration", "timestamp", "dwell_average")
SCAN_DEFAULTS = {"beam_duration": 1.0, "timestamp": "mid", "dwell_average": False}
ANGULAR_DOFS = ("roll", "pitch", "yaw")
#: Largest attitude the motion of a rotation may reach [deg]: the sum of the amplitudes
#: of every component of roll, pitch or yaw (harmonics, a wave spectrum's components, a
#: record's Fourier components), which their phases can line up to. Beyond it the
#: platform capsizes in the model's Euler angles.
MAX_ANGULAR_AMPLITUDE_DEG = 45.0
#: Largest static tilt plus the motion's reach [deg] (the static limit, ``ship.pitch``
#: and ``ship.roll``): at 90 deg the Euler angles of the marine convention are singular.
MAX_ATTITUDE_DEG = 89.0
#: Largest reach of a translation (surge, sway, heave) [m]: the sum of its components'
#: amplitudes. A platform's wave-driven heave is at most half the largest wave heights
#: recorded (~30 m) and its slow drift tens of metres on its moorings; 1000 m is beyond
#: any, and keeps every velocity the model forms (w A) far from overflow.
MAX_TRANSLATION_AMPLITUDE_M = 1000.0


def validate_motion(check, value):
    """The validated ``motion`` section (degrees and seconds, as in the file)."""
    check.mapping(value, "motion")
    check.keys(value, "motion", DEGREES_OF_FREEDOM + ("spectrum", "response", "series"))
    out = {}
    for dof in DEGREES_OF_FREEDOM:
        if dof in value:
            out[dof] = _harmonics(check, value[dof], f"motion.{dof}", dof in ANGULAR_DOFS)
    if ("spectrum" in value) != ("response" in value):
        check.fail("motion.spectrum" if "response" in value else "motion.response",
                   "a wave spectrum and the platform's response go together; allowed: "
                   "both motion.spectrum and motion.response, or neither")
    if "spectrum" in value:
        out["spectrum"] = _spectrum(check, value["spectrum"])
        out["response"] = validate_response(check, value["response"])
    if "series" in value:
        out["series"] = _series(check, value["series"])
    return out


def _series(check, value):
    key = "motion.series"
    check.mapping(value, key)
    check.keys(value, key, SERIES_KEYS)
    check.required(value, key, ("file", "columns"),
                   "a record needs its file and the columns of its degrees of freedom")
    path = check.text(value["file"], f"{key}.file")
    check.limit(f"{key}.file", f"a CSV of at most {MAX_SERIES_ROWS:,} rows and "
                f"{MAX_SERIES_BYTES >> 20} MiB; at least {MIN_SERIES_SAMPLES} samples, "
                f"increasing and equally spaced (within {100 * SERIES_SPACING_TOLERANCE:g} %), "
                f"at most {MAX_SERIES_STEP:g} s apart, lasting at least one scan")
    columns = value["columns"]
    check.mapping(columns, f"{key}.columns")
    check.keys(columns, f"{key}.columns", DEGREES_OF_FREEDOM)
    if not columns:
        check.fail(f"{key}.columns", "empty; allowed: the column of at least one degree of "
                   f"freedom ({', '.join(DEGREES_OF_FREEDOM)})")
    out = {"file": str(_beside(check.source, path)),
           "time": check.text(value.get("time", "time"), f"{key}.time"),
           "columns": {dof: check.text(c, f"{key}.columns.{dof}") for dof, c in
                       columns.items()},
           "components": check.integer(value.get("components", 128), f"{key}.components",
                                       low=1, high=MAX_WAVE_COMPONENTS)}
    read_series(out["file"], out["time"], tuple(out["columns"].items()), check.source)
    return out


def _beside(source, path):
    """`path` relative to the folder of the scenario file `source` (or as given)."""
    from pathlib import Path
    path = Path(path)
    if path.is_absolute() or source.startswith("<"):
        return path
    return Path(source).resolve().parent / path


def read_series(file, time, columns, source="<mapping>"):
    """(times [s], {dof: values [rad or m]}) of a motion record; DataFileError naming the
    file and the column for anything unreadable. Read once per file version."""
    try:
        version = Path(file).stat().st_mtime_ns
    except OSError:
        version = None
    return _read_series(file, version, time, columns)


@functools.lru_cache(maxsize=8)
def _read_series(file, version, time, columns):
    import pandas as pd
    from uq.errors import DataFileError
    from uq.pipeline.inputfile import read_csv
    table = read_csv(Path(file), MAX_SERIES_BYTES, MAX_SERIES_ROWS, SERIES_KIND,
                     DataFileError, "motion.series.file")
    wanted = [time] + [c for _, c in columns]
    missing = [c for c in wanted if c not in table.columns]
    if missing:                  # named by the key that asked for it: time or columns
        key = "motion.series.time" if missing[0] == time else "motion.series.columns"
        raise DataFileError(str(file), key, f"no column "
                            f"{', '.join(map(repr, missing))}; allowed: "
                            f"{', '.join(map(str, table.columns[:12]))}")
    data = {}
    for name in wanted:
        values = pd.to_numeric(table[name], errors="coerce").to_numpy(dtype=float)
        if not np.all(np.isfinite(values)):
            row = int(np.flatnonzero(~np.isfinite(values))[0])
            raise DataFileError(str(file), name, f"row {row + 2} is not a finite number; "
                                "allowed: a complete record of numbers")
        data[name] = values
    times = data[time]
    steps = np.diff(times)
    if len(times) < MIN_SERIES_SAMPLES or np.any(steps <= 0) or \
            np.ptp(steps) > SERIES_SPACING_TOLERANCE * np.mean(steps):
        raise DataFileError(str(file), time, f"{len(times)} samples; allowed: at least "
                            f"{MIN_SERIES_SAMPLES}, increasing and equally spaced (within "
                            f"{100 * SERIES_SPACING_TOLERANCE:g} %)")
    step = float(np.mean(steps))
    if step > MAX_SERIES_STEP:
        raise DataFileError(str(file), time, f"samples {step:g} apart; allowed: the time in "
                            f"seconds, samples at most {MAX_SERIES_STEP:g} s apart (a motion "
                            "record resolves wave motion; is the time in milliseconds?)")
    _warn_slow_motion(file, data, columns, len(times) * step)
    values = {dof: np.radians(data[c]) if dof in ANGULAR_DOFS else data[c]
              for dof, c in columns}
    return times, values


def _warn_slow_motion(file, data, columns, length):
    """Warn where the strongest roll, pitch or heave of a record is slower than wave
    motion (:data:`MAX_WAVE_PERIOD`): a time column in milliseconds, or a drift."""
    import logging
    for dof, column in columns:
        if dof not in WAVE_DOFS:
            continue
        power = np.abs(np.fft.rfft(data[column] - np.mean(data[column]))[1:])
        if not power.size or not np.any(power > 0):
            continue
        period = length / (int(np.argmax(power)) + 1)
        if period > MAX_WAVE_PERIOD:
            logging.getLogger(__name__).warning(
                "%s: column %s (%s): its strongest motion has a period of %.4g s; expected "
                "wave motion, periods of 2-%g s (is the time in milliseconds?)", file, column,
                dof, period, MAX_WAVE_PERIOD)


def _spectrum(check, value):
    key = "motion.spectrum"
    check.mapping(value, key)
    check.keys(value, key, SPECTRUM_KEYS)
    check.required(value, key, ("hs", "tp"), "a spectrum needs hs [m] and tp [s]")
    tp = _period(check, value["tp"], f"{key}.tp")
    band = value.get("band", [SPECTRUM_BAND[0] / tp, SPECTRUM_BAND[1] / tp])
    if "band" not in value:                  # the default band: a problem is tp's
        if not all(0.0 < f <= 1.0 / MIN_MOTION_PERIOD for f in band):
            check.fail(f"{key}.tp", f"{tp:g} s gives the default band {SPECTRUM_BAND[0]:g}/tp "
                       f"to {SPECTRUM_BAND[1]:g}/tp = [{band[0]:g}, {band[1]:g}] Hz, beyond "
                       f"{1.0 / MIN_MOTION_PERIOD:g} Hz (motion periods of at least "
                       f"{MIN_MOTION_PERIOD:g} s); allowed: a peak period in seconds, or an "
                       "explicit band")
    band = check.number_list(band, f"{key}.band", low=0.0, low_open=True,
                             high=1.0 / MIN_MOTION_PERIOD)
    if len(band) != 2 or not band[0] < band[1]:
        check.fail(f"{key}.band", "allowed: [lowest, highest] frequency in Hz, lowest first")
    out = {"kind": check.choice(value.get("kind", "jonswap"), f"{key}.kind", SPECTRUM_KINDS),
           "hs": check.number(value["hs"], f"{key}.hs", low=0.0),
           "tp": tp,
           "gamma": check.number(value.get("gamma", 3.3), f"{key}.gamma", low=1.0, high=10.0),
           "components": check.integer(value.get("components", 32), f"{key}.components",
                                       low=1, high=MAX_WAVE_COMPONENTS),
           "band": band}
    energy = band_energy(tp, out["gamma"], out["components"], tuple(band)) if out["hs"] else 1
    if not 0 < energy < math.inf:
        check.fail(f"{key}.band", f"[{band[0]:g}, {band[1]:g}] Hz holds none of the energy "
                   f"of a spectrum peaked at {1 / tp:g} Hz (it underflows); allowed: a band "
                   f"around the peak, e.g. the default [{SPECTRUM_BAND[0] / tp:g}, "
                   f"{SPECTRUM_BAND[1] / tp:g}] Hz")
    return out


def validate_response(check, value, prefix="motion.response"):
    """A platform's response to the waves (``motion.response``, or `prefix` in another
    configuration): per degree of freedom its ``factor`` per metre of wave amplitude
    [deg m-1 or m m-1] and its phase ``lag`` [deg]."""
    check.mapping(value, prefix)
    check.keys(value, prefix, DEGREES_OF_FREEDOM)
    out = {}
    for dof, spec in value.items():
        key = f"{prefix}.{dof}"
        check.mapping(spec, key)
        check.keys(spec, key, RESPONSE_KEYS)
        check.required(spec, key, ("factor",), "allowed: the amplitude per metre of wave "
                       "amplitude (deg/m or m/m)")
        out[dof] = {"factor": check.number(spec["factor"], f"{key}.factor", low=0.0),
                    "lag": check.number(spec.get("lag", 0.0), f"{key}.lag", low=-360.0,
                                        high=360.0)}
    return out


def _harmonics(check, value, key, angular):
    """One harmonic ``{amplitude, period, phase}`` or a list of them for one degree of
    freedom (e.g. a floater's slow pitch and its wave-frequency pitch), each its own
    component with its own phase."""
    check.limit("motion.<dof>.amplitude", f"a list of 1 to {MAX_WAVE_COMPONENTS} harmonics "
                "per degree of freedom")
    if not isinstance(value, list):
        return _harmonic(check, value, key, angular)
    if not value or len(value) > MAX_WAVE_COMPONENTS:
        check.fail(key, f"a list of {len(value)} harmonics; allowed: 1 to "
                   f"{MAX_WAVE_COMPONENTS} mappings of amplitude, period and phase")
    return [_harmonic(check, item, f"{key}[{i}]", angular) for i, item in enumerate(value)]


def _listed(spec):
    """The harmonics of one degree of freedom's validated settings, as a list."""
    return spec if isinstance(spec, list) else [spec]


def _harmonic(check, value, key, angular):
    check.mapping(value, key)
    check.keys(value, key, HARMONIC_KEYS)
    check.required(value, key, ("amplitude", "period"),
                   "a harmonic needs amplitude and period (phase defaults to random)")
    high = MAX_ANGULAR_AMPLITUDE_DEG if angular else None
    phase = value.get("phase", "random")
    if isinstance(phase, str) and phase != "random":
        check.fail(f"{key}.phase", f"{phase!r} is not allowed; allowed: a number of degrees "
                   "in [-360, 360], or random")
    return {"amplitude": check.number(value["amplitude"], f"{key}.amplitude", low=0.0,
                                      high=high),
            "period": _period(check, value["period"], f"{key}.period"),
            "phase": "random" if phase == "random" else check.number(
                phase, f"{key}.phase", low=-360.0, high=360.0)}


def _period(check, value, key):
    """A motion period [s]: at least :data:`~uq.constants.MIN_MOTION_PERIOD`."""
    if isinstance(value, (int, float)) and not isinstance(value, bool) and \
            0 < value < MIN_MOTION_PERIOD:
        check.fail(key, f"{value:g} s is shorter than any platform motion; allowed: at "
                   f"least {MIN_MOTION_PERIOD:g} s (faster is vibration, which no INS "
                   "resolves)")
    return check.number(value, key, low=MIN_MOTION_PERIOD)


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


def check_motion_reach(check, settings):
    """Refuse motion that can reach more than the model takes, degree of freedom by
    degree of freedom: the sum of the amplitudes of all its components (harmonics, a wave
    spectrum's components through their response factor, a record's Fourier
    components), which their phases can line up to, against
    :data:`MAX_ANGULAR_AMPLITUDE_DEG` (rotations; :data:`MAX_ATTITUDE_DEG` with the
    static ``ship.pitch`` or ``ship.roll``) or :data:`MAX_TRANSLATION_AMPLITUDE_M`.
    Checked once here, before any work: 8 pitch harmonics of 45 deg each passed the
    bound of one harmonic, and a spectrum of hs 1e6 m overflowed at the run's start."""
    reach = (f"the sum of a degree of freedom's amplitudes (its harmonics, a spectrum's "
             f"components, a record's) at most {MAX_ANGULAR_AMPLITUDE_DEG:g} deg per rotation "
             f"({MAX_ATTITUDE_DEG:g} with ship.pitch or ship.roll), "
             f"{MAX_TRANSLATION_AMPLITUDE_M:g} m per translation")
    for key in ("motion.<dof>.amplitude", "motion.response.<dof>.factor",
                "motion.series.columns.<dof>"):
        check.limit(key, reach)
    motion = settings.get("motion") or {}
    if not motion:
        return
    sources = _reach_by_source(motion)
    for index, dof in enumerate(DEGREES_OF_FREEDOM):
        parts = {key: reach[index] for key, reach in sources.items() if reach[index]}
        total = sum(parts.values())
        angular = dof in ANGULAR_DOFS
        unit = "deg" if angular else "m"
        static = abs(settings["ship"][dof]) if dof in ("pitch", "roll") else 0.0
        limit = MAX_ANGULAR_AMPLITUDE_DEG if angular else MAX_TRANSLATION_AMPLITUDE_M
        exceeded = not total <= limit                          # (NaN, inf: exceeded)
        if not exceeded and not (angular and static + total > MAX_ATTITUDE_DEG):
            continue
        key = max(parts, key=lambda k: parts[k] if math.isfinite(parts[k]) else math.inf)
        said = "; ".join(f"{_source(motion, k, dof)}: {v:.4g} {unit}" for k, v in
                         parts.items())
        reach = (f"the {dof} motion can reach {total:.4g} {unit}, the sum of its components' "
                 f"amplitudes, which their phases can line up ({said})")
        if exceeded:
            check.fail(key, f"{reach}; allowed: at most {limit:g} {unit} of {dof} motion in "
                       "all")
        check.fail(key, f"{reach}, on top of ship.{dof} {settings['ship'][dof]:g} deg; "
                   f"allowed: at most {MAX_ATTITUDE_DEG:g} deg of {dof} in all (the Euler "
                   "angles are singular at 90)")


def _source(motion, key, dof):
    """Where the motion of `dof` that `key` names comes from, in words."""
    if key.startswith("motion.response."):
        factor = motion["response"][dof]["factor"]
        return (f"motion.response.{dof}.factor {factor:g} per m of the waves of "
                f"motion.spectrum.hs {motion['spectrum']['hs']:g} m")
    if key.startswith("motion.series."):
        return f"the record of {key}"
    count = len(_listed(motion[dof]))
    return f"{count} harmonic{'s' if count > 1 else ''} of {key}"


def _reach_by_source(motion):
    """Scenario key -> the sum of the amplitudes [deg or m] its components give each
    degree of freedom (in the order of DEGREES_OF_FREEDOM)."""
    sources = {}
    for dof in DEGREES_OF_FREEDOM:
        if dof in motion:
            reach = [0.0] * len(DEGREES_OF_FREEDOM)
            reach[DEGREES_OF_FREEDOM.index(dof)] = sum(one["amplitude"]
                                                       for one in _listed(motion[dof]))
            sources[f"motion.{dof}"] = reach
    with np.errstate(all="ignore"):          # an overflow is an infinite reach, refused
        for dof, reach in _summed(_wave_components(motion)).items():
            sources[f"motion.response.{dof}.factor"] = reach
        for dof, reach in _summed(series_motion(motion)[0]).items():
            sources[f"motion.series.columns.{dof}"] = reach
    return sources


def _summed(components):
    """dof -> the sum of |amplitude| of `components` [deg or m] in that degree of freedom
    alone (in the order of DEGREES_OF_FREEDOM), for each one they move (the components
    of a spectrum or a record move several)."""
    if not components:
        return {}
    totals = np.sum(np.abs(np.array([c.amplitudes for c in components], dtype=float)), axis=0)
    out = {}
    for index, (dof, total) in enumerate(zip(DEGREES_OF_FREEDOM, totals)):
        if total:
            reach = [0.0] * len(DEGREES_OF_FREEDOM)
            reach[index] = float(np.degrees(total) if dof in ANGULAR_DOFS else total)
            out[dof] = reach
    return out


def check_record(settings, n_beams):
    """Refuse a motion record shorter than one scan (``n_beams`` beams of
    ``lidar.scan.beam_duration``): its Fourier series would repeat it within the scan."""
    from uq.errors import DataFileError
    series = (settings.get("motion") or {}).get("series")
    if not series:
        return
    times, _ = read_series(series["file"], series["time"], tuple(series["columns"].items()))
    length = (times[-1] - times[0]) * len(times) / (len(times) - 1)
    duration = {**SCAN_DEFAULTS, **settings["lidar"].get("scan", {})}["beam_duration"]
    if length < n_beams * duration * (1 - SERIES_SPACING_TOLERANCE):   # (its clock jitter)
        raise DataFileError(series["file"], series["time"], f"the record lasts {length:g} s, "
                            f"shorter than one scan ({n_beams} beams of {duration:g} s): it "
                            "would repeat within the scan; allowed: a record at least as "
                            "long as a scan, the time in seconds")


def check_dwell(check, settings):
    """Refuse a dwell average whose quadrature would need more nodes than
    :data:`~uq.constants.MAX_DWELL_TOTAL_NODES` (:func:`uq.physics.timing.dwell_rule`),
    before anything is allocated: a dwell of more cycles of the motion than a lidar has."""
    check.limit("lidar.scan.beam_duration", f"with dwell_average, at most "
                f"{MAX_DWELL_TOTAL_NODES} quadrature nodes per dwell (a dwell of fewer cycles "
                "of the motion)")
    scan = settings["lidar"].get("scan") or {}
    if not scan.get("dwell_average") or not is_time_resolved(settings):
        return
    frequency = dwell_frequency(time_resolved(settings).motion.components)
    try:
        dwell_rule(frequency * scan["beam_duration"])
    except DwellTooLong as error:
        check.fail("lidar.scan.beam_duration", f"{scan['beam_duration']:g} s averaged over "
                   f"the motion (harmonics of the integrand up to "
                   f"{frequency / (2 * math.pi):.3g} Hz) needs {error.nodes:.3g} quadrature "
                   f"nodes per dwell; allowed: at most {MAX_DWELL_TOTAL_NODES} (a "
                   f"beam_duration up to {error.longest_span / frequency:.3g} s), or "
                   "lidar.scan.dwell_average: false")


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
    motion_settings = settings.get("motion") or {}
    components = tuple(_component(dof, one) for dof, spec in motion_settings.items()
                       if dof in DEGREES_OF_FREEDOM for one in _listed(spec))
    components += _wave_components(motion_settings)
    record = series_motion(motion_settings)[0]
    motion = Motion(components + record, tuple(lidar.get("lever_arm", (0.0, 0.0, 0.0))),
                    window=len(record))
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


def _wave_components(motion_settings):
    if "spectrum" not in motion_settings:
        return ()
    spectrum = motion_settings["spectrum"]
    response = {dof: (spec["factor"], math.radians(spec["lag"]))
                for dof, spec in motion_settings["response"].items()}
    return jonswap_components(spectrum["hs"], spectrum["tp"], spectrum["gamma"],
                              spectrum["components"], tuple(spectrum["band"]), response)


def series_motion(motion_settings):
    """(components with random phases, WindowStart or None) of a motion record."""
    if "series" not in motion_settings:
        return (), None
    spec = motion_settings["series"]
    times, values = read_series(spec["file"], spec["time"], tuple(spec["columns"].items()))
    components, _ = series_components(times, values, spec["components"])
    components = tuple(MotionComponent(c.angular_frequency, c.amplitudes, c.lags, None)
                       for c in components)
    length = (times[-1] - times[0]) * len(times) / (len(times) - 1)
    return components, WindowStart([c.angular_frequency for c in components], length)


def random_phase_count(settings):
    """Components of the motion with a random phase (each a Monte Carlo input): the
    harmonics with ``phase: random`` and every component of a wave spectrum."""
    motion = settings.get("motion") or {}
    harmonics = sum(one["phase"] == "random" for dof, spec in motion.items()
                    if dof in DEGREES_OF_FREEDOM for one in _listed(spec))
    return harmonics + (motion["spectrum"]["components"] if "spectrum" in motion else 0)


#: Scenario keys whose value is a file the run reads (relative to the scenario's folder).
FILE_KEYS = ("motion.series.file",)


def input_files(scenario):
    """The files a scenario reads, as ``(dotted key, path)`` in a fixed order: the motion
    record of the settings and every swept value of :data:`FILE_KEYS` (so that a
    checkpoint can cover their content, :mod:`uq.pipeline.checkpoint`)."""
    found = []
    series = (scenario.settings.get("motion") or {}).get("series")
    if series:
        found.append((FILE_KEYS[0], str(series["file"])))
    for key, values in scenario.sweep:
        if key in FILE_KEYS:
            found += [(key, str(_beside(scenario.source, value))) for value in values]
    return list(dict.fromkeys(found))


def beam_stamps(settings, n_beams):
    """Time stamps of the beams [s] (for the Gauss-Markov correlation of INS errors)."""
    scan = {**SCAN_DEFAULTS, **settings["lidar"].get("scan", {})}
    return ScanTiming(**scan).stamps(n_beams)


