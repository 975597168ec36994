"""The ``uq campaign`` configuration: the lidar, the turbulence model, the records, the
platform's motion and the reference of a campaign, validated once.

A configuration is a YAML file with one top-level key ``campaign`` (the shipped example
``scenarios/campaign_buoy.yaml``)::

    campaign:
      name: my_buoy                      # names the output folder and <name>.nc
      description: ...
      lidar: my_lidar.yaml               # a uq scenario: geometry, probe, scan timing,
                                         # INS, errors, lever arm, heading, shear and the
                                         # correction its firmware applies (upward lidar)
      turbulence: {length_scale: 33.6, anisotropy: 3.9}   # Mann; default IEC 61400-1:
                                         # L = 0.8 Lambda_1 at each height, Gamma 3.9
      filtering: spectral                # spectral: to the point's TI | none: motion only
      records:                           # the lidar's ten-minute records (CSV or netCDF)
        file: lidar.csv
        time: Timestamp                  # column of the time stamps
        time_zone: "+01:00"              # of stamps without one: UTC, +hh:mm or an IANA name
        stamp: end                       # start | end: the end of the 10 min it marks
        std_ddof: 1                      # the standard deviation over N - ddof
        units: {speed: m/s, direction: deg, availability: percent}
        minimum_availability: 80         # [units of availability]
        heading: Heading                 # optional column: the lidar's heading [deg]
        heights:
          40: {speed: WS40, std: WS40_SD, direction: WD40, availability: AV40}
      motion:                            # absent: no motion (a fixed lidar)
        kind: sea_state                  # sea_state | statistics | imu
        file: waves.csv                  # with time, time_zone, stamp as the records'
        columns: {hs: Hm0, tp: Tp}
        spectrum: {gamma: 3.3, components: 24, band: [0.5, 4.0]}   # band in 1/Tp
        response:                        # per metre of wave amplitude, lag in deg
          roll: {factor: 4.0, lag: 90}
      reference:                         # optional: a reference TI per record
        file: mast.csv
        heights: {40: {ti: TI40}}        # or {speed: ..., std: ...}
        units: {ti: percent}
      bins: {width: 0.5, required: [4.0, 16.0], minimum_records: 6}   # as uq golden's
      coverage: 0.95
      uncertainty: {filtering: 0.0, motion: 0.0}  # relative u of F and of V_m
      minimum_speed: 2.0                 # [m s-1]

``statistics`` motion: ``columns: {roll: {std: ROLL_SD, period: ROLL_T}, heave:
{amplitude: HEAVE_A, period: HEAVE_T}}`` and ``units: {angle: deg, length: m}``.
``imu`` motion: a log of the platform's attitude and displacement
(:mod:`uq.campaign.imu`), ``time`` as time stamps (``time_unit: timestamp``, in
``time_zone``) or seconds since 1970-01-01 UTC (``time_unit: unix``), ``rate`` [Hz] its
nominal sampling, ``columns: {roll: ..., pitch: ..., heave: ...}``, ``units``.

Bad input raises :class:`uq.errors.ScenarioError` naming the file, the key and what is
allowed; files are read later (:mod:`uq.campaign.recordsfile`,
:mod:`uq.campaign.motioninput`), their problems naming the file and the column.
"""
import dataclasses
import re
from pathlib import Path

import yaml

from uq.constants import (CAMPAIGN_MIN_SPEED, COVERAGE_PROBABILITY, GOLDEN_BIN_WIDTH,
                          GOLDEN_MAX_BINS, GOLDEN_MAX_SPEED, GOLDEN_MIN_RECORDS,
                          GOLDEN_REQUIRED_RANGE, MANN_ANISOTROPY, MAX_ANISOTROPY,
                          MAX_LENGTH_SCALE, MAX_WAVE_COMPONENTS)
from uq.files import check_name
from uq.physics.motion import DEGREES_OF_FREEDOM

TOP_KEYS = ("name", "description", "lidar", "turbulence", "filtering", "records", "motion",
            "reference", "bins", "coverage", "uncertainty", "minimum_speed")
FILTERINGS = ("spectral", "none")
TABLE_KEYS = ("file", "time", "time_zone", "stamp")
STAMPS = ("start", "end")
RECORD_KEYS = TABLE_KEYS + ("heights", "units", "std_ddof", "minimum_availability",
                            "heading")
RECORD_COLUMNS = ("speed", "std", "direction", "availability")
#: Units a file may give, and their factor to the one used inside (m s-1, deg, 1).
SPEED_UNITS = {"m/s": 1.0, "km/h": 1.0 / 3.6, "kn": 1852.0 / 3600.0}
DIRECTION_UNITS = {"deg": 1.0, "rad": 57.29577951308232}
FRACTION_UNITS = {"percent": 0.01, "fraction": 1.0}
ANGLE_UNITS = {"deg": 0.017453292519943295, "rad": 1.0}
LENGTH_UNITS = {"m": 1.0, "cm": 0.01}
MOTION_KINDS = ("sea_state", "statistics", "imu")
MOTION_KEYS = TABLE_KEYS + ("kind", "columns", "spectrum", "response", "units", "rate",
                            "time_unit")
SPECTRUM_KEYS = ("gamma", "components", "band")
STATISTIC_KEYS = ("std", "amplitude", "period")
TIME_UNITS = ("unix", "timestamp")
REFERENCE_KEYS = TABLE_KEYS + ("heights", "units")
#: Default JONSWAP settings of a sea-state motion (as uq's ``motion.spectrum``).
SPECTRUM_DEFAULTS = {"gamma": 3.3, "components": 24, "band": [0.5, 4.0]}
#: Largest rate of an IMU log [Hz] (a buoy's motion package logs 1-20 Hz; 100 Hz keeps a
#: ten-minute record's FFT at 60000 samples).
MAX_IMU_RATE = 100.0


@dataclasses.dataclass(frozen=True)
class TableSpec:
    """A table of time-stamped rows: its file, time column and time conventions."""

    file: Path
    key: str                    # the configuration key, for messages
    time: str = "time"
    time_zone: str = "UTC"
    stamp: str = "start"


@dataclasses.dataclass(frozen=True)
class RecordsSpec:
    table: TableSpec
    heights: dict               # height -> {speed, std, direction, availability}
    units: dict
    ddof: int = 1
    minimum_availability: float = 0.0
    heading: str = None


@dataclasses.dataclass(frozen=True)
class MotionSpec:
    kind: str
    table: TableSpec
    columns: dict
    units: dict
    spectrum: dict = None
    response: dict = None
    rate: float = None
    time_unit: str = "timestamp"


@dataclasses.dataclass(frozen=True)
class ReferenceSpec:
    table: TableSpec
    heights: dict               # height -> {ti} or {speed, std}
    units: dict


@dataclasses.dataclass(frozen=True)
class CampaignConfig:
    """A validated ``campaign`` section (module docstring)."""

    name: str
    source: str
    lidar: object               # uq.pipeline.scenario.Scenario
    records: RecordsSpec
    description: str = ""
    length_scale: float = None  # None: IEC 61400-1 at each height
    anisotropy: float = MANN_ANISOTROPY
    filtering: str = "spectral"
    motion: MotionSpec = None
    reference: ReferenceSpec = None
    bin_width: float = GOLDEN_BIN_WIDTH
    required: tuple = GOLDEN_REQUIRED_RANGE
    minimum_records: int = GOLDEN_MIN_RECORDS
    coverage: float = COVERAGE_PROBABILITY
    filtering_u: float = 0.0
    motion_u: float = 0.0
    minimum_speed: float = CAMPAIGN_MIN_SPEED
    text: str = ""              # the configuration's YAML as read

    @property
    def heights(self):
        return tuple(sorted(self.records.heights))


def load_campaign_config(path):
    """Read and validate a ``uq campaign`` configuration file."""
    from uq.pipeline.scenario import Checker
    from uq.pipeline.yamlfile import read_yaml
    path = Path(path)
    raw = read_yaml(path, kind="a YAML campaign configuration")
    check = Checker(str(path))
    if not isinstance(raw, dict) or "campaign" not in raw:
        check.fail("campaign", "missing; allowed: a mapping under the top-level key "
                   "'campaign'")
    check.keys(raw, "", ("campaign",))
    config = validate_campaign(raw["campaign"], check, path.parent)
    return dataclasses.replace(config, text=yaml.safe_dump(raw, sort_keys=False))


def validate_campaign(raw, check, base):
    """A :class:`CampaignConfig` from the ``campaign`` mapping; files relative to `base`."""
    check.mapping(raw, "campaign")
    check.keys(raw, "campaign", TOP_KEYS)
    check.required(raw, "campaign", ("lidar", "records"), "a campaign needs its lidar's "
                   "scenario and its records")
    settings = {"name": check_name(raw.get("name", "campaign"), check.source,
                                   "campaign.name"),
                "source": check.source,
                "description": check.text(raw.get("description", ""), "campaign.description"),
                "lidar": _lidar(check, raw["lidar"], base),
                "records": _records(check, raw["records"], base),
                "filtering": check.choice(raw.get("filtering", "spectral"),
                                          "campaign.filtering", FILTERINGS)}
    settings.update(_turbulence(check, raw.get("turbulence") or {}))
    if raw.get("motion") is not None:
        settings["motion"] = _motion(check, raw["motion"], base)
    if raw.get("reference") is not None:
        settings["reference"] = _reference(check, raw["reference"], base)
    settings.update(_bins(check, raw.get("bins") or {}))
    settings["coverage"] = check.number(raw.get("coverage", COVERAGE_PROBABILITY),
                                        "campaign.coverage", low=0.0, high=1.0,
                                        low_open=True, high_open=True)
    uncertainty = raw.get("uncertainty") or {}
    check.mapping(uncertainty, "campaign.uncertainty")
    check.keys(uncertainty, "campaign.uncertainty", ("filtering", "motion"))
    settings["filtering_u"] = check.number(uncertainty.get("filtering", 0.0),
                                           "campaign.uncertainty.filtering", low=0.0, high=1.0)
    settings["motion_u"] = check.number(uncertainty.get("motion", 0.0),
                                        "campaign.uncertainty.motion", low=0.0, high=1.0)
    settings["minimum_speed"] = check.number(raw.get("minimum_speed", CAMPAIGN_MIN_SPEED),
                                             "campaign.minimum_speed", low=0.0,
                                             low_open=True, high=GOLDEN_MAX_SPEED)
    return CampaignConfig(**settings)


def _lidar(check, value, base):
    """The lidar's scenario (a file relative to the configuration), an upward lidar."""
    from uq.pipeline.scenario import load_scenario
    path = base / check.text(value, "campaign.lidar")
    scenario = load_scenario(path)
    if "mount" in scenario.settings["lidar"] and scenario.settings["lidar"]["mount"]["tilt"]:
        check.fail("campaign.lidar", f"{path} is a tilted (nacelle) lidar; allowed: an "
                   "upward-looking lidar's scenario (its gates at heights)")
    if scenario.sweep:
        check.fail("campaign.lidar", f"{path} sweeps {', '.join(k for k, _ in scenario.sweep)}"
                   "; allowed: one lidar (no sweep)")
    return scenario


def _table(check, raw, key, base):
    check.required(raw, key, ("file",), "allowed: the file's path, relative to the "
                   "configuration")
    zone = check.text(raw.get("time_zone", "UTC"), f"{key}.time_zone")
    time_zone(zone, check, f"{key}.time_zone")
    return TableSpec(file=base / check.text(raw["file"], f"{key}.file"), key=key,
                     time=check.text(raw.get("time", "time"), f"{key}.time"),
                     time_zone=zone,
                     stamp=check.choice(raw.get("stamp", "start"), f"{key}.stamp", STAMPS))


def time_zone(text, check=None, key=""):
    """A tzinfo of ``UTC``, ``+hh:mm`` / ``-hh:mm`` or an IANA name (``Europe/Oslo``)."""
    import datetime
    import zoneinfo
    if text.upper() in ("UTC", "Z", "GMT"):
        return datetime.timezone.utc
    found = re.fullmatch(r"(?:UTC)?([+-])(\d{1,2}):?(\d{2})", text.strip())
    if found:
        sign = 1 if found.group(1) == "+" else -1
        hours, minutes = int(found.group(2)), int(found.group(3))
        if hours <= 14 and minutes < 60:
            return datetime.timezone(sign * datetime.timedelta(hours=hours, minutes=minutes))
    else:
        try:
            return zoneinfo.ZoneInfo(text)
        except (zoneinfo.ZoneInfoNotFoundError, ValueError):
            pass
    if check is not None:
        check.fail(key, f"{text!r} is not a time zone; allowed: UTC, an offset such as "
                   "+01:00, or an IANA name such as Europe/Oslo")
    raise ValueError(text)


def _records(check, raw, base):
    key = "campaign.records"
    check.mapping(raw, key)
    check.keys(raw, key, RECORD_KEYS)
    check.required(raw, key, ("file", "heights"), "the records need their file and the "
                   "columns of each height")
    heights = {}
    check.mapping(raw["heights"], f"{key}.heights")
    if not raw["heights"]:
        check.fail(f"{key}.heights", "empty; allowed: at least one height")
    for height, columns in raw["heights"].items():
        where = f"{key}.heights.{height}"
        value = check.number(height, where, low=0.0, low_open=True)
        check.mapping(columns, where)
        check.keys(columns, where, RECORD_COLUMNS)
        check.required(columns, where, ("speed", "std", "direction"), "allowed: the columns "
                       "of the mean speed, its standard deviation and the direction "
                       "(availability optional)")
        heights[value] = {name: check.text(columns[name], f"{where}.{name}")
                          for name in RECORD_COLUMNS if columns.get(name) is not None}
    units = _units(check, raw.get("units") or {}, f"{key}.units",
                   {"speed": SPEED_UNITS, "direction": DIRECTION_UNITS,
                    "availability": FRACTION_UNITS},
                   {"speed": "m/s", "direction": "deg", "availability": "percent"})
    minimum = check.number(raw.get("minimum_availability", 0.0),
                           f"{key}.minimum_availability", low=0.0)
    heading = raw.get("heading")
    return RecordsSpec(table=_table(check, raw, key, base), heights=heights, units=units,
                       ddof=check.integer(raw.get("std_ddof", 1), f"{key}.std_ddof", 0, 1),
                       minimum_availability=minimum * FRACTION_UNITS[units["availability"]],
                       heading=None if heading is None else check.text(heading,
                                                                       f"{key}.heading"))


def _units(check, raw, key, allowed, defaults):
    check.mapping(raw, key)
    check.keys(raw, key, tuple(allowed))
    return {name: check.choice(raw.get(name, defaults[name]), f"{key}.{name}",
                               tuple(allowed[name])) for name in allowed}


def _turbulence(check, raw):
    key = "campaign.turbulence"
    check.mapping(raw, key)
    check.keys(raw, key, ("model", "length_scale", "anisotropy"))
    check.choice(raw.get("model", "mann"), f"{key}.model", ("mann",))
    scale = raw.get("length_scale")
    return {"length_scale": None if scale is None else check.number(
                scale, f"{key}.length_scale", low=0.0, low_open=True, high=MAX_LENGTH_SCALE),
            "anisotropy": check.number(raw.get("anisotropy", MANN_ANISOTROPY),
                                       f"{key}.anisotropy", low=0.0, high=MAX_ANISOTROPY)}


def _motion(check, raw, base):
    key = "campaign.motion"
    check.mapping(raw, key)
    check.keys(raw, key, MOTION_KEYS)
    check.required(raw, key, ("kind", "file", "columns"), "allowed: the kind of motion "
                   f"({', '.join(MOTION_KINDS)}), its file and its columns")
    kind = check.choice(raw["kind"], f"{key}.kind", MOTION_KINDS)
    table = _table(check, raw, key, base)
    columns = raw["columns"]
    check.mapping(columns, f"{key}.columns")
    units = _units(check, raw.get("units") or {}, f"{key}.units",
                   {"angle": ANGLE_UNITS, "length": LENGTH_UNITS},
                   {"angle": "deg", "length": "m"})
    out = {"kind": kind, "table": table, "units": units}
    for extra in ("spectrum", "response", "rate", "time_unit"):
        if extra in raw and extra not in _MOTION_EXTRAS[kind]:
            check.fail(f"{key}.{extra}", f"does not apply to kind {kind}; allowed with "
                       f"{kind}: {', '.join(_MOTION_EXTRAS[kind]) or 'none of these'}")
    if kind == "sea_state":
        check.keys(columns, f"{key}.columns", ("hs", "tp"))
        check.required(columns, f"{key}.columns", ("hs", "tp"), "allowed: the columns of "
                       "the significant wave height [m] and the peak period [s]")
        out["columns"] = {c: check.text(columns[c], f"{key}.columns.{c}") for c in columns}
        out["spectrum"] = _spectrum(check, raw.get("spectrum") or {}, f"{key}.spectrum")
        check.required(raw, key, ("response",), "a sea state moves the buoy through its "
                       "response: allowed: response: {roll: {factor, lag}, ...}")
        out["response"] = _response(check, raw["response"], f"{key}.response")
    elif kind == "statistics":
        out["columns"] = _statistics(check, columns, f"{key}.columns")
    else:
        check.keys(columns, f"{key}.columns", DEGREES_OF_FREEDOM)
        if not columns:
            check.fail(f"{key}.columns", "empty; allowed: the column of at least one degree "
                       f"of freedom ({', '.join(DEGREES_OF_FREEDOM)})")
        out["columns"] = {d: check.text(columns[d], f"{key}.columns.{d}") for d in columns}
        check.required(raw, key, ("rate",), "allowed: the log's nominal sampling rate [Hz]")
        out["rate"] = check.number(raw["rate"], f"{key}.rate", low=0.0, low_open=True,
                                   high=MAX_IMU_RATE)
        out["time_unit"] = check.choice(raw.get("time_unit", "timestamp"), f"{key}.time_unit",
                                        TIME_UNITS)
    return MotionSpec(**out)


_MOTION_EXTRAS = {"sea_state": ("spectrum", "response"), "statistics": (),
                  "imu": ("rate", "time_unit")}


def _spectrum(check, raw, key):
    check.mapping(raw, key)
    check.keys(raw, key, SPECTRUM_KEYS)
    out = {**SPECTRUM_DEFAULTS, **raw}
    band = check.number_list(out["band"], f"{key}.band", low=0.0, low_open=True)
    if len(band) != 2 or not band[0] < band[1]:
        check.fail(f"{key}.band", "allowed: [lowest, highest] in multiples of the peak "
                   "frequency 1/Tp, lowest first")
    return {"gamma": check.number(out["gamma"], f"{key}.gamma", low=1.0, high=10.0),
            "components": check.integer(out["components"], f"{key}.components", low=1,
                                        high=MAX_WAVE_COMPONENTS),
            "band": tuple(band)}


def _response(check, raw, key):
    """The buoy's response (uq's ``motion.response`` validator): dof -> (factor, lag)."""
    from uq.pipeline.motionsection import validate_response
    if isinstance(raw, dict) and not raw:
        check.fail(key, "empty; allowed: the response of at least one degree of freedom")
    found = validate_response(check, raw, key)
    return {dof: (spec["factor"], spec["lag"]) for dof, spec in found.items()}


def _statistics(check, raw, key):
    check.keys(raw, key, DEGREES_OF_FREEDOM)
    if not raw:
        check.fail(key, "empty; allowed: the columns of at least one degree of freedom")
    out = {}
    for dof, spec in raw.items():
        where = f"{key}.{dof}"
        check.mapping(spec, where)
        check.keys(spec, where, STATISTIC_KEYS)
        if ("std" in spec) == ("amplitude" in spec) or "period" not in spec:
            check.fail(where, "allowed: {std: COLUMN, period: COLUMN} or {amplitude: "
                       "COLUMN, period: COLUMN}")
        out[dof] = {name: check.text(column, f"{where}.{name}") for name, column in spec.items()}
    return out


def _reference(check, raw, base):
    key = "campaign.reference"
    check.mapping(raw, key)
    check.keys(raw, key, REFERENCE_KEYS)
    check.required(raw, key, ("file", "heights"), "the reference needs its file and the "
                   "columns of each height")
    check.mapping(raw["heights"], f"{key}.heights")
    heights = {}
    for height, columns in raw["heights"].items():
        where = f"{key}.heights.{height}"
        value = check.number(height, where, low=0.0, low_open=True)
        check.mapping(columns, where)
        check.keys(columns, where, ("ti", "speed", "std"))
        if not ("ti" in columns) ^ ({"speed", "std"} <= set(columns)):
            check.fail(where, "allowed: {ti: COLUMN} or {speed: COLUMN, std: COLUMN}")
        heights[value] = {name: check.text(c, f"{where}.{name}") for name, c in columns.items()}
    units = _units(check, raw.get("units") or {}, f"{key}.units",
                   {"ti": FRACTION_UNITS, "speed": SPEED_UNITS},
                   {"ti": "percent", "speed": "m/s"})
    return ReferenceSpec(table=_table(check, raw, key, base), heights=heights, units=units)


def _bins(check, raw):
    key = "campaign.bins"
    check.mapping(raw, key)
    check.keys(raw, key, ("width", "required", "minimum_records"))
    required = check.number_list(raw.get("required", list(GOLDEN_REQUIRED_RANGE)),
                                 f"{key}.required", low=0.0, high=GOLDEN_MAX_SPEED)
    if len(required) != 2 or required[0] > required[1]:
        check.fail(f"{key}.required", "allowed: [low, high] bin centres, low <= high")
    width = check.number(raw.get("width", GOLDEN_BIN_WIDTH), f"{key}.width", low=0.0,
                         low_open=True, high=GOLDEN_MAX_SPEED)
    if GOLDEN_MAX_SPEED / width > GOLDEN_MAX_BINS:
        check.fail(f"{key}.width", f"{width:g} m/s makes more than {GOLDEN_MAX_BINS} bins; "
                   f"allowed: at least {GOLDEN_MAX_SPEED / GOLDEN_MAX_BINS:g} m/s")
    return {"bin_width": width, "required": tuple(required),
            "minimum_records": check.integer(raw.get("minimum_records", GOLDEN_MIN_RECORDS),
                                             f"{key}.minimum_records", low=1)}


def length_scales(config):
    """Mann's L [m] at each of the configuration's heights: the stated one, or IEC
    61400-1's 0.8 Lambda_1 (:func:`uq.pipeline.turbulencesection.default_length_scale`)."""
    from uq.campaign.adapter import default_length_scale
    return tuple(config.length_scale if config.length_scale is not None
                 else default_length_scale(h) for h in config.heights)
