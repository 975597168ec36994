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
stays *pending* until an ``except`` that handles it says so (:func:`acknowledge`). A
stop discarded in a finaliser is sent again from a thread, after the hook has returned
(:func:`_redeliver`). Code that commits a result asks first (:func:`raise_if_stopped`):
the atomic file and folder writes of :mod:`uq.files` and each finished chunk of
:mod:`uq.pipeline.runner`; the command line's ``main`` asks once more when a command
returns. So a stop dropped in C costs at most the work up to the next commit, never a
result the user asked to stop. Outside the command line nothing is ever pending (only
:func:`stopping_on_signals` installs the handler) and the checks are one dict read. No
numpy; main thread only (where Python runs signal handlers).
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


def exception_for(number):
    """The exception a stop raises: :class:`~uq.errors.Terminated` for SIGTERM,
    KeyboardInterrupt for SIGINT."""
    return Terminated() if number == signal.SIGTERM else KeyboardInterrupt()


def stop(number, frame=None):
    """Signal handler: remember the stop, then raise its exception."""
    _pending["number"] = number
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


#: How long after a stop's exception was discarded it is sent again [s]: the exception
#: raised inside the unraisable-exception hook itself would be discarded too (the first
#: bytecode after ``os.kill`` runs the handler), so the signal comes from a thread once
#: the hook has returned; 10 ms is ~1e4 bytecodes later, well out of any finaliser.
REDELIVERY_DELAY_S = 0.01


def _redeliver(previous_hook):
    """An unraisable-exception hook that does not lose a stop: a signal handler's
    exception raised inside a callback Python cannot propagate from (a weakref's, as
    the import system's module locks have, a finaliser's) would be printed as
    "Exception ignored in ..." with a traceback and dropped, so the run would go on.
    The hook writes the stop down and has it sent again shortly (to be raised at the
    next point that can, silently); other exceptions go to `previous_hook`."""
    def hook(unraisable):
        if not issubclass(unraisable.exc_type, KeyboardInterrupt):
            previous_hook(unraisable)
            return
        number = signal.SIGTERM if issubclass(unraisable.exc_type, Terminated) \
            else signal.SIGINT
        _pending["number"] = number
        threading.Thread(target=_send_again, args=(number,), daemon=True).start()
    return hook


def _send_again(number):
    """Send `number` to this process after REDELIVERY_DELAY_S, unless handled by then."""
    time.sleep(REDELIVERY_DELAY_S)
    if _pending["number"] == number:
        os.kill(os.getpid(), number)


@contextlib.contextmanager
def stopping_on_signals():
    """Within the block, SIGTERM (a batch system's time limit, ``timeout``) raises
    :class:`~uq.errors.Terminated` and Ctrl-C KeyboardInterrupt, each written down first
    (:func:`stop`); one discarded in a finaliser is sent again (:func:`_redeliver`).
    SIGINT keeps an ignored or a foreign handler (a program that runs ``main`` inside
    its own). The earlier handlers and unraisable-exception hook are restored afterwards
    and a stop left pending is forgotten. Main thread only (elsewhere the block runs as
    it is)."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    numbers = [signal.SIGTERM]
    if signal.getsignal(signal.SIGINT) is signal.default_int_handler:
        numbers.append(signal.SIGINT)
    previous = {number: signal.signal(number, stop) for number in numbers}
    previous_hook, sys.unraisablehook = sys.unraisablehook, _redeliver(sys.unraisablehook)
    try:
        yield
    finally:
        for number, handler in previous.items():
            signal.signal(number, handler)
        sys.unraisablehook = previous_hook
        acknowledge()
