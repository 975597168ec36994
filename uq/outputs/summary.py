"""Compact text summary of a results Dataset (printed by ``uq run``).

Per output a table: with at most :data:`MAX_SCENE_ROWS` scenes, one row per scene (and
range gate) under its swept values, so that every number says which scene it belongs
to; with more, one row per range gate whose cells give the smallest and largest value
over the scenes and where each occurs. The clause 8 column gives each scene's verdict
(or the verdicts counted) in the words of :mod:`uq.outputs.verdicts`. Record mode adds
the turbulence intensities, each named for what it is (:data:`TI_COLUMNS`).
"""
import numpy as np

from uq.constants import FULL_CIRCLE_DEG, NUMERICAL_ZERO
from uq.outputs import verdicts
from uq.outputs.planning import fixed_phase_note
from uq.outputs.planning import uncertain as planning_uncertain
from uq.outputs.scenes import (gate_words, scene_count, scene_indices, scene_values, sweep_dimensions,
                               swept_keys, where_text)
from uq.pipeline.metadata import QUANTITIES

_COLUMNS = ("true", "nominal", "mc_mean", "mc_u", "gum_u", "paper_u")
_VALUES = ("true", "nominal", "mc_mean")
#: Most scenes listed one row each; beyond, each column's extent and where it occurs.
MAX_SCENE_ROWS = 12
#: Directions this close below 360 deg would print as "360" at four significant digits
#: (half a unit of the fourth digit) [deg]: they are shown as the small negative angle.
DIRECTION_ROUNDING = 0.05
#: Space between columns [characters].
_GAP = 3
#: Record mode's turbulence intensities [%], header -> variable (the field's point TI,
#: the scenario's ``turbulence.intensity``, comes first). Over a ten-minute record the
#: field's TI is lower than its point TI (a record does not see the slowest eddies): the
#: lidar's apparent TI is compared with that one. The lidar's: the spectral path's
#: expectation, and the Monte Carlo records' mean with the 2.5 and 97.5 % points of the
#: records; beside them the records' own field TI (what the simulated field carried).
TI_COLUMNS = {"field record": "turbulence_intensity_true",
              "lidar spectral": "turbulence_intensity_spectral",
              "lidar records": "turbulence_intensity_mc_mean",
              "records 2.5 %": "turbulence_intensity_mc_low",
              "records 97.5 %": "turbulence_intensity_mc_high",
              "records' field": "turbulence_intensity_true_mc_mean"}
#: The TI table's legend.
TI_LEGEND = ("turbulence intensity [%]: field point = the scenario's turbulence.intensity; "
             "field record = the field's TI over a record, which the lidar's is compared "
             "with; lidar spectral = the lidar's apparent TI, expected (spectral path); "
             "lidar records = its mean over the Monte Carlo records, with the records' "
             "2.5 and 97.5 % points; records' field = the field's TI in those records")


def summary_table(dataset, compile_s=0.0):
    """The summary's lines (one string). `compile_s`: seconds of the run's time spent
    compiling kernels (said in the title when > 0)."""
    lines = [_title(dataset, compile_s)]
    per_scene = scene_count(dataset) <= MAX_SCENE_ROWS
    shown = []
    for q in QUANTITIES:
        if f"{q}_gum_u" not in dataset or q == "radial_velocity":
            continue
        shown.append(q)
        lines += [""] + _output_table(dataset, q, per_scene)
    lines += _record_table(dataset, per_scene)
    lines += _motion_note(dataset)
    units = ", ".join(f"{q} [{QUANTITIES[q]['units']}]" for q in shown)
    lines += ["", f"units: {units}" + ("; turbulence intensities [%]"
                                        if "turbulence_intensity_spectral" in dataset else "")]
    if any(verdicts.has_verdicts(dataset, q) for q in shown):
        lines.append("clause 8: JCGM 101's check of the GUM's 95 % interval against Monte "
                     f"Carlo's to {verdicts.validation_digits(dataset)} significant digits "
                     "of u: validated, not validated, or "
                     "undecided (Monte Carlo's numerical error above the check's tolerance: "
                     "more trials decide it; `uq report` gives the numbers)")
    if not per_scene:
        lines.append(f"{scene_count(dataset)} scenes: each statistic's smallest and largest "
                     "value over them, with the scene of each (`uq export` lists every "
                     "scene)")
    return "\n".join(lines)


def _title(dataset, compile_s):
    attrs = dataset.attrs
    compiled = f", of which {compile_s:.1f} s compiling kernels" if compile_s > 0 else ""
    keys = " x ".join(swept_keys(dataset).values())
    scenes = scene_count(dataset)
    sweep = f"{scenes} scenes ({keys}), " if keys else ""
    return (f"{attrs.get('title', '')}  ({sweep}n = {attrs.get('n_samples')}, "
            f"seed = {attrs.get('seed')}, {attrs.get('runtime_s', 0):.1f} s{compiled})")


def _output_table(dataset, q, per_scene):
    """The lines of output `q`: a row per scene and gate, or per gate the extents."""
    uncertain = planning_uncertain(dataset, q)
    judged = uncertain and verdicts.has_verdicts(dataset, q)
    has_gates = "range" in dataset[f"{q}_gum_u"].dims
    if not per_scene:
        return _extent_lines(dataset, q, judged, has_gates)
    columns = [c for c in _COLUMNS if _has_values(dataset, f"{q}_{c}")]
    found = verdicts.details(dataset, q) if judged else None
    indices = scene_indices(dataset, gates=has_gates)
    rows = []
    for index in indices:
        cells = dict(scene_values(dataset, index))
        cells.update({c: _number(_shown(_at(dataset[f"{q}_{c}"], index), q, c))
                      for c in columns})
        if judged:
            cells["clause 8"] = str(found["verdict"][_position(dataset, q, index)])
        rows.append(cells)
    keys = [key for key, _ in scene_values(dataset, indices[0])]
    header = keys + columns + (["clause 8"] if judged else [])
    return [q + ("" if uncertain else " (no uncertainty in any scene)")] + _table(rows, header)


#: Statistics whose extent over many scenes the summary gives (the values themselves
#: follow the swept keys).
_EXTENT_COLUMNS = ("mc_bias", "mc_u", "gum_u", "paper_u")


def _extent_lines(dataset, q, judged, has_gates):
    """Over many scenes: per gate, each statistic's smallest and largest value and the
    scene of each, and the clause 8 verdicts counted."""
    lines = []
    for gate in (range(dataset.sizes["range"]) if has_gates else [None]):
        at = dataset if gate is None else dataset.isel(range=gate)
        title = q if gate is None else \
            f"{q} at {gate_words(dataset)} {float(at['range']):g} m"
        rows = []
        for column in _EXTENT_COLUMNS:
            name = f"{q}_{column}"
            if not _has_values(at, name):
                continue
            values = np.asarray(at[name].values, dtype=float)
            low, high = np.nanargmin(values), np.nanargmax(values)
            rows.append({"statistic": column,
                         "smallest": _number(values.reshape(-1)[low]),
                         "in the scene": _scene_of(at, at[name], low),
                         "largest": _number(values.reshape(-1)[high]),
                         "in the scene ": _scene_of(at, at[name], high)})
        lines += [title] + _table(rows, ["statistic", "smallest", "in the scene", "largest",
                                         "in the scene "])
        if judged:
            lines.append(f"clause 8: {verdicts.counts_text(at, q)}")
    return lines


def _has_values(dataset, name):
    return name in dataset and \
        np.isfinite(np.asarray(dataset[name].values, dtype=float)).any()


def _scene_of(dataset, variable, flat):
    """The scene (swept values) of a flat index into `variable`."""
    index = dict(zip(variable.dims, np.unravel_index(flat, variable.shape)))
    return where_text(dataset, {d: int(i) for d, i in index.items()
                                if d in sweep_dimensions(dataset)})


def _position(dataset, q, index):
    """Index tuple into ``q``'s arrays (their dimension order) of one scene and gate."""
    dims = dataset[f"{q}_gum_u"].dims
    return tuple(index.get(d, 0) for d in dims)


def _at(variable, index):
    return float(variable.isel({d: i for d, i in index.items() if d in variable.dims}))


def _record_table(dataset, per_scene):
    """Record mode: the turbulence intensities of each scene (and gate) [%], and the
    check of the spectral path against the records."""
    if "turbulence_intensity_spectral" not in dataset:
        return []
    present = {header: name for header, name in TI_COLUMNS.items() if name in dataset}
    valid = dataset.get("turbulence_intensity_spectral_valid")
    spectral = dataset["turbulence_intensity_spectral"]
    has_gates = "range" in spectral.dims
    lines = ["", TI_LEGEND]
    if per_scene:
        rows = []
        for index in scene_indices(dataset, gates=has_gates):
            cells = dict(scene_values(dataset, index))
            cells["field point"] = _number(100 * _point_ti(dataset, index))
            cells.update({h: _number(100 * _at(dataset[n], index)) for h, n in present.items()})
            if valid is not None:
                cells["spectral vs records"] = "agree" if bool(valid.isel(
                    {d: i for d, i in index.items() if d in valid.dims})) else "differ"
            rows.append(cells)
        keys = [key for key, _ in scene_values(dataset, scene_indices(
            dataset, gates=has_gates)[0])]
    else:
        gate_key = f"{gate_words(dataset)} [m]"
        rows, keys = [], ([gate_key] if has_gates else [])
        for gate in (range(dataset.sizes["range"]) if has_gates else [None]):
            at = dataset if gate is None else dataset.isel(range=gate)
            cells = {} if gate is None else {gate_key: f"{float(at['range']):g}"}
            cells.update({h: _percent_extent(at, n) for h, n in present.items()})
            if valid is not None:
                v = at["turbulence_intensity_spectral_valid"].values
                cells["spectral vs records"] = f"agree {int(np.sum(v))} of {np.size(v)}"
            rows.append(cells)
    header = keys + (["field point"] if per_scene else []) + list(present) + (
        ["spectral vs records"] if valid is not None else [])
    return lines + _table(rows, header) + _component_lines(dataset)


def _component_lines(dataset):
    """Record mode: the lidar's u, v and w variance ratios (its filtered turbulence over
    the field's, spectral path) per gate, min..max over a sweep."""
    if "turbulence_v_ratio" not in dataset:
        return []
    ratio = dataset["turbulence_v_ratio"]
    lines = ["", "variance ratio lidar / field (spectral path) [1]:"]
    for gate in (range(dataset.sizes["range"]) if "range" in ratio.dims else [None]):
        at = dataset if gate is None else dataset.isel(range=gate)
        where = "" if gate is None else f"{gate_words(dataset)} {float(at['range']):g} m: "
        lines.append("  " + where + ", ".join(
            f"{component} {_extent(at, name)}" for component, name in (
                ("u", "turbulence_intensity_u_ratio"), ("v", "turbulence_v_ratio"),
                ("w", "turbulence_w_ratio"))))
    return lines


def _extent(dataset, name, scale=1.0):
    """'low..high' of the variable `name` times `scale` ('nan' where all are NaN)."""
    values = scale * np.asarray(dataset[name].values, dtype=float)
    if np.all(np.isnan(values)):
        return "nan"
    low, high = np.nanmin(values), np.nanmax(values)
    return _number(low) if _same(low, high) else f"{_number(low)}..{_number(high)}"


def _point_ti(dataset, index):
    """The field's point TI of a scene: the swept ``turbulence.intensity``, else the
    scenario's."""
    if "turbulence_intensity" in index:
        return float(dataset["turbulence_intensity"].values[index["turbulence_intensity"]])
    import yaml
    raw = yaml.safe_load(dataset.attrs.get("scenario", "")) or {}
    return float((raw.get("turbulence") or {}).get("intensity", np.nan))


def _percent_extent(dataset, name):
    return _extent(dataset, name, scale=100.0)


def _motion_note(dataset):
    if "wind_speed_motion_ti" not in dataset:
        return []
    note = fixed_phase_note(dataset)
    ti = _percent_extent(dataset, "wind_speed_motion_ti")
    return ["", f"motion-induced turbulence-intensity increment [%]: {ti}"
            + (f" ({note})" if note else "")
            + ("" if note else " (u of the wind speed from the motion alone over the "
               "speed; it adds to the lidar's own TI in quadrature only where the "
               "turbulence is not filtered: record mode gives the lidar's TI)")]


def _table(rows, columns):
    width = {c: max([len(c)] + [len(cells.get(c, "")) for cells in rows]) for c in columns}
    gap = " " * _GAP
    lines = [gap.join(c.rjust(width[c]) if i else c.ljust(width[c])
                      for i, c in enumerate(columns))]
    for cells in rows:
        lines.append(gap.join(cells.get(c, "").rjust(width[c]) if i else
                              cells.get(c, "").ljust(width[c]) for i, c in enumerate(columns)))
    return lines


def _shown(values, quantity, column):
    """A direction in [0, 360) within DIRECTION_ROUNDING of 360 [deg] is shown as the
    small negative angle it is (359.9999999 and 0.0000001 are not two values)."""
    if quantity != "wind_direction" or column not in _VALUES:
        return values
    values = np.asarray(values, dtype=float)
    return np.where(values > FULL_CIRCLE_DEG - DIRECTION_ROUNDING, values - FULL_CIRCLE_DEG,
                    values)


def _same(low, high):
    """Equal at the digits shown (or within rounding)."""
    return bool(np.isclose(low, high, rtol=1e-6, atol=NUMERICAL_ZERO)) or \
        _number(low) == _number(high)


def _cell(values, column):
    """One value, or ``min..max`` (``swept`` for a value column) over `values`."""
    values = np.asarray(values, dtype=float).reshape(-1)
    if np.all(np.isnan(values)):
        return "nan"
    low, high = np.nanmin(values), np.nanmax(values)
    if _same(low, high):
        return _number(low)
    return "swept" if column in _VALUES else f"{_number(low)}..{_number(high)}"


def _number(value):
    """Four significant digits; rounding noise (below NUMERICAL_ZERO) is 0."""
    value = float(np.asarray(value).reshape(-1)[0]) if np.ndim(value) else float(value)
    if np.isnan(value):
        return "nan"
    return "0" if abs(value) < NUMERICAL_ZERO else f"{value:.4g}"
