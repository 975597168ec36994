"""The campaign report, as Markdown and as self-contained HTML (uq golden's renderers),
from the finished Dataset and its figure files: every number read from the Dataset."""
import numpy as np

from uq.campaign import correction

PERCENT = 100.0


def report_blocks(ds, figures, lidar_name):
    """The report's blocks (heading, paragraph, table, figure); `figures` maps a caption
    to a PNG path."""
    a = ds.attrs
    blocks = [("h1", f"Campaign records corrected: {a['name']}"), ("p", a.get("description", "")),
              ("h2", "Records"),
              ("p", f"{a['n_periods']} ten-minute periods from {_time(ds, 0)} to "
               f"{_time(ds, -1)} UTC at {', '.join(f'{h:g}' for h in ds['height'].values)} m: "
               f"{a['n_record_heights']} record-heights, of which {a['n_corrected']} corrected. "
               f"Periods without a record: {a['n_periods_missing']}; cells that were not "
               f"numbers: {a['n_cells_invalid']}; rows of the motion file off the records' "
               f"periods: {a['n_motion_rows_off_grid']}."),
              ("table", ["flag", "record-heights", "meaning", "values"],
               [[name, a[f"n_{name}"], meaning, "NaN" if invalid else "kept"]
                for _, name, meaning, invalid in correction.FLAGS]),
              ("h2", "Model"),
              ("p", _model_text(ds, lidar_name))]
    blocks += _height_blocks(ds)
    blocks += _bin_blocks(ds)
    blocks += [("h2", "Figures")] + [("figure", path, caption)
                                     for caption, path in figures.items()]
    return blocks


def _time(ds, index):
    return str(ds["time"].values[index])[:16].replace("T", " ")


def _model_text(ds, lidar_name):
    a = ds.attrs
    filtering = ("corrected to the point's TI by the lidar's filtering factor of the "
                 "u-variance (the spectral path: probe volume, beam separation, scan timing, "
                 "the record's high-pass)" if a["filtering"] == "spectral" else
                 "kept (filtering: none): only the motion is removed, the TI is the one a "
                 "lidar of the same type at rest would read")
    return (f"Lidar: {lidar_name}, {a['n_scans']} scans of {a['scan_period']:g} s a record, "
            f"its standard deviation over N - {a['std_ddof']}. The motion "
            f"({a['motion']}) enters through the GUM of the time-resolved measurement model "
            "with the lidar's own correction (its first-order variance, the record's "
            "high-pass) and its second-order shift of the mean speed; every other error of "
            f"a scan through its GUM variance. The lidar's filtering is {filtering}. The "
            f"{100 * a['coverage']:g} % interval holds every TI under which the record's "
            "variance lies within its central share: the spread of a ten-minute variance "
            "(the spectral path's covariance of the lidar's turbulence between scans, the "
            "motion's harmonics aliased by the scans and their cross terms with the "
            "turbulence) in a shifted, scaled chi-square. The model's terms come from tables "
            "(the fast path); their error, measured against the direct path between the "
            f"nodes: TI {100 * a['surrogate_ti_error']:.2f} %, spread of the record variance "
            f"{100 * a['surrogate_spread_error']:.1f} %, motion response "
            f"{100 * a['surrogate_motion_error']:.3f} % of its largest value. Runtime "
            f"{a['runtime_s']:.1f} s.")


def _cell(value, scale=1.0, digits=3):
    value = float(value)
    return "" if not np.isfinite(value) else f"{scale * value:.{digits}f}"


def _height_blocks(ds):
    rows = []
    for h in ds["height"].values:
        d = ds.sel(height=h)
        keep = np.isfinite(d["turbulence_intensity_corrected"].values)
        def mean(name, scale=PERCENT, digits=2):
            return _cell(np.mean(d[name].values[keep]) if keep.any() else np.nan, scale,
                         digits)
        row = [f"{h:g}", int(keep.sum()), mean("turbulence_intensity_measured"),
               mean("turbulence_intensity_corrected"), mean("motion_turbulence_intensity"),
               mean("lidar_filtering_factor", 1.0), mean("wind_speed_motion_bias", 1.0, 3)]
        if "coverage_share" in ds:
            row += [f"{int(d['coverage_n_covered'])}/{int(d['coverage_n_records'])} = "
                    f"{_cell(d['coverage_share'], PERCENT, 1)} %",
                    _cell(d["coverage_p_value"], 1.0, 3)]
        rows.append(row)
    header = ["height [m]", "corrected records", "TI measured [%]", "TI corrected [%]",
              "motion's TI [%]", "filtering factor F", "motion bias [m/s]"]
    text = ("Means over the corrected records. The motion's TI is its variance's square "
            "root over the mean speed; F the lidar's share of the field's u-variance.")
    if "coverage_share" in ds:
        header += ["intervals covering the reference", "binomial p"]
        text += (" Coverage: the share of the records whose interval holds the reference's "
                 f"TI, against the nominal {100 * ds.attrs['coverage']:g} % (two-sided "
                 "binomial test).")
    blocks = [("h2", "Per height"), ("p", text), ("table", header, rows)]
    if "speed_slope_corrected" in ds:
        blocks.append(("table", ["height [m]", "speed slope measured", "speed slope corrected",
                                 "R² measured", "R² corrected"],
                       [[f"{h:g}"] + [_cell(ds[n].sel(height=h), 1.0, 4) for n in (
                           "speed_slope_measured", "speed_slope_corrected",
                           "speed_r_squared_measured", "speed_r_squared_corrected")]
                        for h in ds["height"].values]))
    return blocks


def _bin_blocks(ds):
    blocks = [("h2", "Per wind-speed bin"),
              ("p", "TI in percent. Bins of the reference's speed where it gives one, else "
               "of the corrected mean speed; only corrected records. " + (
                   "MBE = mean(TI - TI_ref), its stated uncertainty u from the records' "
                   "(independent); 'predicted' is the measured MBE the model expects; RMSE; "
                   "representative TI (mean + 1.28 sd) error." if "ti_reference_mean" in ds
                   else ""))]
    for h in ds["height"].values:
        d = ds.sel(height=h)
        keep = np.flatnonzero(d["ti_corrected_count"].values > 0)
        if "ti_reference_mean" in ds:
            names = ("ti_reference_mean", "ti_measured_mean", "ti_corrected_mean",
                     "ti_mean_bias_measured", "ti_mean_bias_measured_predicted",
                     "ti_mean_bias_corrected", "ti_mean_bias_corrected_u", "ti_rmse_measured",
                     "ti_rmse_corrected", "ti_representative_error_measured",
                     "ti_representative_error_corrected")
            header = ["bin [m/s]", "N", "TI ref", "TI meas.", "TI corr.", "MBE meas.",
                      "MBE meas. predicted", "MBE corr.", "u(MBE corr.)", "RMSE meas.",
                      "RMSE corr.", "rep. err. meas.", "rep. err. corr."]
        else:
            names = ("ti_measured_mean", "ti_measured_q90", "ti_corrected_mean",
                     "ti_corrected_std", "ti_corrected_q90")
            header = ["bin [m/s]", "N", "TI meas. mean", "TI meas. Q90", "TI corr. mean",
                      "TI corr. sd", "TI corr. Q90"]
        rows = [[f"{d['bin'].values[i]:g}", int(d["ti_corrected_count"].values[i])]
                + [_cell(d[n].values[i], PERCENT, 2) for n in names] for i in keep]
        blocks += [("h3", f"{h:g} m"), ("table", header, rows)]
    return blocks
