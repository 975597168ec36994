"""``uq run SCENARIO [-o OUT.nc] [--set k=v] [--resume] [--model numpy|compiled]
[--workers N]``."""
import contextlib
import logging
import os
import signal
import sys
from pathlib import Path

from uq.cli.common import (EXIT_OK, EXIT_TERMINATED, add_overrides, interrupted_status,
                           parse_overrides, say)
from uq.cli.sidecompile import draws_records, side_compile
from uq.errors import OutputError, ScenarioError


def add_parser(commands):
    run = commands.add_parser("run", help="run a scenario and write its results (netCDF)")
    run.add_argument("scenario", help="scenario YAML file, or the name of a shipped "
                     "scenario (e.g. rubio2022_case_i)")
    run.add_argument("-o", "--output", help="output file (default results/<name>.nc)")
    add_overrides(run)
    run.add_argument("--resume", action="store_true",
                     help="continue an interrupted run: reuse the finished chunks kept in "
                     "OUT.nc.partial/ and compute only the missing scenes")
    run.add_argument("--model", choices=("auto", "compiled", "numpy"), default="auto",
                     help="the measurement model and statistics: 'auto' (default) the "
                     "compiled ones (numba) where numba's cache holds their kernels, else "
                     "numpy while the kernels compile in a background process for later "
                     "runs (first run after an install); 'compiled' compiles what is "
                     "missing first; 'numpy' the reference model throughout. The same "
                     "numbers to 1e-12 m/s")
    run.add_argument("--device", choices=("cpu", "gpu"), default="cpu",
                     help="where the turbulence boxes of record mode are made: 'cpu' "
                     "(default, the only one this version runs: numpy's FFTs and compiled "
                     "kernels); 'gpu' is refused (exit 2): record mode's boxes are not "
                     "made with CuPy yet")
    scale = run.add_mutually_exclusive_group()
    scale.add_argument("--workers", type=int, metavar="N",
                       help="run the sweep on a local dask cluster of N processes "
                       "(needs the 'dask' extra); same numbers as a single process")
    scale.add_argument("--scheduler", metavar="ADDRESS",
                       help="run the sweep on the dask scheduler at ADDRESS "
                       "(e.g. tcp://host:8786)")
    run.set_defaults(handler=command)
    return run


#: Why ``--device gpu`` is refused (one line, exit 2).
GPU_REFUSED = ("record mode makes its turbulence boxes on the CPU only in this version "
               "(their generation and sampling with CuPy are not wired into the run and "
               "have not been verified on a GPU)")


def check_device(args, scenario):
    """``--device gpu`` is refused before any work (one line, exit 2): no run of this
    version makes a box on a GPU, so the flag would not do what it says."""
    if getattr(args, "device", "cpu") == "gpu":
        raise ScenarioError("--device", "gpu", f"{GPU_REFUSED}; allowed: --device cpu")


def command(args):
    from uq.files import check_target, missing_folders, remove_if_empty, write_netcdf
    from uq.outputs.summary import summary_table
    from uq.pipeline.checkpoint import Checkpoint, checkpoint_directory
    from uq.pipeline.progress import ProgressBar
    from uq.pipeline.runner import run
    from uq.pipeline.scenario import load_scenario
    from uq.pipeline.shipped import scenario_path
    scenario = load_scenario(scenario_path(args.scenario), parse_overrides(args.set))
    output = Path(args.output) if args.output else Path("results") / f"{scenario.name}.nc"
    if output.suffix != ".nc":
        raise ScenarioError("-o", str(output), "the output file must end in .nc")
    check_target(output)                     # before any work: refused targets cost nothing
    check_scale_out(args)
    check_device(args, scenario)
    from uq.cli import firstrun
    compiling = getattr(args, "compile_notice", None)
    if args.model == "auto" and not firstrun.wanted(args):
        args.model = "compiled"              # compiles what it calls first (module doc)
    from uq.pipeline.estimate import run_size
    background = firstrun.Background(args, [scenario.settings],
                                     model_seconds=run_size(scenario).model_seconds())
    load_kernels(args, scenario, background)
    before_run = compiling.seconds if compiling else 0.0     # compiled before the run
    new_folders = missing_folders(output.parent)
    checkpoint = Checkpoint(checkpoint_directory(output), resume=args.resume,
                            notify=None if args.quiet else _note).acquire()
    beside = side_compile(args, scenario)
    if beside:
        say(args, "uq: compiling the model's kernels in a second process while the "
            "turbulence boxes are drawn (once after an install)")
    progress = None if args.quiet else ProgressBar()
    try:
        with dask_client(args) as client:
            dataset = run(scenario, progress=progress, client=client, checkpoint=checkpoint,
                          model=args.model, kernels_ready=beside.wait if beside else None,
                          kernels_missing=background.start)
        dataset.attrs["runtime_s"] += before_run  # the user's wait, compiles included
        write_netcdf(dataset, output)
        checkpoint.clear()                   # still locked: no other run can be in it
    except KeyboardInterrupt as stop:
        status = interrupted_status(stop)
        print(f"\nuq: {'terminated' if status == EXIT_TERMINATED else 'interrupted'}; "
              f"finished chunks are kept in {checkpoint.directory}; "
              "run the same command with --resume to continue", file=sys.stderr)
        return status
    except OutputError as error:             # a full disk: finished chunks are kept
        if checkpoint.is_empty():
            checkpoint.clear()
            remove_if_empty(new_folders)
            raise
        raise OutputError(error.source, error.key, f"{error.problem}; the finished chunks "
                          f"are kept in {checkpoint.directory}: free space and run the same "
                          "command with --resume (or remove that folder)") from None
    except Exception:
        if checkpoint.is_empty():            # nothing to resume: leave nothing behind
            checkpoint.clear()
            remove_if_empty(new_folders)
        raise
    finally:
        if beside:
            beside.stop()
        checkpoint.release()
    compile_s = (compiling.seconds if compiling else 0.0) + (beside.waited if beside else 0.0)
    say(args, summary_table(dataset, compile_s=compile_s))
    say(args, f"wrote {output}")
    return EXIT_OK


def _note(text):
    """A line about the run on stderr (``uq: ...``), beside its progress."""
    print(f"uq: {text}", file=sys.stderr, flush=True)


def load_kernels(args, scenario, background=None):
    """Load the compiled kernels the run surely uses before its progress bar starts: the
    statistics', and the static model's geometry (real arithmetic; the complex kernels
    load when a GUM grid of many scenes first calls them) or the time-resolved model's.
    The wind kernel (scan-wise or point-wise) loads when first called. The first run after an install compiles them into numba's cache; the
    command's :class:`~uq.cli.compiling.CompileNotice` says so, kernel by kernel. A run
    that draws turbulence records loads every kernel when first called, after its
    records' boxes are drawn (:func:`uq.pipeline.records.draw_first_records`): numba
    keeps ~100-170 MB of what it compiles, which a box drawn after it would add to; on a
    cold cache a second process compiles them while the boxes are drawn
    (:mod:`uq.cli.sidecompile`). With ``--model auto`` nothing compiles here: the
    kernels are loaded where numba's cache holds them (a record-mode run's too: loading
    keeps far less than compiling), else their compile starts in the background
    (:mod:`uq.cli.firstrun`; a record's boxes and spectral path take numpy meanwhile,
    :func:`uq.compileguard.cached_kernels`)."""
    model = getattr(args, "model", "compiled")
    if model == "numpy":
        return                                    # no kernel is called
    if model == "auto":                  # loaded where cached; else the compile starts
        from uq.compileguard import KernelNotCached, cached_only
        try:                             # (the run finds it missing too: numpy)
            with cached_only():
                if draws_records(scenario):  # the boxes' and the spectral path's
                    from uq.cli.warmup import compile_record_kernels
                    compile_record_kernels()
                _load_kernels(scenario)
        except KernelNotCached as error:
            background.start(error)
        return
    if draws_records(scenario):          # every kernel when first called (or beside:
        return                           # :mod:`uq.cli.sidecompile`)
    _load_kernels(scenario)


def _load_kernels(scenario):
    """Load (or compile) the kernels of :func:`load_kernels`."""
    from uq.pipeline import motionsection
    import uq.engine.statkernels  # noqa: F401  (numba compiles or loads on import)
    if motionsection.is_time_resolved(scenario.settings):   # the static model unused
        import uq.physics.fusedmotionkernels  # noqa: F401
        return
    from uq.physics import fusedkernels
    for name in static_kernels(scenario):         # the complex kernels: a large GUM grid's
        fusedkernels.compiled(float)[name]


def static_kernels(scenario):
    """The real kernels of the static model :func:`_load_kernels` loads: the INS's
    trigonometry and the true beams' geometry, a tilted mount's (``geometry_mounted``)
    where the file or its sweep tilts the mount, the upward lidar's where not (loading
    one the run never calls would find it missing from a cache ``uq warmup --for``
    filled, and start a needless background compile). The tilt of each of the sweep's
    groups, as the runner assigns it (a linked key's included)."""
    import itertools
    from uq.pipeline.mountsection import tilt_of
    from uq.pipeline.sweep import group_assignments, sweep_plan
    plan = sweep_plan(scenario)
    tilt = tilt_of(scenario.settings["lidar"])
    tilts = {group_assignments(scenario, plan, group).get("lidar.mount.tilt", tilt)
             for group in itertools.product(*(range(len(values))
                                              for values in plan.group_values))}
    return ("ins_trig",) + tuple(sorted({"geometry_mounted" if float(tilt) else "geometry"
                                         for tilt in tilts}))


def check_scale_out(args):
    """Refuse bad --workers before anything is created."""
    if args.workers is not None and args.workers < 1:
        raise ScenarioError("--workers", str(args.workers), "allowed: an integer >= 1")


@contextlib.contextmanager
def dask_client(args):
    """A dask.distributed Client for --workers / --scheduler, else None. It is not made
    dask's default scheduler: the runner submits chunks to it explicitly, and files are
    written in this process (xarray would otherwise take cluster-wide locks to write)."""
    if args.workers is None and args.scheduler is None:
        yield None
        return
    # dask's own log lines (task cancelled at Ctrl-C, ...) are not the user's business;
    # workers read this from the environment they inherit. "critical", not "error": on a
    # loaded machine a worker's heartbeat can meet the scheduler already closed at Ctrl-C
    # and log that as an error with a traceback; a failing task still reaches the user
    # as the exception it raised, through the client.
    os.environ.setdefault("DASK_LOGGING__DISTRIBUTED", "critical")
    try:
        from dask.distributed import Client
    except ImportError:
        raise ScenarioError("--workers/--scheduler", "dask", "dask.distributed is not "
                            "installed; allowed: pip install 'floating-lidar-uq[dask]' (or pip install -e '.[dask]' in a checkout)") from None
    if args.scheduler:
        with Client(args.scheduler, set_as_default=False) as client:
            yield client
        return
    from uq.pipeline.cluster import local_cluster
    logging.getLogger("distributed").setLevel(logging.ERROR)
    # SIGINT ignored while the workers start: they inherit it, so Ctrl-C reaches uq alone
    with local_cluster(args.workers, starting=_ignoring_sigint) as client, \
            _quiet_at_stop():
        try:
            yield client
        except BaseException:
            # failed: closing the client forgets the chunks still pending, and the
            # scheduler, in this process, logs a gather of one of them then in flight as an
            # error ("Couldn't gather keys ... 'forgotten'", seen on a loaded machine); the
            # user gets the exception itself
            _silence_dask()
            raise


#: The loggers of the event loop the local cluster runs in this process.
DASK_LOGGERS = ("distributed", "tornado.application", "tornado.general", "asyncio")


def _silence_dask():
    """Only critical records from dask's and its event loop's loggers from now on."""
    for name in DASK_LOGGERS:
        logging.getLogger(name).setLevel(logging.CRITICAL)


@contextlib.contextmanager
def _quiet_at_stop():
    """Silence dask's loggers when SIGINT or SIGTERM arrives, before the stop's exception
    is raised. At Ctrl-C the main thread's wait in ``distributed.utils.sync`` schedules a
    cancel on the cluster's event loop thread, which can fail there at once and log an
    error with a traceback ("tornado.application - ERROR - Exception in callback
    ... sync.<locals>.cancel", seen on a loaded machine) before any ``except`` of ours
    runs; silencing in the signal handler comes first. The earlier handlers are then
    called as before (:func:`uq.interrupts.stop`'s KeyboardInterrupt or Terminated) and
    restored at the end. Main thread only."""
    import threading
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = {number: signal.getsignal(number) for number in (signal.SIGINT, signal.SIGTERM)}

    def stopping(number, frame):
        _silence_dask()
        handler = previous[number]
        if callable(handler):
            handler(number, frame)
        elif number == signal.SIGINT and handler == signal.SIG_DFL:
            raise KeyboardInterrupt
        elif handler == signal.SIG_DFL:             # the default action: end the process
            signal.signal(number, signal.SIG_DFL)
            os.kill(os.getpid(), number)
    for number in previous:
        signal.signal(number, stopping)
    try:
        yield
    finally:
        for number, handler in previous.items():
            signal.signal(number, handler)


@contextlib.contextmanager
def _ignoring_sigint():
    """Ignore SIGINT while child processes start. A terminal sends Ctrl-C to the whole
    process group; workers started with SIGINT ignored keep ignoring it (POSIX keeps an
    ignored signal across exec, and Python does not override it), so only this process
    sees the interrupt, stops the cluster and exits 130 with one message."""
    previous = signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, previous)
