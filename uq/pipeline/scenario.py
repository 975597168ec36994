"""Scenario files: strict validation into frozen configuration objects.

A scenario is YAML (or a mapping) with the top-level keys of ``docs/scenario.md``: ``name``,
``description``, ``wind``, ``ship``, ``ins``, ``lidar``, ``correction``, ``sampling``,
``sweep``, ``outputs``, and the optional ``fit`` (:mod:`uq.pipeline.fitconfig`). Every key is optional and defaults to :data:`DEFAULTS`. Unknown
keys, wrong types and out-of-range values raise :class:`uq.errors.ScenarioError`, whose
message names the file, the dotted key and what is allowed.

Angles are in degrees here (and in results); internally radians. Angles on the circle
(directions, heading, cog, misalignment, azimuths) may be given in [-360, 360] and are
wrapped into [0, 360).
"""
import copy
import logging
import math
import os
import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import yaml

from uq.constants import (COVERAGE_PROBABILITY, DEFAULT_RECORDS, MAX_RECORD_SCANS, FULL_CIRCLE_DEG, MANN_ANISOTROPY, MAX_BEAMS, MAX_CHUNK_SIZE,
                          MAX_GATES, MAX_GROUPS, MAX_MAGNITUDE, MAX_SCENES, MAX_SEED)
from uq.physics.correction import CORRECTION_MODELS
from uq.physics.beams import beam_unit_vectors
from uq.pipeline.distributions import ERROR_DISTRIBUTIONS, validate_error
from uq.errors import MAX_ECHO, ScenarioError, one_line
from uq.pipeline.fitconfig import validate_fit
from uq.pipeline.motionsection import (check_dwell, check_motion_reach, check_record,
                                       random_phase_count,
                                       validate_ins_timing, validate_lever_arm, validate_motion,
                                       validate_scan)
from uq.pipeline.probesection import PROBE_ERROR_KEYS, check_probe, validate_probe
from uq.pipeline.turbulencesection import (check_record_cost, validate_record,
                                           validate_turbulence)
from uq.physics.modelinputs import error_keys
from uq.physics.scene import ALL_OUTPUTS
from uq.pipeline.mountsection import (check_mount_settings, check_mounted_beams, tilt_of,
                                      validate_mount)
from uq.engine.sampling import PROPAGATION_METHODS
from uq.engine.statistics import INTERVALS
from uq.engine.stopping import STOPPING_RULES
from uq.pipeline.sweep import VECTOR_KEYS
from uq.pipeline.yamlfile import read_yaml

#: What a scenario file is, in messages about the file itself.
SCENARIO_KIND = "a YAML scenario"

log = logging.getLogger(__name__)

INS_CORRELATIONS = ("scan", "beam")
#: The errors of the INS readings (``ins.<key>``) and of the lidar (``lidar.errors.<key>``,
#: the probe's parameters' apart), as :mod:`uq.physics.modelinputs` declares them.
INS_KEYS = error_keys("ins")
LIDAR_ERROR_KEYS = tuple(key for key in error_keys("lidar") if key not in PROBE_ERROR_KEYS)
#: Largest tilt the model accepts [deg]; beyond it the lidar looks sideways.
MAX_TILT_DEG = 89.0
MAX_SAMPLES = 10**10
#: Smallest singular value of the beam matrix, relative to the largest, for the beams to
#: determine the 3-D wind [1]: a singular geometry gives 0 to rounding (~1e-17); 1e-10
#: keeps every geometry whose reconstruction is exact to double precision in a noise-free
#: scan (three azimuths within 1 deg on a 5 deg cone: ~1e-6).
BEAM_RANK_TOLERANCE = 1e-10
#: Fewest Monte Carlo trials that give a coverage interval [1]: JCGM 101:2008, 7.2.2, at
#: least 1/(1 - p) (20 for p = 0.95; 10^4 and more recommended). Fewer give no endpoints.
MIN_SAMPLES = round(1 / (1 - COVERAGE_PROBABILITY))

DEFAULTS = {
    "name": "scenario",
    "description": "",
    "wind": {"speed": 5.0, "direction": 0.0, "vertical": 0.0, "shear": 0.0,
             "reference_height": 100.0},
    "ship": {"sog": 0.0, "cog": 0.0, "heading": 0.0, "pitch": 0.0, "roll": 0.0, "heave": 0.0},
    "ins": {"correlation": "scan"},
    "lidar": {"height": 20.0, "ranges": [100.0], "half_cone": 28.0,
              "azimuths": [0.0, 90.0, 180.0, 270.0], "vertical_beam": False,
              "misalignment": 0.0, "errors": {}},
    "correction": "full",
    "sampling": {"method": "mc", "seed": None, "control_variate": False,
                 "interval": "symmetric", "stopping": "jcgm101"},
    "sweep": {},
    "outputs": ["wind_speed", "wind_direction", "vertical_wind"],
    "fit": {},
    "motion": {},
}
#: Optional top-level sections without defaults: given, they switch record mode on
#: (:mod:`uq.pipeline.turbulencesection`); absent, nothing of them enters the settings.
OPTIONAL_SECTIONS = ("turbulence", "record")
#: Optional keys of a section that enter the settings only when given (so a scenario
#: without them is today's, to the text of its ``scenario`` attribute).
OPTIONAL_LIDAR_KEYS = ("lever_arm", "scan", "probe", "mount")
OPTIONAL_INS_KEYS = ("rate", "interpolation", "clock_offset")
#: Outputs derived from the results rather than evaluated per trial.
DERIVED_OUTPUTS = ("wind_speed_motion_ti",)
#: Outputs of record mode (a ``turbulence`` section, :mod:`uq.pipeline.records`).
RECORD_OUTPUTS = ("turbulence_intensity",)
DEFAULT_SAMPLES = 100_000


@dataclass(frozen=True)
class Scenario:
    """A validated scenario.

    Attributes
    ----------
    name, description : str
    settings : dict
        The full validated settings with defaults filled in (degrees, as in the file).
        Read-only by convention: :meth:`with_values` returns a new scenario.
    sweep : tuple of (str, tuple)
        Dotted key and its values, in file order (outer product).
    links : tuple of (str, str)
        ``(follower, leader)``: a key that takes the swept value of another swept key
        instead of adding a dimension (``sweep: {ship.heading: {same_as: ship.cog}}``).
    source : str
        File path or ``<mapping>``, for messages.
    """

    name: str
    description: str
    settings: dict
    sweep: tuple
    source: str
    links: tuple = ()

    @property
    def text(self):
        """The scenario as YAML text (as run), defaults filled in."""
        # libyaml's emitter where PyYAML has it (~20x faster than the pure-Python one)
        dumper = getattr(yaml, "CSafeDumper", yaml.SafeDumper)
        return yaml.dump(self.settings, Dumper=dumper, sort_keys=False)

    def get(self, dotted):
        """Value at a dotted key, e.g. ``wind.direction``."""
        node = self.settings
        for part in dotted.split("."):
            node = node[part]
        return node

    def with_values(self, assignments):
        """A new scenario with ``{dotted: value}`` set and validated (sweep kept)."""
        raw = copy.deepcopy(self.settings)
        apply_overrides(raw, assignments, self.source)
        settings = _validate(raw, self.source)
        settings["sweep"] = copy.deepcopy(self.settings["sweep"])
        return Scenario(settings["name"], settings["description"], settings, self.sweep,
                        self.source, self.links)

    def assignments(self, point):
        """``{dotted: value}`` of one grid point (a value per swept key), links included."""
        values = dict(zip((key for key, _ in self.sweep), point))
        values.update({follower: values[leader] for follower, leader in self.links})
        return values

    @property
    def outputs(self):
        return tuple(self.settings["outputs"])

    @property
    def sampling(self):
        return self.settings["sampling"]


def load_scenario(path_or_mapping, overrides=None):
    """Read and validate a scenario.

    Parameters
    ----------
    path_or_mapping : str, pathlib.Path, dict or Scenario
    overrides : dict, optional
        ``{dotted.key: value}`` applied before validation (``uq run --set``).

    Returns
    -------
    Scenario

    Raises
    ------
    uq.errors.ScenarioError
    """
    if isinstance(path_or_mapping, Scenario):
        return path_or_mapping.with_values(overrides or {})
    if isinstance(path_or_mapping, dict):
        raw, source = copy.deepcopy(path_or_mapping), "<mapping>"
    else:
        source = str(path_or_mapping)
        raw = read_yaml(Path(path_or_mapping), kind=SCENARIO_KIND)
        if isinstance(raw, dict):
            raw.setdefault("name", Path(path_or_mapping).stem)
    if not isinstance(raw, dict):
        raise ScenarioError(source, "", "a scenario must be a mapping of the top-level keys "
                            f"{', '.join(DEFAULTS)}")
    apply_overrides(raw, overrides or {}, source)
    _monte_carlo_switched_off(raw, overrides or {})
    try:
        scenario = _build(raw, source)
    except ScenarioError as error:
        raise blame_override(error, overrides or {}) from None
    for key, text in keys_without_effect(scenario.settings, dict(scenario.sweep)):
        log.warning("%s: %s: %s", source, key, text)
    return scenario


def blame_override(error, overrides):
    """`error` as an error of the ``--set KEY=VALUE`` that set its key (or a key above
    it, or a key its problem names: the wave height of a spectrum whose motion is too
    large), with the file it was applied to; unchanged where no override set one."""
    named = [dotted for dotted in overrides if error.key == dotted or
             error.key.startswith((dotted + ".", dotted + "[")) or
             (error.key and dotted.startswith(error.key + "."))]
    named = named or [dotted for dotted in overrides
                      if re.search(rf"(?<![\w.]){re.escape(dotted)}(?![\w])", error.problem)]
    if not named:
        return error
    return ScenarioError(f"{override_text(named[0], overrides[named[0]])} (applied to "
                         f"{error.source})", error.key, error.problem)


def override_text(dotted, value):
    """``--set KEY=VALUE`` (or ``--unset KEY`` for None) as a message echoes it: one
    line, the value shortened."""
    if value is None:
        return f"--unset {one_line(dotted, MAX_ECHO)}"
    text = yaml.safe_dump(value, default_flow_style=True, width=math.inf).strip()
    text = text[:-4].strip() if text.endswith("...") else text
    return f"--set {one_line(dotted, MAX_ECHO)}={one_line(text, MAX_ECHO)}"


#: Largest half-cone angle [deg] that is taken for a slip into radians (pi/2 rad is
#: 90 deg; a lidar's half-cone is 15-40 deg, and 1.57 deg is none a lidar has).
RADIAN_LOOKING_HALF_CONE = math.pi / 2


def keys_without_effect(settings, sweep=None):
    """(dotted key, why) of each key of validated `settings` that changes no number in
    this scene, or looks like a slip (a half-cone in radians); `sweep` maps swept keys to
    their values. ``load_scenario`` warns of each on stderr."""
    sweep = sweep or {}
    moving = bool(settings.get("motion"))
    ins, lidar = settings["ins"], settings["lidar"]
    timed = any("correlation_time" in ins[k] for k in INS_KEYS if k in ins)
    found = []
    if "rate" in ins and not moving:
        found.append(("ins.rate", "has no effect without a motion section (an INS on a "
                      "platform at rest reads the same at every sample: the same model, "
                      "other random draws); allowed: add motion, or leave ins.rate out"))
    if "turbulence" in settings and settings["turbulence"]["model"] == "kaimal" and \
            settings["turbulence"]["anisotropy"] != MANN_ANISOTROPY:
        found.append(("turbulence.anisotropy", "has no effect with model kaimal (Mann's "
                      "Gamma); allowed: model mann, or leave anisotropy out"))
    if "scan" in lidar and not moving and not timed and "turbulence" not in settings:
        found.append(("lidar.scan", "has no effect without a motion section or an INS "
                      "error's correlation_time (the beams' times matter only where "
                      "something changes between them)"))
    if "pointwise" in {settings["correction"], *sweep.get("correction", ())} and not moving:
        found.append(("correction", "pointwise gives the numbers of full without a motion "
                      "section (every beam sees the platform of the scan); allowed: add "
                      "motion, or correction: full"))
    if lidar["half_cone"] <= RADIAN_LOOKING_HALF_CONE:
        found.append(("lidar.half_cone", f"{lidar['half_cone']:g} deg: angles are in "
                      f"degrees; {lidar['half_cone']:g} rad would be "
                      f"{math.degrees(lidar['half_cone']):.1f} deg"))
    return found


def apply_overrides(raw, overrides, source):
    """Apply ``{dotted: value}`` (``--set``) to the mapping `raw` in order: a value of
    None (``--set KEY=null`` or ``--unset KEY``) removes the key
    (:func:`remove_dotted`), any other sets it (:func:`assign_dotted`)."""
    for dotted, value in overrides.items():
        if value is None:
            remove_dotted(raw, dotted, source)
        else:
            assign_dotted(raw, dotted, value, source)


def remove_dotted(raw, dotted, source):
    """Remove the key 'a.b...' from `raw` (``--unset a.b``; ``sweep.<dotted key>``
    removes that key's sweep): what the file says without it, its default where it has
    one, else the validator's one line ("missing") for a required key. A key the
    scenario does not set is refused (nothing to remove)."""
    parts = dotted.split(".")
    if parts[0] == "sweep" and len(parts) > 1:
        parts = ["sweep", ".".join(parts[1:])]
    node = raw
    for part in parts[:-1]:
        node = node.get(part) if isinstance(node, dict) else None
    where = f"--unset {one_line(dotted, MAX_ECHO)} (applied to {source})"
    if not isinstance(node, dict) or parts[-1] not in node:
        present = ", ".join(map(str, node)) if isinstance(node, dict) and node else "none"
        raise ScenarioError(where, dotted, "the scenario does not set it: nothing to remove; "
                            f"allowed: a key it sets (here: {one_line(present, MAX_ECHO)})")
    del node[parts[-1]]


def assign_dotted(raw, dotted, value, source):
    """Set raw[a][b]... = value for 'a.b...', creating mappings on the way.

    ``sweep.<dotted key>`` sets the sweep of that (dotted) key.
    """
    parts = dotted.split(".")
    if parts[0] == "sweep" and len(parts) > 1:
        parts = ["sweep", ".".join(parts[1:])]
    node = raw
    for part in parts[:-1]:
        child = node.get(part) if isinstance(node, dict) else None
        if child is None:
            child = node[part] = {}
        if not isinstance(child, dict):
            raise ScenarioError(source, dotted, f"'{part}' is not a mapping")
        node = child
    node[parts[-1]] = value


def _build(raw, source):
    settings = _validate(raw, source)
    sweep, links = _validate_sweep(raw.get("sweep"), settings, source)
    settings["sweep"] = {key: [_plain(v) for v in values] for key, values in sweep}
    settings["sweep"].update({follower: {"same_as": leader} for follower, leader in links})
    return Scenario(settings["name"], settings["description"], settings, sweep, source, links)


def _plain(value):
    """A numpy scalar as the Python number it holds (the scenario text is YAML)."""
    if isinstance(value, (bool, np.bool_)):
        return bool(value)
    if isinstance(value, np.integer):
        return int(value)
    if isinstance(value, np.floating):
        return float(value)
    return value


def load_fit_settings(raw_fit, source):
    """A :class:`uq.pipeline.fitconfig.FitConfig` from a ``fit`` mapping; errors name `source`."""
    return validate_fit(Checker(source), raw_fit)


def _validate(raw, source, check=None):
    check = check or Checker(source)
    if "golden" in raw:
        check.fail("golden", "this is a golden-lidar configuration, not a scenario; "
                   "allowed: uq golden FILE")
    check.keys(raw, "", tuple(DEFAULTS) + OPTIONAL_SECTIONS)
    settings = {
        "name": check.name(raw.get("name", DEFAULTS["name"])),
        "description": check.text(raw.get("description", ""), "description"),
        "wind": _wind(check, raw.get("wind")),
        "ship": _ship(check, raw.get("ship")),
        "ins": _ins(check, raw.get("ins")),
        "lidar": _lidar(check, raw.get("lidar")),
        "correction": check.choice(raw.get("correction", DEFAULTS["correction"]),
                                   "correction", CORRECTION_MODELS),
        "sampling": _sampling(check, raw.get("sampling")),
        "outputs": _outputs(check, raw.get("outputs", DEFAULTS["outputs"])),
    }
    if raw.get("fit") is not None:                   # optional: settings of uq fit
        settings["fit"] = validate_fit(check, raw["fit"]).to_dict()
    if raw.get("motion") is not None:                # optional: motion within the scan
        settings["motion"] = validate_motion(check, raw["motion"])
    if raw.get("turbulence") is not None or raw.get("record") is not None:
        _records(check, raw, settings)               # optional: records in turbulence
    _check_time_resolved(check, settings)
    check_mount_settings(check, settings)
    if "turbulence" in settings:
        check_record_cost(check, settings)
    return settings


def _records(check, raw, settings):
    """``turbulence`` and ``record`` (record mode: one goes with the other; a record
    lasts 600 s unless given)."""
    if raw.get("turbulence") is None:
        check.fail("record", "a record needs a turbulent wind; allowed: add a turbulence "
                   "section (model, intensity), or leave record out")
    lidar = settings["lidar"]
    settings["turbulence"] = validate_turbulence(check, raw["turbulence"],
                                                 settings["wind"]["reference_height"])
    check.limit("record.duration", f"at least one scan and at most {MAX_RECORD_SCANS} scans "
                "(of lidar.scan.beam_duration per beam)")
    check.limit("record.count", "only with sampling.method mc, lhs or sobol")
    settings["record"] = validate_record(check, raw.get("record") or {}, len(lidar["azimuths"])
                                         + int(lidar["vertical_beam"]), lidar)
    count = settings["record"]["count"]
    if settings["sampling"]["method"] == "none" and count != DEFAULT_RECORDS:
        check.fail("record.count", f"{count} Monte Carlo records per scene, but "
                   "sampling.method none draws none (the spectral path alone); allowed: "
                   "leave record.count out (--unset record.count), or sampling.method mc, "
                   "lhs or sobol")


def _section(check, value, key, optional=()):
    value = {} if value is None else value
    check.mapping(value, key)
    check.keys(value, key, tuple(DEFAULTS[key]) + tuple(optional))
    return {**copy.deepcopy(DEFAULTS[key]), **value}


def _wind(check, value):
    w = _section(check, value, "wind")
    return {"speed": check.number(w["speed"], "wind.speed", low=0.0),
            "direction": check.angle(w["direction"], "wind.direction"),
            "vertical": check.number(w["vertical"], "wind.vertical"),
            "shear": check.number(w["shear"], "wind.shear", low=-1.0, high=2.0),
            "reference_height": check.number(w["reference_height"], "wind.reference_height",
                                             low=0.0, low_open=True)}


def _ship(check, value):
    s = _section(check, value, "ship")
    return {"sog": check.number(s["sog"], "ship.sog", low=0.0),
            "cog": check.angle(s["cog"], "ship.cog"),
            "heading": check.angle(s["heading"], "ship.heading"),
            "pitch": check.number(s["pitch"], "ship.pitch", low=-MAX_TILT_DEG, high=MAX_TILT_DEG),
            "roll": check.number(s["roll"], "ship.roll", low=-MAX_TILT_DEG, high=MAX_TILT_DEG),
            "heave": check.number(s["heave"], "ship.heave")}


def _ins(check, value):
    value = {} if value is None else value
    check.mapping(value, "ins")
    check.keys(value, "ins", ("correlation",) + INS_KEYS + OPTIONAL_INS_KEYS)
    out = {"correlation": check.choice(value.get("correlation", "scan"), "ins.correlation",
                                       INS_CORRELATIONS)}
    for key in INS_KEYS:
        if key in value:
            out[key] = _ins_error(check, value[key], f"ins.{key}")
    validate_ins_timing(check, value, out)
    if "clock_offset" in value:
        out["clock_offset"] = validate_error(value["clock_offset"], "ins.clock_offset", check)
    return out


def _ins_error(check, spec, key):
    """An INS error, with an optional ``correlation_time`` [s] (>= 0, .inf allowed)."""
    out = validate_error(spec, key, check, extra=("correlation_time",))
    if "correlation_time" in spec:
        value = spec["correlation_time"]
        if isinstance(value, float) and value == math.inf:
            out["correlation_time"] = math.inf
        else:
            out["correlation_time"] = check.number(value, f"{key}.correlation_time", low=0.0)
    return out


def _lidar(check, value):
    lid = _section(check, value, "lidar", OPTIONAL_LIDAR_KEYS)
    lid["azimuths"] = _azimuth_steps(check, lid["azimuths"])
    check.limit("lidar.ranges", f"at most {MAX_GATES} gates, distinct")
    check.limit("lidar.azimuths", f"at most {MAX_BEAMS} beams, distinct; with the vertical "
                "beam they must determine the 3-D wind")
    check.length(lid["ranges"], "lidar.ranges", MAX_GATES)
    check.length(lid["azimuths"], "lidar.azimuths", MAX_BEAMS)
    out = {"height": check.number(lid["height"], "lidar.height", low=0.0),
           "ranges": check.number_list(lid["ranges"], "lidar.ranges", low=0.0, low_open=True),
           "half_cone": check.number(lid["half_cone"], "lidar.half_cone", low=0.0, high=90.0,
                                     low_open=True, high_open=True),
           "azimuths": [check.angle(a, f"lidar.azimuths[{i}]")
                        for i, a in enumerate(check.list(lid["azimuths"], "lidar.azimuths"))],
           "vertical_beam": check.boolean(lid["vertical_beam"], "lidar.vertical_beam"),
           "misalignment": check.angle(lid["misalignment"], "lidar.misalignment")}
    check.unique(out["ranges"], "lidar.ranges")
    check.unique([a % FULL_CIRCLE_DEG for a in out["azimuths"]], "lidar.azimuths")
    if "mount" in lid:
        out["mount"] = validate_mount(check, lid["mount"])
    if tilt_of(out) != 0:
        check_mounted_beams(check, out)
    elif len(out["azimuths"]) + out["vertical_beam"] < 3 or len(out["azimuths"]) < 2:
        raise ScenarioError(check.source, "lidar.azimuths", "need at least 3 beams (and 2 "
                            "slanted ones) to reconstruct the 3-D wind; allowed: >= 3 "
                            "azimuths, or 2 non-opposite ones with vertical_beam: true")
    else:
        _check_beams_determine_wind(check, out)
    errors = lid["errors"] if lid["errors"] is not None else {}
    check.mapping(errors, "lidar.errors")
    check.keys(errors, "lidar.errors", error_keys("lidar"))
    out["errors"] = {key: validate_error(errors[key], f"lidar.errors.{key}", check)
                     for key in error_keys("lidar") if key in errors}
    if "lever_arm" in lid:
        out["lever_arm"] = validate_lever_arm(check, lid["lever_arm"])
    if "scan" in lid:
        out["scan"] = validate_scan(check, lid["scan"])
    if "probe" in lid:
        out["probe"] = validate_probe(check, lid["probe"])
    check_probe(check, out)
    return out


def _check_time_resolved(check, settings):
    """Keys that only mean something together."""
    ins = settings["ins"]
    if "interpolation" in ins and "rate" not in ins:
        check.fail("ins.interpolation", "needs ins.rate (a continuous INS is not "
                   "interpolated); allowed: give ins.rate in Hz")
    if DERIVED_OUTPUTS[0] in settings["outputs"] and not settings.get("motion"):
        check.fail("outputs", f"{DERIVED_OUTPUTS[0]} needs a motion section; allowed: the "
                   "other outputs")
    if RECORD_OUTPUTS[0] in settings["outputs"] and "turbulence" not in settings:
        check.fail("outputs", f"{RECORD_OUTPUTS[0]} needs a turbulence section; allowed: "
                   "the other outputs, or add turbulence: {model, intensity}")
    check.limit("ins.correlation", "beam only with an INS error")
    if ins["correlation"] == "beam" and not any(key in ins for key in INS_KEYS):
        check.fail("ins.correlation", "beam (an independent INS reading per beam) has no "
                   f"effect without an INS error ({', '.join(f'ins.{k}' for k in INS_KEYS)}); "
                   "allowed: scan, or give an INS error")
    check_motion_reach(check, settings)
    check_dwell(check, settings)
    lidar = settings["lidar"]
    check_record(settings, len(lidar["azimuths"]) + int(lidar["vertical_beam"]))


def _azimuth_steps(check, value):
    """``lidar.azimuths`` as a list: a list as it is, ``{start, stop, step}`` (stop
    excluded) as its values, counted against MAX_BEAMS before they are made."""
    if not (isinstance(value, dict) and set(value) == {"start", "stop", "step"}):
        if isinstance(value, dict):
            check.fail("lidar.azimuths", "expected a list of angles or {start, stop, step} "
                       f"(stop excluded), got a mapping of {', '.join(map(str, value))}")
        return value
    start, stop, step = (check.number(value[k], f"lidar.azimuths.{k}", low=-FULL_CIRCLE_DEG,
                                      high=FULL_CIRCLE_DEG) for k in ("start", "stop", "step"))
    span = (stop - start) / step if step else math.nan
    if not span > 0:
        check.fail("lidar.azimuths", "start, stop, step give no angles; allowed: step != 0 "
                   "pointing from start towards stop (stop excluded)")
    count = math.ceil(span - STEP_ROUNDING)
    if count > MAX_BEAMS:
        check.fail("lidar.azimuths", f"start, stop, step give {count} beams; allowed: at "
                   f"most {MAX_BEAMS}")
    return [start + i * step for i in range(count)]


#: Part of a step by which {start, stop, step} may overshoot stop and still exclude it
#: (rounding of a step such as 7.2 = 360/50, which is not exact in binary) [1].
STEP_ROUNDING = 1e-9


def _check_beams_determine_wind(check, lidar):
    """The beams must span the three wind components (the least-squares matrix of the
    DBS reconstruction has full rank): e.g. azimuths 0 and 180 with a vertical beam do
    not (they see nothing of the cross wind)."""
    vectors = beam_unit_vectors(math.radians(lidar["half_cone"]),
                                np.radians(lidar["azimuths"]), 0.0, lidar["vertical_beam"])
    singular = np.linalg.svd(vectors, compute_uv=False)
    if singular[-1] < BEAM_RANK_TOLERANCE * singular[0]:
        check.fail("lidar.azimuths", f"the beams ({', '.join(f'{a:g}' for a in lidar['azimuths'])}"
                   f"{' and vertical' if lidar['vertical_beam'] else ''}) do not determine the "
                   "3-D wind; allowed: beams spanning north, east and up (e.g. 3 azimuths not "
                   "on one line, or 2 non-opposite ones with vertical_beam: true)")


def _sampling(check, value):
    allowed = ("method", "n", "digits", "seed", "control_variate", "interval", "chunk_size",
               "stopping", "stop_when_gum_valid")
    value = {} if value is None else value
    check.mapping(value, "sampling")
    check.keys(value, "sampling", allowed)
    s = {**DEFAULTS["sampling"], **value}
    out = {"method": check.choice(s["method"], "sampling.method", PROPAGATION_METHODS),
           "interval": check.choice(s["interval"], "sampling.interval", INTERVALS),
           "control_variate": check.boolean(s["control_variate"], "sampling.control_variate"),
           "stopping": check.choice(s["stopping"], "sampling.stopping", STOPPING_RULES)}
    if "n" in value and "digits" in value:
        raise ScenarioError(check.source, "sampling", "give either n or digits, not both")
    if "digits" in value:
        out["digits"] = check.integer(value["digits"], "sampling.digits", low=1, high=6)
    else:
        out["n"] = check.integer(value.get("n", DEFAULT_SAMPLES), "sampling.n",
                                 low=MIN_SAMPLES, high=MAX_SAMPLES)
    out["seed"] = None if s["seed"] is None else check.integer(s["seed"], "sampling.seed", low=0,
                                                               high=MAX_SEED)
    if "chunk_size" in value:
        out["chunk_size"] = check.integer(value["chunk_size"], "sampling.chunk_size", low=1,
                                          high=MAX_CHUNK_SIZE)
    out["stop_when_gum_valid"] = check.boolean(value.get("stop_when_gum_valid", False),
                                               "sampling.stop_when_gum_valid")
    if out["stop_when_gum_valid"] and "digits" not in out:
        check.fail("sampling.stop_when_gum_valid", "needs adaptive sampling; allowed: with "
                   "sampling.digits, not sampling.n")
    for key in MONTE_CARLO_DEFAULTS:
        check.limit(f"sampling.{key}", "not with sampling.method none")
    if out["method"] == "none":
        _no_monte_carlo_keys(check, value)
    return out


#: The keys of ``sampling`` that set the Monte Carlo trials, and their defaults (a
#: validated scenario carries the defaults, which pass again): with ``method: none``
#: there are no trials, and a key set otherwise would be ignored.
MONTE_CARLO_DEFAULTS = {"n": DEFAULT_SAMPLES, "digits": None, "chunk_size": None,
                        "control_variate": False, "interval": "symmetric",
                        "stopping": "jcgm101", "stop_when_gum_valid": False}


def _monte_carlo_switched_off(raw, overrides):
    """An override that sets ``sampling.method`` to none (``--set sampling.method=none``,
    or a whole ``sampling`` section) switches the Monte Carlo off: the file's own Monte
    Carlo keys (``sampling.n`` ..., ``record.count``) are dropped from `raw`, as the file
    wrote them for the method the override replaced. One the overrides set themselves
    stays, and is refused (:func:`_no_monte_carlo_keys`)."""
    method = overrides.get("sampling.method", (overrides.get("sampling") or {}).get(
        "method") if isinstance(overrides.get("sampling"), dict) else None)
    if method != "none":
        return
    sampling, record = raw.get("sampling"), raw.get("record")
    for key in MONTE_CARLO_DEFAULTS:
        if isinstance(sampling, dict) and f"sampling.{key}" not in overrides and \
                not (isinstance(overrides.get("sampling"), dict) and
                     key in overrides["sampling"]):
            sampling.pop(key, None)
    if isinstance(record, dict) and "record.count" not in overrides:
        record.pop("count", None)


def _no_monte_carlo_keys(check, value):
    """Refuse a Monte Carlo key of `value` (``sampling``) set with ``method: none``."""
    for key, default in MONTE_CARLO_DEFAULTS.items():
        if key in value and value[key] != default:
            shown = str(value[key]).lower() if isinstance(value[key], bool) else value[key]
            check.fail(f"sampling.{key}", f"{shown} sets the Monte Carlo trials, but "
                       "sampling.method none draws none (the GUM and the paper's model "
                       f"alone); allowed: leave sampling.{key} out (--unset sampling.{key}), "
                       "or sampling.method mc, lhs or sobol")


def _outputs(check, value):
    items = check.list(value, "outputs")
    for item in items:
        check.choice(item, "outputs", ALL_OUTPUTS + DERIVED_OUTPUTS + RECORD_OUTPUTS)
    check.unique(items, "outputs")
    if not items:
        raise ScenarioError(check.source, "outputs", f"empty; allowed: any of {', '.join(ALL_OUTPUTS)}")
    return list(items)


def _validate_sweep(value, settings, source):
    value = {} if value is None else value
    if not isinstance(value, dict):
        raise ScenarioError(source, "sweep", "must be a mapping of dotted keys to a list of "
                            "values or to {start, stop, step}")
    sweep, links = [], []
    for key, spec in value.items():
        if not isinstance(key, str):
            raise ScenarioError(source, f"sweep.{key}", "a swept key must be a dotted key "
                                "(text), e.g. wind.direction")
        _sweep_key_exists(settings, key, source)
        if isinstance(spec, dict) and set(spec) == {"same_as"}:
            if not isinstance(spec["same_as"], str):
                raise ScenarioError(source, f"sweep.{key}.same_as", f"expected a swept key "
                                    f"(text), got {_kind(spec['same_as'])}")
            links.append((key, spec["same_as"]))
            continue
        sweep.append((key, _sweep_values(spec, f"sweep.{key}", source)))
    _check_sweep_size(sweep, source)           # counts only: nothing allocated yet
    sweep = [(key, tuple(values)) for key, values in sweep]
    swept = dict(sweep)
    for follower, leader in links:
        if leader not in swept:
            raise ScenarioError(source, f"sweep.{follower}.same_as", f"{leader!r} is not a "
                                f"swept key; allowed: one of {', '.join(swept) or '(none)'}")
        if (follower in VECTOR_KEYS) != (leader in VECTOR_KEYS):
            raise ScenarioError(source, f"sweep.{follower}.same_as", f"cannot follow "
                                f"{leader!r}; allowed: pairs of scene values "
                                f"({', '.join(VECTOR_KEYS)}) or pairs of other keys")
        swept[follower] = swept[leader]
    for key, values in swept.items():
        random = set()
        for item in _values_to_validate(key, values, source):
            raw = copy.deepcopy(settings)     # each value must make a valid scenario
            assign_dotted(raw, key, item, source)
            random.add(random_phase_count(_validate(raw, source)) > 0)
        if len(random) > 1:                   # the model's inputs would differ by value
            raise ScenarioError(source, f"sweep.{key}", "some values give the motion random "
                                "phases and others none (different Monte Carlo inputs "
                                "cannot share one sweep); allowed: all values with "
                                "random phases, or none (e.g. phases in degrees only)")
    return tuple(sweep), tuple(links)


def _values_to_validate(key, values, source):
    """The values of a swept key that must each be validated in a whole scenario. A
    scene value (:data:`VECTOR_KEYS`) is a number checked against an interval, so its
    smallest and largest values stand for all (after a type check of each): a sweep of
    10^6 directions costs two validations, not 10^6."""
    if key not in VECTOR_KEYS:
        return values
    for item in values:
        if isinstance(item, bool) or not isinstance(item, (int, float)):
            raise ScenarioError(source, f"sweep.{key}", f"expected numbers, got {_kind(item)}")
    bad = [item for item in values if not math.isfinite(_float_magnitude(item))]
    return bad[:1] or [min(values), max(values)]


def _check_sweep_size(sweep, source):
    """Refuse a sweep of more scenes (or structural groups) than the limits, before
    anything is allocated (:data:`~uq.constants.MAX_SCENES`, ``UQ_MAX_SCENES``)."""
    limit = max_scenes()
    scenes = math.prod(len(values) for _, values in sweep)
    if scenes > limit:
        sizes = " x ".join(f"{len(values)} ({key})" for key, values in sweep)
        raise ScenarioError(source, "sweep", f"{sizes} = {scenes:.3g} scenes; allowed: at "
                            f"most {limit} (environment variable UQ_MAX_SCENES)")
    groups = math.prod(len(values) for key, values in sweep if key not in VECTOR_KEYS)
    if groups > MAX_GROUPS:
        raise ScenarioError(source, "sweep", f"{groups} combinations of structural keys "
                            "(each its own model); allowed: at most "
                            f"{MAX_GROUPS} (sweep scene values such as wind.* and ship.* "
                            "instead, which are evaluated as arrays)")


def sweep_limits():
    """The limits :func:`_check_sweep_size` enforces, in words (the scenario reference)."""
    return (f"at most {MAX_SCENES:,} scenes (environment variable UQ_MAX_SCENES) and "
            f"{MAX_GROUPS:,} combinations of structural keys (each its own model)")


def max_scenes():
    """The most scenes a sweep may have: UQ_MAX_SCENES if set, else MAX_SCENES."""
    text = os.environ.get("UQ_MAX_SCENES", "")
    try:
        return int(text) if text else MAX_SCENES
    except ValueError:
        raise ScenarioError("UQ_MAX_SCENES", "", f"{text!r} is not an integer; allowed: the "
                            "most scenes a sweep may have") from None


def _sweep_key_exists(settings, key, source):
    node = settings
    for part in key.split("."):
        if not isinstance(node, dict) or part not in node:
            raise ScenarioError(source, f"sweep.{key}", "no such scenario key (errors must "
                                "be declared in the scenario before they can be swept)")
        node = node[part]
    if isinstance(node, (dict, list)) or key in ("name", "description"):
        raise ScenarioError(source, f"sweep.{key}", "only a single-valued key can be swept, "
                            "not a section or a list")


def _sweep_values(spec, key, source):
    if isinstance(spec, list):
        if not spec:
            raise ScenarioError(source, key, "empty list; allowed: a non-empty list")
        return spec
    if isinstance(spec, dict) and set(spec) == {"start", "stop", "step"}:
        check = Checker(source)
        start, stop, step = (check.number(spec[k], f"{key}.{k}") for k in ("start", "stop", "step"))
        with np.errstate(all="ignore"):
            span = (stop - start) / step if step else math.nan
        if not span > 0:
            raise ScenarioError(source, key, "start, stop, step give no values; allowed: "
                                "step != 0 pointing from start towards stop (stop excluded)")
        if not span <= max_scenes():
            raise ScenarioError(source, key, f"start, stop, step give {span:.3g} values; "
                                f"allowed: at most {max_scenes()} (environment variable "
                                "UQ_MAX_SCENES)")
        count = math.ceil(span - STEP_ROUNDING)
        return _Steps(start, step, count)
    raise ScenarioError(source, key, "must be a list of values, {start, stop, step} or "
                        "{same_as: another swept key}")


class _Steps:
    """The values start + i step, i < count, made only when iterated."""

    def __init__(self, start, step, count):
        self.start, self.step, self.count = start, step, count

    def __len__(self):
        return self.count

    def __iter__(self):
        return (self.start + i * self.step for i in range(self.count))


class Checker:
    """Type and range checks that raise ScenarioError naming the key."""

    def __init__(self, source):
        self.source = source

    def fail(self, key, problem):
        raise ScenarioError(self.source, key, problem)

    def limit(self, key, text):
        """Declare a limit the validator enforces on `key` beyond its type and range (a
        list's length, a file's size, a sum over keys), where it is enforced: nothing
        here; the scenario reference lists it beside the key
        (:class:`uq.pipeline.reference.RecordingChecker`)."""

    def keys(self, mapping, prefix, allowed):
        for key in mapping:
            if key not in allowed:
                dotted = f"{prefix}.{key}" if prefix else str(key)
                self.fail(dotted, f"unknown key; allowed: {', '.join(allowed)}")

    def required(self, mapping, prefix, names, needs):
        """Fail on the first of `names` missing from `mapping`, as "missing; `needs`"."""
        for name in names:
            if name not in mapping:
                self.fail(f"{prefix}.{name}", f"missing; {needs}")

    def mapping(self, value, key):
        if not isinstance(value, dict):
            self.fail(key, f"expected a mapping, got {_kind(value)}")

    def list(self, value, key):
        if not isinstance(value, list):
            self.fail(key, f"expected a list, got {_kind(value)}")
        return value

    def number(self, value, key, low=None, high=None, low_open=False, high_open=False):
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            self.fail(key, f"expected a finite number, got {_kind(value)}")
        if not _float_magnitude(value) <= MAX_MAGNITUDE:
            self.fail(key, f"{_kind(value)} is not allowed; allowed: a finite number of "
                      f"magnitude at most {MAX_MAGNITUDE:g}")
        below = low is not None and (value < low or (low_open and value == low))
        above = high is not None and (value > high or (high_open and value == high))
        if below or above:
            self.fail(key, f"{value} is out of range; allowed: {_range(low, high, low_open, high_open)}")
        return float(value)

    def integer(self, value, key, low=None, high=None):
        if isinstance(value, bool) or not isinstance(value, int):
            self.fail(key, f"expected an integer, got {_kind(value)}")
        self.number(value, key, low, high)
        return int(value)

    def angle(self, value, key):
        """An angle on the circle [deg], given in [-360, 360], wrapped into [0, 360)."""
        value = self.number(value, key, -FULL_CIRCLE_DEG, FULL_CIRCLE_DEG)
        return value % FULL_CIRCLE_DEG

    def length(self, value, key, most):
        """Refuse a list longer than `most` before its elements are checked."""
        if isinstance(value, list) and len(value) > most:
            self.fail(key, f"{len(value)} values; allowed: at most {most}")

    def number_list(self, value, key, **limits):
        items = self.list(value, key)
        if not items:
            self.fail(key, "empty list; allowed: at least one value")
        return [self.number(v, f"{key}[{i}]", **limits) for i, v in enumerate(items)]

    def unique(self, values, key):
        if len(set(values)) != len(values):
            self.fail(key, "values repeat; allowed: distinct values")

    def boolean(self, value, key):
        if not isinstance(value, bool):
            self.fail(key, f"expected true or false, got {_kind(value)}")
        return value

    def choice(self, value, key, allowed):
        if not isinstance(value, str) or value not in allowed:
            self.fail(key, f"{value!r} is not allowed; allowed: {', '.join(allowed)}")
        return value

    def text(self, value, key):
        if not isinstance(value, str):
            self.fail(key, f"expected text, got {_kind(value)}")
        return value

    def name(self, value):
        if not isinstance(value, str) or not re.fullmatch(r"[A-Za-z0-9][A-Za-z0-9_.-]*", value):
            self.fail("name", f"{value!r} is not allowed; allowed: letters, digits, '_', '.', "
                      "'-' (it names the output file)")
        return value


def _kind(value):
    if isinstance(value, int) and not isinstance(value, bool) and abs(value) > 10**30:
        return f"an integer of {len(str(abs(value)))} digits"
    return "nothing" if value is None else f"{type(value).__name__} {value!r}"[:60]


def _float_magnitude(value):
    """|value| as a float (inf for an integer too large for a float; NaN stays NaN)."""
    try:
        return abs(float(value))
    except OverflowError:
        return math.inf


def _range(low, high, low_open, high_open):
    left = "-inf" if low is None else f"{low:g}"
    right = "inf" if high is None else f"{high:g}"
    return f"{'(' if low_open or low is None else '['}{left}, {right}{')' if high_open or high is None else ']'}"


__all__ = ["Scenario", "load_scenario", "ScenarioError", "DEFAULTS", "ERROR_DISTRIBUTIONS"]
