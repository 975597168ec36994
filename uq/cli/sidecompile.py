"""Compile a record-mode run's kernels in a second process while this one draws the
turbulence boxes (``uq run``, first run after an install).

A record-mode run (a ``turbulence`` section with Monte Carlo records) spends its first
~20 s drawing Mann boxes (numpy and scipy's FFT, :mod:`uq.pipeline.records`) and, on a
cold numba cache, ~17-35 s compiling the measurement model's and the statistics'
kernels, one after the other on one core. Here ``uq warmup --for`` (the same scenario
without its records, a few trials per scene: every kernel its per-scan Monte Carlo calls,
into numba's on-disk cache, :mod:`uq.cli.warmup`) runs in a child process on the second
core while the boxes are drawn; the run waits for it (:meth:`SideCompile.wait`) before its
model first runs (:func:`uq.pipeline.runner.run`'s `kernels_ready`) and then loads the
kernels from the cache. The numbers never depend on it: the child only fills the cache
(the same kernels, the same code; a cold and a warm run are bit-identical). Where the
child fails, the run compiles as it would without it.

Started only where it can help and the machine has room: the compiled model on this
machine (no ``--workers`` or ``--scheduler``: a cluster's workers compile for
themselves), two or more usable cores, :data:`SIDE_COMPILE_MIN_AVAILABLE_MB` of free
memory (the two processes together peak at ~870 MB against ~490 MB for one), and a
cache that does not hold the kernels yet (:func:`kernels_cached`).
"""
import logging
import os
import subprocess
import sys
import tempfile
import time

from uq.cpus import usable_cpus

#: Trials per scene of the child's run: the kernels' types, not their work, matter.
SIDE_COMPILE_TRIALS = 64
#: Memory the machine must have free to start the child [MB]: its peak (~390-400 MB,
#: ``uq warmup --for sathe2011_ti`` on an empty cache, 2026-11-25) beside the run's own
#: (~490 MB), with room to spare; with less the run compiles its kernels itself.
SIDE_COMPILE_MIN_AVAILABLE_MB = 1024
#: Seconds the run waits for the child to end after asking it to stop.
SIDE_COMPILE_STOP_SECONDS = 5.0

LOG = logging.getLogger(__name__)


def usable_cores():
    """The cores this process may run on [1] (:func:`uq.cpus.usable_cpus`)."""
    return usable_cpus()


#: The largest kernel of each kind of record-mode run, (module, function): a cache that
#: holds it for the current source holds the run's kernels (:func:`kernels_cached`).
LARGEST_KERNELS = {False: ("uq.physics.fusedkernels", "wind_scan"),
                   True: ("uq.physics.fusedmotionkernels", "reconstruct")}


def available_memory_mb():
    """Memory the machine has free for a new process [MB] (``MemAvailable`` of
    /proc/meminfo; elsewhere the free physical pages); 0 where unknown."""
    try:
        with open("/proc/meminfo", encoding="ascii") as file:
            for line in file:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) / 1024
    except OSError:
        pass
    try:
        return os.sysconf("SC_AVPHYS_PAGES") * os.sysconf("SC_PAGE_SIZE") / 2**20
    except (AttributeError, ValueError, OSError):
        return 0.0


def kernels_cached(time_resolved=False):
    """Whether numba's cache holds the largest kernel of a static (or `time_resolved`)
    record-mode run for the current source (:data:`LARGEST_KERNELS`), asked without
    importing its module (the motion kernels compile on import): numba's own index
    file and source stamp, found for a stand-in function of the kernel's file, name and
    first line (:func:`_stand_in`). Unknown (numba's internals changed): False."""
    try:
        from numba.core.caching import FunctionCache
        return bool(FunctionCache(_stand_in(*LARGEST_KERNELS[time_resolved]))
                    ._cache_file._load_index())
    except Exception:                        # noqa: BLE001 (an internal API: be safe)
        return False


def _stand_in(module, name):
    """A function with the code location numba's cache keys a kernel by: the module's
    file, the kernel's name and its first line (its first decorator's, as Python
    records it), read from the source with :mod:`ast`."""
    import ast
    import importlib.util
    import types
    path = importlib.util.find_spec(module).origin
    with open(path, encoding="utf-8") as file:
        tree = ast.parse(file.read(), path)
    (node,) = [n for n in tree.body if isinstance(n, ast.FunctionDef) and n.name == name]
    line = min([node.lineno] + [d.lineno for d in node.decorator_list])
    code = _stand_in.__code__.replace(co_filename=path, co_firstlineno=line, co_name=name,
                                      co_qualname=name)
    function = types.FunctionType(code, {})
    function.__qualname__ = name
    return function


def draws_records(scenario):
    """Whether a run of `scenario` draws Monte Carlo turbulence records (record mode
    with ``sampling.method`` other than none)."""
    return "turbulence" in scenario.settings and scenario.sampling["method"] != "none"


def wanted(args, scenario):
    """Whether ``uq run`` `args` of `scenario` should compile its kernels beside."""
    from uq.pipeline import motionsection
    return (draws_records(scenario) and getattr(args, "model", "compiled") == "compiled"
            and getattr(args, "workers", None) is None
            and getattr(args, "scheduler", None) is None
            and usable_cores() >= 2
            and available_memory_mb() >= SIDE_COMPILE_MIN_AVAILABLE_MB
            and not kernels_cached(motionsection.is_time_resolved(scenario.settings)))


class SideCompile:
    """The child process of ``uq warmup --for`` a scenario (see the module docstring).

    Parameters
    ----------
    settings : dict
        The run's validated settings (written to a temporary file for the child).
    stream : file or None
        Where :meth:`wait` says how long the compile took (None: nothing is said). The
        child itself prints nothing (``-q``, its output discarded): its lines would cut
        into the run's.

    Attributes
    ----------
    waited : float
        Wall time the run waited for the child [s] (part of the run's compile time).
    """

    def __init__(self, settings, stream):
        import yaml                          # (not on the command line's import path)
        handle, self.path = tempfile.mkstemp(prefix="uq-side-compile-", suffix=".yaml")
        with os.fdopen(handle, "w") as file:
            yaml.safe_dump(settings, file)
        self.stream, self.waited = stream, 0.0
        self.started = time.perf_counter()
        command = [sys.executable, "-m", "uq.cli", "warmup", "--for", self.path, "-q"]
        # its own session: Ctrl-C at the terminal reaches the run, which stops the child;
        # nothing of it on the terminal (its "terminated" when the run stops it, say)
        self.child = subprocess.Popen(command, stdin=subprocess.DEVNULL,
                                      stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                                      start_new_session=True)

    def wait(self):
        """Wait for the child (called before the run's model first runs); True where
        it filled the cache."""
        if self.child is None:
            return True
        if self.child.poll() is None:
            # the statistics' kernels, which the child compiles last, here meanwhile:
            # the child then loads them (a kernel both compile is only time lost; this
            # compile is counted by the command's own notice, not in `waited`)
            import uq.engine.statkernels  # noqa: F401  (compiled or loaded on import)
        waiting = time.perf_counter()
        status = self.child.wait()
        self.waited = time.perf_counter() - waiting
        self.child = None
        self._remove_file()
        if status != 0:
            LOG.info("the kernels' compile beside the run ended with status %s: the run "
                     "compiles them itself", status)
        elif self.stream is not None:
            print(f"uq: the model's kernels compiled beside the boxes in "
                  f"{time.perf_counter() - self.started:.1f} s (the run waited "
                  f"{self.waited:.1f} s for them)", file=self.stream, flush=True)
        return status == 0

    def stop(self):
        """End the child if it still runs (the run failed or was stopped)."""
        if self.child is not None and self.child.poll() is None:
            self.child.terminate()
            try:
                self.child.wait(SIDE_COMPILE_STOP_SECONDS)
            except subprocess.TimeoutExpired:
                self.child.kill()
                self.child.wait()
        self.child = None
        self._remove_file()

    def _remove_file(self):
        try:
            os.unlink(self.path)
        except FileNotFoundError:
            pass


def side_compile(args, scenario):
    """A started :class:`SideCompile` for ``uq run`` `args` of `scenario`, or None."""
    if not wanted(args, scenario):
        return None
    return SideCompile(scenario.settings, None if getattr(args, "quiet", False)
                       else sys.stderr)
