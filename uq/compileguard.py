"""Run a compiled kernel only if numba's on-disk cache holds it: never compile.

``uq run`` (its default ``--model auto``) evaluates a chunk with the compiled model
inside :func:`cached_only`: where a kernel the chunk calls is not in numba's cache for
this source, this numba and this CPU, numba would compile it (seconds to tens of
seconds on a first run); here it raises :class:`KernelNotCached` instead, and the
chunk runs the numpy model (the same numbers to 1e-12,
``tests/pipeline/test_model_switch.py``) while the kernels compile in another process
for later runs (:mod:`uq.cli.firstrun`).

The test is numba's own: its ``numba:compile`` event (the documented event API,
:mod:`numba.core.event`) fires only after a dispatcher found no entry in its cache
index (wrong source stamp, numba version, CPU or signature) and before it compiles; the
listener raises there, which ends that compile before it starts. A kernel found in the
cache loads as usual. Imports numba only when entered.

The lock of the background compile of a numba cache (:func:`lock_path`, one per cache
folder and user; :mod:`uq.cli.firstrun` takes it) is here too, so that whatever waits
for that compile (``uq bench``, CI) needs no command-line module.
"""
import contextlib
import threading

#: The numba event that precedes a compile (and never a load from the cache).
COMPILE_EVENT = "numba:compile"

_LOCK = threading.Lock()
_ACTIVE = [0]                    # guards entered and not left (any thread)


class KernelNotCached(RuntimeError):
    """A kernel that numba would have to compile: not in its on-disk cache."""


def active():
    """Whether a :func:`cached_only` guard is open (:mod:`uq.cli.compiling` then prints
    nothing for the compile that is refused)."""
    return _ACTIVE[0] > 0


@contextlib.contextmanager
def cached_only():
    """Within: a kernel missing from numba's cache raises :class:`KernelNotCached`
    (naming it) instead of compiling; kernels in the cache load and run as usual."""
    from numba.core import event

    class _Refuse(event.Listener):
        def on_start(self, item):
            raise KernelNotCached(_kernel_name(item.data))

        def on_end(self, item):
            pass
    listener = _Refuse()
    with _LOCK:
        _ACTIVE[0] += 1
    event.register(COMPILE_EVENT, listener)
    try:
        yield
    finally:
        event.unregister(COMPILE_EVENT, listener)
        with _LOCK:
            _ACTIVE[0] -= 1


def _kernel_name(data):
    """'module.function' of a compile event's data."""
    function = getattr(data.get("dispatcher"), "py_func", None)
    return f"{function.__module__}.{function.__name__}" if function else "a kernel"


def lock_path(folder=None):
    """The lock file of the background compile of numba's cache in `folder` (default:
    this process's, ``NUMBA_CACHE_DIR`` or beside the code): one per cache folder and
    user, in the temporary folder."""
    import hashlib
    import os
    import tempfile
    if folder is None:
        import numba
        folder = numba.config.CACHE_DIR or os.path.dirname(os.path.abspath(__file__))
    digest = hashlib.sha256(os.path.abspath(folder).encode()).hexdigest()[:16]
    return os.path.join(tempfile.gettempdir(), f"uq-compile-{os.getuid()}-{digest}.lock")


def wait_for_background(folder=None):
    """Wait until no background compile of numba's cache in `folder` (default this
    process's) holds its lock, i.e. until one running has ended; returns at once when
    none runs."""
    import fcntl
    import os
    try:
        handle = os.open(lock_path(folder), os.O_RDWR | os.O_CREAT, 0o600)
    except OSError:
        return
    try:
        fcntl.flock(handle, fcntl.LOCK_EX)                 # blocks while one compiles
    finally:
        os.close(handle)
