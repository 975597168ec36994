"""Figures from finished result Datasets, for any run (no physics; no I/O but the
trials of a single scene, drawn again by :mod:`uq.outputs.samples`).

* a single scene: the variance budget as bars in the output's units
  (:func:`plot_budget`), u against the range gate (:func:`plot_against_gate`), and the
  Monte Carlo histogram with the GUM's Gaussian and both 95 % intervals, the picture of
  the JCGM 101 clause 8 validation (:func:`plot_histogram`);
* a 1-D sweep: u of each model against the swept value (:func:`plot_against_sweep`);
* a 2-D sweep, or a 3-D one with a short third dimension: maps per model
  (:func:`plot_maps`), on one colour scale where every panel's variation shows on it,
  else one scale per panel (:func:`shared_scale`);
* a probe volume (``lidar.probe``) and several range gates: the systematic error of the
  wind speed from the probe against the range gate, a line per probe kind and a panel per
  value of one other swept key (:func:`plot_probe_bias`).

Each takes a Dataset and returns a matplotlib Figure; :mod:`uq.outputs.figures` decides
which a result gets.
"""
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.lines import Line2D  # noqa: E402
from matplotlib.ticker import FuncFormatter, NullFormatter  # noqa: E402
from scipy.stats import norm  # noqa: E402

from uq.constants import COVERAGE_PROBABILITY, FULL_CIRCLE_DEG, NUMERICAL_ZERO  # noqa: E402
from uq.outputs import layout  # noqa: E402
from uq.outputs.labels import (QUANTITIES, SWEEP_QUANTITIES, coordinate_label,  # noqa: E402
                               model_style, quantity_label)
from uq.outputs.planning import models as available_models  # noqa: E402
from uq.outputs.planning import uncertain  # noqa: E402

#: A colour scale is shared by the panels of a map figure when each panel spans at least
#: this share of the common range: viridis then still gives its variation ~80 of its 256
#: colours. Below it, a panel's own pattern would fade into one colour: one scale each.
SHARED_SCALE_FRACTION = 0.3
#: Gates drawn where a figure has room for a few: the lowest, the middle, the highest.
SHOWN_GATES = 3
#: Smallest colour span of a map panel with its own scale, relative to its mean [1]: a
#: variation below it (e.g. Monte Carlo noise of u, ~1e-4 relative at 10^5 trials) is
#: shown as flat instead of stretched over the whole colour bar.
MAP_MIN_RELATIVE_SPAN = 0.01
#: Largest number of values of a numeric sweep axis that get a tick each [1].
MAP_VALUE_TICKS = 12
#: A log axis spanning fewer decades than this labels its minor ticks at 2 and 5 times
#: a power of ten; a longer one only its decades (the labels would collide).
MINOR_LABEL_DECADES = 2.0
#: Most columns of a legend under the panels.
LEGEND_COLUMNS = 4
#: Histogram bins of the Monte Carlo trials.
HISTOGRAM_BINS = 80
#: Height of a histogram panel over its tallest bar or curve [1]: room for the legend
#: above the data.
HISTOGRAM_HEADROOM = 1.45


def plot_uncertainty_against_direction(results, axes_pair=None):
    """u(wind speed) and u(wind direction) against the swept wind direction.

    Parameters
    ----------
    results : dict
        Label -> Dataset with a ``wind_direction`` sweep dimension (e.g. one per INS
        correlation mode). Each is drawn as Monte Carlo (markers) and physical GUM
        (dashed), and, from the first, the Rubio & Gottschall (2022) model: the models'
        one style (:func:`uq.outputs.labels.model_style`); with several results a colour
        per result.

    Returns
    -------
    matplotlib.figure.Figure
    """
    figure, axes = plt.subplots(1, 2, figsize=(10, 4.2), constrained_layout=True) \
        if axes_pair is None else (axes_pair[0].figure, axes_pair)
    several = len(results) > 1
    for k, (label, ds) in enumerate(results.items()):
        x = ds["wind_direction"].values
        for ax, q in ((axes[0], "wind_speed"), (axes[1], "wind_direction")):
            for model in ("gum_u", "mc_u"):
                style = model_style(model)
                if several:
                    style.update(color=RESULT_COLOURS[k % len(RESULT_COLOURS)],
                                 label=f"{style['label']} ({label})")
                ax.plot(x, ds[f"{q}_{model}"], **style)
            ax.set_xlabel("wind direction [deg]")
            ax.set_ylabel(quantity_label(q))
    first = next(iter(results.values()))
    for ax, q in ((axes[0], "wind_speed"), (axes[1], "wind_direction")):
        if f"{q}_paper_u" in first and np.isfinite(first[f"{q}_paper_u"].values).any():
            ax.plot(first["wind_direction"], first[f"{q}_paper_u"], **model_style("paper_u"))
        ax.set_xlim(0, 360)
        ax.set_xticks(range(0, 361, 90))
        ax.grid(alpha=0.3)
    if axes_pair is None:
        legend_below(figure, axes[0])
    else:
        axes[0].legend(fontsize=7)
    return figure


#: Colours of several results in one figure (the models keep their line styles).
RESULT_COLOURS = ("tab:blue", "tab:orange", "tab:green")


def _two_and_five(value, _position):
    """Minor tick labels of a log axis at 2 and 5 times a power of ten (the others
    unlabelled, so that they do not overlap)."""
    mantissa = value / 10 ** np.floor(np.log10(value) + 1e-9)
    return f"{value:g}" if np.isclose(mantissa, 2) or np.isclose(mantissa, 5) else ""


def plot_bench(dataset):
    """Relative error of u(wind speed) against wall time, one panel per scene: every
    repeated run as a point and the median per method and sample size as a diamond,
    joined in order of sample size (measurements, no fitted line: a handful of noisy wall
    times gives no slope worth stating). A dashed guide of slope -1/2 through plain Monte
    Carlo's largest run shows how its error falls with time (error ~ n^-1/2 and time ~ n);
    the reference's own relative error, below which no error can be measured, is the grey
    floor; the dotted line the 1e-3 target."""
    scenes = list(dataset["scene"].values)
    figure, axes = plt.subplots(1, len(scenes), figsize=(5.2 * len(scenes), 4.4),
                                constrained_layout=True, squeeze=False)
    for ax, scene in zip(axes[0], scenes):
        floor = float(dataset["reference_relative_error"].sel(scene=scene)) \
            if "reference_relative_error" in dataset else 0.0
        for method in dataset["method"].values:
            data = dataset.sel({"scene": scene, "method": method})
            times, errors = data["time_s"].values.ravel(), data["relative_error"].values.ravel()
            points, = ax.plot(times, errors, ".", alpha=0.4, ms=4, label=f"{method}: runs")
            colour = points.get_color()
            ax.plot(data["time_s"].median("repeat"), data["relative_error"].median("repeat"),
                    "D-", color=colour, ms=4, lw=0.8, markerfacecolor="none",
                    label=f"{method}: medians")
        guide = _half_slope_guide(dataset.sel(scene=scene))
        if guide is not None:
            ax.plot(*guide, "--", color="0.3", lw=1, label="slope -1/2 (error ~ time^-1/2)")
        ax.set_xscale("log")
        ax.set_yscale("log")
        if floor > 0:
            ax.axhspan(ax.get_ylim()[0], floor, color="0.85", zorder=0,
                       label="below the reference's own error")
        ax.axhline(1e-3, color="k", lw=0.8, ls=":", label="1e-3 target")
        low, high = ax.get_xlim()
        if np.log10(high / low) < MINOR_LABEL_DECADES:      # room for 0.02, 0.05, ...
            ax.xaxis.set_minor_formatter(FuncFormatter(_two_and_five))
        else:
            ax.xaxis.set_minor_formatter(NullFormatter())
        ax.set_title(str(scene), fontsize=9)
        ax.set_xlabel("wall time [s]")
        ax.set_ylabel("relative error of u(wind speed) [1]")
        ax.grid(alpha=0.3, which="both")
    # below the panels: inside, the legend would cover runs' points
    handles, labels = axes[0, 0].get_legend_handles_labels()
    layout.legend_below(figure, handles, labels, fontsize=8, markerscale=2)
    return figure


def _half_slope_guide(dataset, method="mc"):
    """(times, errors) of a line of slope -1/2 on log axes through plain Monte Carlo's
    median at its largest sample size, over the times measured; None without it."""
    if method not in dataset["method"].values:
        return None
    data = dataset.sel(method=method)
    times = np.asarray(data["time_s"].median("repeat").values, float).ravel()
    errors = np.asarray(data["relative_error"].median("repeat").values, float).ravel()
    finite = np.isfinite(times) & np.isfinite(errors) & (times > 0) & (errors > 0)
    if not finite.any():
        return None
    anchor = np.flatnonzero(finite)[np.argmax(times[finite])]
    every = np.asarray(dataset["time_s"].values, float).ravel()
    every = every[np.isfinite(every) & (every > 0)]
    span = np.geomspace(every.min(), every.max(), 20)
    return span, errors[anchor] * np.sqrt(times[anchor] / span)


def sweep_quantities(dataset):
    """The wind outputs of the result that have an uncertainty somewhere (some model's u
    above NUMERICAL_ZERO; e.g. not the vertical wind of a scene with no vertical error),
    in order."""
    return [q for q in SWEEP_QUANTITIES if f"{q}_gum_u" in dataset and uncertain(dataset, q)]


def shown_gates(dataset):
    """Indices of the range gates a figure draws: all up to SHOWN_GATES, else the lowest,
    the middle and the highest."""
    n = dataset.sizes.get("range", 1) if "range" in dataset.dims else 1
    if n <= SHOWN_GATES:
        return list(range(n))
    return sorted({0, n // 2, n - 1})


def middle_gate(dataset):
    """The result at its middle range gate (unchanged without a range dimension), and a
    text naming the gate (empty without gates)."""
    if "range" not in dataset.dims:
        gate = f"range gate {float(dataset['range']):g} m" if "range" in dataset.coords else ""
        return dataset, gate
    index = dataset.sizes["range"] // 2
    at = dataset.isel(range=index)
    return at, f"range gate {float(at['range']):g} m (middle of {dataset.sizes['range']})"


def shared_scale(panels):
    """Do the panels (arrays) share one colour scale (see SHARED_SCALE_FRACTION)? Panels
    that are flat (to NUMERICAL_ZERO) have no variation to show and do not count: if all
    are, one scale shows how they differ."""
    ranges = [float(np.nanmax(p) - np.nanmin(p)) for p in panels]
    common = max(float(np.nanmax(p)) for p in panels) - min(float(np.nanmin(p)) for p in panels)
    varied = [r for r in ranges if r > NUMERICAL_ZERO]
    return not varied or min(varied) >= SHARED_SCALE_FRACTION * common


def plot_budget(dataset):
    """Single scene: each input's contribution |c_i| u_i to the GUM uncertainty, in the
    output's units, as horizontal bars (largest on top); one panel per output, one bar
    colour per shown range gate; the dashed line is the combined GUM u (the bars add in
    quadrature, not linearly)."""
    quantities = [q for q in sweep_quantities(dataset) if f"{q}_budget" in dataset]
    inputs = [str(name) for name in dataset["input"].values]
    figure, axes = plt.subplots(1, len(quantities), figsize=(4.6 * len(quantities),
                                                             1.2 + 0.42 * len(inputs)),
                                constrained_layout=True, squeeze=False)
    gates = shown_gates(dataset)
    height = 0.8 / len(gates)
    for ax, quantity in zip(axes[0], quantities):
        budget = np.sqrt(np.atleast_2d(dataset[f"{quantity}_budget"].values.T).T)
        budget = budget.reshape(len(inputs), -1)                # inputs x gates
        order = np.argsort(budget.max(axis=1))
        gum_u = np.atleast_1d(dataset[f"{quantity}_gum_u"].values)
        for k, gate in enumerate(gates):
            colour = f"C{k}"
            label = _gate_text(dataset, gate)
            ax.barh(np.arange(len(inputs)) + (k - (len(gates) - 1) / 2) * height,
                    budget[order, gate], height=height, color=colour, label=label)
            ax.axvline(gum_u[gate], color=colour, ls="--", lw=1)
        ax.set_yticks(np.arange(len(inputs)), [inputs[i] for i in order], fontsize=8)
        ax.set_xlabel(f"contribution |c$_i$| u$_i$ [{QUANTITIES[quantity][2]}]")
        ax.set_title(f"{QUANTITIES[quantity][0]} (dashed: GUM u)", fontsize=9)
        ax.grid(alpha=0.3, axis="x")
    if len(gates) > 1:
        axes[0, 0].legend(fontsize=7, loc="lower right")
    return figure


def _gate_name(dataset, gate):
    """``range gate 100 m`` of gate index `gate` ('' without a range coordinate)."""
    if "range" not in dataset.coords:
        return ""
    ranges = np.atleast_1d(dataset["range"].values)
    return f"range gate {float(ranges[gate]):g} m"


def _gate_text(dataset, gate):
    if "range" not in dataset.dims:
        return "GUM"
    return f"range gate {float(dataset['range'].values[gate]):g} m"


def plot_against_gate(dataset, panels=None):
    """Single scene with several range gates: u of each model (Monte Carlo with +-2
    standard errors of u) against the range gate; one panel per output (`panels`:
    (quantity, {dim: index}, title) each, default :func:`output_panels`)."""
    panels = output_panels(dataset) if panels is None else panels
    figure, axes = plt.subplots(1, len(panels), figsize=(4.2 * len(panels), 4),
                                sharey=True, constrained_layout=True, squeeze=False)
    gates = dataset["range"].values
    for ax, (quantity, where, title) in zip(axes[0], panels):
        at = dataset.isel(where)
        for model in available_models(at, quantity):
            values = at[f"{quantity}_{model}"].values
            ax.plot(values, gates, **model_style(model))
            if model == "mc_u":
                ax.errorbar(values, gates, xerr=2 * u_standard_error(at, quantity),
                            fmt="none", ecolor="k", elinewidth=0.8, zorder=4,
                            label=ERROR_BAR_LABEL)
        ax.set_xlabel(quantity_label(quantity))
        if title:
            ax.set_title(title, fontsize=9)
        ax.grid(alpha=0.3)
    axes[0, 0].set_ylabel(coordinate_label(dataset, "range"))
    legend_below(figure, axes[0, 0])
    return figure


def output_panels(dataset):
    """(quantity, {}, None) per output a sweep figure shows (:func:`sweep_quantities`)."""
    return [(quantity, {}, None) for quantity in sweep_quantities(dataset)]


def beam_panels(dataset, quantity="radial_velocity"):
    """(quantity, {"beam": k}, "radial velocity, beam at 90 deg") per beam of an output
    with a beam dimension; [] when the result has no uncertainty of it."""
    if f"{quantity}_gum_u" not in dataset or "beam" not in dataset[f"{quantity}_gum_u"].dims \
            or not uncertain(dataset, quantity):
        return []
    azimuths = dataset["beam_azimuth"].values if "beam_azimuth" in dataset.coords else \
        dataset["beam"].values.astype(float)
    return [(quantity, {"beam": k}, f"{QUANTITIES[quantity][0]}, "
             + ("vertical beam" if np.isnan(azimuth) else f"beam at {azimuth:g} deg"))
            for k, azimuth in enumerate(azimuths)]


def plot_beams(dataset, quantity="radial_velocity"):
    """An output with a value per beam (radial velocity): a panel per beam, u against
    the range gate (a single scene) or the swept key (a 1-D sweep)."""
    panels = beam_panels(dataset, quantity)
    if dataset["mc_n_samples"].ndim == 0:
        return plot_against_gate(dataset, panels)
    return plot_against_sweep(dataset, panels=panels)


def legend_below(figure, ax, fontsize=7):
    """The legend of `ax`'s lines under the panels, off the data, in as many columns as
    fit the canvas (:func:`uq.outputs.layout.legend_below`)."""
    handles, labels = ax.get_legend_handles_labels()
    layout.legend_below(figure, handles, labels, fontsize=fontsize, longest=LEGEND_COLUMNS)


#: Legend entry of the error bars on the Monte Carlo u: what they are, in the PNG.
ERROR_BAR_LABEL = "Monte Carlo u ± 2 standard errors"


def u_standard_error(dataset, quantity):
    """Standard error of the Monte Carlo u: the run's own, from independent batches
    (``q_mc_u_standard_error``), or, where it has fewer than two batches (NaN), that of
    the standard deviation of N normal draws, u / sqrt(2 (N - 1))."""
    return u_standard_error_array(dataset, quantity).values


def u_standard_error_array(dataset, quantity):
    """:func:`u_standard_error` as a DataArray (the result's dimensions)."""
    u = dataset[f"{quantity}_mc_u"]
    normal = u / np.sqrt(2 * (dataset["mc_n_samples"] - 1))
    stored = dataset.get(f"{quantity}_mc_u_standard_error")
    return normal if stored is None else stored.fillna(normal)


def plot_histogram(dataset, trials):
    """Single scene, the picture of JCGM 101 clause 8: per output, the histogram of the
    Monte Carlo trials (density), the GUM's Gaussian N(y, u^2), the Monte Carlo 95 %
    interval (solid) and the GUM's y +- k u (dashed), and the validation's verdict with
    the endpoint differences against their tolerance delta.

    Parameters
    ----------
    trials : dict
        output -> (n, n_gates) trials (:func:`uq.outputs.samples.scene_trials`).
    """
    quantities = [q for q in sweep_quantities(dataset) if q in trials]
    figure, axes = plt.subplots(1, len(quantities), figsize=(4.6 * len(quantities), 4.0),
                                constrained_layout=True, squeeze=False)
    for ax, quantity in zip(axes[0], quantities):
        gate = histogram_gate(dataset, quantity)
        at = dataset.isel(range=gate) if "range" in dataset.dims else dataset
        values = trials[quantity].reshape(len(trials[quantity]), -1)[:, gate]
        _histogram_panel(ax, at, quantity, values, _gate_name(dataset, gate))
    n = len(next(iter(trials.values())))
    gates = "; each panel at the range gate where the GUM fails, else the middle one" \
        if "range" in dataset.dims and dataset.sizes["range"] > 1 else ""
    layout.suptitle(figure, f"Monte Carlo ({n:,} trials) against the GUM{gates}",
                    fontsize=10)
    return figure


def histogram_gate(dataset, quantity):
    """Index of the range gate a histogram shows: the first where clause 8 refuses the
    GUM conclusively, else the first where it refuses it, else the middle gate (0
    without gates)."""
    if "range" not in dataset.dims:
        return 0
    valid = dataset.get(f"{quantity}_gum_valid")
    if valid is not None:
        failed = ~valid.values.astype(bool)
        conclusive = dataset.get(f"{quantity}_gum_validation_conclusive")
        sure = failed & (conclusive.values.astype(bool) if conclusive is not None else True)
        for candidates in (sure, failed):
            if candidates.any():
                return int(np.flatnonzero(candidates)[0])
    return dataset.sizes["range"] // 2


def _histogram_panel(ax, at, quantity, values, where=""):
    value, u = float(at[f"{quantity}_gum_value"]), float(at[f"{quantity}_gum_u"])
    low, high = float(at[f"{quantity}_mc_low"]), float(at[f"{quantity}_mc_high"])
    if quantity == "wind_direction":                 # on the circle: about the GUM value
        values, low, high = (_near(v, value) for v in (values, low, high))
    values = values[np.isfinite(values)]
    ax.hist(values, bins=HISTOGRAM_BINS, density=True, color="0.75",
            label="Monte Carlo trials")
    k = norm.ppf((1 + COVERAGE_PROBABILITY) / 2)
    if u > 0:
        grid = np.linspace(min(values.min(), value - 4 * u), max(values.max(), value + 4 * u),
                           400)
        ax.plot(grid, norm.pdf(grid, value, u), color="tab:orange",
                label="GUM: N(y, u$^2$)")
    for end in (low, high):
        ax.axvline(end, color="k", lw=1.5, label="Monte Carlo 95 % interval"
                   if end == low else None)
    for end in (value - k * u, value + k * u):
        ax.axvline(end, color="tab:orange", ls="--", lw=1.5, label="GUM 95 % interval"
                   if end < value else None)
    ax.set_xlabel(f"{QUANTITIES[quantity][0]} [{QUANTITIES[quantity][2]}]")
    ax.set_ylabel("probability density")
    ax.set_title(_validation_text(at, quantity, value - k * u - low, value + k * u - high)
                 + (f"\n{where}" if where else ""), fontsize=8)
    ax.set_ylim(top=ax.get_ylim()[1] * HISTOGRAM_HEADROOM)      # the legend above the bars
    ax.legend(fontsize=6, loc="upper left", ncols=2)


def _near(values, centre):
    """Angles [deg] moved by whole turns to within half a turn of `centre`."""
    half = FULL_CIRCLE_DEG / 2
    return (np.asarray(values) - centre + half) % FULL_CIRCLE_DEG - half + centre


def _validation_text(at, quantity, d_low, d_high):
    """The clause 8 verdict and its numbers, for a panel's title."""
    name = f"{quantity}_gum_valid"
    if name not in at or f"{quantity}_mc_u" not in at:       # no Monte Carlo to validate
        return QUANTITIES[quantity][0]
    verdict = "GUM validated" if bool(at[name]) else "GUM not validated"
    delta = at.get(f"{quantity}_mc_numerical_tolerance")
    tolerance = f", delta {float(delta):.2g}" if delta is not None else ""
    return (f"{QUANTITIES[quantity][0]}: {verdict} (JCGM 101 cl. 8)\n"
            f"endpoint differences {d_low:+.2g}, {d_high:+.2g}{tolerance}")


def plot_against_sweep(dataset, dim=None, lines=None, panels=None):
    """u of each model against a swept value, one panel per output (`panels`, see
    :func:`plot_against_gate`), Monte Carlo with +-2 standard errors of u.

    A colour per value of `lines` (a second, short sweep dimension, e.g. ``correction``:
    one line per value; then at the middle range gate), else per shown range gate; the
    model by line style and marker."""
    dim = dim or dataset["mc_n_samples"].dims[0]
    panels = output_panels(dataset) if panels is None else panels
    figure, axes = plt.subplots(1, len(panels), figsize=(4.5 * len(panels), 3.6),
                                constrained_layout=True, squeeze=False)
    curves = _curves(dataset, lines)
    for ax, (quantity, where, title) in zip(axes[0], panels):
        for k, (at, name) in enumerate(curves):
            at = at.isel(where)
            for model in available_models(dataset, quantity):
                style = model_style(model)
                style.setdefault("marker", ".")          # a value alone still shows
                if len(curves) > 1:
                    style.update(color=f"C{k}", label=f"{style['label']}, {name}")
                ax.plot(_positions(dataset[dim]), at[f"{quantity}_{model}"].values, **style)
                if model == "mc_u":                     # +-2 standard errors of u
                    ax.errorbar(_positions(dataset[dim]), at[f"{quantity}_mc_u"].values,
                                yerr=2 * u_standard_error(at, quantity), fmt="none",
                                ecolor=style["color"], elinewidth=0.7, zorder=4,
                                label=ERROR_BAR_LABEL if k == 0 else None)
        _name_ticks(ax.xaxis, dataset[dim])
        ax.set_xlabel(coordinate_label(dataset, dim))
        ax.set_ylabel(quantity_label(quantity))
        if title:
            ax.set_title(title, fontsize=9)
        ax.grid(alpha=0.3)
    if lines is not None and "range" in dataset.dims:
        layout.suptitle(figure, middle_gate(dataset)[1], fontsize=9)
    if len(curves) > 1:          # colours for the lines, styles for the models: a short key
        _key_below(figure, [name for _, name in curves],
                   available_models(dataset, panels[0][0]))
    else:
        legend_below(figure, axes[0, 0])
    return figure


def _key_below(figure, names, models):
    """A legend under the panels: a colour per line (C0, C1, ...), then each model's
    style in black, then the error bars."""
    handles = [Line2D([], [], color=f"C{k}", label=name) for k, name in enumerate(names)]
    for model in models:
        style = {**model_style(model), "color": "k"}
        style.setdefault("marker", ".")
        handles.append(Line2D([], [], **style))
    if "mc_u" in models:
        handles.append(Line2D([], [], color="k", marker="|", linestyle="none", markersize=8,
                              label=ERROR_BAR_LABEL))
    layout.legend_below(figure, handles, [h.get_label() for h in handles], fontsize=7,
                        longest=LEGEND_COLUMNS)


def _curves(dataset, lines):
    """(data, name) per line of :func:`plot_against_sweep`: per value of `lines` (at
    the middle gate), else per shown gate."""
    if lines is not None:
        at = middle_gate(dataset)[0]
        return [(at.sel({lines: value}), f"{coordinate_label(dataset, lines).split(' [')[0]}"
                 f" {_format(value)}") for value in dataset[lines].values]
    if "range" not in dataset.dims:
        return [(dataset, "")]
    return [(dataset.isel(range=gate), _gate_text(dataset, gate))
            for gate in shown_gates(dataset)]


def plot_maps(dataset, quantity, x, y, facet=None):
    """Maps of u(`quantity`) over the sweep dimensions `x` and `y`, one column per model
    and one row per value of `facet` (a third sweep dimension); a shared colour scale or
    one per panel (:func:`shared_scale`). With range gates, the middle gate.

    Monte Carlo noise draws nothing: a Monte Carlo panel whose values all lie within +-2
    of their standard errors of one value is drawn flat, at its mean, and says so
    (common random numbers make the noise of neighbouring scenes alike, so it would
    look like structure); no colour scale spans less than the panels' +-2 standard
    errors (nor MAP_MIN_RELATIVE_SPAN of their mean)."""
    at, gate_text = middle_gate(dataset)
    models = available_models(at, quantity)
    rows = [None] if facet is None else list(at[facet].values)
    noise = _map_noise(at, quantity)
    panels = [[at[f"{quantity}_{m}"].sel({facet: r}) if facet else at[f"{quantity}_{m}"]
               for m in models] for r in rows]
    bands = [[_panel_noise(noise, m, facet, r) for m in models] for r in rows]
    smoothed = [[_without_noise(panel, band, (x, y), at) for panel, band in zip(row, band_row)]
                for row, band_row in zip(panels, bands)]
    drawn = [[panel for panel, _ in row] for row in smoothed]
    flats = [[note for _, note in row] for row in smoothed]
    flat = [p.values for row in drawn for p in row]
    band = max([b for row in bands for b in row], default=0.0)
    shared = shared_scale(flat)
    figure, axes = plt.subplots(len(rows), len(models),
                                figsize=(4.3 * len(models) + 0.8, 3.3 * len(rows) + 0.5),
                                constrained_layout=True, squeeze=False, sharex=True,
                                sharey=True)
    limits = _panel_limits(np.concatenate([v.ravel() for v in flat]), band)
    for i, (row, value) in enumerate(zip(drawn, rows)):
        for j, (panel, model) in enumerate(zip(row, models)):
            ax = axes[i, j]
            mesh = ax.pcolormesh(_positions(at[x]), _positions(at[y]),
                                 panel.transpose(y, x).values, shading="nearest",
                                 cmap="viridis", **dict(zip(("vmin", "vmax"), limits if shared
                                                            else _panel_limits(panel.values,
                                                                               bands[i][j]))))
            _name_ticks(ax.xaxis, at[x])
            _name_ticks(ax.yaxis, at[y])
            if flats[i][j]:
                ax.text(0.5, 0.02, flats[i][j], transform=ax.transAxes, ha="center",
                        va="bottom", fontsize=7, bbox={"facecolor": "white", "alpha": 0.8,
                                                       "edgecolor": "none"})
            if not shared:
                bar = figure.colorbar(mesh, ax=ax, label=quantity_label(quantity))
                bar.formatter.set_useOffset(False)           # the values, not an offset
            title = model_style(model)["label"]
            if facet is not None:
                title += f"\n{coordinate_label(at, facet)} = {_format(value)}"
            ax.set_title(title, fontsize=9)
            if i == len(rows) - 1:
                ax.set_xlabel(coordinate_label(at, x))
            if j == 0:
                ax.set_ylabel(coordinate_label(at, y))
    if shared:
        bar = figure.colorbar(mesh, ax=axes, label=quantity_label(quantity))
        bar.formatter.set_useOffset(False)
    scale = "one colour scale" if shared else "one colour scale per panel"
    layout.suptitle(figure, f"u({QUANTITIES[quantity][0]}), {scale}"
                    + (f", {gate_text}" if gate_text else ""), fontsize=10)
    return figure


def _map_noise(at, quantity):
    """Twice the standard error of the Monte Carlo u of every scene (a DataArray), or
    None without Monte Carlo."""
    if f"{quantity}_mc_u" not in at:
        return None
    return 2 * u_standard_error_array(at, quantity)


def _panel_noise(noise, model, facet, value):
    """The largest +-2 standard errors of a panel [units of u]: 0 for a model without
    sampling noise (GUM, the paper's)."""
    if noise is None or not model.startswith("mc_"):
        return 0.0
    panel = noise.sel({facet: value}) if facet else noise
    return float(panel.max()) if np.isfinite(panel).any() else 0.0


def _without_noise(panel, band, dims, dataset):
    """(panel to draw, note): a Monte Carlo panel averaged along each of its `dims` whose
    variation (the largest spread along it) lies within 2 `band`, i.e. within +-2 standard
    errors of one value, with a note saying so; unchanged, '' otherwise."""
    if not band or not np.isfinite(panel.values).any():
        return panel, ""
    mean = float(np.nanmean(np.abs(panel.values)))
    notes = []
    for dim in dims:
        spread = float((panel.max(dim) - panel.min(dim)).max())
        if NUMERICAL_ZERO * mean < spread <= 2 * band:
            panel = panel * 0 + panel.mean(dim)
            notes.append(f"{coordinate_label(dataset, dim).split(' [')[0]} "
                         f"({100 * spread / mean:.2g} %)")
    if not notes:
        return panel, ""
    return panel, (f"averaged over {' and '.join(notes)}: the spread is within\n"
                   f"±2 Monte Carlo standard errors (±{100 * band / mean:.2g} %)")


def _positions(coordinate):
    """Positions of a coordinate's values on an axis: the numbers, or 0, 1, ... for texts
    and flags (named by :func:`_name_ticks`)."""
    values = coordinate.values
    return values if values.dtype.kind in "iuf" else np.arange(values.size)


def _panel_limits(values, band=0.0):
    """(vmin, vmax) of a colour scale: the values' range, widened about its middle to at
    least MAP_MIN_RELATIVE_SPAN of their mean magnitude and to +-`band` (the Monte Carlo
    noise, twice the standard error), so that noise takes few colours."""
    low, high = float(np.nanmin(values)), float(np.nanmax(values))
    span = max(MAP_MIN_RELATIVE_SPAN * float(np.nanmean(np.abs(values))), 2 * band)
    if high - low >= span:
        return low, high
    middle = (low + high) / 2
    return middle - span / 2, middle + span / 2


def _name_ticks(axis, coordinate):
    """Ticks named by the values of a text or flag coordinate; a tick at each value of a
    numeric one of few values."""
    values = coordinate.values
    if values.dtype.kind in "iuf" and values.size <= MAP_VALUE_TICKS:
        axis.set_ticks(values)
    elif values.dtype.kind not in "iuf":
        axis.set_ticks(np.arange(values.size), [str(v).lower() if values.dtype == bool
                                               else str(v) for v in values])


#: Colours of the probe kinds (:func:`plot_probe_bias`).
PROBE_COLOURS = {"point": "0.5", "pulsed": "tab:blue", "cw": "tab:red"}
#: The coordinate of a swept probe kind.
PROBE_KIND_DIM = "lidar_probe_kind"


def probe_panels(dataset):
    """The sweep dimension whose values get a panel each in :func:`plot_probe_bias`
    (None: one panel), or False when the result has no such figure (no probe bias, fewer
    than two gates, or more than one swept key beside the probe kind)."""
    if "wind_speed_probe_bias" not in dataset or dataset.sizes.get("range", 1) < 2 \
            or "range" not in dataset.dims:
        return False
    others = [d for d in dataset["mc_n_samples"].dims if d != PROBE_KIND_DIM]
    if len(others) > 1:
        return False
    return others[0] if others else None


def plot_probe_bias(dataset):
    """Systematic error of the horizontal wind speed from the probe volume against the
    range gate, in m s-1 (top) and relative to the true speed (bottom): a line per probe
    kind (when ``lidar.probe.kind`` is swept), a column per value of the other swept key."""
    column_dim = probe_panels(dataset)
    columns = [None] if column_dim is None else list(dataset[column_dim].values)
    figure, axes = plt.subplots(2, len(columns), figsize=(4.2 * len(columns) + 0.6, 6.2),
                                constrained_layout=True, squeeze=False, sharex=True,
                                sharey="row")
    gates = dataset["range"].values
    if PROBE_KIND_DIM in dataset.dims:
        kinds = list(dataset[PROBE_KIND_DIM].values)
    else:                       # one kind: a selected value of the sweep, or the scenario's
        kinds = [str(dataset[PROBE_KIND_DIM].values) if PROBE_KIND_DIM in dataset.coords
                 else dataset.attrs.get("probe", "probe").split(":")[0]]
    for j, value in enumerate(columns):
        at = dataset if column_dim is None else dataset.sel({column_dim: value})
        for kind in kinds:
            one = at.sel({PROBE_KIND_DIM: kind}) if PROBE_KIND_DIM in at.dims else at
            bias = one["wind_speed_probe_bias"].values
            relative = 100 * bias / one["wind_speed_true"].values
            style = {"color": PROBE_COLOURS.get(kind, "k"), "marker": ".", "label": kind}
            axes[0, j].plot(gates, bias, **style)
            axes[1, j].plot(gates, relative, **style)
        if column_dim is not None:
            axes[0, j].set_title(f"{coordinate_label(dataset, column_dim)} = "
                                 f"{_format(value)}", fontsize=9)
        axes[1, j].set_xlabel(coordinate_label(dataset, "range"))
        for ax in axes[:, j]:
            ax.axhline(0.0, color="k", linewidth=0.6)
            ax.grid(alpha=0.3)
    axes[0, 0].set_ylabel("probe bias of " + QUANTITIES["wind_speed"][0] + " [m s$^{-1}$]")
    axes[1, 0].set_ylabel("probe bias / true " + QUANTITIES["wind_speed"][0] + " [%]")
    axes[0, 0].legend(fontsize=8, title="lidar.probe.kind", title_fontsize=8)
    layout.suptitle(figure, "Systematic error of the wind speed from the probe volume "
                    "(range weighting along the beams)", fontsize=10)
    return figure


def _format(value):
    return f"{value:g}" if isinstance(value, (int, float, np.number)) else str(value)
