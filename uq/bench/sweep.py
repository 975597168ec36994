"""Benchmark of planning sweeps (not a timed test): ``python -m uq.bench.sweep``.

Measures, in one run on one machine (so the ratios are meaningful on a noisy host):

1. the Fig. 2 grid of Rubio & Gottschall (2022): 4 cog x 360 misalignments x 360 wind
   directions = 518,400 scenes, GUM of the physical model and the paper's model, no
   sampling (``sampling.method: none``), with its peak memory;
2. Monte Carlo at 10^4 draws per scene on a 4 x 12 x 12 sub-grid: time per scene;
3. the same Monte Carlo scene by scene (one scene per chunk), for the speed-up that
   vectorising over scenes and sharing the draws (common random numbers) gives;
4. the floor: drawing one scene's 3 x 10^4 normal deviates with numpy's Generator.

Writes ``results/bench_sweep.json`` and prints a table.
"""
import json
import resource
import sys
import time
from pathlib import Path

import numpy as np

from uq.files import write_text
from uq.pipeline import sweep
from uq.pipeline.runner import run
from uq.pipeline.scenario import load_scenario
from uq.pipeline.shipped import scenario_path

SCENARIO = scenario_path("rubio2022_misalignment")
MC_DRAWS = 10_000


def _timed(function):
    started = time.perf_counter()
    result = function()
    return time.perf_counter() - started, result


def gum_grid(step=1.0, model="compiled"):
    """The Fig. 2 grid, GUM only, with the measurement model `model` (``uq run
    --model``): (seconds, scenes)."""
    scenario = load_scenario(SCENARIO, {
        "sampling.method": "none",
        "sweep.lidar.misalignment": {"start": -180, "stop": 180, "step": step},
        "sweep.wind.direction": {"start": 0, "stop": 360, "step": step}})
    seconds, dataset = _timed(lambda: run(scenario, model=model))
    return seconds, int(dataset["mc_n_samples"].size)


def monte_carlo(step=30.0, scene_by_scene=False, draws=MC_DRAWS):
    """Monte Carlo at `draws` per scene on a coarse Fig. 2 grid: (seconds, scenes)."""
    scenario = load_scenario(SCENARIO, {
        "sampling.n": draws,
        "sweep.lidar.misalignment": {"start": -180, "stop": 180, "step": step},
        "sweep.wind.direction": {"start": 0, "stop": 360, "step": step}})
    saved = sweep.SWEEP_CHUNK_ELEMENTS
    if scene_by_scene:
        sweep.SWEEP_CHUNK_ELEMENTS = 1
    try:
        seconds, dataset = _timed(lambda: run(scenario))
    finally:
        sweep.SWEEP_CHUNK_ELEMENTS = saved
    return seconds, int(dataset["mc_n_samples"].size)


def draw_floor(repeats=200, draws=MC_DRAWS):
    """Seconds to draw one scene's 3 x `draws` standard normals (numpy Generator)."""
    generator = np.random.default_rng(1)
    seconds, _ = _timed(lambda: [generator.standard_normal((draws, 3))
                                 for _ in range(repeats)])
    return seconds / repeats


#: Draws per scene of the serial-fraction benchmark: a user's sweep.
SERIAL_DRAWS = 100_000
#: Workers whose Amdahl bound is reported [1].
AMDAHL_WORKERS = (2, 4, 8, 16)


def serial_fraction(workers=2, quick=False, draws=SERIAL_DRAWS):
    """The serial share of a distributed sweep, from CPU times, not wall time.

    ``rubio2022_misalignment`` at `draws` per scene (its whole grid: 3456 scenes, 108
    chunks at 10^5; `quick`: 1 misalignment in 3 and 1 wind direction in 3, 12 chunks)
    runs as ``uq run`` runs it (a checkpoint, then the results file), once in this
    process and once on a local cluster of `workers` processes
    (:func:`uq.pipeline.cluster.local_cluster`, started and warmed beforehand). CPU
    times are user + system time of all threads of a process (getrusage):

    - C_single: this process, the single-process run;
    - C_driver: this process, the distributed run (dask's scheduler and client threads
      live in it too); C_window: its part between the first chunk's result (received
      and saved) and the last's, while at least one worker is computing;
    - C_workers: the worker processes, the distributed run.

    The serial fraction is the driver's CPU time that does not overlap the workers' (the
    planning, the scattering and submitting, the wait for and saving of the first chunk;
    then the assembly, the results file and the checkpoint's removal) over the
    single-process run's::

        f = (C_driver - C_window) / C_single

    ``amdahl_speedup_N = 1 / (f + (1 - f) / N)`` is Amdahl's bound with N workers and
    ``amdahl_efficiency_N`` that over N (the target, 0.6 up to 8 workers, needs f <=
    0.095; the project asks for f < 0.05).
    Two more figures say what else could limit it: ``driver_cpu_over_single`` =
    C_driver / C_single (the fraction if all the driver's work were serial: a bound
    from above on f), and ``driver_throughput_speedup`` = C_single / C_window, the
    speed-up at which the driver's work during the run (receiving and writing each
    chunk, dask's scheduling) would fill its own core. ``speedup_N`` = C_single /
    (C_driver - C_window + max(C_workers / N, C_window)) adds the workers' own overhead
    (``worker_cpu_over_single`` = C_workers / C_single; 1: none), given N free cores.
    The cluster's start is wall time before the first chunk, reported on its own
    (``cluster_start_wall_s``). The results of the two runs are checked bit for bit.

    Returns
    -------
    dict
        Figures named ``serial_*``: the fraction, the CPU times [s], wall times [s]
        (indicative: the machine may be loaded) and the bounds.
    """
    import tempfile
    from uq.pipeline.cluster import local_cluster
    scenario = _serial_scenario(quick, draws)
    with tempfile.TemporaryDirectory() as folder:
        run_as_uq_run(scenario.with_values({"sampling.n": 1000}), folder)  # kernels loaded
        single = run_as_uq_run(scenario, folder)
        started = time.perf_counter()
        with local_cluster(workers) as client:
            start_wall = time.perf_counter() - started
            run_as_uq_run(scenario.with_values({"sampling.n": 1000}), folder, client)
            before = client.run(_process_cpu)
            distributed = run_as_uq_run(scenario, folder, client)
            after = client.run(_process_cpu)
    if not all(np.array_equal(single["dataset"][v].values, distributed["dataset"][v].values,
                              equal_nan=True) for v in single["dataset"].data_vars):
        raise AssertionError("the distributed sweep differs from the single-process one")
    workers_cpu = sum(after[key] - before[key] for key in after)
    c_single, c_driver, c_window = single["cpu"], distributed["cpu"], distributed["window"]
    f = (c_driver - c_window) / c_single
    figures = {"serial_workers": workers, "serial_draws": draws,
               "serial_chunks": len(sweep.sweep_plan(scenario).chunks),
               "serial_single_cpu_s": c_single, "serial_driver_cpu_s": c_driver,
               "serial_driver_window_cpu_s": c_window, "serial_workers_cpu_s": workers_cpu,
               "serial_fraction": f, "serial_driver_cpu_over_single": c_driver / c_single,
               "serial_driver_throughput_speedup": c_single / c_window,
               "serial_worker_cpu_over_single": workers_cpu / c_single,
               "serial_single_wall_s": single["wall"],
               "serial_distributed_wall_s": distributed["wall"],
               "serial_wall_speedup": single["wall"] / distributed["wall"],
               "serial_cluster_start_wall_s": start_wall}
    for n in AMDAHL_WORKERS:
        figures[f"serial_amdahl_speedup_{n}"] = 1 / (f + (1 - f) / n)
        figures[f"serial_amdahl_efficiency_{n}"] = 1 / (f + (1 - f) / n) / n
        figures[f"serial_speedup_{n}"] = c_single / (c_driver - c_window + max(
            workers_cpu / n, c_window))
    return figures


def _serial_scenario(quick, draws):
    """``rubio2022_misalignment`` at `draws` per scene, its grid (`quick`: a ninth)."""
    changes = {"sampling.n": draws}
    if quick:
        changes.update({"sweep.lidar.misalignment": {"start": -180, "stop": 180, "step": 45},
                        "sweep.wind.direction": {"start": 0, "stop": 360, "step": 30}})
    return load_scenario(SCENARIO, changes)


def run_as_uq_run(scenario, folder, client=None):
    """Run `scenario` as ``uq run`` does (a checkpoint in `folder`, then the results
    file): {"cpu": CPU time [s] of this process, all threads; "window": its part between
    the first chunk saved and the last; "wall": wall time [s]; "dataset": the results}."""
    from uq.files import write_netcdf
    from uq.pipeline.checkpoint import Checkpoint
    marks = {}

    def progress(done, total):                # after each chunk is saved
        if done == 1:
            marks["first"] = _process_cpu()
        if done == total:
            marks["last"] = _process_cpu()
    checkpoint = Checkpoint(Path(folder) / "out.nc.partial").acquire()
    cpu, wall = _process_cpu(), time.perf_counter()
    try:
        dataset = run(scenario, client=client, checkpoint=checkpoint, progress=progress)
        write_netcdf(dataset, Path(folder) / "out.nc")
        checkpoint.clear()
    finally:
        checkpoint.release()
    return {"cpu": _process_cpu() - cpu, "window": marks["last"] - marks["first"],
            "wall": time.perf_counter() - wall, "dataset": dataset}


def _process_cpu():
    """CPU time [s] of this process, user + system, all its threads."""
    usage = resource.getrusage(resource.RUSAGE_SELF)
    return usage.ru_utime + usage.ru_stime


def main(out=Path("results") / "bench_sweep.json"):
    gum_s, gum_scenes = gum_grid()
    peak_mb = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    mc_s, mc_scenes = monte_carlo()
    loop_s, loop_scenes = monte_carlo(scene_by_scene=True)
    floor = draw_floor()
    figures = {
        "fig2_grid_scenes": gum_scenes, "fig2_grid_gum_s": gum_s,
        "fig2_grid_gum_us_per_scene": 1e6 * gum_s / gum_scenes,
        "fig2_grid_peak_rss_mb": peak_mb,
        "mc_draws_per_scene": MC_DRAWS, "mc_scenes": mc_scenes,
        "mc_ms_per_scene": 1e3 * mc_s / mc_scenes,
        "mc_scene_by_scene_ms_per_scene": 1e3 * loop_s / loop_scenes,
        "vectorised_speedup": (loop_s / loop_scenes) / (mc_s / mc_scenes),
        "draw_floor_ms_per_scene": 1e3 * floor,
        "mc_time_over_draw_floor": (mc_s / mc_scenes) / floor,
    }
    out = write_text(Path(out), json.dumps(figures, indent=1))      # atomic, its folder made
    for key, value in figures.items():
        print(f"{key:34s} {value:12.4g}")
    print(f"wrote {out}")
    return figures


if __name__ == "__main__":
    main(*sys.argv[1:2])
