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
import math
import re
from dataclasses import dataclass
from pathlib import Path

import yaml

from uq.constants import FULL_CIRCLE_DEG
from uq.physics.correction import CORRECTION_MODELS
from uq.pipeline.distributions import ERROR_DISTRIBUTIONS, validate_error
from uq.errors import ScenarioError
from uq.pipeline.fitconfig import validate_fit
from uq.physics.measurement import OUTPUTS
from uq.engine.sampling import PROPAGATION_METHODS
from uq.engine.statistics import INTERVALS
from uq.engine.stopping import STOPPING_RULES
from uq.pipeline.sweep import VECTOR_KEYS

INS_CORRELATIONS = ("scan", "beam")
INS_KEYS = ("heading", "pitch", "roll", "sog", "cog", "heave")
LIDAR_ERROR_KEYS = ("half_cone", "misalignment", "radial_velocity", "height")
#: Largest tilt the model accepts [deg]; beyond it the lidar looks sideways.
MAX_TILT_DEG = 89.0
MAX_SAMPLES = 10**10

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
}
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
        for dotted, value in assignments.items():
            assign_dotted(raw, dotted, value, self.source)
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
        raw = read_yaml(Path(path_or_mapping))
        if isinstance(raw, dict):
            raw.setdefault("name", Path(path_or_mapping).stem)
    if not isinstance(raw, dict):
        raise ScenarioError(source, "", "a scenario must be a mapping of the top-level keys "
                            f"{', '.join(DEFAULTS)}")
    for dotted, value in (overrides or {}).items():
        assign_dotted(raw, dotted, value, source)
    return _build(raw, source)


def read_yaml(path):
    try:
        text = path.read_text()
    except OSError as error:
        raise ScenarioError(str(path), "", f"cannot read the file ({error.strerror})") from None
    try:
        return yaml.safe_load(text)
    except yaml.YAMLError as error:
        mark = getattr(error, "problem_mark", None)
        where = f" at line {mark.line + 1}" if mark else ""
        raise ScenarioError(str(path), "", f"not valid YAML{where}") from None


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
    settings["sweep"] = {key: list(values) for key, values in sweep}
    settings["sweep"].update({follower: {"same_as": leader} for follower, leader in links})
    return Scenario(settings["name"], settings["description"], settings, sweep, source, links)


def load_fit_settings(raw_fit, source):
    """A :class:`uq.pipeline.fitconfig.FitConfig` from a ``fit`` mapping; errors name `source`."""
    return validate_fit(Checker(source), raw_fit)


def _validate(raw, source, check=None):
    check = check or Checker(source)
    check.keys(raw, "", DEFAULTS)
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
    return settings


def _section(check, value, key):
    value = {} if value is None else value
    check.mapping(value, key)
    check.keys(value, key, DEFAULTS[key])
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
    check.keys(value, "ins", ("correlation",) + INS_KEYS)
    out = {"correlation": check.choice(value.get("correlation", "scan"), "ins.correlation",
                                       INS_CORRELATIONS)}
    for key in INS_KEYS:
        if key in value:
            out[key] = validate_error(value[key], f"ins.{key}", check)
    return out


def _lidar(check, value):
    lid = _section(check, value, "lidar")
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
    if len(out["azimuths"]) + out["vertical_beam"] < 3 or len(out["azimuths"]) < 2:
        raise ScenarioError(check.source, "lidar.azimuths", "need at least 3 beams (and 2 "
                            "slanted ones) to reconstruct the 3-D wind; allowed: >= 3 "
                            "azimuths, or 2 non-opposite ones with vertical_beam: true")
    errors = lid["errors"] if lid["errors"] is not None else {}
    check.mapping(errors, "lidar.errors")
    check.keys(errors, "lidar.errors", LIDAR_ERROR_KEYS)
    out["errors"] = {key: validate_error(errors[key], f"lidar.errors.{key}", check)
                     for key in LIDAR_ERROR_KEYS if key in errors}
    return out


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
        out["n"] = check.integer(value.get("n", DEFAULT_SAMPLES), "sampling.n", low=2,
                                 high=MAX_SAMPLES)
    out["seed"] = None if s["seed"] is None else check.integer(s["seed"], "sampling.seed", low=0)
    if "chunk_size" in value:
        out["chunk_size"] = check.integer(value["chunk_size"], "sampling.chunk_size", low=1)
    out["stop_when_gum_valid"] = check.boolean(value.get("stop_when_gum_valid", False),
                                               "sampling.stop_when_gum_valid")
    if out["stop_when_gum_valid"] and "digits" not in out:
        check.fail("sampling.stop_when_gum_valid", "needs adaptive sampling; allowed: with "
                   "sampling.digits, not sampling.n")
    return out


def _outputs(check, value):
    items = check.list(value, "outputs")
    for item in items:
        check.choice(item, "outputs", OUTPUTS)
    check.unique(items, "outputs")
    if not items:
        raise ScenarioError(check.source, "outputs", f"empty; allowed: any of {', '.join(OUTPUTS)}")
    return list(items)


def _validate_sweep(value, settings, source):
    value = {} if value is None else value
    if not isinstance(value, dict):
        raise ScenarioError(source, "sweep", "must be a mapping of dotted keys to a list of "
                            "values or to {start, stop, step}")
    sweep, links = [], []
    for key, spec in value.items():
        _sweep_key_exists(settings, key, source)
        if isinstance(spec, dict) and set(spec) == {"same_as"}:
            links.append((key, spec["same_as"]))
            continue
        sweep.append((key, tuple(_sweep_values(spec, f"sweep.{key}", source))))
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
        for item in values:       # each value must make a valid scenario
            raw = copy.deepcopy(settings)
            assign_dotted(raw, key, item, source)
            _validate(raw, source)
    return tuple(sweep), tuple(links)


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
        if step == 0 or (stop - start) / step <= 0:
            raise ScenarioError(source, key, "start, stop, step give no values; allowed: "
                                "step != 0 pointing from start towards stop (stop excluded)")
        count = math.ceil((stop - start) / step - 1e-9)
        return [start + i * step for i in range(count)]
    raise ScenarioError(source, key, "must be a list of values, {start, stop, step} or "
                        "{same_as: another swept key}")


class Checker:
    """Type and range checks that raise ScenarioError naming the key."""

    def __init__(self, source):
        self.source = source

    def fail(self, key, problem):
        raise ScenarioError(self.source, key, problem)

    def keys(self, mapping, prefix, allowed):
        for key in mapping:
            if key not in allowed:
                dotted = f"{prefix}.{key}" if prefix else str(key)
                self.fail(dotted, f"unknown key; allowed: {', '.join(allowed)}")

    def mapping(self, value, key):
        if not isinstance(value, dict):
            self.fail(key, f"expected a mapping, got {_kind(value)}")

    def list(self, value, key):
        if not isinstance(value, list):
            self.fail(key, f"expected a list, got {_kind(value)}")
        return value

    def number(self, value, key, low=None, high=None, low_open=False, high_open=False):
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
            self.fail(key, f"expected a finite number, got {_kind(value)}")
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
    return "nothing" if value is None else f"{type(value).__name__} {value!r}"[:60]


def _range(low, high, low_open, high_open):
    left = "-inf" if low is None else f"{low:g}"
    right = "inf" if high is None else f"{high:g}"
    return f"{'(' if low_open or low is None else '['}{left}, {right}{')' if high_open or high is None else ']'}"


__all__ = ["Scenario", "load_scenario", "ScenarioError", "DEFAULTS", "ERROR_DISTRIBUTIONS"]
