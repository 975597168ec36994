"""Figures of a finished fit Dataset (:mod:`uq.fit.fitting`): the profile and a corner plot."""
import corner
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

LABELS = {"reference_speed": "$U_{ref}$ [m s$^{-1}$]", "shear": r"$\alpha$ [1]",
          "friction_velocity": "$u_*$ [m s$^{-1}$]", "roughness_length": "$z_0$ [m]",
          "ln_sigma": r"ln $\sigma$ [ln(m s$^{-1}$)]"}


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
                label="95 % confidence (delta method)")
        ax.errorbar(fit.observed_speed, fit.observed_height, xerr=fit.observed_speed_u,
                    fmt="o", color="k", ms=4, label="observed $\\pm 1u$")
        ax.set_title(f"{name}: {_parameter_text(dataset, name)}", fontsize=9)
        ax.set_xlabel("wind speed [m s$^{-1}$]")
    axes[0, 0].set_ylabel("height above sea level [m]")
    axes[0, 0].legend(fontsize=7, loc="upper left")
    figure.tight_layout()
    return figure


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
    first), with the true values where the Dataset has them."""
    name = dataset["fit"].values[0] if fit is None else fit
    row = dataset.sel(fit=name)
    burn, thin = int(row["burn"]), int(row["thin"])
    chain = row["chain"].values[:, burn::thin]                   # ensemble, step, walker, k
    samples = chain.reshape(-1, chain.shape[-1])
    samples = samples[np.all(np.isfinite(samples), axis=1)]
    names = list(dataset["parameter"].values)
    truths = row["true_value"].values if "true_value" in dataset else None
    figure = corner.corner(samples, labels=[LABELS.get(n, n) for n in names],
                           quantiles=[0.025, 0.5, 0.975], show_titles=True,
                           title_fmt=".3g", truths=truths, truth_color="C3")
    figure.suptitle(f"posterior: {name}", fontsize=10, y=1.04)
    return figure
