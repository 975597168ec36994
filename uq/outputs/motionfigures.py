"""Figures of time-resolved motion results (no physics; trials drawn again by
:mod:`uq.outputs.samples`).

* :func:`tiana2017_error_map`: the error of the horizontal wind speed of a VAD against
  the wind direction and the tilt amplitude (Tiana-Alsina et al. 2017, Figs. 3a/4a), for
  a sweep of ``wind.direction`` and ``motion.pitch.amplitude`` (or ``ship.pitch``);
* :func:`correction_comparison`: scatter and bias of the horizontal wind speed (and the
  vertical wind) under each correction model of a ``correction`` sweep of a moving
  platform: the Monte Carlo trials as histograms of the error, bias +- u beside them;
* :func:`uncertainty_against_preview`: with several range gates (a nacelle lidar's
  preview distances), u of its hub-height wind speed, yaw misalignment and shear
  exponent against them, per correction model.

References
----------
.. [1] Tiana-Alsina, J., Rocadenbosch, F. and Gutierrez-Antunano, M. A. (2017). IGARSS.
"""
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402
import yaml  # noqa: E402

from uq.outputs import layout  # noqa: E402
from uq.outputs.samples import HISTOGRAM_TRIALS, scene_assignments, trials_with  # noqa: E402

TILT_DIMENSIONS = ("motion_pitch_amplitude", "ship_pitch", "motion_roll_amplitude",
                   "ship_roll")
#: Contour levels of the error map [m s-1].
CONTOURS = (-1.0, -0.5, -0.25, -0.1, -0.05, -0.02, 0.02, 0.05, 0.1, 0.25, 0.5, 1.0)
#: Histogram bins per correction model.
HISTOGRAM_BINS = 70
#: Units of the harmonic motion's degrees of freedom (docs/scenario.md, motion.<dof>).
HARMONIC_UNITS = {"roll": "deg", "pitch": "deg", "yaw": "deg", "surge": "m", "sway": "m",
                  "heave": "m"}
CORRECTION_COLOURS = {"none": "tab:grey", "yaw": "tab:purple", "tilt2d": "tab:brown",
                      "full": "tab:red", "pointwise": "tab:blue"}


def tiana_plan(dataset, dims):
    """The error map when a result sweeps wind direction and one tilt amplitude."""
    tilt = [d for d in dims if d in TILT_DIMENSIONS]
    if set(dims) == {"wind_direction"} | set(tilt) and len(tilt) == 1 and \
            "wind_speed_nominal" in dataset:
        return [("tiana2017_speed_error_map",
                 lambda ds: tiana2017_error_map(ds, tilt[0]))]
    return []


def tiana2017_error_map(dataset, tilt):
    """HWS error (error-free reconstruction minus truth) [m s-1] over wind direction and
    tilt amplitude, diverging colours centred on 0, with contours (their levels marked on
    the colour bar: labels in the map would collide)."""
    error = (dataset["wind_speed_nominal"] - dataset["wind_speed_true"]).transpose(
        tilt, "wind_direction").values
    x, y = dataset["wind_direction"].values, dataset[tilt].values
    limit = float(np.nanmax(np.abs(error))) or 1.0
    figure, ax = plt.subplots(figsize=(7.2, 4.2), constrained_layout=True)
    mesh = ax.pcolormesh(x, y, error, cmap="RdBu_r", vmin=-limit, vmax=limit,
                         shading="nearest")
    bar = figure.colorbar(mesh, ax=ax, label="HWS error, reconstructed minus true "
                          "[m s$^{-1}$]")
    levels = [v for v in CONTOURS if np.nanmin(error) < v < np.nanmax(error)]
    if levels:
        lines = ax.contour(x, y, error, levels=levels, colors="k", linewidths=0.6)
        bar.add_lines(lines)
    ax.set_xlabel("wind direction [deg]")
    ax.set_ylabel(_tilt_label(tilt))
    scenario = yaml.safe_load(dataset.attrs.get("scenario", "")) or {}
    ax.set_title(_tiana_title(scenario, tilt) + f"; error {np.nanmin(error):+.2f} to "
                 f"{np.nanmax(error):+.2f} m/s", fontsize=9)
    return figure


def _tilt_label(tilt):
    kind = "static " if tilt.startswith("ship_") else "sinusoidal "
    axis = "pitch" if "pitch" in tilt else "roll"
    return f"{kind}{axis} amplitude [deg]"


def _tiana_title(scenario, tilt):
    lidar = scenario.get("lidar", {})
    n = len(lidar.get("azimuths", []))
    text = f"VAD of {n} lines of sight, half-cone {lidar.get('half_cone', '?')} deg, " \
           f"correction {scenario.get('correction', '?')}"
    motion = (scenario.get("motion") or {}).get("pitch" if "pitch" in tilt else "roll")
    if motion and tilt.startswith("motion_"):
        text += f", {1 / motion['period']:.2g} Hz, phase {motion['phase']:g} deg at the " \
                "scan's start\ncf. Tiana-Alsina et al. (2017), Fig. 4a"
    else:
        text += "\ncf. Tiana-Alsina et al. (2017), Fig. 3a"
    return text


def comparison_plan(dataset, dims):
    """Scatter and bias per correction model, for a ``correction`` sweep in motion."""
    scenario = yaml.safe_load(dataset.attrs.get("scenario", "")) or {}
    if tuple(dims) == ("correction",) and scenario.get("motion") and \
            dataset.attrs.get("sampling_method") not in (None, "none") and \
            "wind_speed_true" in dataset:
        plan = [("motion_correction_comparison", correction_comparison)]
        if dataset.sizes.get("range", 1) > 1 and any(
                f"{q}_mc_u" in dataset for q in PREVIEW_QUANTITIES):
            plan.append(("uncertainty_against_preview", uncertainty_against_preview))
        return plan
    return []


#: What a nacelle lidar's figure shows against the preview distance, with its unit.
PREVIEW_QUANTITIES = {"wind_speed": ("u(hub-height wind speed)", "m s$^{-1}$"),
                      "yaw_misalignment": ("u(yaw misalignment)", "deg"),
                      "shear_exponent": ("u(shear exponent)", "1")}


def uncertainty_against_preview(dataset):
    """u of the hub-height wind speed, the yaw misalignment and the shear exponent against
    the range gate (a nacelle lidar's preview distance), a colour per correction model:
    Monte Carlo as markers, the GUM as dashed lines (log scale: the models differ by
    orders of magnitude)."""
    quantities = [q for q in PREVIEW_QUANTITIES if f"{q}_mc_u" in dataset]
    figure, axes = plt.subplots(1, len(quantities), figsize=(4.4 * len(quantities), 3.8),
                                constrained_layout=True, squeeze=False)
    ranges = dataset["range"].values
    for ax, q in zip(axes[0], quantities):
        for c in [str(c) for c in dataset["correction"].values]:
            colour = CORRECTION_COLOURS.get(c)
            mc = dataset[f"{q}_mc_u"].sel(correction=c).values
            ax.plot(ranges, mc, "o", color=colour, label=f"{c}: Monte Carlo")
            if f"{q}_gum_u" in dataset:
                ax.plot(ranges, dataset[f"{q}_gum_u"].sel(correction=c).values, "--",
                        color=colour, lw=1.0, label=f"{c}: GUM")
        words, unit = PREVIEW_QUANTITIES[q]
        ax.set_yscale("log")
        ax.set_xlabel("preview distance [m]")
        ax.set_ylabel(f"{words} [{unit}]")
        ax.grid(True, which="both", lw=0.3)
    axes[0][0].legend(fontsize=8)
    scenario = yaml.safe_load(dataset.attrs.get("scenario", "")) or {}
    n = int(np.max(dataset["mc_n_samples"]))
    layout.suptitle(figure, f"{scenario.get('name', '')}: {_sea(scenario)}; {n} Monte Carlo "
                    "scans per model", fontsize=9)
    return figure


def correction_comparison(dataset, n_max=HISTOGRAM_TRIALS):
    """Histograms (density, step lines) of the reconstructed minus the true horizontal
    wind speed and vertical wind for each correction model, from the run's own trials
    (drawn again), the legend giving each model's bias and u; with several range gates,
    at the middle one (the title says which)."""
    corrections = [str(c) for c in dataset["correction"].values]
    gate = dataset.sizes["range"] // 2 if "range" in dataset.dims else 0
    quantities = [q for q in ("wind_speed", "vertical_wind") if f"{q}_mc_u" in dataset]
    figure, axes = plt.subplots(1, len(quantities), figsize=(5.2 * len(quantities), 4.0),
                                constrained_layout=True, squeeze=False)
    trials = {c: trials_with(dataset, scene_assignments(dataset, {"correction": c}),
                                 tuple(quantities), n_max)
              for c in corrections}
    for ax, q in zip(axes[0], quantities):
        errors = {c: trials[c][q][:, gate] - float(_at(dataset, f"{q}_true", c, gate))
                  for c in corrections}
        for c in corrections:                 # each model on bins of its own spread
            finite = errors[c][np.isfinite(errors[c])]
            edges = np.linspace(*np.percentile(finite, [0.1, 99.9]), HISTOGRAM_BINS)
            bias = float(_at(dataset, f"{q}_mc_mean", c, gate)
                         - _at(dataset, f"{q}_true", c, gate))
            u = float(_at(dataset, f"{q}_mc_u", c, gate))
            ax.hist(errors[c], bins=edges, histtype="step", lw=1.4,
                    color=CORRECTION_COLOURS.get(c), density=True,
                    label=f"{c}: bias {bias:+.3f}, u {u:.3f}")
        ax.axvline(0.0, color="k", lw=0.6)
        unit = "m s$^{-1}$"
        name = "horizontal wind speed" if q == "wind_speed" else "vertical wind"
        ax.set_xlabel(f"{name}: reconstructed minus true [{unit}]")
        ax.set_ylabel("probability density [s m$^{-1}$]")
        ax.legend(fontsize=8, title="correction", title_fontsize=8)
    n = int(np.max(dataset["mc_n_samples"]))
    scenario = yaml.safe_load(dataset.attrs.get("scenario", "")) or {}
    where = f"; range gate {float(dataset['range'].values[gate]):g} m (middle of " \
        f"{dataset.sizes['range']})" if "range" in dataset.dims else ""
    layout.suptitle(figure, f"{_sea(scenario)}; {n} Monte Carlo scans per model"
                    f"{'' if n <= n_max else f' (histograms: the first {n_max})'}{where}",
                    fontsize=9)
    return figure


def _sea(scenario):
    """The motion in words, for a title."""
    motion = scenario.get("motion") or {}
    if "spectrum" in motion:
        sea = motion["spectrum"]
        return f"JONSWAP sea, Hs {sea['hs']:g} m, Tp {sea['tp']:g} s"
    if "series" in motion:
        record = motion["series"]
        return (f"measured motion record {Path(str(record.get('file', ''))).name} "
                f"({record.get('components', '')} harmonics kept, random window per scan)")
    parts = [f"{dof} {one['amplitude']:g} {HARMONIC_UNITS.get(dof, '')} at "
             f"{one['period']:g} s" for dof, spec in motion.items()
             for one in (spec if isinstance(spec, list) else [spec])
             if isinstance(one, dict) and "amplitude" in one]
    return "harmonic motion: " + ", ".join(parts) if parts else "motion"


def _at(dataset, name, correction, gate=0):
    value = dataset[name].sel(correction=correction)
    return value.isel(range=gate) if "range" in value.dims else value
