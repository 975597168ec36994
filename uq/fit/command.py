"""``uq fit``: read the input and the fit settings, fit, write netCDF and figures.

I/O and orchestration only; the fit is :mod:`uq.fit.fitting`, the figures
:mod:`uq.fit.plots`.
"""
import logging
from pathlib import Path

import numpy as np
import yaml

from uq.constants import MAX_FIT_TABLE_BYTES
from uq.errors import DataFileError, ScenarioError
from uq.fit.bayesfit import NotConverged
from uq.fit.fitting import (MAX_FIT_POINTS, combine_fits, fit_notes, fit_profile,
                            profile_from_results, profile_from_table, true_parameters)
from uq.files import check_target, save_figure, write_netcdf
from uq.pipeline.inputfile import read_csv
from uq.pipeline.metadata import history
from uq.pipeline.results import open_results
from uq.pipeline.scenario import apply_overrides, load_fit_settings, read_yaml

#: What a fit configuration (-c) is, in messages about the file.
FIT_CONFIG_KIND = "a YAML fit configuration"
#: What a fit table is, in messages about the file.
FIT_TABLE_KIND = "a CSV table of heights and wind speeds"

EXIT_OK, EXIT_FAILURE = 0, 1
log = logging.getLogger(__name__)


def run_fit(input_path, config_path=None, output=None, overrides=None, quiet=False):
    """Fit `input_path` (.nc results or .csv table); returns the exit status. The table
    of results goes to stdout (not with `quiet`), diagnostics to the log."""
    path = Path(input_path)
    if path.suffix not in (".nc", ".csv"):
        raise ScenarioError(str(path), "", "allowed: results of uq run (.nc) or a CSV table "
                            "(.csv)")
    output = Path(output) if output else path.with_name(f"{path.stem}_fit.nc")
    if output.suffix != ".nc":
        raise ScenarioError("-o", str(output), "the output file must end in .nc")
    check_target(output)                           # before the fit (minutes)
    results = open_results(path) if path.suffix == ".nc" else None
    scenario = None if results is None else _scenario_of(results, path)
    config = fit_settings(config_path, scenario, overrides or {})
    try:
        dataset = _fit_input(path, results, scenario, config)
    except NotConverged as error:
        log.error("fit failed: %s", error)
        return EXIT_FAILURE
    write_netcdf(dataset, output)
    from uq.fit.plots import plot_corner, plot_profile_fit
    figures = [output.with_name(f"{output.stem}_profile.png"),
               output.with_name(f"{output.stem}_corner.png")]
    save_figure(plot_profile_fit(dataset), figures[0], dpi=120, bbox_inches="tight")
    save_figure(plot_corner(dataset), figures[1], dpi=100, bbox_inches="tight")
    if not quiet:
        print(fit_table(dataset))
        print(f"wrote {output}, {figures[0].name}, {figures[1].name}")
    return EXIT_OK


def _scenario_of(results, path):
    """The scenario mapping recorded in a results file."""
    try:
        scenario = yaml.safe_load(results.attrs["scenario"]) or {}
    except yaml.YAMLError:
        scenario = None
    if not isinstance(scenario, dict):
        raise DataFileError(str(path), "scenario", "the recorded scenario attribute is not "
                            "a YAML mapping; allowed: results written by uq run")
    return scenario


def fit_settings(config_path, scenario, overrides):
    """FitConfig from -c FILE's fit section, else the results' scenario's (a mapping),
    then --set. The file is read like a scenario (bounded, strict YAML); an error in a
    value given with --set names --set."""
    source, raw = "defaults", {}
    if config_path:
        source = str(config_path)
        document = read_yaml(config_path, kind=FIT_CONFIG_KIND)
        if not isinstance(document, dict) or "fit" not in document:
            raise ScenarioError(source, "fit", "no 'fit' section; allowed: a YAML mapping "
                                "with a top-level 'fit' key")
        raw = document["fit"] or {}
    elif scenario is not None:
        source = "scenario of the results"
        raw = scenario.get("fit") or {}
    if not isinstance(raw, dict):
        raise ScenarioError(source, "fit", "allowed: a mapping of fit settings")
    raw = {"fit": dict(raw)}
    for key in overrides:
        if not key.startswith("fit."):
            raise ScenarioError("--set", key, "allowed: fit.<key>=<value>")
    apply_overrides(raw, overrides, source)
    try:
        return load_fit_settings(raw["fit"], source)
    except ScenarioError as error:
        if any(_related(error.key, key) for key in overrides):
            raise ScenarioError("--set", error.key, error.problem) from None
        raise


def _related(key, given):
    """Does the checked `key` lie at or below (or above) the dotted key `given`?"""
    return any(a == b or a.startswith(b + ".") or a.startswith(b + "[")
               for a, b in ((key, given), (given, key)))


def _fit_input(path, results, scenario, config):
    if results is None:
        table = read_csv(path, MAX_FIT_TABLE_BYTES, MAX_FIT_POINTS, FIT_TABLE_KIND,
                         DataFileError)
        data, dropped = profile_from_table(table, config.columns, source=str(path))
        dataset = combine_fits({"data": fit_profile(data, config)})
        dataset.attrs["rows_dropped_not_finite"] = dropped
        if dropped:
            log.warning("%d row(s) with a missing value not fitted", dropped)
    else:
        fits = {kind: fit_profile(profile_from_results(results, kind, str(path)), config)
                for kind in ("propagated", "naive")}
        dataset = combine_fits(fits, true_parameters(scenario, config))
    dataset.attrs.update(source=str(path), fit_settings=yaml.safe_dump(config.to_dict()),
                         history=history(f"uq fit {path}"))
    return dataset


def fit_table(dataset):
    """Posterior median [95 % interval] and the chain's Monte Carlo standard error of
    the interval's ends (the larger), beside least squares, per fit and parameter."""
    lines = [f"{'fit':<12}{'parameter':<18}{'median':>10}{'95 % credible':>24}"
             f"{'MC error':>10}{'least squares':>15}{'95 % confidence':>24}{'true':>9}"]
    for fit in dataset["fit"].values:
        row = dataset.sel(fit=fit)
        for name in dataset["parameter"].values:
            p = row.sel(parameter=name)
            truth = float(dataset["true_value"].sel(parameter=name)) \
                if "true_value" in dataset else np.nan
            lines.append(
                f"{fit:<12}{name:<18}{float(p.posterior_median):>10.4g}"
                f"{_interval(p.posterior_low95, p.posterior_high95):>24}"
                f"{_chain_error(p):>10.2g}"
                f"{float(p.least_squares_value):>15.4g}"
                f"{_interval(p.least_squares_low95, p.least_squares_high95):>24}"
                f"{truth:>9.4g}")
    if "least_squares_basis" in dataset.coords:
        for fit in dataset["fit"].values:
            basis = str(dataset["least_squares_basis"].sel(fit=fit).values)
            extra = float(dataset["least_squares_extra_scatter"].sel(fit=fit)) \
                if "least_squares_extra_scatter" in dataset else np.nan
            scatter = f" (extra scatter {extra:.3g} m s-1)" if extra > 0 else ""
            lines.append(f"least squares, {fit}: {basis}{scatter}")
    for note in fit_notes(dataset):
        lines.append(f"note: {note}")
    return "\n".join(lines)


def _chain_error(row):
    """The larger Monte Carlo standard error of the two ends of the 95 % interval."""
    if "posterior_low95_mcse" not in row:
        return np.nan
    return max(float(row.posterior_low95_mcse), float(row.posterior_high95_mcse))


def _interval(low, high):
    return f"[{float(low):.4g}, {float(high):.4g}]"
