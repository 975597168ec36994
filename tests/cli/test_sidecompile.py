"""The kernels' compile in a second process beside a record-mode run's boxes
(uq.cli.sidecompile, uq warmup --for)."""
import argparse
import os
import sys
from pathlib import Path

import pytest

from uq.cli import main, sidecompile, warmup
from uq.pipeline import records, runner
from uq.pipeline.scenario import load_scenario
from uq.pipeline.shipped import scenario_path

#: A record-mode scenario small enough for a test: two 60 s records, 64 trials.
SMALL_RECORDS = ("turbulence: {intensity: 0.1}\nrecord: {duration: 60, count: 2}\n"
                 "sampling: {method: mc, n: 64, seed: 1}\n")


def _args(**changes):
    return argparse.Namespace(**{"model": "compiled", "workers": None, "scheduler": None,
                                 "quiet": True, **changes})


def test_compile_for_runs_the_scenario_without_its_records(monkeypatch):
    ran = []
    monkeypatch.setattr(runner, "run", lambda scenario: ran.append(scenario))
    warmup.compile_for("floating_lidar_ti")
    (scenario,) = ran
    assert "turbulence" not in scenario.settings and "record" not in scenario.settings
    # the correction sweep stays (its kernels differ), the intensity's goes with its section
    assert set(scenario.settings["sweep"]) == {"correction"}
    assert scenario.sampling["n"] == sidecompile.SIDE_COMPILE_TRIALS
    shipped = load_scenario(scenario_path("floating_lidar_ti"))
    for section in ("wind", "lidar", "motion", "ins", "ship"):
        assert scenario.settings[section] == shipped.settings[section]


def test_compile_for_takes_overrides(monkeypatch):
    ran = []
    monkeypatch.setattr(runner, "run", lambda scenario: ran.append(scenario))
    warmup.compile_for("sathe2011_ti", ["correction=none"])
    assert ran[0].settings["correction"] == "none"


FREE = sidecompile.SIDE_COMPILE_MIN_AVAILABLE_MB


@pytest.mark.parametrize("changes, cores, cached, free, expected", [
    ({}, 2, False, FREE, True),
    ({}, 1, False, FREE, False),                    # no second core to compile on
    ({}, 2, False, FREE - 1, False),                # no room for a second process
    ({}, 2, True, FREE, False),                     # nothing to compile
    ({"workers": 2}, 2, False, FREE, False),        # the workers compile for themselves
    ({"scheduler": "tcp://x:1"}, 2, False, FREE, False),
    ({"model": "numpy"}, 2, False, FREE, False),    # no kernel is called
])
def test_wanted_only_where_it_can_help(monkeypatch, changes, cores, cached, free, expected):
    monkeypatch.setattr(sidecompile, "usable_cores", lambda: cores)
    monkeypatch.setattr(sidecompile, "available_memory_mb", lambda: free)
    monkeypatch.setattr(sidecompile, "kernels_cached", lambda motion: cached)
    scenario = load_scenario(scenario_path("sathe2011_ti"))
    assert sidecompile.wanted(_args(**changes), scenario) is expected


def test_not_wanted_without_records(monkeypatch):
    monkeypatch.setattr(sidecompile, "usable_cores", lambda: 2)
    monkeypatch.setattr(sidecompile, "available_memory_mb", lambda: FREE)
    monkeypatch.setattr(sidecompile, "kernels_cached", lambda motion: False)
    for name, changes in (("rubio2022_case_i", {}), ("sathe2011_ti", {"sampling.method": "none"})):
        scenario = load_scenario(scenario_path(name), changes)
        assert not sidecompile.wanted(_args(), scenario)


def test_the_stand_in_finds_the_kernel_s_own_cache_files():
    from numba.core.caching import FunctionCache
    from uq.physics import fusedkernels
    real = FunctionCache(fusedkernels._KERNELS["wind_scan"][0])
    found = FunctionCache(sidecompile._stand_in(*sidecompile.LARGEST_KERNELS[False]))
    assert found._cache_file._index_path == real._cache_file._index_path


@pytest.mark.parametrize("time_resolved", [False, True])
def test_kernels_cached_once_the_largest_kernel_is_compiled(time_resolved):
    from uq.physics import fusedkernels
    fusedkernels.compiled(float)["wind_scan"]       # compiled or loaded: now in the cache
    import uq.physics.fusedmotionkernels  # noqa: F401  (the same, on import)
    assert sidecompile.kernels_cached(time_resolved) is True


def test_wanted_asks_the_cache_of_the_run_s_kind(monkeypatch):
    asked = []
    monkeypatch.setattr(sidecompile, "usable_cores", lambda: 2)
    monkeypatch.setattr(sidecompile, "available_memory_mb", lambda: FREE)
    monkeypatch.setattr(sidecompile, "kernels_cached", lambda motion: asked.append(motion))
    for name in ("sathe2011_ti", "floating_lidar_ti"):
        sidecompile.wanted(_args(), load_scenario(scenario_path(name)))
    assert asked == [False, True]


def test_kernels_cached_is_false_where_numba_internals_fail(monkeypatch):
    import numba.core.caching

    def broken(function):
        raise AttributeError("numba changed")
    monkeypatch.setattr(numba.core.caching, "FunctionCache", broken)
    assert sidecompile.kernels_cached() is False


def _side(monkeypatch, code, stream=None):
    """A SideCompile whose child is `code` (Python), not uq warmup."""
    real = sidecompile.subprocess.Popen

    def popen(command, **kwargs):
        assert command[1:5] == ["-m", "uq.cli", "warmup", "--for"]
        assert Path(command[5]).exists() and command[6] == "-q"
        return real([sys.executable, "-c", code], **kwargs)
    monkeypatch.setattr(sidecompile.subprocess, "Popen", popen)
    return sidecompile.SideCompile({"name": "x"}, stream)


def test_wait_reports_the_child_and_removes_its_file(monkeypatch, capsys):
    side = _side(monkeypatch, "import sys; sys.exit(0)", sys.stderr)
    assert side.wait() is True and side.waited >= 0.0
    assert not Path(side.path).exists()
    assert "compiled beside the boxes" in capsys.readouterr().err
    assert side.wait() is True                      # a second chunk does not wait again


def test_a_failed_child_leaves_the_compile_to_the_run(monkeypatch, capsys):
    side = _side(monkeypatch, "import sys; sys.exit(3)", sys.stderr)
    assert side.wait() is False
    assert capsys.readouterr().err == ""            # said at -v only
    assert not Path(side.path).exists()


def test_stop_ends_a_running_child(monkeypatch):
    side = _side(monkeypatch, "import time; time.sleep(60)")
    child = side.child
    side.stop()
    assert child.poll() is not None and not Path(side.path).exists()


def test_run_waits_for_the_kernels_after_the_boxes_before_the_model(monkeypatch, tmp_path):
    events = []

    class Beside:
        waited = 0.0

        def wait(self):
            events.append("wait")

        def stop(self):
            events.append("stop")
    prepare, run_scene = records.prepare_records, runner.run_scene
    monkeypatch.setattr(records, "prepare_records",
                        lambda *a, **k: (events.append("boxes"), prepare(*a, **k))[1])
    monkeypatch.setattr(runner, "run_scene",
                        lambda *a, **k: (events.append("model"), run_scene(*a, **k))[1])
    monkeypatch.setattr("uq.cli.run.side_compile", lambda args, scenario: Beside())
    scenario = tmp_path / "ti.yaml"
    scenario.write_text(SMALL_RECORDS)
    assert main(["run", str(scenario), "-q", "-o", str(tmp_path / "ti.nc")]) == 0
    assert events == ["boxes", "wait", "model", "stop"]


def test_available_memory_is_the_machine_s():
    # MemAvailable lies between 0 and the machine's physical memory
    total = os.sysconf("SC_PHYS_PAGES") * os.sysconf("SC_PAGE_SIZE") / 2**20
    assert 0.0 < sidecompile.available_memory_mb() <= total


def test_nothing_of_the_child_reaches_the_terminal(monkeypatch, capfd):
    # the child's own lines ("uq: terminated" when the run stops it) would cut into the
    # run's: its output is discarded, at the file descriptors
    side = _side(monkeypatch, "import sys; print('out'); sys.stderr.write('uq: terminated')")
    assert side.wait() is True
    captured = capfd.readouterr()
    assert captured.out == "" and captured.err == ""
