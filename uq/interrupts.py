"""A stop that is never lost: Ctrl-C (SIGINT) and SIGTERM remembered until handled.

Python turns SIGINT into a KeyboardInterrupt raised in whatever Python code runs next
in the main thread, and that code may be somewhere the exception cannot leave: a
finaliser or a weakref callback (the import system's module locks have one, so any
import can be there) only prints it, and C code that calls Python and clears its error
(``PyDict_GetItem``, ``PyObject_HasAttr`` before Python 3.13) drops it. The earlier
remedy, sending the signal again from the unraisable-exception hook, lost it too: the
handler ran at once, inside the hook, whose exception is dropped as well. A run
interrupted so went on to the end and wrote its results with status 0 (once in CI;
twice in 600 Ctrl-C sent 0.05-1.55 s into a first run; the one traced was raised in a
module lock's callback during an import).

So the handler (:func:`stop`) writes the stop down before it raises, and the stop
stays *pending* until an ``except`` that handles it says so (:func:`acknowledge`).
Two things make sure it arrives:

* a watcher thread (:func:`_watch`) sends the signal again when, a little later, the
  stop is still pending and the main thread is not cleaning up after it (in an
  ``except``, ``finally`` or ``__exit__`` of a KeyboardInterrupt): it was dropped;
* code that commits a result asks first (:func:`raise_if_stopped`): the atomic file and
  folder writes of :mod:`uq.files`, each finished chunk of :mod:`uq.pipeline.runner`,
  and the command line's ``main`` when a command returns, or when it fails: an error
  raised while a stop is pending is taken for the stop (library code can turn the
  KeyboardInterrupt into another error: a C extension's import fails with
  "ImportError: initialization failed" when Ctrl-C lands in its initialisation).

Outside the command line nothing is ever pending (only :func:`stopping_on_signals`
installs the handler) and the checks are one dict read. No numpy; main thread only
(where Python runs signal handlers).
"""
import contextlib
import os
import signal
import sys
import threading
import time

from uq.errors import Terminated

#: The signal number of the stop not yet handled, or None.
_pending = {"number": None}

#: How often the watcher looks at a pending stop [s]. A stop is sent again after two
#: looks in a row found it pending with the main thread not handling it, so 10-20 ms
#: after it was dropped: ~1e4 bytecodes, well out of the finaliser or C call that
#: dropped it (sent from there, it would be dropped there again), and well under what a
#: person notices after Ctrl-C.
WATCH_INTERVAL_S = 0.01
#: Looks in a row that find the stop dropped before it is sent again: one look can
#: fall in the microseconds when the exception unwinds frames with no handler.
WATCH_LOOKS = 2


def exception_for(number):
    """The exception a stop raises: :class:`~uq.errors.Terminated` for SIGTERM,
    KeyboardInterrupt for SIGINT."""
    return Terminated() if number == signal.SIGTERM else KeyboardInterrupt()


def stop(number, frame=None):
    """Signal handler: write the stop down, watch that it arrives, raise its exception."""
    _note(number)
    raise exception_for(number)


def pending():
    """The signal number of a stop not yet handled, or None."""
    return _pending["number"]


def raise_if_stopped():
    """Raise the pending stop's exception again (it was lost on its way), if any."""
    number = _pending["number"]
    if number is not None:
        raise exception_for(number)


def acknowledge():
    """The stop is handled (its ``except`` ran): forget it; returns its number or None."""
    number, _pending["number"] = _pending["number"], None
    return number


def hold(number, frame=None):
    """Signal handler while the command is starting (:func:`hold_while_starting`): write
    the stop down, raise nothing (an exception raised inside an import reaches the user
    as a traceback); the command's ``main`` raises it once it can handle it."""
    _pending["number"] = number


def hold_while_starting(argv=None):
    """When this process is the ``uq`` command (its console script, or ``python -m
    uq.cli``), hold a Ctrl-C that lands while the package is imported (:func:`hold`)
    instead of raising it inside an import, where it ends the process with a traceback;
    ``uq.cli.main`` then exits 130 with one line. A program that imports uq keeps its own
    handler. Returns whether the handler was installed. (A Ctrl-C before Python starts
    importing uq, in its first tens of milliseconds, ends it as Python does.)"""
    argv = list(getattr(sys, "orig_argv", None) or sys.argv) if argv is None else argv
    command = any(os.path.basename(a) == "uq" for a in argv[1:2]) or \
        any(a == "-m" and b in ("uq.cli", "uq") for a, b in zip(argv, argv[1:]))
    if not command or threading.current_thread() is not threading.main_thread() or \
            signal.getsignal(signal.SIGINT) is not signal.default_int_handler:
        return False
    signal.signal(signal.SIGINT, hold)
    return True


def _note(number):
    """Write the stop `number` down and start its watcher."""
    _pending["number"] = number
    threading.Thread(target=_watch, args=(number,), daemon=True,
                     name="uq-stop-watcher").start()


def _watch(number):
    """Send `number` to this process again if the stop stays pending while the main
    thread does not handle it (:data:`WATCH_LOOKS` looks in a row); ends when the stop is
    handled. The sent signal runs :func:`stop` again, with a watcher of its own."""
    dropped = 0
    while _pending["number"] == number:
        time.sleep(WATCH_INTERVAL_S)
        dropped = 0 if _main_thread_handles_a_stop() else dropped + 1
        if dropped >= WATCH_LOOKS and _pending["number"] == number:
            os.kill(os.getpid(), number)
            return


def _main_thread_handles_a_stop():
    """Whether the main thread is in an ``except``, ``finally`` or ``__exit__`` of a
    KeyboardInterrupt (its ``sys.exc_info()``, read from another thread): cleaning up
    after the stop, which a second one would break (a dask client left half closed
    printed its failure at exit)."""
    handled = sys._current_exceptions().get(threading.main_thread().ident)
    if isinstance(handled, tuple):               # Python 3.11: an exc_info triple
        handled = handled[1]
    return isinstance(handled, KeyboardInterrupt)


def _unraisable_hook(previous_hook):
    """An unraisable-exception hook that keeps a stop quiet: a stop's exception dropped
    in a finaliser or weakref callback is not printed as "Exception ignored in ..." with
    a traceback; it stays pending and its watcher sends it again. Other exceptions go to
    `previous_hook`. Neither is a dask client's failed close at garbage collection once
    its event loop is gone ("IOLoop is closed", :func:`_closed_loop_client`): a run
    stopped during the client's close, and there is nothing left to close."""
    def hook(unraisable):
        if _closed_loop_client(unraisable):
            return
        if not issubclass(unraisable.exc_type, KeyboardInterrupt):
            previous_hook(unraisable)
            return
        number = signal.SIGTERM if issubclass(unraisable.exc_type, Terminated) \
            else signal.SIGINT
        if _pending["number"] != number:     # not raised by stop(): watch it here
            _note(number)
    return hook


def _closed_loop_client(unraisable):
    """Whether `unraisable` is ``distributed.Client.__del__``'s RuntimeError "IOLoop is
    closed": the client's second close, after its cluster and loop have stopped."""
    function = unraisable.object
    return (unraisable.exc_type is RuntimeError
            and "IOLoop is closed" in str(unraisable.exc_value)
            and getattr(function, "__qualname__", "") == "Client.__del__"
            and getattr(function, "__module__", "").startswith("distributed"))


@contextlib.contextmanager
def stopping_on_signals():
    """Within the block, SIGTERM (a batch system's time limit, ``timeout``) raises
    :class:`~uq.errors.Terminated` and Ctrl-C KeyboardInterrupt, each written down and
    watched until handled (:func:`stop`). SIGINT keeps an ignored or a foreign handler
    (a program that runs ``main`` inside its own). The earlier handlers and
    unraisable-exception hook are restored afterwards and a stop left pending is
    forgotten. Main thread only (elsewhere the block runs as it is)."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    numbers = [signal.SIGTERM]
    if signal.getsignal(signal.SIGINT) in (signal.default_int_handler, hold):
        numbers.append(signal.SIGINT)
    previous = {number: signal.signal(number, stop) for number in numbers}
    previous_hook = sys.unraisablehook
    sys.unraisablehook = _unraisable_hook(previous_hook)
    try:
        yield
    finally:
        for number, handler in previous.items():
            signal.signal(number, handler)
        sys.unraisablehook = previous_hook
        acknowledge()
