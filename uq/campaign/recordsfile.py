"""Reading a campaign's ten-minute tables (the lidar's records, a per-record motion or
a reference) as a user has them: other column names, another time zone, time stamps at
the start or the end of the ten minutes, missing records, other units.

Conventions (pinned by tests):

* Every table is put on one grid of ten-minute periods, each named by its **start in
  UTC** (``time``). A stamp without a time zone is in the configuration's ``time_zone``
  (UTC, an offset ``+hh:mm`` or an IANA name; a stamp that the zone's daylight-saving
  change makes ambiguous or non-existent is refused); a stamp with a zone is converted.
  ``stamp: end`` marks the end of the period (10:10 is the period 10:00-10:10).
* The records' grid runs from their first to their last period; a period without a row
  is a **missing record**: NaN, counted (``n_missing``) and flagged. A motion or
  reference table is read onto the records' grid (its other rows are left out, counted).
* A cell that is not a number is NaN, counted (``n_invalid``); nothing is dropped
  silently. Speeds are converted to m s-1, directions to degrees, availabilities and
  TIs to fractions (the configuration's ``units``).

Problems are one line (:class:`uq.errors.DataFileError`) naming the file, the column
and what is allowed: a missing file or column, a stamp that is not a date, stamps not on
a ten-minute grid, a repeated period, negative speeds or standard deviations, a median
speed that looks like km/h or knots, directions outside [-360, 360] deg, availabilities
outside [0, 1].
"""
import warnings

import numpy as np
import pandas as pd
import xarray as xr

from uq.campaign.config import (DIRECTION_UNITS, FRACTION_UNITS, SPEED_UNITS, time_zone)
from uq.constants import CAMPAIGN_RECORD_SECONDS, MAX_RECORD_BYTES, MAX_RECORD_ROWS
from uq.errors import DataFileError
from uq.pipeline.inputfile import check_regular, read_csv

PERIOD = pd.Timedelta(seconds=CAMPAIGN_RECORD_SECONDS)
TABLE_KIND = "a UTF-8 CSV file of ten-minute records"
#: Largest plausible median ten-minute speed [m s-1] (as uq golden's): above it the
#: column is in km/h or knots.
MAX_MEDIAN_SPEED = 25.0


def read_table(spec):
    """The table of a :class:`uq.campaign.config.TableSpec` (pandas) indexed by the UTC
    start of each row's period (``time``), its rows sorted."""
    table = _read(spec)
    if spec.time not in table.columns:
        raise DataFileError(str(spec.file), f"{spec.key}.time", f"no column {spec.time!r}; "
                            f"allowed: {listing(table.columns)}")
    if table.empty:
        raise DataFileError(str(spec.file), f"{spec.key}.file", f"no rows; allowed: "
                            f"{TABLE_KIND}")
    start = utc_times(table[spec.time], spec.time_zone, str(spec.file), f"{spec.key}.time")
    if spec.stamp == "end":
        start = start - PERIOD
    table.index = pd.DatetimeIndex(start, name="time")
    table = table.sort_index()
    _check_grid(table.index, table[spec.time], str(spec.file), f"{spec.key}.time")
    return table


def _read(spec):
    """The file as a pandas table (CSV, or a netCDF file of one-dimensional variables)."""
    key = f"{spec.key}.file"
    if spec.file.suffix != ".nc":
        return read_csv(spec.file, MAX_RECORD_BYTES, MAX_RECORD_ROWS, TABLE_KIND,
                        DataFileError, key)
    check_regular(spec.file, MAX_RECORD_BYTES, "a netCDF file of ten-minute records",
                  DataFileError, key)
    try:
        with xr.open_dataset(spec.file) as ds:
            return ds.to_dataframe().reset_index()
    except (OSError, ValueError) as error:
        reason = str(error).splitlines()[0][:120] if str(error) else type(error).__name__
        raise DataFileError(str(spec.file), key, f"cannot read it as netCDF ({reason}); "
                            "allowed: a netCDF file of ten-minute records") from None


def utc_times(column, zone, source, key):
    """The stamps of `column` in UTC, without a zone (pandas Series of datetime64): those
    with a zone converted, those without localised to `zone` (module docstring)."""
    with warnings.catch_warnings():          # pandas warns when it parses row by row
        warnings.simplefilter("ignore", UserWarning)
        try:
            parsed = pd.to_datetime(column, errors="coerce")
        except (ValueError, TypeError):      # a stamp unlike the first, or mixed zones
            return _stamp_by_stamp(column, source, key)
    if parsed.isna().any():
        _bad_stamp(column, parsed, source, key)
    if parsed.dt.tz is not None:
        return parsed.dt.tz_convert(None)
    try:
        local = parsed.dt.tz_localize(time_zone(zone), ambiguous="raise",
                                      nonexistent="raise")
    except Exception as error:      # pytz/zoneinfo AmbiguousTimeError, NonExistentTimeError
        raise DataFileError(source, key, f"stamp {str(error)[:60]} is ambiguous or does "
                            f"not exist in {zone} (a daylight-saving change); allowed: "
                            "stamps in UTC or with their offset") from None
    return local.dt.tz_convert(None)


def _stamp_by_stamp(column, source, key):
    """Stamps of different forms parsed one by one: a stamp that is not a date is
    refused; stamps that all carry a zone (offsets that change with daylight saving)
    are converted; some with a zone and some without are refused."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)
        parsed = pd.to_datetime(column, errors="coerce", format="mixed", utc=True)
    if parsed.isna().any():
        _bad_stamp(column, parsed, source, key)
    zoned = column.astype(str).str.contains(r"(?:Z|[+-]\d\d:?\d\d)\s*$", regex=True)
    if not zoned.all():
        row = int(np.flatnonzero(~zoned.to_numpy())[0])
        raise DataFileError(source, key, f"stamp {column.iloc[row]!r} (row {row + 2}) has no "
                            "time zone where others have one; allowed: all stamps with "
                            "their zone, or none (the configuration's time_zone)")
    return parsed.dt.tz_convert(None)


def _bad_stamp(column, parsed, source, key):
    row = int(np.flatnonzero(parsed.isna().to_numpy())[0])
    raise DataFileError(source, key, f"stamp {column.iloc[row]!r} (row {row + 2}) is not a "
                        "date and time; allowed: dates and times (ISO 8601, e.g. "
                        "2016-07-01 10:10), all in one time zone")


def _check_grid(index, stamps, source, key):
    """Refuse repeated periods and stamps off the ten-minute grid."""
    if index.has_duplicates:
        raise DataFileError(source, key, f"period starting {index[index.duplicated()][0]} "
                            "UTC repeats; allowed: one row per ten-minute period")
    offset = (index - index[0]) % PERIOD
    off = np.flatnonzero(offset != pd.Timedelta(0))
    if off.size:
        raise DataFileError(source, key, f"stamp {stamps.sort_index().iloc[off[0]]!r} is "
                            f"not on the ten-minute grid of the first ({stamps.sort_index().iloc[0]!r}); "
                            "allowed: ten-minute records")


def numbers(table, column, source, key, factor=1.0):
    """A column as floats times `factor` (cells that are not numbers: NaN) and how many
    cells were not numbers (an empty cell is a missing value, not counted)."""
    if column not in table.columns:
        raise DataFileError(source, key, f"no column {column!r}; allowed: "
                            f"{listing(table.columns)}")
    values = pd.to_numeric(table[column], errors="coerce").to_numpy(dtype=float)
    bad = int(np.sum(np.isnan(values)) - np.sum(table[column].isna()))
    return values * factor, bad


def listing(columns):
    """Column names for a one-line message (control characters shown)."""
    names = [repr(str(c))[1:-1][:40] for c in columns]
    return ", ".join(names[:12]) + (", ..." if len(names) > 12 else "")


def load_records(spec):
    """The lidar's records (:class:`uq.campaign.config.RecordsSpec`) as a Dataset with
    dimensions ``time`` (period start, UTC) and ``height`` [m]: ``speed``, ``std``
    [m s-1], ``direction`` [deg, "from", in [0, 360)], ``availability`` [1] and
    ``heading`` (time) [deg] (NaN where the file gives none); attributes ``n_missing``
    (periods without a row), ``n_invalid`` (cells not numbers) and ``file``."""
    table = read_table(spec.table)
    grid = pd.date_range(table.index[0], table.index[-1], freq=PERIOD, name="time")
    source = str(spec.table.file)
    factors = {"speed": SPEED_UNITS[spec.units["speed"]],
               "std": SPEED_UNITS[spec.units["speed"]],
               "direction": DIRECTION_UNITS[spec.units["direction"]],
               "availability": FRACTION_UNITS[spec.units["availability"]]}
    heights = sorted(spec.heights)
    data, invalid = {}, 0
    for name in ("speed", "std", "direction", "availability"):
        columns = []
        for h in heights:
            column = spec.heights[h].get(name)
            if column is None:                   # no availability given: every record's
                columns.append(np.full(len(table), 1.0))
                continue
            key = f"{spec.table.key}.heights.{h:g}.{name}"
            values, bad = numbers(table, column, source, key, factors[name])
            _check_column(name, values, source, f"{key} (column {column!r})")
            invalid += bad
            columns.append(values)
        data[name] = (("time", "height"), np.stack(columns, axis=-1))
    heading = np.full(len(table), np.nan)
    if spec.heading is not None:
        heading, bad = numbers(table, spec.heading, source, f"{spec.table.key}.heading",
                               DIRECTION_UNITS[spec.units["direction"]])
        invalid += bad
    data["heading"] = (("time",), heading)
    ds = xr.Dataset(data, coords={"time": table.index.values, "height": heights})
    ds = ds.reindex(time=grid)
    ds["availability"] = ds["availability"].fillna(0.0)
    ds["direction"] = np.mod(ds["direction"], 360.0)
    ds["heading"] = np.mod(ds["heading"], 360.0)
    ds.attrs.update(n_missing=len(grid) - len(table), n_invalid=invalid, file=source,
                    n_rows=len(table))
    return ds


def _check_column(name, values, source, key):
    finite = values[np.isfinite(values)]
    if not finite.size:
        return
    if name in ("speed", "std") and finite.min() < 0:
        raise DataFileError(source, key, f"negative value {finite.min():g}; allowed: "
                            "speeds and standard deviations >= 0 (a missing value left empty)")
    if name == "speed" and np.median(finite) > MAX_MEDIAN_SPEED:
        raise DataFileError(source, key, f"median wind speed {np.median(finite):.1f} m/s "
                            "looks like km/h or knots; allowed: the unit given in "
                            "campaign.records.units.speed")
    if name == "direction" and np.abs(finite).max() > 360.0 + 1e-9:
        raise DataFileError(source, key, f"direction {finite[np.abs(finite) > 360][0]:g} deg "
                            "is out of range; allowed: degrees in [-360, 360] (or "
                            "units.direction: rad)")
    if name == "availability" and (finite.min() < 0 or finite.max() > 1.0 + 1e-9):
        raise DataFileError(source, key, f"availability {finite.max():g} is out of range; "
                            "allowed: [0, 100] % (units.availability: percent) or [0, 1] "
                            "(fraction)")


def on_grid(table, times):
    """`table` (indexed by period start) on the records' periods `times`; rows off
    them are left out (their number returned)."""
    kept = table.index.isin(times)
    return table.reindex(pd.DatetimeIndex(times, name="time")), int(np.sum(~kept))


def load_reference(spec, times, heights):
    """The reference on the records' grid: its TI [1] and mean speed [m s-1] (NaN where
    it gives none), each (time, height), and the number of its rows off the grid."""
    table, outside = on_grid(read_table(spec.table), times)
    source = str(spec.table.file)
    tis, speeds = [], []
    nan = np.full(len(times), np.nan)
    for h in heights:
        if h not in spec.heights:
            tis.append(nan)
            speeds.append(nan)
            continue
        names, key = spec.heights[h], f"{spec.table.key}.heights.{h:g}"
        speed = nan
        if "ti" in names:
            ti, _ = numbers(table, names["ti"], source, f"{key}.ti",
                            FRACTION_UNITS[spec.units["ti"]])
        else:
            factor = SPEED_UNITS[spec.units["speed"]]
            speed, _ = numbers(table, names["speed"], source, f"{key}.speed", factor)
            std, _ = numbers(table, names["std"], source, f"{key}.std", factor)
            _check_column("speed", speed, source, f"{key}.speed (column {names['speed']!r})")
            _check_column("std", std, source, f"{key}.std (column {names['std']!r})")
            with np.errstate(divide="ignore", invalid="ignore"):
                ti = np.where(speed > 0, std / speed, np.nan)
        finite = ti[np.isfinite(ti)]
        if finite.size and (finite.min() < 0 or np.median(finite) > 1.0):
            raise DataFileError(source, f"{key}.ti", f"TI median {np.median(finite):g}: "
                                "a percentage read as a fraction? allowed: units.ti percent "
                                "or fraction, values >= 0")
        tis.append(ti)
        speeds.append(speed)
    return np.stack(tis, axis=-1), np.stack(speeds, axis=-1), outside
