"""Compact text summary of a results Dataset (printed by ``uq run``)."""
import numpy as np

from uq.constants import FULL_CIRCLE_DEG, NUMERICAL_ZERO
from uq.outputs.planning import fixed_phase_note
from uq.pipeline.metadata import QUANTITIES

_COLUMNS = ("true", "nominal", "mc_mean", "mc_u", "gum_u", "paper_u")
_VALUES = ("true", "nominal", "mc_mean")
#: Directions this close below 360 deg would print as "360" at four significant digits
#: (half a unit of the fourth digit) [deg]: they are shown as the small negative angle.
DIRECTION_ROUNDING = 0.05
#: Space between columns [characters].
_GAP = 3


def summary_table(dataset, compile_s=0.0):
    """A few lines: per output (and gate), each column's value or min..max over the sweep.

    Columns with no value anywhere (the paper's model outside its domain, Monte Carlo
    when it did not run) are left out; widths follow the content, so cells never run
    together. The last column counts the scenes whose GUM interval Monte Carlo validates
    (JCGM 101 clause 8) out of all scenes, and in brackets those where Monte Carlo was
    precise enough for that verdict to be conclusive; a footnote says so. `compile_s`:
    seconds of the run's time spent compiling kernels (said in the title when > 0).
    """
    compiled = f", of which {compile_s:.1f} s compiling kernels" if compile_s > 0 else ""
    title = (f"{dataset.attrs.get('title', '')}  (n = {dataset.attrs.get('n_samples')}, "
             f"seed = {dataset.attrs.get('seed')}, {dataset.attrs.get('runtime_s', 0):.1f} s"
             f"{compiled})")
    rows, shown = [], []
    for q in QUANTITIES:
        if f"{q}_gum_u" not in dataset or q == "radial_velocity":
            continue
        shown.append(q)
        gates = dataset["range"].values.reshape(-1) if "range" in dataset[f"{q}_gum_u"].dims \
            else [None]
        for gate in gates:
            select = {} if gate is None else {"range": gate}
            label = q if gate is None else f"{q} @{gate:g} m"
            cells = {c: _cell(_shown(dataset[f"{q}_{c}"].sel(select).values, q, c), c)
                     if f"{q}_{c}" in dataset else "nan" for c in _COLUMNS}
            cells["GUM valid"] = _verdict(dataset, q, select)
            rows.append((label, cells))
    columns = [c for c in _COLUMNS if any(cells[c] != "nan" for _, cells in rows)]
    columns.append("GUM valid")
    lines = [title] + _table(rows, columns)
    lines += _motion_line(dataset)
    lines += _record_lines(dataset)
    units = ", ".join(f"{q} [{QUANTITIES[q]['units']}]" for q in shown)
    lines.append(f"units: {units}")
    lines.append("GUM valid: scenes whose GUM interval Monte Carlo validates (JCGM 101 "
                 "clause 8) / scenes; (n): of those verdicts, n were conclusive")
    return "\n".join(lines)


def _table(rows, columns):
    width = {"output": max([len("output")] + [len(label) for label, _ in rows])}
    for c in columns:
        width[c] = max([len(c)] + [len(cells[c]) for _, cells in rows])
    gap = " " * _GAP
    header = "output".ljust(width["output"]) + "".join(gap + c.rjust(width[c]) for c in columns)
    lines = [header]
    for label, cells in rows:
        lines.append(label.ljust(width["output"])
                     + "".join(gap + cells[c].rjust(width[c]) for c in columns))
    return lines


def _verdict(dataset, q, select):
    if f"{q}_gum_valid" not in dataset or f"{q}_mc_u" not in dataset:   # no Monte Carlo
        return "nan"
    valid = dataset[f"{q}_gum_valid"].sel(select).values
    conclusive = dataset[f"{q}_gum_validation_conclusive"].sel(select).values
    return f"{int(np.sum(valid))}/{np.size(valid)} ({int(np.sum(conclusive))})"


def _motion_line(dataset):
    if "wind_speed_motion_ti" not in dataset:
        return []
    ti = _cell(100 * dataset["wind_speed_motion_ti"].values, "mc_u")
    note = fixed_phase_note(dataset)
    return [f"motion-induced turbulence-intensity increment [%]: {ti}"
            + (f" ({note})" if note else "")]


def _record_lines(dataset):
    """Record mode: per gate the true, spectral and Monte Carlo TI [%] (min..max over a
    sweep), and the scenes where the records validate the spectral path."""
    if "turbulence_intensity_spectral" not in dataset:
        return []
    true = _cell(100 * dataset["turbulence_intensity_true"].values, "mc_u")
    lines = [f"turbulence intensity over a record [%]: true {true}"]
    spectral = dataset["turbulence_intensity_spectral"]
    gates = dataset["range"].values.reshape(-1) if "range" in spectral.dims else [None]
    for gate in gates:
        select = {} if gate is None else {"range": gate}
        text = f"  apparent{'' if gate is None else f' @{gate:g} m'}: spectral " + \
            _cell(100 * spectral.sel(select).values, "mc_u")
        if "turbulence_intensity_mc_mean" in dataset:
            valid = dataset["turbulence_intensity_spectral_valid"].sel(select).values
            text += (f", Monte Carlo {_cell(100 * dataset['turbulence_intensity_mc_mean'].sel(select).values, 'mc_u')}"
                     f" (95 % of records {_cell(100 * dataset['turbulence_intensity_mc_low'].sel(select).values, 'mc_u')}"
                     f" to {_cell(100 * dataset['turbulence_intensity_mc_high'].sel(select).values, 'mc_u')});"
                     f" spectral validated {int(np.sum(valid))}/{np.size(valid)}")
        lines.append(text)
        if "turbulence_v_ratio" in dataset:
            ratios = ", ".join(
                f"{c} {_cell(dataset[name].sel(select).values, 'mc_u')}" for c, name in (
                    ("u", "turbulence_intensity_u_ratio"), ("v", "turbulence_v_ratio"),
                    ("w", "turbulence_w_ratio")))
            lines.append(f"    variance ratios lidar / field: {ratios}")
    return lines


def _shown(values, quantity, column):
    """A direction in [0, 360) within DIRECTION_ROUNDING of 360 [deg] is shown as the
    small negative angle it is (359.9999999 and 0.0000001 are not two values)."""
    if quantity != "wind_direction" or column not in _VALUES:
        return values
    values = np.asarray(values, dtype=float)
    return np.where(values > FULL_CIRCLE_DEG - DIRECTION_ROUNDING, values - FULL_CIRCLE_DEG,
                    values)


def _cell(values, column):
    values = np.asarray(values, dtype=float).reshape(-1)
    if np.all(np.isnan(values)):
        return "nan"
    low, high = np.nanmin(values), np.nanmax(values)
    if np.isclose(low, high, rtol=1e-6, atol=NUMERICAL_ZERO) or _number(low) == _number(high):
        return _number(low)                     # (the same at the digits shown)
    return "swept" if column in _VALUES else f"{_number(low)}..{_number(high)}"


def _number(value):
    """Four significant digits; rounding noise (below NUMERICAL_ZERO) is 0."""
    return "0" if abs(value) < NUMERICAL_ZERO else f"{value:.4g}"
