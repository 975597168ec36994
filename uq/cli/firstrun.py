"""``uq run``'s first run after an install: no wait for numba.

numba compiles a kernel the first time a process calls it and keeps it in its on-disk
cache; a run's kernels take 10-40 s of CPU to compile (one core), against 2-6 s for the
whole run of most shipped scenarios once they are cached. ``uq run`` (``--model auto``,
its default) therefore never compiles them itself: each chunk runs the compiled model
where numba's cache holds every kernel it calls (:mod:`uq.compileguard`), else the numpy
reference model and statistics (the same numbers to 1e-12 m/s; 1-4 times the compiled
model's CPU time on the shipped scenarios; a sweep's numpy chunks run on the cores'
threads, :func:`uq.pipeline.runner.run`), and the first chunk that finds a kernel
missing starts :class:`BackgroundCompile`: ``python -m uq.cli.firstrun SETTINGS`` in a
process of its own (its own session, at a low priority: :data:`BACKGROUND_NICE`), which
compiles every kernel a run of the same scenario calls (``uq warmup --for``,
:func:`uq.cli.warmup.compile_for`) into numba's cache and ends. It outlives the run
when the run ends first (it is then written to the cache for the next run); a later
chunk of the same run takes the compiled model once it has ended.

One at a time per cache: the parent takes an exclusive lock (``flock``) on a file named
after the cache folder and hands it to the child, which holds it until it ends; a run
that finds the lock taken starts none (another compile is filling the same cache).
Not started (the run then compiles in its own process, as ``--model compiled``): with
``UQ_BACKGROUND_COMPILE=0`` in the environment (batch jobs, CI), on a dask cluster (its
workers compile for themselves) or with less than
:data:`~uq.cli.sidecompile.SIDE_COMPILE_MIN_AVAILABLE_MB` of memory free.
"""
import fcntl
import logging
import os
import subprocess
import sys
import tempfile

from uq.compileguard import lock_path, wait_for_background  # noqa: F401 (public here too)

#: The environment variable that turns the background compile off ("0"): the run then
#: compiles what it calls in its own process first (``--model compiled``).
BACKGROUND_VARIABLE = "UQ_BACKGROUND_COMPILE"
#: The background compile's niceness (``nice``): it takes a core only when the user's
#: own work leaves one idle.
BACKGROUND_NICE = 10

LOG = logging.getLogger(__name__)


def wanted(args):
    """Whether ``uq run`` `args` may leave its kernels to a background compile (else it
    compiles them itself, ``--model compiled``)."""
    from uq.cli.sidecompile import SIDE_COMPILE_MIN_AVAILABLE_MB, available_memory_mb
    return (os.environ.get(BACKGROUND_VARIABLE, "1") != "0"
            and getattr(args, "workers", None) is None
            and getattr(args, "scheduler", None) is None
            and available_memory_mb() >= SIDE_COMPILE_MIN_AVAILABLE_MB)


def _take_lock():
    """An open file descriptor holding the exclusive lock, or None if another process
    holds it (or it cannot be made)."""
    try:
        handle = os.open(lock_path(), os.O_RDWR | os.O_CREAT, 0o600)
    except OSError:
        return None
    try:
        fcntl.flock(handle, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except OSError:
        os.close(handle)
        return None
    return handle


def compile_running():
    """Whether a background compile of this cache is running (its lock is held)."""
    handle = _take_lock()
    if handle is None:
        return True
    os.close(handle)                      # (closing releases it)
    return False


class Background:
    """A command's background compile, started once, when a kernel is found missing
    from numba's cache; :meth:`start` is :func:`uq.run`'s `kernels_missing`.

    Parameters
    ----------
    args : argparse.Namespace
        The command's (``-q``: nothing said).
    settings : list of dict
        The validated settings of the scenarios whose kernels to compile.
    agreement : str
        How the numpy model's numbers compare with the compiled one's (said).
    """

    def __init__(self, args, settings, agreement="the same numbers to 1e-12",
                 model_seconds=0.0):
        self.args, self.settings, self.compile = args, settings, None
        self.agreement, self.model_seconds = agreement, model_seconds

    def start(self, missing=None):
        """Start the compile (once) and say so on stderr; returns its ``ended``
        (whether to try the compiled model again)."""
        if self.compile is None:
            self.compile = BackgroundCompile(self.settings, self.model_seconds)
            whose = (f"process {self.compile.pid}" if self.compile.pid else
                     "another uq's process")
            if not getattr(self.args, "quiet", False):     # a notice, as "compiling"
                print(f"uq: numba's cache does not hold this run's compiled kernels "
                      f"({missing}): they compile in the background ({whose}, low "
                      f"priority) for later runs; this run uses the numpy model meanwhile "
                      f"({self.agreement})", file=sys.stderr, flush=True)
        return self.compile.ended


class BackgroundCompile:
    """The background compile of a run's kernels (module docstring).

    Parameters
    ----------
    settings : list of dict
        The validated settings of the scenarios whose kernels to compile (written to a
        temporary file for the child, one YAML document each).

    Attributes
    ----------
    child : subprocess.Popen or None
        The compiling process; None where another one held the lock (it fills the same
        cache).
    """

    def __init__(self, settings, model_seconds=0.0):
        self.child = None
        lock = _take_lock()
        if lock is None:
            return
        import yaml
        try:
            handle, path = tempfile.mkstemp(prefix="uq-compile-", suffix=".yaml")
            with os.fdopen(handle, "w") as file:
                yaml.safe_dump_all(settings, file)
            # its own session (a Ctrl-C at the terminal is the run's, not its); nothing
            # of it on the terminal; the lock's descriptor inherited: it holds the lock
            # until it ends (the run may end first)
            after = [] if compile_beside(model_seconds) else [str(os.getpid())]
            self.child = subprocess.Popen(
                [sys.executable, "-m", "uq.cli.firstrun", path, str(lock)] + after,
                stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL,
                stderr=subprocess.DEVNULL, start_new_session=True, pass_fds=(lock,))
        except OSError as error:
            LOG.info("the background compile could not start (%s)", error)
        finally:
            os.close(lock)

    @property
    def pid(self):
        return self.child.pid if self.child else None

    def ended(self):
        """Whether the kernels' compile has ended well (this run's child, or the one that
        held the lock)."""
        if self.child is None:
            return not compile_running()
        return self.child.poll() == 0


def lower_priority():
    """This process's CPU priority lowered as far as a user may: Linux's idle class
    (``SCHED_IDLE``: it runs only on a core the user's other work leaves idle; at
    :data:`BACKGROUND_NICE` a compile still took ~10 % of a core a first run's FFTs
    were using, which slowed them by a third on 2 cores), else niceness
    :data:`BACKGROUND_NICE`."""
    try:
        os.nice(BACKGROUND_NICE)
    except OSError:
        pass
    try:
        os.sched_setscheduler(0, os.SCHED_IDLE, os.sched_param(0))
    except (AttributeError, OSError):
        pass


def compile_beside(model_seconds=0.0):
    """Whether the background compile may run beside the run that started it: where a
    core is left to it (more usable CPUs than the
    :data:`~uq.pipeline.runner.NUMPY_CHUNK_THREADS` a run's numpy chunks take, or the
    two threads of a record's FFTs), or where the run's model is estimated at
    `model_seconds` [s] of CPU or more, :data:`~uq.constants.
    BACKGROUND_BESIDE_MIN_MODEL_CPU_S` (its later chunks then take the compiled model).
    Else it compiles a record's kernels (which the run takes as soon as they are in the
    cache) and waits for the run to end before the rest: measured on 2 cores, a compile
    beside a short run, even at the idle class, slowed it by 20-30 % (the first run of
    rubio2022_tilt 17.4 s against 10.3 s after it) and ended after it, so no chunk took
    the compiled model."""
    from uq.constants import BACKGROUND_BESIDE_MIN_CPUS, BACKGROUND_BESIDE_MIN_MODEL_CPU_S
    from uq.cpus import usable_cpus
    return (usable_cpus() >= BACKGROUND_BESIDE_MIN_CPUS
            or model_seconds >= BACKGROUND_BESIDE_MIN_MODEL_CPU_S)


def _wait_for_exit(pid):
    """Return once process `pid`, this one's parent, has ended (this one is then
    another's child)."""
    import time
    while os.getppid() == pid:
        time.sleep(WAIT_POLL_SECONDS)


#: Seconds between two looks whether the run that started the compile has ended.
WAIT_POLL_SECONDS = 0.5


def main(argv=None):
    """``python -m uq.cli.firstrun SETTINGS.yaml LOCK_FD [PID]``: compile, at a low
    priority, every kernel a run of each scenario of the file calls (then remove the
    file): a record's boxes' and spectral path's first, then, given the run's `PID`,
    once that process has ended (:func:`compile_beside`), the others. The lock is
    released when this process ends."""
    path, _lock, *after = (sys.argv[1:] if argv is None else argv)[:3]
    lower_priority()
    import yaml
    try:
        from uq.cli.warmup import compile_for, compile_record_kernels, record_mode
        with open(path, encoding="utf-8") as file:
            documents = list(yaml.safe_load_all(file))
        if any(record_mode(settings) for settings in documents):
            compile_record_kernels()         # the run takes them as soon as they are in
        if after:
            _wait_for_exit(int(after[0]))
        for settings in documents:
            compile_for(settings)
    finally:
        try:
            os.unlink(path)
        except OSError:
            pass
    return 0


if __name__ == "__main__":
    sys.exit(main())
