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
