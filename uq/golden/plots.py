"""Figures of a finished golden-lidar Dataset (:func:`uq.golden.analysis.analyse`).

Each function takes the Dataset and a height [m] and returns a matplotlib Figure; no
numbers are computed here beyond what a plot needs (lines through the stored slopes).
"""
import matplotlib.pyplot as plt
import numpy as np

from .classification import percentage_deviation

TERMS = (("reference_calibration", "reference calibration"),
         ("reference_classification", "reference classification"),
         ("statistical", "statistical (sigma/sqrt N)"),
         ("mean_deviation", "mean deviation |dv| (IEC)"))
COLOURS = ("#4c72b0", "#dd8452", "#55a868", "#c44e52")


def plot_scatter(ds, height):
    """Unit against reference, speed and direction, with the KPI regressions."""
    comparisons = ds["comparison"].values
    fig, axes = plt.subplots(len(comparisons), 2, figsize=(9, 3.6 * len(comparisons)),
                             squeeze=False, layout="constrained")
    for row, key in zip(axes, comparisons):
        c = ds.sel(comparison=key, height=height)
        _scatter_speed(row[0], c)
        _scatter_direction(row[1], c)
        row[0].set_title(f"{key} at {height:g} m: wind speed")
        row[1].set_title(f"{key} at {height:g} m: wind direction")
    return fig


def _scatter_speed(ax, c):
    x, y = c["paired_reference_speed"].values, c["paired_unit_speed"].values
    ax.plot(x, y, ".", ms=1.5, alpha=0.3, color="grey")
    top = np.nanmax(x)
    slope = float(c["speed_slope"])
    ax.plot([0, top], [0, top], "k:", lw=1, label="1:1")
    ax.plot([0, top], [0, slope * top], "r-", lw=1.2,
            label=f"y = {slope:.4f} x, R² = {float(c['speed_r_squared']):.4f}")
    ax.set(xlabel=f"{_name(c, 'reference')} [m/s]", ylabel=f"{_name(c, 'unit')} [m/s]")
    ax.legend(loc="upper left", fontsize=8)


def _scatter_direction(ax, c):
    x = np.mod(c["paired_reference_direction"].values, 360.0)
    y = c["paired_unit_direction"].values
    y = x + np.mod(y - x + 180.0, 360.0) - 180.0          # wrap-around, as in the KPI
    ax.plot(x, y, ".", ms=1.5, alpha=0.3, color="grey")
    slope, offset = float(c["direction_slope"]), float(c["direction_offset"])
    ax.plot([0, 360], [0, 360], "k:", lw=1)
    ax.plot([0, 360], [offset, offset + 360 * slope], "r-", lw=1.2,
            label=f"y = {slope:.4f} x {offset:+.2f}°, R² = "
            f"{float(c['direction_r_squared']):.4f}")
    ax.set(xlabel=f"{_name(c, 'reference')} [deg]", ylabel=f"{_name(c, 'unit')} [deg]",
           xlim=(0, 360))
    ax.legend(loc="upper left", fontsize=8)


def plot_deviation_against_environment(ds, height):
    """Percentage deviation against each environmental variable, with the slope."""
    comparisons, variables = ds["comparison"].values, ds["variable"].values
    fig, axes = plt.subplots(len(comparisons), len(variables), squeeze=False,
                             figsize=(3.4 * len(variables), 3.0 * len(comparisons)),
                             layout="constrained")
    for row, key in zip(axes, comparisons):
        c = ds.sel(comparison=key, height=height)
        ref, unit = c["paired_reference_speed"].values, c["paired_unit_speed"].values
        inside = (ref >= ds.attrs["required_low"] - ds.attrs["bin_width"] / 2) & \
                 (ref < ds.attrs["required_high"] + ds.attrs["bin_width"] / 2)
        deviation = np.where(inside, percentage_deviation(unit, ref), np.nan)
        for ax, variable in zip(row, variables):
            x = c["paired_environment"].sel(variable=variable).values
            x = np.where(np.isfinite(deviation), x, np.nan)        # the records regressed
            ax.plot(x, deviation, ".", ms=1.5, alpha=0.25, color="grey")
            s = c.sel(variable=variable)
            line = np.nanpercentile(x, [0.5, 99.5])
            ax.set_xlim(line)
            ax.plot(line, float(s["slope_intercept"]) + float(s["slope"]) * line, "r-",
                    label=f"m = {float(s['slope']):.3g} ± {float(s['slope_standard_error']):.2g}"
                    f" %/unit, p = {float(s['slope_p_value']):.2g}")
            ax.set(xlabel=str(variable), ylabel="deviation [%]", title=f"{key}, {height:g} m")
            ax.set_ylim(np.nanpercentile(deviation, [0.5, 99.5]))
            ax.legend(fontsize=7, loc="lower left")
    return fig


def plot_uncertainty_terms(ds, height, unit=None):
    """Seed Fig. 3: the calibration-uncertainty terms of `unit` per bin, one row per
    reference and one column per framework; a bottom row compares the references.

    Bars stack the terms' shares of the variance, scaled so that the stack's height is
    u_cal (the terms add in quadrature, not linearly)."""
    keys = [k for k, u in zip(ds["comparison"].values, ds["unit"].values) if u == unit] \
        if unit else list(ds["comparison"].values)
    frameworks = ds["framework"].values
    fig, axes = plt.subplots(len(keys) + 1, len(frameworks), squeeze=False, sharex=True,
                             figsize=(5.5 * len(frameworks), 2.8 * (len(keys) + 1)),
                             layout="constrained")
    shown = ds.sel(height=height).isel(bin=np.flatnonzero(ds["required"].values))
    for row, key in zip(axes, keys):
        for ax, framework in zip(row, frameworks):
            _stacked_terms(ax, shown.sel(comparison=key, framework=framework))
            ax.set_title(f"{key}, {framework.upper()}, {height:g} m")
    for ax, framework in zip(axes[-1], frameworks):
        for key in keys:
            c = shown.sel(comparison=key, framework=framework)
            ax.plot(c["bin"], c["calibration"], "o-", ms=3, label=f"u_cal, {key}")
        ax.set(xlabel="reference wind speed bin [m/s]", ylabel="u_cal [m/s]",
               title=f"references compared, {framework.upper()}")
        ax.legend(fontsize=7)
    axes[0][0].legend(fontsize=7, loc="upper left")
    return fig


def _stacked_terms(ax, c):
    total = c["calibration"].values
    bottom = np.zeros_like(total)
    with np.errstate(invalid="ignore", divide="ignore"):
        for (name, label), colour in zip(TERMS, COLOURS):
            share = np.nan_to_num(c[name].values ** 2 / total ** 2 * total)
            ax.bar(c["bin"], share, bottom=bottom, width=0.4, color=colour, label=label)
            bottom = bottom + share
    ax.set(ylabel="u_cal [m/s]")


def _name(c, role):
    return str(c[role].values)
