"""Ctrl-C, as a terminal sends it (SIGINT to the whole process group): exit 130 with one
message, no traceback from any process, no results file."""
import os
import signal
import subprocess
import sys
import time


def interrupt(args, cwd, after, wait_for=None):
    child = subprocess.Popen([sys.executable, "-m", "uq.cli", *args], cwd=cwd, text=True,
                             stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                             start_new_session=True)
    try:
        deadline = time.monotonic() + 120
        while wait_for is not None and not wait_for():
            assert time.monotonic() < deadline and child.poll() is None
            time.sleep(0.05)
        time.sleep(after)
        os.killpg(child.pid, signal.SIGINT)
        _, err = child.communicate(timeout=60)
        return child.returncode, err
    finally:                                   # never leave a process group behind
        try:
            os.killpg(child.pid, signal.SIGKILL)
        except ProcessLookupError:
            pass


def test_ctrl_c_early_exits_130_without_a_file(tmp_path):
    status, err = interrupt(["run", "rubio2022_case_i", "-o", "out.nc"], tmp_path, after=0.4)
    assert status == 130 and "Traceback" not in err, err
    assert not (tmp_path / "out.nc").exists()


def test_ctrl_c_with_two_workers_is_one_message(tmp_path):
    partial = tmp_path / "out.nc.partial"
    status, err = interrupt(["run", "rubio2022_misalignment", "--workers", "2", "--quiet",
                             "-o", "out.nc"], tmp_path, after=0.5,
                            wait_for=lambda: any(partial.glob("chunk-*.sha256")))
    assert status == 130, err
    assert err.strip().splitlines() == ["uq: interrupted; finished chunks are kept in "
                                        "out.nc.partial; run the same command with --resume "
                                        "to continue"]
    assert not (tmp_path / "out.nc").exists() and any(partial.glob("chunk-*.nc"))
