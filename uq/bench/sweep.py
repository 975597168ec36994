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


#: Draws per scene of the serial-fraction benchmark: the user's run of issue 26.
SERIAL_DRAWS = 100_000
#: Workers whose Amdahl bound is reported [1].
AMDAHL_WORKERS = (2, 4, 8, 16)


def serial_fraction(workers=2, quick=False, draws=SERIAL_DRAWS):
    """The serial share of a distributed sweep, from CPU times, not wall time.

    ``rubio2022_misalignment`` at `draws` per scene (its whole grid, 108 chunks at 10^5;
    `quick`: 1 misalignment in 3 and 1 wind direction in 3, 12 chunks) runs as
    ``uq run`` runs it (a checkpoint, then the results file), once in this process and
    once on a local cluster of `workers` processes (:func:`uq.pipeline.cluster.
    local_cluster`, started and warmed beforehand). With C_single the CPU time (user +
    system, all threads) of the single-process run, C_driver that of this process during
    the distributed run and C_workers that of the workers during it::

        f = C_driver / C_single

    Every CPU second the driving process spends is counted as serial, also what runs
    beside the workers (dask's scheduler and client threads live in this process): f
    bounds from above the share of the run that cannot be spread over workers, and so
    ``amdahl_speedup_N = 1 / (f + (1 - f) / N)`` bounds the speed-up with N workers
    from below as far as the driver is concerned. ``worker_cpu_over_single`` =
    C_workers / C_single is the workers' own overhead (1: none); with it the speed-up is
    at most ``C_single / (C_driver + C_workers / N)`` (``speedup_N``), given N free cores.
    The cluster's start is wall time before the first chunk, reported on its own. The
    results of the two runs are checked bit for bit.

    Returns
    -------
    dict
        ``serial_fraction``, ``serial_fraction_main_thread`` (uq's own code in the
        driver: planning, checkpoint writes, assembly, the results file),
        ``single_cpu_s``, ``driver_cpu_s``, ``workers_cpu_s``, ``chunks``, wall times
        [s] and the bounds.
    """
    import tempfile
    from uq.pipeline.cluster import local_cluster
    scenario = _serial_scenario(quick, draws)
    with tempfile.TemporaryDirectory() as folder:
        run_as_uq_run(scenario.with_values({"sampling.n": 1000}), folder)  # kernels loaded
        single_cpu, single_wall, single_thread, reference = run_as_uq_run(scenario, folder)
        started = time.perf_counter()
        with local_cluster(workers) as client:
            start_wall = time.perf_counter() - started
            run_as_uq_run(scenario.with_values({"sampling.n": 1000}), folder, client)
            before = client.run(_process_cpu)
            driver_cpu, wall, thread, result = run_as_uq_run(scenario, folder, client)
            after = client.run(_process_cpu)
    if not all(np.array_equal(reference[v].values, result[v].values, equal_nan=True)
               for v in reference.data_vars):
        raise AssertionError("the distributed sweep differs from the single-process one")
    workers_cpu = sum(after[key] - before[key] for key in after)
    f = driver_cpu / single_cpu
    figures = {"serial_workers": workers, "serial_draws": draws,
               "serial_chunks": len(sweep.sweep_plan(scenario).chunks),
               "serial_single_cpu_s": single_cpu, "serial_driver_cpu_s": driver_cpu,
               "serial_workers_cpu_s": workers_cpu, "serial_fraction": f,
               "serial_fraction_main_thread": thread / single_cpu,
               "serial_worker_cpu_over_single": workers_cpu / single_cpu,
               "serial_single_wall_s": single_wall, "serial_distributed_wall_s": wall,
               "serial_cluster_start_wall_s": start_wall}
    for n in AMDAHL_WORKERS:
        figures[f"serial_amdahl_speedup_{n}"] = 1 / (f + (1 - f) / n)
        figures[f"serial_speedup_{n}"] = single_cpu / (driver_cpu + workers_cpu / n)
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
    file): (CPU time [s] of this process, all threads; wall time [s]; CPU time [s] of
    this thread; the results)."""
    from uq.files import write_netcdf
    from uq.pipeline.checkpoint import Checkpoint
    checkpoint = Checkpoint(Path(folder) / "out.nc.partial").acquire()
    cpu, wall, thread = _process_cpu(), time.perf_counter(), time.thread_time()
    try:
        dataset = run(scenario, client=client, checkpoint=checkpoint)
        write_netcdf(dataset, Path(folder) / "out.nc")
        checkpoint.clear()
    finally:
        checkpoint.release()
    return (_process_cpu() - cpu, time.perf_counter() - wall, time.thread_time() - thread,
            dataset)


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
