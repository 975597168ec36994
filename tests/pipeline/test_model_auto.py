"""``uq.run(model="auto")``: each chunk the compiled model where numba's cache holds its
kernels, else the numpy model (uq.compileguard), with the same numbers to 1e-12 m s-1
(the tolerance of tests/pipeline/test_model_switch.py, which says why)."""
import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

from uq.compileguard import KernelNotCached, active, cached_only
from uq.pipeline.runner import ModelChoice, run
from uq.pipeline.scenario import load_scenario
from uq.pipeline.shipped import scenario_path
from tests.conftest import child_failure, cpu_limited
from tests.pipeline.test_model_switch import _assert_agree

ROOT = Path(__file__).resolve().parents[2]
SMALL = {"sampling.n": 600, "sweep.wind.direction": [0.0, 90.0, 200.0]}


def _work(log, missing_until=None):
    """A chunk's work that logs its flag and finds a kernel missing while compiled and
    `missing_until` (a callable) says so."""
    def work(compiled):
        log.append(compiled)
        if compiled and missing_until is not None and missing_until():
            raise KernelNotCached("uq.physics.fusedkernels.wind_scan")
        return "compiled" if compiled else "numpy"
    return work


@pytest.mark.parametrize("model, flag", [("compiled", True), ("numpy", False)])
def test_a_fixed_model_runs_every_chunk_with_its_flag(model, flag):
    choice, log = ModelChoice(model), []
    for _ in range(3):
        choice.evaluate(_work(log))
    assert log == [flag] * 3 and choice.numpy_chunks == 0


def test_auto_runs_compiled_while_every_kernel_is_cached():
    choice, log = ModelChoice("auto"), []
    assert [choice.evaluate(_work(log)) for _ in range(2)] == ["compiled"] * 2
    assert log == [True, True] and choice.missing is None


def test_auto_falls_back_to_numpy_and_asks_once_for_the_compile():
    asked, compile_ended = [], [False]

    def kernels_missing(error):
        asked.append(str(error))
        return lambda: compile_ended[0]
    choice, log = ModelChoice("auto", kernels_missing), []
    missing = [True]
    work = _work(log, lambda: missing[0])
    assert choice.evaluate(work) == "numpy"          # tried compiled, found it missing
    assert choice.evaluate(work) == "numpy"          # not tried again: still compiling
    assert log == [True, False, False]
    compile_ended[0], missing[0] = True, False       # the background compile has ended
    assert choice.evaluate(work) == "compiled"
    assert asked == ["uq.physics.fusedkernels.wind_scan"]
    assert (choice.numpy_chunks, choice.chunks) == (2, 3)
    assert "wind_scan" in choice.missing


def test_auto_without_a_compile_keeps_numpy():
    choice, log = ModelChoice("auto"), []
    work = _work(log, lambda: True)
    for _ in range(3):
        assert choice.evaluate(work) == "numpy"
    assert log == [True, False, False, False]


def test_the_guard_refuses_a_compile_and_lets_a_cached_kernel_load():
    import numba
    fresh = numba.njit(lambda x: x + 1)              # never compiled: not cached
    with pytest.raises(KernelNotCached, match="<lambda>"):
        with cached_only():
            assert active()
            fresh(1)
    assert not active() and fresh(1) == 2            # compiles again outside the guard
    with cached_only():
        assert fresh(2) == 3                         # compiled in this process: loaded


def test_a_warm_cache_runs_the_compiled_model_bit_for_bit():
    """Once compiled (by the first run here), auto finds every kernel and runs them."""
    scenario = load_scenario(scenario_path("rubio2022_case_i"), SMALL)
    compiled = run(scenario)
    auto = run(scenario, model="auto")
    assert "model" not in auto.attrs
    xr.testing.assert_identical(compiled.drop_attrs(), auto.drop_attrs())


CHILD = """
import json, sys
import uq.pipeline.runner
from uq.pipeline.runner import run
if len(sys.argv) > 3:                          # the threads of auto's numpy chunks
    import threading
    uq.pipeline.runner.NUMPY_CHUNK_THREADS = int(sys.argv[3])
    chunk, names = uq.pipeline.runner.run_chunk, set()
    def run_chunk(*args, **kwargs):              # (said on stdout: the threads it ran on)
        names.add(threading.current_thread().name.split("_")[0])
        return chunk(*args, **kwargs)
    uq.pipeline.runner.run_chunk = run_chunk
from uq.pipeline.scenario import load_scenario
from uq.pipeline.shipped import scenario_path
changes = json.loads(sys.argv[1])
result = run(load_scenario(scenario_path(changes.pop("name")), changes), model="auto")
result.to_netcdf(sys.argv[2])
if len(sys.argv) > 3:
    print(json.dumps(sorted(names)))
"""


@pytest.mark.parametrize("name, changes", [
    ("rubio2022_case_i", SMALL),
    ("floating_lidar_waves", {"sampling.n": 500}),
    # record mode: the boxes' colouring and sampling and the spectral path by numpy too
    ("sathe2011_ti", {"sampling.n": 500, "record.duration": 120, "record.count": 2}),
])
def test_a_cold_cache_runs_numpy_compiles_nothing_and_agrees(tmp_path, name, changes):
    """In a new process with an empty cache, auto runs every chunk with numpy and leaves
    the cache empty (nothing compiled); its numbers are the compiled run's to 1e-12 (the
    wind outputs, m s-1) and every other variable's to 1e-9 of its largest value (the
    spectral path's sums may differ by 3e-10, tests/physics/test_spectralsums.py) plus
    1e-12 (a value that is zero but for rounding)."""
    cache = tmp_path / "numba"
    env = {**os.environ, "NUMBA_CACHE_DIR": str(cache), "PYTHONPATH": str(ROOT)}
    out = tmp_path / "auto.nc"
    done = subprocess.run([sys.executable, "-c", CHILD, json.dumps({"name": name, **changes}),
                           str(out)], env=env, capture_output=True, text=True,
                          preexec_fn=cpu_limited())
    assert done.returncode == 0, child_failure(done)
    assert not list(cache.rglob("*.nbi"))            # no kernel was compiled into it
    with xr.open_dataset(out) as cold:
        cold = cold.load()
    assert cold.attrs["model"].startswith("numpy for ")
    scenario = load_scenario(scenario_path(name), changes)
    warm = run(scenario)
    _assert_agree(warm, cold, scenario.settings["wind"]["speed"])
    for variable in ("wind_speed_mc_mean", "wind_speed_mc_u"):    # not only NaN-free
        assert np.all(np.isfinite(cold[variable].values))
    for variable in warm.data_vars:
        values = warm[variable].values
        if values.dtype.kind == "f" and np.isfinite(values).any():
            gap = np.nanmax(np.abs(cold[variable].values - values))
            assert gap <= 1e-9 * np.nanmax(np.abs(values)) + 1e-12, (variable, gap)


@pytest.mark.parametrize("name, changes, chunks", [
    ("rubio2022_half_cone", {"sampling.n": 300}, 7),
    # record mode: the first chunk draws every scene's records, the later ones on threads
    ("floating_lidar_ti", {"sampling.n": 300, "record.duration": 120, "record.count": 2,
                           "sweep.turbulence.intensity": [0.06, 0.12]}, 4),
])
def test_numpy_chunks_on_threads_are_the_sequential_ones_bit_for_bit(tmp_path, name, changes,
                                                                     chunks):
    """A cold cache's sweep of many chunks: after the first, auto's numpy chunks run on
    two threads (set, whatever the machine's cores); each is the same bytes as in the
    same run with its chunks in sequence (one thread; both with numba's cache empty, so
    a record's kernels are numpy's too)."""
    results = {}
    for threads in (2, 1):
        cache = tmp_path / f"numba{threads}"
        env = {**os.environ, "NUMBA_CACHE_DIR": str(cache), "PYTHONPATH": str(ROOT)}
        out = tmp_path / f"auto{threads}.nc"
        done = subprocess.run([sys.executable, "-c", CHILD, json.dumps({"name": name, **changes}),
                               str(out), str(threads)], env=env, capture_output=True,
                              text=True, preexec_fn=cpu_limited())
        assert done.returncode == 0, child_failure(done)
        ran_on = json.loads(done.stdout.strip().splitlines()[-1])
        assert ran_on == (["MainThread", "uq-chunk"] if threads > 1 else ["MainThread"])
        with xr.open_dataset(out) as result:
            results[threads] = result.load()
        assert results[threads].attrs["model"].startswith(
            f"numpy for {chunks} of {chunks} chunks")
    cold, sequential = results[2], results[1]
    assert set(cold.data_vars) == set(sequential.data_vars)
    for name in sequential.data_vars:
        np.testing.assert_array_equal(cold[name].values, sequential[name].values, name)
