"""The figures of a campaign, from its finished Dataset alone (TI in percent)."""
import numpy as np

PERCENT = 100.0
MEASURED, CORRECTED, REFERENCE, PREDICTED = "0.55", "tab:blue", "black", "tab:orange"


def _axes(count, width=4.2, height=3.6):
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(1, count, figsize=(width * count, height), squeeze=False,
                             constrained_layout=True)
    return fig, axes[0]


def plot_scatter(ds):
    """Measured and corrected TI against the reference's, one panel per height, the
    corrected with its interval; the 1:1 line."""
    heights = ds["height"].values
    fig, axes = _axes(len(heights))
    for ax, h in zip(axes, heights):
        d = ds.sel(height=h)
        reference = d["turbulence_intensity_reference"].values * PERCENT
        corrected = d["turbulence_intensity_corrected"].values * PERCENT
        keep = np.isfinite(reference) & np.isfinite(corrected)
        measured = d["turbulence_intensity_measured"].values * PERCENT
        low = d["turbulence_intensity_corrected_low"].values * PERCENT
        high = d["turbulence_intensity_corrected_high"].values * PERCENT
        ax.errorbar(reference[keep], corrected[keep], yerr=[corrected[keep] - low[keep],
                                                            high[keep] - corrected[keep]],
                    fmt="none", ecolor=CORRECTED, alpha=0.15, lw=0.8)
        ax.plot(reference[keep], measured[keep], ".", color=MEASURED, ms=3,
                label="measured")
        ax.plot(reference[keep], corrected[keep], ".", color=CORRECTED, ms=3,
                label="corrected (95 % interval)")
        # every point inside; the intervals' upper ends up to their 99.5 % quantile (the
        # few beyond run off the top, counted in the title)
        points = np.concatenate([reference[keep], measured[keep], corrected[keep]])
        ends = high[keep][np.isfinite(high[keep])]
        top = max(float(np.max(points)) if points.size else 1.0,
                  float(np.quantile(ends, 0.995)) if ends.size else 0.0) * 1.05
        past = int(np.sum(ends > top))
        ax.plot([0, top], [0, top], "-", color=REFERENCE, lw=0.8, label="1:1")
        ax.set(xlim=(0, top), ylim=(0, top), xlabel="reference TI [%]", ylabel="lidar TI [%]",
               title=f"{h:g} m ({int(keep.sum())} records)"
               + (f"\n{past} interval{'s run' if past > 1 else ' runs'} past the top" if past
                  else ""))
        ax.legend(fontsize=7, loc="upper left")
    return fig


def plot_bin_errors(ds):
    """Per bin: the mean bias of the measured and of the corrected TI against the
    reference, the corrected's with its stated uncertainty (2u), the measured's as the
    model predicts it, and the RMSEs; one panel per height."""
    heights = ds["height"].values
    fig, axes = _axes(len(heights))
    centres = ds["bin"].values
    for ax, h in zip(axes, heights):
        d = ds.sel(height=h)
        count = d["ti_n_records"].values
        keep = count > 0
        ax.axhline(0.0, color=REFERENCE, lw=0.6)
        ax.plot(centres[keep], d["ti_mean_bias_measured"].values[keep] * PERCENT, "o-",
                color=MEASURED, ms=3, label="MBE measured")
        ax.plot(centres[keep], d["ti_mean_bias_measured_predicted"].values[keep] * PERCENT,
                "--", color=PREDICTED, label="MBE measured, predicted")
        ax.errorbar(centres[keep], d["ti_mean_bias_corrected"].values[keep] * PERCENT,
                    yerr=2 * d["ti_mean_bias_corrected_u"].values[keep] * PERCENT, fmt="o-",
                    color=CORRECTED, ms=3, capsize=2, label="MBE corrected (2u)")
        ax.plot(centres[keep], d["ti_rmse_measured"].values[keep] * PERCENT, ":",
                color=MEASURED, label="RMSE measured")
        ax.plot(centres[keep], d["ti_rmse_corrected"].values[keep] * PERCENT, ":",
                color=CORRECTED, label="RMSE corrected")
        ax.set(xlabel="wind-speed bin [m/s]", ylabel="TI error [percentage points]",
               title=f"{h:g} m")
        ax.legend(fontsize=7)
    return fig


def plot_bins(ds):
    """Per bin: the mean and the 90 % quantile of the measured and of the corrected TI
    (and of the reference's mean where given); one panel per height."""
    heights = ds["height"].values
    fig, axes = _axes(len(heights))
    centres = ds["bin"].values
    for ax, h in zip(axes, heights):
        d = ds.sel(height=h)
        keep = d["ti_corrected_count"].values > 0
        for label, colour in (("measured", MEASURED), ("corrected", CORRECTED)):
            ax.plot(centres[keep], d[f"ti_{label}_mean"].values[keep] * PERCENT, "o-",
                    color=colour, ms=3, label=f"{label} mean")
            ax.plot(centres[keep], d[f"ti_{label}_q90"].values[keep] * PERCENT, "^--",
                    color=colour, ms=3, label=f"{label} Q90")
        if "ti_reference_mean" in d:
            ax.plot(centres[keep], d["ti_reference_mean"].values[keep] * PERCENT, "s-",
                    color=REFERENCE, ms=3, lw=0.8, label="reference mean")
        ax.set(xlabel="wind-speed bin [m/s]", ylabel="TI [%]", title=f"{h:g} m", ylim=(0, None))
        ax.legend(fontsize=7)
    return fig


def plot_time_series(ds, height):
    """TI at `height` over the campaign: measured, corrected with its interval, the
    reference (at the records corrected), and the motion's TI increment."""
    import matplotlib.pyplot as plt
    d = ds.sel(height=height)
    fig, ax = plt.subplots(figsize=(11, 3.8), constrained_layout=True)
    time = d["time"].values
    ax.fill_between(time, d["turbulence_intensity_corrected_low"].values * PERCENT,
                    d["turbulence_intensity_corrected_high"].values * PERCENT,
                    color=CORRECTED, alpha=0.2, lw=0, label="corrected, 95 % interval")
    ax.plot(time, d["turbulence_intensity_measured"].values * PERCENT, "-", color=MEASURED,
            lw=0.8, label="measured")
    ax.plot(time, d["turbulence_intensity_corrected"].values * PERCENT, "-", color=CORRECTED,
            lw=0.9, label="corrected")
    if "turbulence_intensity_reference" in d:             # where the lidar's is corrected
        corrected = np.isfinite(d["turbulence_intensity_corrected"].values)
        ax.plot(time, np.where(corrected, d["turbulence_intensity_reference"].values, np.nan)
                * PERCENT, "-", color=REFERENCE, lw=0.8, label="reference")
    ax.plot(time, d["motion_turbulence_intensity"].values * PERCENT, "-", color=PREDICTED,
            lw=0.8, label="motion's TI increment")
    ax.set(xlabel="time (UTC)", ylabel="TI [%]", title=f"Turbulence intensity at {height:g} m",
           ylim=(0, None))
    ax.legend(fontsize=7, ncol=5, loc="upper left")
    fig.autofmt_xdate()
    return fig
