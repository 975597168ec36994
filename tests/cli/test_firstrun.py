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


def test_the_child_compiles_each_scenario_and_removes_its_file(tmp_path, monkeypatch):
    settings = tmp_path / "s.yaml"
    settings.write_text("name: x\n---\nname: y\n")
    compiled = []
    monkeypatch.setattr("uq.cli.warmup.compile_for", lambda path: compiled.append(path))
    monkeypatch.setattr(firstrun.os, "nice", lambda value: compiled.append(value))
    assert firstrun.main([str(settings), "3"]) == 0
    assert compiled == [firstrun.BACKGROUND_NICE, {"name": "x"}, {"name": "y"}]
    assert not settings.exists()


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
