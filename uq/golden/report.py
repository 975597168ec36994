"""The golden-lidar report, as Markdown and as self-contained HTML (figures embedded),
from a finished Dataset and its figure files. No numbers are computed here that
:mod:`uq.golden.findings` or the Dataset do not hold.

The report is a list of blocks (heading, paragraph, table, figure) rendered twice.
"""
import base64
import html

import numpy as np

from uq.files import SIGNATURE
from .findings import chain_roles, reference_comparison, thin_bins
from .plots import p_value_text

STYLE = """body{font-family:system-ui,sans-serif;max-width:1150px;margin:2em auto;color:#222}
table{border-collapse:collapse;margin:.6em 0}td,th{border:1px solid #bbb;padding:3px 7px;
font-size:88%;text-align:right}th{background:#eee}img{max-width:100%}"""
KPI_COLUMNS = (("speed_slope", "speed slope", "{:.4f}"), ("speed_r_squared", "speed R²", "{:.4f}"),
               ("direction_slope", "dir. slope", "{:.4f}"),
               ("direction_offset", "dir. offset [deg]", "{:.2f}"),
               ("direction_r_squared", "dir. R²", "{:.4f}"),
               ("availability", "availability", "{:.3f}"))
VERDICTS = ("speed_slope_verdict", "speed_r_squared_verdict", "direction_slope_verdict",
            "direction_offset_verdict", "direction_r_squared_verdict", "availability_verdict",
            "coverage_verdict")


def report_blocks(ds, figures, height):
    """The report's blocks; `figures` maps a caption to a PNG path."""
    blocks = [("h1", f"Golden-lidar verification: {ds.attrs['name']}"),
              ("p", ds.attrs.get("description", "")), ("h2", "Campaign"),
              ("table", ["comparison", "records with both speeds", "timestamps only in the unit",
                "timestamps only in the reference"],
               _campaign_rows(ds))]
    blocks += _thin_blocks(ds)
    blocks += _finding_blocks(ds, height)
    blocks += [("h2", "KPIs (Carbon Trust OWA roadmap, IEA Wind RP 18)"),
               ("table", ["comparison", "height [m]"] + [c[1] for c in KPI_COLUMNS],
                _kpi_rows(ds)),
               ("table", ["comparison", "height [m]"] + [v.replace("_verdict", "")
                                                          for v in VERDICTS],
                _verdict_rows(ds)),
               ("h2", "Sensitivity to environmental variables"),
               ("p", "OLS slope of the percentage deviation against each variable, records "
                f"with reference speed in the bins {ds.attrs['required_low']:g}-"
                f"{ds.attrs['required_high']:g} m/s; significant when p < "
                f"{ds.attrs['significance']:g} (two-sided t-test). Only significant slopes "
                "enter Eq. 1."),
               ("table", ["comparison", "height [m]", "variable", "slope [%/unit]",
                          "std. error", "p", "R²", "records", "significant"],
                _sensitivity_rows(ds)),
               ]
    blocks += _classification_blocks(ds)
    blocks += _smc_blocks(ds, height)
    blocks += [("h2", f"Calibration uncertainty per bin at {height:g} m (Eqs. 2-3)")]
    blocks += _calibration_tables(ds, height)
    blocks += _turbulence_blocks(ds, height)
    blocks += [("h2", "Figures")] + [("figure", path, caption)
                                     for caption, path in figures.items()]
    return blocks


def _classification_blocks(ds):
    """The class number of each comparison and height (IEC 61400-12-1 Annex L: the
    largest sum of the significant slopes' effects over the variables' ranges) and the
    classification uncertainty each route gives over the required bins."""
    required = np.flatnonzero(ds["required"].values)
    rows = []
    for k in ds["comparison"].values:
        for h in ds["height"].values:
            c = ds.sel(comparison=k, height=h).isel(bin=required)
            rows.append([str(k), f"{h:g}", _cell(float(c["class_number"])),
                         _span(c["classification_class_number"].values),
                         _span(c["classification_per_variable"].values),
                         _span(c["classification"].values)])
    return [("h2", "Classification (IEC 61400-12-1 Annex L)"),
            ("p", f"Route used: {ds.attrs.get('route', '')}. The class number [%] comes from "
             "the significant sensitivity slopes over the classification ranges; its "
             "uncertainty is class number / sqrt(3) % of the bin's speed. The per-variable "
             "route (Eq. 1) uses the SMC's environmental means against the verification's. "
             "Each column gives the smallest and largest value over the required bins "
             "[m/s]."),
            ("table", ["comparison", "height [m]", "class number [%]",
                       "u_class, class-number route [m/s]",
                       "u_class, per-variable route (SMC) [m/s]", "u_class used [m/s]"],
             rows)]


def _smc_blocks(ds, height):
    """The specific measurement campaign the configuration names: its records per bin
    and its environmental means against the verification campaign's, at `height`."""
    if "smc_n_records" not in ds:
        return [("h2", "Specific measurement campaign (SMC)"),
                ("p", "The configuration names no SMC (golden.smc): the per-variable route "
                 "has no campaign to apply the slopes to.")]
    required = np.flatnonzero(ds["required"].values)
    c = ds.sel(height=height).isel(comparison=0, bin=required)
    first = str(ds["comparison"].values[0])
    records = int(np.nansum(ds["smc_n_records"].sel(height=height).isel(comparison=0)))
    rows = [[f"{b:g}", str(int(c["smc_n_records"].values[i]))]
            + [_cell(c["verification_mean"].sel(variable=v).values[i]) + " / "
               + _cell(c["smc_mean"].sel(variable=v).values[i])
               for v in ds["variable"].values]
            for i, b in enumerate(c["bin"].values)]
    return [("h2", f"Specific measurement campaign (SMC) at {height:g} m"),
            ("p", f"{records} SMC records at {height:g} m. Per required bin: the SMC's "
             "records and each environmental variable's mean in the verification campaign "
             f"(as the reference of {first} measured it) / in the SMC, in the variable's "
             "own units; the per-variable classification (Eq. 1) applies each comparison's "
             "sensitivity slopes to that difference."),
            ("table", ["bin [m/s]", "SMC records"] + [f"{v}: verification / SMC"
                                                      for v in ds["variable"].values], rows)]


def _span(values):
    values = np.asarray(values, float)
    if not np.isfinite(values).any():
        return ""
    low, high = np.nanmin(values), np.nanmax(values)
    return _cell(low) if np.isclose(low, high) else f"{_cell(low)} to {_cell(high)}"


def _campaign_rows(ds):
    rows = []
    for k in ds["comparison"].values:
        c = ds.sel(comparison=k)
        both = np.isfinite(c["paired_unit_speed"]) & np.isfinite(c["paired_reference_speed"])
        rows.append([str(k), int(both.any("height").sum()), int(c["records_only_unit"].max()),
                     int(c["records_only_reference"].max())])
    return rows


def _thin_blocks(ds):
    thin = thin_bins(ds)
    if not thin:
        return [("p", f"Every required bin holds at least {ds.attrs['minimum_records']} "
                      "records.")]
    text = "; ".join(f"{k} at {h:g} m: " + ", ".join(f"{b:g} m/s ({n})" for b, n in bins)
                     for k, h, bins in thin)
    return [("p", f"Bins with fewer than {ds.attrs['minimum_records']} records (flagged, "
                  f"their terms are not reliable): {text}.")]


def _finding_blocks(ds, height):
    roles = chain_roles(ds)
    if roles is None:
        return []
    unit, golden, mast = roles
    rows = [r for r in reference_comparison(ds, unit, golden, mast) if r["height"] == height]
    blocks = [("h2", f"Golden lidar: {unit} against {golden} and against {mast}")]
    for r in rows:
        fw = "IEC 61400-12-1" if r["framework"] == "iec" else "LUSR"
        lower = r["calibration_golden"] < r["calibration_mast"]
        blocks.append(("p", (
            f"**{fw}: the golden lidar {'lowers' if lower else 'does not lower'} {unit}'s "
            f"calibration uncertainty** at {height:g} m: {r['calibration_golden']:.4f} m/s "
            f"with {golden} as reference against {r['calibration_mast']:.4f} m/s with the "
            f"{mast} (mean over {r['bins']} bins; lower in "
            f"{r['bins_calibration_smaller']} of them).")))
        blocks.append(("p", (
            f"{fw}, {height:g} m, {r['bins']} bins: the deviation term of {unit} is "
            f"{r['deviation_golden']:.4f} m/s with {golden} as reference and "
            f"{r['deviation_mast']:.4f} m/s with the {mast} (mean over the bins), smaller in "
            f"{r['bins_deviation_smaller']} of {r['bins']} bins. Calibration uncertainty "
            f"{r['calibration_golden']:.4f} against {r['calibration_mast']:.4f} m/s "
            f"(smaller in {r['bins_calibration_smaller']} bins). The chain keeps both "
            f"classification terms: u_class,{golden} = {r['golden_classification']:.4f} m/s "
            f"inside u_cal, and u_class,{unit} = {r['unit_classification']:.4f} m/s (from "
            f"the same-type slopes; {r['unit_classification_mast']:.4f} m/s from the "
            f"slopes against the {mast}) in the total.")))
    return blocks


def _kpi_rows(ds):
    return [[str(k), f"{h:g}"] + [fmt.format(float(ds[v].sel(comparison=k, height=h)))
                                  for v, _, fmt in KPI_COLUMNS]
            for k in ds["comparison"].values for h in ds["height"].values]


def _verdict_rows(ds):
    return [[str(k), f"{h:g}"] + [str(ds[v].sel(comparison=k, height=h).values)
                                  for v in VERDICTS]
            for k in ds["comparison"].values for h in ds["height"].values]


def _sensitivity_rows(ds):
    rows = []
    for k in ds["comparison"].values:
        for h in ds["height"].values:
            for v in ds["variable"].values:
                s = ds.sel(comparison=k, height=h, variable=v)
                rows.append([str(k), f"{h:g}", str(v), f"{float(s['slope']):.4g}",
                             f"{float(s['slope_standard_error']):.2g}",
                             p_value_text(float(s['slope_p_value'])).removeprefix("p = "),
                             f"{float(s['slope_r_squared']):.3f}",
                             int(s["slope_n_records"]),
                             "yes" if bool(s["slope_significant"]) else "no"])
    return rows


CALIBRATION_COLUMNS = (("n_records", "N"), ("reference_calibration", "u_cal,ref"),
                       ("reference_classification", "u_class,ref"),
                       ("statistical", "sigma/sqrt N"), ("mean_deviation", "|dv|"),
                       ("deviation", "u_dev"), ("calibration", "u_cal"),
                       ("classification", "u_class,unit"), ("total", "total"))


def _calibration_tables(ds, height):
    blocks = []
    bins = np.flatnonzero(ds["required"].values)
    for k in ds["comparison"].values:
        for fw in ds["framework"].values:
            c = ds.sel(comparison=k, height=height, framework=fw).isel(bin=bins)
            rows = [[f"{b:g}"] + [_cell(c[name].values[i]) for name, _ in CALIBRATION_COLUMNS]
                    + ["" if c["sufficient"].values[i] else "too few"]
                    for i, b in enumerate(c["bin"].values)]
            blocks += [("h3", f"{k}, {fw.upper()} [m/s]"),
                       ("table", ["bin [m/s]"] + [h for _, h in CALIBRATION_COLUMNS] + ["flag"],
                        rows)]
    return blocks


TI_COLUMNS = (("ti_n_records", "N"), ("ti_reference_mean", "TI ref [%]"),
              ("ti_unit_mean", "TI unit [%]"), ("ti_predicted_mean", "TI predicted [%]"),
              ("ti_mean_bias", "MBE [pp]"), ("ti_relative_error", "rel. error"),
              ("ti_rmse", "RMSE [pp]"), ("ti_representative_error", "rep. TI error [pp]"))
TI_VERDICTS = ("ti_mean_bias_verdict", "ti_relative_error_verdict", "ti_rmse_verdict",
               "ti_representative_error_verdict")


def _turbulence_blocks(ds, height):
    """Per-bin TI KPIs at `height` (:mod:`uq.golden.turbulence`), when the files hold a TI."""
    if "ti_mean_bias" not in ds:
        return [("h2", "Turbulence intensity"),
                ("p", "No TI: the instruments carry no TI variable (golden.kpi.turbulence."
                 "variable), so no TI KPI is computed.")]
    bins = np.flatnonzero(ds["required"].values)
    blocks = [("h2", f"Turbulence intensity per bin at {height:g} m"),
              ("p", "TI in percent; MBE = mean(unit - reference), relative error = MBE / "
               "mean reference TI, RMSE, and the representative TI (mean + 1.28 sd) of the "
               "unit minus the reference's (Carbon Trust OWA roadmap v3.0 metrics). "
               "Verdicts against golden.kpi.turbulence.bands; without a band a KPI is "
               "informational (no published numeric band). 'TI predicted' is the apparent "
               "TI the unit's lidar reads of the reference's TI by uq's spectral path (probe "
               "volume, beam separation, scan timing; fixed lidar, IEC Mann field), blank "
               "when the unit names no scenario.")]
    blocks += _campaign_ti_blocks(ds)
    for k in ds["comparison"].values:
        c = ds.sel(comparison=k, height=height).isel(bin=bins)
        ratio = float(c["ti_predicted_ratio"])
        rows = [[f"{b:g}"] + [_cell(c[name].values[i]) for name, _ in TI_COLUMNS]
                + [", ".join(sorted({str(c[v].values[i]) for v in TI_VERDICTS}))]
                for i, b in enumerate(c["bin"].values) if c["ti_n_records"].values[i] > 0]
        note = (f"predicted u-variance ratio {ratio:.3f} (TI x {np.sqrt(ratio):.3f})"
                if np.isfinite(ratio) else "no scenario: no prediction")
        if bool(c.get("ti_unit_copies_reference", False)):
            note += (f"; {c['unit'].values}'s TI is {c['reference'].values}'s, record for "
                     "record (a synthetic campaign's lidars carry the mast's TI): not a "
                     "measurement, so no TI error is stated")
        blocks += [("h3", f"{k}: {note}"),
                   ("table", ["bin [m/s]"] + [h for _, h in TI_COLUMNS] + ["verdicts"], rows)]
    return blocks


def _campaign_ti_blocks(ds):
    """A paragraph naming the instruments whose TI is a ``uq campaign``'s corrected TI."""
    named = [item.split(":") for item in ds.attrs.get("campaign_instruments", "").split()]
    if not named:
        return []
    text = "; ".join(f"{name} (motion: {motion})" for name, motion in named)
    return [("p", f"The TI of {text} is uq campaign's: each record's TI corrected for the "
                  "platform's motion and the lidar's filtering (its results file's "
                  "turbulence_intensity_corrected), so the KPIs above use the corrected TI.")]


def _cell(value):
    if np.issubdtype(np.asarray(value).dtype, np.integer):
        return str(int(value))
    return "" if not np.isfinite(value) else f"{value:.4f}"


def render_markdown(blocks):
    """Markdown text of the blocks (figures as links to their files)."""
    lines = []
    for block in blocks:
        kind = block[0]
        if kind in ("h1", "h2", "h3"):
            lines += ["#" * int(kind[1]) + " " + block[1], ""]
        elif kind == "p":
            lines += [block[1], ""] if block[1] else []
        elif kind == "table":
            lines += ["| " + " | ".join(block[1]) + " |",
                      "|" + "---|" * len(block[1])]
            lines += ["| " + " | ".join(str(c) for c in row) + " |" for row in block[2]]
            lines.append("")
        elif kind == "figure":
            lines += [f"![{block[2]}]({block[1].parent.name}/{block[1].name})", "",
                      f"*{block[2]}*", ""]
    return "\n".join(lines)


def render_html(blocks):
    """One self-contained HTML page (figures embedded as base64 PNG)."""
    title = next(b[1] for b in blocks if b[0] == "h1")
    parts = [f"<!DOCTYPE html><!-- {SIGNATURE} --><html><head><meta charset='utf-8'>"
             f"<title>{_e(title)}</title>"
             f"<style>{STYLE}</style></head><body>"]
    for block in blocks:
        kind = block[0]
        if kind in ("h1", "h2", "h3"):
            parts.append(f"<{kind}>{_e(block[1])}</{kind}>")
        elif kind == "p" and block[1]:
            parts.append(f"<p>{_strong(_e(block[1]))}</p>")
        elif kind == "table":
            head = "".join(f"<th>{_e(h)}</th>" for h in block[1])
            body = "".join("<tr>" + "".join(f"<td>{_e(c)}</td>" for c in row) + "</tr>"
                           for row in block[2])
            parts.append(f"<table><tr>{head}</tr>{body}</table>")
        elif kind == "figure":
            data = base64.b64encode(block[1].read_bytes()).decode()
            parts.append(f"<figure><img src='data:image/png;base64,{data}' alt='{_e(block[2])}'>"
                         f"<figcaption>{_e(block[2])}</figcaption></figure>")
    parts.append("</body></html>")
    return "\n".join(parts)


def _strong(text):
    """Markdown's ``**bold**`` as HTML's ``<b>bold</b>`` (in escaped text)."""
    parts = text.split("**")
    return "".join(f"<b>{p}</b>" if k % 2 else p for k, p in enumerate(parts))


def _e(text):
    return html.escape(str(text))
