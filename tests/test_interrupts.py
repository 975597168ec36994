"""A Ctrl-C or SIGTERM that library code drops is not lost (uq.interrupts): it stays
pending until an ``except`` handles it, it is sent again when dropped, and nothing is
committed while it is pending (an atomic file, a folder, a run's next chunk, a
command's exit status).

CI once saw ``uq run`` finish with status 0 after Ctrl-C (the stop was raised in an
import lock's weakref callback, and sent again from inside the unraisable hook, where it
was dropped a second time). Dropping in C is imitated here by an ``except
BaseException: pass`` around the signal."""
import gc
import os
import signal
import sys
import time
import weakref

import pytest

import uq.cli.listing
import uq.pipeline.sweep
from uq import interrupts
from uq.cli import main
from uq.errors import Terminated
from uq.files import atomic_file, new_partial_folder, replace_folder
from uq.pipeline.checkpoint import Checkpoint
from uq.pipeline.runner import run
from uq.pipeline.scenario import load_scenario


@pytest.fixture
def python_sigint():
    """SIGINT as a terminal leaves a Python program (a pytest-xdist worker may have it
    ignored); the test process's handler is restored afterwards."""
    before = signal.signal(signal.SIGINT, signal.default_int_handler)
    yield
    signal.signal(signal.SIGINT, before)
    interrupts.acknowledge()


def swallowed(number):
    """Send `number` to this process inside code that discards the exception."""
    try:
        os.kill(os.getpid(), number)
        for _ in range(10 ** 4):                 # the handler runs between bytecodes
            pass
    except BaseException:
        pass


def waiting(seconds=30.0):
    """Run Python code for up to `seconds` (a stop sent again is raised in here; the
    watcher sends it after ~20 ms, the bound only ends a test that fails)."""
    for _ in range(int(seconds / 0.001)):
        time.sleep(0.001)


@pytest.fixture
def no_watcher(monkeypatch):
    """The watcher never sends a stop again (as if the main thread always looked busy
    with it): only the checks before a commit are left to find it."""
    monkeypatch.setattr(interrupts, "WATCH_LOOKS", 10 ** 9)


@pytest.mark.parametrize("number, exception", [(signal.SIGINT, KeyboardInterrupt),
                                               (signal.SIGTERM, Terminated)])
def test_a_dropped_stop_is_sent_again(python_sigint, number, exception):
    with interrupts.stopping_on_signals():
        with pytest.raises(exception):
            swallowed(number)
            assert interrupts.pending() == number
            waiting()
        assert interrupts.acknowledge() == number
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler   # restored


def test_a_dropped_stop_stays_pending_until_handled(python_sigint, no_watcher):
    with interrupts.stopping_on_signals():
        swallowed(signal.SIGINT)
        for _ in range(2):                       # raised again until handled
            with pytest.raises(KeyboardInterrupt):
                interrupts.raise_if_stopped()
        assert interrupts.acknowledge() == signal.SIGINT
        interrupts.raise_if_stopped()            # handled: nothing raised


def test_a_stop_raised_in_a_weakref_callback_comes_again(python_sigint):
    """As CI saw it: Ctrl-C lands in a weakref callback (an import's module lock has
    one), where Python only hands the exception to the unraisable hook. It is raised
    again in the main flow, once the hook has returned (sent from inside the hook it
    landed in the hook and was dropped too)."""
    class Thing:
        pass

    def callback(reference):
        os.kill(os.getpid(), signal.SIGINT)
        for _ in range(10 ** 6):                 # the handler raises in here
            pass

    with interrupts.stopping_on_signals():
        thing = Thing()
        reference = weakref.ref(thing, callback)
        with pytest.raises(KeyboardInterrupt):
            del thing                            # the callback runs: its error is dropped
            gc.collect()
            waiting()                            # the stop sent again lands here
        assert reference() is None
        assert interrupts.acknowledge() == signal.SIGINT


def test_no_second_stop_while_the_first_is_cleaned_up(python_sigint):
    """A KeyboardInterrupt dropped in a finaliser while the same stop is being handled
    in the main flow (its clean-up running) is not sent again."""
    import types
    dropped = types.SimpleNamespace(exc_type=KeyboardInterrupt, exc_value=KeyboardInterrupt(),
                                    exc_traceback=None, err_msg=None, object=None)
    with interrupts.stopping_on_signals():
        try:
            interrupts.stop(signal.SIGINT)
        except KeyboardInterrupt:
            sys.unraisablehook(dropped)          # as Python does inside a finaliser
            waiting(0.2)                         # 10x the watcher's delay: no second stop
            assert interrupts.acknowledge() == signal.SIGINT


def test_nothing_is_pending_outside_the_command_line(python_sigint):
    """Library use (no stopping_on_signals): Python's own KeyboardInterrupt, nothing
    written down, the checks are no-ops."""
    swallowed(signal.SIGINT)
    assert interrupts.pending() is None
    interrupts.raise_if_stopped()


def test_ctrl_c_during_a_library_write_is_not_left_pending(python_sigint, tmp_path):
    """A write held back by Ctrl-C (uq.files.deferred_interrupt) outside the command line
    raises KeyboardInterrupt and leaves no stop pending: a notebook's later writes go on,
    and no watcher sends the signal again."""
    target = tmp_path / "out.txt"
    with pytest.raises(KeyboardInterrupt):
        with atomic_file(target) as temporary:
            os.kill(os.getpid(), signal.SIGINT)    # held back until the file is whole
            temporary.write_text("result")
    assert interrupts.pending() is None
    later = tmp_path / "later.txt"
    with atomic_file(later) as temporary:          # the next write is committed
        temporary.write_text("result")
    assert later.read_text() == "result"


def test_a_foreign_sigint_handler_is_kept(python_sigint):
    """A program running ``main`` inside its own with its own Ctrl-C handler keeps it."""
    def own(number, frame):
        pass
    signal.signal(signal.SIGINT, own)
    with interrupts.stopping_on_signals():
        assert signal.getsignal(signal.SIGINT) is own
        assert signal.getsignal(signal.SIGTERM) is interrupts.stop
    assert signal.getsignal(signal.SIGINT) is own


def test_an_atomic_file_is_not_committed_while_a_stop_is_pending(python_sigint, no_watcher,
        tmp_path):
    target = tmp_path / "out.txt"
    with interrupts.stopping_on_signals():
        swallowed(signal.SIGINT)
        with pytest.raises(KeyboardInterrupt):
            with atomic_file(target) as temporary:
                temporary.write_text("result")
    assert list(tmp_path.iterdir()) == []        # neither the file nor its temporary


def test_a_folder_is_not_put_in_place_while_a_stop_is_pending(python_sigint, no_watcher,
        tmp_path):
    folder = tmp_path / "report"
    partial = new_partial_folder(folder)
    (partial / "report.md").write_text("result")
    with interrupts.stopping_on_signals():
        swallowed(signal.SIGTERM)
        with pytest.raises(Terminated):
            replace_folder(partial, folder, kind="golden")
    assert list(tmp_path.iterdir()) == []        # the partial folder removed, no folder


def test_a_run_stops_after_the_chunk_it_finished(python_sigint, no_watcher,
        tmp_path, monkeypatch):
    """The chunk that was computing when the stop was swallowed is kept for --resume;
    no further chunk is computed."""
    monkeypatch.setattr(uq.pipeline.sweep, "SWEEP_CHUNK_ELEMENTS", 1)
    monkeypatch.setattr(uq.pipeline.sweep, "SWEEP_CHUNK_ELEMENTS_COMPILED", 1)
    scenario = load_scenario({"name": "tiny", "sampling": {"n": 500, "seed": 7},
                              "lidar": {"errors": {"radial_velocity": {"dist": "normal",
                                                                       "u": 0.1}}},
                              "sweep": {"wind.direction": [0.0, 90.0, 180.0]}})
    directory = tmp_path / "out.nc.partial"
    with interrupts.stopping_on_signals():
        swallowed(signal.SIGINT)
        with pytest.raises(KeyboardInterrupt):
            run(scenario, checkpoint=Checkpoint(directory).acquire())
    assert len(list(directory.glob("chunk-*.nc"))) == 1


def test_a_command_that_swallowed_ctrl_c_exits_130(python_sigint, no_watcher,
        monkeypatch, capsys):
    """The command ran to its end, but the user asked it to stop: 130, one line."""
    def command(args):
        swallowed(signal.SIGINT)
        print("listed")
        return 0
    monkeypatch.setattr(uq.cli.listing, "command", command)
    before = signal.getsignal(signal.SIGTERM), sys.unraisablehook
    assert main(["list"]) == 130
    captured = capsys.readouterr()
    assert captured.out == "listed\n" and captured.err == "\nuq: interrupted\n"
    assert interrupts.pending() is None          # handled
    assert (signal.getsignal(signal.SIGTERM), sys.unraisablehook) == before   # restored


def test_a_stop_turned_into_another_error_is_the_stop(python_sigint, no_watcher, monkeypatch,
                                                        capsys):
    """Ctrl-C landing in a C extension's initialisation made its import fail with
    "ImportError: initialization failed" (its cause the KeyboardInterrupt): seen in a
    test run as status 1 and a traceback. With the stop pending, that is the stop."""
    def command(args):
        swallowed(signal.SIGINT)
        raise ImportError("initialization failed")
    monkeypatch.setattr(uq.cli.listing, "command", command)
    assert main(["list"]) == 130
    assert capsys.readouterr().err == "\nuq: interrupted\n"


def test_an_error_without_a_stop_stays_the_error(python_sigint, monkeypatch):
    def command(args):
        raise ImportError("initialization failed")
    monkeypatch.setattr(uq.cli.listing, "command", command)
    with pytest.raises(ImportError):
        main(["list"])
