"""A results file as a table: one row per scene and range gate, one column per variable
with its unit in the header (``uq export``). No physics.

The rows are the scenes of the sweep (the dimensions of ``mc_n_samples``) times the
range gates (``range``, where the run has several gates); the first columns are their
coordinates. Every variable along those dimensions is a column; a variable with a
dimension of its own (``beam``, the budget's ``input``, a covariance's ``range_other``)
gives a column per value of it, ``name[dim=value]``. A header reads ``name [units]``.
Above the header, comment lines (``#``) say where the table comes from; they carry
:data:`uq.files.SIGNATURE`, the mark that lets uq replace its own table later
(``pandas.read_csv(path, comment="#")`` reads the table).
"""
import numpy as np

from uq._version import __version__
from uq.errors import DataFileError
from uq.files import SIGNATURE

#: Most cells (rows x columns) a table may have [1]; counted before it is built. 10^8
#: cells are ~2 GB of CSV text: larger sweeps are exported in parts with ``--select``.
MAX_TABLE_CELLS = 100_000_000
#: The gate dimension of a results file.
GATE = "range"


def row_dimensions(dataset):
    """The dimensions of a row: the sweep's (those of ``mc_n_samples``), then ``range``."""
    dims = list(dataset["mc_n_samples"].dims)
    if GATE in dataset.dims and GATE not in dims:
        dims.append(GATE)
    return dims


def table_size(dataset):
    """(rows, columns) of :func:`results_table` of `dataset`, counted without building it."""
    dims = row_dimensions(dataset)
    rows = int(np.prod([dataset.sizes[d] for d in dims])) if dims else 1
    columns = len(dims) + sum(1 for name in dataset.coords if name not in dims
                              and set(dataset[name].dims) <= set(dims))
    for variable in dataset.data_vars.values():
        extra = [d for d in variable.dims if d not in dims]
        columns += int(np.prod([dataset.sizes[d] for d in extra])) if extra else 1
    return rows, columns


def results_table(dataset, source=""):
    """The table of `dataset` (a pandas DataFrame, headers ``name [units]``). Refuses
    (DataFileError naming `source`) a table of more than MAX_TABLE_CELLS cells."""
    import pandas as pd
    rows, columns = table_size(dataset)
    if rows * columns > MAX_TABLE_CELLS:
        raise DataFileError(source, "", f"its table would have {rows} rows x {columns} "
                            f"columns; allowed: at most {MAX_TABLE_CELLS:.0e} cells (export "
                            "parts of the sweep with --select DIM=VALUE)")
    dims = row_dimensions(dataset)
    shape = tuple(dataset.sizes[d] for d in dims)
    index = np.indices(shape).reshape(len(dims), -1) if dims else np.zeros((0, 1), int)
    columns = {}
    for position, dim in enumerate(dims):
        columns[header(dim, dataset[dim] if dim in dataset.coords else None)] = (
            dataset[dim].values[index[position]] if dim in dataset.coords
            else index[position])
    labels = [name for name in dataset.coords if set(dataset[name].dims) <= set(dims)]
    for name in labels + list(dataset.data_vars):
        if name in dims:
            continue
        for label, values in _columns(dataset[name], dims, shape):
            columns[header(label, dataset[name])] = values
    return pd.DataFrame(columns)


def _columns(variable, dims, shape):
    """(label, values per row) of `variable`: one, or one per value of its own dims."""
    own = [d for d in variable.dims if d not in dims]
    ordered = variable.transpose(*[d for d in dims if d in variable.dims], *own)
    if not own:
        yield variable.name, _broadcast(ordered, dims, shape)
        return
    for position in np.ndindex(*ordered.shape[len(ordered.dims) - len(own):]):
        part = ordered[(Ellipsis, *position)]
        label = ",".join(f"{d}={_value(variable, d, i)}" for d, i in zip(own, position))
        yield f"{variable.name}[{label}]", _broadcast(part, dims, shape)


def _value(variable, dim, i):
    """The coordinate value `i` of `dim` as text (the index where there is none)."""
    if dim in variable.coords:
        value = variable.coords[dim].values[i]
        return value.item() if hasattr(value, "item") else value
    return i


def _broadcast(variable, dims, shape):
    """The values of `variable` (dims a subset of `dims`) repeated over the rows."""
    present = [d for d in dims if d in variable.dims]
    values = np.asarray(variable.transpose(*present).values)
    expanded = values.reshape([shape[i] if d in present else 1 for i, d in enumerate(dims)])
    return np.broadcast_to(expanded, shape).reshape(-1)


def header(name, variable=None):
    """``name [units]`` (just the name where the variable has no units)."""
    units = None if variable is None else variable.attrs.get("units")
    return f"{name} [{units}]" if units else str(name)


def table_text(dataset, source):
    """The CSV text of the table: comment lines naming its origin, then the table."""
    table = results_table(dataset, source)
    comment = (f"# {SIGNATURE} {__version__} from {source} (scenario "
               f"{dataset.attrs.get('scenario_name', _scenario_name(dataset))}); one row "
               f"per scene and range gate; read with pandas.read_csv(path, comment='#')\n")
    return comment + table.to_csv(index=False)


def _scenario_name(dataset):
    """The scenario's name, from the YAML text recorded in the results."""
    import yaml
    try:
        scenario = yaml.safe_load(dataset.attrs.get("scenario", "")) or {}
    except yaml.YAMLError:
        return "?"
    return scenario.get("name", "?") if isinstance(scenario, dict) else "?"
