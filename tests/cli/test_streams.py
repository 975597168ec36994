"""Standard output that cannot be written (uq.cli.streams): a full device or a pipe whose
reader left ends every command quietly, never with a traceback."""
import os
import subprocess
import sys

import pytest
from conftest import cpu_limited

from uq.cli import main
from uq.cli.streams import EXIT_PIPE_CLOSED

#: Commands that write to standard output without computing much (no run).
WRITERS = [["list"], ["check", "rubio2022_case_i"], ["--help"], ["--version"],
           ["run", "--help"], ["check", "golden_campaign"]]


def uq(args, stdout, **kwargs):
    return subprocess.run([sys.executable, "-m", "uq.cli", *args], stdout=stdout,
                          stderr=subprocess.PIPE, text=True, preexec_fn=cpu_limited(),
                          timeout=600, **kwargs)


@pytest.mark.skipif(not os.path.exists("/dev/full"), reason="no /dev/full")
@pytest.mark.parametrize("args", WRITERS)
def test_a_full_standard_output_is_one_line_and_status_1(args):
    """``uq list > /dev/full``: was an OSError traceback (ENOSPC)."""
    with open("/dev/full", "w") as full:
        done = uq(args, full)
    assert done.returncode == 1, done.stderr
    assert done.stderr.strip().splitlines() == [
        "uq: error: cannot write to standard output (No space left on device)"]


@pytest.mark.parametrize("args", [["list"], ["check", "rubio2022_case_i"], ["--help"]])
def test_a_closed_pipe_ends_the_command_quietly(args):
    """``uq list | head -1`` whose reader left before uq wrote: was a BrokenPipeError
    traceback; now status 141 (128 + SIGPIPE, a shell's code for it) and nothing on
    stderr. The pipe's read end is closed before the child starts, so it always finds it
    closed (no race with a reader)."""
    read, write = os.pipe()
    os.close(read)
    try:
        done = uq(args, write)
    finally:
        os.close(write)
    assert done.returncode == EXIT_PIPE_CLOSED, done.stderr
    assert done.stderr == ""


def test_in_process_a_failing_stdout_is_the_status_not_an_exception(monkeypatch, capsys):
    class Broken:
        def write(self, text):
            raise BrokenPipeError(32, "Broken pipe")

        def flush(self):
            pass
    monkeypatch.setattr(sys, "stdout", Broken())
    assert main(["list"]) == EXIT_PIPE_CLOSED
    assert isinstance(sys.stdout, Broken)             # restored after the command
