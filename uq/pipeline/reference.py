"""The scenario reference (``docs/scenario.md``), generated from the validator itself.

The validator of :mod:`uq.pipeline.scenario` is run on :data:`EXEMPLAR`, a scenario that
sets every optional key, with a checker that records each check it makes: the dotted
key, its type, its range or allowed values, and its value (the default, where the
exemplar leaves the default in place). Units and meanings come from :data:`MEANINGS`;
``tests/pipeline/test_reference.py`` fails when a checked key has no meaning, a meaning
names no checked key, or ``docs/scenario.md`` differs from what this module renders.

Regenerate with ``python -m uq.pipeline.reference > docs/scenario.md``.
"""
import copy
import math
from pathlib import Path

import numpy as np

from uq.constants import MAX_CONFIG_BYTES, MAX_CONFIG_DEPTH, MAX_CONFIG_NODES, MAX_MAGNITUDE
from uq.physics import modelinputs
from uq.physics.correction import CORRECTION_DESCRIPTIONS
from uq.pipeline import scenario as scenario_module
from uq.pipeline.probesection import KIND_PARAMETERS
from uq.pipeline.distributions import ERROR_DISTRIBUTIONS
from uq.pipeline.probesection import PROBE_ERROR_KEYS
from uq.pipeline.scenario import DEFAULTS, Checker

#: A scenario that sets every optional key (values are examples, not defaults).
EXEMPLAR_OPTIONAL = {
    "ins": {"heading": {"dist": "normal", "u": 0.1}, "pitch": {"dist": "normal", "u": 0.05},
            "roll": {"dist": "normal", "u": 0.05}, "sog": {"dist": "normal", "u": 0.1},
            "cog": {"dist": "normal", "u": 0.1}, "heave": {"dist": "normal", "u": 0.02},
            "rate": 10.0, "interpolation": "linear",
            "clock_offset": {"dist": "normal", "u": 0.02}},
    "lidar": {"errors": {"half_cone": {"dist": "normal", "u": 0.1},
                         "misalignment": {"dist": "normal", "u": 0.3},
                         "radial_velocity": {"dist": "normal", "u": 0.05},
                         "height": {"dist": "normal", "u": 0.2},
                         "gate_length": {"dist": "normal", "u": 1.0},
                         "pulse_fwhm": {"dist": "normal", "u": 1.0},
                         "wavelength": {"dist": "normal", "u": 0.001},
                         "beam_radius": {"dist": "normal", "u": 1.0}},
              "lever_arm": [0.0, 0.0, 2.0],
              "mount": {"tilt": 90.0},
              "scan": {},
              "probe": {"kind": "cw", "gate_length": 30.0, "pulse_fwhm": 22.5,
                        "wavelength": 1.565, "beam_radius": 28.0, "truncation": 0.02}},
    "motion": {**{dof: {"amplitude": 1.0, "period": 5.0, "phase": 0.0}
                  for dof in ("roll", "pitch", "yaw", "surge", "sway", "heave")},
               "spectrum": {"hs": 2.0, "tp": 7.0},
               "response": {"roll": {"factor": 2.0, "lag": 90.0}}},
    "sampling": {"chunk_size": 65536, "seed": 1},
    "turbulence": {"model": "mann", "intensity": 0.1, "length_scale": 33.6,
                   "anisotropy": 3.9},
    "record": {"duration": 600.0, "count": 20},
    "fit": {"priors": {"shear": {"dist": "uniform", "low": -0.5, "high": 1.0},
                       "reference_speed": {"dist": "normal", "mean": 9.0, "u": 2.0}},
            "columns": {"height": "height", "speed": "speed", "speed_u": "speed_u",
                        "height_u": "height_u"}},
}
#: Keys checked only in the alternative form of a section (digits instead of n).
EXEMPLAR_ALTERNATIVE = {"sampling": {"digits": 2, "stop_when_gum_valid": True},
                        "lidar": {"mount": {"tilt": 90.0}},
                        "ins": {"sog": {"dist": "normal", "u": 0.1, "correlation_time": 2.0}}}

#: Dotted key (``*`` for any name) -> (unit, meaning). Keys of error distributions
#: (``ins.heading`` ...) are described once, in the table of distributions.
MEANINGS = {
    "name": ("", "name of the scenario; names the output file results/<name>.nc"),
    "description": ("", "free text, kept in the results"),
    "wind.speed": ("m s-1", "horizontal wind speed at wind.reference_height (> 0 with a "
                   "turbulence section: the mean wind carries the frozen field)"),
    "wind.direction": ("deg", "meteorological direction the wind comes from, clockwise "
                       "from north"),
    "wind.vertical": ("m s-1", "vertical wind, positive upwards"),
    "wind.shear": ("1", "power-law shear exponent alpha: U(z) = U_ref (z / z_ref)^alpha"),
    "wind.reference_height": ("m", "height above sea level of wind.speed"),
    "ship.sog": ("m s-1", "speed over ground"),
    "ship.cog": ("deg", "course over ground, clockwise from north"),
    "ship.heading": ("deg", "heading of the bow, clockwise from north"),
    "ship.pitch": ("deg", "pitch, positive bow up"),
    "ship.roll": ("deg", "roll, positive starboard down"),
    "ship.heave": ("m s-1", "heave velocity, positive up"),
    "ins.correlation": ("", "scan: one INS reading per scan, shared by all beams; beam: an "
                        "independent reading per beam (point-wise correction)"),
    "lidar.height": ("m", "height of the lidar above sea level at the platform's static "
                     "attitude (ship.pitch, ship.roll): the height surveyed at its trim. The "
                     "static attitude does not move the lidar through lidar.lever_arm, the "
                     "motion does, from there (a static pitch p and a height h are the "
                     "level platform with its motion frozen at pitch p and a height h - "
                     "[(R(p) - 1) lever_arm]_up: tested)"),
    "lidar.ranges": ("m", "range-gate heights above a level lidar"),
    "lidar.half_cone": ("deg", "half-cone angle of the slanted beams, from vertical"),
    "lidar.azimuths": ("deg", "beam azimuths, clockwise from the reference beam: a list, "
                       "or {start, stop, step} (stop excluded; e.g. a conical scan of 50 "
                       "lines of sight: {start: 0, stop: 360, step: 7.2})"),
    "lidar.vertical_beam": ("", "a vertical beam besides the slanted ones"),
    "lidar.misalignment": ("deg", "angle from the bow to the reference beam, clockwise"),
    "lidar.probe.kind": ("", "range weighting of each radial velocity along its beam: "
                         "point (at the gate centre; the default), pulsed (the range "
                         "gate convolved with a Gaussian pulse), cw (a focused continuous wave: a Lorentzian "
                         "with truncated tails); cut at the lens; see uq/physics/probe.py. "
                         "The parameters of every kind may be given (kind can be swept)"),
    "lidar.probe.gate_length": ("m", "range-gate length of a pulsed lidar"),
    "lidar.probe.pulse_fwhm": ("m", "full width at half maximum of a pulsed lidar's pulse "
                               "in range (c tau / 2 for a pulse of duration tau)"),
    "lidar.probe.wavelength": ("um", "laser wavelength of a CW lidar"),
    "lidar.probe.beam_radius": ("mm", "1/e^2 intensity radius of a CW lidar's beam at the "
                                "lens; the Rayleigh length at the focus F (the gate's slant "
                                "distance) is lambda F^2 / (pi a^2)"),
    "lidar.probe.truncation": ("1", "a CW weighting's tails are cut where it falls below "
                               "this fraction of its peak (abs(s) <= sqrt(1/t - 1) z_R) for "
                               "the wind profile of a scan; part of that model (the "
                               "Lorentzian's variance is infinite), stated in the results' "
                               "probe attribute. Not of the turbulence paths: their CW "
                               "weighting is cut at the lens alone (there is no beam "
                               "behind it)"),
    "correction": ("", "motion correction; what each removes is stated below (Correction "
                   "models) and in the results' correction_description attribute"),
    "sampling.method": ("", "mc, lhs, sobol, or none (GUM and the paper's model only)"),
    "sampling.n": ("1", "Monte Carlo trials per scene (give n or digits)"),
    "sampling.digits": ("1", "adaptive sampling to this many significant digits "
                        "(JCGM 101 7.9)"),
    "sampling.seed": ("1", "seed of the random numbers; none draws a new one (recorded in "
                      "the results)"),
    "sampling.control_variate": ("", "use the GUM linearisation as a control variate"),
    "sampling.interval": ("", "coverage interval: probabilistically symmetric or shortest"),
    "sampling.stopping": ("", "stopping rule of adaptive sampling"),
    "sampling.chunk_size": ("1", "trials evaluated together (memory; never changes a "
                            "number)"),
    "sampling.stop_when_gum_valid": ("", "stop a scene once clause 8 validates its GUM "
                                     "(with digits)"),
    "outputs": ("", "quantities to report (wind_speed_motion_ti: the motion-induced "
                "turbulence-intensity increment, u of Vh from motion over Vh; needs motion; "
                "yaw_misalignment: wind_direction minus ship.heading, the rotor axis, in "
                "[-180, 180) deg; shear_exponent: the power-law exponent from the upper and "
                "lower beams of a tilted mount, w = 0 assumed; "
                "turbulence_intensity: the records' apparent TI against the true one, "
                "needs turbulence)"),
    "motion.<dof>.amplitude": ("deg or m", "amplitude of a harmonic motion of a degree of "
                               "freedom, added to the static attitude: roll, pitch, yaw in "
                               "deg; surge, sway, heave in m"),
    "motion.<dof>.period": ("s", "period of the harmonic (a degree of freedom may also "
                            "take a list of harmonics, each {amplitude, period, phase})"),
    "motion.<dof>.phase": ("deg", "phase at the start of the scan (0: at the static "
                           "attitude, moving positive), or random: uniform over the cycle, "
                           "per trial (default)"),
    "motion.spectrum.kind": ("", "wave spectrum: jonswap (Hasselmann et al. 1973, via "
                             "wavespectra)"),
    "motion.spectrum.hs": ("m", "significant wave height"),
    "motion.spectrum.tp": ("s", "peak period"),
    "motion.spectrum.gamma": ("1", "peak enhancement factor"),
    "motion.spectrum.components": ("1", "wave components (equal frequency bins), each with "
                                   "a random phase"),
    "motion.spectrum.band": ("Hz", "[lowest, highest] frequency (default [0.5, 4] / tp)"),
    "motion.response.<dof>.factor": ("deg m-1 or m m-1", "motion of a degree of freedom "
                                     "per metre of wave amplitude (a flat response; "
                                     "typical values below, Response factors)"),
    "motion.response.<dof>.lag": ("deg", "phase lag of that degree of freedom"),
    "motion.series.file": ("", "CSV of a measured motion record (relative to the "
                           "scenario file); each trial reads a random window of it"),
    "motion.series.time": ("s", "column of the sample times (equally spaced)"),
    "motion.series.columns.<dof>": ("deg or m", "column of a degree of freedom: roll, pitch, "
                                "yaw in deg; surge, sway, heave in m"),
    "motion.series.components": ("1", "Fourier harmonics of the record kept (those with "
                                 "the most motion)"),
    "turbulence.model": ("", "spectral model of the frozen turbulent field (Taylor): mann "
                         "(Mann 1994 uniform-shear tensor) or kaimal (IEC 61400-1 Kaimal "
                         "spectra with its exponential coherence); gives record mode"),
    "turbulence.intensity": ("1", "sigma_u / U of the point field at wind.reference_height "
                             "(required: the site's; from 1e-6, three orders below any "
                             "lidar's resolution, where the records' variances stay far "
                             "above float64's smallest numbers)"),
    "turbulence.length_scale": ("m", "Mann's L (default 0.8 Lambda_1) or Kaimal's L_u "
                                "(default 8.1 Lambda_1); Lambda_1 = 0.7 z below 60 m, 42 m "
                                "above (IEC 61400-1 Ed. 3, Annex B). The records' box has "
                                "cells of L / 8 (Kaimal: Lambda_1 / 8) over the record's "
                                "advected length and the scan's width and height (Mann: "
                                "plus 3 L each side): at most 33554432 cells, and for "
                                "Kaimal 1024 points across the wind where its records read "
                                "the field, checked at validation "
                                "(the message gives the smallest L that fits)"),
    "turbulence.anisotropy": ("1", "Mann's Gamma (IEC 61400-1 Ed. 3, Annex B: 3.9)"),
    "record.count": ("1", "Monte Carlo records per scene (each a turbulence box; not with "
                     "sampling.method none, the spectral path alone)"),
    "record.duration": ("s", "length of a record, the scans that lidar.scan times in it, "
                        "reduced to a mean and standard deviation (needs turbulence; "
                        "default 600 with turbulence). With Monte Carlo records the box "
                        "(see turbulence.length_scale) spans wind.speed x record.duration "
                        "along the wind, with the motion's reach (3 standard deviations) "
                        "around the probes: at most 33554432 cells, checked at validation "
                        "(the message gives the longest record at that wind speed)"),
    "lidar.lever_arm": ("m", "(bow, starboard, up) from the INS to the lidar"),
    "lidar.mount.tilt": ("deg", "boresight tilted from vertical towards the bow (0: the "
                         "upward lidar, as without mount; 90: a nacelle lidar looking "
                         "along the bow); for tilt > 0 lidar.azimuths are clock positions "
                         "about the boresight (0 up, 90 starboard, 180 down, 270 port: "
                         "clockwise looking along it), lidar.half_cone the opening from it "
                         "and lidar.ranges preview distances along it; 2 beams (90, 270) "
                         "assume w = 0; no vertical beam"),
    "lidar.scan.beam_duration": ("s", "dwell per line of sight; beams in the order of "
                                 "azimuths, then the vertical beam"),
    "lidar.scan.timestamp": ("", "a beam's time stamp: start, mid or end of its dwell"),
    "lidar.scan.dwell_average": ("", "radial velocity averaged over the dwell "
                                 "(composite Gauss-Legendre quadrature to 1e-9 of the "
                                 "motion's highest harmonic; at most 512 nodes per dwell)"),
    "ins.rate": ("Hz", "INS sampling rate (absent: a continuous INS)"),
    "ins.interpolation": ("", "reading between INS samples: nearest, or linear (the "
                          "default; attitude on the rotation group); needs ins.rate"),
    "ins.<error>.correlation_time": ("s", "Gauss-Markov correlation time of that INS "
                                     "error between the beams, timed by lidar.scan (0: "
                                     "independent per beam, .inf: one per scan); in any "
                                     "error of ins.heading ... ins.heave"),
    "fit.profile": ("", "wind-profile model of uq fit"),
    "fit.reference_height": ("m", "z_ref of the power law"),
    "fit.scatter": ("", "fit an extra scatter ln_sigma"),
    "fit.priors.<parameter>.dist": ("", "prior of a profile parameter (shear, "
                                    "reference_speed, roughness_length, friction_velocity, "
                                    "ln_sigma)"),
    "fit.priors.<parameter>.low": ("as the parameter", "lower bound (uniform, log_uniform)"),
    "fit.priors.<parameter>.high": ("as the parameter", "upper bound (uniform, "
                                    "log_uniform)"),
    "fit.priors.<parameter>.mean": ("as the parameter", "mean (normal)"),
    "fit.priors.<parameter>.u": ("as the parameter", "standard deviation (normal)"),
    "fit.walkers": ("1", "emcee walkers per ensemble"),
    "fit.ensembles": ("1", "independent ensembles (for R-hat)"),
    "fit.max_steps": ("1", "steps per ensemble before a fit is declared not converged"),
    "fit.seed": ("1", "seed of the chains"),
    "fit.columns.height": ("", "CSV column of the measurement heights [m]"),
    "fit.columns.speed": ("", "CSV column of the wind speeds [m s-1]"),
    "fit.columns.speed_u": ("", "CSV column of the speeds' standard uncertainties [m s-1] "
                            "(absent: the fit's scatter alone)"),
    "fit.columns.height_u": ("", "CSV column of the heights' standard uncertainties [m] "
                             "(absent: exact heights)"),
    "sweep": ("", "scenes to run: dotted keys mapped to a list of values, {start, stop, "
              "step} (stop excluded) or {same_as: another.swept.key}; the outer product "
              "(see Sweeps below)"),
}
#: Why the per-scan models leave the lever arm's velocity in (docs/scenario.md).
PER_SCAN_LEVER_ARM = (
    "The per-scan models (`yaw`, `tilt2d`, `full`) take one INS reading per scan (at the "
    "scan's mid time when the platform moves during the scan) and remove the velocity "
    "the INS reports: that of its own point. A lidar `lidar.lever_arm` r away from the "
    "INS moves at that velocity plus omega x r; the per-scan models do not remove "
    "omega x r (a lidar 2.5 m above the INS of a buoy rolling 5 deg at 7 s moves ~0.2 m/s "
    "faster or slower than the INS), `pointwise` does, at each beam's time stamp. "
    "Without `motion` the platform does not rotate and the two are the same.")
#: Typical response factors of a buoy (docs/scenario.md, "Response factors").
RESPONSE_FACTORS = (
    "`motion.response` moves each degree of freedom by a factor per metre of wave "
    "amplitude (one factor and lag for every wave component). For a buoy small against "
    "the wave length that follows the sea surface, linear (Airy) deep-water wave theory "
    "gives the factors: it heaves with the surface, **1 m/m**; it surges with the "
    "horizontal orbital motion, **1 m/m**, a quarter period from the heave (a lag of "
    "90 deg, its sign set by the waves' direction against the bow); "
    "and it tilts with the surface slope, k a for a wave of amplitude a and wave number "
    "k = omega^2 / g, i.e. **(2 pi / Tp)^2 / g rad/m**: 9.2 deg/m at Tp = 5 s, "
    "4.7 deg/m at 7 s, 2.3 deg/m at 10 s (pitch for waves from ahead, roll from abeam; "
    "Longuet-Higgins, Cartwright & Smith 1963, who measured directional wave spectra "
    "from exactly this slope-following of a pitch-roll buoy; Holthuijsen 2007, *Waves "
    "in Oceanic and Coastal Waters*, Ch. 7). A larger hull (a 3 m discus or a spar "
    "lidar buoy) filters the waves shorter than itself and responds less: take these as "
    "upper bounds, and a measured record (`motion.series`) where one exists. "
    "`floating_lidar_waves` uses roll 4, pitch 3 deg/m, heave 1, surge 0.5 m/m at Tp = 7 s.")
DISTRIBUTION_MEANINGS = {
    "normal": "N(mean, u^2)",
    "uniform": "U(mean - half_width, mean + half_width); u = half_width / sqrt(3)",
    "triangular": "symmetric triangle on mean +- half_width; u = half_width / sqrt(6)",
    "arcsine": "arcsine on mean +- amplitude (a sinusoid at a random phase); "
               "u = amplitude / sqrt(2)",
    "student_t": "scaled t with dof > 2 and standard deviation u",
    "constant": "a known offset: value + mean",
}


class RecordingChecker(Checker):
    """A :class:`~uq.pipeline.scenario.Checker` that records every check it makes."""

    def __init__(self, source):
        super().__init__(source)
        self.records, self._depth, self.overlay = {}, 0, {}
        self.required_keys = set()
        self.limits = {}

    def limit(self, key, text):
        texts = self.limits.setdefault(key, [])
        if text not in texts:
            texts.append(text)

    def required(self, mapping, prefix, names, needs):
        self.required_keys.update(f"{prefix}.{name}" for name in names)
        return super().required(mapping, prefix, names, needs)

    def _record(self, kind, key, value, **limits):
        if self._depth:
            return
        if "[" in key:                        # an element of a list: the list's row
            key, kind, value = key.split("[")[0], f"list of {kind}s", None
        if _is_set(self.overlay, key):         # an example value, not a default
            value = None
        self.records.setdefault(key, (kind, value, limits))

    def _nested(self, kind, method, value, key, *args, **kwargs):
        self._record(kind, key, value, **dict(zip(("low", "high"), args)), **kwargs)
        self._depth += 1
        try:
            return method(value, key, *args, **kwargs)
        finally:
            self._depth -= 1

    def number(self, value, key, *args, **kwargs):
        return self._nested("number", super().number, value, key, *args, **kwargs)

    def integer(self, value, key, *args, **kwargs):
        return self._nested("integer", super().integer, value, key, *args, **kwargs)

    def angle(self, value, key):
        return self._nested("angle", super().angle, value, key)

    def number_list(self, value, key, **limits):
        return self._nested("list of numbers", super().number_list, value, key, **limits)

    def boolean(self, value, key):
        return self._nested("boolean", super().boolean, value, key)

    def choice(self, value, key, allowed):
        self._record("choice", key, value, allowed=tuple(allowed))
        return super().choice(value, key, allowed)

    def text(self, value, key):
        return self._nested("text", super().text, value, key)

    def name(self, value):
        self._record("name", "name", value)
        return super().name(value)


def recorded_checks():
    """Dotted key -> (kind, value, limits) of every check the validator makes; the value
    is the default wherever the exemplar leaves the key unset, ``REQUIRED`` where the
    validator requires the key in its section; `limits` holds under ``"more"`` the limits
    the validator declares beyond type and range (:meth:`Checker.limit`)."""
    import tempfile
    with tempfile.TemporaryDirectory() as folder:
        record = Path(folder) / "record.csv"
        times = np.arange(32) * 0.5
        record.write_text("time,roll\n" + "".join(f"{t},{np.sin(t)}\n" for t in times))
        series = {"motion": {"series": {"file": str(record), "columns": {"roll": "roll"}}}}
        return _recorded(series)


def _recorded(series):
    checker = RecordingChecker("<reference>")
    for overlay in (_merge(copy.deepcopy(EXEMPLAR_OPTIONAL), series), EXEMPLAR_ALTERNATIVE):
        checker.overlay = overlay
        raw = _merge(copy.deepcopy(DEFAULTS), overlay)
        raw["outputs"] = list(scenario_module.ALL_OUTPUTS)
        scenario_module._validate(raw, checker.source, checker)
    required = checker.required_keys | {f"lidar.probe.{name}" for name in
                                        KIND_PARAMETERS["pulsed"] + KIND_PARAMETERS["cw"]}
    records = {key: (kind, REQUIRED if key in required else value, limits)
               for key, (kind, value, limits) in checker.records.items()}
    return {**records, MORE: checker.limits}


#: The key of :func:`recorded_checks` that holds the declared limits, row key -> texts.
MORE = "<limits>"


#: The default of a key that must be given when its section is (see :func:`render`).
REQUIRED = "required"


def _merge(base, overlay):
    """`base` with `overlay` merged in, mapping by mapping."""
    for key, value in overlay.items():
        if isinstance(value, dict) and isinstance(base.get(key), dict):
            _merge(base[key], value)
        else:
            base[key] = value
    return base


#: The scenario's unit names of the declaration's UDUNITS names (``degree`` -> ``deg``).
_SCENARIO_UNIT = {"degree": "deg"}


def error_meaning(key):
    """(unit, meaning) of the key of a declared model input's error distribution
    (:mod:`uq.physics.modelinputs`), or None."""
    for row in modelinputs.INPUTS:
        if row.holds_distribution and row.key == key:
            draw = {"reading": "one reading per scan, or per beam with ins.correlation: beam",
                    "scan": "one draw per scan", "beam_gate": "one draw per beam and gate"}
            needs = " (needs the parameter in lidar.probe)" if \
                key.rpartition(".")[2] in PROBE_ERROR_KEYS else ""
            return (_SCENARIO_UNIT.get(row.unit, row.unit),
                    f"{row.meaning}; {draw[row.shape]}{needs} (a distribution)")
    return None


def meaning(key):
    """(unit, meaning) of a dotted key, or None."""
    if key in MEANINGS:
        return MEANINGS[key]
    declared = error_meaning(key)
    if declared:
        return declared
    parts = key.split(".")
    for i in range(len(parts) - 1, 0, -1):
        for pattern in (".".join(parts[:i] + ["*"] + parts[i + 1:]), ".".join(parts[:i] + ["*"])):
            if pattern in MEANINGS:
                return MEANINGS[pattern]
    return None


def documented_keys(records):
    """The rows of the reference: error distributions collapsed to their key."""
    records = dict(records)
    more = records.pop(MORE, {})
    errors = {key.rpartition(".")[0] for key in records if key.endswith(".dist")
              and not key.startswith("fit.")}
    rows = {}
    for key, (kind, value, limits) in records.items():
        parent = key.rpartition(".")[0]
        if parent in errors and not key.endswith(".correlation_time"):
            rows.setdefault(parent, ("distribution", None, {}))
            continue
        if key.startswith("ins.") and key.endswith(".correlation_time"):
            key = "ins.<error>.correlation_time"
        if key.startswith("fit.priors."):     # one row per prior key, any parameter
            key, value = "fit.priors.<parameter>." + key.rpartition(".")[2], None
        if key.startswith("motion.series.columns."):
            key = "motion.series.columns.<dof>"
        if key.startswith("motion.response."):        # one row per key, any dof
            key = "motion.response.<dof>." + key.rpartition(".")[2]
        elif key.startswith("motion.") and not key.startswith(("motion.spectrum.",
                                                                "motion.series.")):
            key = "motion.<dof>." + key.rpartition(".")[2]
        if key == "outputs":
            kind = "list of choices"
        if kind.startswith("list of") and value != REQUIRED:    # the whole list's default
            value = _lookup(DEFAULTS, key) if _is_set(DEFAULTS, key) else None
        rows.setdefault(key, (kind, value, limits))
    rows["sweep"] = ("mapping", None, {})
    more = {**more, "sweep": [scenario_module.sweep_limits()]}
    unknown = set(more) - set(rows)
    if unknown:
        raise KeyError(f"limits declared for keys with no row: {sorted(unknown)}")
    return {key: (kind, value, {**limits, "more": tuple(more.get(key, ()))})
            for key, (kind, value, limits) in rows.items()}


def _is_set(overlay, key):
    try:
        _lookup(overlay, key)
        return True
    except (KeyError, TypeError):
        return False


def _allowed(kind, limits):
    """The allowed column: the type's range or choices, then the declared limits."""
    return "; ".join([_range_or_choices(kind, limits), *limits.get("more", ())])


def _range_or_choices(kind, limits):
    if kind in ("choice", "list of choices"):
        return ", ".join(str(a) for a in limits["allowed"])
    if kind in ("angle", "list of angles"):
        return "[-360, 360], wrapped into [0, 360)"
    if kind == "distribution":
        return "a distribution (below)"
    if kind == "name":
        return "letters, digits, '_', '.', '-'"
    if kind == "mapping":
        return "dotted keys of single values"
    low, high = limits.get("low"), limits.get("high")
    if low is None and high is None:
        return "any finite" if kind != "text" and kind != "boolean" else \
            ("true, false" if kind == "boolean" else "text")
    left = "(" if limits.get("low_open") or low is None else "["
    right = ")" if limits.get("high_open") or high is None else "]"
    return f"{left}{_number(low, '-inf')}, {_number(high, 'inf')}{right}"


def _number(value, infinite):
    return infinite if value is None else (f"{value:g}" if isinstance(value, float) and
                                           not math.isinf(value) else str(value))


def _default(key, kind, value):
    if kind == "distribution":
        return "none (no error)"
    if value == REQUIRED:
        return "**required**"
    if key == "sweep":
        return "none (one scene)"
    if key == "sampling.seed":
        return "none (a new seed, recorded)"
    if value is None or isinstance(value, dict):
        return "-"
    if isinstance(value, list):
        value = ", ".join(map(str, value))
    return f"`{value}`" if value != "" else "empty"


def _lookup(mapping, key):
    node = mapping
    for part in key.split("."):
        node = node[part]
    return node


def render():
    """The Markdown text of ``docs/scenario.md``."""
    rows = documented_keys(recorded_checks())
    lines = ["# Scenario reference", "",
             "Generated from the validator (`python -m uq.pipeline.reference > "
             "docs/scenario.md`); `tests/pipeline/test_reference.py` fails when the two "
             "drift apart. Every top-level section is optional, and so is every key "
             "with a default; a key whose default reads **required** must be given "
             "when its section is (for `lidar.probe`, when its `kind` uses it). Unknown "
             "keys are an error. Angles are in degrees, clockwise; wind direction is "
             "where the wind comes from.", "",
             f"Every number is finite, of magnitude at most 10^{round(math.log10(MAX_MAGNITUDE))} "
             "(`inf` in the allowed column stands for that bound). A scenario file is UTF-8 "
             f"YAML of at most {MAX_CONFIG_BYTES / 2**20:g} MiB, nested at most {MAX_CONFIG_DEPTH} "
             f"levels deep, of at most {MAX_CONFIG_NODES:,} values once its aliases are "
             "expanded. `--set KEY=null` or `--unset KEY` removes an optional key from "
             "the command line.", "",
             "| key | type | unit | default | allowed | meaning |",
             "|---|---|---|---|---|---|"]
    for key in sorted(rows, key=_order):
        kind, value, limits = rows[key]
        unit, text = meaning(key) or ("?", "?")
        lines.append(f"| `{key}` | {kind} | {unit or '-'} | {_default(key, kind, value)} | "
                     f"{_allowed(kind, limits)} | {text} |")
    lines += ["", "## Distributions of errors", "",
              "Every error is a mapping with `dist`, its parameters and an optional `mean` "
              "(a bias, default 0), in the unit of the quantity it belongs to.", "",
              "| dist | parameters | distribution |", "|---|---|---|"]
    lines += [f"| `{name}` | {', '.join(parameters)} | {DISTRIBUTION_MEANINGS[name]} |"
              for name, parameters in ERROR_DISTRIBUTIONS.items()]
    lines += ["", "## Sweeps", "",
              "`sweep` maps dotted keys to a list of values, to `{start, stop, step}` (stop "
              "excluded) or to `{same_as: another.swept.key}`; the scenes are the outer "
              "product. Only single-valued keys can be swept."]
    lines += ["", "## Correction models", "",
              "What each `correction` removes from the measured radial velocities (the "
              "same text is the results' `correction_description` attribute):", ""]
    lines += [f"* `{model}`: {text}." for model, text in CORRECTION_DESCRIPTIONS.items()]
    lines += ["", PER_SCAN_LEVER_ARM]
    lines += ["", "## Response factors", "", RESPONSE_FACTORS, ""]
    return "\n".join(lines)


def _order(key):
    sections = list(DEFAULTS) + list(scenario_module.OPTIONAL_SECTIONS)
    return (sections.index(key.split(".")[0]) if key.split(".")[0] in sections else 99, key)


if __name__ == "__main__":
    print(render(), end="")
