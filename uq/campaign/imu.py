"""An IMU log of the platform's motion cut into ten-minute records: each record's
cross-spectra of its degrees of freedom, on the motion tables' frequency bins.

The log holds the platform's attitude (roll, pitch, yaw) and displacement (surge, sway,
heave) sampled at a nominal ``rate`` [Hz], with gaps (samples lost, a logger restarted).
Per record [start, start + 10 min):

* the samples split into contiguous segments wherever two samples are more than 1.5
  sampling intervals apart (a gap); segments shorter than :data:`MIN_SEGMENT_SECONDS`
  are left out;
* each segment's mean is removed (and yaw unwrapped across 0/360 deg first); its
  discrete Fourier transform gives, at each frequency ``f_j = j / T_seg`` (0 < f_j below
  Nyquist), the one-sided complex amplitudes ``c_j = 2 X_j / n`` of the degrees of
  freedom, and ``c_j c_j^H / 2`` its share of their covariance (Parseval: the shares sum
  to the segment's covariance matrix);
* the segments' shares are averaged weighted by their lengths (Welch's averaging over
  non-overlapping, unwindowed segments) and summed into the nearest bin of the motion
  tables' grid (:data:`uq.campaign.surrogate.FREQUENCY_STEP`): the record's matrix M_b
  per bin, ``sum_b M_b`` its covariance, at the bin's power-weighted mean frequency (a
  line keeps its own frequency: the response changes by several per cent within a bin);
* a record whose segments cover less than :data:`MIN_COVERAGE` of its ten minutes has no
  motion (NaN in the results, flagged ``no_motion_data``); power below the first bin's
  half-step or above the tables' top frequency is left out (its share reported).

The matrices enter :class:`uq.campaign.motion.MotionSet` through the polarisation basis.

References
----------
.. [1] Welch, P. D. (1967). The use of fast Fourier transform for the estimation of
   power spectra. IEEE Trans. Audio Electroacoust. 15(2), 70-73.
"""
import numpy as np
import pandas as pd

from uq.campaign import motion, surrogate
from uq.campaign.config import ANGLE_UNITS, LENGTH_UNITS
from uq.campaign.recordsfile import PERIOD, listing, utc_times
from uq.constants import MAX_SERIES_BYTES, MAX_SERIES_ROWS
from uq.errors import DataFileError
from uq.physics.motion import ANGULAR, DEGREES_OF_FREEDOM
from uq.pipeline.inputfile import read_csv

#: Shortest segment kept [s]: it resolves 1/60 Hz, below the motion tables' first bins
#: and a buoy's slowest wave motion (30 s periods).
MIN_SEGMENT_SECONDS = 60.0
#: Least share of a record's ten minutes its segments must cover [1]: half a record
#: estimates the motion's spectrum with twice the variance of a whole one.
MIN_COVERAGE = 0.5
#: A gap: samples more than this many nominal intervals apart [1].
GAP_INTERVALS = 1.5
LOG_KIND = "a UTF-8 CSV IMU log"


def read_log(spec):
    """(times [s since 1970-01-01 UTC] (n,), values {dof: (n,) [rad or m]}) of an IMU
    log (:class:`uq.campaign.config.MotionSpec` of kind ``imu``), sorted in time."""
    source, key = str(spec.table.file), spec.table.key
    table = read_csv(spec.table.file, MAX_SERIES_BYTES, MAX_SERIES_ROWS, LOG_KIND,
                     DataFileError, f"{key}.file")
    if spec.table.time not in table.columns:
        raise DataFileError(source, f"{key}.time", f"no column {spec.table.time!r}; "
                            f"allowed: {listing(table.columns)}")
    if spec.time_unit == "unix":
        times = pd.to_numeric(table[spec.table.time], errors="coerce").to_numpy(float)
        if not np.all(np.isfinite(times)):
            row = int(np.flatnonzero(~np.isfinite(times))[0])
            raise DataFileError(source, f"{key}.time", f"row {row + 2} is not a number of "
                                "seconds; allowed: seconds since 1970-01-01 UTC")
    else:
        stamps = utc_times(table[spec.table.time], spec.table.time_zone, source, f"{key}.time")
        times = (stamps - pd.Timestamp(0)).dt.total_seconds().to_numpy()
    order = np.argsort(times, kind="stable")
    values = {}
    for dof, column in spec.columns.items():
        if column not in table.columns:
            raise DataFileError(source, f"{key}.columns.{dof}", f"no column {column!r}; "
                                f"allowed: {listing(table.columns)}")
        data = pd.to_numeric(table[column], errors="coerce").to_numpy(float)
        factor = ANGLE_UNITS[spec.units["angle"]] if dof in ANGULAR else \
            LENGTH_UNITS[spec.units["length"]]
        values[dof] = data[order] * factor
    times = times[order]
    if np.any(np.diff(times) <= 0):
        row = int(np.flatnonzero(np.diff(times) <= 0)[0])
        raise DataFileError(source, f"{key}.time", f"time {table[spec.table.time].iloc[order[row]]!r} "
                            "repeats; allowed: one sample per time")
    return times, values


def segments(times, rate):
    """(start, stop) index pairs of the contiguous runs of `times` [s] (gaps: more than
    :data:`GAP_INTERVALS` nominal intervals)."""
    breaks = np.flatnonzero(np.diff(times) > GAP_INTERVALS / rate) + 1
    edges = np.concatenate([[0], breaks, [len(times)]])
    return list(zip(edges[:-1], edges[1:]))


def record_spectra(times, values, starts, rate):
    """Per record (period starts [s since 1970 UTC] (n,)): the cross-spectral matrices on
    the motion tables' bins (n, n_bins, m, m) [rad2, m2], each bin's frequency (the mean
    of its Fourier frequencies weighted by their power, the bin's centre where it has
    none) (n, n_bins) [Hz], the covered share of the record (n,) and the share of its
    power outside the bins (n,)."""
    dofs = list(values)
    grid = surrogate.frequency_grid(surrogate.FREQUENCY_STEP)
    out = np.zeros((len(starts), grid.size, len(dofs), len(dofs)), complex)
    moment = np.zeros((len(starts), grid.size))
    covered, outside = np.zeros(len(starts)), np.zeros(len(starts))
    data = np.stack([values[d] for d in dofs], axis=-1)                    # (samples, m)
    length = PERIOD.total_seconds()
    for i, start in enumerate(starts):
        a, b = np.searchsorted(times, [start, start + length])
        total = 0.0
        for first, last in segments(times[a:b], rate):
            part = data[a + first:a + last]
            if last - first < 2 or (last - first) / rate < MIN_SEGMENT_SECONDS or \
                    not np.all(np.isfinite(part)):
                continue
            spectra, first, weight, left = _segment(part, dofs, rate, grid)
            out[i] += spectra * weight
            moment[i] += first * weight
            outside[i] += left * weight
            total += weight
        covered[i] = total / length
        if total > 0:
            out[i] /= total
            moment[i] /= total
            inside = np.real(np.trace(out[i], axis1=-2, axis2=-1)).sum()
            left = outside[i] / total
            outside[i] = left / (inside + left) if inside + left > 0 else 0.0
    power = np.real(np.trace(out, axis1=-2, axis2=-1))
    with np.errstate(invalid="ignore", divide="ignore"):
        frequency = np.where(power > 0, moment / power, grid[None])
    return out, frequency, covered, outside


def _segment(part, dofs, rate, grid):
    """(the segment's cross-spectra on the bins (n_bins, m, m), the first moment of each
    bin's power in frequency (n_bins,) [Hz x power], its length [s], the power (trace)
    left outside the bins)."""
    part = part.copy()
    for j, dof in enumerate(dofs):
        if dof == "yaw":
            part[:, j] = np.unwrap(part[:, j])
    part -= part.mean(axis=0)
    n = part.shape[0]
    coefficients = 2.0 * np.fft.rfft(part, axis=0) / n                    # (f, m)
    frequency = np.fft.rfftfreq(n, 1.0 / rate)
    shares = np.einsum("fd,fe->fde", coefficients, np.conj(coefficients)) / 2.0
    if n % 2 == 0:
        shares[-1] /= 4.0                                  # Nyquist: X counted once
    shares, frequency = shares[1:], frequency[1:]
    step = surrogate.FREQUENCY_STEP
    index = np.rint(frequency / step).astype(int) - 1
    inside = (index >= 0) & (index < grid.size)
    out = np.zeros((grid.size, len(dofs), len(dofs)), complex)
    np.add.at(out, index[inside], shares[inside])
    trace = np.real(np.trace(shares, axis1=-2, axis2=-1))
    first = np.zeros(grid.size)
    np.add.at(first, index[inside], (trace * frequency)[inside])
    left = float(trace[~inside].sum())
    return out, first, n / rate, left


def motion_set(spec, record_times):
    """:class:`uq.campaign.motion.MotionSet` of the records (period starts, numpy
    datetime64 (n,)) from an IMU log; the log's samples outside every record left out."""
    times, values = read_log(spec)
    starts = (pd.DatetimeIndex(record_times) - pd.Timestamp(0)).total_seconds().to_numpy()
    spectra, frequency, covered, outside = record_spectra(times, values, starts, spec.rate)
    dofs = [DEGREES_OF_FREEDOM.index(d) for d in values]
    shapes, labels = motion.polarisation_shapes(dofs)
    local = list(range(len(dofs)))
    power = motion.polarisation_powers(spectra, local)                     # (n, b, S)
    n, bins, count = power.shape
    valid = covered >= MIN_COVERAGE
    return motion.MotionSet(
        shapes, np.repeat(frequency, count, axis=1),
        np.broadcast_to(np.tile(np.arange(count), bins), (n, bins * count)).copy(),
        np.where(valid[:, None], power.reshape(n, bins * count), 0.0), valid, labels,
        random_phases=False), outside
