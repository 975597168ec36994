"""Ctrl-C, as a terminal sends it (SIGINT to the whole process group): exit 130 with one
message, no traceback from any process, no results file. SIGTERM, as a batch system's time
limit or ``timeout`` sends it: the same clean-up, exit 143."""
import os
import signal
import subprocess
import sys
import time

import pytest
from conftest import cpu_limited


def as_from_a_terminal():
    """In the child before exec: Ctrl-C as a shell leaves it (default action, not
    blocked), whatever the test process's state (a pytest-xdist worker that ran other
    tests may have SIGINT ignored or blocked: both are inherited across exec, and an
    ignored Ctrl-C lets the run finish with status 0); CPU time bounded."""
    signal.signal(signal.SIGINT, signal.SIG_DFL)
    signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGINT})
    cpu_limited()()


def interrupt(args, cwd, after, wait_for=None, number=signal.SIGINT):
    """Start ``uq ARGS``, wait until `wait_for()` holds (if given) and `after` seconds
    more, send signal `number` (Ctrl-C by default); (status, stderr). The child is bounded
    in CPU time, not in wall time: a child that runs away dies of SIGXCPU and fails the
    wait."""
    child = subprocess.Popen([sys.executable, "-m", "uq.cli", *args], cwd=cwd, text=True,
                             stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                             start_new_session=True, preexec_fn=as_from_a_terminal)
    try:
        while wait_for is not None and not wait_for():
            assert child.poll() is None, child.communicate()[1]
            time.sleep(0.05)
        time.sleep(after)
        os.killpg(child.pid, number)
        _, err = child.communicate()
        state = (f"; this process: SIGINT {signal.getsignal(signal.SIGINT)}, blocked "
                 f"{signal.SIGINT in signal.pthread_sigmask(signal.SIG_BLOCK, set())}")
        return child.returncode, err + (state if child.returncode == 0 else "")
    finally:                                   # never leave a process group behind
        try:
            os.killpg(child.pid, signal.SIGKILL)
        except ProcessLookupError:
            pass


#: Exit status after Ctrl-C: 130, or death by SIGINT (-2 from subprocess, which a shell
#: also reports as 130 = 128 + 2) when the interrupt lands while the interpreter is still
#: importing; both tell the caller the run was interrupted, neither is 0.
INTERRUPTED = (130, -2)


@pytest.mark.parametrize("after", [0.2, 0.4, 0.7])
def test_ctrl_c_early_exits_130_without_a_file(tmp_path, after):
    status, err = interrupt(["run", "rubio2022_case_i", "-o", "out.nc"], tmp_path, after=after)
    assert status in INTERRUPTED and "Traceback" not in err, err
    assert not (tmp_path / "out.nc").exists()


@pytest.mark.parametrize("after", [0.3, 0.8])
def test_ctrl_c_with_two_workers_is_one_message(tmp_path, after):
    """Also while a chunk is being written: the write finishes first (a netCDF write
    interrupted half-way can leave its lock held, and the clean-up then hangs)."""
    partial = tmp_path / "out.nc.partial"
    status, err = interrupt(["run", "rubio2022_misalignment", "--workers", "2", "--quiet",
                             "-o", "out.nc"], tmp_path, after=after,
                            wait_for=lambda: any(partial.glob("chunk-*.sha256")))
    assert status == 130, err
    assert err.strip().splitlines() == ["uq: interrupted; finished chunks are kept in "
                                        "out.nc.partial; run the same command with --resume "
                                        "to continue"], err
    assert not (tmp_path / "out.nc").exists() and any(partial.glob("chunk-*.nc"))


def test_sigterm_while_golden_writes_leaves_nothing(tmp_path):
    """The hidden .NAME.partial folder of uq golden is removed, no output folder made."""
    status, err = interrupt(["golden", "golden_campaign", "-o", "out"], tmp_path, after=0.5,
                            wait_for=lambda: any(tmp_path.glob(".out.*.partial/data")),
                            number=signal.SIGTERM)
    assert status == 143, err
    assert err.strip().splitlines() == ["uq: terminated"]
    assert list(tmp_path.iterdir()) == []


def test_sigterm_during_a_run_keeps_the_checkpoint_and_exits_143(tmp_path):
    partial = tmp_path / "out.nc.partial"
    status, err = interrupt(["run", "rubio2022_misalignment", "--quiet", "-o", "out.nc"],
                            tmp_path, after=0.0,
                            wait_for=lambda: any(partial.glob("chunk-*.sha256")),
                            number=signal.SIGTERM)
    assert status == 143, err
    assert err.strip().splitlines() == ["uq: terminated; finished chunks are kept in "
                                        "out.nc.partial; run the same command with --resume "
                                        "to continue"]
    assert not (tmp_path / "out.nc").exists()


def test_timeout_of_golden_leaves_nothing(tmp_path):
    """`timeout` (coreutils) sends SIGTERM when its time is up: nothing stays behind,
    whenever it lands (before, during or after the partial folder exists)."""
    for seconds in ("1", "3", "5"):
        done = subprocess.run(["timeout", seconds, sys.executable, "-m", "uq.cli", "golden",
                               "golden_campaign", "-o", "out"], cwd=tmp_path,
                              capture_output=True, text=True, timeout=300)
        assert "Traceback" not in done.stderr, done.stderr
        if done.returncode == 0:                 # finished within the time: its folder
            assert [p.name for p in tmp_path.iterdir()] == ["out"]
            break
        assert done.returncode == 124, done.stderr      # timeout's code after its SIGTERM
        assert list(tmp_path.iterdir()) == [], seconds


def test_an_interrupt_raised_inside_a_callback_is_not_lost():
    """SIGTERM's exception raised where Python cannot propagate it (a weakref callback,
    a finaliser) is neither printed as 'Exception ignored' with a traceback nor dropped:
    the signal comes again and ends the block at the next safe point."""
    import types
    from uq.interrupts import stopping_on_signals
    from uq.errors import Terminated
    unraisable = types.SimpleNamespace(exc_type=Terminated, exc_value=Terminated(),
                                       exc_traceback=None, err_msg=None, object=None)
    before = sys.unraisablehook
    with pytest.raises(Terminated):
        with stopping_on_signals():
            sys.unraisablehook(unraisable)           # as Python does inside a callback
            for _ in range(1000):                    # the redelivered signal lands here
                time.sleep(0.001)
    assert sys.unraisablehook is before                  # restored after the block


def test_dask_is_silenced_before_the_stop_is_raised():
    """Ctrl-C during a distributed run: dask's and its event loop's loggers are quiet
    before KeyboardInterrupt reaches any code (the loop thread logs the cancel's failure
    at once), and the earlier handlers are back afterwards."""
    import logging
    import os
    import pytest
    from uq.cli.run import DASK_LOGGERS, _quiet_at_stop
    levels = {name: logging.getLogger(name).level for name in DASK_LOGGERS}
    before = signal.getsignal(signal.SIGINT), signal.getsignal(signal.SIGTERM)
    for name in DASK_LOGGERS:
        logging.getLogger(name).setLevel(logging.NOTSET)
    # the earlier handler is Python's own (a test runner's worker may have inherited
    # SIGINT ignored, and then no stop is raised, rightly)
    inherited = signal.signal(signal.SIGINT, signal.default_int_handler)
    before = signal.getsignal(signal.SIGINT), signal.getsignal(signal.SIGTERM)
    try:
        with pytest.raises(KeyboardInterrupt):
            with _quiet_at_stop():
                os.kill(os.getpid(), signal.SIGINT)
                for _ in range(10 ** 6):        # the handler runs between bytecodes
                    pass
        assert all(logging.getLogger(name).level == logging.CRITICAL
                   for name in DASK_LOGGERS)
        assert (signal.getsignal(signal.SIGINT), signal.getsignal(signal.SIGTERM)) == before
    finally:
        signal.signal(signal.SIGINT, inherited)
        for name, level in levels.items():
            logging.getLogger(name).setLevel(level)


#: A ``sitecustomize`` that sends this process Ctrl-C when the module named by
#: UQ_TEST_INTERRUPT_AT is first imported: the interrupt lands at a chosen moment of the
#: command's start, without timing it.
INTERRUPT_AT_IMPORT = '''
import os, signal, sys

class InterruptAt:
    def find_spec(self, name, path=None, target=None):
        if name == os.environ["UQ_TEST_INTERRUPT_AT"]:
            sys.meta_path.remove(self)
            os.kill(os.getpid(), signal.SIGINT)
        return None

sys.meta_path.insert(0, InterruptAt())
'''


@pytest.mark.parametrize("module", [
    "uq.numbacache", "uq._version", "uq.cli", "uq.cli.common", "argparse", "uq.cli.streams",
    "uq.cli.run", "uq.cli.golden", "uq.cli.warmup", "uq.pipeline.shipped", "yaml"])
def test_ctrl_c_while_the_command_starts_is_one_line_and_130(tmp_path, module):
    """Ctrl-C while ``uq`` is importing its own modules (~0.05-0.1 s after the start):
    it was a KeyboardInterrupt traceback and death by SIGINT; now the stop is held until
    the command can handle it (:func:`uq.interrupts.hold_while_starting`). Only the
    interpreter's own start and the import of uq.interrupts come before."""
    (tmp_path / "hook").mkdir()
    (tmp_path / "hook" / "sitecustomize.py").write_text(INTERRUPT_AT_IMPORT)
    environment = {**os.environ, "UQ_TEST_INTERRUPT_AT": module,
                   "PYTHONPATH": os.pathsep.join([str(tmp_path / "hook")] + [
                       p for p in os.environ.get("PYTHONPATH", "").split(os.pathsep) if p])}
    done = subprocess.run([sys.executable, "-m", "uq.cli", "check", "rubio2022_case_i"],
                          cwd=tmp_path, capture_output=True, text=True, env=environment,
                          preexec_fn=as_from_a_terminal, timeout=600)
    assert done.returncode == 130, (module, done.returncode, done.stderr)
    assert done.stderr.strip().splitlines() == ["uq: interrupted"], done.stderr
    assert done.stdout == ""


def test_the_held_stop_only_for_the_command():
    """A program that imports uq keeps Python's Ctrl-C (a KeyboardInterrupt where it
    lands); the command's console script and ``python -m uq.cli`` hold it."""
    from uq.interrupts import hold_while_starting
    assert hold_while_starting(["python", "notebook.py"]) is False
    assert signal.getsignal(signal.SIGINT) is not __import__("uq").interrupts.hold


def test_a_dask_client_closed_again_after_its_loop_is_quiet():
    """A dask client's close at garbage collection after its loop has gone (a stop during
    its close) prints nothing; any other unraisable exception reaches the earlier hook."""
    from types import SimpleNamespace
    from uq.interrupts import _unraisable_hook
    seen = []
    hook = _unraisable_hook(seen.append)

    def __del__(self):
        pass
    __del__.__qualname__, __del__.__module__ = "Client.__del__", "distributed.client"
    client = SimpleNamespace(exc_type=RuntimeError, exc_value=RuntimeError("IOLoop is closed"),
                             object=__del__)
    other = SimpleNamespace(exc_type=RuntimeError, exc_value=RuntimeError("IOLoop is closed"),
                            object=print)
    hook(client)
    hook(other)
    assert seen == [other]
