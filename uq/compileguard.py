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

The same guard serves the kernels a record-mode run calls outside its chunks' model
(the colouring of its turbulence boxes, their sampling along the beams, the spectral
path's sums): within :func:`numpy_while_uncached` (``uq run --model auto``),
:func:`cached_kernels` hands their module to the caller only where numba's cache holds
its kernels, else None and the caller takes its numpy equivalent (the same numbers to
rounding); it looks again, at most every :data:`RETRY_SECONDS`, so that a run takes
the compiled kernels once the background compile has written them.

The lock of the background compile of a numba cache (:func:`lock_path`, one per cache
folder and user; :mod:`uq.cli.firstrun` takes it) is here too, so that whatever waits
for that compile (``uq bench``, CI) needs no command-line module.
"""
import contextlib
import importlib
import sys
import threading
import time

#: The numba event that precedes a compile (and never a load from the cache).
COMPILE_EVENT = "numba:compile"

#: Seconds between two looks for a kernel module found missing from numba's cache
#: (:func:`cached_kernels`): a look that fails costs the module's import (~10 ms); the
#: background compile of a record's kernels takes seconds.
RETRY_SECONDS = 1.0

_LOCK = threading.Lock()
_ACTIVE = [0]                    # guards entered and not left (any thread)
_NUMPY_WHILE_UNCACHED = [0]      # numpy_while_uncached entered and not left
_MISSED = {}                     # module name -> time of the last look that failed


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


@contextlib.contextmanager
def numpy_while_uncached():
    """Within (process-wide, any thread): :func:`cached_kernels` returns None for a
    kernel module that numba would have to compile, and nothing compiles."""
    with _LOCK:
        _NUMPY_WHILE_UNCACHED[0] += 1
    try:
        yield
    finally:
        with _LOCK:
            _NUMPY_WHILE_UNCACHED[0] -= 1


def cached_kernels(name):
    """The kernel module `name` (e.g. ``"uq.physics.turbulencekernels"``, whose kernels
    compile on import): imported as usual (compiling what numba's cache lacks); within
    :func:`numpy_while_uncached`, None where its kernels are not all in the cache (the
    caller then runs its numpy equivalent), looked for again at most every
    :data:`RETRY_SECONDS`."""
    # (importlib, not sys.modules: a module another thread is importing is waited for)
    if not _NUMPY_WHILE_UNCACHED[0] or name in sys.modules:
        return importlib.import_module(name)
    with _LOCK:
        if time.monotonic() - _MISSED.get(name, -float("inf")) < RETRY_SECONDS:
            return None
    try:
        with cached_only():
            return importlib.import_module(name)
    except KernelNotCached:
        with _LOCK:
            _MISSED[name] = time.monotonic()
        return None


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
