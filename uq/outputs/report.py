"""A self-contained HTML report of one run: scenario, figures, tables, planning answers.

Figures are embedded as base64 PNG, so the single file can be mailed or archived. The
numbers come from :mod:`uq.outputs.planning`; the figures from :mod:`uq.outputs.figures`. Written
atomically (:func:`uq.files.write_text`).
"""
import base64
import html
import io

import matplotlib.pyplot as plt
import numpy as np

from uq.files import SIGNATURE, write_text
from uq.outputs import planning
from uq.outputs.figures import figure_plan

QUANTITY_UNITS = {"wind_speed": "m/s", "wind_direction": "deg", "vertical_wind": "m/s"}
STYLE = """body{font-family:system-ui,sans-serif;max-width:1100px;margin:2em auto;color:#222}
table{border-collapse:collapse;margin:.6em 0}td,th{border:1px solid #bbb;padding:3px 8px;
font-size:90%;text-align:left}th{background:#eee}pre{background:#f6f6f6;padding:.8em;
overflow-x:auto;font-size:85%}img{max-width:100%}.no{color:#a00}.yes{color:#070}"""


def write_report(dataset, path, source="", targets=planning.DEFAULT_TARGETS):
    """Write the report of `dataset` to `path` (HTML); returns the path."""
    page = render_report(dataset, source=source, targets=targets)
    return write_text(path, page)


def render_report(dataset, source="", targets=planning.DEFAULT_TARGETS):
    """The report as one HTML string."""
    name = dataset.attrs.get("title", "uq results")
    parts = [f"<!DOCTYPE html><!-- {SIGNATURE} --><html><head><meta charset='utf-8'>"
             f"<title>{_e(name)}</title>"
             f"<style>{STYLE}</style></head><body><h1>{_e(name)}</h1>",
             _run_table(dataset, source), _answers(dataset, targets), _findings(dataset),
             _summary_tables(dataset), _figures(dataset),
             "<h2>Scenario as run</h2><pre>", _e(dataset.attrs.get("scenario", "")), "</pre>",
             "</body></html>"]
    return "\n".join(parts)


def _e(text):
    return html.escape(str(text))


def _table(header, rows):
    head = "".join(f"<th>{_e(h)}</th>" for h in header)
    body = "".join("<tr>" + "".join(f"<td>{cell}</td>" for cell in row) + "</tr>" for row in rows)
    return f"<table><tr>{head}</tr>{body}</table>"


def _run_table(dataset, source):
    keys = ("uq_version", "sampling_method", "n_samples", "seed", "scenes", "correction",
            "ins_correlation", "runtime_s")
    rows = [(_e(k), _e(f"{dataset.attrs[k]:.1f}" if k == "runtime_s" else dataset.attrs[k]))
            for k in keys if k in dataset.attrs]
    sweep = ", ".join(f"{d} ({dataset.sizes[d]})" for d in dataset["mc_n_samples"].dims)
    rows += [("results file", _e(source)), ("sweep dimensions", _e(sweep or "none"))]
    return "<h2>Run</h2>" + _table(("attribute", "value"), rows)


def _answers(dataset, targets):
    out = ["<h2>Campaign-planning answers</h2>"]
    dims = set(dataset["mc_n_samples"].dims)
    if "lidar_misalignment" in dims:
        rows = [(planning.MODEL_NAMES[m],
                 f"{a['best']:g}" if a["gain"] > planning.EQUAL_WITHIN else "any (no effect)",
                 f"{a['u_best']:.4g}", f"{a['worst']:g}", f"{a['u_worst']:.4g}",
                 f"{100 * a['gain']:.2f} %")
                for m, a in planning.misalignment_answer(dataset).items()]
        out += ["<h3>Best misalignment</h3><p>u(Vh) averaged over the other swept keys.</p>",
                _table(("model", "best [deg]", "u [m/s]", "worst [deg]", "u [m/s]",
                        "gain best vs worst"), rows)]
    if {"wind_speed", "ship_sog"} <= dims:
        rows = [(f"{target:g}", planning.MODEL_NAMES[m], _ratio(a["ratio"]),
                 f"{a['limiting_speed']:g}") for target in targets
                for m, a in planning.velocity_ratio_answer(dataset, target).items()]
        out += ["<h3>Largest velocity ratio that keeps u(Vh) under a target</h3><p>VR = sog / "
                "Vh on the swept grid, for every swept wind speed (direction-averaged u).</p>",
                _table(("target u(Vh) [m/s]", "model", "largest VR", "limiting Vh [m/s]"), rows)]
    for quantity in ("wind_speed", "wind_direction", "vertical_wind"):
        if f"{quantity}_budget" in dataset:
            out += [_budget(dataset, quantity), _disagreement(dataset, quantity),
                    _bias(dataset, quantity)]
    return "\n".join(out)


def _ratio(value):
    if np.isnan(value):
        return "none: exceeded already at sog = 0"
    return "no limit on the swept grid" if np.isinf(value) else f"{value:.3g}"


def _budget(dataset, quantity):
    rows = [(_e(name), f"{100 * share:.1f} %") for name, share in
            planning.budget_answer(dataset, quantity)]
    validity = planning.gum_validity_answer(dataset, quantity)
    note = "" if validity is None else (
        f"<p>GUM interval validated by Monte Carlo (JCGM 101 clause 8) in "
        f"{100 * validity['valid']:.0f} % of scenes; the verdict is conclusive (not decided "
        f"by sampling noise) in {100 * validity['conclusive']:.0f} %.</p>")
    return (f"<h3>Uncertainty budget of {quantity.replace('_', ' ')}</h3><p>Share of the GUM "
            f"variance, averaged over the grid; the first input dominates.</p>"
            + _table(("input", "share"), rows) + note)


def _disagreement(dataset, quantity):
    answer = planning.disagreement_answer(dataset, quantity)
    title = f"<h4>Paper model against sampling: {quantity.replace('_', ' ')}</h4>"
    if answer is None:
        return title + "<p>The scenes are outside the paper's model (or it has no such output).</p>"
    where = ", ".join(f"{k} = {v:g}" if isinstance(v, float) else f"{k} = {v}"
                      for k, v in answer["where_max"].items())
    return title + (f"<p>u(paper) / u({answer['reference']}) over {answer['scenes']} scenes: "
                    f"median {answer['median']:.3f}, range {answer['min']:.3f} to "
                    f"{answer['max']:.3f}; largest disagreement at {_e(where)}.</p>")


def _bias(dataset, quantity):
    answer = planning.bias_answer(dataset, quantity)
    unit = QUANTITY_UNITS[quantity]
    text = (f"<h4>Bias: {quantity.replace('_', ' ')}</h4><p>Largest systematic error of the "
            f"correction (reconstruction with zero errors minus truth): "
            f"{answer['correction']['value']:+.3g} {unit} at {_e(_where(answer['correction']))}.")
    if "mc" in answer:
        text += (f" Largest Monte Carlo bias (mean minus truth): {answer['mc']['value']:+.3g} "
                 f"{unit} at {_e(_where(answer['mc']))}; larger than 3 standard errors in "
                 f"{100 * answer['significant']:.0f} % of scenes.")
    return text + "</p>"


def _where(item):
    return ", ".join(f"{k} = {v:g}" if isinstance(v, float) else f"{k} = {v}"
                     for k, v in item["where"].items()) or "every scene"


def _findings(dataset):
    rows = [(_e(r["finding"]), _e(r["model"]),
             f"<span class='{'yes' if r['holds'] else 'no'}'>{'holds' if r['holds'] else 'does not hold'}</span>",
             _e(r["evidence"])) for r in planning.paper_findings(dataset)]
    if not rows:
        return ""
    return ("<h2>Findings of Rubio &amp; Gottschall (2022, Sec. 3)</h2>"
            + _table(("finding", "model", "verdict", "evidence"), rows))


def _summary_tables(dataset):
    out = ["<h2>Uncertainty over the grid</h2>"]
    for quantity, unit in QUANTITY_UNITS.items():
        rows = []
        for model, label in planning.MODEL_NAMES.items():
            name = f"{quantity}_{model}"
            if name in dataset and np.isfinite(dataset[name].values).any():
                v = dataset[name].values
                rows.append((label, f"{np.nanmin(v):.4g}", f"{np.nanmedian(v):.4g}",
                             f"{np.nanmax(v):.4g}", f"{int(np.isnan(v).sum())}"))
        if rows:
            out += [f"<h3>u({quantity.replace('_', ' ')}) [{unit}]</h3>",
                    _table(("model", "min", "median", "max", "NaN scenes"), rows)]
    return "\n".join(out)


def _figures(dataset):
    out = ["<h2>Figures</h2>"]
    for name, function in figure_plan(dataset):
        figure = function(dataset)
        buffer = io.BytesIO()
        figure.savefig(buffer, format="png", dpi=100)
        plt.close(figure)
        data = base64.b64encode(buffer.getvalue()).decode("ascii")
        out.append(f"<h3>{_e(name)}</h3><img alt='{_e(name)}' src='data:image/png;base64,{data}'>")
    return "\n".join(out)
