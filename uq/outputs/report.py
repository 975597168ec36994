"""A self-contained HTML report of one run: what was run, the answers to the question it
was made for, every output's uncertainty, budget and clause 8 verdicts, scene by scene,
the figures and the scenario.

Figures are embedded as base64 PNG, so the single file can be mailed or archived; each
has a caption that says what it shows. Every number is read from the results (the
planning answers from :mod:`uq.outputs.planning`, the clause 8 verdicts in words from
:mod:`uq.outputs.verdicts`); the figures are those of :mod:`uq.outputs.figures` (a
single scene gets the single-scene figures). Counts say what they count: scenes of the
sweep, and range gates within a scene, separately; a table that leaves rows out says so.
A deterministic number within :data:`uq.constants.NUMERICAL_ZERO` is reported as zero, a
Monte Carlo bias only beyond 3 of its standard errors. The scenario as run is folded
(``<details>``). Written atomically (:func:`uq.files.write_text`).

Turbulence intensities carry one name each (:data:`TI_NAMES`): the field's point TI
(the scenario's input), the field's TI over a record (what the lidar's is compared with),
the lidar's apparent TI (spectral path, and the Monte Carlo records), and the records'
own field TI.
"""
import base64
import html
import io

import matplotlib.pyplot as plt
import numpy as np

from scipy.stats import norm

from uq.constants import BOX_KEPT_WHOLE, COVERAGE_PROBABILITY, NUMERICAL_ZERO
from uq.files import SIGNATURE, write_text
from uq.outputs import planning, verdicts
from uq.outputs.figures import (caption, figure_plan, mark_selection, no_figure_reason,
                                select_scenes, sweep_dimensions)
from uq.outputs.labels import KEY_WORDS
from uq.outputs.labels import QUANTITIES as LABEL_QUANTITIES
from uq.outputs.scenes import (gate_words, scene_count, scene_indices, scene_values,
                               swept_keys, where_text)
from uq.pipeline.metadata import QUANTITIES
from uq.pipeline.metadata import TI_NAMES as METADATA_TI_NAMES

#: Units as the report's text writes them.
HTML_UNITS = {"degree": "deg", "m s-1": "m/s", "1": "", "m": "m"}
#: Each output's unit as the text writes it.
QUANTITY_UNITS = {q: HTML_UNITS.get(a["units"], a["units"]) for q, a in QUANTITIES.items()}
#: Most rows of the scene-by-scene table of an output (scenes x range gates); beyond, the
#: table says how many it leaves out and where they are (``uq export`` has them all).
MAX_TABLE_ROWS = 96
#: Coverage factor of the GUM's 95 % interval of a Gaussian (JCGM 100, G.1.3).
GUM_COVERAGE_FACTOR = float(norm.ppf((1 + COVERAGE_PROBABILITY) / 2))
#: NUMERICAL_ZERO as the text writes it (1e-9).
_ZERO = f"{NUMERICAL_ZERO:.0e}".replace("e-0", "e-")
#: True turbulence intensity [1] for which the report states the apparent one of a run
#: with motion but no records: 6 %, a typical offshore value at hub height in moderate
#: wind (IEC 61400-1 class C at 15 m/s is ~14 %; measured North Sea means are 5-8 %).
DEFAULT_TRUE_TI = 0.06
#: The turbulence intensities of record mode: variable -> (name, what it is); the same
#: words as the result files' attributes.
TI_NAMES = METADATA_TI_NAMES
STYLE = """body{font-family:system-ui,sans-serif;max-width:1100px;margin:2em auto;color:#222}
table{border-collapse:collapse;margin:.6em 0}td,th{border:1px solid #bbb;padding:3px 8px;
font-size:90%;text-align:left}th{background:#eee}pre{background:#f6f6f6;padding:.8em;
overflow-x:auto;font-size:85%}img{max-width:100%}.no{color:#a00}.yes{color:#070}
.undecided{color:#555}figure{margin:1em 0}figcaption{font-size:90%;color:#444;
max-width:900px}summary{cursor:pointer;font-weight:bold}"""


def write_report(dataset, path, source="", targets=None, select=None, true_ti=None):
    """Write the report of `dataset` to `path` (HTML); returns the path."""
    page = render_report(dataset, source=source, targets=targets, select=select,
                         true_ti=true_ti)
    return write_text(path, page)


def render_report(dataset, source="", targets=None, select=None, true_ti=None):
    """The report as one HTML string.

    Parameters
    ----------
    targets : dict, optional
        ``{output: (u, ...)}``: which swept values keep u(output) under each u (in the
        output's units); absent, the wind speed's velocity-ratio answer uses
        :data:`uq.outputs.planning.DEFAULT_TARGETS` where wind and ship speed are swept.
    select : dict, optional
        ``{dim: value}``: the scenes the figures show
        (:func:`uq.outputs.figures.select_scenes`); the tables cover them all.
    true_ti : float, optional
        The true turbulence intensity [1] for which the apparent one of a run with motion
        and no records is stated (default :data:`DEFAULT_TRUE_TI`).
    """
    name = dataset.attrs.get("title", "uq results")
    targets = dict(targets or {})
    parts = [f"<!DOCTYPE html><!-- {SIGNATURE} --><html><head><meta charset='utf-8'>"
             f"<title>{_e(name)}</title>"
             f"<style>{STYLE}</style></head><body><h1>{_e(name)}</h1>",
             _description(dataset), _run_table(dataset, source),
             _answers(dataset, targets, DEFAULT_TRUE_TI if true_ti is None else true_ti),
             _outputs(dataset), _findings(dataset),
             _summary_tables(dataset), _records_table(dataset), _scene_tables(dataset),
             _figures(select_scenes(dataset, select), select),
             _scenario(dataset),
             "</body></html>"]
    return "\n".join(p for p in parts if p)


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
                   f"from none. {_box_sentence(data)}</p>")
    if "turbulence_spectral_converged" in data and not bool(
            np.all(data["turbulence_spectral_converged"].values)):
        out.append("<p><b>The spectral path did not reach its tolerance</b>: its stated "
                   "errors say by how much.</p>")
    return "\n".join(out)


def _box_sentence(data):
    """What the records' turbulence box holds of the model's u-variance, from the run's
    stored shares (the box alone; with the scales below its cells drawn at the beams)."""
    kept = float(np.atleast_1d(data["turbulence_intensity_box_kept"].values)[0])
    if "turbulence_intensity_box_resolved" not in data:
        return (f"The records' field at the lidar's beams keeps {_number(kept)} of the "
                f"model's u-variance over a record.")
    resolved = float(np.atleast_1d(data["turbulence_intensity_box_resolved"].values)[0])
    if not np.isfinite(resolved) or resolved == kept:
        return (f"The turbulence box keeps {_number(kept)} of the model's u-variance over "
                f"a record (its scales below the cells are drawn at the reference point "
                f"alone): the records' lidar TI^2 may read up to that share low.")
    if abs(kept - 1.0) <= BOX_KEPT_WHOLE:        # the band larger than the box drawn too
        return (f"The turbulence box resolves {_number(resolved)} of the model's u-variance "
                f"over a record; the scales below its cells are drawn at every beam, gate "
                f"and scan (independent: they decorrelate within a few cells) and at the "
                f"reference point, and the eddies larger than the box as one slow trend a "
                f"record that every beam and the reference point share, so the records' "
                f"field where the beams read it keeps {_number(kept)}.")
    return (f"The turbulence box resolves {_number(resolved)} of the model's u-variance over "
            f"a record; the scales below its cells are drawn at every beam, gate and scan "
            f"(independent: they decorrelate within a few cells) and at the reference "
            f"point, so the records' field where the beams read it keeps {_number(kept)} "
            f"(the rest: eddies longer than the box along the wind).")


def _table(header, rows):
    head = "".join(f"<th>{_e(h)}</th>" for h in header)
    body = "".join("<tr>" + "".join(f"<td>{cell}</td>" for cell in row) + "</tr>" for row in rows)
    return f"<table><tr>{head}</tr>{body}</table>"


def extent(dataset, variable):
    """What the values of `variable` are, counted: ``36 scenes x 3 range gates``."""
    dims = sweep_dimensions(dataset)
    scenes = int(np.prod([dataset.sizes[d] for d in dims])) if dims else 1
    parts = [f"{scenes} scene{'s' if scenes != 1 else ''}"] if dims else []
    for dim, word in (("range", gate_words(dataset)), ("beam", "beam")):
        if dim in dataset[variable].dims:
            n = dataset.sizes[dim]
            parts.append(f"{n} {word}{'s' if n != 1 else ''}")
    return " x ".join(parts) or "the scene"


def _share(count, total, dataset, variable):
    """``34 of 36 (scenes x range gates)``."""
    return f"{count} of {total} ({extent(dataset, variable)})"


def _description(dataset):
    """The scenario's own description: what the run was made for."""
    import yaml
    try:
        raw = yaml.safe_load(dataset.attrs.get("scenario", "")) or {}
    except yaml.YAMLError:
        return ""
    text = str(raw.get("description") or "").strip() if isinstance(raw, dict) else ""
    return f"<p>{_e(text)}</p>" if text else ""


def _run_table(dataset, source):
    keys = ("uq_version", "sampling_method", "n_samples", "seed", "correction",
            "ins_correlation", "runtime_s")
    rows = [(_e(k), _e(f"{dataset.attrs[k]:.1f}" if k == "runtime_s" else dataset.attrs[k]))
            for k in keys if k in dataset.attrs]
    keys = swept_keys(dataset)
    sweep = " x ".join(f"{key} ({dataset.sizes[dim]})" for dim, key in keys.items())
    gates = dataset.sizes["range"] if "range" in dataset.dims else 1
    size = f"{scene_count(dataset)} scene{'s' if scene_count(dataset) != 1 else ''}" + (
        f" x {gates} {gate_words(dataset)}s" if gates > 1 else "")
    records = _record_count(dataset)
    if records:
        size += f"; {records} Monte Carlo records of {_record_seconds(dataset):g} s per scene"
    rows += [("results file", _e(source)), ("swept keys", _e(sweep or "none")),
             ("size", _e(size))]
    return "<h2>Run</h2>" + _table(("attribute", "value"), rows)


def _scenario_section(dataset, section):
    import yaml
    try:
        raw = yaml.safe_load(dataset.attrs.get("scenario", "")) or {}
    except yaml.YAMLError:
        return {}
    value = raw.get(section) if isinstance(raw, dict) else None
    return value if isinstance(value, dict) else {}


def _record_count(dataset):
    if "turbulence_intensity_mc_mean" not in dataset:
        return 0
    return int(_scenario_section(dataset, "record").get("count", 0))


def _record_seconds(dataset):
    return float(_scenario_section(dataset, "record").get("duration", float("nan")))


def _answers(dataset, targets, true_ti):
    """The answers to the question the run was made for: the targets asked for, the
    paper's planning answers (velocity ratio, misalignment), the turbulence intensity the
    lidar reads (record mode) or the motion's TI increment."""
    out = [_target_answers(dataset, targets),
           _velocity_ratio(dataset, targets.get("wind_speed")),
           _misalignment(dataset), _record_ti(dataset), _apparent_ti(dataset, true_ti)]
    out = [part for part in out if part]
    return "<h2>Answers</h2>" + "\n".join(out) if out else ""


def _target_answers(dataset, targets):
    """Per output and target: which swept values and range gates keep u under it."""
    out = []
    for quantity, values in targets.items():
        unit = QUANTITY_UNITS[quantity]
        for target in values:
            answer = planning.target_answer(dataset, quantity, target)
            model = planning.MODEL_NAMES[answer["model"]]
            out.append(f"<h3>Which values keep u({_words(quantity)}) at or under "
                       f"{target:g} {unit}</h3><p>u: {model}. \u201cEvery scene\u201d: "
                       "the value keeps u under the target whatever the other swept keys; "
                       "\u201csome scene\u201d: for some of their values.</p>")
            rows = []
            for group in answer["groups"]:
                name = ", ".join(f"{swept_keys(dataset).get(d, d)} = {v}"
                                 for d, v in group["group"].items()) or "all scenes"
                keys = "; ".join(
                    f"{_key_words(dataset, dim)}: every scene {_values(found['always'])}, "
                    f"some scene {_values(found['somewhere'])}"
                    for dim, found in group["keys"].items()) or "-"
                best = group["best"]
                rows.append((_e(name), f"{group['meeting']} of {group['total']}", _e(keys),
                             _e(f"{_number(best['value'])} {unit} at "
                                f"{_where(best, dataset)}")))
            out.append(_table(("scenes", "meeting the target", "values that keep u under it",
                               "best scene"), rows))
    return "\n".join(out)


def _words(quantity):
    """An output in words (``wind speed``, ``yaw misalignment``)."""
    return LABEL_QUANTITIES[quantity][0] if quantity in LABEL_QUANTITIES else \
        quantity.replace("_", " ")


def _key_words(dataset, dim):
    if dim == "range":
        return f"{gate_words(dataset)} [m]"
    return swept_keys(dataset).get(dim, dim)


def _values(values):
    if not values:
        return "none"
    return ", ".join(f"{v:g}" if isinstance(v, float) else str(v) for v in values)


def _velocity_ratio(dataset, targets):
    dims = set(dataset["mc_n_samples"].dims)
    if not {"wind_speed", "ship_sog"} <= dims:
        return ""
    rows = [(f"{target:g}", planning.MODEL_NAMES[m], _ratio(a["ratio"]),
             f"{a['limiting_speed']:g}") for target in (targets or planning.DEFAULT_TARGETS)
            for m, a in planning.velocity_ratio_answer(dataset, target).items()]
    return ("<h3>Largest velocity ratio that keeps u(Vh) under a target</h3><p>VR = sog / "
            "Vh on the swept grid, for every swept wind speed (direction-averaged u); "
            "<code>--target wind_speed=U</code> sets the targets.</p>"
            + _table(("target u(Vh) [m/s]", "model", "largest VR", "limiting Vh [m/s]"), rows))


def _misalignment(dataset):
    if "lidar_misalignment" not in dataset["mc_n_samples"].dims:
        return ""
    rows = [(planning.MODEL_NAMES[m],
             f"{a['best']:g}" if a["gain"] > planning.EQUAL_WITHIN else "any (no effect)",
             f"{a['u_best']:.4g}",
             f"{a['worst']:g}" if a["gain"] > planning.EQUAL_WITHIN else "any",
             f"{a['u_worst']:.4g}", f"{100 * a['gain']:.2f} %")
            for m, a in planning.misalignment_answer(dataset).items()]
    return ("<h3>Best misalignment</h3><p>u(Vh) averaged over the other swept keys.</p>"
            + _table(("model", "best [deg]", "u [m/s]", "worst [deg]", "u [m/s]",
                      "gain best vs worst"), rows))


def _record_ti(dataset):
    """Record mode: the turbulence intensity the lidar reads, per scene and gate, beside
    the field's TIs it is compared with, and the check of the spectral path."""
    if "turbulence_intensity_spectral" not in dataset:
        return ""
    spectral = dataset["turbulence_intensity_spectral"]
    has_gates = "range" in spectral.dims
    sampled = "turbulence_intensity_mc_mean" in dataset
    header = [key for key, _ in scene_values(dataset, scene_indices(dataset, has_gates)[0])]
    header += ["field, point [%]", "field, over a record [%]", "lidar, spectral [%]"]
    if sampled:
        header += ["lidar, records: mean [%]", "95 % of records [%]", "records' field [%]",
                   "spectral vs records"]
    header += [f"{c} variance ratio" for c in ("u", "v", "w") if _ratio_name(dataset, c)]
    rows = []
    point = _point_intensity(dataset)
    for index in scene_indices(dataset, gates=has_gates):
        at = dataset.isel({d: i for d, i in index.items()})
        row = [_e(v) for _, v in scene_values(dataset, index)]
        row += [_pc(point(index)), _pc(at["turbulence_intensity_true"]), _pc(spectral.isel(
            {d: i for d, i in index.items() if d in spectral.dims}))]
        if sampled:
            z = float(at["turbulence_intensity_spectral_z"]) \
                if "turbulence_intensity_spectral_z" in at else float("nan")
            agree = bool(at["turbulence_intensity_spectral_valid"]) \
                if "turbulence_intensity_spectral_valid" in at else None
            row += [_pc(at["turbulence_intensity_mc_mean"]),
                    f"{_pc(at['turbulence_intensity_mc_low'])} to "
                    f"{_pc(at['turbulence_intensity_mc_high'])}",
                    _pc(at.get("turbulence_intensity_true_mc_mean", np.nan)),
                    "-" if agree is None else
                    f"<span class='{'yes' if agree else 'no'}'>"
                    f"{'agree' if agree else 'differ'}</span> (z = {z:+.2f})"]
        row += [f"{float(at[_ratio_name(dataset, c)]):.3f}" for c in ("u", "v", "w")
                if _ratio_name(dataset, c)]
        rows.append(row)
    names = "".join(f"<li><b>{_e(name)}</b>: {_e(meaning)}</li>"
                    for name, meaning in TI_NAMES.values())
    return ("<h3>The turbulence intensity the lidar reads</h3>"
            "<p>The lidar's apparent TI against the field's TI over a record, which it is "
            "compared with. The names:</p><ul>" + names + "</ul><p>\u201cSpectral vs "
            "records\u201d: the spectral expectation of TI^2 against the records' mean, in "
            "standard errors of that mean (agree where |z| is within the check's limit, "
            "turbulence_intensity_spectral_z_limit: Student's t at 97.5 % with one degree "
            "of freedom fewer than the records, a 5 % false-alarm rate). The variance ratios are "
            "the lidar's filtered variance of each wind component over the field's at the "
            "reference point (spectral path).</p>" + _table(header, rows))


def _ratio_name(dataset, component):
    name = {"u": "turbulence_intensity_u_ratio", "v": "turbulence_v_ratio",
            "w": "turbulence_w_ratio"}[component]
    return name if name in dataset else None


def _point_intensity(dataset):
    """A function of a scene's index: the field's point TI (swept, or the scenario's)."""
    if "turbulence_intensity" in dataset.dims:
        values = dataset["turbulence_intensity"].values
        return lambda index: float(values[index["turbulence_intensity"]])
    if "turbulence_intensity" in dataset.coords:
        value = float(dataset["turbulence_intensity"])
        return lambda index: value
    value = float(_scenario_section(dataset, "turbulence").get("intensity", np.nan))
    return lambda index: value


def _pc(value):
    value = float(np.asarray(value).reshape(-1)[0]) if np.ndim(value) else float(value)
    return "nan" if not np.isfinite(value) else f"{100 * value:.2f}"


def apparent_ti(true_ti, motion_ti):
    """Turbulence intensity a lidar in motion reports [1] if the motion's scatter of Vh
    added in quadrature to the wind's own TI (independent: the wave phases are not the
    turbulence), sqrt(TI^2 + TI_motion^2); the lidar's filtering of the turbulence is
    left out (record mode computes it)."""
    return np.sqrt(true_ti**2 + np.asarray(motion_ti) ** 2)


def _apparent_ti(dataset, true_ti):
    """A run with motion but no records: the motion's TI increment per scene, and the
    apparent TI for a stated true TI if the two added in quadrature, said for what it is."""
    if "wind_speed_motion_ti" not in dataset or "turbulence_intensity_spectral" in dataset:
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
        "<h3>The motion's turbulence-intensity increment</h3>",
        f"<p><b>Note:</b> {_e(note[0].upper() + note[1:])}.</p>" if note else "",
        "<p>The motion-induced increment is u of Vh from the motion alone over Vh. Added "
        f"in quadrature to a true TI of {100 * true_ti:g} % (<code>--true-ti</code>), "
        "sqrt(TI^2 + TI_motion^2), it gives the last column. That sum leaves out the "
        "lidar's own filtering of the turbulence (probe volume, beam separation), which "
        "lowers its TI by as much as the motion raises it: a <code>turbulence</code> "
        "section (record mode) computes the TI the lidar reads.</p>",
        _table(("correction", "motion-induced TI increment", "sum in quadrature"), rows)])


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


def _outputs(dataset):
    """Per output of the run: its uncertainty budget, the clause 8 verdicts, the paper's
    model against sampling and the bias."""
    out = []
    for quantity in QUANTITY_UNITS:
        if f"{quantity}_gum_u" not in dataset:
            continue
        if not planning.uncertain(dataset, quantity):
            out.append(_no_uncertainty(dataset, quantity))
            continue
        out.append(f"<h3>{_e(_words(quantity)).capitalize()}</h3>")
        if f"{quantity}_budget" in dataset:
            out.append(_budget(dataset, quantity))
        out.append(_clause8(dataset, quantity))
        if planning.disagreement_answer(dataset, quantity) is not None:
            out.append(_disagreement(dataset, quantity))
        if f"{quantity}_true" in dataset and f"{quantity}_nominal" in dataset:
            out.append(_bias(dataset, quantity))
    return "<h2>Each output</h2>" + "\n".join(out) if out else ""


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
    variable = f"{quantity}_gum_u"
    over = "per correction model, each averaged over the other swept keys" if corrections \
        else f"averaged over {extent(dataset, variable)}"
    return (f"<h4>Uncertainty budget</h4><p>Share of the GUM variance, {over}; the first "
            "input dominates.</p>" + _table(header, rows))


def _clause8(dataset, quantity):
    """The clause 8 verdicts counted in words, with delta and the digits, and what a
    refusal means where one is conclusive."""
    if not verdicts.has_verdicts(dataset, quantity) or f"{quantity}_mc_u" not in dataset:
        return ""
    unit = QUANTITY_UNITS[quantity]
    found = verdicts.details(dataset, quantity)
    digits = verdicts.validation_digits(dataset)
    text = (f"<h4>The GUM against Monte Carlo (JCGM 101 clause 8)</h4><p>The GUM's 95 % "
            f"interval y &plusmn; {GUM_COVERAGE_FACTOR:.2f} u against Monte Carlo's, to "
            f"{digits} significant digits of u (delta: half a unit of the last digit): "
            f"{_e(verdicts.counts_text(dataset, quantity))} "
            f"({_e(extent(dataset, f'{quantity}_gum_u'))}).")
    ratio = found["u_ratio"][np.isfinite(found["u_ratio"])]
    if ratio.size:
        text += (f" GUM u over Monte Carlo u: median {np.median(ratio):.4f}, "
                 f"{np.min(ratio):.4f} to {np.max(ratio):.4f}.")
    counts = verdicts.counts(dataset, quantity)
    if counts[verdicts.UNDECIDED]:
        text += (" <i>Undecided</i> means Monte Carlo's own numerical error exceeds delta, "
                 "so this run's trials cannot tell; more trials (or "
                 "<code>sampling.digits</code> with <code>stop_when_gum_valid</code>) "
                 "decide it.")
    refused = np.flatnonzero(found["verdict"].reshape(-1) == verdicts.NOT_VALIDATED)
    if refused.size:
        worst = refused[np.argmax(np.maximum(np.abs(found["d_low"].reshape(-1)[refused]),
                                             np.abs(found["d_high"].reshape(-1)[refused])))]
        index = dict(zip(dataset[f"{quantity}_gum_valid"].dims,
                         np.unravel_index(worst, found["verdict"].shape)))
        at = dataset.isel({d: int(i) for d, i in index.items()})
        text += (f" Where it is not validated, the largest difference is at "
                 f"{_e(where_text(dataset, {d: int(i) for d, i in index.items()}))}: "
                 f"{_e(verdicts.one(at, quantity, unit))}.")
    return text + "</p>"


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
    title = "<h4>The paper's model against sampling</h4>"
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
    text = "<h4>Bias</h4><p>Systematic error of the correction " \
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
            parts.append(f"{gate_words(dataset)} {value:g} m" if dataset is not None
                         else f"range gate {value:g} m")
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
        if f"{quantity}_gum_u" not in dataset:
            continue
        if not planning.uncertain(dataset, quantity):
            out.append(f"<h3>u({_words(quantity)}) [{unit}]</h3><p>none (at most "
                       f"{_ZERO} {unit} in every model)</p>")
            continue
        names = [(label, f"{quantity}_{model}") for model, label in planning.MODEL_NAMES.items()]
        names = [(label, name) for label, name in names
                 if name in dataset and np.isfinite(dataset[name].values).any()]
        if not names:
            continue
        if single:
            gates = np.atleast_1d(dataset["range"].values)
            header = ("model",) + tuple(f"{gate_words(dataset)} {g:g} m" for g in gates)
            rows = [(label + beam,) + tuple(_number(v) for v in np.atleast_1d(values))
                    for label, name in names
                    for beam, values in _per_beam(dataset, dataset[name])]
        else:
            header = ("model", "min", "median", "max", "outside the model")
            rows = [(label, _number(np.nanmin(v)), _number(np.nanmedian(v)),
                     _number(np.nanmax(v)), f"{int(np.isnan(v).sum())} of {v.size}")
                    for label, name in names for v in [dataset[name].values]]
            header = header[:-1] + (f"outside the model (of {extent(dataset, names[0][1])})",)
        out += [f"<h3>u({_words(quantity)}) [{unit}]</h3>", _table(header, rows)]
    return "\n".join(out)


def _scene_tables(dataset):
    """Per output, a row per scene and range gate under its swept values: u, the 95 %
    interval, the bias, the clause 8 verdict with its numbers and, for the wind speed of
    a run with motion, the motion's TI increment. Beyond MAX_TABLE_ROWS rows, the rows
    with the largest u, in sweep order, and how many are left out."""
    out = []
    for quantity in QUANTITY_UNITS:
        if f"{quantity}_gum_u" not in dataset or "beam" in dataset[f"{quantity}_gum_u"].dims \
                or not planning.uncertain(dataset, quantity):
            continue
        unit = QUANTITY_UNITS[quantity]
        columns = _scene_columns(dataset, quantity, unit)
        has_gates = "range" in dataset[f"{quantity}_gum_u"].dims
        indices = scene_indices(dataset, gates=has_gates)
        header = [_key_header(dataset, d) for d in indices[0]] + [n for n, _ in columns]
        shown, note = _shown_rows(dataset, quantity, indices)
        rows = []
        for index in shown:
            at = dataset.isel(index)
            rows.append([_e(v) for _, v in scene_values(dataset, index)]
                        + [cell(at) for _, cell in columns])
        out += [f"<h3>{_e(_words(quantity)).capitalize()}</h3>", note, _table(header, rows)]
    if not out:
        return ""
    return ("<h2>Scene by scene</h2><p>u: Monte Carlo where sampled, else the GUM; the "
            "95 % interval likewise (the GUM's y &plusmn; 1.96 u); bias: Monte Carlo mean "
            "minus true (else the error-free reconstruction minus true); clause 8: the "
            "verdict, then delta and the GUM's minus Monte Carlo's interval ends.</p>"
            + "\n".join(part for part in out if part))


def _shown_rows(dataset, quantity, indices):
    """The rows of a scene table (all, or the MAX_TABLE_ROWS with the largest u in sweep
    order) and a sentence saying what is left out ('' when nothing is)."""
    if len(indices) <= MAX_TABLE_ROWS:
        return indices, ""
    u, _ = planning.scene_uncertainty(dataset, quantity)
    values = np.array([float(u.isel({d: i for d, i in index.items() if d in u.dims}))
                       for index in indices])
    keep = np.sort(np.argsort(-np.nan_to_num(values, nan=-np.inf))[:MAX_TABLE_ROWS])
    return [indices[k] for k in keep], (
        f"<p>{MAX_TABLE_ROWS} of {len(indices)} rows (scenes x {gate_words(dataset)}s): "
        "those with the largest u, in sweep order; <code>uq export</code> lists every "
        "one.</p>")


def _scene_columns(dataset, quantity, unit):
    """(header, cell function of one scene and gate) of an output's scene table."""
    sampled = f"{quantity}_mc_u" in dataset
    u_name = f"{quantity}_mc_u" if sampled else f"{quantity}_gum_u"
    columns = [(f"u [{unit}]", lambda at: _number(float(at[u_name]))),
               (f"95 % interval [{unit}]", lambda at: _interval(at, quantity, sampled)),
               (f"bias [{unit}]", lambda at: _scene_bias(at, quantity))]
    if sampled and verdicts.has_verdicts(dataset, quantity):
        columns.append(("clause 8", lambda at: _verdict_cell(at, quantity)))
    if quantity == "wind_speed" and "wind_speed_motion_ti" in dataset:
        columns.append(("TI increment from motion",
                        lambda at: f"{100 * float(at['wind_speed_motion_ti']):.2f} %"))
    return columns


#: The class (colour) of each clause 8 verdict in the report.
VERDICT_CLASS = {verdicts.VALIDATED: "yes", verdicts.NOT_VALIDATED: "no",
                 verdicts.UNDECIDED: "undecided"}


def _verdict_cell(at, quantity):
    found = {k: np.asarray(v).reshape(-1)[0] for k, v in verdicts.details(at, quantity).items()}
    word = str(found["verdict"])
    return (f"<span class='{VERDICT_CLASS[word]}'>{word}</span>; delta "
            f"{found['delta']:.2g}; ends {found['d_low']:+.2g}, {found['d_high']:+.2g}")


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
