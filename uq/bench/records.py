"""Record mode on the CPU: records per second of the shipped record-mode scenarios, and
where a record's time goes.

Each scenario (``sathe2011_ti``: a pulsed DBS; ``sathe2011_ti_cw``: a CW VAD of 50 lines
of sight; ``floating_lidar_ti``: a buoy's DBS in a sea, two corrections) runs as shipped
with :func:`uq.run` in this process (numba's cache filled: a warm run): its Monte Carlo
records (``record.count`` per scene with wind, every swept scene) over the wall time of
the whole run. A second run under :mod:`cProfile` says where the time goes, as shares of
that run's time: the turbulence boxes (``uq.pipeline.records.unit_box_parts``: white
noise, FFTs and the spectral colouring), their sampling along the beams
(``uq.physics.turbulencesampling.record_radial_velocities``), each record's scans
through the measurement model (``monte_carlo_record``), the spectral path and the
per-scan Monte Carlo (``uq.propagate``). The GPU path is refused in this version
(``uq run --device gpu``): no GPU figure.
"""
import cProfile
import pstats
import time

from uq.pipeline.runner import run
from uq.pipeline.scenario import load_scenario
from uq.pipeline.shipped import scenario_path

#: The shipped record-mode scenarios: name -> what it is.
SCENARIOS = {"sathe2011_ti": "pulsed DBS (4 beams, 4 gates), 8 records",
             "sathe2011_ti_cw": "CW VAD (50 lines of sight, 4 gates), 4 records",
             "floating_lidar_ti": "buoy DBS in a sea, 6 intensities x 2 corrections, "
                                  "5 records each"}
#: Where the time goes: label -> (module file's tail, function name) in the profile.
PARTS = {"boxes": ("records.py", "unit_box_parts"),
         "sampling": ("turbulencesampling.py", "record_radial_velocities"),
         "records_model": ("records.py", "monte_carlo_record"),
         "spectral_path": ("records.py", "_spectral_path"),
         "per_scan_monte_carlo": ("propagate.py", "propagate")}


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


def shares(profile, total):
    """{part: share of `total` seconds} of :data:`PARTS` found in the profile."""
    stats = pstats.Stats(profile).stats
    out = {}
    for label, (tail, function) in PARTS.items():
        seconds = sum(entry[3] for (path, _, name), entry in stats.items()
                      if path.endswith(tail) and name == function)
        out[label] = seconds / total if total else float("nan")
    return out


def measure(names=None, progress=None):
    """{figure: value}: ``records_per_second_<name>`` (records over the wall time of a warm
    run), ``record_run_<name>_s``, ``records_<name>`` and the shares
    ``record_<name>_<part>_share`` (:func:`shares`, from a second, profiled run)."""
    say = progress or (lambda text: None)
    figures = {"records_gpu": "not measured: uq run --device gpu is refused in this "
                              "version (no run makes its boxes on a GPU)"}
    for name in names or SCENARIOS:
        scenario = load_scenario(scenario_path(name))
        run(scenario)                             # kernels loaded, caches warm
        started = time.perf_counter()
        run(scenario)
        seconds = time.perf_counter() - started
        records = record_count(scenario)
        profile = cProfile.Profile()
        started = time.perf_counter()
        profile.runcall(run, scenario)
        profiled = time.perf_counter() - started
        parts = shares(profile, profiled)
        figures.update({f"records_per_second_{name}": records / seconds,
                        f"record_run_{name}_s": seconds, f"records_{name}": records})
        figures.update({f"record_{name}_{part}_share": value for part, value in parts.items()})
        say(f"{name} ({SCENARIOS.get(name, '')}): {records} records in {seconds:.1f} s, "
            f"{records / seconds:.2f} records/s; "
            + ", ".join(f"{part} {100 * value:.0f} %" for part, value in parts.items()))
    return figures
