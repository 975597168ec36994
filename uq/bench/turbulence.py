"""Benchmark of the Monte Carlo turbulence path: one ten-minute record.

A record of a 5-beam DBS at 100 m (half-cone 30 deg, pulsed probe of gate 18.75 m and
pulse 24.75 m, 1 s per beam, U = 10 m/s, Mann field with IEC parameters) costs one box
(:func:`uq.physics.turbulencebox.mann_box`, sized by ``box_for``) plus the sampling of every
beam of every scan and the reconstruction of each scan with the nominal operator. The
target is a record in at most 5x the time of its box alone. Times are CPU times
(``time.process_time``) and ratios from the same run; records per second on the machine's
cores are measured with one record per process, all processes at once (wall time). Run:
``python -m uq.bench.turbulence`` (prints JSON); ``--device gpu`` times the CuPy path,
``--model kaimal`` the Kaimal box.
"""
import json
import resource
import sys
import time
from concurrent.futures import ProcessPoolExecutor

import numpy as np

from uq import constants
from uq.physics import probe, turbulencebox, turbulencesampling
from uq.physics.scangeometry import ScanGeometry

#: The benchmark's scene: height [m], half-cone [deg], gate and pulse [m], dwell [s],
#: speed [m s-1], record [s], alpha eps^(2/3) [m4/3 s-2] (intensity ~0.1 at 10 m/s).
HEIGHT, HALF_CONE, GATE, PULSE, DWELL, SPEED, RECORD, ALPHA_EPSILON = (
    100.0, 30.0, 18.75, 24.75, 1.0, 10.0, 600.0, 0.05)
PROBE_NODES = 15
#: sigma_u of the Kaimal benchmark [m s-1] (intensity 0.1 at 10 m/s).
KAIMAL_SIGMA_U = 1.0


def dbs_geometry():
    """The 5-beam DBS (4 beams at 90 deg azimuth steps, then the vertical one)."""
    a = np.radians(HALF_CONE)
    az = np.radians([0.0, 90.0, 180.0, 270.0])
    d = np.array([[np.sin(a) * np.cos(q), np.sin(a) * np.sin(q), np.cos(a)] for q in az]
                 + [[0.0, 0.0, 1.0]])
    ranges = np.r_[[HEIGHT / np.cos(a)] * 4, HEIGHT]
    gates = (np.array([0.0, 0.0, -HEIGHT]) + ranges[:, None] * d)[:, None, :]
    half = GATE + PULSE               # W_p there is ~1e-3 of its peak
    offsets = np.linspace(-half, half, PROBE_NODES)
    weights = probe.pulsed_weight(offsets, GATE, PULSE)
    return ScanGeometry(directions=d, gate_centres=gates, times=(np.arange(5) + 0.5) * DWELL,
                        dwell=DWELL, scan_period=5 * DWELL, probe_offsets=offsets,
                        probe_weights=(weights / weights.sum())[None],
                        reconstruction=np.linalg.pinv(d)[None], speed=SPEED,
                        record_duration=RECORD)


def _synchronise(xp):
    if xp is not np:
        xp.cuda.Device().synchronize()


def _box(model, grid, seed, xp, workers):
    rng = np.random.default_rng(seed)
    if model == "mann":
        return turbulencebox.mann_box(grid, ALPHA_EPSILON, constants.MANN_LENGTH_SCALE_IEC,
                                      constants.MANN_ANISOTROPY, rng, xp=xp, workers=workers)
    return turbulencebox.kaimal_box(grid, KAIMAL_SIGMA_U, SPEED,
                                    constants.IEC_SCALE_PARAMETER, rng, xp=xp)


def one_record(seed=0, device="cpu", workers=None, model="mann"):
    """CPU seconds of (box, sampling + reconstruction + statistics) for one record,
    and the box's cells; on a GPU the times are wall times after synchronising. The
    Kaimal box's Cholesky factors run on the BLAS's threads: on a loaded machine set
    OPENBLAS_NUM_THREADS=1 (measured 6 s against 60 s of CPU with the default threads)."""
    xp = turbulencebox.array_namespace(device)
    clock = time.process_time if xp is np else time.perf_counter
    geometry = dbs_geometry()
    scale = (constants.MANN_LENGTH_SCALE_IEC if model == "mann"
             else constants.IEC_SCALE_PARAMETER)
    grid = turbulencebox.box_for(geometry, scale, model=model)
    n_scans = int(RECORD / geometry.scan_period)
    start = clock()
    box = _box(model, grid, seed, xp, workers)
    _synchronise(xp)
    boxed = clock()
    radial = turbulencesampling.record_radial_velocities(box, geometry, n_scans, xp=xp)
    radial = radial.get() if xp is not np else radial
    wind = turbulencesampling.reconstruct_scans(radial, geometry)[:, 0] + [SPEED, 0.0, 0.0]
    turbulencesampling.record_statistics(wind)
    done = clock()
    return {"box_s": boxed - start, "sampling_s": done - boxed, "cells": grid.cells,
            "shape": list(grid.shape),
            "peak_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024}


def records_per_second(processes=2, records_each=1):
    """Records per wall second with one record per process, ``processes`` at once."""
    started = time.perf_counter()
    with ProcessPoolExecutor(processes) as pool:
        list(pool.map(one_record, range(processes * records_each)))
    return processes * records_each / (time.perf_counter() - started)


def measure(repeats=3, device="cpu", processes=2, model="mann"):
    """The benchmark's numbers: median box and record times, their ratio, records/s."""
    runs = [one_record(seed, device, model=model) for seed in range(repeats)]
    box = float(np.median([r["box_s"] for r in runs]))
    record = float(np.median([r["box_s"] + r["sampling_s"] for r in runs]))
    result = {"device": device, "model": model, "box_shape": runs[0]["shape"], "box_cells": runs[0]["cells"],
              "box_s": box, "record_s": record, "record_over_box": record / box,
              "peak_mb": max(r["peak_mb"] for r in runs)}
    if device == "cpu" and model == "mann":
        result["records_per_second_cpu"] = processes / record   # one record per core
        result["records_per_second"] = records_per_second(processes)
        result["processes"] = processes
    return result


def main(argv=None):
    argv = sys.argv[1:] if argv is None else argv
    device = argv[argv.index("--device") + 1] if "--device" in argv else "cpu"
    model = argv[argv.index("--model") + 1] if "--model" in argv else "mann"
    print(json.dumps(measure(device=device, model=model), indent=1))


if __name__ == "__main__":
    main()
