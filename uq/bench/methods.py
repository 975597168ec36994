"""``uq bench``: error in u(wind speed) against wall time, for every sampling method.

Two scenes (``rubio2022_case_i`` at one wind direction, and ``floating_lidar_full``) are
run with each method at several sample sizes, each repeated with independent seeds, so the
result shows the spread and not one lucky draw. The error is measured against a
high-precision reference (randomised Sobol' with the control variate at 2^22 trials, whose
own standard error is recorded). Results: ``results/bench.nc`` (dims scene, method, n,
repeat) and a plot. Also measured in the same run: the time to draw each scene's random
numbers alone (the floor of plain Monte Carlo); the speed targets are in
:mod:`uq.bench.targets`.
"""
import time

import numpy as np
import xarray as xr

from uq.pipeline.runner import run
from uq.pipeline.scenario import load_scenario
from uq.pipeline.shipped import shipped_folder

ROOT = shipped_folder()
SCENES = {"rubio2022_case_i": (ROOT / "rubio2022_case_i.yaml",
                               {"sweep": {}, "wind.direction": 30.0}),
          "floating_lidar_full": (ROOT / "floating_lidar_full.yaml", {})}
#: method label -> (sampling.method, control variate)
METHODS = {"mc": ("mc", False), "lhs": ("lhs", False), "sobol": ("sobol", False),
           "mc+cv": ("mc", True), "sobol+cv": ("sobol", True)}
REFERENCE_SAMPLES = 2**22
#: Relative error the target asks for, and in what share of runs [1].
TARGET_ERROR, TARGET_SHARE = 1e-3, 0.95


def scene(name, **changes):
    path, overrides = SCENES[name]
    return load_scenario(path, {**overrides, "outputs": ["wind_speed"], **changes})


def timed_u(scenario):
    """(wall time [s], u(wind speed) per gate, its reported standard error)."""
    started = time.perf_counter()
    result = run(scenario)
    elapsed = time.perf_counter() - started
    return (elapsed, np.atleast_1d(result["wind_speed_mc_u"].values),
            np.atleast_1d(result["wind_speed_mc_u_standard_error"].values))


def reference(name):
    """High-precision u(wind speed) per gate and its standard error."""
    _, u, error = timed_u(scene(name, **{"sampling.method": "sobol", "sampling.n":
                                         REFERENCE_SAMPLES, "sampling.control_variate": True,
                                         "sampling.seed": 10**6}))
    return u, error


def measure(sizes, repeats, progress=None):
    """The benchmark Dataset: time_s, relative_error (largest over gates), reported
    relative standard error; dims (scene, method, n, repeat)."""
    shape = (len(SCENES), len(METHODS), len(sizes), repeats)
    times, errors, reported = np.zeros(shape), np.zeros(shape), np.zeros(shape)
    references, reference_errors = [], []
    for i, name in enumerate(SCENES):
        truth, truth_error = reference(name)
        references.append(truth[0])
        reference_errors.append(float(np.max(truth_error / truth)))
        for j, (method, cv) in enumerate(METHODS.values()):
            for k, n in enumerate(sizes):
                for r in range(repeats):
                    t, u, e = timed_u(scene(name, **{"sampling.method": method, "sampling.n": n,
                                                     "sampling.control_variate": cv,
                                                     "sampling.seed": 1000 * r + k}))
                    times[i, j, k, r] = t
                    errors[i, j, k, r] = np.max(np.abs(u / truth - 1))
                    reported[i, j, k, r] = np.max(e / u)
                if progress:
                    progress(f"{name} {list(METHODS)[j]} n={n}")
    dims = ("scene", "method", "n", "repeat")
    return xr.Dataset(
        {"time_s": (dims, times, {"units": "s", "long_name": "wall time of uq.run"}),
         "relative_error": (dims, errors, {"units": "1", "long_name": "|u / u_reference - 1| "
                                           "of u(wind speed), largest over range gates"}),
         "reported_relative_error": (dims, reported, {"units": "1", "long_name":
                                                      "reported standard error of u over u"}),
         "reference_u": ("scene", references, {"units": "m s-1"}),
         "reference_relative_error": ("scene", reference_errors, {"units": "1"})},
        coords={"scene": list(SCENES), "method": list(METHODS), "n": list(sizes),
                "repeat": np.arange(repeats)})


def time_to_target(dataset):
    """Per scene and method: the smallest swept n whose 95 % quantile (over repeats) of
    the relative error is <= 1e-3, and its median time; where no swept n reaches it, the
    error is extrapolated as n^-1/2 (time as n) from the largest n, and flagged."""
    quantile = dataset["relative_error"].quantile(TARGET_SHARE, dim="repeat")
    median_time = dataset["time_s"].median("repeat")
    rows = {}
    for name in dataset["scene"].values:
        for method in dataset["method"].values:
            q = quantile.sel({"scene": name, "method": method}).values
            t = median_time.sel({"scene": name, "method": method}).values
            reached = np.flatnonzero(q <= TARGET_ERROR)
            if reached.size:
                rows[name, method] = (float(t[reached[0]]), False)
            else:
                factor = (q[-1] / TARGET_ERROR) ** 2
                rows[name, method] = (float(t[-1] * factor), True)
    return rows


def draw_floor(name, n, repeats=5):
    """Seconds to draw n trials' standard normals for the scene's random inputs (the
    median of `repeats`, as the run times it is compared with), and their dimension."""
    from uq.pipeline.modelsetup import error_inputs, scene_from_settings
    from uq.engine.inputs import input_set
    scenario = scene(name)
    base = scene_from_settings(scenario.settings)
    dimension = input_set(error_inputs(scenario.settings, base.n_beams,
                                       len(base.ranges))).dimension
    generator = np.random.default_rng(1)
    times = []
    for _ in range(repeats):
        started = time.perf_counter()
        generator.standard_normal((n, dimension))
        times.append(time.perf_counter() - started)
    return float(np.median(times)), dimension


#: The scale run, in a new process. Its peak memory is the process's own high-water mark
#: of resident memory (VmHWM, Linux: per address space, so it starts afresh at exec);
#: ru_maxrss is not, as Linux keeps it across fork and exec: a child of a large parent
#: (``uq bench`` at ~600 MB) would report the parent's size.
SCALE_SCRIPT = """
import resource, time, uq
scenario = uq.load_scenario({"name": "scale", "correction": "none", "outputs": ["wind_speed"],
    "lidar": {"errors": {"radial_velocity": {"dist": "normal", "u": 0.1}}},
    "sampling": {"n": %d, "seed": 1}})
started = time.perf_counter()
result = uq.run(scenario)
seconds = time.perf_counter() - started
try:
    peak = next(float(line.split()[1]) / 1024 for line in open("/proc/self/status")
                if line.startswith("VmHWM:"))
except OSError:
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
print(seconds, peak, float(result["wind_speed_mc_u"]))
"""


def scale(n=10**8):
    """Wall time [s] and peak resident memory [MB] of one n-trial run, in a fresh process
    (so the peak is that run's own)."""
    import subprocess
    import sys
    out = subprocess.run([sys.executable, "-c", SCALE_SCRIPT % n], capture_output=True,
                         text=True, check=True).stdout.split()
    return float(out[0]), float(out[1])
