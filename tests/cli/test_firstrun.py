"""``uq run``'s first run after an install (uq.cli.firstrun): the numpy model now, the
kernels compiled in a background process for later runs; a cold and a warm cache give
the same numbers (to 1e-12 m s-1: tests/pipeline/test_model_switch.py says why)."""
import argparse
import os
import re
import subprocess
import sys
import time
from pathlib import Path

import pytest
import xarray as xr

from uq.cli import firstrun, main, sidecompile
from tests.conftest import child_failure, cpu_limited
from tests.pipeline.test_model_switch import _assert_agree

ROOT = Path(__file__).resolve().parents[2]
FREE = sidecompile.SIDE_COMPILE_MIN_AVAILABLE_MB


def _args(**changes):
    return argparse.Namespace(**{"workers": None, "scheduler": None, **changes})


@pytest.mark.parametrize("environment, changes, free, expected", [
    ("1", {}, FREE, True),
    ("0", {}, FREE, False),                          # turned off (batch jobs, CI)
    ("1", {"workers": 2}, FREE, False),              # the workers compile for themselves
    ("1", {"scheduler": "tcp://x:1"}, FREE, False),
    ("1", {}, FREE - 1, False),                      # no room for a second process
])
def test_wanted_only_where_it_can_run(monkeypatch, environment, changes, free, expected):
    monkeypatch.setenv(firstrun.BACKGROUND_VARIABLE, environment)
    monkeypatch.setattr(sidecompile, "available_memory_mb", lambda: free)
    assert firstrun.wanted(_args(**changes)) is expected


def test_one_compile_at_a_time_per_cache(tmp_path, monkeypatch):
    """The lock is taken by the first and held by its child: a second start finds it
    held, starts nothing and reports the first's end."""
    monkeypatch.setattr(firstrun, "lock_path", lambda folder=None: str(tmp_path / "lock"))
    real = firstrun.subprocess.Popen
    started = []

    def popen(command, **kwargs):
        assert command[1:3] == ["-m", "uq.cli.firstrun"] and Path(command[3]).exists()
        started.append(command)
        # holds the inherited lock until stdin closes
        return real([sys.executable, "-c", "import sys; sys.stdin.read()"],
                    **{**kwargs, "stdin": subprocess.PIPE})
    monkeypatch.setattr(firstrun.subprocess, "Popen", popen)
    first = firstrun.BackgroundCompile([{"name": "x"}])
    assert first.child is not None and firstrun.compile_running()
    second = firstrun.BackgroundCompile([{"name": "x"}])
    assert second.child is None and not second.ended() and len(started) == 1
    first.child.stdin.close()
    first.child.wait()
    assert first.ended() and second.ended() and not firstrun.compile_running()


def _child_calls(monkeypatch, calls):
    """firstrun.main's compiles, priority and waits recorded in `calls`, not done."""
    monkeypatch.setattr("uq.cli.warmup.compile_for", lambda path: calls.append(path))
    monkeypatch.setattr("uq.cli.warmup.compile_record_kernels",
                        lambda: calls.append("record kernels"))
    monkeypatch.setattr(firstrun, "lower_priority", lambda: calls.append("lowered"))
    monkeypatch.setattr(firstrun, "_wait_for_exit", lambda pid: calls.append(("wait", pid)))


def test_the_child_compiles_each_scenario_and_removes_its_file(tmp_path, monkeypatch):
    settings = tmp_path / "s.yaml"
    settings.write_text("name: x\n---\nname: y\n")
    compiled = []
    _child_calls(monkeypatch, compiled)
    assert firstrun.main([str(settings), "3"]) == 0
    assert compiled == ["lowered", {"name": "x"}, {"name": "y"}]
    assert not settings.exists()


def test_the_child_compiles_a_records_kernels_first_then_waits_for_the_run(tmp_path,
                                                                           monkeypatch):
    # a record-mode scenario's boxes and spectral path first (the run takes them as soon
    # as they are cached), then, given the run's process, the rest once it has ended
    settings = tmp_path / "s.yaml"
    settings.write_text("name: x\nturbulence: {model: mann}\n")
    calls = []
    _child_calls(monkeypatch, calls)
    assert firstrun.main([str(settings), "3", "1234"]) == 0
    assert calls == ["lowered", "record kernels", ("wait", 1234),
                     {"name": "x", "turbulence": {"model": "mann"}}]


def test_the_priority_is_the_idle_class_where_linux_has_it():
    # in a child process: this one's priority is the suite's
    code = ("import os; from uq.cli.firstrun import lower_priority, BACKGROUND_NICE; "
            "lower_priority(); print(os.sched_getscheduler(0) == os.SCHED_IDLE, "
            "os.nice(0) >= BACKGROUND_NICE)")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          env={**os.environ, "PYTHONPATH": str(ROOT)})
    assert done.returncode == 0, child_failure(done)
    assert done.stdout.split() == ["True", "True"]


def test_the_child_waits_for_its_parent_to_end(tmp_path):
    # a parent starts a child that waits for it, then ends after writing its mark: the
    # child's mark comes after the parent's (an order, not a duration)
    marks = tmp_path / "marks"
    child = ("import os, sys; from uq.cli.firstrun import _wait_for_exit; "
             "_wait_for_exit(int(sys.argv[1])); open(sys.argv[2], 'a').write('child\\n')")
    parent = (f"import os, subprocess, sys; subprocess.Popen([sys.executable, '-c', {child!r}, "
              "str(os.getpid()), sys.argv[1]]); import time; time.sleep(1.0); "
              "open(sys.argv[1], 'a').write('parent\\n')")
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    done = subprocess.run([sys.executable, "-c", parent, str(marks)], env=env,
                          capture_output=True, text=True)
    assert done.returncode == 0, child_failure(done)
    for _ in range(600):                 # the child polls every WAIT_POLL_SECONDS
        if marks.exists() and "child" in marks.read_text():
            break
        time.sleep(0.1)
    assert marks.read_text().split() == ["parent", "child"]


@pytest.mark.parametrize("cpus, beside", [(2, False), (4, False), (5, True), (16, True)])
def test_the_compile_runs_beside_the_run_only_with_a_core_to_spare(monkeypatch, cpus,
                                                                   beside):
    monkeypatch.setattr("uq.cpus.usable_cpus", lambda: cpus)
    assert firstrun.compile_beside() is beside


@pytest.mark.parametrize("model_seconds, beside", [(0.0, False), (29.9, False),
                                                   (30.0, True), (float("nan"), False)])
def test_a_long_run_compiles_beside_itself_on_two_cores(monkeypatch, model_seconds, beside):
    """On 2 CPUs a run whose model is estimated at BACKGROUND_BESIDE_MIN_MODEL_CPU_S or
    more has the compile beside it (no run's pid for the child to wait for); a shorter
    one, or one not estimated (NaN), has it wait."""
    from uq.constants import BACKGROUND_BESIDE_MIN_MODEL_CPU_S
    assert BACKGROUND_BESIDE_MIN_MODEL_CPU_S == 30.0          # the cases above
    monkeypatch.setattr("uq.cpus.usable_cpus", lambda: 2)
    assert firstrun.compile_beside(model_seconds) is beside
    monkeypatch.setattr(firstrun, "_take_lock", lambda: os.open(os.devnull, os.O_RDONLY))
    commands = []
    monkeypatch.setattr(firstrun.subprocess, "Popen",
                        lambda command, **kwargs: commands.append(command))
    firstrun.BackgroundCompile([{"name": "x"}], model_seconds)
    os.unlink(commands[0][3])                                  # the settings' file
    assert commands[0][5:] == ([] if beside else [str(os.getpid())])


@pytest.mark.parametrize("n, long", [(10_000, False), (100_000, True)])
def test_uq_run_gives_the_compile_its_models_estimate(monkeypatch, tmp_path, n, long):
    """uq run hands its scenario's estimated model CPU (uq check's estimate, without the
    start and records) to the background compile: rubio2022_misalignment as shipped
    (10^4 trials a scene, 5 s) has it wait on 2 CPUs, at 10^5 trials (52 s) beside."""
    from uq.pipeline.estimate import run_size
    from uq.pipeline.scenario import load_scenario
    from uq.pipeline.shipped import scenario_path
    seen = []

    class Stop(Exception):
        pass

    def background(args, settings, agreement="", model_seconds=0.0):
        seen.append(model_seconds)
        raise Stop
    monkeypatch.setattr(firstrun, "Background", background)
    with pytest.raises(Stop):
        main(["run", "rubio2022_misalignment", "-q", "--set", f"sampling.n={n}",
              "-o", str(tmp_path / "m.nc")])
    scenario = load_scenario(scenario_path("rubio2022_misalignment"), {"sampling.n": n})
    assert seen == [run_size(scenario).model_seconds()]
    monkeypatch.setattr("uq.cpus.usable_cpus", lambda: 2)
    assert firstrun.compile_beside(seen[0]) is long


def test_turned_off_the_run_compiles_itself(tmp_path, monkeypatch):
    """UQ_BACKGROUND_COMPILE=0 (the suite's setting): --model auto is --model compiled,
    no background process."""
    monkeypatch.setattr(firstrun, "BackgroundCompile",
                        lambda settings: pytest.fail("no background compile"))
    out = tmp_path / "r.nc"
    assert main(["run", "rubio2022_case_i", "-q", "--set", "sampling.n=100",
                 "--set", "sweep.wind.direction=[0]", "-o", str(out)]) == 0
    with xr.open_dataset(out) as result:
        assert "model" not in result.attrs


def _ended(pid):
    """Whether process `pid` has ended (it is not this process's child)."""
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return True
    return Path(f"/proc/{pid}/stat").exists() and \
        Path(f"/proc/{pid}/stat").read_text().split(")")[-1].split()[0] == "Z"


def test_a_cold_then_a_warm_run_agree(tmp_path):
    """The README's first command with an empty cache: it runs the numpy model, says a
    background process compiles the kernels, writes its file and ends; once that process
    has ended, the same command runs the compiled model (no such line) with the same
    numbers. The processes' CPU is bounded (cpu_limited: the child inherits the limit)."""
    env = {**os.environ, "NUMBA_CACHE_DIR": str(tmp_path / "numba"),
           firstrun.BACKGROUND_VARIABLE: "1", "PYTHONPATH": str(ROOT)}
    command = [sys.executable, "-m", "uq.cli", "run", "rubio2022_case_i", "--set",
               "sampling.n=500", "--set", "sweep.wind.direction=[0, 90, 200]"]
    runs = []
    for name in ("cold", "warm"):
        done = subprocess.run(command + ["-o", str(tmp_path / f"{name}.nc")], env=env,
                              capture_output=True, text=True, preexec_fn=cpu_limited())
        assert done.returncode == 0, child_failure(done)
        runs.append(done.stderr)
        if name == "cold":
            found = re.search(r"background \(process (\d+), low priority\)", done.stderr)
            assert found, done.stderr
            pid = int(found.group(1))
            while not _ended(pid):      # bounded by the child's CPU limit, not a clock
                time.sleep(0.5)
    assert "background" not in runs[1] and "compiling" not in runs[1]
    with xr.open_dataset(tmp_path / "cold.nc") as cold, \
            xr.open_dataset(tmp_path / "warm.nc") as warm:
        assert cold.attrs["model"].startswith("numpy for 1 of 1 chunks")
        assert "model" not in warm.attrs
        _assert_agree(warm.load(), cold.load(), 5.0)     # the scenario's wind speed


@pytest.mark.parametrize("name, changes, expected", [
    ("rubio2022_case_i", {}, ("ins_trig", "geometry")),
    ("nacelle_fixed", {}, ("ins_trig", "geometry_mounted")),          # lidar.mount.tilt 90
    # a sweep over the tilt (upward and along the bow): both geometries
    ("nacelle_fixed", {"sweep.lidar.mount.tilt": [0, 90], "outputs": ["wind_speed"]},
     ("ins_trig", "geometry", "geometry_mounted")),
])
def test_a_run_loads_the_static_kernels_it_calls(name, changes, expected):
    """``uq run`` loads ahead the real kernels of the geometry its scenes use (a tilted
    mount's or the upward lidar's), so that a cache ``uq warmup --for`` filled holds
    every kernel it asks for (it asked for the upward lidar's on a nacelle, found it
    missing and started a background compile after a warmup)."""
    from uq.cli.run import static_kernels
    from uq.pipeline.scenario import load_scenario
    from uq.pipeline.shipped import scenario_path
    assert static_kernels(load_scenario(scenario_path(name), changes)) == expected


def test_a_nacelle_run_calls_the_kernels_it_loads_ahead():
    """The kernels a nacelle's run calls include the mounted geometry (and not the upward
    lidar's): the real kernels a short run in this process asks for, recorded."""
    from uq.pipeline.runner import run
    from uq.pipeline.scenario import load_scenario
    from uq.pipeline.shipped import scenario_path
    from uq.physics import fusedkernels
    called = []
    real = fusedkernels.compiled(float)
    original = type(real).__getitem__

    def record(self, name):
        called.append(name)
        return original(self, name)
    type(real).__getitem__ = record
    try:
        run(load_scenario(scenario_path("nacelle_fixed"), {"sampling.n": 64}))
    finally:
        type(real).__getitem__ = original
    assert "geometry_mounted" in called and "geometry" not in called
