"""The ``uq golden`` configuration: which files hold which instrument, at which heights,
which comparisons to make, and the settings of bins, classification and KPIs.

A configuration is a YAML file with one top-level key ``golden``; see
``scenarios/golden_campaign.yaml`` (the shipped synthetic campaign, a ``synthetic``
section instead of files) and the README for the form with data files. Validated once, at
construction; a bad key raises :class:`uq.errors.ScenarioError` naming the file, the key
and what is allowed.
"""
from dataclasses import dataclass, field
from pathlib import Path

from uq.constants import (GOLDEN_BIN_WIDTH, GOLDEN_MAX_BINS, GOLDEN_MAX_SPEED,
                          GOLDEN_MIN_RECORDS, GOLDEN_REQUIRED_RANGE, GOLDEN_SIGNIFICANCE,
                          KPI_AVAILABILITY)
from uq.errors import ScenarioError
from uq.files import check_name
from uq.pipeline.scenario import Checker
from uq.pipeline.yamlfile import read_yaml
from .overrides import SCENARIO_SEPARATOR, load_lidar_scenario, split_overrides

TOP_KEYS = ("name", "description", "instruments", "comparisons", "smc", "classification",
            "bins", "kpi", "synthetic")
INSTRUMENT_KEYS = ("file", "time", "heights", "environment", "calibration", "class_number",
                   "scenario", "campaign")
#: The keys a ``campaign`` instrument takes: its records are those of a ``uq campaign``
#: results file (its heights, speeds and the TI corrected for the platform's motion).
CAMPAIGN_INSTRUMENT_KEYS = ("campaign", "calibration", "class_number")
TURBULENCE_KEYS = ("variable", "bands")
HEIGHT_KEYS = ("speed", "direction", "environment")
CLASSIFICATION_KEYS = ("variables", "significance", "ranges", "route")
ROUTES = ("per_variable", "class_number")
SYNTHETIC_KEYS = ("truth", "verification", "smc", "lidars", "mast", "scans_per_record",
                  "site_separation", "direction_separation", "outage", "seed")


@dataclass(frozen=True)
class Instrument:
    """One instrument's records: a file, its time column and its columns per height.

    ``heights`` maps a height [m] to ``{"speed": column, "direction": column or None,
    "environment": {variable: column}}``; ``environment`` holds the columns common to
    all heights (a height's own entry wins). With ``campaign`` the file is a ``uq
    campaign`` results file, which gives the heights and variables itself. ``calibration`` (absolute [m s-1], relative
    [1]) and ``class_number`` [%] are given for a reference that is not itself verified
    in this configuration (a mast)."""

    name: str
    file: Path
    time: str
    heights: dict
    environment: dict
    calibration: tuple = None
    class_number: float = None
    scenario: object = None
    campaign: bool = False


@dataclass(frozen=True)
class GoldenConfig:
    """A validated ``golden`` section (see the module docstring)."""

    name: str
    source: str
    description: str = ""
    instruments: dict = field(default_factory=dict)
    comparisons: tuple = ()
    smc: Instrument = None
    variables: tuple = ()
    significance: float = GOLDEN_SIGNIFICANCE
    ranges: dict = field(default_factory=dict)
    route: str = "per_variable"
    bin_width: float = GOLDEN_BIN_WIDTH
    required: tuple = GOLDEN_REQUIRED_RANGE
    minimum_records: int = GOLDEN_MIN_RECORDS
    availability: tuple = KPI_AVAILABILITY
    synthetic: dict = None
    ti_variable: str = "turbulence_intensity"
    ti_bands: dict = field(default_factory=dict)


def load_golden_config(path, overrides=None):
    """Read and validate a ``uq golden`` configuration file.

    Parameters
    ----------
    path : str or pathlib.Path
    overrides : dict, optional
        ``uq golden --set`` (:func:`split_overrides`): ``{dotted: value}`` of the
        configuration's own keys (``golden.bins.width``), and ``{NAME:dotted: value}`` of
        the uq scenario its lidar NAME names (``unit:lidar.height``; NAME is a role of
        ``golden.synthetic.lidars``, or an instrument, or ``smc``, with a ``scenario``).
        A value of None removes the key (``--unset``), as in ``uq run``.
    """
    from uq.pipeline.scenario import apply_overrides, blame_override
    path = Path(path)
    raw = read_yaml(path, kind="a YAML golden configuration")
    check = Checker(str(path))
    if not isinstance(raw, dict) or "golden" not in raw:
        check.fail("golden", "missing; allowed: a mapping under the top-level key 'golden'")
    own, scenarios = split_overrides(overrides or {})
    apply_overrides(raw, own, str(path))
    _known_scenarios(check, raw["golden"], scenarios)
    try:
        check.keys(raw, "", ("golden",))
        return validate_golden(raw["golden"], check, path.parent, scenarios)
    except ScenarioError as error:
        raise blame_override(error, own) from None


def scenario_names(raw):
    """The names of the uq scenarios a ``golden`` mapping names: the roles of a synthetic
    campaign's lidars, else the instruments (and ``smc``) with a ``scenario``."""
    if not isinstance(raw, dict):
        return []
    if isinstance(raw.get("synthetic"), dict):
        lidars = raw["synthetic"].get("lidars")
        return list(lidars) if isinstance(lidars, dict) else []
    named = {**(raw.get("instruments") if isinstance(raw.get("instruments"), dict) else {}),
             "smc": raw.get("smc")}
    return [name for name, spec in named.items() if isinstance(spec, dict) and
            spec.get("scenario") is not None]


def _known_scenarios(check, raw, scenarios):
    """Refuse an override of a scenario the configuration does not name."""
    names = scenario_names(raw)
    for name, keys in scenarios.items():
        if name not in names:
            check.fail(f"--set {name}{SCENARIO_SEPARATOR}{next(iter(keys))}",
                       "no lidar scenario "
                       f"named {name!r} in this configuration; allowed: "
                       f"{', '.join(names) or 'none (it names no scenario)'} before "
                       f"'{SCENARIO_SEPARATOR}'")


def validate_golden(raw, check, base, scenarios=None):
    """A :class:`GoldenConfig` from the ``golden`` mapping; relative files are read from
    `base`; `scenarios` the overrides of its lidars' scenarios by name
    (:func:`split_overrides`)."""
    scenarios = scenarios or {}
    check.mapping(raw, "golden")
    check.keys(raw, "golden", TOP_KEYS)
    settings = {"name": check_name(raw.get("name", "golden"), check.source, "golden.name"),
                "source": check.source,
                "description": check.text(raw.get("description", ""), "golden.description")}
    settings.update(_bins(check, raw.get("bins") or {}))
    settings.update(_classification(check, raw.get("classification") or {}))
    settings["availability"] = _availability(check, raw.get("kpi") or {})
    settings.update(_turbulence(check, (raw.get("kpi") or {}).get("turbulence") or {}))
    if "synthetic" in raw:
        for key in ("instruments", "comparisons", "smc"):
            if key in raw:
                check.fail(f"golden.{key}", "not allowed with golden.synthetic (the synthetic "
                           "campaign generates its instruments); allowed: one of the two")
        settings["synthetic"] = _synthetic(check, raw["synthetic"], scenarios)
        return GoldenConfig(**settings)
    for key in ("instruments", "comparisons"):
        if key not in raw:
            check.fail(f"golden.{key}", "missing; allowed: data files and comparisons, or a "
                       "'synthetic' section")
    check.mapping(raw["instruments"], "golden.instruments")
    instruments = {name: _instrument(check, spec, f"golden.instruments.{name}", name, base,
                                     scenarios)
                   for name, spec in raw["instruments"].items()}
    settings["instruments"] = instruments
    settings["comparisons"] = _comparisons(check, raw["comparisons"], instruments)
    if "smc" in raw:
        settings["smc"] = _instrument(check, raw["smc"], "golden.smc", "smc", base, scenarios)
    _references_are_calibrated(check, settings["comparisons"], instruments)
    return GoldenConfig(**settings)


def _instrument(check, spec, key, name, base, scenarios=None):
    check.mapping(spec, key)
    check.keys(spec, key, INSTRUMENT_KEYS)
    if "campaign" in spec:
        return _campaign_instrument(check, spec, key, name, base)
    for needed in ("file", "heights"):
        if needed not in spec:
            check.fail(f"{key}.{needed}", "missing")
    heights = {}
    check.mapping(spec["heights"], f"{key}.heights")
    for height, columns in spec["heights"].items():
        where = f"{key}.heights.{height}"
        value = check.number(height, where, low=0.0, low_open=True)
        check.mapping(columns, where)
        check.keys(columns, where, HEIGHT_KEYS)
        if "speed" not in columns:
            check.fail(f"{where}.speed", "missing; allowed: the column of the wind speed [m s-1]")
        heights[value] = {"speed": check.text(columns["speed"], f"{where}.speed"),
                          "direction": _optional_text(check, columns.get("direction"),
                                                      f"{where}.direction"),
                          "environment": _columns(check, columns.get("environment") or {},
                                                  f"{where}.environment")}
    calibration = None
    if "calibration" in spec:
        cal = spec["calibration"]
        check.mapping(cal, f"{key}.calibration")
        check.keys(cal, f"{key}.calibration", ("absolute", "relative"))
        calibration = (check.number(cal.get("absolute", 0.0), f"{key}.calibration.absolute",
                                    low=0.0),
                       check.number(cal.get("relative", 0.0), f"{key}.calibration.relative",
                                    low=0.0))
    class_number = spec.get("class_number")
    if class_number is not None:
        class_number = check.number(class_number, f"{key}.class_number", low=0.0)
    scenario = None
    if spec.get("scenario") is not None:         # the lidar's uq scenario: predicted TI
        scenario = load_lidar_scenario(base / check.text(spec["scenario"], f"{key}.scenario"),
                                       name, scenarios or {})
    return Instrument(name=name, file=base / check.text(spec["file"], f"{key}.file"),
                      scenario=scenario,
                      time=check.text(spec.get("time", "time"), f"{key}.time"),
                      heights=heights,
                      environment=_columns(check, spec.get("environment") or {},
                                           f"{key}.environment"),
                      calibration=calibration, class_number=class_number)


def _campaign_instrument(check, spec, key, name, base):
    """An instrument whose records are a ``uq campaign`` results file (``<name>.nc``):
    its heights, its speeds and directions, and as its TI the campaign's TI corrected for
    the platform's motion and the lidar's filtering (:func:`uq.golden.records.
    load_campaign_records`)."""
    for other in spec:
        if other not in CAMPAIGN_INSTRUMENT_KEYS:
            check.fail(f"{key}.{other}", "not allowed with campaign (the campaign's file "
                       f"gives the records); allowed: {', '.join(CAMPAIGN_INSTRUMENT_KEYS)}")
    calibration = None
    if "calibration" in spec:
        cal = spec["calibration"]
        check.mapping(cal, f"{key}.calibration")
        check.keys(cal, f"{key}.calibration", ("absolute", "relative"))
        calibration = tuple(check.number(cal.get(part, 0.0), f"{key}.calibration.{part}",
                                         low=0.0) for part in ("absolute", "relative"))
    class_number = spec.get("class_number")
    return Instrument(name=name, file=base / check.text(spec["campaign"], f"{key}.campaign"),
                      time="time", heights={}, environment={}, calibration=calibration,
                      class_number=None if class_number is None else check.number(
                          class_number, f"{key}.class_number", low=0.0),
                      campaign=True)


def _columns(check, value, key):
    check.mapping(value, key)
    return {name: check.text(column, f"{key}.{name}") for name, column in value.items()}


def _optional_text(check, value, key):
    return None if value is None else check.text(value, key)


def _comparisons(check, value, instruments):
    items = check.list(value, "golden.comparisons")
    pairs = []
    for i, item in enumerate(items):
        key = f"golden.comparisons[{i}]"
        check.mapping(item, key)
        check.keys(item, key, ("unit", "reference"))
        pair = tuple(check.choice(item.get(role), f"{key}.{role}", tuple(instruments))
                     for role in ("unit", "reference"))
        if pair[0] == pair[1]:
            check.fail(key, "unit and reference are the same instrument; allowed: two "
                       "different instruments")
        pairs.append(pair)
    if not pairs:
        check.fail("golden.comparisons", "empty; allowed: at least one {unit, reference}")
    return tuple(pairs)


def _references_are_calibrated(check, comparisons, instruments):
    """A reference is calibrated by a stated uncertainty or by being the unit of exactly
    one comparison (the golden-lidar chain); loops are not allowed."""
    verified = {}
    for unit, reference in comparisons:
        verified.setdefault(unit, []).append(reference)
    for _, reference in comparisons:
        stated = instruments[reference].calibration is not None
        count = len(verified.get(reference, []))
        if not stated and count != 1:
            check.fail(f"golden.instruments.{reference}.calibration", "a reference needs a "
                       "stated calibration {absolute, relative} or exactly one comparison in "
                       f"which it is the unit (it has {count})")
        if stated and count:
            check.fail(f"golden.instruments.{reference}.calibration", "given, but the "
                       "instrument is also verified here; allowed: one of the two")
    for unit in verified:
        seen, node = {unit}, unit
        while node in verified and instruments[node].calibration is None:
            node = verified[node][0]
            if node in seen:
                check.fail("golden.comparisons", f"the chain of references loops at {node}")
            seen.add(node)


def _bins(check, raw):
    check.mapping(raw, "golden.bins")
    check.keys(raw, "golden.bins", ("width", "required", "minimum_records"))
    required = check.number_list(raw.get("required", list(GOLDEN_REQUIRED_RANGE)),
                                 "golden.bins.required", low=0.0, high=GOLDEN_MAX_SPEED)
    if len(required) != 2 or required[0] > required[1]:
        check.fail("golden.bins.required", "allowed: [low, high] bin centres, low <= high")
    width = check.number(raw.get("width", GOLDEN_BIN_WIDTH), "golden.bins.width", low=0.0,
                         low_open=True, high=GOLDEN_MAX_SPEED)
    if GOLDEN_MAX_SPEED / width > GOLDEN_MAX_BINS:
        check.fail("golden.bins.width", f"{width:g} m/s makes more than {GOLDEN_MAX_BINS} "
                   f"bins from 0 to {GOLDEN_MAX_SPEED:g} m/s; allowed: at least "
                   f"{GOLDEN_MAX_SPEED / GOLDEN_MAX_BINS:g} m/s")
    return {"bin_width": width, "required": tuple(required),
            "minimum_records": check.integer(raw.get("minimum_records", GOLDEN_MIN_RECORDS),
                                             "golden.bins.minimum_records", low=1)}


def _classification(check, raw):
    check.mapping(raw, "golden.classification")
    check.keys(raw, "golden.classification", CLASSIFICATION_KEYS)
    variables = [check.text(v, f"golden.classification.variables[{i}]") for i, v in
                 enumerate(check.list(raw.get("variables", []),
                                      "golden.classification.variables"))]
    ranges = {}
    for name, pair in (raw.get("ranges") or {}).items():
        values = check.number_list(pair, f"golden.classification.ranges.{name}")
        if len(values) != 2 or values[0] >= values[1]:
            check.fail(f"golden.classification.ranges.{name}", "allowed: [low, high], low < high")
        ranges[name] = tuple(values)
    return {"variables": tuple(variables), "ranges": ranges,
            "significance": check.number(raw.get("significance", GOLDEN_SIGNIFICANCE),
                                         "golden.classification.significance", low=0.0,
                                         high=1.0, low_open=True, high_open=True),
            "route": check.choice(raw.get("route", "per_variable"),
                                  "golden.classification.route", ROUTES)}


def _availability(check, raw):
    check.mapping(raw, "golden.kpi")
    check.keys(raw, "golden.kpi", ("availability", "turbulence"))
    values = check.number_list(raw.get("availability", list(KPI_AVAILABILITY)),
                               "golden.kpi.availability", low=0.0, high=1.0)
    if len(values) != 2 or values[0] < values[1]:
        check.fail("golden.kpi.availability", "allowed: [best, minimum], best >= minimum")
    return tuple(values)


def _turbulence(check, raw):
    """``golden.kpi.turbulence``: the environmental variable holding each instrument's TI
    [%] and optional ``[best, minimum]`` bands of the TI KPIs (:mod:`uq.golden.turbulence`;
    without a band a KPI is informational)."""
    from .turbulence import TI_KPIS
    key = "golden.kpi.turbulence"
    check.mapping(raw, key)
    check.keys(raw, key, TURBULENCE_KEYS)
    bands = raw.get("bands") or {}
    check.mapping(bands, f"{key}.bands")
    check.keys(bands, f"{key}.bands", tuple(TI_KPIS))
    out = {}
    for name, pair in bands.items():
        values = check.number_list(pair, f"{key}.bands.{name}", low=0.0)
        if len(values) != 2 or values[0] > values[1]:
            check.fail(f"{key}.bands.{name}", "allowed: [best, minimum] bounds of the "
                       "absolute value, 0 <= best <= minimum")
        out[name] = tuple(values)
    return {"ti_variable": check.text(raw.get("variable", "turbulence_intensity"),
                                      f"{key}.variable"), "ti_bands": out}


def _synthetic(check, raw, scenarios=None):
    from .campaign import validate_synthetic
    check.mapping(raw, "golden.synthetic")
    check.keys(raw, "golden.synthetic", SYNTHETIC_KEYS)
    return validate_synthetic(check, raw, scenarios or {})


def fail(source, key, problem):
    """Raise the one-line bad-input error (file, key, what is allowed)."""
    raise ScenarioError(source, key, problem)
