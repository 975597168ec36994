"""Record mode on the CPU: records per second of the shipped record-mode scenarios, and
where a record's time goes.

Each scenario (``sathe2011_ti``: a pulsed DBS; ``sathe2011_ti_cw``: a CW VAD of 50 lines
of sight; ``floating_lidar_ti``: a buoy's DBS in a sea, two corrections) runs as shipped
with :func:`uq.run` in this process (numba's cache filled: a warm run; the records and
spectral paths a run keeps for reuse dropped first, as in a new process): its Monte Carlo
records (``record.count`` per scene with wind, every swept scene) over the wall time of
the whole run. A second run, each part timed on every thread (:func:`timed_parts`), says
where the time goes, as shares of that run's wall time: each record's turbulence
(``_draw_unit_record``: its box and the sampling along the beams, whichever functions
make them), of which the turbulence boxes (``uq.pipeline.records.unit_box_parts``: white
noise, FFTs and the spectral colouring), their sampling along the beams
(``uq.physics.turbulencesampling.record_radial_velocities``), each record's scans
through the measurement model (``monte_carlo_record``), the spectral path and the
per-scan Monte Carlo (``uq.propagate``). The GPU path is refused in this version
(``uq run --device gpu``): no GPU figure.
"""
import contextlib
import functools
import importlib
import threading
import time

from uq.pipeline.records import forget_kept
from uq.pipeline.runner import run
from uq.pipeline.scenario import load_scenario
from uq.pipeline.shipped import scenario_path

#: The shipped record-mode scenarios: name -> what it is.
SCENARIOS = {"sathe2011_ti": "pulsed DBS (4 beams, 4 gates), 8 records",
             "sathe2011_ti_cw": "CW VAD (50 lines of sight, 4 gates), 4 records",
             "floating_lidar_ti": "buoy DBS in a sea, 6 intensities x 2 corrections, "
                                  "5 records each"}
#: Where the time goes: label -> (module, function). The run computes its chunks and
#: draws on threads, which a profiler of the calling thread does not see: each function
#: is timed on every thread while the measured run lasts (:func:`timed_parts`).
PARTS = {"unit_records": ("uq.pipeline.records", "_draw_unit_record"),   # boxes + sampling
         "boxes": ("uq.pipeline.records", "unit_box_parts"),
         "sampling": ("uq.physics.turbulencesampling", "record_radial_velocities"),
         "records_model": ("uq.pipeline.records", "monte_carlo_record"),
         "spectral_path": ("uq.pipeline.records", "spectral_variances"),
         "per_scan_monte_carlo": ("uq.pipeline.runner", "propagate")}   # (as runner calls it)


def record_count(scenario):
    """Monte Carlo records of a run of `scenario`: ``record.count`` per scene with wind
    (the sweep's outer product; a scene of speed 0 has no frozen field, no record)."""
    if scenario.sampling["method"] == "none":
        return 0
    sweep = dict(scenario.sweep)
    speeds = sweep.get("wind.speed", (scenario.settings["wind"]["speed"],))
    scenes = 1
    for key, values in scenario.sweep:
        scenes *= 1 if key == "wind.speed" else len(values)
    windy = sum(1 for speed in speeds if speed > 0)
    return scenario.settings["record"]["count"] * scenes * windy


@contextlib.contextmanager
def timed_parts():
    """While entered, the seconds spent in each function of :data:`PARTS` (on every
    thread, a call inside another call of the same function counted once), accumulated
    into the dict it yields."""
    seconds = {label: 0.0 for label in PARTS}
    lock = threading.Lock()
    depth = threading.local()
    originals = []

    def wrap(label, function):
        @functools.wraps(function)
        def timed(*args, **kwargs):
            level = getattr(depth, label, 0)
            setattr(depth, label, level + 1)
            started = time.perf_counter()
            try:
                return function(*args, **kwargs)
            finally:
                setattr(depth, label, level)
                if level == 0:
                    with lock:
                        seconds[label] += time.perf_counter() - started
        return timed
    for label, (module_name, name) in PARTS.items():
        module = importlib.import_module(module_name)
        originals.append((module, name, getattr(module, name)))
        setattr(module, name, wrap(label, getattr(module, name)))
    try:
        yield seconds
    finally:
        for module, name, function in originals:
            setattr(module, name, function)


def shares(seconds, total):
    """{part: its seconds over `total` [1]} (summed over threads: on several cores the
    parts may add to more than 1)."""
    return {label: value / total if total else float("nan")
            for label, value in seconds.items()}


def measure(names=None, progress=None):
    """{figure: value}: ``records_per_second_<name>`` (records over the wall time of a warm
    run), ``record_run_<name>_s``, ``records_<name>`` and the shares
    ``record_<name>_<part>_share`` (:func:`shares`, from a second, timed run)."""
    say = progress or (lambda text: None)
    figures = {"records_gpu": "not measured: uq run --device gpu is refused in this "
                              "version (no run makes its boxes on a GPU)"}
    for name in names or SCENARIOS:
        scenario = load_scenario(scenario_path(name))
        run(scenario)                             # kernels loaded
        forget_kept()                             # records made again, as a new process
        started = time.perf_counter()
        run(scenario)
        seconds = time.perf_counter() - started
        records = record_count(scenario)
        forget_kept()
        with timed_parts() as spent:
            started = time.perf_counter()
            run(scenario)
            timed = time.perf_counter() - started
        parts = shares(spent, timed)
        figures.update({f"records_per_second_{name}": records / seconds,
                        f"record_run_{name}_s": seconds, f"records_{name}": records})
        figures.update({f"record_{name}_{part}_share": value for part, value in parts.items()})
        say(f"{name} ({SCENARIOS.get(name, '')}): {records} records in {seconds:.1f} s, "
            f"{records / seconds:.2f} records/s; "
            + ", ".join(f"{part} {100 * value:.0f} %" for part, value in parts.items()))
    return figures
