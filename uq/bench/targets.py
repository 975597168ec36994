"""The speed targets, each a ratio of two times measured in the same
run on the same machine, so that a busy or slow host moves both alike.

=====================================  ==========================================  ======
figure                                 against                                     target
=====================================  ==========================================  ======
plain ``mc``, ``floating_lidar_full``   drawing its normals alone                   <= 3x
as shipped (all five outputs), 2 x 10^6
every shipped scenario of Monte Carlo   drawing its normals + the process start     <= 4x
trials, ``uq run`` in a new process
Monte Carlo sweep, 10^4 draws/scene     drawing one scene's normals                 <= 2.5x
Fig. 2 GUM grid, 518,400 scenes         the numpy model's complex step (before)     >= 5x
10^6 four-beam scans, radial noise      numpy: 4 x 10^6 normals, differences, hypot  <= 1x
10^6 point-wise scans in motion         10^6 static scans (wall time)               <= 4x
conical scan, 50 lines of sight         a 4-beam scan in motion, per trial          <= 15x
pulsed probe, ``floating_lidar_full``   the compiled point model, ``uq.run``        <= 3x
nacelle lidar (tilt 90), 4 beams,       a 4-beam DBS scan, the same run otherwise   <= 1x
static and point-wise in motion         (CPU time per scan)
``uq run rubio2022_case_i``, numba's    CPU time [s] (and peak memory [MB]) in a     <= 20 s
cache empty (a fresh cache folder)      new process; the same run with it filled     600 MB
``uq run floating_lidar_waves`` (the    the same                                    <= 30 s
motion kernels), numba's cache empty                                                600 MB
``uq run floating_lidar_ti`` (record   wall time [s] (the kernels compile in a      <= 30 s
mode), numba's cache empty             second process beside the boxes); peak of    600 MB
                                       the larger process [MB]
driver CPU of a distributed sweep not   the single-process run's CPU time (serial    <= 0.05
overlapping its workers, 10^5 draws     fraction f; Amdahl's S(8)/8 >= 0.6)
first run of every shipped scenario,    the same command once numba's cache is      <= 5 s
numba's cache empty (wall time)         filled (:mod:`uq.bench.firstrun`)           more
time to 1e-3 on ``rubio2022_case_i``,   plain ``mc``'s (:mod:`uq.bench.methods`)    >= 20x
the fastest method                                                                  faster
=====================================  ==========================================  ======

The probe's figure is a whole ``uq.run`` of ``floating_lidar_full`` with a
WindCube-like pulsed probe against the same run at a point, n trials each; the model's
own ratio (the measurement model alone, the same draws) is reported beside it.

The nacelle figures are whole ``uq.run`` calls; the measurement model's own
ratios (``nacelle_static_model_over_dbs``, ``nacelle_motion_model_over_dbs``: the model
alone on the same draws, :func:`nacelle_models`) are reported beside them.

The draw floor of a run is measured by replaying the engine's own draws: the run is
made once with :func:`uq.engine.propagate.normal_scores` recorded (the shape of every
block it draws), then the same blocks are drawn again with numpy's Generator alone.
The serial fraction is :func:`uq.bench.sweep.serial_fraction`:
``rubio2022_misalignment`` at 10^5 draws per scene on 2 local workers, from the CPU
times of the driving process and of the workers (the whole grid; ``--quick``: a ninth).

A shipped file whose command works on ten-minute records (a record-mode scenario, a
campaign, a golden-lidar campaign: :func:`works_on_records`) is timed end to end too, but
left out of the worst ratio to its draws: its normals are a few of its random numbers
(the records' turbulence boxes are the rest) and its time is the records'. Record mode's
figure is its records per second (:mod:`uq.bench.records`).

The process start is a new interpreter that imports what ``uq run`` imports (numpy,
scipy, xarray, netCDF4, numba, matplotlib and uq's modules) and exits.
"""
import contextlib
import json
import os
import subprocess
import sys
import tempfile
import time

import numpy as np

from uq.bench import sweep
from uq.bench.sweep import MC_DRAWS
from uq.pipeline.runner import run
from uq.pipeline.scenario import MIN_SAMPLES, load_scenario
from uq.pipeline.shipped import scenario_path, shipped_folder

#: The targets: figure -> (limit, "max" or "min") [1].
TARGETS = {"floating_lidar_full_mc_over_draw_floor": (3.0, "max"),
           "shipped_worst_over_floor_and_start": (4.0, "max"),
           "sweep_mc_over_draw_floor": (2.5, "max"),
           "gum_grid_speedup": (5.0, "min"),
           "scans_over_numpy": (1.0, "max"),
           "pointwise_motion_over_static": (4.0, "max"),
           "conical_over_four_beam": (15.0, "max"),
           "pulsed_probe_over_point": (3.0, "max"),
           "nacelle_static_over_dbs": (1.0, "max"), "nacelle_motion_over_dbs": (1.0, "max"),
           "nacelle_motion_none_over_dbs": (1.0, "max"),
           "cold_start_cpu_s": (20.0, "max"), "cold_start_peak_rss_mb": (600.0, "max"),
           "cold_start_motion_cpu_s": (30.0, "max"),
           "cold_start_motion_peak_rss_mb": (600.0, "max"),
           "cold_start_record_wall_s": (30.0, "max"),
           "cold_start_record_peak_rss_mb": (600.0, "max"),
           "serial_fraction": (0.05, "max"), "serial_amdahl_efficiency_8": (0.6, "min"),
           "first_run_worst_over_warm_s": (5.0, "max"),
           "rubio2022_case_i_best_speedup": (20.0, "min")}
#: The first run of a time-resolved scenario (the motion kernels: the slowest to compile).
COLD_MOTION_SCENARIO = "floating_lidar_waves"
#: The first run of a record-mode scenario (the slowest of the three shipped: boxes,
#: motion kernels compiled in a second process beside them; timed in wall time, since
#: two processes share the cores).
COLD_RECORD_SCENARIO = "floating_lidar_ti"
#: Imports of ``uq run`` that a new process pays before any work.
START_SCRIPT = ("import numpy, scipy.stats, xarray, netCDF4, numba, matplotlib.pyplot; "
                "import uq.cli.run, uq.pipeline.runner, uq.physics.fused, uq.outputs.plots")


def median_time(function, repeats, clock=time.perf_counter):
    """Median time [s] of `repeats` calls after one warm call (imports, caches, numba's
    kernels loaded), read from `clock` (default: wall time)."""
    function()
    times = []
    for _ in range(repeats):
        started = clock()
        function()
        times.append(clock() - started)
    return float(np.median(times))


@contextlib.contextmanager
def recorded_draws():
    """Record the (rows, dimension) of every block the engine draws (a list, filled
    while the context is open)."""
    from uq.engine import propagate
    original, shapes = propagate.normal_scores, []

    def recording(method, seed, block, dimension, *args, out=None, rows=None, **kwargs):
        result = original(method, seed, block, dimension, *args, out=out, rows=rows,
                          **kwargs)
        shapes.append(result.shape)
        return result
    propagate.normal_scores = recording
    try:
        yield shapes
    finally:
        propagate.normal_scores = original


def draw_floor(shapes, repeats=5):
    """Median time [s] to draw the blocks `shapes` with one numpy Generator into
    preallocated arrays (the engine draws into its own buffer too)."""
    generator = np.random.default_rng(1)
    buffers = [np.empty(shape) for shape in shapes]

    def draw():
        for buffer in buffers:
            generator.standard_normal(out=buffer)
    return median_time(draw, repeats)


def run_floor(scenario):
    """The draw floor [s] of `scenario` (anything :func:`uq.run` takes)."""
    with recorded_draws() as shapes:
        run(scenario)
    return draw_floor(shapes)


#: Trials of the run of ``floating_lidar_full`` as shipped against its draws.
FULL_AS_SHIPPED_TRIALS = 2_000_000


def floating_lidar_full_as_shipped(n=FULL_AS_SHIPPED_TRIALS, repeats=5):
    """(seconds, floor) of plain mc on ``floating_lidar_full`` with every shipped
    output, at n trials."""
    scenario = load_scenario(scenario_path("floating_lidar_full"),
                             {"sampling.n": n, "sampling.method": "mc"})
    return median_time(lambda: run(scenario), repeats), run_floor(scenario)


def process_start(repeats=3):
    """Median wall time [s] of a new interpreter importing what ``uq run`` imports."""
    return median_time(lambda: subprocess.run([sys.executable, "-c", START_SCRIPT],
                                              check=True), repeats)


def _command(name, folder):
    """The command a user runs for shipped scenario `name` (golden and campaign
    configurations run with ``uq golden`` and ``uq campaign`` into a folder), writing
    into `folder`."""
    from uq.pipeline.shipped import shipped_command
    kind = shipped_command(name)
    if kind != "run":
        return [kind, name, "-o", os.path.join(folder, name), "-q"]
    return ["run", name, "-o", os.path.join(folder, f"{name}.nc"), "-q"]


#: A child process that runs a command with the engine's draws recorded and prints their
#: block shapes as JSON (the bench never imports the command line: it sits above it).
RECORD_SCRIPT = """
import contextlib, json, sys
from uq.bench.targets import recorded_draws
from uq.cli import main
with recorded_draws() as shapes, contextlib.redirect_stdout(sys.stderr):
    main(sys.argv[1:])
print(json.dumps(shapes))
"""


def shipped_end_to_end(repeats=3, names=None):
    """Per shipped scenario: (seconds of its command in a new process, its draw floor).
    The command's outputs go to a temporary folder, removed afterwards."""
    names = names or sorted(p.stem for p in shipped_folder().glob("*.yaml"))
    rows = {}
    with tempfile.TemporaryDirectory() as folder:
        for name in names:
            command = _command(name, folder)
            _clean(folder)
            recorded = subprocess.run([sys.executable, "-c", RECORD_SCRIPT] + command,
                                      check=True, capture_output=True, text=True).stdout
            floor = draw_floor([tuple(shape) for shape in json.loads(recorded)])

            def in_new_process():
                _clean(folder)
                subprocess.run(uq_command() + command, check=True,
                               stdout=subprocess.DEVNULL)
            rows[name] = (median_time(in_new_process, repeats), floor)
    return rows


def uq_command():
    """How a user starts uq: the ``uq`` script installed beside this interpreter, else
    ``python -m uq.cli``."""
    script = os.path.join(os.path.dirname(sys.executable), "uq")
    return [script] if os.access(script, os.X_OK) else [sys.executable, "-m", "uq.cli"]


def _clean(folder):
    """Remove what the last command wrote in the temporary `folder` (ours alone)."""
    import shutil
    for entry in os.scandir(folder):
        if entry.is_dir():
            shutil.rmtree(entry.path)
        else:
            os.unlink(entry.path)


def sweep_monte_carlo(draws=MC_DRAWS):
    """(seconds per scene of a Monte Carlo sweep of ``rubio2022_misalignment`` at `draws`
    per scene, the floor per scene: drawing that scene's normals)."""
    seconds, scenes = sweep.monte_carlo(draws=draws)
    return seconds / scenes, sweep.draw_floor(draws=draws)


def gum_grid(repeats=1):
    """(seconds of the Fig. 2 GUM grid, seconds of the same with the numpy model's
    complex step, the previous implementation), and the number of scenes."""
    new_s, scenes = sweep.gum_grid()
    old_s, _ = sweep.gum_grid(model="numpy")          # uq run --model numpy
    return new_s, old_s, scenes


def _scans(n, **changes):
    settings = {"name": "scans", "correction": "none", "outputs": ["wind_speed"],
                "lidar": {"errors": {"radial_velocity": {"dist": "normal", "u": 0.1}}},
                "sampling": {"n": n, "seed": 1}}
    return load_scenario(settings, changes)                # dotted keys, as uq run --set


def numpy_scans(n, u=0.1, generator=None):
    """The straightforward numpy version of n four-beam scans with radial noise, level
    and at rest: draw the 4 n normals, difference opposite beams, hypot; u(Vh) [m s-1]."""
    generator = generator or np.random.default_rng(1)
    noise = generator.standard_normal((n, 4)) * u
    sine = np.sin(np.deg2rad(28.0))
    north = 10.0 + (noise[:, 0] - noise[:, 2]) / (2 * sine)
    east = (noise[:, 1] - noise[:, 3]) / (2 * sine)
    return float(np.std(np.hypot(north, east)))


def scans_against_numpy(n=10**6, repeats=5):
    """(seconds of uq.run of n four-beam scans with radial noise, seconds of
    :func:`numpy_scans`)."""
    scenario = _scans(n)
    return (median_time(lambda: run(scenario), repeats),
            median_time(lambda: numpy_scans(n), repeats))


def motion_scans(n=10**6, repeats=5):
    """(wall seconds of n point-wise corrected DBS scans under harmonic roll and pitch of
    random phase, 1 s per beam, with radial noise; wall seconds of n static scans; the
    same two in CPU time): each the median of `repeats` :func:`uq.run` calls, the two
    kinds in alternating pairs (ABBA) so that a drift of the machine falls on both. The
    wall time is the user's (the draws of the next chunk run in a second thread beside
    the model); the process's CPU time (both threads) is what a busy machine does not
    move."""
    moving = _scans(n, **{"correction": "pointwise", "lidar.scan.beam_duration": 1.0,
                          "motion.roll": {"amplitude": 5.0, "period": 6.0},
                          "motion.pitch": {"amplitude": 3.0, "period": 5.0}})
    static = _scans(n)
    run(moving), run(static)
    wall, cpu = [], []
    for index in range(repeats):
        pair = (moving, static) if index % 2 == 0 else (static, moving)
        times = {}
        for scenario in pair:
            started, used = time.perf_counter(), time.process_time()
            run(scenario)
            times[id(scenario)] = (time.perf_counter() - started,
                                   time.process_time() - used)
        wall.append((times[id(moving)][0], times[id(static)][0]))
        cpu.append((times[id(moving)][1], times[id(static)][1]))
    wall, cpu = np.median(wall, axis=0), np.median(cpu, axis=0)
    return float(wall[0]), float(wall[1]), float(cpu[0]), float(cpu[1])


def conical_scans(n=2**17, repeats=5):
    """(seconds of n conical scans of 50 lines of sight in 1 s, seconds of n 4-beam
    scans of 1 s), both without a vertical beam, under 5 deg pitch of random phase."""
    common = {"lidar.vertical_beam": False, "motion.pitch": {"amplitude": 5.0,
                                                              "period": 3.33}}
    conical = _scans(n, **common, **{"lidar.azimuths": [7.2 * i for i in range(50)],
                                     "lidar.scan.beam_duration": 0.02})
    four = _scans(n, **common, **{"lidar.scan.beam_duration": 0.25})
    return (median_time(lambda: run(conical), repeats),
            median_time(lambda: run(four), repeats))


def median_cpu_time(function, repeats):
    """Median CPU time [s] of this process (``time.process_time``) over `repeats` calls
    after one warm call: a figure a busy machine does not move (all of the process's
    threads: the engine's drawing thread too)."""
    return median_time(function, repeats, clock=time.process_time)


def paired_cpu_times(first, second, repeats):
    """(median CPU time [s] of `first`, of `second`, median of their ratios) over
    `repeats` pairs after one warm call of each. The calls alternate, the order turning
    each pair (ABBA), so a drift of the machine's speed (frequency, a neighbour's cache
    use) falls on both alike; each pair's ratio is taken before the median: two runs
    of tens of ms differ by 1-2 % from one call to the next, more than the difference
    a like-for-like ratio is asked about."""
    first(), second()
    times = []
    for index in range(repeats):
        pair = (first, second) if index % 2 == 0 else (second, first)
        measured = []
        for function in pair:
            started = time.process_time()
            function()
            measured.append(time.process_time() - started)
        times.append(measured if index % 2 == 0 else measured[::-1])
    times = np.asarray(times)
    return (float(np.median(times[:, 0])), float(np.median(times[:, 1])),
            float(np.median(times[:, 0] / times[:, 1])))


#: The nacelle lidar of the issue's held-out check: 4 beams at clock positions up,
#: starboard, down, port, half-cone 15 deg, the boresight along the bow at 150 m, 100 m
#: preview; in motion pitch 3 deg at 25 s of random phase, the INS 150 m below.
NACELLE = {"lidar.mount": {"tilt": 90.0}, "lidar.half_cone": 15.0, "lidar.height": 150.0,
           "lidar.ranges": [100.0], "lidar.vertical_beam": False,
           "outputs": ["wind_speed", "wind_direction"]}
NACELLE_MOTION = {"correction": "pointwise", "lidar.scan.beam_duration": 0.25,
                  "lidar.lever_arm": [0.0, 0.0, 150.0],
                  "motion.pitch": {"amplitude": 3.0, "period": 25.0}}
#: The held-out check's other correction: none (the same motion).
NACELLE_MOTION_NONE = {**NACELLE_MOTION, "correction": "none"}


def nacelle_scans(n=2**17, repeats=15):
    """CPU time [s] of ``uq.run`` of n nacelle scans and of n DBS scans of the same beam
    count (the DBS: the same lidar upward, half-cone 15 deg, azimuths 0/90/180/270), the
    same outputs, radial noise, correction and motion: {(beams, kind): (nacelle, dbs,
    median ratio)} (:func:`paired_cpu_times`) for 4 beams static (``ship.pitch`` 2 deg)
    and in motion (point-wise), and the 2-beam nacelle lidar (clock 90/270) against the
    4-beam DBS (a DBS needs 3 beams or more)."""
    static = {"ship.pitch": 2.0}
    cases = {(4, "static"): static, (4, "motion"): NACELLE_MOTION,
             (4, "motion_none"): NACELLE_MOTION_NONE,
             (2, "static"): static, (2, "motion"): NACELLE_MOTION}
    times = {}
    for (beams, kind), changes in cases.items():
        azimuths = [0.0, 90.0, 180.0, 270.0] if beams == 4 else [90.0, 270.0]
        nacelle = _scans(n, **NACELLE, **changes, **{"lidar.azimuths": azimuths})
        dbs = _scans(n, **{**NACELLE, "lidar.mount": {"tilt": 0.0}}, **changes,
                     **{"lidar.azimuths": [0.0, 90.0, 180.0, 270.0]})
        times[beams, kind] = paired_cpu_times(lambda: run(nacelle), lambda: run(dbs),
                                              repeats)
    return times


def nacelle_models(n=2**17, repeats=15):
    """CPU time [s] of the measurement model alone (the compiled one, as ``uq.run`` calls
    it, the same draws) of the 4-beam nacelle lidar and the DBS of :func:`nacelle_scans`:
    {kind: (nacelle, dbs, median ratio)} (:func:`paired_cpu_times`) for "static" and
    "motion" (the whole run's ratio also counts the draws and the pipeline, the same for
    both)."""
    from uq.physics.measurement import measurement_model
    from uq.pipeline.modelsetup import error_inputs, scene_from_settings
    from uq.engine.inputs import input_set
    azimuths = {"lidar.azimuths": [0.0, 90.0, 180.0, 270.0]}
    times = {}
    for kind, changes in (("static", {"ship.pitch": 2.0}), ("motion", NACELLE_MOTION),
                          ("motion_none", NACELLE_MOTION_NONE)):
        calls = []
        for mount in (NACELLE["lidar.mount"], {"tilt": 0.0}):
            scenario = _scans(n, **{**NACELLE, "lidar.mount": mount}, **changes, **azimuths)
            scene = scene_from_settings(scenario.settings)
            inputs = input_set(error_inputs(scenario.settings, scene.n_beams,
                                            len(scene.ranges)))
            errors = inputs.values(np.random.default_rng(1).standard_normal(
                (n, inputs.dimension)))
            errors.update(inputs.constants)
            calls.append(lambda scene=scene, errors=errors: measurement_model(
                scene, tuple(NACELLE["outputs"]), **errors))
        times[kind] = paired_cpu_times(*calls, repeats)
    return times


def probe_against_point(n=2**16, repeats=5):
    """(seconds of ``uq.run`` of ``floating_lidar_full`` with a pulsed probe, of the same
    at a point; seconds of its measurement model alone with the probe, at a point) at n
    trials, each compiled (:mod:`uq.physics.fusedprobe`)."""
    from uq.constants import WINDCUBE_GATE_LENGTH, WINDCUBE_PULSE_FWHM
    from uq.physics.measurement import measurement_model
    from uq.physics.probe import resolve
    from uq.pipeline.modelsetup import error_inputs, scene_from_settings
    from uq.engine.inputs import input_set
    point = load_scenario(scenario_path("floating_lidar_full"),
                          {"sampling.n": n, "sampling.method": "mc"})
    pulsed = load_scenario(point, {"lidar.probe": {
        "kind": "pulsed", "gate_length": WINDCUBE_GATE_LENGTH,
        "pulse_fwhm": WINDCUBE_PULSE_FWHM}})
    times = [median_time(lambda: run(pulsed), repeats), median_time(lambda: run(point), repeats)]
    for scenario in (pulsed, point):
        scene = resolve(scene_from_settings(scenario.settings))
        inputs = input_set(error_inputs(scenario.settings, scene.n_beams, len(scene.ranges)))
        errors = inputs.values(np.random.default_rng(1).standard_normal((n, inputs.dimension)))
        errors.update(inputs.constants)
        outputs = ("wind_speed", "wind_direction", "vertical_wind")
        times.append(median_time(lambda: measurement_model(scene, outputs, **errors),
                                 repeats))
    return tuple(times)


#: A child that runs a command of uq's and writes its peak resident memory [MB] to the
#: file named by UQ_BENCH_PEAK_FILE: its own high-water mark (VmHWM, which starts afresh
#: at exec) or its waited-for children's, the larger (ru_maxrss, which Linux keeps across
#: fork and exec, would report the size of ``uq bench`` itself, ~700 MB).
PEAK_SCRIPT = """
import os, resource, sys
from uq.cli import main
try:
    status = main(sys.argv[1:])
finally:
    try:
        own = next(float(line.split()[1]) / 1024 for line in open("/proc/self/status")
                   if line.startswith("VmHWM:"))
    except OSError:
        own = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    children = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss / 1024
    with open(os.environ["UQ_BENCH_PEAK_FILE"], "w") as file:
        file.write(repr(max(own, children)))
sys.exit(status)
"""


def child_usage(arguments, env=None, cwd=None):
    """(CPU time [s], peak resident memory [MB]) of ``uq ARGUMENTS`` in a child process:
    user + system time of the process and its waited-for children (numba compiles in
    the process itself; a record-mode run's compile beside it), from wait4, and the
    larger peak of the process and those children (:data:`PEAK_SCRIPT`)."""
    with tempfile.NamedTemporaryFile("r", suffix=".peak") as peak:
        child = subprocess.Popen([sys.executable, "-c", PEAK_SCRIPT, *arguments], cwd=cwd,
                                 env={**(env or os.environ), "UQ_BENCH_PEAK_FILE": peak.name},
                                 stdout=subprocess.DEVNULL)
        _, status, usage = os.wait4(child.pid, 0)
        child.returncode = os.waitstatus_to_exitcode(status)
        if child.returncode != 0:
            raise RuntimeError(f"uq {' '.join(arguments)} failed with status "
                               f"{child.returncode}")
        return usage.ru_utime + usage.ru_stime, float(peak.read())


def cold_start(name="rubio2022_case_i", prefix="cold_start"):
    """``uq run NAME --model compiled`` (compile what it calls first, in its own process:
    the cost ``--model auto``, the default, leaves to a background process, measured by
    :mod:`uq.bench.firstrun`) in a new process with an empty numba cache (a fresh
    ``NUMBA_CACHE_DIR``), then again with that cache filled: {cold CPU [s], cold wall
    [s], cold peak RSS [MB], warm CPU [s]}, named ``{prefix}_cpu_s`` and so on. CPU time,
    not wall time: on a loaded machine the wall time says how busy it is; on an idle one
    the wall time of the single-threaded compile is about its CPU time (a record-mode
    run compiles in a second process beside its boxes: its wall time is the figure; its
    peak is the larger of the two processes', :func:`child_usage`)."""
    with tempfile.TemporaryDirectory() as folder:
        env = {**os.environ, "NUMBA_CACHE_DIR": os.path.join(folder, "numba")}
        argv = ["run", name, "-q", "--model", "compiled", "-o",
                os.path.join(folder, "out.nc")]
        started = time.perf_counter()
        cold_cpu, cold_mb = child_usage(argv, env)
        cold_wall = time.perf_counter() - started
        os.remove(os.path.join(folder, "out.nc"))
        warm_cpu, warm_mb = child_usage(argv, env)
    warm = prefix.replace("cold", "warm")
    return {f"{prefix}_cpu_s": cold_cpu, f"{prefix}_wall_s": cold_wall,
            f"{prefix}_peak_rss_mb": cold_mb,
            f"{warm}_cpu_s": warm_cpu, f"{warm}_peak_rss_mb": warm_mb,
            f"{prefix}_over_warm": cold_cpu / warm_cpu}


def measure(quick=False, progress=None, scale=1):
    """Every figure of the table above as ``{name: value}`` (times [s], ratios [1]);
    `quick` leaves out the two slow ones (every shipped scenario end to end, the GUM
    grid) and uses 2^17 trials for ``floating_lidar_full``; `scale` (a power of two <= 1)
    shrinks every trial count (a test's small run)."""
    say = progress or (lambda text: None)
    figures = {}

    def trials(n):
        return max(MIN_SAMPLES, int(n * scale))

    n = trials(2**17 if quick else FULL_AS_SHIPPED_TRIALS)
    seconds, floor = floating_lidar_full_as_shipped(n)
    figures.update(floating_lidar_full_mc_n=n, floating_lidar_full_mc_s=seconds,
                   floating_lidar_full_draw_floor_s=floor,
                   floating_lidar_full_mc_over_draw_floor=seconds / floor)
    say(f"floating_lidar_full as shipped, plain mc at n = {n}: {seconds:.3f} s, its draws "
        f"{floor:.3f} s")
    seconds, numpy_s = scans_against_numpy(trials(10**6))
    figures.update(scans_1e6_s=seconds, scans_1e6_numpy_s=numpy_s,
                   scans_over_numpy=seconds / numpy_s)
    say(f"10^6 four-beam scans: {seconds:.3f} s, numpy {numpy_s:.3f} s")
    seconds, static_s, cpu_s, static_cpu_s = motion_scans(trials(10**6))
    figures.update(pointwise_motion_1e6_s=seconds, static_1e6_s=static_s,
                   pointwise_motion_over_static=seconds / static_s,
                   pointwise_motion_1e6_cpu_s=cpu_s, static_1e6_cpu_s=static_cpu_s,
                   pointwise_motion_over_static_cpu=cpu_s / static_cpu_s)
    say(f"10^6 point-wise scans in motion: {seconds:.3f} s, static {static_s:.3f} s "
        f"(wall; CPU {cpu_s:.3f} s, {static_cpu_s:.3f} s)")
    seconds, four_s = conical_scans(trials(2**17))
    figures.update(conical_2e17_s=seconds, four_beam_motion_2e17_s=four_s,
                   conical_over_four_beam=seconds / four_s)
    say(f"2^17 conical scans of 50 lines of sight: {seconds:.3f} s, 4-beam {four_s:.3f} s")
    n = trials(2**16)
    probe_s, point_s, probe_model_s, point_model_s = probe_against_point(n)
    figures.update(pulsed_probe_n=n, pulsed_probe_s=probe_s, point_probe_s=point_s,
                   pulsed_probe_over_point=probe_s / point_s,
                   pulsed_probe_model_over_point=probe_model_s / point_model_s)
    say(f"floating_lidar_full, pulsed probe, n = {n}: {probe_s:.3f} s, at a point "
        f"{point_s:.3f} s (the model alone {probe_model_s:.3f} s, {point_model_s:.3f} s)")
    n = trials(2**17)
    for (beams, kind), (nacelle_s, dbs_s, ratio) in nacelle_scans(n).items():
        name = f"nacelle_{kind}" + ("" if beams == 4 else "_2_beams")
        figures.update({f"{name}_cpu_s": nacelle_s, f"dbs_{kind}_cpu_s": dbs_s,
                        f"{name}_over_dbs": ratio})
        say(f"{n} nacelle scans, {beams} beams, {kind}: {nacelle_s:.3f} s of CPU, a 4-beam "
            f"DBS {dbs_s:.3f} s")
    for kind, (nacelle_s, dbs_s, ratio) in nacelle_models(n).items():
        figures[f"nacelle_{kind}_model_over_dbs"] = ratio
        say(f"{n} nacelle scans, 4 beams, {kind}, the measurement model alone: "
            f"{nacelle_s:.4f} s of CPU, a 4-beam DBS {dbs_s:.4f} s")
    per_scene, floor = sweep_monte_carlo(trials(MC_DRAWS))
    figures.update(sweep_mc_s_per_scene=per_scene, sweep_draw_floor_s_per_scene=floor,
                   sweep_mc_over_draw_floor=per_scene / floor)
    say(f"Monte Carlo sweep: {1e3 * per_scene:.3f} ms per scene, its draws "
        f"{1e3 * floor:.3f} ms")
    figures.update(sweep.serial_fraction(quick=quick, draws=trials(sweep.SERIAL_DRAWS)))
    say(f"distributed sweep, {figures['serial_chunks']} chunks on "
        f"{figures['serial_workers']} workers: serial fraction "
        f"{figures['serial_fraction']:.3f} (all the driver's CPU "
        f"{figures['serial_driver_cpu_over_single']:.3f}), Amdahl speed-up with 8 workers "
        f"{figures['serial_amdahl_speedup_8']:.1f}; wall "
        f"{figures['serial_single_wall_s']:.1f} s in one process, "
        f"{figures['serial_distributed_wall_s']:.1f} s distributed")
    if quick:
        return figures
    figures.update(cold_start())
    say(f"uq run rubio2022_case_i, numba's cache empty: {figures['cold_start_cpu_s']:.1f} s "
        f"of CPU time, peak {figures['cold_start_peak_rss_mb']:.0f} MB; the cache filled "
        f"{figures['warm_start_cpu_s']:.1f} s")
    figures.update(cold_start(COLD_MOTION_SCENARIO, "cold_start_motion"))
    say(f"uq run {COLD_MOTION_SCENARIO}, numba's cache empty: "
        f"{figures['cold_start_motion_cpu_s']:.1f} s of CPU time, peak "
        f"{figures['cold_start_motion_peak_rss_mb']:.0f} MB; the cache filled "
        f"{figures['warm_start_motion_cpu_s']:.1f} s")
    figures.update(cold_start(COLD_RECORD_SCENARIO, "cold_start_record"))
    say(f"uq run {COLD_RECORD_SCENARIO}, numba's cache empty: "
        f"{figures['cold_start_record_wall_s']:.1f} s wall "
        f"({figures['cold_start_record_cpu_s']:.1f} s of CPU time over the cores), peak "
        f"{figures['cold_start_record_peak_rss_mb']:.0f} MB a process; the cache filled "
        f"{figures['warm_start_record_cpu_s']:.1f} s of CPU")
    new_s, old_s, scenes = gum_grid()
    figures.update(gum_grid_scenes=scenes, gum_grid_s=new_s, gum_grid_numpy_s=old_s,
                   gum_grid_us_per_scene=1e6 * new_s / scenes, gum_grid_speedup=old_s / new_s)
    say(f"Fig. 2 GUM grid, {scenes} scenes: {new_s:.2f} s, numpy complex step {old_s:.2f} s")
    start = process_start()
    figures["process_start_s"] = start
    names = []
    for name, (seconds, floor) in shipped_end_to_end().items():
        ratio = seconds / (floor + start)
        figures.update({f"shipped_{name}_s": seconds, f"shipped_{name}_draw_floor_s": floor,
                        f"shipped_{name}_over_floor_and_start": ratio})
        names.append(name)
        say(f"uq run {name}: {seconds:.2f} s; draws {floor:.3f} s + start {start:.2f} s")
    figures.update(shipped_worst(figures, names))
    return figures


def works_on_records(name):
    """Whether the command of shipped file `name` works on ten-minute records: ``uq
    campaign`` and ``uq golden`` (a campaign's records), or ``uq run`` of a record-mode
    scenario (a ``turbulence`` section, Monte Carlo records)."""
    from uq.pipeline.shipped import shipped_command
    kind = shipped_command(name)
    if kind != "run":
        return True
    scenario = load_scenario(scenario_path(name))
    return "turbulence" in scenario.settings and scenario.sampling["method"] != "none"


def shipped_worst(figures, names):
    """``shipped_worst_over_floor_and_start`` (and its name) over the shipped files
    `names` whose figures are in `figures` and whose command works on Monte Carlo
    trials, not records (:func:`works_on_records`); ``shipped_on_records``: the others,
    comma-separated."""
    records = [name for name in names if works_on_records(name)]
    trials = {name: figures[f"shipped_{name}_over_floor_and_start"] for name in names
              if name not in records}
    worst = max(trials, key=trials.get)
    return {"shipped_worst_over_floor_and_start": trials[worst],
            "shipped_worst_name": worst, "shipped_on_records": ", ".join(records)}


def verdicts(figures):
    """Lines "figure value (target): met / NOT met" for the targets measured."""
    lines = []
    for name, (limit, sense) in TARGETS.items():
        if name in figures:
            value = figures[name]
            met = value <= limit if sense == "max" else value >= limit
            bound = "<=" if sense == "max" else ">="
            lines.append(f"{name:42s} {value:8.2f}  (target {bound} {limit:g}): "
                         f"{'met' if met else 'NOT met'}")
    return lines
