"""Reading 10-min records of one instrument (CSV or netCDF) into a Dataset, with the
checks that catch the usual mistakes.

The result has dimensions ``time`` and ``height`` [m] and variables ``speed`` [m s-1],
``direction`` [deg, clockwise from north, "from", in [0, 360)] and one variable per
environmental variable. Values that are not numbers become NaN and are counted in the
attribute ``n_invalid``; nothing is dropped silently.

Checks (each a one-line :class:`uq.errors.DataFileError` naming the file and the key):
missing file or column, unreadable or repeated timestamps, records not 10 min apart,
negative speeds or speeds that look like km/h or knots, directions outside [-360, 360] or
that look like radians.
"""
import warnings

import numpy as np
import pandas as pd
import xarray as xr

from uq.constants import (FULL_CIRCLE_DEG, GOLDEN_MAX_SPEED, MAX_RECORD_BYTES,
                          MAX_RECORD_ROWS)
from uq.errors import DataFileError
from uq.pipeline.inputfile import check_regular, read_csv

RECORD_MINUTES = 10
#: What a table of records is, in messages about the file.
RECORDS_KIND = "a UTF-8 CSV file of 10-min records"
#: Largest plausible median 10-min wind speed [m s-1]: a median above this is a unit
#: mistake (km/h is 3.6 times m/s, knots 1.94 times; 25 m/s is a gale's mean).
MAX_MEDIAN_SPEED = 25.0
#: Directions all within [-2 pi, 2 pi] with at least this spread [deg-or-rad] are radians.
RADIAN_SPREAD = 1.0
#: Largest ratio of a column's median speed to that of an instrument's other heights taken
#: as the same unit [1]: shear between measured heights stays below 2 (power law, exponent
#: 0.4 over a factor 5 in height: 1.9); km/h is 3.6 times m/s.
HEIGHT_RATIO = 2.5
#: Largest ratio of the concurrent speeds of two instruments at one height taken as the
#: same unit [1]: they agree within a few per cent; knots are 1.94 times m/s, km/h 3.6.
UNIT_RATIO = 1.5


def read_table(instrument):
    """The file's table (pandas) with a DatetimeIndex named ``time``."""
    path, source = instrument.file, str(instrument.file)
    table = _read(path, source, instrument.name)
    key = f"instruments.{instrument.name}.time"
    if instrument.time not in table.columns:
        raise DataFileError(source, key, f"no column {instrument.time!r}; allowed: "
                            f"{_listing(table.columns)}")
    if table.empty:
        raise DataFileError(source, f"instruments.{instrument.name}.file", "no records (a "
                            f"header only); allowed: {RECORDS_KIND}")
    time = _times(table[instrument.time], source, key)
    table.attrs["zoned"] = int(time.dt.tz is not None)
    table.index = pd.DatetimeIndex(time.dt.tz_convert(None) if table.attrs["zoned"] else time,
                                   name="time")
    _check_times(table.index, source, key)
    return table


def _times(column, source, key):
    """The timestamps of `column` (all with a time zone, or all without)."""
    with warnings.catch_warnings():      # pandas warns when it parses element by element
        warnings.simplefilter("ignore", UserWarning)
        try:
            time = pd.to_datetime(column, errors="coerce")
        except ValueError:               # "Mixed timezones detected"
            raise DataFileError(source, key, f"timestamps in different time zones "
                                f"({_zones(column)}); allowed: one time zone per file"
                                ) from None
    if time.isna().any():
        row = int(np.flatnonzero(time.isna())[0])
        raise DataFileError(source, key, f"timestamp {column.iloc[row]!r} (row {row + 1}) is "
                            "not a date and time, or not in the time zone of the first one; "
                            "allowed: dates and times, all in one time zone")
    return time


def _zones(column):
    """The first two different time-zone suffixes of `column` and their rows, as text."""
    zones = column.astype(str).str.extract(r"(Z|[+-]\d\d:?\d\d)\s*$")[0].fillna("none")
    first = zones.iloc[0]
    other = int(np.flatnonzero(zones.to_numpy() != first)[0])
    return f"{first} in row 1, {zones.iloc[other]} in row {other + 1}"


def _read(path, source, name):
    """The file as a pandas table; DataFileError if it is not a regular CSV (or netCDF)
    file within the bounds."""
    key = f"instruments.{name}.file"
    if path.suffix != ".nc":
        return read_csv(path, MAX_RECORD_BYTES, MAX_RECORD_ROWS, RECORDS_KIND, DataFileError,
                        key)
    check_regular(path, MAX_RECORD_BYTES, "a netCDF file of 10-min records", DataFileError,
                  key)
    try:
        with xr.open_dataset(path) as ds:
            return ds.to_dataframe().reset_index()
    except (OSError, ValueError) as error:
        reason = str(error).splitlines()[0][:120] if str(error) else type(error).__name__
        raise DataFileError(source, key, f"cannot read it as netCDF ({reason}); allowed: a "
                            "netCDF file of 10-min records") from None


#: The variables of a ``uq campaign`` results file an instrument takes
#: (:func:`load_campaign_records`): its name -> the campaign's, and the factor to the
#: units here (TI in percent).
CAMPAIGN_VARIABLES = {"speed": ("wind_speed_corrected", 1.0),
                      "direction": ("wind_direction", 1.0),
                      "turbulence_intensity": ("turbulence_intensity_corrected", 100.0)}


def load_records(instrument):
    """The instrument's records as a Dataset (see the module docstring)."""
    if instrument.campaign:
        return load_campaign_records(instrument)
    table = read_table(instrument)
    source, prefix = str(instrument.file), f"instruments.{instrument.name}.heights"
    heights = sorted(instrument.heights)
    data, invalid = {}, 0
    variables = _variables(instrument)
    for name in ("speed", "direction") + variables:
        columns = []
        for h in heights:
            column = _column_name(instrument, h, name)
            key = f"{prefix}.{h:g}.{name}" if name in ("speed", "direction") else \
                f"instruments.{instrument.name}.environment.{name}"
            values, bad = _numbers(table, column, source, key)
            invalid += bad
            columns.append(values)
        data[name] = (("time", "height"), np.stack(columns, axis=-1))
    ds = xr.Dataset(data, coords={"time": table.index.values, "height": heights})
    keys = {name: [_column_key(instrument, h, name) for h in heights]
            for name in ("speed", "direction")}
    _check_speed(ds["speed"].values, source, keys["speed"])
    ds["direction"] = _checked_direction(ds["direction"].values, source, keys["direction"])
    ds.attrs.update(instrument=instrument.name, file=source, n_invalid=invalid,
                    zoned=table.attrs["zoned"])
    return ds


def load_campaign_records(instrument):
    """The records of a ``uq campaign`` results file as an instrument's Dataset: the
    corrected mean speed [m s-1], the direction [deg] and, as ``turbulence_intensity``
    [%], the TI corrected for the platform's motion and the lidar's filtering (NaN where
    the campaign could not correct a record). Its time stamps are the periods' starts in
    UTC (a zone: the other instrument's stamps need one too)."""
    source, key = str(instrument.file), f"instruments.{instrument.name}.campaign"
    check_regular(instrument.file, MAX_RECORD_BYTES, "a uq campaign results file",
                  DataFileError, key)
    try:
        with xr.open_dataset(instrument.file) as ds:
            ds = ds.load()
    except (OSError, ValueError) as error:
        reason = str(error).splitlines()[0][:120] if str(error) else type(error).__name__
        raise DataFileError(source, key, f"cannot read it as netCDF ({reason}); allowed: "
                            "the <name>.nc of a uq campaign results folder") from None
    missing = [name for name, _ in CAMPAIGN_VARIABLES.values() if name not in ds]
    if missing or not str(ds.attrs.get("title", "")).startswith("uq campaign"):
        raise DataFileError(source, key, f"not a uq campaign results file (no "
                            f"{', '.join(missing) or 'uq campaign title'}); allowed: the "
                            "<name>.nc that 'uq campaign' writes")
    out = xr.Dataset({name: (("time", "height"), ds[variable].values * factor)
                      for name, (variable, factor) in CAMPAIGN_VARIABLES.items()},
                     coords={"time": ds["time"].values, "height": ds["height"].values})
    out.attrs.update(instrument=instrument.name, file=source, n_invalid=0, zoned=1,
                     campaign_motion=ds.attrs.get("motion", "none"),
                     campaign_filtering=ds.attrs.get("filtering", ""))
    return out


def align(unit, reference):
    """The two Datasets on their common timestamps and heights, and what was left out:
    ``(unit, reference, counts)`` with counts of records only in one of them. Raises
    when they share no timestamp or no height."""
    times = np.intersect1d(unit["time"].values, reference["time"].values)
    heights = np.intersect1d(unit["height"].values, reference["height"].values)
    names = f"{unit.attrs['instrument']} and {reference.attrs['instrument']}"
    if unit.attrs.get("zoned") != reference.attrs.get("zoned"):
        zoned = unit if unit.attrs.get("zoned") else reference
        raise DataFileError(unit.attrs["file"], "time", f"{names}: only "
                            f"{zoned.attrs['instrument']} gives its timestamps a time zone; "
                            "allowed: both with a time zone (compared in UTC) or both "
                            "without")
    if len(heights) == 0:
        raise DataFileError(unit.attrs["file"], "heights", f"{names} share no height "
                            f"({_heights(unit)} against {_heights(reference)})")
    if len(times) == 0:
        raise DataFileError(unit.attrs["file"], "time", f"{names} share no timestamp "
                            f"({_span(unit)} against {_span(reference)}); check the period "
                            "and the time zone")
    counts = {"only_unit": unit.sizes["time"] - len(times),
              "only_reference": reference.sizes["time"] - len(times)}
    pick = {"time": times, "height": heights}
    unit, reference = unit.sel(pick), reference.sel(pick)
    check_same_units(unit, reference)
    return unit, reference, counts


def _variables(instrument):
    names = set(instrument.environment)
    for columns in instrument.heights.values():
        names |= set(columns["environment"])
    return tuple(sorted(names))


def _column_name(instrument, height, name):
    columns = instrument.heights[height]
    if name in ("speed", "direction"):
        return columns[name]
    return columns["environment"].get(name, instrument.environment.get(name))


def _numbers(table, column, source, key):
    """A column as float (non-numbers -> NaN, counted); None -> all NaN."""
    if column is None:
        return np.full(len(table), np.nan), 0
    if column not in table.columns:
        raise DataFileError(source, key, f"no column {column!r}; allowed: "
                            f"{_listing(table.columns)}")
    values = pd.to_numeric(table[column], errors="coerce").to_numpy(dtype=float)
    bad = int(np.sum(np.isnan(values)) - np.sum(table[column].isna()))
    return values, bad


def _check_times(index, source, key):
    if index.has_duplicates:
        raise DataFileError(source, key, f"timestamp {index[index.duplicated()][0]} repeats; "
                            "allowed: one record per 10-min period")
    if len(index) > 1:
        steps = np.diff(index.sort_values().values) / np.timedelta64(1, "m")
        if np.median(steps) != RECORD_MINUTES:
            raise DataFileError(source, key, f"records are {np.median(steps):g} min apart "
                                "(median); allowed: 10-min records")


def _column_key(instrument, height, name):
    """``instruments.NAME.heights.H.speed (column 'ws')``: the key and the column."""
    return (f"instruments.{instrument.name}.heights.{height:g}.{name} (column "
            f"{_column_name(instrument, height, name)!r})")


def _check_speed(speed, source, keys):
    """Each column of `speed` (time, height) [m s-1] must look like m/s: not negative, a
    plausible median, no value above GOLDEN_MAX_SPEED, and not 3.6 times the other columns."""
    medians = []
    for column, key in zip(speed.T, keys):
        finite = column[np.isfinite(column)]
        if finite.size and finite.min() < 0:
            raise DataFileError(source, key, f"negative wind speed {finite.min():g}; allowed: "
                                "speeds >= 0 [m s-1]")
        if finite.size and finite.max() > GOLDEN_MAX_SPEED:
            raise DataFileError(source, key, f"wind speed {finite.max():g} (a code for a "
                                f"missing value?); allowed: m s-1, at most {GOLDEN_MAX_SPEED:g} "
                                "(leave a missing value empty)")
        medians.append(np.median(finite) if finite.size else np.nan)
        if finite.size and medians[-1] > MAX_MEDIAN_SPEED:
            raise DataFileError(source, key, f"median wind speed {medians[-1]:.1f} looks "
                                "like km/h or knots; allowed: m s-1")
    for i, key in enumerate(keys):
        others = np.delete(np.asarray(medians), i)
        others = others[np.isfinite(others) & (others > 0)]
        if others.size and medians[i] > HEIGHT_RATIO * np.median(others):
            raise DataFileError(source, key, f"median wind speed {medians[i]:.1f} is "
                                f"{medians[i] / np.median(others):.1f} times that of the "
                                "other heights: km/h (3.6 times m/s)? allowed: m s-1 in "
                                "every column")


def _checked_direction(direction, source, keys):
    """Directions (time, height) [deg] checked column by column, wrapped into [0, 360)."""
    for column, key in zip(direction.T, keys):
        finite = column[np.isfinite(column)]
        outside = finite[np.abs(finite) > FULL_CIRCLE_DEG]
        if outside.size:
            raise DataFileError(source, key, f"direction {outside[0]:g} is out of range; "
                                "allowed: degrees in [-360, 360]")
        if finite.size > 1 and np.abs(finite).max() <= 2 * np.pi \
                and np.ptp(finite) > RADIAN_SPREAD:
            raise DataFileError(source, key, f"directions span {finite.min():.2f} to "
                                f"{finite.max():.2f}: radians? allowed: degrees")
    return (("time", "height"), np.mod(direction, FULL_CIRCLE_DEG))


def check_same_units(unit, reference):
    """Refuse a pair whose concurrent speeds differ by a unit factor at a height: the
    median ratio outside [1/UNIT_RATIO, UNIT_RATIO] (km/h is 3.6 times m/s, knots 1.94;
    two instruments at one height agree within a few per cent)."""
    for h in unit["height"].values:
        a, b = unit["speed"].sel(height=h).values, reference["speed"].sel(height=h).values
        both = np.isfinite(a) & np.isfinite(b) & (a > 0) & (b > 0)
        if not both.any():
            continue
        ratio = float(np.median(a[both] / b[both]))
        if 1 / UNIT_RATIO <= ratio <= UNIT_RATIO:
            continue
        big, small = (unit, reference) if ratio > 1 else (reference, unit)
        raise DataFileError(big.attrs["file"], f"instruments.{big.attrs['instrument']}."
                            f"heights.{h:g}.speed", f"concurrent speeds are "
                            f"{max(ratio, 1 / ratio):.2f} times those of "
                            f"{small.attrs['instrument']} at {h:g} m (median ratio): km/h "
                            "(3.6) or knots (1.94)? allowed: m s-1 in every file")


def _listing(columns):
    """Column names for a one-line message (control characters and newlines shown)."""
    names = [repr(str(c))[1:-1][:40] for c in columns]
    return ", ".join(names[:12]) + (", ..." if len(names) > 12 else "")


def _heights(ds):
    return ", ".join(f"{h:g}" for h in ds["height"].values) + " m"


def _span(ds):
    return f"{str(ds['time'].values[0])[:16]}..{str(ds['time'].values[-1])[:16]}"
