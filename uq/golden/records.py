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

from uq.constants import FULL_CIRCLE_DEG
from uq.errors import DataFileError

RECORD_MINUTES = 10
#: Largest plausible median 10-min wind speed [m s-1]: a median above this is a unit
#: mistake (km/h is 3.6 times m/s, knots 1.94 times; 25 m/s is a gale's mean).
MAX_MEDIAN_SPEED = 25.0
#: Directions all within [0, 2 pi] with at least this spread [deg-or-rad] are radians.
RADIAN_SPREAD = 1.0


def read_table(instrument):
    """The file's table (pandas) with a DatetimeIndex named ``time``."""
    path, source = instrument.file, str(instrument.file)
    if not path.exists():
        raise DataFileError(source, f"instruments.{instrument.name}.file",
                            "no such file; allowed: a CSV or netCDF file of 10-min records")
    if path.is_dir():
        raise DataFileError(source, f"instruments.{instrument.name}.file", "is a folder; "
                            "allowed: a CSV or netCDF file of 10-min records")
    table = _read(path, source, instrument.name)
    key = f"instruments.{instrument.name}.time"
    if instrument.time not in table.columns:
        raise DataFileError(source, key, f"no column {instrument.time!r}; allowed: "
                            f"{_listing(table.columns)}")
    with warnings.catch_warnings():      # pandas warns when it parses element by element
        warnings.simplefilter("ignore", UserWarning)
        time = pd.to_datetime(table[instrument.time], errors="coerce")
    if time.isna().any():
        row = int(np.flatnonzero(time.isna())[0])
        raise DataFileError(source, key, f"timestamp {table[instrument.time].iloc[row]!r} "
                            f"(row {row + 1}) is not a date and time")
    table.index = pd.DatetimeIndex(time, name="time")
    _check_times(table.index, source, key)
    return table


def _read(path, source, name):
    """The file as a pandas table; DataFileError if it is not CSV (or netCDF) text."""
    try:
        if path.suffix == ".nc":
            with xr.open_dataset(path) as ds:
                return ds.to_dataframe().reset_index()
        return pd.read_csv(path, encoding="utf-8")
    except (OSError, ValueError, UnicodeDecodeError, pd.errors.ParserError,
            pd.errors.EmptyDataError) as error:
        reason = str(error).splitlines()[0][:120] if str(error) else type(error).__name__
        raise DataFileError(source, f"instruments.{name}.file", f"cannot read it as "
                            f"{'netCDF' if path.suffix == '.nc' else 'CSV'} ({reason}); "
                            "allowed: a UTF-8 CSV or a netCDF file of 10-min records") from None


def load_records(instrument):
    """The instrument's records as a Dataset (see the module docstring)."""
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
    _check_speed(ds["speed"].values, source, prefix)
    ds["direction"] = _checked_direction(ds["direction"].values, source, prefix)
    ds.attrs.update(instrument=instrument.name, file=source, n_invalid=invalid)
    return ds


def align(unit, reference):
    """The two Datasets on their common timestamps and heights, and what was left out:
    ``(unit, reference, counts)`` with counts of records only in one of them. Raises
    when they share no timestamp or no height."""
    times = np.intersect1d(unit["time"].values, reference["time"].values)
    heights = np.intersect1d(unit["height"].values, reference["height"].values)
    names = f"{unit.attrs['instrument']} and {reference.attrs['instrument']}"
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
    return unit.sel(pick), reference.sel(pick), counts


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


def _check_speed(speed, source, key):
    finite = speed[np.isfinite(speed)]
    if finite.size and finite.min() < 0:
        raise DataFileError(source, key, f"negative wind speed {finite.min():g}; allowed: "
                            "speeds >= 0 [m s-1]")
    if finite.size and np.median(finite) > MAX_MEDIAN_SPEED:
        raise DataFileError(source, key, f"median wind speed {np.median(finite):.1f} looks "
                            "like km/h or knots; allowed: m s-1")


def _checked_direction(direction, source, key):
    finite = direction[np.isfinite(direction)]
    outside = finite[np.abs(finite) > FULL_CIRCLE_DEG]
    if outside.size:
        raise DataFileError(source, key, f"direction {outside[0]:g} is out of range; "
                            "allowed: degrees in [-360, 360]")
    if finite.size > 1 and finite.min() >= 0 and finite.max() <= 2 * np.pi \
            and np.ptp(finite) > RADIAN_SPREAD:
        raise DataFileError(source, key, f"directions span {finite.min():.2f}-"
                            f"{finite.max():.2f}: radians? allowed: degrees")
    return (("time", "height"), np.mod(direction, FULL_CIRCLE_DEG))


def _listing(columns):
    """Column names for a one-line message (control characters and newlines shown)."""
    names = [repr(str(c))[1:-1][:40] for c in columns]
    return ", ".join(names[:12]) + (", ..." if len(names) > 12 else "")


def _heights(ds):
    return ", ".join(f"{h:g}" for h in ds["height"].values) + " m"


def _span(ds):
    return f"{str(ds['time'].values[0])[:16]}..{str(ds['time'].values[-1])[:16]}"
