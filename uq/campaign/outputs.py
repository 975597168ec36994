"""What a campaign's Dataset says about itself: the CF attributes of every variable, and
its tables as CSV with the unit of each column in the header (``name [unit]``)."""
import numpy as np
import pandas as pd

from uq.campaign import correction
from uq.pipeline.metadata import cf_encode, history

#: name -> (units, long_name, standard_name or None).
METADATA = {
    "time": (None, "start of the ten-minute period (UTC)", "time"),
    "height": ("m", "measurement height above sea level", "height"),
    "bin": ("m s-1", "centre of the wind-speed bin (the reference's speed where it "
            "gives one, else the corrected mean speed)", None),
    "wind_speed_measured": ("m s-1", "the lidar's ten-minute mean horizontal wind speed, "
                            "as recorded", "wind_speed"),
    "wind_speed_std_measured": ("m s-1", "the lidar's ten-minute standard deviation of the "
                                "horizontal wind speed, as recorded", None),
    "wind_direction": ("degree", "the lidar's ten-minute wind direction", "wind_from_direction"),
    "availability": ("1", "the lidar's availability of the record at the height", None),
    "wind_speed_corrected": ("m s-1", "mean horizontal wind speed freed of the platform "
                             "motion's bias", "wind_speed"),
    "turbulence_intensity_measured": ("1", "the lidar's turbulence intensity, recorded "
                                      "standard deviation over mean speed", None),
    "turbulence_intensity_corrected": ("1", "turbulence intensity corrected for the "
                                       "platform's motion and the lidar's filtering", None),
    "turbulence_intensity_corrected_u": ("1", "standard uncertainty of the corrected "
                                         "turbulence intensity", None),
    "turbulence_intensity_corrected_low": ("1", "lower end of the corrected turbulence "
                                           "intensity's coverage interval", None),
    "turbulence_intensity_corrected_high": ("1", "upper end of the corrected turbulence "
                                            "intensity's coverage interval", None),
    "turbulence_intensity_reference": ("1", "the reference's turbulence intensity", None),
    "turbulence_intensity_measured_predicted": ("1", "expected measured turbulence "
                                                "intensity of the model given the "
                                                "reference's", None),
    "turbulence_intensity_measured_predicted_u": ("1", "standard deviation of the measured "
                                                  "turbulence intensity the model predicts "
                                                  "from record to record", None),
    "wind_speed_reference": ("m s-1", "the reference's ten-minute mean wind speed",
                             "wind_speed"),
    "variance_corrected": ("m2 s-2", "the field's ten-minute u-variance at the gate, "
                           "corrected (may be negative)", None),
    "lidar_filtering_factor": ("1", "the lidar's filtering factor of the record's "
                               "u-variance (spectral path; 1 with filtering none)", None),
    "record_variance_spread": ("1", "tr((PC)^2) / tr(PC)^2 of the lidar's turbulence over "
                               "a record: half the squared coefficient of variation of its "
                               "variance", None),
    "motion_variance": ("m2 s-2", "the platform motion's variance of the record's "
                        "horizontal speed (GUM, the record's high-pass)", None),
    "motion_u": ("m s-1", "the platform motion's standard uncertainty of one scan's "
                 "horizontal speed (GUM)", None),
    "motion_cross": ("m2 s-2", "the motion's cross term with the turbulence in the "
                     "spread of the record's variance, sum of its harmonics' variances "
                     "times the turbulence's cross response", None),
    "motion_phase": ("m4 s-4", "variance of the motion's own sample variance over a record "
                     "(its harmonics' phases unknown)", None),
    "motion_turbulence_intensity": ("1", "the motion's turbulence-intensity increment, "
                                    "sqrt(motion variance) over the corrected mean speed",
                                    None),
    "wind_speed_motion_bias": ("m s-1", "the platform motion's bias of the mean horizontal "
                               "speed (second order)", None),
    "scan_noise_variance": ("m2 s-2", "variance of one scan's horizontal speed from every "
                            "error but the motion (GUM)", None),
    "record_flags": (None, "what the model could not take or flags in the record", None),
    "required": (None, "the bin is in the required range", None),
    "coverage_n_records": ("1", "records with an interval and a reference", None),
    "coverage_n_covered": ("1", "records whose interval covers the reference", None),
    "coverage_share": ("1", "share of the records whose interval covers the reference",
                       None),
    "coverage_p_value": ("1", "two-sided binomial test of the covered records against "
                         "the nominal coverage", None),
}
#: Per-bin names: prefix -> (units, long name); each is made of the prefix and the
#: statistic (:func:`bin_metadata`).
BIN_STATISTICS = {"count": ("1", "records in the bin"), "mean": ("1", "mean"),
                  "std": ("1", "standard deviation (ddof 1)"), "q90": ("1", "90 % quantile")}
BIN_METRICS = {"mean_bias": "mean bias error against the reference",
               "relative_mean_bias": "mean bias error over the mean reference turbulence "
               "intensity", "rmse": "root-mean-square error against the reference",
               "relative_rmse": "root-mean-square error over the mean reference turbulence "
               "intensity", "representative_error": "representative turbulence "
               "intensity (mean + 1.28 sd) minus the reference's",
               "representative": "representative turbulence intensity (mean + 1.28 sd)"}


def bin_metadata(name):
    """(units, long_name) of a per-bin variable ``ti_...`` (None if unknown)."""
    for label in ("measured", "corrected"):
        for stat, (units, text) in BIN_STATISTICS.items():
            if name == f"ti_{label}_{stat}":
                return units, f"{text} of the {label} turbulence intensity in the bin"
        for metric, text in BIN_METRICS.items():
            if name == f"ti_{metric}_{label}":
                return "1", f"{text}, {label} turbulence intensity"
    fixed = {"ti_n_records": ("1", "records with a reference and a corrected turbulence "
                              "intensity in the bin"),
             "ti_reference_mean": ("1", "mean reference turbulence intensity in the bin"),
             "ti_reference_representative": ("1", "representative reference turbulence "
                                             "intensity (mean + 1.28 sd)"),
             "ti_corrected_u_mean": ("1", "standard uncertainty of the bin's mean corrected "
                                     "turbulence intensity"),
             "ti_mean_bias_corrected_u": ("1", "stated standard uncertainty of the corrected "
                                          "mean bias error"),
             "ti_mean_bias_measured_predicted": ("1", "mean bias error of the measured "
                                                 "turbulence intensity the model predicts"),
             "ti_mean_bias_measured_predicted_u": ("1", "standard uncertainty of the bin's "
                                                   "measured mean bias about its prediction")}
    return fixed.get(name)


def annotate(ds, command):
    """CF attributes in place; returns `ds`."""
    for name in ds.variables:
        found = METADATA.get(name)
        if found is None:
            found = bin_metadata(name)
            found = None if found is None else (*found, None)
        if found is None and name.startswith("speed_"):
            found = (None if "verdict" in name else "1", name.replace("_", " ") +
                     " (OWA roadmap KPI of the lidar's mean speed against the reference's)",
                     None)
        if found is None:
            continue
        units, long_name, standard = found
        ds[name].attrs["long_name"] = long_name
        if units and np.asarray(ds[name].values).dtype.kind not in "OUSM":
            ds[name].attrs["units"] = units
        if standard:
            ds[name].attrs["standard_name"] = standard
    ds["height"].attrs.update(axis="Z", positive="up")
    ds["time"].attrs.update(axis="T")
    ds["record_flags"].attrs.update(
        flag_masks=np.array([bit for bit, _, _, _ in correction.FLAGS], dtype=np.int32),
        flag_meanings=" ".join(name for _, name, _, _ in correction.FLAGS))
    for name in list(ds.data_vars):
        if ds[name].dtype == object:
            ds[name] = ds[name].astype(str)
    ds.attrs.update(Conventions="CF-1.10", title=f"uq campaign: {ds.attrs['name']}",
                    history=history(command))
    return cf_encode(ds)


def _header(ds, name):
    units = ds[name].attrs.get("units")
    return f"{name} [{units}]" if units else name


def records_table(ds):
    """One row per period and height: the records' variables (CSV, units in headers)."""
    names = [n for n in ds.data_vars if ds[n].dims == ("time", "height")]
    frame = ds[names].to_dataframe().reset_index()
    frame["time"] = pd.DatetimeIndex(frame["time"]).strftime("%Y-%m-%dT%H:%MZ")
    return frame.rename(columns={"time": "time [UTC, start of period]", "height": "height [m]",
                                 **{n: _header(ds, n) for n in names}})


def bins_table(ds):
    """One row per bin and height: the per-bin variables (CSV, units in headers)."""
    names = [n for n in ds.data_vars if ds[n].dims == ("bin", "height")]
    frame = ds[names + ["required"]].to_dataframe().reset_index()
    return frame.rename(columns={"bin": "bin [m s-1]", "height": "height [m]",
                                 **{n: _header(ds, n) for n in names}})


def heights_table(ds):
    """One row per height: coverage and speed KPIs (where given)."""
    names = [n for n in ds.data_vars if ds[n].dims == ("height",)]
    if not names:
        return None
    frame = ds[names].to_dataframe().reset_index()
    return frame.rename(columns={"height": "height [m]", **{n: _header(ds, n) for n in names}})
