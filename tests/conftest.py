"""Shared helpers for the tests."""
import copy
import os
import resource

import numpy as np
import pytest

from uq.pipeline.modelsetup import scene_from_settings
from uq.pipeline.scenario import load_scenario

# `uq run` (--model auto) leaves a cold cache's kernels to a background process that
# outlives the command (uq.cli.firstrun): the suite's commands compile in their own
# process instead (as --model compiled), so that no test leaves a process behind;
# tests/cli/test_firstrun.py turns it on where it is tested.
os.environ["UQ_BACKGROUND_COMPILE"] = "0"


def make_scene(**changes):
    """A Scene from the default scenario with dotted-key changes (degrees, as in YAML)."""
    return scene_from_settings(load_scenario({"name": "test",
                                              **with_changes({}, changes)}).settings)


def with_changes(settings, changes):
    """A deep copy of the scenario mapping `settings` with the dotted-key `changes`
    applied (``{"lidar.errors.height": None}`` removes that key; any other value sets it,
    making the mappings on its path where they are missing); `settings` is not changed."""
    out = copy.deepcopy(settings)
    for dotted, value in changes.items():
        node = out
        *parents, last = dotted.split(".")
        for part in parents:
            node = node.setdefault(part, {})
        if value is None:
            node.pop(last, None)
        else:
            node[last] = value
    return out


#: CPU time a child process of a test may use before the kernel stops it [s]: a cold
#: start that compiles every numba kernel (~100 s of CPU on the 2-core CI machine) and
#: the longest child's own work (a notebook's fits, ~60 s), with a factor of 3 to spare.
#: A bound on work, not on wall time: a loaded machine slows a child, it does not make
#: it use more CPU.
CHILD_CPU_SECONDS = 600


def cpu_limited(seconds=CHILD_CPU_SECONDS):
    """A ``preexec_fn`` for :mod:`subprocess` that limits the child's CPU time to
    `seconds` (``RLIMIT_CPU``; the kernel ends a child that exceeds it with SIGXCPU, so
    a runaway child fails the test with its status instead of hanging it). Its own
    children (dask workers) inherit the limit, each for itself."""
    def limit():
        resource.setrlimit(resource.RLIMIT_CPU, (seconds, seconds))
    return limit


def child_failure(result):
    """What a failed child process said: its status and the ends of its stdout and
    stderr (for an assertion's message)."""
    return (f"child exited with status {result.returncode}; stdout: "
            f"{(result.stdout or '')[-1000:]!r}; stderr: {(result.stderr or '')[-2000:]!r}")


@pytest.fixture
def rng():
    return np.random.default_rng(12345)


@pytest.fixture(scope="session")
def cf_compliance():
    """A function that checks one netCDF file the way the ecosystem's tools do (issue 16,
    "files that the ecosystem's tools accept") and returns its checker report:

    * the IOOS compliance-checker, CF 1.10, finds no error (no failed high-priority
      check) and raises no exception of its own;
    * no coordinate variable (a 1-D numeric variable named as its dimension) carries a
      _FillValue or a missing value, and each is strictly monotonic (CF 2.5.1, 5; also
      checked here, as the checker skips that check when any coordinate is a string);
    * xarray opens it and ``xarray.decode_cf`` of the raw variables gives the same Dataset;
    * ``ncdump -h`` reads it (where the netCDF utilities are installed).
    """
    import json
    import shutil
    import subprocess
    import tempfile
    from pathlib import Path

    import netCDF4
    import xarray as xr
    from compliance_checker.runner import CheckSuite, ComplianceChecker

    import warnings
    with warnings.catch_warnings():         # the checker's own deprecation notices
        warnings.simplefilter("ignore", DeprecationWarning)
        CheckSuite().load_all_available_checkers()

    def check(path):
        with tempfile.TemporaryDirectory() as folder:
            report_path = Path(folder) / "report.json"
            _, raised = ComplianceChecker.run_checker(str(path), ["cf:1.10"], 0, "normal",
                                                      output_filename=str(report_path),
                                                      output_format="json")
            report = json.loads(report_path.read_text())["cf:1.10"]
        failed = [(item["name"], item["msgs"]) for item in report["high_priorities"]
                  if item["value"][0] < item["value"][1]]
        assert not raised, f"{path}: the checker raised (see its stderr)"
        assert not failed, f"{path}: CF 1.10 errors {failed}"
        with netCDF4.Dataset(path) as handle:
            for name, variable in handle.variables.items():
                if variable.dimensions != (name,) or variable.dtype.kind not in "iuf":
                    continue
                assert "_FillValue" not in variable.ncattrs(), f"{path}: {name} _FillValue"
                values = np.ma.filled(variable[:].astype(float), np.nan)
                assert np.isfinite(values).all(), f"{path}: {name} has missing values"
                steps = np.diff(values)
                assert np.all(steps > 0) or np.all(steps < 0), f"{path}: {name} not monotonic"
        with xr.open_dataset(path) as decoded, xr.open_dataset(path, decode_cf=False) as raw:
            assert xr.decode_cf(raw).identical(decoded), f"{path}: decode_cf round trip"
        if shutil.which("ncdump"):
            subprocess.run(["ncdump", "-h", str(path)], check=True, capture_output=True)
        return report
    return check
