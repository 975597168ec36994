"""Figures of a finished fit Dataset (:mod:`uq.fit.fitting`): the profile and a corner plot."""
import textwrap

import corner
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.lines import Line2D  # noqa: E402

from uq.outputs import layout  # noqa: E402

LABELS = {"reference_speed": "$U_{ref}$ [m s$^{-1}$]", "shear": r"$\alpha$ [1]",
          "friction_velocity": "$u_*$ [m s$^{-1}$]", "roughness_length": r"ln $z_0$ [ln m]",
          "ln_sigma": r"ln $\sigma$ [ln(m s$^{-1}$)]"}
#: Short names for the corner plot's titles (the units are on the axes).
TITLES = {"reference_speed": "$U_{ref}$", "shear": r"$\alpha$", "friction_velocity": "$u_*$",
          "roughness_length": r"ln $z_0$", "ln_sigma": r"ln $\sigma$"}
#: Parameters drawn as their natural logarithm in the corner plot.
LOGARITHMIC = ("roughness_length",)
#: Share of the draws each corner axis spans (central): the bulk, not a far tail.
CORNER_RANGE = 0.995
#: Share of the profile figure's height below the panels for the legend (off the data).
LEGEND_SPACE = 0.12
#: Bounds of the number of histogram bins of the corner plot.
MIN_CORNER_BINS, MAX_CORNER_BINS = 15, 50


def plot_profile_fit(dataset):
    """One panel per fit: observations (+-1 u), posterior median profile, 95 % credible
    band of the profile, 95 % posterior predictive band, least-squares fit and its 95 %
    confidence band; speed [m s-1] against height [m]."""
    fits = list(dataset["fit"].values)
    figure, axes = plt.subplots(1, len(fits), figsize=(4.6 * len(fits), 4.6), sharey=True,
                                squeeze=False)
    for ax, name in zip(axes[0], fits):
        fit = dataset.sel(fit=name)
        z = fit["grid_height"].values
        ax.fill_betweenx(z, fit.predictive_low95, fit.predictive_high95, color="C0", alpha=0.15,
                         label="95 % posterior predictive")
        ax.fill_betweenx(z, fit.profile_low95, fit.profile_high95, color="C0", alpha=0.4,
                         label="95 % credible band")
        ax.plot(fit.profile_median, z, color="C0", label="posterior median")
        ax.plot(fit.least_squares_fit, z, "--", color="C3", label="least squares")
        ax.plot(fit.least_squares_confidence_low, z, ":", color="C3")
        ax.plot(fit.least_squares_confidence_high, z, ":", color="C3",
                label="95 % confidence (least squares, delta method)")
        ax.errorbar(fit.observed_speed, fit.observed_height, xerr=fit.observed_speed_u,
                    fmt="o", color="k", ms=4, label="observed $\\pm 1u$")
        ax.set_title(f"{name}: {_parameter_text(dataset, name)}", fontsize=9)
        ax.set_xlabel("wind speed [m s$^{-1}$]" + _basis_text(fit))
    axes[0, 0].set_ylabel("height above sea level [m]")
    handles, labels = axes[0, 0].get_legend_handles_labels()
    figure.tight_layout(rect=(0, LEGEND_SPACE, 1, 1))
    figure.legend(handles, labels, fontsize=7, loc="lower center", ncol=3, frameon=False)
    return figure


def _basis_text(fit):
    """What the least-squares band rests on, wrapped for a legend."""
    if "least_squares_basis" not in fit.coords:
        return ""
    return "\n" + "\n".join(textwrap.wrap("least-squares band on "
                                          f"{fit['least_squares_basis'].values}", 48))


def _parameter_text(dataset, name):
    fit = dataset.sel(fit=name)
    parts = []
    for parameter in dataset["parameter"].values[:int(dataset.attrs.get("profile_parameters",
                                                                        2))]:
        p = fit.sel(parameter=parameter)
        parts.append(f"{parameter} {float(p.posterior_median):.3g} "
                     f"[{float(p.posterior_low95):.3g}, {float(p.posterior_high95):.3g}]")
    return "\n".join(parts)


def plot_corner(dataset, fit=None):
    """Corner plot (corner.py) of the burnt-in, thinned posterior of one fit (default the
    first), with the true values where the Dataset has them.

    What a person should see is the bulk of the posterior: each axis spans the central
    :data:`CORNER_RANGE` of the draws (a far tail of a few draws would otherwise squeeze
    the histogram into one spike), with a number of bins that grows with the draws. The
    roughness length is drawn as ln z0, the scale the profile is linear in and the
    sampler works on. The titles give the median and the 95 % interval.
    """
    name = dataset["fit"].values[0] if fit is None else fit
    row = dataset.sel(fit=name)
    burn, thin = int(row["burn"]), int(row["thin"])
    chain = row["chain"].values[:, burn::thin]                   # ensemble, step, walker, k
    samples = chain.reshape(-1, chain.shape[-1])
    samples = samples[np.all(np.isfinite(samples), axis=1)]
    names = list(dataset["parameter"].values)
    truths = row["true_value"].values.copy() if "true_value" in dataset else None
    samples, labels, titles = _corner_scale(samples, names, truths)
    figure = corner.corner(samples, bins=_corner_bins(len(samples)),
                           range=[CORNER_RANGE] * len(names), labels=labels, titles=titles,
                           quantiles=[0.025, 0.5, 0.975], title_quantiles=[0.025, 0.5, 0.975],
                           show_titles=True, title_fmt=".3g", title_kwargs={"fontsize": 9},
                           label_kwargs={"fontsize": 9}, truths=truths, truth_color="C3",
                           quiet=True)   # corner nudges degenerate contour levels itself
    figure.subplots_adjust(top=0.86, left=0.14, bottom=0.2, wspace=0.15, hspace=0.15)
    layout.suptitle(figure, f"posterior: {name} (median, 95 % interval; axes: central "
                    f"{100 * CORNER_RANGE:g} % of {len(samples)} draws)", fontsize=10)
    key = [Line2D([], [], color="k", label="posterior: histograms, density contours"),
           Line2D([], [], color="k", ls="--", label="2.5, 50 and 97.5 % quantiles")]
    if truths is not None:
        key.append(Line2D([], [], color="C3", label="true value"))
    figure.legend(handles=key, loc="lower center", fontsize=8, frameon=False,
                  ncols=layout.legend_columns(figure, [h.get_label() for h in key], 8))
    return figure


def _corner_scale(samples, names, truths):
    """Samples, axis labels and titles, with the roughness length as ln z0."""
    samples = samples.copy()
    labels, titles = [], []
    for k, name in enumerate(names):
        if name in LOGARITHMIC:
            samples[:, k] = np.log(samples[:, k])
            if truths is not None and np.isfinite(truths[k]):
                truths[k] = np.log(truths[k])
        labels.append(LABELS.get(name, name))
        titles.append(TITLES.get(name, name))
    return samples, labels, titles


def _corner_bins(draws):
    """Histogram bins: ~sqrt(draws) / 4, from 15 (a few hundred draws) to 50."""
    return int(np.clip(np.sqrt(draws) / 4, MIN_CORNER_BINS, MAX_CORNER_BINS))
