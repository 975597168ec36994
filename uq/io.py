"""Reading and writing results (netCDF4). No physics here.

Files are written atomically: to a temporary file in the target folder, then renamed, so
a failed or interrupted run never leaves a partial file behind.
"""
import os
import tempfile
from pathlib import Path

import xarray as xr

from .errors import ScenarioError


def write_results(dataset, path):
    """Write `dataset` to netCDF4 at `path` atomically; returns the path."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    handle, temporary = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".part",
                                         dir=path.parent)
    os.close(handle)
    try:
        dataset.to_netcdf(temporary, format="NETCDF4", engine="netcdf4")
        os.replace(temporary, path)
    except BaseException:
        Path(temporary).unlink(missing_ok=True)
        raise
    return path


def read_results(path):
    """Open a results file fully into memory (the file is closed afterwards)."""
    with xr.open_dataset(path, engine="netcdf4") as dataset:
        return dataset.load()


def open_results(path):
    """Results of ``uq run`` at `path`, or ScenarioError (bad input: exit 2) naming it."""
    try:
        dataset = read_results(path)
    except (OSError, ValueError) as error:
        raise ScenarioError(str(path), "", f"cannot read it as netCDF results ({error}); "
                            "allowed: a file written by uq run") from None
    if "mc_n_samples" not in dataset or "scenario" not in dataset.attrs:
        raise ScenarioError(str(path), "", "not a uq results file (no mc_n_samples variable "
                            "or scenario attribute); allowed: a file written by uq run")
    return dataset
