"""The scenes of a result and their names, for tables that list them (no numbers made).

A result has one dimension per swept scenario key (named by the dotted key with ``.``
replaced by ``_``) and, with several range gates, a ``range`` dimension. Tables name a
scene by its swept values under the dotted keys the user wrote (``turbulence.intensity``,
not the dimension ``turbulence_intensity``, which an output of the same name would
shadow).
"""
import numpy as np
import yaml


def sweep_dimensions(dataset):
    """The sweep dimensions of a result, in file order."""
    return tuple(dataset["mc_n_samples"].dims)


def swept_keys(dataset):
    """``{dimension: dotted key}`` of the swept keys, in file order (a dimension whose
    key the scenario does not name keeps its own name)."""
    try:
        sweep = (yaml.safe_load(dataset.attrs.get("scenario", "")) or {}).get("sweep") or {}
    except yaml.YAMLError:
        sweep = {}
    by_dimension = {key.replace(".", "_"): key for key in sweep}
    return {dim: by_dimension.get(dim, dim) for dim in sweep_dimensions(dataset)}


def scene_count(dataset):
    """Number of scenes (1 without a sweep)."""
    return int(np.prod([dataset.sizes[d] for d in sweep_dimensions(dataset)], dtype=int))


def scene_indices(dataset, gates=False):
    """Every scene as ``{dimension: index}``, in the sweep's order (the last key fastest);
    with `gates`, every scene and range gate (``range`` last) where there are gates."""
    dims = list(sweep_dimensions(dataset))
    if gates and "range" in dataset.dims:
        dims.append("range")
    return [dict(zip(dims, index)) for index in np.ndindex(*[dataset.sizes[d] for d in dims])]


def value_text(value):
    """A coordinate's value as a table writes it (``%g`` for numbers)."""
    value = value.item() if hasattr(value, "item") else value
    if isinstance(value, bytes):
        value = value.decode()
    return f"{value:g}" if isinstance(value, (int, float)) and not isinstance(value, bool) \
        else str(value)


def gate_words(dataset):
    """What a range gate is called: a nacelle lidar's (a tilted mount, ``lidar.mount``)
    is a preview distance along its boresight, an upward lidar's a range gate."""
    try:
        lidar = (yaml.safe_load(dataset.attrs.get("scenario", "")) or {}).get("lidar") or {}
    except yaml.YAMLError:
        lidar = {}
    tilt = (lidar.get("mount") or {}).get("tilt", 0) if isinstance(lidar, dict) else 0
    return "preview distance" if tilt else "range gate"


def scene_values(dataset, index):
    """``[(dotted key or "range gate [m]", value text), ...]`` of one scene (and gate)."""
    keys = swept_keys(dataset)
    return [(f"{gate_words(dataset)} [m]" if dim == "range" else keys[dim],
             value_text(dataset[dim].values[position])) for dim, position in index.items()]


def where_text(dataset, index):
    """``wind.direction = 90, range gate 80 m``: a scene (and gate) in words."""
    gate = f"{gate_words(dataset)} [m]"
    parts = [f"{gate[:-4]} {value} m" if key == gate else f"{key} = {value}"
             for key, value in scene_values(dataset, index)]
    return ", ".join(parts) or "the one scene"
