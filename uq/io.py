"""Reading and writing results (netCDF4). No physics here.

Files are written atomically: to a temporary file in the target folder, then renamed, so
a failed or interrupted run never leaves a partial file behind.
"""
import os
import tempfile
from pathlib import Path

import xarray as xr


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
