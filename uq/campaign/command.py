"""``uq campaign CONFIG.yaml [-o FOLDER]``: correct a campaign's records and write its
report, tables and figures into one folder.

The folder (default ``results/<name>/``) holds ``<name>.nc`` (every record and table,
CF), ``tables/records.csv`` (one row per period and height), ``tables/bins.csv`` (one
row per bin and height), ``tables/heights.csv`` (per height: coverage, speed KPIs, with
a reference), ``figures/*.png``, ``report.html`` (self-contained) and ``report.md``.
Everything is written into a fresh temporary folder beside it and renamed into place at
the end (:func:`uq.files.replace_folder`): a failure leaves no half-written folder, and
a folder uq did not write is never replaced.
"""
import shutil
import sys
from pathlib import Path

import numpy as np

from uq.files import (check_folder_target, new_partial_folder, replace_folder, save_figure,
                      write_netcdf, write_text)
from .analysis import analyse
from .config import load_campaign_config


def run_campaign(config_path, output=None, stream=None, client=None, kernels_missing=None):
    """Correct the campaign of `config_path` and write the folder; returns its path.
    `client`: a dask client (the tables' nodes and the records' chunks on its workers);
    `kernels_missing`: as :func:`uq.campaign.analysis.analyse`'s."""
    stream = stream or sys.stdout
    config = load_campaign_config(config_path)
    folder = Path(output) if output else Path("results") / config.name
    check_folder_target(folder)                 # before any work
    ds = analyse(config, client, kernels_missing)
    partial = new_partial_folder(folder)
    try:
        write_folder(ds, partial, config)
    except BaseException:
        shutil.rmtree(partial, ignore_errors=True)
        raise
    replace_folder(partial, folder, kind="campaign")
    print(summary(ds), file=stream)
    print(f"wrote {folder}/ (report.html, report.md, {config.name}.nc, tables/, figures/)",
          file=stream)
    return folder


def write_folder(ds, folder, config):
    """The netCDF file, the tables, the figures and the report of `ds` into `folder`."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from . import figures, outputs
    from .report import report_blocks
    from uq.golden.report import render_html, render_markdown
    outputs.annotate(ds, f"uq campaign, campaign {config.name}")
    (folder / "tables").mkdir(parents=True, exist_ok=True)
    (folder / "figures").mkdir(exist_ok=True)
    write_netcdf(ds, folder / f"{config.name}.nc")
    tables = {"records": outputs.records_table(ds), "bins": outputs.bins_table(ds),
              "heights": outputs.heights_table(ds)}
    for name, frame in tables.items():
        if frame is not None:
            write_text(folder / "tables" / f"{name}.csv", frame.to_csv(index=False,
                                                                       float_format="%.6g"))
    drawings = [("bins", figures.plot_bins, "Mean and 90 % quantile of the measured and "
                 "corrected TI per wind-speed bin")]
    if "turbulence_intensity_reference" in ds:
        drawings += [("scatter", figures.plot_scatter, "Measured and corrected TI against "
                      "the reference's, the corrected with its 95 % interval"),
                     ("bin_errors", figures.plot_bin_errors, "Errors of the measured and "
                      "corrected TI per bin against the reference: mean bias (the corrected "
                      "with 2u, the measured's as predicted) and RMSE")]
    counts = ds["turbulence_intensity_corrected"].notnull().sum("time").values
    fullest = float(ds["height"].values[int(np.argmax(counts))])      # the most corrected
    drawings.append(("time_series", lambda d: figures.plot_time_series(d, fullest),
                     f"Turbulence intensity at {fullest:g} m (the height with the most "
                     "corrected records) over the campaign (the reference at the records "
                     "corrected)"))
    shown = {}
    for stem, draw, caption in drawings:
        fig = draw(ds)
        path = folder / "figures" / f"{stem}.png"
        save_figure(fig, path, dpi=90)
        plt.close(fig)
        shown[caption] = path
    blocks = report_blocks(ds, shown, config.lidar.name)
    write_text(folder / "report.md", render_markdown(blocks))
    write_text(folder / "report.html", render_html(blocks))


def summary(ds):
    """A few lines for the terminal: per height the corrected records, mean TIs and, with
    a reference, the intervals' coverage."""
    lines = [f"{'height':>8}{'records':>9}{'TI meas.':>10}{'TI corr.':>10}{'motion TI':>11}"
             + ("   coverage (p)" if "coverage_share" in ds else "")]
    for h in ds["height"].values:
        d = ds.sel(height=h)
        keep = d["turbulence_intensity_corrected"].notnull()
        mean = lambda name: float(d[name].where(keep).mean()) * 100.0  # noqa: E731
        line = (f"{h:>8g}{int(keep.sum()):>9d}{mean('turbulence_intensity_measured'):>9.2f}%"
                f"{mean('turbulence_intensity_corrected'):>9.2f}%"
                f"{mean('motion_turbulence_intensity'):>10.2f}%")
        if "coverage_share" in ds:
            line += (f"   {100 * float(d['coverage_share']):.1f} % "
                     f"({float(d['coverage_p_value']):.2f})")
        lines.append(line)
    a = ds.attrs
    lines.append(f"{a['n_corrected']} of {a['n_record_heights']} record-heights corrected "
                 f"({a['n_periods_missing']} periods missing); fast path's TI error "
                 f"{100 * a['surrogate_ti_error']:.2f} %; {a['runtime_s']:.1f} s")
    return "\n".join(lines)
