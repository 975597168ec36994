"""Compact text summary of a results Dataset (printed by ``uq run``)."""
import numpy as np

from uq.pipeline.metadata import QUANTITIES

_COLUMNS = ("true", "nominal", "mc_mean", "mc_u", "gum_u", "paper_u")
_VALUES = ("true", "nominal", "mc_mean")


def summary_table(dataset):
    """A few lines: per output (and gate), each column's value or min..max over the sweep.

    The last column counts the scenes whose GUM interval is validated (JCGM 101 clause 8)
    and, in brackets, those where Monte Carlo was precise enough for the verdict to be
    conclusive (its numerical error within the tolerance).
    """
    lines = [f"{dataset.attrs.get('title', '')}  (n = {dataset.attrs.get('n_samples')}, "
             f"seed = {dataset.attrs.get('seed')}, {dataset.attrs.get('runtime_s', 0):.1f} s)"]
    header = f"{'output':<22}" + "".join(f"{c:>16}" for c in _COLUMNS) + f"{'GUM valid':>14}"
    lines.append(header)
    for q in QUANTITIES:
        if f"{q}_mc_u" not in dataset or q == "radial_velocity":
            continue
        gates = dataset["range"].values.reshape(-1) if "range" in dataset[f"{q}_mc_u"].dims else [None]
        for gate in gates:
            select = {} if gate is None else {"range": gate}
            label = q if gate is None else f"{q} @{gate:g} m"
            cells = [_cell(dataset[f"{q}_{c}"].sel(select).values, c) for c in _COLUMNS]
            valid = dataset[f"{q}_gum_valid"].sel(select).values
            conclusive = dataset[f"{q}_gum_validation_conclusive"].sel(select).values
            verdict = f"{int(np.sum(valid))}/{np.size(valid)} ({int(np.sum(conclusive))})"
            lines.append(f"{label:<22}" + "".join(f"{c:>16}" for c in cells) + f"{verdict:>14}")
    units = ", ".join(f"{q} [{attrs['units']}]" for q, attrs in QUANTITIES.items())
    lines.append(f"units: {units}")
    return "\n".join(lines)


def _cell(values, column):
    values = np.asarray(values, dtype=float).reshape(-1)
    if np.all(np.isnan(values)):
        return "nan"
    low, high = np.nanmin(values), np.nanmax(values)
    if np.isclose(low, high, rtol=1e-6, atol=1e-12):
        return f"{low:.4g}"
    return "swept" if column in _VALUES else f"{low:.3g}..{high:.3g}"
