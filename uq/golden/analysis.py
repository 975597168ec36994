"""The orchestrator of ``uq golden``: records in, one Dataset of every table out.

For each comparison (a unit verified against a reference) and height: the per-bin
statistics, the deviation terms of Eq. 3 under both frameworks, the sensitivity slopes
and the unit's classification uncertainty (Eq. 1 and the class-number route), the KPIs;
then the golden-lidar chain (seed Fig. 1): a reference that is itself verified here
brings its own calibration and classification uncertainty into the unit's Eq. 2.

Dimensions: ``comparison`` (``unit-reference``), ``height`` [m], ``bin`` (centre
[m s-1]), ``framework`` (``iec``, ``lusr``), ``variable`` (environmental), ``time``
(the paired records, for the figures).
"""
import functools

import numpy as np
import xarray as xr

from uq.errors import ScenarioError
from uq.pipeline.metadata import cf_encode, history
from . import binning, calibration, classification, kpi, turbulence
from .records import align, load_records

FRAMEWORKS = calibration.FRAMEWORKS
RECORD_PERIOD = np.timedelta64(10, "m")
#: Sensitivity fields -> result variables (dimension ``variable``).
SENSITIVITY_NAMES = {"slope": "slope", "intercept": "slope_intercept",
                     "slope_standard_error": "slope_standard_error",
                     "p_value": "slope_p_value", "r_squared": "slope_r_squared",
                     "n_records": "slope_n_records", "significant": "slope_significant"}


def analyse(config):
    """Every table of a :class:`uq.golden.config.GoldenConfig` as one Dataset."""
    records = {name: load_records(spec) for name, spec in config.instruments.items()}
    smc = load_records(config.smc) if config.smc is not None else None
    _check_variables(config, records, smc)
    pairs = {f"{u}-{r}": align(records[u], records[r]) for u, r in config.comparisons}
    top = max(float(np.nanmax(ref["speed"].values)) for _, ref, _ in pairs.values())
    # the grid covers the data and the required range (an empty required bin is flagged)
    centres = binning.bin_centres(0.0, max(top, config.required[1]), config.bin_width)
    parts = [_comparison(config, key, *pairs[key], centres, smc) for key in pairs]
    ds = xr.concat(parts, dim="comparison", join="outer", coords="different",
                   compat="equals")
    ds = ds.assign_coords(comparison=list(pairs), bin=centres)
    ds["required"] = ("bin", binning.sufficient_bins(np.zeros(len(centres)), centres,
                                                     config.minimum_records,
                                                     config.required)[1])
    ds["unit"] = ("comparison", [u for u, _ in config.comparisons])
    ds["reference"] = ("comparison", [r for _, r in config.comparisons])
    _chain(config, ds)
    _annotate(ds)
    ds.attrs.update(Conventions="CF-1.10", title=f"uq golden: verification campaign "
                    f"{config.name}", history=history(f"uq golden, campaign {config.name}"),
                    name=config.name, description=config.description,
                    significance=config.significance, route=config.route,
                    bin_width=config.bin_width, required_low=config.required[0],
                    required_high=config.required[1], minimum_records=config.minimum_records,
                    n_invalid=sum(int(r.attrs["n_invalid"]) for r in records.values()),
                    campaign_instruments=" ".join(
                        f"{name}:{r.attrs['campaign_motion']}" for name, r in records.items()
                        if "campaign_motion" in r.attrs))
    return ds


def _check_variables(config, records, smc):
    for name in config.variables:
        for where, ds in list(records.items()) + [("smc", smc)]:
            if ds is not None and name not in ds:
                raise ScenarioError(config.source, "golden.classification.variables",
                                    f"{name!r} is not an environmental variable of {where}; "
                                    f"allowed: {', '.join(_env(ds)) or 'none declared'}")
    if config.route == "class_number":
        missing = [v for v in config.variables if v not in config.ranges]
        if missing:
            raise ScenarioError(config.source, "golden.classification.ranges",
                                f"no range for {', '.join(missing)}; the class-number route "
                                "needs [low, high] for every variable")
    elif config.smc is None and any(s.calibration is None for s in config.instruments.values()):
        raise ScenarioError(config.source, "golden.smc", "missing; the per_variable route "
                            "(Eq. 1) needs the specific measurement campaign's records, "
                            "or set classification.route: class_number")


def _env(ds):
    return [v for v in ds.data_vars if v not in ("speed", "direction")]


def _comparison(config, key, unit, reference, counts, centres, smc):
    """Tables of one comparison, dimensions (height, bin, framework, variable, time)."""
    heights = unit["height"].values
    scenario = tuple(config.instruments[ds.attrs["instrument"]].scenario
                     if ds.attrs.get("instrument") in config.instruments else None
                     for ds in (unit, reference))
    per_height = [_height_tables(config, unit.sel(height=h), reference.sel(height=h),
                                 centres, smc.sel(height=h) if smc is not None and h in
                                 smc["height"].values else None, scenario) for h in heights]
    ds = xr.concat(per_height, dim="height").assign_coords(height=heights)
    ds["records_only_unit"] = counts["only_unit"]
    ds["records_only_reference"] = counts["only_reference"]
    return ds.expand_dims(comparison=[key])


def _height_tables(config, unit, reference, centres, smc, scenario=None):
    ref_speed, unit_speed = reference["speed"].values, unit["speed"].values
    stats = binning.bin_statistics(ref_speed, unit_speed, centres, config.bin_width)
    sufficient, required = binning.sufficient_bins(stats["n_records"], centres,
                                                   config.minimum_records, config.required)
    data = {k: ("bin", v) for k, v in stats.items()}
    data["sufficient"] = ("bin", sufficient)
    terms = [calibration.deviation_terms(stats, f) for f in FRAMEWORKS]
    data["statistical"] = (("framework", "bin"), np.array([t[0] for t in terms]))
    data["mean_deviation"] = (("framework", "bin"), np.array([t[1] for t in terms]))
    fits = _sensitivities(config, unit, reference)
    data.update({SENSITIVITY_NAMES[name]: ("variable", np.array([getattr(f, name)
                                                                 for f in fits]))
                 for name in SENSITIVITY_NAMES})          # (no variable: empty tables)
    # only significant slopes enter Eq. 1 and the class number (seed: "sensitive variables")
    slopes = np.array([f.slope if f.significant else 0.0 for f in fits])
    data.update(_classification(config, centres, reference, smc, slopes))
    data.update(_kpis(config, unit, reference, sufficient, required))
    data.update(_paired(config, unit, reference))
    data.update(_turbulence(config, unit, reference, centres, scenario))
    return xr.Dataset(data, coords={"framework": list(FRAMEWORKS),
                                    "variable": list(config.variables)})


def _turbulence(config, unit, reference, centres, scenario):
    """TI statistics, KPIs and verdicts per bin (:mod:`uq.golden.turbulence`) when both
    instruments carry the TI variable; the predicted apparent TI when the unit names its
    scenario (NaN otherwise)."""
    name = config.ti_variable
    if name not in unit or name not in reference:
        return {}
    stats = turbulence.ti_bin_kpis(reference[name].values, unit[name].values,
                                   reference["speed"].values, centres, config.bin_width)
    copied = turbulence.copies(reference[name].values, unit[name].values)
    if copied:                  # not a measurement of the unit: no error to state
        stats.update({k: np.full_like(stats[k], np.nan) for k in turbulence.UNIT_STATISTICS})
    data = {f"ti_{k}": ("bin", v) for k, v in stats.items()}
    data["ti_unit_copies_reference"] = ((), copied)
    for kpi_name in turbulence.TI_KPIS:
        data[f"ti_{kpi_name}_verdict"] = ("bin", turbulence.band_verdicts(
            stats[kpi_name], config.ti_bands.get(kpi_name)))
    unit_scenario, reference_scenario = scenario or (None, None)
    ratio = np.nan
    if unit_scenario is not None:    # a lidar reference filters too: the ratio of the two
        speed, height = float(np.mean(config.required)), float(unit["height"])
        ratio = _predicted_ratio(unit_scenario, height, speed) / (
            1.0 if reference_scenario is None else
            _predicted_ratio(reference_scenario, height, speed))
    data["ti_predicted_ratio"] = ((), ratio)
    data["ti_predicted_mean"] = ("bin", stats["reference_mean"] * np.sqrt(ratio))
    return data


@functools.lru_cache(maxsize=256)
def _cached_ratio(source, text, height, speed):
    """The ratio of the scenario as run (its `text`: ``uq golden --set`` may have changed
    it from the file at `source`)."""
    import yaml
    from uq.pipeline.scenario import load_scenario
    settings = load_scenario(yaml.safe_load(text)).settings
    return turbulence.predicted_variance_ratio(settings, height, speed)


def _predicted_ratio(scenario, height, speed):
    """The unit's u-variance ratio (:func:`uq.golden.turbulence.predicted_variance_ratio`),
    once per scenario file, height and speed."""
    return turbulence.predicted_variance_ratio(scenario.settings, height, speed) \
        if scenario.source is None else _cached_ratio(str(scenario.source), scenario.text,
                                                      height, speed)


def _in_required_range(config, speed):
    half = config.bin_width / 2.0
    return (speed >= config.required[0] - half) & (speed < config.required[1] + half)


def _sensitivities(config, unit, reference):
    """:class:`uq.golden.classification.Sensitivity` per variable, over the records with
    the reference speed in the required bins."""
    ref_speed = reference["speed"].values
    deviation = classification.percentage_deviation(unit["speed"].values, ref_speed)
    deviation = np.where(_in_required_range(config, ref_speed), deviation, np.nan)
    return [classification.sensitivity(reference[v].values, deviation, config.significance)
            for v in config.variables]


def _bin_means(values, speed, centres, width):
    """Mean of `values` per bin of `speed`."""
    index = binning.bin_index(speed, width)
    keys = np.rint(np.asarray(centres) / width).astype(int)
    return np.array([np.nanmean(values[index == k]) if np.any(np.isfinite(
        values[index == k])) else np.nan for k in keys])


def _classification(config, centres, reference, smc, slopes):
    """The unit's classification uncertainty by both routes (NaN where not possible)."""
    out = {}
    ver = np.array([_bin_means(reference[v].values, reference["speed"].values, centres,
                               config.bin_width) for v in config.variables])
    ver = ver.reshape(len(config.variables), len(centres))     # (0 variables: empty)
    out["verification_mean"] = (("variable", "bin"), ver)
    if smc is not None:
        smc_means = np.array([_bin_means(smc[v].values, smc["speed"].values, centres,
                                         config.bin_width) for v in config.variables])
        smc_means = smc_means.reshape(len(config.variables), len(centres))
        out["smc_mean"] = (("variable", "bin"), smc_means)
        out["smc_n_records"] = ("bin", binning.bin_statistics(
            smc["speed"].values, smc["speed"].values, centres, config.bin_width)["n_records"])
        per_variable = classification.per_variable_uncertainty(centres, slopes, smc_means,
                                                               ver.reshape(smc_means.shape))
    else:
        per_variable = np.full(len(centres), np.nan)
    out["classification_per_variable"] = ("bin", per_variable)
    ranges = [config.ranges.get(v) for v in config.variables]
    number = classification.class_number([m for m, r in zip(slopes, ranges) if r],
                                         [r for r in ranges if r]) \
        if all(ranges) else np.nan
    out["class_number"] = number
    out["classification_class_number"] = ("bin", classification.class_number_uncertainty(
        centres, number))
    return out


def _kpis(config, unit, reference, sufficient, required):
    """KPIs and verdicts; availability over the reference's span of 10-min periods."""
    values = {**kpi.speed_kpis(reference["speed"].values, unit["speed"].values),
              **kpi.direction_kpis(reference["direction"].values, unit["direction"].values)}
    times = reference["time"].values
    expected = int((times.max() - times.min()) / RECORD_PERIOD) + 1 if len(times) else 0
    available = kpi.availability(np.sum(np.isfinite(unit["speed"].values)), expected)
    values.update(availability=available,
                  availability_verdict=kpi.at_least_verdict(available, config.availability),
                  coverage_verdict=kpi.coverage_verdict(sufficient, required))
    return values


def _paired(config, unit, reference):
    """The paired records (for the figures of a finished Dataset)."""
    data = {"paired_reference_speed": ("time", reference["speed"].values),
            "paired_unit_speed": ("time", unit["speed"].values),
            "paired_reference_direction": ("time", reference["direction"].values),
            "paired_unit_direction": ("time", unit["direction"].values)}
    if config.variables:
        data["paired_environment"] = (("variable", "time"), np.array(
            [reference[v].values for v in config.variables]))
    return data | {"time": ("time", reference["time"].values)}


def _chain(config, ds):
    """Eq. 2 along the golden-lidar chain, per comparison, framework, height and bin."""
    ds["deviation"] = calibration.quadrature(ds["statistical"], ds["mean_deviation"])
    chosen = ds["classification_per_variable"] if config.route == "per_variable" \
        else ds["classification_class_number"]
    ds["classification"] = chosen
    verified = {u: key for key, u in zip(ds["comparison"].values, ds["unit"].values)}
    cal, cls = [], []
    for key, reference in zip(ds["comparison"].values, ds["reference"].values):
        ref_cal, ref_cls = _reference_terms(config, ds, reference, verified)
        cal.append(ref_cal)
        cls.append(ref_cls)
    like = ds["deviation"]
    ds["reference_calibration"] = xr.concat(cal, "comparison").broadcast_like(like)
    ds["reference_classification"] = xr.concat(cls, "comparison").broadcast_like(like)
    ds["calibration"] = calibration.calibration_uncertainty(
        ds["reference_calibration"], ds["reference_classification"], ds["deviation"])
    ds["total"] = calibration.quadrature(ds["calibration"], ds["classification"])
    ds["reference_calibration"] = ds["reference_calibration"].transpose(*like.dims)
    ds["reference_classification"] = ds["reference_classification"].transpose(*like.dims)


def _reference_terms(config, ds, reference, verified):
    """(u_cal,Ref, u_class,Ref) of a reference: stated, or from its own comparison."""
    spec = config.instruments[reference]
    centres = ds["bin"]
    if spec.calibration is not None:
        stated = calibration.stated_calibration(centres.values, *spec.calibration)
        number = spec.class_number or 0.0
        return (xr.DataArray(stated, coords={"bin": centres}, dims="bin"),
                xr.DataArray(classification.class_number_uncertainty(centres.values, number),
                             coords={"bin": centres}, dims="bin"))
    own = ds.sel(comparison=verified[reference])
    own_cal = calibration.calibration_uncertainty(
        *_reference_terms(config, ds, own["reference"].item(), verified), own["deviation"])
    return own_cal.drop_vars("comparison", errors="ignore"), \
        own["classification"].drop_vars("comparison", errors="ignore")


#: Marks a variable along ``variable`` whose unit is each environmental variable's own
#: (degC, percent, m s-1, ...): one netCDF variable holds several, and the configuration
#: names columns, not units, so it carries no ``units`` attribute (a wrong one, "1" or
#: "percent", would mislead) and its long_name says so.
PER_VARIABLE = ""
#: units and long names of the result variables (verdicts and flags are dimensionless).
METADATA = {
    "height": ("m", "measurement height above sea level"),
    "bin": ("m s-1", "centre of the reference-wind-speed bin"),
    "n_records": ("1", "paired 10-min records in the bin"),
    "sufficient": ("1", "the bin holds the minimum number of records"),
    "required": ("1", "the bin is in the required range"),
    "reference_mean": ("m s-1", "mean reference wind speed in the bin"),
    "unit_mean": ("m s-1", "mean wind speed of the unit in the bin"),
    "unit_std": ("m s-1", "standard deviation of the unit's wind speed in the bin"),
    "deviation_mean": ("m s-1", "mean deviation unit minus reference (Delta v)"),
    "deviation_std": ("m s-1", "standard deviation of the deviations"),
    "statistical": ("m s-1", "sigma/sqrt(N) term of Eq. 3 (sigma_FLS for IEC, sigma_dev "
                    "for LUSR)"),
    "mean_deviation": ("m s-1", "|Delta v| term of Eq. 3 (IEC; zero for LUSR)"),
    "deviation": ("m s-1", "deviation term u_dev (Eq. 3)"),
    "reference_calibration": ("m s-1", "calibration uncertainty of the reference"),
    "reference_classification": ("m s-1", "classification uncertainty of the reference"),
    "calibration": ("m s-1", "calibration uncertainty of the unit against the reference "
                    "(Eq. 2)"),
    "classification_per_variable": ("m s-1", "classification uncertainty of the unit, "
                                    "Eq. 1 for the SMC"),
    "classification_class_number": ("m s-1", "classification uncertainty of the unit, "
                                    "class number / sqrt(3) %"),
    "classification": ("m s-1", "classification uncertainty of the unit (chosen route)"),
    "total": ("m s-1", "calibration and classification uncertainty of the unit"),
    "verification_mean": (PER_VARIABLE, "bin mean of the variable in the verification "
                          "campaign, in the variable's own units (those of its column)"),
    "smc_mean": (PER_VARIABLE, "bin mean of the variable in the SMC, in the variable's own "
                 "units (those of its column)"),
    "smc_n_records": ("1", "SMC records in the bin"),
    "slope": (PER_VARIABLE, "sensitivity slope of the percentage deviation, in percent per "
              "unit of the variable (its column's unit)"),
    "slope_intercept": ("percent", "intercept of the sensitivity regression"),
    "slope_standard_error": (PER_VARIABLE, "standard error of the sensitivity slope, in "
                             "percent per unit of the variable (its column's unit)"),
    "slope_p_value": ("1", "two-sided p-value of the slope (t-test of zero slope)"),
    "slope_r_squared": ("1", "R^2 of the sensitivity regression"),
    "slope_n_records": ("1", "records in the sensitivity regression"),
    "slope_significant": ("1", "slope significant at the configured level"),
    "class_number": ("percent", "class number from the slopes and the variables' ranges"),
    "speed_slope": ("1", "wind-speed regression slope through the origin"),
    "speed_r_squared": ("1", "R^2 of the wind-speed regression"),
    "speed_n_records": ("1", "records in the wind-speed regression"),
    "direction_slope": ("1", "wind-direction regression slope"),
    "direction_offset": ("degree", "wind-direction regression offset"),
    "direction_r_squared": ("1", "R^2 of the wind-direction regression"),
    "direction_n_records": ("1", "records in the wind-direction regression"),
    "availability": ("1", "fraction of 10-min periods with a valid unit record"),
    "records_only_unit": ("1", "timestamps of the unit without a reference record"),
    "records_only_reference": ("1", "timestamps of the reference without a unit record"),
    "paired_reference_speed": ("m s-1", "reference wind speed of the paired records"),
    "paired_unit_speed": ("m s-1", "unit wind speed of the paired records"),
    "paired_reference_direction": ("degree", "reference wind direction (from, clockwise "
                                   "from north)"),
    "paired_unit_direction": ("degree", "unit wind direction (from, clockwise from north)"),
    "paired_environment": (PER_VARIABLE, "environmental variables of the reference, each "
                           "in its own units (those of its column)"),
    "ti_n_records": ("1", "records in the bin with a TI from both instruments"),
    "ti_reference_mean": ("percent", "mean TI of the reference in the bin"),
    "ti_unit_mean": ("percent", "mean TI of the unit in the bin"),
    "ti_mean_bias": ("percent", "TI mean bias error, unit minus reference (percentage "
                     "points)"),
    "ti_relative_error": ("1", "TI mean bias error over the reference's mean TI"),
    "ti_rmse": ("percent", "root-mean-square TI error (percentage points)"),
    "ti_reference_representative": ("percent", "representative TI of the reference, mean "
                                    "+ 1.28 sd"),
    "ti_unit_representative": ("percent", "representative TI of the unit, mean + 1.28 sd"),
    "ti_representative_error": ("percent", "representative TI of the unit minus the "
                                "reference's (percentage points)"),
    "ti_predicted_ratio": ("1", "u-variance ratio lidar / point predicted by the spectral "
                           "path for the unit's lidar (IEC Mann field, fixed and level), "
                           "over the reference's own ratio where the reference is a lidar "
                           "with a scenario"),
    "ti_predicted_mean": ("percent", "apparent TI the unit is predicted to read: reference "
                          "mean TI times sqrt(ti_predicted_ratio)"),
    "ti_unit_copies_reference": ("", "the unit's TI is the reference's record for record (not "
                                 "a measurement: its TI statistics are NaN)"),
    "time": ("", "start of the paired 10-min record"),
    "comparison": ("", "comparison: unit-reference"),
    "framework": ("", "framework of the deviation term: iec (IEC 61400-12-1) or lusr"),
    "variable": ("", "environmental variable"),
    "unit": ("", "instrument verified in the comparison"),
    "reference": ("", "reference instrument of the comparison"),
}
#: CF standard names of the coordinates. "height" is the vertical distance above the
#: surface, here the sea surface (CF's checker expects it of a coordinate named height).
STANDARD_NAMES = {"height": "height", "time": "time"}


def _annotate(ds):
    """CF attributes and encodings, in place (:func:`uq.pipeline.metadata.cf_encode`):
    units (none for texts and the time, which xarray encodes), long names, standard
    names of the height and time coordinates."""
    for name, (units, long_name) in METADATA.items():
        if name in ds.variables:
            ds[name].attrs.update({"long_name": long_name, **({"units": units} if units
                                                              else {})})
    for name in ds.data_vars:
        if name.endswith("_verdict"):
            ds[name].attrs.update(long_name=name.replace("_", " "))
    for name, standard_name in STANDARD_NAMES.items():
        if name in ds.variables:
            ds[name].attrs["standard_name"] = standard_name
    if "height" in ds.variables:
        ds["height"].attrs.update(axis="Z", positive="up")
    cf_encode(ds)
