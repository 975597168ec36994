"""``uq golden CONFIG.yaml [-o DIR]``: analyse a verification campaign and write its
report, tables and figures into one folder.

The folder (default ``results/<name>/``) holds ``<name>.nc`` (every table),
``tables/per_bin.csv``, ``tables/sensitivity.csv``, ``tables/kpi.csv``, ``figures/*.png``,
``report.html`` (self-contained) and ``report.md``; for a synthetic campaign also
``data/`` (the generated records and their ``campaign.yaml``, the form a real campaign's
configuration takes). Everything is written into a fresh temporary folder beside it and
renamed into place at the end (:func:`uq.files.replace_folder`), so a failure leaves no
half-written folder, and a folder uq did not write is never replaced.
"""
import logging
import shutil
import sys
from pathlib import Path

import matplotlib

from uq.files import (check_folder_target, new_partial_folder, replace_folder, save_figure,
                      write_netcdf, write_text)
from .analysis import analyse
from .config import load_golden_config
from .findings import thin_bins
from .report import render_html, render_markdown, report_blocks

log = logging.getLogger(__name__)
PER_BIN = ("n_records", "sufficient", "reference_mean", "unit_mean", "unit_std",
           "deviation_mean", "deviation_std", "reference_calibration",
           "reference_classification", "statistical", "mean_deviation", "deviation",
           "calibration", "classification_per_variable", "classification_class_number",
           "classification", "total")
SENSITIVITY = ("slope", "slope_intercept", "slope_standard_error", "slope_p_value",
               "slope_r_squared", "slope_n_records", "slope_significant")
KPI = ("speed_slope", "speed_r_squared", "speed_n_records", "speed_slope_verdict",
       "speed_r_squared_verdict", "direction_slope", "direction_offset",
       "direction_r_squared", "direction_n_records", "direction_slope_verdict",
       "direction_offset_verdict", "direction_r_squared_verdict", "availability",
       "availability_verdict", "coverage_verdict", "class_number")


def run_golden(config_path, output=None, stream=None, overrides=None, model="compiled",
               kernels_missing=None):
    """Analyse the campaign of `config_path` and write the folder; returns its path.
    The summary goes to `stream` (default stdout), warnings to the log (stderr);
    `overrides` are ``uq golden --set`` (:func:`uq.golden.config.load_golden_config`).
    `model` and `kernels_missing`: the synthetic lidars' model, as :func:`uq.run`'s (the
    campaign is generated again from its seed where ``auto`` finds a kernel missing)."""
    stream = stream or sys.stdout
    config = load_golden_config(config_path, overrides)
    folder = Path(output) if output else Path("results") / config.name
    check_folder_target(folder)               # before any work
    partial = new_partial_folder(folder)
    try:
        if config.synthetic is not None:
            from uq.pipeline.runner import ModelChoice
            from .campaign import generate_campaign
            choice = ModelChoice(model, kernels_missing)
            config = load_golden_config(choice.evaluate(
                lambda compiled: generate_campaign(config, partial / "data", compiled)))
        ds = analyse(config)
        _write(ds, partial, config.name)
    except BaseException:
        shutil.rmtree(partial, ignore_errors=True)
        raise
    replace_folder(partial, folder, kind="golden")
    for key, height, bins in thin_bins(ds):
        log.warning("%s at %g m: required bins with too few records: %s", key, height,
                    ", ".join(f"{b:g} m/s ({n})" for b, n in bins))
    print(_summary(ds), file=stream)
    print(f"wrote {folder}/ (report.html, report.md, {config.name}.nc, tables/, figures/)",
          file=stream)
    return folder


def _write(ds, folder, name):
    from . import plots
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    (folder / "tables").mkdir(parents=True, exist_ok=True)
    (folder / "figures").mkdir(exist_ok=True)
    write_netcdf(ds, folder / f"{name}.nc")
    for table, frame in golden_tables(ds).items():
        write_text(folder / "tables" / f"{table}.csv",
                   with_units(frame, ds).to_csv(float_format="%.6g"))
    height = float(ds["height"].max())
    figures = {}
    drawings = {"scatter": (plots.plot_scatter, "Unit against reference with the KPI "
                            "regressions"),
                "deviation": (plots.plot_deviation_against_environment, "Percentage "
                              "deviation against the environmental variables"),
                "uncertainty_terms": (plots.plot_uncertainty_terms, "Calibration-"
                                      "uncertainty terms per bin (seed Fig. 3)")}
    if not ds.sizes.get("variable"):            # no environmental variable to plot against
        del drawings["deviation"]
    if "ti_mean_bias" in ds:
        drawings["turbulence"] = (plots.plot_turbulence, "Mean turbulence intensity per bin: "
                                  "measured and predicted by uq's spectral path")
    for stem, (draw, caption) in drawings.items():
        fig = draw(ds, height)
        path = folder / "figures" / f"{stem}.png"
        save_figure(fig, path, dpi=90)
        plt.close(fig)
        figures[f"{caption}, {height:g} m"] = path
    blocks = report_blocks(ds, figures, height)
    write_text(folder / "report.md", render_markdown(blocks))
    write_text(folder / "report.html", render_html(blocks))


def golden_tables(ds):
    """The Dataset's tables as pandas DataFrames (long format, one row per index)."""
    tables = {"per_bin": ds[list(PER_BIN)].to_dataframe(),
            "sensitivity": ds[list(SENSITIVITY)].to_dataframe(),
            "kpi": ds[list(KPI)].to_dataframe()}
    if "ti_mean_bias" in ds:
        tables["turbulence"] = ds[[v for v in ds.data_vars if v.startswith("ti_")
                                   and "bin" in ds[v].dims]].to_dataframe()
    return tables


#: Columns whose unit depends on the row's environmental variable (no one CF unit).
PER_VARIABLE_UNITS = {"slope": "percent per unit of the variable",
                      "slope_standard_error": "percent per unit of the variable"}


def with_units(frame, ds):
    """The table with each column's and index's unit in its header (``bin [m s-1]``),
    as the Dataset's ``units`` give them (UDUNITS; a variable without units, a name or
    a verdict, keeps its bare name)."""
    def named(name):
        units = ds[name].attrs.get("units") if name in ds.variables else None
        if name in PER_VARIABLE_UNITS:
            units = PER_VARIABLE_UNITS[name]
        return f"{name} [{units}]" if units else name
    frame = frame.rename(columns=named)
    frame.index = frame.index.set_names([named(n) for n in frame.index.names])
    return frame


def _summary(ds):
    lines = [f"{'comparison':<12}{'height':>8}{'speed slope':>13}{'R2':>9}{'dir offset':>12}"
             f"  verdicts (speed slope, R2, dir slope, offset, R2, availability, coverage)"]
    for k in ds["comparison"].values:
        for h in ds["height"].values:
            c = ds.sel(comparison=k, height=h)
            verdicts = ", ".join(str(c[v].values) for v in (
                "speed_slope_verdict", "speed_r_squared_verdict", "direction_slope_verdict",
                "direction_offset_verdict", "direction_r_squared_verdict",
                "availability_verdict", "coverage_verdict"))
            lines.append(f"{k:<12}{h:>8g}{float(c['speed_slope']):>13.4f}"
                         f"{float(c['speed_r_squared']):>9.4f}"
                         f"{float(c['direction_offset']):>12.2f}  {verdicts}")
    return "\n".join(lines)
