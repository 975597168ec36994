"""Reading results files (netCDF4). No physics here; writing is :mod:`uq.files`."""
import xarray as xr

from uq.constants import MAX_RESULTS_BYTES
from uq.errors import DataFileError
from uq.pipeline.inputfile import check_regular


def read_results(path):
    """Open a results file fully into memory (the file is closed afterwards)."""
    with xr.open_dataset(path, engine="netcdf4") as dataset:
        return dataset.load()


def open_results(path):
    """Results of ``uq run`` at `path`, or DataFileError (bad input: exit 2) naming it.
    A path that is not a regular file (a FIFO would block the netCDF library) or larger
    than MAX_RESULTS_BYTES is refused unopened."""
    check_regular(path, MAX_RESULTS_BYTES, "a results file of uq run (netCDF)",
                  DataFileError)
    try:
        dataset = read_results(path)
    except (OSError, ValueError) as error:
        raise DataFileError(str(path), "", f"cannot read it as netCDF results ({error}); "
                            "allowed: a file written by uq run") from None
    if "mc_n_samples" not in dataset or "scenario" not in dataset.attrs:
        raise DataFileError(str(path), "", "not a uq results file (no mc_n_samples variable "
                            "or scenario attribute); allowed: a file written by uq run")
    return dataset
