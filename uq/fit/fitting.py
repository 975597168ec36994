"""The fit orchestrator: profile data -> least squares and emcee posterior -> Dataset.

Inputs (:func:`profile_from_results`, :func:`profile_from_table`):

* ``uq run`` results with range gates: the observed speeds are the Monte Carlo means
  per gate (the expected measurement), fitted twice:

  - ``propagated``: at the propagated mean gate heights (``gate_height_mc_mean``) with
    the full Monte Carlo covariance of the speeds between gates
    (``wind_speed_mc_covariance``), which already holds what the height errors do to
    the speeds (the model measures at the true heights), so no separate height term;
  - ``naive``: at the nominal heights ``lidar height + range`` with independent errors
    (the diagonal only), as if each gate's error were its own.

* a table of heights and speeds (e.g. 10-min mast records, several per height), with
  optional standard uncertainties of speed and height.

Each fit gives the posterior summary (median, 68 % and 95 % central credible
intervals, each with its Monte Carlo standard error ``posterior_<key>_mcse``), the
posterior predictive band, the least-squares (``curve_fit``) estimate
with its delta-method intervals beside it, and the chains.

References
----------
.. [1] Matavar, A. (2024). Wind field reconstruction from floating lidars. MSc thesis,
   TU Delft, Sec. 5.2.2 and App. A.11.
"""
import numpy as np
import pandas as pd
import xarray as xr

from uq.errors import DataFileError
from uq.fit.bayesfit import (ProfilePosterior, posterior_summary, profile_data, sample_posterior,
                             variances)
from uq.fit.profilefit import INTERVAL_BASES, least_squares_profile
from uq.physics.profiles import PROFILES
from uq.pipeline.metadata import cf_encode, history

#: Heights of the bands: this many points between the lowest and highest gate.
GRID_POINTS = 60
#: Posterior draws used for the bands (thinned, all ensembles).
BAND_DRAWS = 4000
SUMMARY_KEYS = ("low95", "low68", "median", "high68", "high95")


#: Fewest profile points a fit needs [1]: two parameters and a residual.
MIN_FIT_POINTS = 3
#: Most profile points of a fit [1]: the likelihood is O(n) per walker and step; with
#: 32 walkers, 4 ensembles and ~10^4 steps, 10^4 points take ~10 min on one core.
MAX_FIT_POINTS = 10_000


def profile_from_results(dataset, kind="propagated", source="results"):
    """ProfileData of a results Dataset with range gates; `kind` propagated | naive."""
    _check_results(dataset, source)
    speeds = dataset["wind_speed_mc_mean"].values
    if kind == "naive":
        heights = dataset["gate_height_true"].values
        return profile_data(heights, speeds, speed_covariance=dataset["wind_speed_mc_u"].values)
    return profile_data(dataset["gate_height_mc_mean"].values, speeds,
                        speed_covariance=dataset["wind_speed_mc_covariance"].values)


def _check_results(dataset, source):
    extra = [d for d in dataset["mc_n_samples"].dims]
    if extra:
        raise DataFileError(source, "sweep", f"results of a sweep ({', '.join(extra)}); "
                            "allowed: results of one scene (run without sweep)")
    if dataset.sizes.get("range", 1) < 3:
        raise DataFileError(source, "lidar.ranges", f"{dataset.sizes.get('range', 1)} range "
                            "gate(s); allowed: at least 3 gates to fit a profile")
    missing = [v for v in ("wind_speed_mc_mean", "wind_speed_mc_covariance",
                           "gate_height_mc_mean") if v not in dataset]
    if missing:
        raise DataFileError(source, "outputs", f"no {', '.join(missing)}; allowed: results "
                            "of a scenario whose outputs include wind_speed and gate_height")


def profile_from_table(table, columns, source="table"):
    """ProfileData from a mapping/DataFrame of columns (height, speed[, speed_u, height_u]);
    rows with a missing value are dropped and counted (returned second)."""
    missing = [columns[k] for k in ("height", "speed") if columns[k] not in table]
    if missing:
        raise DataFileError(source, "fit.columns", f"no column {', '.join(missing)}; allowed: "
                            f"the file's columns ({', '.join(map(str, table))})")
    names = {k: columns[k] for k in ("height", "speed", "speed_u", "height_u") if k in columns}
    values = {k: _numbers(table[c], c, source) for k, c in names.items() if c in table}
    finite = np.all([np.isfinite(v) for v in values.values()], axis=0)
    values = {k: v[finite] for k, v in values.items()}
    if np.any(values["height"] <= 0):
        raise DataFileError(source, columns["height"], "heights must be > 0 m")
    if len(values["height"]) > MAX_FIT_POINTS:
        raise DataFileError(source, "", f"{len(values['height'])} rows; allowed: at most "
                            f"{MAX_FIT_POINTS} (average the records per height first: a "
                            "profile fit of more points costs minutes per 10^4 and adds "
                            "nothing the means do not hold)")
    if len(values["height"]) < MIN_FIT_POINTS:
        raise DataFileError(source, "", f"{len(values['height'])} row(s) with a height and a "
                            f"speed; allowed: at least {MIN_FIT_POINTS} to fit a profile "
                            "with a residual")
    return profile_data(values["height"], values["speed"], values.get("speed_u"),
                        values.get("height_u")), int(np.sum(~finite))


def _numbers(column, name, source):
    """A table column as floats (empty cells NaN); text in it is bad input."""
    values = pd.to_numeric(column, errors="coerce").to_numpy(dtype=float)
    text = column[np.isnan(values) & column.notna().to_numpy()]
    if len(text):
        raise DataFileError(source, str(name), f"{str(text.iloc[0])[:40]!r} (row "
                            f"{text.index[0] + 1}) is not a number; allowed: numbers without "
                            "units (m, m s-1)")
    return values


def fit_profile(data, config, seed=None):
    """Least squares and the emcee posterior of one ProfileData; a Dataset.

    Parameters
    ----------
    data : uq.fit.bayesfit.ProfileData
    config : uq.pipeline.fitconfig.FitConfig
    seed : int, optional
        Overrides ``config.seed``.
    """
    posterior = ProfilePosterior(config.profile, data, fixed=config.fixed,
                                 scatter=config.scatter, priors=config.priors)
    chains = sample_posterior(posterior, config.seed if seed is None else seed,
                              walkers=config.walkers, ensembles=config.ensembles,
                              max_steps=config.max_steps)
    grid = np.linspace(data.heights.min(), data.heights.max(), GRID_POINTS)
    known = bool(np.all(variances(data.speed_covariance) > 0))
    # the data's covariance where it is given (plus, with a free scatter, the extra
    # scatter estimated from the residuals), else the residuals' scatter alone;
    # curve_fit takes standard deviations (1-D) or a covariance matrix (2-D)
    sigma = data.speed_covariance if np.ndim(data.speed_covariance) == 2 else \
        np.sqrt(data.speed_covariance)
    least = least_squares_profile(config.profile, data.heights, data.speeds,
                                  sigma=sigma if known else None, scatter=config.scatter,
                                  fixed=config.fixed, grid=grid)
    return _fit_dataset(data, posterior, chains, least, grid)


def _fit_dataset(data, posterior, chains, least, grid):
    names = list(posterior.parameter_names)
    summary = posterior_summary(chains["samples"], names)
    bands = predictive_bands(posterior, chains["samples"], grid)
    k = len(posterior.names)
    summaries = {f"posterior_{key}": ("parameter", [summary[n][key] for n in names])
                 for key in SUMMARY_KEYS}
    summaries.update({f"posterior_{key}_mcse": ("parameter", chains["quantile_mcse"][key])
                      for key in SUMMARY_KEYS})
    ds = xr.Dataset(
        summaries,
        coords={"parameter": names, "point": np.arange(grid.size),
                "gate": np.arange(data.heights.size)})
    ds["grid_height"] = ("point", grid)
    ls = np.full(len(names), np.nan)
    ds["least_squares_value"] = ("parameter", _pad(least["parameters"], ls))
    ds["least_squares_standard_error"] = ("parameter", _pad(least["standard_errors"], ls))
    ds["least_squares_low95"] = ("parameter", _pad(least["parameter_low"], ls))
    ds["least_squares_high95"] = ("parameter", _pad(least["parameter_high"], ls))
    for key in ("fit", "confidence_low", "confidence_high", "prediction_low", "prediction_high"):
        ds[f"least_squares_{key}"] = ("point", least[key])
    for key, values in bands.items():
        ds[key] = ("point", values)
    ds["observed_height"] = ("gate", data.heights)
    ds["observed_speed"] = ("gate", data.speeds)
    ds["observed_speed_u"] = ("gate", np.sqrt(variances(data.speed_covariance)))
    ds["chain"] = (("ensemble", "step", "walker", "parameter"), chains["chain"])
    ds["tau"] = ("parameter", chains["tau"])
    ds["rhat"] = ("parameter", chains["rhat"])
    ds["maximum_a_posteriori"] = ("parameter", chains["map"])
    ds["least_squares_extra_scatter"] = least["extra_scatter"]
    ds.attrs.update(burn=chains["burn"], thin=chains["thin"], profile=posterior.name,
                    profile_parameters=k, least_squares_basis=least["interval_basis"])
    return ds


def _pad(values, template):
    out = template.copy()
    out[:len(values)] = values
    return out


def predictive_bands(posterior, samples, grid, probability=0.95):
    """Credible band of the mean profile and posterior predictive band at `grid`.

    The predictive draw at height z is f(z; theta) + e, e ~ N(0, s_meas(z)^2 + sigma^2):
    s_meas^2 is the gates' variance (:meth:`ProfilePosterior.gate_variances`),
    interpolated between gates; sigma the scatter of the draw (0 without scatter).
    One predictive draw per posterior draw, from a generator seeded by the samples'
    size, so the band is reproducible.
    """
    flat = samples.reshape(-1, samples.shape[-1])
    step = max(1, len(flat) // BAND_DRAWS)
    flat = flat[::step]
    k = len(posterior.names)
    profiles = posterior.model(grid[None, :], *[flat[:, j, None] for j in range(k)])
    variance = posterior.gate_variances(flat[:, :k])
    order = np.argsort(posterior.data.heights)
    heights = posterior.data.heights[order]
    noise = np.array([np.interp(grid, heights, v[order]) for v in variance])
    if posterior.scatter:
        noise = noise + np.exp(2 * flat[:, k, None])
    rng = np.random.default_rng(len(flat))
    predictive = profiles + rng.standard_normal(profiles.shape) * np.sqrt(noise)
    tail = (1 - probability) / 2
    low, median, high = np.quantile(profiles, [tail, 0.5, 1 - tail], axis=0)
    p_low, p_high = np.quantile(predictive, [tail, 1 - tail], axis=0)
    return {"profile_median": median, "profile_low95": low, "profile_high95": high,
            "predictive_low95": p_low, "predictive_high95": p_high}


def true_parameters(scenario_settings, config):
    """The scenario's true profile parameters (power law only), else None."""
    wind = scenario_settings["wind"]
    if config.profile != "power_law":
        return None
    speed = wind["speed"] * (config.reference_height / wind["reference_height"]) ** wind["shear"]
    return {"reference_speed": speed, "shear": wind["shear"]}


def combine_fits(fits, truth=None):
    """Fits by name -> one Dataset with dimension ``fit``, with its CF attributes
    (:func:`annotate`).

    The fits' chains may have different lengths (each ensemble runs until it has
    converged): the shorter ones are padded with NaN at the end of ``step``, which
    becomes an index coordinate (0, 1, ...) so that the fits align on it.
    """
    steps = max(ds.sizes["step"] for ds in fits.values())
    padded = [ds.assign_coords(step=np.arange(ds.sizes["step"])).reindex(step=np.arange(steps))
              for ds in fits.values()]
    combined = xr.concat(padded, dim="fit", combine_attrs="drop_conflicts")
    combined = combined.assign_coords(fit=list(fits))
    combined["burn"] = ("fit", [ds.attrs["burn"] for ds in fits.values()])
    combined["thin"] = ("fit", [ds.attrs["thin"] for ds in fits.values()])
    combined.coords["least_squares_basis"] = (
        "fit", [INTERVAL_BASES[ds.attrs["least_squares_basis"]] for ds in fits.values()])
    combined.attrs.pop("least_squares_basis", None)
    if truth is not None:
        combined["true_value"] = ("parameter", [truth.get(p, np.nan)
                                                for p in combined["parameter"].values])
    notes = fit_notes(combined)
    if notes:
        combined.attrs["comment"] = " ".join(notes)
    return annotate(combined)


#: Two fits' 95 % intervals whose widths differ by less than this share are "the same"
#: to a reader: less than a line's width in the figure, the third digit of the table.
SAME_WIDTH = 0.1


def fit_notes(dataset):
    """Sentences a reader of the fits needs (list of str): where a free scatter's
    posterior reaches beyond the gates' own uncertainty, it dominates the likelihood, and
    fits that differ only in the gates' covariance (propagated, naive) come out the same.

    With n gates and k profile parameters the data hold n - k residual degrees of freedom
    for the scatter; with few of them (3 gates: 1) its posterior stays wide, up to values
    well above the measurement uncertainty, whatever the covariance.
    """
    if "ln_sigma" not in dataset["parameter"].values or "posterior_high95" not in dataset:
        return []
    notes = []
    k = int(dataset.attrs.get("profile_parameters", dataset.sizes["parameter"] - 1))
    n = int(np.isfinite(dataset["observed_speed"].isel(fit=0)).sum())
    reach = float(np.exp(dataset["posterior_high95"].sel(parameter="ln_sigma")).max())
    own = float(dataset["observed_speed_u"].max())
    if reach > own:
        notes.append(f"The free scatter (fit.scatter: true) reaches {reach:.3g} m s-1 at its "
                     f"97.5 % quantile, above the gates' own uncertainty ({own:.3g} m s-1): "
                     f"with {n} points and {k} parameters the data hold {n - k} residual "
                     "degree(s) of freedom and cannot bound it, so the posterior is wider "
                     "than the least-squares interval, which rests on the data's "
                     "covariance.")
    fits = list(dataset["fit"].values)
    if {"propagated", "naive"} <= set(fits):
        first = dataset["parameter"].values[0]
        width = (dataset["posterior_high95"] - dataset["posterior_low95"]).sel(parameter=first)
        a, b = float(width.sel(fit="propagated")), float(width.sel(fit="naive"))
        if abs(a - b) < SAME_WIDTH * max(a, b):
            why = "the free scatter, common to both, widens both alike" if reach > own else \
                "the gates' errors are nearly independent"
            notes.append(f"The propagated and naive posteriors are the same ({first}'s 95 % "
                         f"widths {a:.3g} and {b:.3g}): {why}; "
                         + ("set fit.scatter: false to compare the covariances alone."
                            if reach > own else "the covariance adds nothing here."))
    return notes


#: Marks a variable whose unit is its parameter's (``parameter_units``): one netCDF
#: variable holds parameters of different units, so it carries no ``units`` attribute.
PER_PARAMETER = None
#: name -> (units or PER_PARAMETER, long_name) of the variables of a fit Dataset.
FIT_METADATA = {
    "fit": ("", "fit: propagated (mean gate heights, full covariance), naive (nominal "
            "heights, independent errors) or data (a table)"),
    "parameter": ("", "parameter of the profile (ln_sigma: natural logarithm of the extra "
                  "scatter in m s-1)"),
    "parameter_units": ("", "units of the parameter"),
    "point": ("1", "index of the heights of the bands (grid_height)"),
    "gate": ("1", "index of the observations (range gates or table rows)"),
    "step": ("1", "step of the chains (before burn-in and thinning)"),
    "grid_height": ("m", "height of the bands"),
    "posterior_low95": (PER_PARAMETER, "posterior 2.5 % quantile (lower end of the 95 % "
                        "credible interval)"),
    "posterior_low68": (PER_PARAMETER, "posterior 16 % quantile (lower end of the 68 % "
                        "credible interval)"),
    "posterior_median": (PER_PARAMETER, "posterior median"),
    "posterior_high68": (PER_PARAMETER, "posterior 84 % quantile (upper end of the 68 % "
                         "credible interval)"),
    "posterior_high95": (PER_PARAMETER, "posterior 97.5 % quantile (upper end of the 95 % "
                         "credible interval)"),
    "least_squares_value": (PER_PARAMETER, "least-squares estimate (curve_fit)"),
    "least_squares_standard_error": (PER_PARAMETER, "standard error of the least-squares "
                                     "estimate (delta method)"),
    "least_squares_low95": (PER_PARAMETER, "lower end of the 95 % confidence interval "
                            "(delta method; on ln z0 for the roughness length)"),
    "least_squares_high95": (PER_PARAMETER, "upper end of the 95 % confidence interval "
                             "(delta method; on ln z0 for the roughness length)"),
    "least_squares_fit": ("m s-1", "least-squares profile at grid_height"),
    "least_squares_basis": ("", "what the least-squares intervals rest on (the speeds' "
                            "given covariance, an extra scatter estimated from the "
                            "residuals, or both) and their quantiles"),
    "least_squares_extra_scatter": ("m s-1", "extra scatter of the least-squares fit "
                                    "estimated from the residuals (Paule-Mandel; 0 where "
                                    "the given covariance explains them, missing where no "
                                    "covariance is given: then the whole scatter is "
                                    "estimated)"),
    "least_squares_confidence_low": ("m s-1", "lower end of the 95 % confidence band of "
                                     "the least-squares profile"),
    "least_squares_confidence_high": ("m s-1", "upper end of the 95 % confidence band of "
                                      "the least-squares profile"),
    "least_squares_prediction_low": ("m s-1", "lower end of the 68 % prediction band of a "
                                     "new measurement (least squares)"),
    "least_squares_prediction_high": ("m s-1", "upper end of the 68 % prediction band of "
                                      "a new measurement (least squares)"),
    "profile_median": ("m s-1", "posterior median of the profile at grid_height"),
    "profile_low95": ("m s-1", "lower end of the 95 % credible band of the profile"),
    "profile_high95": ("m s-1", "upper end of the 95 % credible band of the profile"),
    "predictive_low95": ("m s-1", "lower end of the 95 % posterior predictive band"),
    "predictive_high95": ("m s-1", "upper end of the 95 % posterior predictive band"),
    "observed_height": ("m", "height of the observations"),
    "observed_speed": ("m s-1", "observed wind speed"),
    "observed_speed_u": ("m s-1", "standard uncertainty of the observed wind speed"),
    "chain": (PER_PARAMETER, "positions of the walkers of each ensemble at each step "
              "(missing after the end of a shorter chain)"),
    "tau": ("1", "integrated autocorrelation time, in steps (largest over the ensembles)"),
    "rhat": ("1", "rank-normalised split R-hat across the ensembles"),
    "maximum_a_posteriori": (PER_PARAMETER, "maximum a posteriori (start of the chains)"),
    "burn": ("1", "steps dropped as burn-in (2 tau)"),
    "thin": ("1", "thinning of the chains, in steps (tau / 2)"),
    "true_value": (PER_PARAMETER, "true value of the scenario (missing where it has none)"),
}
#: Units of the profile parameters (and of the scatter's logarithm).
PARAMETER_UNITS = {**{name: unit for _, names, units, _ in PROFILES.values()
                      for name, unit in zip(names, units)}, "ln_sigma": "1"}


def annotate(dataset):
    """CF attributes of a fit Dataset, in place: units and long_name of every variable
    (:data:`FIT_METADATA`), the parameters' units as the auxiliary coordinate
    ``parameter_units``, and the global Conventions, title and history. Returns it."""
    dataset.coords["parameter_units"] = ("parameter", [PARAMETER_UNITS.get(str(name), "")
                                                       for name in dataset["parameter"].values])
    for name, variable in dataset.variables.items():
        base = name[:-len("_mcse")] if name.endswith("_mcse") else name
        units, long_name = FIT_METADATA.get(base, ("", name.replace("_", " ")))
        if name != base:
            long_name = f"Monte Carlo standard error of the {long_name} (Vehtari et al. 2021)"
        if units is PER_PARAMETER:
            long_name += ", in the units of parameter_units"
        elif units:
            variable.attrs["units"] = units
        variable.attrs["long_name"] = long_name
    profile = dataset.attrs.get("profile", "wind")
    dataset.attrs.update(Conventions="CF-1.10", title=f"uq fit: {profile} profile",
                         history=history(f"uq fit, {profile} profile"))
    return cf_encode(dataset)
