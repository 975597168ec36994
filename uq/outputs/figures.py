"""Section 3 of Rubio & Gottschall (2022) from result files: Figs. 2-7.

Every figure shows the paper's analytic model, the first-order GUM of the physical model
and Monte Carlo side by side (the models a result file has). Plot functions take a
finished Dataset and return a matplotlib Figure; :func:`make_figures` picks the figures a
result's sweep dimensions allow and saves them. No physics here: averages over wind
direction are plain means over a uniform sweep of the full circle.

References
----------
.. [1] Rubio, H. and Gottschall, J. (2022). Development of an uncertainty model for
   ship-based lidar measurements. J. Phys.: Conf. Ser. 2362 012034.
"""
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.lines import Line2D  # noqa: E402

from uq.files import output_folder, save_figure  # noqa: E402
from uq.outputs.planning import VELOCITY_RATIOS, velocity_ratio_line  # noqa: E402
from uq.outputs.planning import models as available_models  # noqa: E402
from uq.outputs.plots import plot_uncertainty_against_direction  # noqa: E402

#: Uncertainty variables: suffix -> (label, line style).
MODELS = {"paper_u": ("Rubio & Gottschall (2022)", "-"),
          "gum_u": ("GUM, physical model", "--"),
          "mc_u": ("Monte Carlo, physical model", ":")}
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
    per model; the red line (right axis) is the direction average."""
    models = available_models(dataset, "wind_speed")
    cogs = dataset["ship_cog"].values
    figure, axes = plt.subplots(len(cogs), len(models), figsize=(4.2 * len(models), 2.8 * len(cogs)),
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
    (blue to green) and the mean over cog (red); one panel per model."""
    models = available_models(dataset, "wind_direction")
    figure, axes = plt.subplots(1, len(models), figsize=(4.2 * len(models), 3.4), sharey=True,
                                constrained_layout=True, squeeze=False)
    colours = plt.cm.winter(np.linspace(0, 1, dataset.sizes["ship_cog"]))
    x = dataset["lidar_misalignment"].values
    for ax, model in zip(axes[0], models):
        mean = direction_mean(dataset, f"wind_direction_{model}")
        for colour, cog in zip(colours, dataset["ship_cog"].values):
            ax.plot(x, mean.sel(ship_cog=cog), color=colour, label=f"cog {cog:g} deg")
        ax.plot(x, mean.mean("ship_cog"), color="red", lw=2, label="mean over cog")
        ax.set_title(MODELS[model][0], fontsize=9)
        ax.set_xlabel("misalignment [deg]")
        ax.grid(alpha=0.3)
    axes[0, 0].set_ylabel(_label("wind_direction") + ", direction mean")
    axes[0, 0].legend(fontsize=7)
    return figure


def fig4a_speed_against_velocities(dataset):
    """Fig. 4a [1]: direction-averaged u(Vh) over Vh x sog, with the VR = 0.5, 1, 2 lines."""
    models = available_models(dataset, "wind_speed")
    figure, axes = plt.subplots(1, len(models), figsize=(4.2 * len(models), 3.6), sharey=True,
                                constrained_layout=True, squeeze=False)
    means = {m: direction_mean(dataset, f"wind_speed_{m}") for m in models}
    low = min(float(v.min()) for v in means.values())
    high = max(float(v.max()) for v in means.values())
    speed, sog = dataset["wind_speed"].values, dataset["ship_sog"].values
    for ax, model in zip(axes[0], models):
        mesh = ax.pcolormesh(speed, sog, means[model].transpose("ship_sog", "wind_speed").values,
                             vmin=low, vmax=high, cmap="viridis", shading="nearest")
        for ratio, style in zip(VELOCITY_RATIOS, ("--", "-.", ":")):
            ax.plot(speed, ratio * speed, style, color="white", lw=1.2, label=f"VR = {ratio:g}")
        ax.set_ylim(sog.min(), sog.max())
        ax.set_title(MODELS[model][0], fontsize=9)
        ax.set_xlabel("horizontal wind speed $V_h$ [m s$^{-1}$]")
    axes[0, 0].set_ylabel("ship speed over ground [m s$^{-1}$]")
    axes[0, 0].legend(fontsize=7, loc="upper left")
    figure.colorbar(mesh, ax=axes, label=_label("wind_speed") + ", direction mean")
    return figure


def fig4b_relative_against_speed(dataset):
    """Fig. 4b [1]: relative u(Vh) / Vh [%] against Vh for VR = 0.5, 1, 2."""
    figure, ax = plt.subplots(figsize=(5.5, 3.6), constrained_layout=True)
    colours = ("tab:blue", "tab:orange", "tab:green")
    for ratio, colour in zip(VELOCITY_RATIOS, colours):
        for model in available_models(dataset, "wind_speed"):
            at, line = velocity_ratio_line(dataset, f"wind_speed_{model}", ratio)
            ax.plot(at, 100 * line / at, MODELS[model][1], color=colour,
                    label=f"VR = {ratio:g}, {MODELS[model][0]}")
    ax.set_xlabel("horizontal wind speed $V_h$ [m s$^{-1}$]")
    ax.set_ylabel("u($V_h$) / $V_h$ [%], direction mean")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=6)
    return figure


def fig5_radial_against_direction(dataset):
    """Fig. 5 [1]: per-beam radial-velocity u against wind direction; top: pitch lines
    (roll 0), bottom: roll lines (pitch 0); colour = tilt, line style = model."""
    beams = dataset["beam"].values
    figure, axes = plt.subplots(2, len(beams), figsize=(3.3 * len(beams) + 1.5, 6), sharex=True,
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
                    ax.plot(level["wind_direction"], level[f"radial_velocity_{model}"].sel(
                        {tilt: angle, "beam": beam}), MODELS[model][1], color=colour)
            ax.set_title(f"beam {beam_name(dataset, beam)}, {tilt.split('_')[1]} "
                         f"({other.split('_')[1]} 0)", fontsize=9)
            ax.grid(alpha=0.3)
            if row == 1:
                ax.set_xlabel("wind direction [deg]")
        axes[row, 0].set_ylabel(_label("radial_velocity"))
        handles = [Line2D([], [], color=c, label=f"{a:g} deg") for c, a in zip(colours, values)]
        axes[row, -1].legend(handles=handles, title=tilt.split("_")[1], fontsize=7,
                             title_fontsize=8, loc="upper left", bbox_to_anchor=(1.02, 1))
    styles = [Line2D([], [], color="k", ls=MODELS[m][1], label=MODELS[m][0]) for m in models]
    figure.legend(handles=styles, fontsize=7, loc="outside lower center", ncols=len(styles))
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
    one column per model."""
    models = available_models(dataset, "wind_speed")
    figure, axes = plt.subplots(2, len(models), figsize=(4 * len(models), 6.4),
                                constrained_layout=True, squeeze=False)
    for row, quantity in enumerate(("wind_speed", "wind_direction")):
        means = {m: direction_mean(dataset, f"{quantity}_{m}") for m in models}
        low = min(float(v.min()) for v in means.values())
        high = max(float(v.max()) for v in means.values())
        for col, model in enumerate(models):
            ax = axes[row, col]
            mesh = ax.pcolormesh(dataset["ship_pitch"], dataset["ship_roll"],
                                 means[model].transpose("ship_roll", "ship_pitch").values,
                                 vmin=low, vmax=high, cmap="viridis", shading="nearest")
            ax.set_title(MODELS[model][0], fontsize=9)
            ax.set_xlabel("pitch [deg] (bow up +)")
            ax.set_ylabel("roll [deg] (starboard down +)")
        figure.colorbar(mesh, ax=axes[row], label=_label(quantity) + ", direction mean")
    return figure


def fig7_half_cone(dataset):
    """Fig. 7 [1]: direction-averaged u(Vh) and u(Theta) against the half-cone angle."""
    figure, axes = plt.subplots(1, 2, figsize=(10, 3.6), constrained_layout=True)
    for ax, quantity in zip(axes, ("wind_speed", "wind_direction")):
        for model in available_models(dataset, quantity):
            ax.plot(dataset["lidar_half_cone"], direction_mean(dataset, f"{quantity}_{model}"),
                    MODELS[model][1], marker="o", ms=3, label=MODELS[model][0])
        ax.set_xlabel("half-cone angle [deg]")
        ax.set_ylabel(_label(quantity) + ", direction mean")
        ax.set_yscale("log")
        ax.grid(alpha=0.3, which="both")
    axes[0].legend(fontsize=7)
    return figure


def plot_against_sweep(dataset):
    """Any 1-D sweep: u of each output against the swept key, one line per model."""
    (dim,) = [d for d in dataset["mc_n_samples"].dims]
    quantities = [q for q in ("wind_speed", "wind_direction", "vertical_wind")
                  if f"{q}_gum_u" in dataset]
    figure, axes = plt.subplots(1, len(quantities), figsize=(4.5 * len(quantities), 3.4),
                                constrained_layout=True, squeeze=False)
    for ax, quantity in zip(axes[0], quantities):
        data = dataset[[f"{quantity}_{m}" for m in available_models(dataset, quantity)]]
        extra = [d for d in data.dims if d != dim]
        for model in available_models(dataset, quantity):
            line = data[f"{quantity}_{model}"]
            line = line.isel({d: 0 for d in extra}) if extra else line
            ax.plot(dataset[dim], line, MODELS[model][1], marker="o", ms=3, label=MODELS[model][0])
        ax.set_xlabel(dataset[dim].attrs.get("long_name", dim))
        ax.set_ylabel(f"u({quantity.replace('_', ' ')}) [{dataset[f'{quantity}_gum_u'].attrs.get('units', '')}]")
        ax.grid(alpha=0.3)
    axes[0, 0].legend(fontsize=7)
    return figure


def figure_plan(dataset):
    """Which figures a result supports: list of (file stem, plot function)."""
    dims = set(dataset["mc_n_samples"].dims)
    plan = []
    if {"ship_cog", "lidar_misalignment", "wind_direction"} <= dims:
        plan += [("fig2_speed_maps", fig2_speed_maps)]
        if "wind_direction_gum_u" in dataset:
            plan += [("fig3_direction_against_misalignment", fig3_direction_against_misalignment)]
    if {"wind_speed", "ship_sog", "wind_direction"} <= dims:
        plan += [("fig4a_speed_against_velocities", fig4a_speed_against_velocities),
                 ("fig4b_relative_against_speed", fig4b_relative_against_speed)]
    if {"ship_pitch", "ship_roll", "wind_direction"} <= dims:
        if "radial_velocity_gum_u" in dataset and "beam" in dataset.dims:
            plan += [("fig5_radial_against_direction", fig5_radial_against_direction)]
        plan += [("fig6_tilt_maps", fig6_tilt_maps)]
    if {"lidar_half_cone", "wind_direction"} <= dims:
        plan += [("fig7_half_cone", fig7_half_cone)]
    if not plan and dims == {"wind_direction"}:
        plan += [("uncertainty_against_direction", lambda ds: plot_uncertainty_against_direction(
            {ds.attrs.get("ins_correlation", "physical"): ds}))]
    elif not plan and len(dims) == 1:
        plan += [("uncertainty_against_sweep", plot_against_sweep)]
    return plan


def make_figures(dataset, directory, stem="", formats=("png",)):
    """Draw and save every figure the result supports; returns the paths written."""
    directory = output_folder(directory)
    paths = []
    for name, function in figure_plan(dataset):
        figure = function(dataset)
        for extension in formats:
            paths.append(save_figure(figure, directory / f"{stem}{name}.{extension}",
                                     dpi=130))
        plt.close(figure)
    return paths
