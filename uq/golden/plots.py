"""Figures of a finished golden-lidar Dataset (:func:`uq.golden.analysis.analyse`).

Each function takes the Dataset and a height [m] and returns a matplotlib Figure; no
numbers are computed here beyond what a plot needs (lines through the stored slopes).
Axes are labelled in words with units; p-values are rounded (:func:`p_value_text`); the
calibration terms, which add in quadrature, are stacked as variances on an axis of
squared units, never as shares drawn on an axis in m/s.
"""
import matplotlib.pyplot as plt
import numpy as np

from .classification import percentage_deviation

#: Words and units of the environmental variables of the shipped campaigns (their
#: columns' units); any other variable is named by its column, "in its own unit".
ENVIRONMENT_LABELS = {"shear": "shear exponent [1]",
                      "turbulence_intensity": "turbulence intensity [%]",
                      "temperature": "air temperature [°C]",
                      "wind_veer": "wind veer [deg]",
                      "air_density": "air density [kg m$^{-3}$]",
                      "significant_wave_height": "significant wave height [m]"}
#: p-values below this are written as "p < 0.001" (more digits say nothing).
SMALLEST_P = 1e-3

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
        row[0].set_title(f"{_pair(c)} at {height:g} m: wind speed", fontsize=10)
        row[1].set_title(f"{_pair(c)} at {height:g} m: wind direction", fontsize=10)
    return fig


def _scatter_speed(ax, c):
    x, y = c["paired_reference_speed"].values, c["paired_unit_speed"].values
    ax.plot(x, y, ".", ms=1.5, alpha=0.3, color="grey", label="10-min records")
    top = np.nanmax(x)
    slope = float(c["speed_slope"])
    ax.plot([0, top], [0, top], "k:", lw=1, label="1:1")
    ax.plot([0, top], [0, slope * top], "r-", lw=1.2,
            label=f"y = {slope:.4f} x, R² = {float(c['speed_r_squared']):.4f}")
    ax.set(xlabel=f"wind speed of the reference, {_name(c, 'reference')} [m/s]",
           ylabel=f"wind speed of the unit, {_name(c, 'unit')} [m/s]")
    ax.legend(loc="upper left", fontsize=8)


def _scatter_direction(ax, c):
    x = np.mod(c["paired_reference_direction"].values, 360.0)
    y = c["paired_unit_direction"].values
    y = x + np.mod(y - x + 180.0, 360.0) - 180.0          # wrap-around, as in the KPI
    ax.plot(x, y, ".", ms=1.5, alpha=0.3, color="grey", label="10-min records")
    slope, offset = float(c["direction_slope"]), float(c["direction_offset"])
    ax.plot([0, 360], [0, 360], "k:", lw=1, label="1:1")
    ax.plot([0, 360], [offset, offset + 360 * slope], "r-", lw=1.2,
            label=f"y = {slope:.4f} x {offset:+.2f}°, R² = "
            f"{float(c['direction_r_squared']):.4f}")
    ax.set(xlabel=f"wind direction of the reference, {_name(c, 'reference')} [deg]",
           ylabel=f"wind direction of the unit, {_name(c, 'unit')} [deg]", xlim=(0, 360))
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
            ax.plot(x, deviation, ".", ms=1.5, alpha=0.25, color="grey",
                    label="10-min records")
            s = c.sel(variable=variable)
            line = np.nanpercentile(x, [0.5, 99.5])
            ax.set_xlim(line)
            ax.plot(line, float(s["slope_intercept"]) + float(s["slope"]) * line, "r-",
                    label=f"slope {float(s['slope']):.3g} ± "
                    f"{float(s['slope_standard_error']):.2g} %/unit, "
                    f"{p_value_text(float(s['slope_p_value']))}")
            ax.set(xlabel=environment_label(str(variable)),
                   ylabel="unit minus reference\n[% of the reference]")
            ax.set_title(f"{_pair(c)}, {height:g} m", fontsize=10)
            ax.set_ylim(np.nanpercentile(deviation, [0.5, 99.5]))
            ax.legend(fontsize=7, loc="lower left")
    return fig


def plot_uncertainty_terms(ds, height, unit=None):
    """Seed Fig. 3: the calibration-uncertainty terms of `unit` per bin, one row per
    reference and one column per framework; a bottom row compares the references.

    The terms add in quadrature (u_cal^2 = sum of u_i^2), so the bars stack their
    variances u_i^2 on an axis in (m/s)^2, whose total is u_cal^2; the bottom row gives
    u_cal itself in m/s."""
    keys = [k for k, u in zip(ds["comparison"].values, ds["unit"].values) if u == unit] \
        if unit else list(ds["comparison"].values)
    frameworks = ds["framework"].values
    fig, axes = plt.subplots(len(keys) + 1, len(frameworks), squeeze=False, sharex=True,
                             figsize=(5.5 * len(frameworks), 2.8 * (len(keys) + 1)),
                             layout="constrained")
    shown = ds.sel(height=height).isel(bin=np.flatnonzero(ds["required"].values))
    for row, key in zip(axes, keys):
        for ax, framework in zip(row, frameworks):
            c = shown.sel(comparison=key, framework=framework)
            _stacked_terms(ax, c)
            ax.set_title(f"{_pair(c)}, {framework.upper()}, {height:g} m", fontsize=10)
    for ax, framework in zip(axes[-1], frameworks):
        for key in keys:
            c = shown.sel(comparison=key, framework=framework)
            ax.plot(c["bin"], c["calibration"], "o-", ms=3, label=f"{_pair(c)}")
        ax.set(xlabel="reference wind speed bin [m/s]",
               ylabel="calibration uncertainty\nu$_{cal}$ [m/s]")
        ax.set_title(f"u$_{{cal}}$ with each reference, {framework.upper()}", fontsize=10)
        ax.legend(fontsize=7)
    axes[0][0].legend(fontsize=7, loc="upper left")
    return fig


def plot_turbulence(ds, height):
    """Mean TI per bin, reference and unit as measured and the unit as predicted by the
    spectral path (dashed), one panel per comparison; below, the mean bias error."""
    comparisons = ds["comparison"].values
    fig, axes = plt.subplots(2, len(comparisons), squeeze=False, sharex=True,
                             figsize=(4.6 * len(comparisons), 5.6), layout="constrained")
    shown = ds.sel(height=height).isel(bin=np.flatnonzero(ds["required"].values))
    for column, key in enumerate(comparisons):
        c = shown.sel(comparison=key)
        top, bottom = axes[0][column], axes[1][column]
        top.plot(c["bin"], c["ti_reference_mean"], "o-", ms=3,
                 label=f"{_name(c, 'reference')} (reference)")
        copied = bool(c.get("ti_unit_copies_reference", False))
        if not copied:           # a copy of the reference's TI is not the unit's measurement
            top.plot(c["bin"], c["ti_unit_mean"], "s-", ms=3,
                     label=f"{_name(c, 'unit')} measured")
        if np.isfinite(float(c["ti_predicted_ratio"])):
            top.plot(c["bin"], c["ti_predicted_mean"], "--", color="k",
                     label=f"{_name(c, 'unit')} predicted by uq")
        top.set(ylabel="mean turbulence intensity [%]")
        top.set_title(f"{_pair(c)}, {height:g} m" + (
            f"\n{_name(c, 'unit')}'s TI: the reference's, not measured" if copied else ""),
            fontsize=9)
        top.legend(fontsize=7)
        bottom.axhline(0.0, color="0.6", lw=0.8)
        if not copied:
            bottom.plot(c["bin"], c["ti_mean_bias"], "o-", ms=3, label="measured")
        bottom.plot(c["bin"], c["ti_predicted_mean"] - c["ti_reference_mean"], "--",
                    color="k", label="predicted")
        bottom.set(xlabel="reference wind speed bin [m/s]",
                   ylabel="TI mean bias error\nunit - reference [percentage points]")
        bottom.legend(fontsize=7)
    return fig


def _stacked_terms(ax, c):
    """The terms' variances stacked (they add); the stack's top is u_cal^2."""
    bottom = np.zeros(c["bin"].size)
    for (name, label), colour in zip(TERMS, COLOURS):
        variance = np.nan_to_num(c[name].values ** 2)
        ax.bar(c["bin"], variance, bottom=bottom, width=0.4, color=colour,
               label=f"{label}$^2$")
        bottom = bottom + variance
    top = float(np.max(bottom, initial=0.0))
    if top > 0:
        ax.set_ylim(0, 1.15 * top)              # room above the tallest stack
    ax.set(ylabel="variance u$^2$ [(m/s)$^2$]\n(stack: u$_{cal}^2$)")


def environment_label(variable):
    """An environmental variable in words with its unit (its column's name otherwise)."""
    return ENVIRONMENT_LABELS.get(variable, f"{variable.replace('_', ' ')} "
                                  "(in the unit of its column)")


def p_value_text(p):
    """``p = 0.14``, ``p = 0.017``, ``p < 0.001``: two significant digits, no more."""
    if not np.isfinite(p):
        return "p: none"
    return f"p < {SMALLEST_P:g}" if p < SMALLEST_P else f"p = {p:.2g}"


def _pair(c):
    """``flsa against mast``."""
    return f"{_name(c, 'unit')} against {_name(c, 'reference')}"


def _name(c, role):
    return str(c[role].values)
