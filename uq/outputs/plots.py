"""Figures from finished result Datasets (no physics, no I/O beyond saving)."""
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.ticker import NullFormatter  # noqa: E402


def plot_uncertainty_against_direction(results, axes_pair=None):
    """u(wind speed) and u(wind direction) against the swept wind direction.

    Parameters
    ----------
    results : dict
        Label -> Dataset with a ``wind_direction`` sweep dimension (e.g. one per INS
        correlation mode). Each is drawn as Monte Carlo (points), physical GUM (line) and,
        from the first, the Rubio & Gottschall (2022) model (dashed).

    Returns
    -------
    matplotlib.figure.Figure
    """
    figure, axes = plt.subplots(1, 2, figsize=(10, 3.8), constrained_layout=True) \
        if axes_pair is None else (axes_pair[0].figure, axes_pair)
    for (label, ds), colour in zip(results.items(), ("tab:blue", "tab:orange", "tab:green")):
        x = ds["wind_direction"].values
        for ax, q, unit in ((axes[0], "wind_speed", "m s$^{-1}$"), (axes[1], "wind_direction", "deg")):
            ax.plot(x, ds[f"{q}_gum_u"], color=colour, label=f"GUM, physical ({label})")
            ax.plot(x, ds[f"{q}_mc_u"], "o", ms=3, color=colour, label=f"Monte Carlo ({label})")
            ax.set_xlabel("wind direction [deg]")
            ax.set_ylabel(f"u({q.replace('_', ' ')}) [{unit}]")
    first = next(iter(results.values()))
    for ax, q in ((axes[0], "wind_speed"), (axes[1], "wind_direction")):
        ax.plot(first["wind_direction"], first[f"{q}_paper_u"], "k--",
                label="Rubio & Gottschall (2022)")
        ax.set_xlim(0, 360)
        ax.set_xticks(range(0, 361, 90))
        ax.grid(alpha=0.3)
    axes[0].legend(fontsize=7)
    return figure


def plot_bench(dataset):
    """Relative error of u(wind speed) against wall time, one panel per scene: every
    repeated run as a point, the median per method and sample size as a line."""
    scenes = list(dataset["scene"].values)
    figure, axes = plt.subplots(1, len(scenes), figsize=(5.2 * len(scenes), 4),
                                constrained_layout=True, squeeze=False)
    for ax, scene in zip(axes[0], scenes):
        for method in dataset["method"].values:
            data = dataset.sel({"scene": scene, "method": method})
            line, = ax.plot(data["time_s"].median("repeat"),
                            data["relative_error"].median("repeat"), "-", label=str(method))
            ax.plot(data["time_s"].values.ravel(), data["relative_error"].values.ravel(), ".",
                    color=line.get_color(), alpha=0.4, ms=4)
        ax.axhline(1e-3, color="k", lw=0.8, ls="--")
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.xaxis.set_minor_formatter(NullFormatter())     # decades only: no overlaps
        ax.set_title(str(scene), fontsize=9)
        ax.set_xlabel("wall time [s]")
        ax.set_ylabel("relative error of u(wind speed) [1]")
        ax.grid(alpha=0.3, which="both")
    axes[0, 0].legend(fontsize=7, title="method (points: runs; line: median)", title_fontsize=7)
    return figure
