"""A self-contained HTML report of one run: scenario, figures, tables, planning answers.

Figures are embedded as base64 PNG, so the single file can be mailed or archived; each
has a caption that says what to see. The numbers come from :mod:`uq.outputs.planning`;
the figures from :mod:`uq.outputs.figures` (a single scene gets the single-scene
figures). Counts say what they count: scenes of the sweep, and range gates within a
scene, separately. A deterministic number within :data:`uq.constants.NUMERICAL_ZERO`
is reported as zero, a Monte Carlo bias only beyond 3 of its standard errors. The
scenario as run is folded (``<details>``). Written atomically
(:func:`uq.files.write_text`).
"""
import base64
import html
import io

import matplotlib.pyplot as plt
import numpy as np

from scipy.stats import norm

from uq.constants import COVERAGE_PROBABILITY, NUMERICAL_ZERO
from uq.files import SIGNATURE, write_text
from uq.outputs import planning
from uq.outputs.figures import (caption, figure_plan, mark_selection, no_figure_reason,
                                select_scenes, sweep_dimensions)
from uq.outputs.labels import KEY_WORDS

QUANTITY_UNITS = {"wind_speed": "m/s", "wind_direction": "deg", "vertical_wind": "m/s",
                  "gate_height": "m", "radial_velocity": "m/s"}
#: Most scenes of a sweep whose numbers the report lists scene by scene.
MAX_TABLE_SCENES = 48
#: Coverage factor of the GUM's 95 % interval of a Gaussian (JCGM 100, G.1.3).
GUM_COVERAGE_FACTOR = float(norm.ppf((1 + COVERAGE_PROBABILITY) / 2))
#: NUMERICAL_ZERO as the text writes it (1e-9).
_ZERO = f"{NUMERICAL_ZERO:.0e}".replace("e-0", "e-")
#: Units as the report's text writes them.
HTML_UNITS = {"degree": "deg", "m s-1": "m/s", "1": ""}
#: True turbulence intensity [1] for which the report states the apparent one: 6 %, a
#: typical offshore value at hub height in moderate wind (IEC 61400-1 class C at 15 m/s
#: is ~14 %; measured North Sea means are 5-8 %).
DEFAULT_TRUE_TI = 0.06
STYLE = """body{font-family:system-ui,sans-serif;max-width:1100px;margin:2em auto;color:#222}
table{border-collapse:collapse;margin:.6em 0}td,th{border:1px solid #bbb;padding:3px 8px;
font-size:90%;text-align:left}th{background:#eee}pre{background:#f6f6f6;padding:.8em;
overflow-x:auto;font-size:85%}img{max-width:100%}.no{color:#a00}.yes{color:#070}
figure{margin:1em 0}figcaption{font-size:90%;color:#444;max-width:900px}
summary{cursor:pointer;font-weight:bold}"""


def write_report(dataset, path, source="", targets=planning.DEFAULT_TARGETS, select=None,
                 true_ti=DEFAULT_TRUE_TI):
    """Write the report of `dataset` to `path` (HTML); returns the path."""
    page = render_report(dataset, source=source, targets=targets, select=select,
                         true_ti=true_ti)
    return write_text(path, page)


def render_report(dataset, source="", targets=planning.DEFAULT_TARGETS, select=None,
                  true_ti=DEFAULT_TRUE_TI):
    """The report as one HTML string. `select` (``{dim: value}``) picks the scenes the
    figures show (:func:`uq.outputs.figures.select_scenes`); the tables cover them all.
    `true_ti` [1]: the true turbulence intensity for which the apparent one is stated
    (results with motion)."""
    name = dataset.attrs.get("title", "uq results")
    parts = [f"<!DOCTYPE html><!-- {SIGNATURE} --><html><head><meta charset='utf-8'>"
             f"<title>{_e(name)}</title>"
             f"<style>{STYLE}</style></head><body><h1>{_e(name)}</h1>",
             _run_table(dataset, source), _answers(dataset, targets),
             _apparent_ti(dataset, true_ti), _findings(dataset),
             _summary_tables(dataset), _records_table(dataset), _scene_tables(dataset),
             _figures(select_scenes(dataset, select), select),
             _scenario(dataset),
             "</body></html>"]
    return "\n".join(parts)


def _e(text):
    return html.escape(str(text))


def _records_table(dataset):
    """Record mode: per range gate (the first scene of a sweep), the lidar's u, v, w
    variance ratios with their numerical errors, each component's apparent TI (spectral
    from the turbulence alone; the Monte Carlo records' mean, scans' errors included) and
    the field's true TI, and the records' check of the spectral path."""
    from uq.outputs.recordfigures import COMPONENTS
    if "turbulence_v_ratio" not in dataset:
        return ""
    first = {d: 0 for d in dataset["turbulence_v_ratio"].dims if d != "range"}
    data = dataset.isel(first)
    gates = np.atleast_1d(data["range"].values)
    where = "" if not first else " (first scene: " + ", ".join(
        f"{d} {_e(str(dataset[d].values[0]))}" for d in first) + ")"
    header = ("component", "quantity") + tuple(f"range gate {g:g} m" for g in gates)
    rows = []
    for label, ratio, error, spectral, mc, true in COMPONENTS:
        rows.append((label, "variance ratio lidar / field") + tuple(
            f"{_number(r)} &plusmn; {_number(e)}" for r, e in zip(
                np.atleast_1d(data[ratio].values), np.atleast_1d(data[error].values))))
        rows.append(("", "apparent TI [%], spectral (turbulence)") + tuple(
            _number(100 * v) for v in np.atleast_1d(data[spectral].values)))
        if mc in data:
            rows.append(("", "apparent TI [%], Monte Carlo records") + tuple(
                _number(100 * v) for v in np.atleast_1d(data[mc].values)))
        rows.append(("", "true TI [%] (reference point)") + (_number(
            100 * float(data[true])),) * len(gates))
    out = [f"<h2>Turbulence over a record{where}</h2>", _table(header, rows)]
    if "turbulence_intensity_spectral_z" in data:
        z, limit = np.atleast_1d(data["turbulence_intensity_spectral_z"].values), float(
            np.atleast_1d(data["turbulence_intensity_spectral_z_limit"].values)[0])
        resolution = np.atleast_1d(data["turbulence_intensity_check_resolution"].values)
        out.append(f"<p>The Monte Carlo records check the spectral path's apparent TI: z = "
                   f"{', '.join(_number(v) for v in z)} against |z| &le; {_number(limit)} "
                   f"(Student's t of the run's records, 5 % false alarms); at this record "
                   f"count the check tells a "
                   f"relative difference of the TI of {', '.join(_number(100 * r) for r in resolution)} % "
                   f"from none. The records' field keeps "
                   f"{_number(float(data['turbulence_intensity_box_kept']))} of the field's "
                   f"u-variance at the reference point over a record.</p>")
    if "turbulence_spectral_converged" in data and not bool(
            np.all(data["turbulence_spectral_converged"].values)):
        out.append("<p><b>The spectral path did not reach its tolerance</b>: its stated "
                   "errors say by how much.</p>")
    return "\n".join(out)


def _table(header, rows):
    head = "".join(f"<th>{_e(h)}</th>" for h in header)
    body = "".join("<tr>" + "".join(f"<td>{cell}</td>" for cell in row) + "</tr>" for row in rows)
    return f"<table><tr>{head}</tr>{body}</table>"


def extent(dataset, variable):
    """What the values of `variable` are, counted: ``36 scenes x 3 range gates``."""
    dims = sweep_dimensions(dataset)
    scenes = int(np.prod([dataset.sizes[d] for d in dims])) if dims else 1
    parts = [f"{scenes} scene{'s' if scenes != 1 else ''}"] if dims else []
    for dim, word in (("range", "range gate"), ("beam", "beam")):
        if dim in dataset[variable].dims:
            n = dataset.sizes[dim]
            parts.append(f"{n} {word}{'s' if n != 1 else ''}")
    return " x ".join(parts) or "the scene"


def _share(count, total, dataset, variable):
    """``34 of 36 (scenes x range gates)``."""
    return f"{count} of {total} ({extent(dataset, variable)})"


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
                 f"{a['u_best']:.4g}",
                 f"{a['worst']:g}" if a["gain"] > planning.EQUAL_WITHIN else "any",
                 f"{a['u_worst']:.4g}", f"{100 * a['gain']:.2f} %")
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
    for quantity in QUANTITY_UNITS:
        if f"{quantity}_budget" not in dataset:
            continue
        if not planning.uncertain(dataset, quantity):
            out.append(_no_uncertainty(dataset, quantity))
            continue
        out += [_budget(dataset, quantity), _disagreement(dataset, quantity),
                _bias(dataset, quantity)]
    return "\n".join(out)


def apparent_ti(true_ti, motion_ti):
    """Turbulence intensity a lidar in motion reports [1]: the motion's scatter of Vh adds
    in quadrature to the wind's own (independent: the wave phases are not the
    turbulence), sqrt(TI^2 + TI_motion^2)."""
    return np.sqrt(true_ti**2 + np.asarray(motion_ti) ** 2)


def _apparent_ti(dataset, true_ti):
    """The apparent TI per scene for a stated true TI (results with motion)."""
    if "wind_speed_motion_ti" not in dataset:
        return ""
    motion = dataset["wind_speed_motion_ti"]
    rows = []
    if "correction" in motion.dims:
        for correction in motion["correction"].values:
            m = motion.sel(correction=correction)
            rows.append((str(correction), _percent_range(m), _percent_range(apparent_ti(
                true_ti, m.values))))
    else:
        rows.append(("as run", _percent_range(motion), _percent_range(apparent_ti(
            true_ti, motion.values))))
    note = planning.fixed_phase_note(dataset)
    return "\n".join([
        "<h3>Apparent turbulence intensity</h3>",
        f"<p><b>Note:</b> {_e(note[0].upper() + note[1:])}.</p>" if note else "",
        f"<p>A true turbulence intensity of {100 * true_ti:g} % reads as sqrt(TI^2 + "
        "TI_motion^2): the motion-induced increment (u of Vh from the motion alone, over Vh) "
        "adds in quadrature (<code>--true-ti</code> sets the true TI).</p>",
        _table(("model", "motion-induced TI increment", "apparent TI"), rows)])


def _percent_range(values):
    values = np.asarray(values, dtype=float).reshape(-1)
    low, high = 100 * np.nanmin(values), 100 * np.nanmax(values)
    return f"{low:.2f} %" if np.isclose(low, high) else f"{low:.2f} to {high:.2f} %"


def _no_uncertainty(dataset, quantity):
    """No random error: say so, and give the systematic error of the error-free
    reconstruction (nominal minus true) where it is not zero (e.g. uncorrected motion)."""
    unit = QUANTITY_UNITS[quantity]
    title = f"<h3>{quantity.replace('_', ' ').capitalize()}</h3>"
    text = (f"<p>No uncertainty in these scenes: u at most {_ZERO} {unit} (rounding) in "
            "every model, so no budget and no comparison of models.")
    nominal, true = dataset.get(f"{quantity}_nominal"), dataset.get(f"{quantity}_true")
    if nominal is None or true is None:
        return title + text + "</p>"
    error = np.asarray(nominal - true, dtype=float)
    if quantity == "wind_direction":
        error = (error + 180.0) % 360.0 - 180.0
    error = np.where(np.abs(error) <= NUMERICAL_ZERO, 0.0, error)      # rounding is none
    if not np.nanmax(np.abs(error), initial=0.0) > NUMERICAL_ZERO:
        return title + text + " The error-free reconstruction equals the truth.</p>"
    return (title + text + f" The error-free reconstruction is systematically off: "
            f"reconstructed minus true from {np.nanmin(error):+.3g} to {np.nanmax(error):+.3g} "
            f"{unit} over the scenes (the model's own error, e.g. uncorrected motion or "
            "tilt; see the figures).</p>")


def _ratio(value):
    if np.isnan(value):
        return "none: exceeded already at sog = 0"
    return "no limit on the swept grid" if np.isinf(value) else f"{value:.3g}"


def _budget(dataset, quantity):
    corrections = _swept_corrections(dataset)
    if corrections:                  # one column per correction model: averaging would mix them
        shares = {c: dict(planning.budget_answer(dataset.sel(correction=c), quantity))
                  for c in corrections}
        names = sorted({n for share in shares.values() for n in share},
                       key=lambda n: -np.nanmax([share.get(n, 0.0) for share in shares.values()]
                                                + [0.0]))
        rows = [(_e(n), *[_percent(shares[c].get(n, 0.0)) for c in corrections])
                for n in names]
        header = ("input", *[f"share, {c}" for c in corrections])
    else:
        rows = [(_e(name), f"{100 * share:.1f} %") for name, share in
                planning.budget_answer(dataset, quantity)]
        header = ("input", "share")
    validity = planning.gum_validity_answer(dataset, quantity)
    variable = f"{quantity}_gum_u"
    note = "" if validity is None else (
        f"<p>GUM interval validated by Monte Carlo (JCGM 101 clause 8) for "
        f"{_share(validity['valid_count'], validity['compared'], dataset, variable)}; the "
        f"verdict is conclusive (not decided by sampling noise) for "
        f"{validity['conclusive_count']} of the {validity['compared']}.</p>")
    over = "per correction model, each averaged over the other swept keys" if corrections \
        else f"averaged over {extent(dataset, variable)}"
    return (f"<h3>Uncertainty budget of {quantity.replace('_', ' ')}</h3><p>Share of the GUM "
            f"variance, {over}; the first input dominates.</p>"
            + _table(header, rows) + note)


def _percent(share):
    """A share of the variance in per cent; "-" where there is no variance to share."""
    return "-" if not np.isfinite(share) else f"{100 * share:.1f} %"


def _swept_corrections(dataset):
    """The swept correction models (a column each in the budget), or ()."""
    if "correction" not in dataset.dims or dataset.sizes["correction"] < 2:
        return ()
    return tuple(str(c) for c in dataset["correction"].values)


def _disagreement(dataset, quantity):
    answer = planning.disagreement_answer(dataset, quantity)
    title = f"<h4>Paper model against sampling: {quantity.replace('_', ' ')}</h4>"
    if answer is None:
        return title + "<p>Outside the paper's model (or the model has no such output).</p>"
    where = _where({"where": answer["where_max"]}, dataset)
    reference = planning.MODEL_NAMES[answer["reference"]]
    return title + (f"<p>u(paper) / u({reference}) over {answer['scenes']} values "
                    f"({extent(dataset, f'{quantity}_paper_u')}): "
                    f"median {answer['median']:.3f}, range {answer['min']:.3f} to "
                    f"{answer['max']:.3f}; largest disagreement at {_e(where)}.</p>")


def _bias(dataset, quantity):
    answer = planning.bias_answer(dataset, quantity)
    unit = QUANTITY_UNITS[quantity]
    correction = answer["correction"]
    probe = answer.get("probe")
    text = f"<h4>Bias: {quantity.replace('_', ' ')}</h4><p>Systematic error of the correction " \
        "(reconstruction with zero errors minus truth" + (
            ", less the probe volume's" if probe else "") + "): "
    text += _systematic(correction, unit, dataset)
    if probe:
        text += (" Systematic error of the probe volume (the radial velocities weighted "
                 "along the beams minus the same at the gate centres): "
                 + _systematic(probe, unit, dataset))
    if "mc" in answer:
        variable = f"{quantity}_mc_bias"
        if answer["mc_significant"] is None:
            text += (f" Monte Carlo mean minus truth within {planning.BIAS_STANDARD_ERRORS} "
                     f"standard errors everywhere ({extent(dataset, variable)}; largest "
                     f"{answer['mc']['value']:+.2g} {unit}): no bias beyond sampling noise.")
        else:
            largest = answer["mc_significant"]
            text += (f" Monte Carlo bias (mean minus truth) beyond "
                     f"{planning.BIAS_STANDARD_ERRORS} standard errors for "
                     f"{_share(answer['significant_count'], answer['compared'], dataset, variable)}"
                     f"; largest {largest['value']:+.3g} {unit} at {_e(_where(largest, dataset))}.")
    return text + "</p>"


def _systematic(item, unit, dataset):
    """``none (...)`` or ``largest +x unit at ...`` of a systematic error."""
    if item["zero"]:
        return (f"none (at most {abs(item['value']):.1g} {unit}, within the {_ZERO} {unit} "
                "of rounding).")
    return f"largest {item['value']:+.3g} {unit} at {_e(_where(item, dataset))}."


def _where(item, dataset=None):
    """``wind direction = 30 deg, range gate 160 m``: where a value was found."""
    parts = []
    for key, value in item["where"].items():
        if key == "range":
            parts.append(f"range gate {value:g} m")
        elif isinstance(value, float):
            unit = dataset[key].attrs.get("units", "") if dataset is not None and \
                key in dataset.coords else ""
            unit = HTML_UNITS.get(unit, unit)
            parts.append(f"{KEY_WORDS.get(key, key)} {value:g}{' ' + unit if unit else ''}")
        else:
            parts.append(f"{key} = {value}")
    return ", ".join(parts) or "every scene"


def _findings(dataset):
    rows = [(_e(r["finding"]), _e(r["model"]),
             f"<span class='{'yes' if r['holds'] else 'no'}'>{'holds' if r['holds'] else 'does not hold'}</span>",
             _e(r["evidence"])) for r in planning.paper_findings(dataset)]
    if not rows:
        return ""
    return ("<h2>Findings of Rubio &amp; Gottschall (2022, Sec. 3)</h2>"
            + _table(("finding", "model", "verdict", "evidence"), rows))


def _summary_tables(dataset):
    """u of each model: per range gate for a single scene, else min, median and max over
    the scenes (and gates), with the number of values outside the model."""
    single = not sweep_dimensions(dataset)
    out = ["<h2>Uncertainty</h2>"]
    for quantity, unit in QUANTITY_UNITS.items():
        if f"{quantity}_gum_u" in dataset and not planning.uncertain(dataset, quantity):
            out.append(f"<h3>u({quantity.replace('_', ' ')}) [{unit}]</h3><p>none (at most "
                       f"{_ZERO} {unit} in every model)</p>")
            continue
        names = [(label, f"{quantity}_{model}") for model, label in planning.MODEL_NAMES.items()]
        names = [(label, name) for label, name in names
                 if name in dataset and np.isfinite(dataset[name].values).any()]
        if not names:
            continue
        if single:
            gates = np.atleast_1d(dataset["range"].values)
            header = ("model",) + tuple(f"range gate {g:g} m" for g in gates)
            rows = [(label + beam,) + tuple(_number(v) for v in np.atleast_1d(values))
                    for label, name in names
                    for beam, values in _per_beam(dataset, dataset[name])]
        else:
            header = ("model", "min", "median", "max", "outside the model")
            rows = [(label, _number(np.nanmin(v)), _number(np.nanmedian(v)),
                     _number(np.nanmax(v)), f"{int(np.isnan(v).sum())} of {v.size}")
                    for label, name in names for v in [dataset[name].values]]
            header = header[:-1] + (f"outside the model (of {extent(dataset, names[0][1])})",)
        out += [f"<h3>u({quantity.replace('_', ' ')}) [{unit}]</h3>", _table(header, rows)]
    return "\n".join(out)


#: Outputs listed scene by scene (one value per scene and gate).
SCENE_QUANTITIES = ("wind_speed", "wind_direction", "vertical_wind", "gate_height")
#: Most range gates listed per scene (else the lowest, middle and highest).
MAX_TABLE_GATES = 3


def _scene_tables(dataset):
    """The answer as a table, for a sweep of at most MAX_TABLE_SCENES scenes: per output,
    a row per scene (and range gate) with u, the 95 % interval, the bias and, for the
    wind speed of a run with motion, the turbulence-intensity increment."""
    dims = sweep_dimensions(dataset)
    scenes = int(np.prod([dataset.sizes[d] for d in dims])) if dims else 1
    if not dims or scenes > MAX_TABLE_SCENES:
        return ""
    out = ["<h2>Scene by scene</h2><p>u: Monte Carlo where sampled, else the GUM; the 95 % "
           "interval likewise (the GUM's y ± 1.96 u); bias: Monte Carlo mean minus true "
           "(else the error-free reconstruction minus true).</p>"]
    gates = _table_gates(dataset)
    for quantity in SCENE_QUANTITIES:
        if f"{quantity}_gum_u" not in dataset or not planning.uncertain(dataset, quantity):
            continue
        unit = QUANTITY_UNITS[quantity]
        columns = _scene_columns(dataset, quantity, unit)
        header = tuple(_key_header(dataset, d) for d in dims) + (
            ("range gate [m]",) if gates else ()) + tuple(name for name, _ in columns)
        rows = []
        for index in np.ndindex(*[dataset.sizes[d] for d in dims]):
            scene = dataset.isel(dict(zip(dims, index)))
            keys = tuple(_e(_value_text(scene[d].values)) for d in dims)
            for gate in gates or [None]:
                at = scene if gate is None else scene.isel(range=gate)
                rows.append(keys + ((f"{float(at['range']):g}",) if gates else ())
                            + tuple(cell(at) for _, cell in columns))
        out += [f"<h3>{quantity.replace('_', ' ').capitalize()}</h3>", _table(header, rows)]
    return "\n".join(out)


def _table_gates(dataset):
    """Gate indices listed per scene ([] without a range dimension)."""
    if "range" not in dataset.dims:
        return []
    n = dataset.sizes["range"]
    return list(range(n)) if n <= MAX_TABLE_GATES else sorted({0, n // 2, n - 1})


def _scene_columns(dataset, quantity, unit):
    """(header, cell function of one scene and gate) of an output's scene table."""
    sampled = f"{quantity}_mc_u" in dataset
    u_name = f"{quantity}_mc_u" if sampled else f"{quantity}_gum_u"
    columns = [(f"u [{unit}]", lambda at: _number(float(at[u_name]))),
               (f"95 % interval [{unit}]", lambda at: _interval(at, quantity, sampled)),
               (f"bias [{unit}]", lambda at: _scene_bias(at, quantity))]
    if f"{quantity}_gum_valid" in dataset:
        columns.append(("GUM validated", lambda at: "yes" if bool(at[f"{quantity}_gum_valid"])
                        else "<span class='no'>no</span>"))
    if quantity == "wind_speed" and "wind_speed_motion_ti" in dataset:
        columns.append(("TI increment from motion",
                        lambda at: f"{100 * float(at['wind_speed_motion_ti']):.2f} %"))
    return columns


def _interval(at, quantity, sampled):
    if sampled:
        low, high = float(at[f"{quantity}_mc_low"]), float(at[f"{quantity}_mc_high"])
    else:
        value, u = float(at[f"{quantity}_gum_value"]), float(at[f"{quantity}_gum_u"])
        low, high = value - GUM_COVERAGE_FACTOR * u, value + GUM_COVERAGE_FACTOR * u
    return f"[{low:.4g}, {high:.4g}]"


def _scene_bias(at, quantity):
    name = f"{quantity}_mc_bias"
    if name in at:
        return _number(float(at[name]))
    difference = float(at[f"{quantity}_nominal"] - at[f"{quantity}_true"])
    if quantity == "wind_direction":
        difference = (difference + 180.0) % 360.0 - 180.0
    return _number(difference)


def _key_header(dataset, dim):
    """A swept key in words with its unit, as the report writes them."""
    units = dataset[dim].attrs.get("units")
    words = KEY_WORDS.get(dim) or str(dataset[dim].attrs.get("long_name", dim)).replace(
        "swept scenario key ", "")
    units = HTML_UNITS.get(units, units)
    return f"{words} [{units}]" if units else words


def _value_text(value):
    value = value.item() if hasattr(value, "item") else value
    return f"{value:g}" if isinstance(value, float) else str(value)


def _per_beam(dataset, variable):
    """[(", beam at 90 deg", values over the gates), ...] of a variable with a beam
    dimension, else [("", its values)]."""
    if "beam" not in variable.dims:
        return [("", variable.values)]
    azimuths = dataset["beam_azimuth"].values if "beam_azimuth" in dataset.coords else \
        variable["beam"].values.astype(float)
    return [(", vertical beam" if np.isnan(a) else f", beam at {a:g} deg",
             variable.isel(beam=k).values) for k, a in enumerate(azimuths)]


def _number(value):
    """A value with 4 significant digits; 0 within NUMERICAL_ZERO (rounding)."""
    return "0" if abs(value) <= NUMERICAL_ZERO else f"{value:.4g}"


def _figures(dataset, select=None):
    out = ["<h2>Figures</h2>"]
    reason = no_figure_reason(dataset)
    if reason:
        out.append(f"<p>{_e(reason)}.</p>")
    for name, function in figure_plan(dataset):
        figure = mark_selection(function(dataset), dataset, select)
        buffer = io.BytesIO()
        figure.savefig(buffer, format="png", dpi=100)
        plt.close(figure)
        data = base64.b64encode(buffer.getvalue()).decode("ascii")
        out.append(f"<figure><img alt='{_e(name)}' src='data:image/png;base64,{data}'>"
                   f"<figcaption><b>{_e(name)}.</b> {_e(caption(name))}</figcaption></figure>")
    return "\n".join(out)


def _scenario(dataset):
    """The scenario as run, folded: it is long, and the report's reader wants the answers."""
    text = dataset.attrs.get("scenario", "")
    lines = text.count("\n")
    return (f"<h2>Scenario as run</h2><details><summary>the scenario's YAML ({lines} lines, "
            f"defaults filled in)</summary><pre>{_e(text)}</pre></details>")
