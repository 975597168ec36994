"""The orchestrator of ``uq campaign``: a configuration in, one Dataset of every record
and table out.

1. The lidar's records (:mod:`uq.campaign.recordsfile`), the platform's motion on their
   periods (:mod:`uq.campaign.motioninput`), the reference (optional).
2. The records the model cannot take (missing, low availability, low speed, no motion)
   are flagged and left out (NaN).
3. The tables of the fast path over the campaign's heights and speeds
   (:mod:`uq.campaign.surrogate`), their error measured at points between their nodes.
4. The model's terms of every record and height from the tables
   (:mod:`uq.campaign.model`), the correction (:mod:`uq.campaign.correction`), in chunks
   of :data:`~uq.constants.CAMPAIGN_CHUNK_RECORDS` (a dask task each).
5. Per-bin statistics and, with a reference, its errors before and after
   (:mod:`uq.campaign.bins`), the share of intervals that cover the reference.

Dimensions: ``time`` (the start of each ten-minute period, UTC), ``height`` [m],
``bin`` (centre [m s-1]). With a client (dask), the tables' nodes and the chunks run on
its workers; without one, on a pool of threads here, one per CPU the process may use (at
most :data:`~uq.constants.CAMPAIGN_THREADS`: the spectral path's compiled sums and
numpy's array loops release Python's lock); every number is the same either way (no
randomness; each task a fixed computation, its result put in its own place).
"""
import concurrent.futures
import contextlib
import time as clock

import numpy as np
import xarray as xr
from scipy import stats

from uq.campaign import bins, correction, model, motion, surrogate
from uq.campaign.config import length_scales
from uq.campaign.motioninput import load_motion
from uq.campaign.recordsfile import load_records, load_reference
from uq.constants import (CAMPAIGN_CHUNK_RECORDS, CAMPAIGN_RECORD_SECONDS, CAMPAIGN_THREADS,
                          FULL_CIRCLE_DEG)
from uq.cpus import usable_cpus
from uq.golden import binning, kpi

#: Margin of the tables' speed range beyond the records' fastest [1] (the tables'
#: polynomial in log U is then never extrapolated).
SPEED_MARGIN = 1.05


def local_threads():
    """Threads for the tables' nodes and the records' chunks where no dask client is
    given: one per CPU this process may use, at most :data:`~uq.constants.
    CAMPAIGN_THREADS`; None on one CPU (run in order)."""
    count = min(usable_cpus(), CAMPAIGN_THREADS)
    return concurrent.futures.ThreadPoolExecutor(count) if count > 1 else None


def analyse(config, client=None, kernels_missing=None):
    """Every record and table of a :class:`uq.campaign.config.CampaignConfig` as a
    Dataset (module docstring); `client` a dask client or None (threads here,
    :func:`local_threads`).

    `kernels_missing` (here, not on a cluster): where given, the campaign compiles in
    this process only the spectral path's kernels (~3 s of CPU; their numpy sums would
    take six times theirs); where numba's cache lacks the compiled motion model's
    (~25 s of CPU to compile, a few seconds of the campaign's work in numpy), the
    numpy model runs (:func:`uq.campaign.adapter.numpy_motion_model`) and
    ``kernels_missing(error, [lidar settings])`` is called once, before the tables (``uq
    campaign``: their compile in the background, for later campaigns). Without it,
    whatever is missing compiles here."""
    if client is not None:
        return _analyse(config, client.submit)
    chosen = contextlib.nullcontext()
    if kernels_missing is not None:
        chosen = _motion_model(config, kernels_missing)
    pool = local_threads()
    try:
        with chosen:
            return _analyse(config, None if pool is None else pool.submit)
    finally:
        if pool is not None:
            pool.shutdown(cancel_futures=True)


def _motion_model(config, kernels_missing):
    """The context the campaign's motion model runs in (:func:`analyse`): nothing, or
    :func:`uq.campaign.adapter.numpy_motion_model` where its kernels are not cached.
    Evaluated here, before any thread starts: the check refuses every compile of the
    process while it runs (:func:`uq.compileguard.cached_only`)."""
    from uq.campaign import adapter
    from uq.physics.lidarspectral import spectral_sums
    spectral_sums()                               # loaded, or compiled here: first
    lidar, height = config.lidar.settings, float(config.heights[0])
    settings = adapter.gate_settings(lidar, [height], {
        "model": "mann", "anisotropy": config.anisotropy,
        "length_scale": float(length_scales(config)[0])}, CAMPAIGN_RECORD_SECONDS)
    missing = adapter.motion_kernels_missing(settings)
    if missing is None:
        return contextlib.nullcontext()
    kernels_missing(missing, [lidar])
    return adapter.numpy_motion_model()


def _analyse(config, submit):
    """:func:`analyse` with `submit` ``(function, *args) -> future`` or None."""
    started = clock.perf_counter()
    records = load_records(config.records)
    times, heights = records["time"].values, list(config.heights)
    motions, outside, motion_off = motion_of(config, times)
    reference = None if config.reference is None else \
        load_reference(config.reference, times, heights)      # every file read first
    flags = input_flags(config, records, motions, outside)
    usable = (flags & correction.INVALIDATING) == 0
    speed = records["speed"].values
    top = float(np.nanmax(np.where(usable, speed, np.nan))) if usable.any() else \
        2.0 * config.minimum_speed
    scales = length_scales(config)
    turbulence = {"model": "mann", "anisotropy": config.anisotropy}
    lidar = config.lidar.settings
    tables = surrogate.build_tables(lidar, heights, scales, turbulence,
                                    CAMPAIGN_RECORD_SECONDS,
                                    (config.minimum_speed, max(top * SPEED_MARGIN,
                                                               2 * config.minimum_speed)),
                                    motions.shapes, submit)
    ti_error, spread_error = surrogate.spectral_errors(tables, lidar, scales, turbulence,
                                                       submit)
    motion_error = surrogate.motion_errors(tables, lidar, scales, turbulence,
                                           motions.shapes) if motions.shapes.size else 0.0
    corrected = correct_records(config, records, motions, tables, usable, submit)
    flags |= np.where(usable & ~corrected.pop("consistent"),
                      correction.FLAG_BITS["variance_below_model"], 0)
    flags |= np.where(usable & (np.abs(corrected["wind_speed_motion_bias"]) > _tolerance(
        corrected["motion_u"])), correction.FLAG_BITS["motion_clause8"], 0)
    ds = _dataset(config, records, corrected, flags, tables)
    if reference is not None:
        ds["turbulence_intensity_reference"] = (("time", "height"), reference[0])
        ds["wind_speed_reference"] = (("time", "height"), reference[1])
        ds.attrs["n_reference_off_grid"] = reference[2]
        predicted, predicted_u = _predicted(config, ds, tables)
        ds["turbulence_intensity_measured_predicted"] = (("time", "height"), predicted)
        ds["turbulence_intensity_measured_predicted_u"] = (("time", "height"), predicted_u)
    ds = ds.assign(_bin_tables(config, ds))
    ds.attrs.update(surrogate_ti_error=ti_error, surrogate_spread_error=spread_error,
                    surrogate_motion_error=motion_error,
                    surrogate_nodes=f"spectral path: {tables.speeds.size} speeds x "
                    f"{tables.spectral_directions} directions; motion: "
                    f"{tables.motion_speeds.size} speeds x {tables.motion_directions} "
                    f"directions, frequencies every {tables.response_step:g} Hz")
    ds.attrs.update(_counts(flags, records, motion_off))
    ds.attrs["runtime_s"] = clock.perf_counter() - started
    return ds


def motion_of(config, times):
    """(MotionSet within the tables' band, the share of each record's motion power
    outside it, the motion file's rows off the records' grid)."""
    if config.motion is None:
        return motion.no_motion(len(times)), np.zeros(len(times)), 0
    found, outside, off = load_motion(config.motion, times)
    found, left = found.within(surrogate.FREQUENCY_STEP / 2.0, surrogate.FREQUENCY_TOP)
    return found, np.maximum(outside, left), off


def input_flags(config, records, motions, outside):
    """Flags (time, height) of what the inputs say alone."""
    bits = correction.FLAG_BITS
    speed, std = records["speed"].values, records["std"].values
    present = np.isfinite(speed) & np.isfinite(std) & np.isfinite(records["direction"].values)
    flags = np.where(~present, bits["missing"], 0)
    flags |= np.where(present & (records["availability"].values
                                 < config.records.minimum_availability),
                      bits["low_availability"], 0)
    with np.errstate(invalid="ignore"):
        flags |= np.where(speed < config.minimum_speed, bits["low_speed"], 0)
    flags |= np.where(~motions.valid[:, None], bits["no_motion_data"], 0)
    flags |= np.where((outside > correction.OUTSIDE_SHARE)[:, None],
                      bits["motion_outside_band"], 0)
    return flags.astype(np.int32)


def _tolerance(u):
    """JCGM 101 7.9.2's numerical tolerance of u at the clause-8 digits."""
    from uq.engine.gum import numerical_tolerance
    return numerical_tolerance(u, correction.CLAUSE8_DIGITS)


def record_directions(config, records, tables):
    """Each record's wind direction relative to the tables' heading [deg] (time,
    height): the lidar's direction minus its heading of the record (the file's, else the
    scenario's), plus the tables' heading."""
    heading = records["heading"].values
    heading = np.where(np.isfinite(heading), heading, tables.heading)
    return np.mod(records["direction"].values - heading[:, None] + tables.heading,
                  FULL_CIRCLE_DEG)


def correct_records(config, records, motions, tables, usable, submit=None):
    """The corrected records and the model's terms, arrays (time, height), NaN where not
    `usable`; in chunks (a dask task each with `submit`)."""
    n_time, n_height = usable.shape
    rows, columns = np.nonzero(usable)
    direction = record_directions(config, records, tables)
    speed, std = records["speed"].values, records["std"].values
    run = surrogate.runner(submit)
    tasks = []
    for start in range(0, rows.size, CAMPAIGN_CHUNK_RECORDS):
        r, c = rows[start:start + CAMPAIGN_CHUNK_RECORDS], columns[start:start + CAMPAIGN_CHUNK_RECORDS]
        tasks.append(run(correct_chunk, tables, c, speed[r, c], std[r, c], direction[r, c],
                         motions.take(r), config.filtering == "spectral",
                         config.records.ddof, config.coverage, config.filtering_u,
                         config.motion_u))
    out = {}
    for start, task in zip(range(0, rows.size, CAMPAIGN_CHUNK_RECORDS), tasks):
        part = surrogate.result(task)
        r, c = rows[start:start + CAMPAIGN_CHUNK_RECORDS], columns[start:start + CAMPAIGN_CHUNK_RECORDS]
        for name, values in part.items():
            if name not in out:
                out[name] = np.full((n_time, n_height), np.nan if values.dtype != bool else False,
                                    dtype=values.dtype)
            out[name][r, c] = values
    if not out:                                        # no usable record
        out = {name: np.full((n_time, n_height), np.nan) for name in RESULT_NAMES}
        out["consistent"] = np.zeros((n_time, n_height), bool)
    return out


#: The names :func:`correct_chunk` returns.
RESULT_NAMES = ("wind_speed_corrected", "turbulence_intensity_measured",
                "turbulence_intensity_corrected", "turbulence_intensity_corrected_u",
                "turbulence_intensity_corrected_low", "turbulence_intensity_corrected_high",
                "variance_corrected", "lidar_filtering_factor", "record_variance_spread",
                "motion_variance", "motion_u", "motion_cross", "motion_phase",
                "wind_speed_motion_bias", "scan_noise_variance")


def correct_chunk(tables, height_index, speed, std, direction, motions, filtering, ddof,
                  coverage, filtering_u, motion_u):
    """One chunk of records: the model's terms (fast path) and the correction."""
    terms = model.fast_terms(tables, height_index, speed, direction, motions, filtering)
    out = correction.correct(speed, std, terms["filtering"], terms["spread"],
                             terms["motion_variance"], terms["motion_bias"],
                             terms["noise_variance"], tables.n_scans, ddof, coverage,
                             filtering_u, motion_u, terms["motion_cross"],
                             terms["motion_phase"])
    out.update(lidar_filtering_factor=terms["filtering"], record_variance_spread=terms["spread"],
               motion_variance=terms["motion_variance"], motion_u=terms["motion_u"],
               motion_cross=terms["motion_cross"], motion_phase=terms["motion_phase"],
               wind_speed_motion_bias=terms["motion_bias"],
               scan_noise_variance=terms["noise_variance"])
    return out


def _dataset(config, records, corrected, flags, tables):
    invalid = (flags & correction.INVALIDATING) != 0
    data = {"wind_speed_measured": records["speed"].values,
            "wind_speed_std_measured": records["std"].values,
            "wind_direction": records["direction"].values,
            "availability": records["availability"].values}
    for name, values in corrected.items():
        data[name] = np.where(invalid, np.nan, values) if values.dtype != bool else values
    with np.errstate(invalid="ignore", divide="ignore"):
        data["turbulence_intensity_measured"] = np.where(
            np.isfinite(records["speed"].values) & (records["speed"].values > 0),
            records["std"].values / records["speed"].values, np.nan)
        data["motion_turbulence_intensity"] = np.sqrt(data["motion_variance"]) / \
            data["wind_speed_corrected"]
    data["record_flags"] = flags
    ds = xr.Dataset({name: (("time", "height"), values) for name, values in data.items()},
                    coords={"time": records["time"].values,
                            "height": np.array(config.heights, float)})
    ds.attrs.update(name=config.name, description=config.description,
                    configuration=config.text, lidar_scenario=config.lidar.text,
                    filtering=config.filtering, coverage=config.coverage,
                    n_scans=tables.n_scans, scan_period=tables.scan_period,
                    std_ddof=config.records.ddof, minimum_speed=config.minimum_speed,
                    motion=config.motion.kind if config.motion else "none",
                    bin_width=config.bin_width)
    return ds


def _predicted(config, ds, tables):
    """The measured TI the model predicts from the reference's TI, and its standard
    deviation from record to record (:func:`uq.campaign.correction.predicted_measured`,
    at the corrected mean speed over the measured one)."""
    mean, spread = correction.predicted_measured(
        ds["turbulence_intensity_reference"].values, ds["wind_speed_corrected"].values,
        ds["lidar_filtering_factor"].values, ds["record_variance_spread"].values,
        ds["motion_variance"].values, ds["scan_noise_variance"].values, tables.n_scans,
        config.records.ddof, ds["motion_cross"].values, ds["motion_phase"].values)
    ratio = ds["wind_speed_corrected"].values / ds["wind_speed_measured"].values
    return mean * ratio, spread * ratio


def _bin_tables(config, ds):
    """Per-bin variables (bin, height), and with a reference its metrics and the
    intervals' coverage per height."""
    has_reference = "turbulence_intensity_reference" in ds
    binned = binning_speed(ds)
    centres = binning.bin_centres(0.0, max(float(np.nanmax(binned))
                                           if np.isfinite(binned).any()
                                           else 0.0, config.required[1]), config.bin_width)
    heights = ds["height"].values
    out = {}

    def put(name, values):
        out.setdefault(name, np.full((len(centres), len(heights)), np.nan))
        out[name][:, j] = values
    for j in range(len(heights)):
        d = ds.isel(height=j)
        corrected = d["turbulence_intensity_corrected"].values
        measured = np.where(np.isfinite(corrected), d["turbulence_intensity_measured"].values,
                            np.nan)
        speed = binned[:, j]
        for label, values in (("measured", measured), ("corrected", corrected)):
            for stat, value in bins.bin_statistics(values, speed, centres,
                                                   config.bin_width).items():
                put(f"ti_{label}_{stat}", value)
        put("ti_corrected_u_mean", bins.bin_sums(d["turbulence_intensity_corrected_u"].values
                                                 ** 2, speed, centres, config.bin_width))
        if not has_reference:
            continue
        reference = d["turbulence_intensity_reference"].values
        for label, values in (("measured", measured), ("corrected", corrected)):
            for stat, value in bins.reference_metrics(reference, values, speed, centres,
                                                      config.bin_width).items():
                name = METRIC_NAMES[stat]
                if name is not None:
                    put(name.format(label=label), value)
        predicted = d["turbulence_intensity_measured_predicted"].values
        both = np.isfinite(reference) & np.isfinite(corrected)
        put("ti_mean_bias_measured_predicted", bins.bin_statistics(
            np.where(both, predicted - reference, np.nan), speed, centres,
            config.bin_width)["mean"])
        put("ti_mean_bias_corrected_u", bins.bin_sums(np.where(
            both, d["turbulence_intensity_corrected_u"].values ** 2, np.nan), speed, centres,
            config.bin_width))
        put("ti_mean_bias_measured_predicted_u", bins.bin_sums(np.where(
            both, d["turbulence_intensity_measured_predicted_u"].values ** 2, np.nan), speed,
            centres, config.bin_width))
    data = {name: (("bin", "height"), values) for name, values in out.items()}
    data["required"] = ("bin", binning.sufficient_bins(np.zeros(len(centres)), centres,
                                                       config.minimum_records,
                                                       config.required)[1])
    if has_reference:
        data.update(_coverage(ds))
        data.update(_speed_kpis(ds))
    return xr.Dataset(data, coords={"bin": centres, "height": heights})


#: The campaign's names of :func:`uq.campaign.bins.reference_metrics`' (None: the
#: lidar's mean TI of the bin, which ``ti_<label>_mean`` holds).
METRIC_NAMES = {"n_records": "ti_n_records", "reference_mean": "ti_reference_mean",
                "reference_representative": "ti_reference_representative",
                "unit_mean": None, "unit_representative": "ti_representative_{label}",
                "mean_bias": "ti_mean_bias_{label}",
                "relative_error": "ti_relative_mean_bias_{label}", "rmse": "ti_rmse_{label}",
                "relative_rmse": "ti_relative_rmse_{label}",
                "representative_error": "ti_representative_error_{label}"}


def _coverage(ds):
    """Per height: records whose interval covers the reference, their share, and the
    two-sided binomial test's p-value against the nominal coverage."""
    low, high = (ds[f"turbulence_intensity_corrected_{e}"].values for e in ("low", "high"))
    reference = ds["turbulence_intensity_reference"].values
    valid = np.isfinite(low) & np.isfinite(high) & np.isfinite(reference)
    covered = valid & (reference >= low) & (reference <= high)
    n, k = valid.sum(axis=0), covered.sum(axis=0)
    p = [stats.binomtest(int(ki), int(ni), ds.attrs["coverage"]).pvalue if ni else np.nan
         for ki, ni in zip(k, n)]
    with np.errstate(invalid="ignore", divide="ignore"):
        share = np.where(n > 0, k / np.maximum(n, 1), np.nan)
    return {"coverage_n_records": ("height", n), "coverage_n_covered": ("height", k),
            "coverage_share": ("height", share), "coverage_p_value": ("height", np.array(p))}


def binning_speed(ds):
    """The speed each record is binned by (time, height) [m s-1]: the reference's where
    it gives one (as ``uq golden`` bins), else the lidar's corrected mean speed."""
    speed = ds["wind_speed_corrected"].values
    if "wind_speed_reference" in ds:
        reference = ds["wind_speed_reference"].values
        speed = np.where(np.isfinite(reference), reference, speed)
    return speed


def _speed_kpis(ds):
    """Per height, where the reference gives mean speeds: the OWA roadmap's speed KPIs
    (:func:`uq.golden.kpi.speed_kpis`: the slope through the origin and R^2, with their
    verdicts) of the lidar's measured and of its corrected mean speed."""
    if not np.isfinite(ds["wind_speed_reference"].values).any():
        return {}
    out = {}
    for label, name in (("measured", "wind_speed_measured"), ("corrected", "wind_speed_corrected")):
        found = [kpi.speed_kpis(ds["wind_speed_reference"].values[:, j],
                                np.where(np.isfinite(ds["turbulence_intensity_corrected"].values[:, j]),
                                         ds[name].values[:, j], np.nan))
                 for j in range(ds.sizes["height"])]
        for key in ("speed_slope", "speed_r_squared", "speed_slope_verdict",
                    "speed_r_squared_verdict"):
            values = [f[key] for f in found]
            out[f"{key}_{label}"] = ("height", np.array(values, dtype=object
                                                          if "verdict" in key else float))
    return out


def _counts(flags, records, motion_off):
    """Counts of the flags and of the inputs' losses (global attributes)."""
    out = {f"n_{name}": int(np.sum((flags & bit) != 0)) for bit, name, _, _ in
           correction.FLAGS}
    out.update(n_record_heights=int(flags.size),
               n_corrected=int(np.sum((flags & correction.INVALIDATING) == 0)),
               n_periods=int(records.sizes["time"]),
               n_periods_missing=int(records.attrs["n_missing"]),
               n_cells_invalid=int(records.attrs["n_invalid"]),
               n_motion_rows_off_grid=int(motion_off))
    return out
