"""The figures of a result: Rubio & Gottschall (2022), Figs. 2-7, and a figure for
every other run.

Every figure shows the paper's analytic model, the first-order GUM of the physical model
and Monte Carlo side by side (the models a result file has), Monte Carlo as markers on
top of the lines so that it stays visible where it equals the GUM. Plot functions take a
finished Dataset and return a matplotlib Figure; :func:`figure_plan` picks the figures a
result's sweep dimensions allow, :func:`make_figures` saves them:

* the paper's sweeps: its figures (:func:`paper_plan`);
* a single scene: the variance budget, u against the range gate (with gates) and the
  Monte Carlo histogram against the GUM (JCGM 101 clause 8) (:mod:`uq.outputs.plots`);
* any 1-D sweep: u against the swept value; any 2-D sweep: maps per model and output;
  3-D: the same maps, one row per value of a short third dimension (at most
  :data:`MAX_FACETS` values);
* more dimensions: none until ``select={dim: value}`` (``uq plot --select dim=value``)
  fixes all but two or three of them; :func:`no_figure_reason` says which.

No physics here: averages over wind direction are plain means over a uniform sweep of
the full circle.

References
----------
.. [1] Rubio, H. and Gottschall, J. (2022). Development of an uncertainty model for
   ship-based lidar measurements. J. Phys.: Conf. Ser. 2362 012034.
"""
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.lines import Line2D  # noqa: E402

from uq.errors import ScenarioError  # noqa: E402
from uq.files import check_target, output_folder, save_figure  # noqa: E402
from uq.outputs import layout, motionfigures, plots, recordfigures  # noqa: E402
from uq.outputs.labels import MODELS as LABEL_MODELS  # noqa: E402
from uq.outputs.labels import coordinate_label, model_style  # noqa: E402
from uq.outputs.planning import VELOCITY_RATIOS, velocity_ratio_line  # noqa: E402
from uq.outputs.planning import models as available_models  # noqa: E402
from uq.outputs.plots import plot_uncertainty_against_direction  # noqa: E402
from uq.outputs.samples import can_redraw, scene_trials  # noqa: E402

#: Uncertainty variables: suffix -> (label, ...): the one mapping of
#: :data:`uq.outputs.labels.MODELS` (labels, line styles, markers and colours).
MODELS = LABEL_MODELS
UNITS = {"wind_speed": "m s$^{-1}$", "wind_direction": "deg", "radial_velocity": "m s$^{-1}$"}
SYMBOLS = {"wind_speed": "$V_h$", "wind_direction": r"$\Theta$", "radial_velocity": "$v_r$"}
BEAM_NAMES = {0.0: "N", 90.0: "E", 180.0: "S", 270.0: "W"}


def direction_mean(dataset, name):
    """Mean over the wind-direction sweep (a uniform sweep of the circle)."""
    return dataset[name].mean("wind_direction")


def _label(quantity):
    return f"u({SYMBOLS[quantity]}) [{UNITS[quantity]}]"


def fig2_speed_maps(dataset):
    """Fig. 2 [1]: u(Vh) over wind direction x misalignment, one row per cog, one column
    per model; the red line (right axis, on the colour bar's scale) is the direction
    average."""
    models = available_models(dataset, "wind_speed")
    cogs = dataset["ship_cog"].values
    figure, axes = plt.subplots(len(cogs), len(models), figsize=(4.4 * len(models), 2.8 * len(cogs)),
                                sharex=True, sharey=True, constrained_layout=True, squeeze=False)
    values = [dataset[f"wind_speed_{m}"] for m in models]
    low = min(float(v.min()) for v in values)
    high = max(float(v.max()) for v in values)
    x = dataset["lidar_misalignment"].values
    for row, cog in enumerate(cogs):
        for col, model in enumerate(models):
            ax = axes[row, col]
            data = dataset[f"wind_speed_{model}"].sel(ship_cog=cog)
            mesh = ax.pcolormesh(x, dataset["wind_direction"].values,
                                 data.transpose("wind_direction", "lidar_misalignment").values,
                                 vmin=low, vmax=high, cmap="viridis", shading="nearest")
            twin = ax.twinx()
            twin.plot(x, direction_mean(dataset, f"wind_speed_{model}").sel(ship_cog=cog),
                      color="red", lw=1.5)
            twin.set_ylim(low, high)
            twin.tick_params(labelsize=7, colors="red")
            if col == len(models) - 1:
                twin.set_ylabel("direction mean of\nu($V_h$) [m s$^{-1}$]", color="red",
                                fontsize=8)
            if row == 0:
                ax.set_title(MODELS[model][0], fontsize=9)
            if col == 0:
                ax.set_ylabel(f"cog = {cog:g} deg\nwind direction [deg]")
            if row == len(cogs) - 1:
                ax.set_xlabel("misalignment [deg]")
    figure.colorbar(mesh, ax=axes, label=_label("wind_speed") + "  (red: direction mean)")
    return figure


def fig3_direction_against_misalignment(dataset):
    """Fig. 3 [1]: direction-averaged u(Theta) against misalignment, a line per cog
    (blue to green) over the mean over cog (wide, pale red); one panel per model. Each
    cog line has its own marker, placed at other points than the others', so that lines
    that coincide all stay visible; the panel gives their largest spread."""
    models = available_models(dataset, "wind_direction")
    figure, axes = plt.subplots(1, len(models), figsize=(4.2 * len(models), 3.6), sharey=True,
                                constrained_layout=True, squeeze=False)
    n_cogs = dataset.sizes["ship_cog"]
    colours = plt.cm.winter(np.linspace(0, 1, n_cogs))
    markers = ("o", "s", "^", "v", "D", "P")
    x = dataset["lidar_misalignment"].values
    for ax, model in zip(axes[0], models):
        mean = direction_mean(dataset, f"wind_direction_{model}")
        ax.plot(x, mean.mean("ship_cog"), color="red", lw=6, alpha=0.3, zorder=1,
                label="mean over cog")
        for k, (colour, cog) in enumerate(zip(colours, dataset["ship_cog"].values)):
            ax.plot(x, mean.sel(ship_cog=cog), color=colour, lw=1, marker=markers[k % 6],
                    ms=4, markevery=(2 * k % len(x), 2 * n_cogs), zorder=2,
                    label=f"cog {cog:g} deg")
        spread = float((mean.max("ship_cog") - mean.min("ship_cog")).max() / mean.mean())
        ax.set_title(f"{MODELS[model][0]}\nthe {n_cogs} cog lines within {100 * spread:.2g} %",
                     fontsize=9)
        ax.set_xlabel("misalignment [deg]")
        ax.grid(alpha=0.3)
    axes[0, 0].set_ylabel(_label("wind_direction") + ", direction mean")
    axes[0, 0].legend(fontsize=7)
    return figure


def fig4a_speed_against_velocities(dataset):
    """Fig. 4a [1]: direction-averaged u(Vh) over Vh x sog, with the VR = 0.5, 1, 2 lines;
    one colour scale per panel where a common one would hide a panel's variation
    (:func:`uq.outputs.plots.shared_scale`): the models differ by more than the ~6 %
    the velocity ratio makes."""
    models = available_models(dataset, "wind_speed")
    means = {m: direction_mean(dataset, f"wind_speed_{m}").transpose("ship_sog", "wind_speed")
             for m in models}
    shared = plots.shared_scale([v.values for v in means.values()])
    figure, axes = plt.subplots(1, len(models), figsize=(4.6 * len(models), 3.8), sharey=True,
                                constrained_layout=True, squeeze=False)
    limits = _limits(means.values()) if shared else {}
    speed, sog = dataset["wind_speed"].values, dataset["ship_sog"].values
    for ax, model in zip(axes[0], models):
        mesh = ax.pcolormesh(speed, sog, means[model].values, cmap="viridis",
                             shading="nearest", **limits)
        for ratio, style in zip(VELOCITY_RATIOS, ("--", "-.", ":")):
            ax.plot(speed, ratio * speed, style, color="white", lw=1.2, label=f"VR = {ratio:g}")
        ax.set_ylim(sog.min(), sog.max())
        ax.set_title(MODELS[model][0], fontsize=9)
        ax.set_xlabel("horizontal wind speed $V_h$ [m s$^{-1}$]")
        if not shared:
            figure.colorbar(mesh, ax=ax, label=_label("wind_speed") + ", direction mean")
    axes[0, 0].set_ylabel("ship speed over ground [m s$^{-1}$]")
    axes[0, 0].legend(fontsize=7, loc="upper left")
    if shared:
        figure.colorbar(mesh, ax=axes, label=_label("wind_speed") + ", direction mean")
    return figure


def _limits(arrays):
    """vmin and vmax over several DataArrays (one colour scale)."""
    arrays = list(arrays)
    return {"vmin": min(float(a.min()) for a in arrays),
            "vmax": max(float(a.max()) for a in arrays)}


def fig4b_relative_against_speed(dataset):
    """Fig. 4b [1]: relative u(Vh) / Vh [%] against Vh for VR = 0.5, 1, 2 (left), and,
    where the 1/Vh fall hides it, the ratio's own effect: u at each VR over u at the
    smallest VR, minus one [%] (right). A colour per ratio, the models by line style,
    Monte Carlo as markers on top."""
    figure, (ax, effect) = plt.subplots(1, 2, figsize=(11, 4), constrained_layout=True)
    colours = ("tab:blue", "tab:orange", "tab:green")
    for model in available_models(dataset, "wind_speed"):
        lines = {r: velocity_ratio_line(dataset, f"wind_speed_{model}", r)
                 for r in VELOCITY_RATIOS}
        base_at, base = lines[VELOCITY_RATIOS[0]]
        for ratio, colour in zip(VELOCITY_RATIOS, colours):
            at, line = lines[ratio]
            style = model_style(model)
            style.update(color=colour, label=f"VR = {ratio:g}, {MODELS[model][0]}")
            if np.size(at) < 2 and not style.get("marker"):
                style["marker"] = "_"          # one speed on the line: a tick shows it
            ax.plot(at, 100 * line / at, **style)
            if ratio != VELOCITY_RATIOS[0]:
                common = np.isin(base_at, at)
                effect.plot(base_at[common], 100 * (line / base[common] - 1),
                            **{**style, "label": None})
    ax.set_xlabel("horizontal wind speed $V_h$ [m s$^{-1}$]")
    ax.set_ylabel("u($V_h$) / $V_h$ [%], direction mean")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=6)
    effect.axhline(0, color="k", lw=0.8)
    effect.set_xlabel("horizontal wind speed $V_h$ [m s$^{-1}$]")
    effect.set_ylabel(f"u($V_h$) at VR / u($V_h$) at VR = {VELOCITY_RATIOS[0]:g} - 1 [%]")
    effect.set_title("the velocity ratio's effect (colours as left)", fontsize=9)
    effect.grid(alpha=0.3)
    return figure


def fig5_radial_against_direction(dataset):
    """Fig. 5 [1]: per-beam radial-velocity u against wind direction; top: pitch lines
    (roll 0), bottom: roll lines (pitch 0); colour = tilt, line style = model, Monte Carlo
    as markers on top."""
    beams = dataset["beam"].values
    figure, axes = plt.subplots(2, len(beams), figsize=(3.3 * len(beams) + 1.5, 6.2), sharex=True,
                                sharey=True, constrained_layout=True, squeeze=False)
    models = available_models(dataset, "radial_velocity")
    for row, (tilt, other) in enumerate((("ship_pitch", "ship_roll"), ("ship_roll", "ship_pitch"))):
        level = dataset.sel({other: 0.0})
        values = level[tilt].values
        colours = plt.cm.coolwarm(np.linspace(0, 1, len(values)))
        for col, beam in enumerate(beams):
            ax = axes[row, col]
            for colour, angle in zip(colours, values):
                for model in models:
                    style = model_style(model)
                    style.update(color=colour, label=None, markersize=3, markevery=2)
                    ax.plot(level["wind_direction"], level[f"radial_velocity_{model}"].sel(
                        {tilt: angle, "beam": beam}), **style)
            ax.set_title(f"beam {beam_name(dataset, beam)}, {tilt.split('_')[1]} "
                         f"({other.split('_')[1]} 0)", fontsize=9)
            ax.grid(alpha=0.3)
            if row == 1:
                ax.set_xlabel("wind direction [deg]")
        axes[row, 0].set_ylabel(_label("radial_velocity"))
        handles = [Line2D([], [], color=c, label=f"{a:g} deg") for c, a in zip(colours, values)]
        axes[row, -1].legend(handles=handles, title=tilt.split("_")[1], fontsize=7,
                             title_fontsize=8, loc="upper left", bbox_to_anchor=(1.02, 1))
    styles = [Line2D([], [], **{**model_style(m), "color": "k"}) for m in models]
    layout.legend_below(figure, styles, [h.get_label() for h in styles], fontsize=7)
    return figure


def beam_name(dataset, beam):
    """N, E, S, W for the paper's beams (by azimuth), else the azimuth or "vertical"."""
    if "beam_azimuth" not in dataset.coords:                 # results of uq < 0.2
        azimuth = float(beam)
    else:
        azimuth = float(dataset["beam_azimuth"].sel(beam=beam))
    if np.isnan(azimuth):
        return "vertical"
    return BEAM_NAMES.get(azimuth, f"{azimuth:g} deg")


def fig6_tilt_maps(dataset):
    """Fig. 6 [1]: direction-averaged u(Vh) (top) and u(Theta) (bottom) over pitch x roll,
    one column per model; one colour scale per panel where a common one would hide the
    tilt's effect (a few per cent) behind the models' difference."""
    models = available_models(dataset, "wind_speed")
    figure, axes = plt.subplots(2, len(models), figsize=(4.4 * len(models), 6.6),
                                constrained_layout=True, squeeze=False)
    for row, quantity in enumerate(("wind_speed", "wind_direction")):
        means = {m: direction_mean(dataset, f"{quantity}_{m}").transpose("ship_roll", "ship_pitch")
                 for m in models}
        shared = plots.shared_scale([v.values for v in means.values()])
        limits = _limits(means.values()) if shared else {}
        for col, model in enumerate(models):
            ax = axes[row, col]
            mesh = ax.pcolormesh(dataset["ship_pitch"], dataset["ship_roll"],
                                 means[model].values, cmap="viridis", shading="nearest",
                                 **limits)
            ax.set_title(MODELS[model][0], fontsize=9)
            ax.set_xlabel("pitch [deg] (bow up +)")
            ax.set_ylabel("roll [deg] (starboard down +)")
            if not shared:
                figure.colorbar(mesh, ax=ax, label=_label(quantity) + ",\ndirection mean")
        if shared:
            figure.colorbar(mesh, ax=axes[row], label=_label(quantity) + ", direction mean")
    return figure


def fig7_half_cone(dataset):
    """Fig. 7 [1]: direction-averaged u(Vh) and u(Theta) against the half-cone angle
    (linear axes: the values span a factor of about two)."""
    figure, axes = plt.subplots(1, 2, figsize=(10, 3.6), constrained_layout=True)
    for ax, quantity in zip(axes, ("wind_speed", "wind_direction")):
        for model in available_models(dataset, quantity):
            style = model_style(model)
            if model != "mc_u":
                style.update(marker=".", markersize=4)
            ax.plot(dataset["lidar_half_cone"], direction_mean(dataset, f"{quantity}_{model}"),
                    **style)
        ax.set_xlabel("half-cone angle [deg]")
        ax.set_ylabel(_label(quantity) + ", direction mean")
        ax.set_ylim(bottom=0)
        ax.grid(alpha=0.3)
    axes[0].legend(fontsize=7)
    return figure


def plot_against_sweep(dataset):
    """Any 1-D sweep: u of each output against the swept key, one line per model
    (:func:`uq.outputs.plots.plot_against_sweep`)."""
    return plots.plot_against_sweep(dataset)


#: Largest number of values of a third sweep dimension drawn as rows of maps.
MAX_FACETS = 4
#: What each figure shows, under it in the report: stem (or stem prefix) -> caption.
CAPTIONS = {
    "fig2_speed_maps": "u(Vh) over wind direction and misalignment, a row per course over "
    "ground; the red line is the mean over wind direction. See whether u depends on the "
    "misalignment (the paper's model) or not (the physical model with one INS reading per "
    "scan).",
    "fig3_direction_against_misalignment": "u(wind direction), averaged over wind "
    "direction, against misalignment, a line per course over ground over their mean.",
    "fig4a_speed_against_velocities": "u(Vh) over wind speed and ship speed; the white "
    "lines are velocity ratios VR = sog/Vh of 0.5, 1 and 2. Each panel has its own colour "
    "scale where the models' difference would hide the ratio's effect.",
    "fig4b_relative_against_speed": "Relative u(Vh) along the three velocity ratios: a "
    "higher ratio gives a higher relative uncertainty. Monte Carlo (markers) lies on the "
    "GUM (dashed) where the first order holds.",
    "fig5_radial_against_direction": "Each beam's radial-velocity u against wind "
    "direction, for pitch (top) and roll (bottom); colour is the tilt, line style the "
    "model, markers Monte Carlo.",
    "fig6_tilt_maps": "u(Vh) and u(wind direction), averaged over wind direction, over "
    "pitch and roll: does tilt lower the uncertainty? Each panel has its own colour scale "
    "where a common one would hide the tilt's effect.",
    "fig7_half_cone": "u against the half-cone angle, averaged over wind direction.",
    "uncertainty_against_direction": "u(Vh) and u(wind direction) against wind direction: "
    "the paper's model (dashed), the physical GUM (line) and Monte Carlo (points).",
    "uncertainty_against_sweep": "u of each model against the swept value (with two "
    "swept keys, a line per value of the shorter or categorical one); Monte Carlo "
    "with two standard errors of u (from independent batches, or u/sqrt(2(N-1)) for runs "
    "of fewer than two batches), so that its difference from the GUM can be told from "
    "sampling noise.",
    "radial_velocity_per_beam": "u of each beam's radial velocity, a panel per beam, "
    "against the range gate or the swept value; Monte Carlo with two standard errors of u.",
    "maps_": "u over the two swept keys, one column per model (one colour scale, or one "
    "per panel where a common one would hide a panel's variation); white: outside the "
    "model (the paper's model covers only its own cases).",
    "budget": "Each input's contribution to the GUM uncertainty, |c_i| u_i, in the "
    "output's units; the dashed line is the combined u (the bars add in quadrature). The "
    "longest bar is the input to improve first.",
    "uncertainty_against_gate": "u of each model against the range gate; Monte Carlo with "
    "two standard errors of u (from independent batches, or u/sqrt(2(N-1)) for runs of "
    "fewer than two batches).",
    "histogram": "The Monte Carlo trials against the GUM's Gaussian, with both 95 % "
    "intervals (JCGM 101, clause 8): where the dashed and solid lines part by more than "
    "delta, the GUM interval is not validated.",
    "tiana2017_speed_error_map": "The horizontal wind speed of the error-free "
    "reconstruction minus the true one (no correction) over wind direction and tilt or "
    "motion amplitude, cf. Tiana-Alsina et al. (2017), Figs. 3a and 4a: the static tilt "
    "biases Vh low in every direction; a sinusoidal tilt during the scan biases it up or "
    "down with the wind direction, by far more than the same static tilt. The title states "
    "the time-stamp and phase conventions.",
    "motion_correction_comparison": "Histograms (probability density, a step line per "
    "correction model) of the reconstructed minus the true horizontal wind speed and "
    "vertical wind, from the run's own trials drawn again; the legend gives each model's "
    "bias and u, the title the range gate shown. One INS reading per scan applied to beams "
    "measured at other phases of the motion (full) can scatter more than no correction; "
    "point-wise correction removes the motion.",
    "record_spectra": "Power spectral densities, once a scan, of one beam's radial velocity "
    "(left) and of the horizontal wind speed the lidar reports (right), the mean over the "
    "run's Monte Carlo records of each record's periodogram: the field's u at the reference "
    "point (thick), the lidar at rest and moving with each swept correction; the dashed "
    "line is the -5/3 slope of the inertial range, the dotted one where the motion's peak "
    "folds into the once-a-scan sampling. The title names the scene and range gate.",
    "ti_budget": "What makes the lidar's apparent TI differ from the field's: the record "
    "variance of the reported wind speed split into the field's own u-variance and what "
    "the beams' separation, the scan's timing and the probe volume take away (negative "
    "bars), then the per-scan errors the motion, the INS and the noise add (spectral path "
    "and the GUM of one scan); the bars add up to the total in the legend. The title names "
    "the scene.",
    "apparent_against_true_ti": "The lidar's apparent TI against the field's TI over a "
    "record, which it is compared with (not the point TI the scenario sets, on the top "
    "axis): the spectral path's expectation (line) and the Monte Carlo records' mean with "
    "the 95 % of records (markers), each against its own field TI; on the dashed line the "
    "lidar would read the field's TI.",
    "component_ratios": "The lidar's along-wind (u), lateral (v) and vertical (w) "
    "turbulence: left, the variance ratio of what the lidar reports to the field's at the "
    "reference point (spectral path; the bars are the quadrature's stated numerical "
    "error); right, each component's apparent TI from the turbulence alone (lines) and the "
    "Monte Carlo records' mean with the scans' errors (points), against the field's TI "
    "over a record (dashed). The title names the scene.",
    "uncertainty_against_preview": "u of the hub-height wind speed, the yaw misalignment "
    "and the shear exponent against the preview distance, a colour per correction model: "
    "Monte Carlo as markers, the GUM as dashed lines, on a log scale.",
    "probe_bias_against_range": "The systematic error of the horizontal wind speed from "
    "the probe volume (the radial velocities weighted along the beams, minus the same at "
    "the gate centres) against the range gate, a line per probe kind. Under a power-law "
    "shear it is about alpha (alpha - 1) Var(W) cos^2(half-cone) / (2 z^2): a pulsed "
    "lidar's probe has a fixed length, so its bias falls with height; a CW lidar's probe "
    "grows as the square of the focus distance, so its bias grows.",
}


def caption(stem):
    """The caption of a figure (by its stem, or the stem's prefix)."""
    return CAPTIONS.get(stem) or next((text for prefix, text in CAPTIONS.items()
                                       if prefix.endswith("_") and stem.startswith(prefix)), "")


def sweep_dimensions(dataset):
    """The sweep dimensions of a result, in file order."""
    return tuple(dataset["mc_n_samples"].dims)


def select_scenes(dataset, select=None):
    """The result at fixed values of some sweep dimensions (``{dim: value}``; a value may
    be text, as typed after ``--select``); the nearest swept value is taken. Unknown
    dimensions or values that are not numbers raise ScenarioError (``--select``)."""
    if not select:
        return dataset
    dims = sweep_dimensions(dataset)
    chosen = {}
    for dim, value in select.items():
        if dim not in dims:
            raise ScenarioError("--select", f"{dim}={value}", f"no such sweep dimension; "
                                f"allowed: {', '.join(dims) or 'none (no sweep)'}")
        chosen[dim] = _selected_value(dataset[dim], dim, value)
    return dataset.sel(chosen)


def _selected_value(coordinate, dim, value):
    """The swept value nearest to `value` (text or number), or the exact text."""
    if coordinate.dtype.kind in "OUS":
        if str(value) not in [str(v) for v in coordinate.values]:
            raise ScenarioError("--select", f"{dim}={value}", "allowed: one of "
                                + ", ".join(str(v) for v in coordinate.values))
        return str(value)
    try:
        number = float(value)
    except (TypeError, ValueError):
        raise ScenarioError("--select", f"{dim}={value}", "allowed: a number (the nearest "
                            "swept value is taken)") from None
    return coordinate.values[int(np.argmin(np.abs(coordinate.values - number)))]


def no_figure_reason(dataset):
    """Why a result gets no figure, in one line for the command line (naming the
    ``--select dim=value`` that gives it some); None when it gets figures."""
    if figure_plan(dataset):
        return None
    if not plots.sweep_quantities(dataset):
        return ("no figure: no output has an uncertainty in these scenes (no error declared "
                "under ins or lidar.errors, or none that reaches them)")
    dims = sweep_dimensions(dataset)
    keep = _mapped_dimensions(dataset)
    fix = [d for d in dims if d not in keep]
    example = " ".join(f"--select {d}={dataset[d].values[0]}" for d in fix)
    return (f"no figure for a sweep of {len(dims)} dimensions ("
            + ", ".join(f"{d}: {dataset.sizes[d]}" for d in dims)
            + f"); fix all but two (or three, if the third has at most {MAX_FACETS} values) "
            f"with --select dim=value, e.g. {example}")


def _mapped_dimensions(dataset):
    """The dimensions maps would show: the two longest sweep dimensions."""
    dims = sorted(sweep_dimensions(dataset), key=lambda d: -dataset.sizes[d])
    return dims[:2]


def paper_plan(dataset):
    """The figures of Rubio & Gottschall (2022), for a result swept over exactly the
    keys of one of them (with more keys: :func:`select_scenes` first)."""
    dims = set(sweep_dimensions(dataset))
    plan = []
    if dims == {"ship_cog", "lidar_misalignment", "wind_direction"}:
        plan += [("fig2_speed_maps", fig2_speed_maps)]
        if "wind_direction_gum_u" in dataset:
            plan += [("fig3_direction_against_misalignment", fig3_direction_against_misalignment)]
    if dims == {"wind_speed", "ship_sog", "wind_direction"}:
        plan += [("fig4a_speed_against_velocities", fig4a_speed_against_velocities),
                 ("fig4b_relative_against_speed", fig4b_relative_against_speed)]
    if dims == {"ship_pitch", "ship_roll", "wind_direction"}:
        if "radial_velocity_gum_u" in dataset and "beam" in dataset.dims:
            plan += [("fig5_radial_against_direction", fig5_radial_against_direction)]
        plan += [("fig6_tilt_maps", fig6_tilt_maps)]
    if dims == {"lidar_half_cone", "wind_direction"}:
        plan += [("fig7_half_cone", fig7_half_cone)]
    plan += motionfigures.tiana_plan(dataset, dims)
    plan += motionfigures.comparison_plan(dataset, sweep_dimensions(dataset))
    return plan


def figure_plan(dataset, select=None):
    """Which figures a result supports: list of (file stem, plot function of the
    Dataset). With `select` (``{dim: value}``) the plan is that of the selected scenes
    (:func:`select_scenes`), and its functions must be given them (:func:`make_figures`
    does). Empty only for a sweep of more dimensions than a figure shows, or a run
    without any uncertainty (:func:`no_figure_reason`)."""
    dataset = select_scenes(dataset, select)
    return uncertainty_plan(dataset) + probe_plan(dataset) + \
        recordfigures.record_plan(dataset)


def uncertainty_plan(dataset):
    """The figures of the uncertainties (:func:`figure_plan` without the probe's)."""
    plan = paper_plan(dataset)
    if plan:
        return plan
    return (scalar_plan(dataset) if plots.sweep_quantities(dataset) else []) \
        + beam_plan(dataset)


def scalar_plan(dataset):
    """The figures of the outputs with one value per scene and gate."""
    dims = sweep_dimensions(dataset)
    if not dims:
        return single_scene_plan(dataset)
    if dims == ("wind_direction",):
        return [("uncertainty_against_direction", lambda ds: plot_uncertainty_against_direction(
            {ds.attrs.get("ins_correlation", "physical"): ds}))]
    if len(dims) == 1:
        return [("uncertainty_against_sweep", plot_against_sweep)]
    return line_plan(dataset) or map_plan(dataset)


def beam_plan(dataset):
    """An output per beam (the radial velocity) of a single scene or a 1-D sweep: a
    panel per beam (:func:`uq.outputs.plots.plot_beams`)."""
    if not plots.beam_panels(dataset) or len(sweep_dimensions(dataset)) > 1:
        return []
    return [("radial_velocity_per_beam", plots.plot_beams)]


def probe_plan(dataset):
    """A probe volume and several range gates: its systematic error against the range
    gate (:func:`uq.outputs.plots.plot_probe_bias`)."""
    if plots.probe_panels(dataset) is False:
        return []
    return [("probe_bias_against_range", plots.plot_probe_bias)]


def single_scene_plan(dataset):
    """A single scene: the budget, u against the range gate and the clause 8 histogram."""
    quantities = plots.sweep_quantities(dataset)
    plan = []
    if any(f"{q}_budget" in dataset for q in quantities):
        plan.append(("budget", plots.plot_budget))
    if dataset.sizes.get("range", 1) > 1 and "range" in dataset.dims:
        plan.append(("uncertainty_against_gate", plots.plot_against_gate))
    if can_redraw(dataset) and any(f"{q}_mc_low" in dataset for q in quantities):
        sampled = tuple(q for q in quantities if f"{q}_mc_low" in dataset)
        plan.append(("histogram", lambda ds: plots.plot_histogram(ds, scene_trials(ds, sampled))))
    return plan


#: Most scenes of a 2-D sweep drawn as lines (a line per value of one key) instead of maps.
MAX_LINE_SCENES = 48
#: Most values of the key whose values get a line each.
MAX_LINES = 6


def line_plan(dataset):
    """A small 2-D sweep (at most MAX_LINE_SCENES scenes) with a key of at most
    MAX_LINES values (a categorical one, such as ``correction``, first): u against the
    other key, a line per value of that one; [] otherwise (maps)."""
    dims = sweep_dimensions(dataset)
    if len(dims) != 2 or np.prod([dataset.sizes[d] for d in dims]) > MAX_LINE_SCENES:
        return []
    short = sorted(dims, key=lambda d: (dataset[d].dtype.kind in "iuf", dataset.sizes[d]))
    lines, x = short[0], short[1]
    if dataset.sizes[lines] > MAX_LINES:
        return []
    return [("uncertainty_against_sweep", lambda ds: plots.plot_against_sweep(ds, x, lines))]


def map_plan(dataset):
    """2-D sweeps: maps per output; 3-D: the same with a row per value of the third
    (shortest) dimension when it has at most MAX_FACETS values; else nothing."""
    dims = sweep_dimensions(dataset)
    x, y = sorted(_mapped_dimensions(dataset), key=dims.index)
    facets = [d for d in dims if d not in (x, y)]
    if len(facets) > 1 or (facets and dataset.sizes[facets[0]] > MAX_FACETS):
        return []
    facet = facets[0] if facets else None
    return [(f"maps_{q}", lambda ds, q=q: plots.plot_maps(ds, q, x, y, facet))
            for q in plots.sweep_quantities(dataset)]


def make_figures(dataset, directory, stem="", formats=("png",), select=None):
    """Draw and save every figure the result (at `select`, :func:`figure_plan`)
    supports; returns the paths written."""
    dataset = select_scenes(dataset, select)
    suffix = "".join(f"_{dim}_{_text(dataset[dim].values.item())}" for dim in select or {})
    plan = figure_plan(dataset)
    targets = {name: [Path(directory) / f"{stem}{name}{suffix}.{extension}"
                      for extension in formats] for name, _ in plan}
    for path in (p for paths in targets.values() for p in paths):
        check_target(path)                  # every target before any figure is drawn
    output_folder(directory)
    written = []
    for name, function in plan:
        figure = mark_selection(function(dataset), dataset, select)
        written += [save_figure(figure, path, dpi=130) for path in targets[name]]
        plt.close(figure)
    return written


def mark_selection(figure, dataset, select):
    """The fixed sweep values of `select` (``--select``) in the figure's title, so that a
    figure of some scenes says which; `dataset` is the selection. Returns the figure."""
    if not select:
        return figure
    text = "selected: " + ", ".join(
        f"{coordinate_label(dataset, dim).split(' [')[0]} = {_text(dataset[dim].values.item())}"
        + (f" {dataset[dim].attrs['units']}" if dataset[dim].attrs.get("units") else "")
        for dim in select)
    title = figure._suptitle.get_text().replace("\n", " ") \
        if figure._suptitle is not None else ""
    layout.suptitle(figure, f"{title}\n{text}" if title else text, fontsize=9)
    return figure


def _text(value):
    return f"{value:g}" if isinstance(value, (int, float)) else str(value)
