"""``uq bench``'s result as JSON (``bench.json`` beside ``bench.nc``): what a documentation
page of the benchmark is generated from.

The file holds the machine (processor, cores, memory, the versions of Python and of the
numerical libraries), the date (UTC), the machine's load average when the benchmark
started and ended, and every figure: its value, unit, what it measures, its target
(limit and sense) where it has one and whether that is met. The figures are those of
:func:`uq.bench.targets.measure` and of the methods' benchmark (times to a relative
error of 1e-3), each a time or a ratio of two times from the same run.
"""
import datetime
import json
import os
import platform

from uq.cpus import usable_cpus

#: What each figure with a target measures, and its unit ("1": a ratio).
DESCRIPTIONS = {
    "floating_lidar_full_mc_over_draw_floor": (
        "1", "wall time of uq.run of floating_lidar_full as shipped (all five outputs, "
        "plain mc) over the time to draw its standard normals alone, at "
        "floating_lidar_full_mc_n trials"),
    "shipped_worst_over_floor_and_start": (
        "1", "worst over the shipped scenarios of Monte Carlo trials (not those that work "
        "on ten-minute records: shipped_on_records): wall time of the user's command in a "
        "new process over its draws plus the process start"),
    "sweep_mc_over_draw_floor": (
        "1", "Monte Carlo sweep at 10^4 draws per scene (rubio2022_misalignment): time "
        "per scene over drawing one scene's normals"),
    "gum_grid_speedup": (
        "1", "the numpy model's complex-step GUM of the Fig. 2 grid (518,400 scenes) over "
        "the compiled one's"),
    "scans_over_numpy": (
        "1", "10^6 four-beam scans with radial noise (uq.run) over the same in a few lines "
        "of numpy"),
    "pointwise_motion_over_static": (
        "1", "wall time of uq.run of 10^6 point-wise corrected DBS scans in harmonic roll "
        "and pitch over 10^6 static scans"),
    "conical_over_four_beam": (
        "1", "2^17 conical scans of 50 lines of sight over 4-beam scans, in motion"),
    "pulsed_probe_over_point": (
        "1", "uq.run of floating_lidar_full with a pulsed probe over the same at a point"),
    "nacelle_static_over_dbs": ("1", "nacelle lidar against a DBS, static, CPU time"),
    "nacelle_motion_over_dbs": ("1", "nacelle lidar against a DBS, point-wise in motion, "
                                "CPU time"),
    "nacelle_motion_none_over_dbs": ("1", "nacelle lidar against a DBS in motion, "
                                     "correction none, CPU time"),
    "cold_start_cpu_s": ("s", "uq run rubio2022_case_i --model compiled with numba's cache "
                         "empty: CPU time (compiling in the run's own process)"),
    "cold_start_peak_rss_mb": ("MB", "the same: peak resident memory"),
    "cold_start_motion_cpu_s": ("s", "uq run floating_lidar_waves --model compiled, cache "
                                "empty: CPU time"),
    "cold_start_motion_peak_rss_mb": ("MB", "the same: peak resident memory"),
    "cold_start_record_wall_s": ("s", "uq run floating_lidar_ti --model compiled, cache "
                                 "empty: wall time"),
    "cold_start_record_peak_rss_mb": ("MB", "the same: peak resident memory of the larger "
                                      "process"),
    "serial_fraction": ("1", "driver CPU of a distributed sweep not overlapping its "
                        "workers, over the single-process run's CPU"),
    "serial_amdahl_efficiency_8": ("1", "Amdahl's speed-up with 8 workers over 8, from the "
                                   "serial fraction"),
    "first_run_worst_over_warm_s": (
        "s", "worst over the shipped scenarios: wall time of the user's command with "
        "numba's cache empty (the default --model auto: numpy while the kernels compile in "
        "the background) minus the same command once the cache is filled"),
    "rubio2022_case_i_best_speedup": (
        "1", "rubio2022_case_i: plain mc's time to a relative error of 1e-3 in u(wind "
        "speed) (95 % of runs) over the fastest method's"),
}


def machine_description():
    """The machine and software the figures were measured on."""
    import numba
    import numpy
    import scipy
    from uq._version import __version__
    processor = platform.processor() or platform.machine()
    try:
        with open("/proc/cpuinfo", encoding="ascii", errors="replace") as file:
            processor = next((line.split(":", 1)[1].strip() for line in file
                              if line.startswith("model name")), processor)
    except OSError:
        pass
    try:
        memory = os.sysconf("SC_PHYS_PAGES") * os.sysconf("SC_PAGE_SIZE") / 2**30
    except (ValueError, OSError, AttributeError):
        memory = float("nan")
    cores = usable_cpus()
    return {"processor": processor, "logical_cores": os.cpu_count(), "usable_cores": cores,
            "memory_gib": round(memory, 1), "system": platform.platform(),
            "python": platform.python_version(), "numpy": numpy.__version__,
            "scipy": scipy.__version__, "numba": numba.__version__, "uq": __version__}


def now():
    """The date and time (UTC, ISO 8601)."""
    return datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%dT%H:%M:%SZ")


def machine_line(machine):
    """:func:`machine_description` in one line."""
    return (f"{machine['processor']}, {machine['usable_cores']} usable cores of "
            f"{machine['logical_cores']}, {machine['memory_gib']} GiB, {machine['system']}, "
            f"Python {machine['python']}, numpy {machine['numpy']}, numba {machine['numba']}")


def load_line(loads):
    """The load averages (1, 5, 15 min) at the named moments, in one line."""
    return "; ".join(f"{moment} " + ", ".join(f"{value:.2f}" for value in values)
                     for moment, values in loads.items())


def document(figures, targets, started, loads, time_to_target=(), command="uq bench"):
    """The JSON document of a benchmark run: `figures` {name: value}, `targets` {name:
    (limit, "max" or "min")}, `started` (:func:`now` at the start), `loads` {moment:
    load averages}, `time_to_target` rows (scene, method, seconds, extrapolated).

    The keys the documentation's reader takes (``figures`` {name: number},
    ``time_to_target``, ``machine``, ``load_average``, ``measured_at``, ``command``) come
    with ``targets`` (each target's limit, sense, verdict, unit and description),
    ``notes`` (the figures that are not numbers) and the machine's and loads' details."""
    from uq._version import __version__
    from uq.files import SIGNATURE
    numbers = {name: value for name, value in figures.items()
               if isinstance(value, (int, float)) and not isinstance(value, bool)}
    rows = {}
    for name, (limit, sense) in targets.items():
        if name in numbers:
            value = numbers[name]
            units, description = DESCRIPTIONS.get(name, ("", ""))
            rows[name] = {"value": value, "limit": limit, "sense": sense,
                          "met": bool(value <= limit if sense == "max" else value >= limit),
                          "units": units, "description": description}
    machine = machine_description()
    return {"title": "uq bench", "generator": f"{SIGNATURE} {__version__}",
            "command": command, "measured_at": started, "ended": now(),
            "machine": machine_line(machine), "machine_details": machine,
            "load_average": load_line(loads), "load_averages": loads,
            "figures": numbers, "targets": rows,
            "notes": {name: value for name, value in figures.items() if name not in numbers},
            "time_to_target": [list(row) for row in time_to_target]}


def write(path, document_):
    """Write the JSON document atomically (:func:`uq.files.write_text`)."""
    from uq.files import write_text
    write_text(path, json.dumps(document_, indent=1, default=_plain) + "\n")


def _plain(value):
    """numpy scalars and arrays as JSON numbers and lists."""
    import numpy as np
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, np.ndarray):
        return value.tolist()
    raise TypeError(f"not JSON: {type(value).__name__}")
