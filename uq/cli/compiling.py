"""Say on stderr when a command compiles numba kernels, kernel by kernel, and how long.

The first run after an install (or after an upgrade of numba, or a change of a kernel's
source) compiles the kernels it calls into numba's on-disk cache; later runs load them
in milliseconds. :class:`CompileNotice` listens to numba's ``numba:compile`` events
(its documented event API, :mod:`numba.core.event`), which fire only for a compile,
never for a load from the cache: each top-level kernel prints one line (its name, its
number type and the seconds it took), and :attr:`CompileNotice.seconds` adds them up
for the run's summary. Helpers compiled inside a kernel are part of its line. Nothing is
printed with ``--quiet``, or when nothing compiles (a warm cache).
"""
import sys
import threading
import time

#: What the first line says, once per process.
FIRST_LINE = ("uq: compiling kernels into numba's cache (once after an install; "
              "`uq warmup` compiles them all ahead)")
#: How every line of the notice starts (tests tell it from other output by this).
PREFIX = "uq: compiling"


class CompileNotice:
    """A ``numba:compile`` listener that prints a line per top-level kernel compiled.

    Parameters
    ----------
    stream : file or None
        Where the lines go; None prints nothing but still counts.
    """

    def __init__(self, stream):
        self.stream = stream
        self.seconds = 0.0              # wall time of the top-level compiles [s]
        self.kernels = 0                # top-level compiles
        self._local = threading.local()
        self._told = False

    def install(self):
        """Register with numba (imports numba); returns self."""
        from numba.core import event
        listener = self

        class _Listener(event.Listener):
            def on_start(self, item):
                listener._start(item)

            def on_end(self, item):
                listener._end(item)
        self._listener = _Listener()
        event.register("numba:compile", self._listener)
        return self

    def remove(self):
        """Unregister from numba (a command's notice ends with the command)."""
        from numba.core import event
        event.unregister("numba:compile", self._listener)

    def __enter__(self):
        return self.install()

    def __exit__(self, *exc):
        self.remove()

    def _start(self, item):
        from uq.compileguard import active
        if active():                    # refused, not compiled (uq.compileguard)
            return
        depth = getattr(self._local, "depth", 0)
        self._local.depth = depth + 1
        if depth == 0:
            self._local.started = time.perf_counter()
            if self.stream is not None:
                if not self._told:
                    print(FIRST_LINE, file=self.stream, flush=True)
                    self._told = True
                print(f"{PREFIX} {kernel_name(item.data)} ...", end="", file=self.stream,
                      flush=True)

    def _end(self, item):
        from uq.compileguard import active
        if active():
            return
        self._local.depth -= 1
        if self._local.depth == 0:
            elapsed = time.perf_counter() - self._local.started
            self.seconds += elapsed
            self.kernels += 1
            if self.stream is not None:
                print(f" {elapsed:.1f} s", file=self.stream, flush=True)


def kernel_name(data):
    """'module.function (number type)' of a compile event's data."""
    dispatcher = data.get("dispatcher")
    function = getattr(dispatcher, "py_func", None)
    name = f"{function.__module__.rsplit('.', 1)[-1]}.{function.__name__}" if function \
        else str(dispatcher)
    text = str(data.get("args", ""))
    number = "complex" if "complex" in text else "float"
    return f"{name} ({number})"


def notice(args):
    """A CompileNotice for a command's `args` on stderr (silent with --quiet), to be
    used as a context manager around the command."""
    return CompileNotice(None if getattr(args, "quiet", False) else sys.stderr)
