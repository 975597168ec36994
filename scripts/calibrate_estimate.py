"""Calibrate the costs of ``uq check``'s run-time estimate (:mod:`uq.pipeline.estimate`):
run each model path at two sizes and print the marginal CPU time per unit (the
difference of the two runs over the difference of their sizes, so that fixed costs
cancel), ready to paste into :data:`uq.pipeline.estimate.COSTS`.

    python scripts/calibrate_estimate.py

CPU time (``time.process_time``, all threads of this process), not wall time: on a busy
machine wall time says more about the load than about the model. Run it with numba's
cache warm (``uq warmup``), on an idle machine if there is one. Each timed run has a seed
of its own (a record drawn once is kept in memory and would be reused).
"""
import itertools
import time
from pathlib import Path

from uq.pipeline.runner import run
from uq.pipeline.scenario import load_scenario

ROOT = Path(__file__).resolve().parents[1] / "scenarios"
SEEDS = itertools.count(1000)


def cpu_seconds(name, changes):
    scenario = load_scenario(ROOT / f"{name}.yaml", {**changes, "sampling.seed": next(SEEDS)})
    run(load_scenario(scenario.settings, {"sampling.seed": next(SEEDS)}))    # warm
    started = time.process_time()
    run(scenario)
    return time.process_time() - started


def marginal(name, changes, key, sizes):
    """CPU seconds per unit of `key` between its two `sizes`."""
    times = [cpu_seconds(name, {**changes, key: size}) for size in sizes]
    return (times[1] - times[0]) / (sizes[1] - sizes[0])


def settings(name, changes):
    return load_scenario(ROOT / f"{name}.yaml", changes).settings


if __name__ == "__main__":
    one = {"sweep": {}}
    static = marginal("rubio2022_case_i", one, "sampling.n", (2**15, 2**18))
    print(f"static_trial_gate = {static:.3g}")
    gates3 = marginal("floating_lidar_full", one, "sampling.n", (2**15, 2**17)) / 3
    print(f"  (check: floating_lidar_full per trial and gate {gates3:.3g})")
    probe = marginal("probe_volume", one, "sampling.n", (2**11, 2**14)) / 9
    print(f"probe_trial_gate = {probe:.3g}")
    n = 2**14
    waves = settings("floating_lidar_waves", one)
    beams = len(waves["lidar"]["azimuths"]) + int(waves["lidar"]["vertical_beam"])
    component = marginal("floating_lidar_waves", {**one, "sampling.n": n},
                         "motion.spectrum.components", (8, 32)) / (n * beams)
    print(f"motion_trial_beam_component = {component:.3g}")
    nacelle = settings("nacelle_floating", one)
    per_trial = marginal("nacelle_floating", one, "sampling.n", (2**12, 2**15))
    motion = (per_trial - component * 4 * 3) / len(nacelle["lidar"]["ranges"])
    print(f"motion_trial_gate = {motion:.3g}  (nacelle_floating per trial {per_trial:.3g})")
    for name, label in (("tiana2017_vad_static", "scene_beam_gate"),
                        ("tiana2017_vad", "motion_scene_beam_gate")):
        scenes = {}
        for count in (90, 360):
            scenes[count] = {"sweep": {"wind.direction": {"start": 0, "stop": 360,
                                                          "step": 360 / count}}}
        times = [cpu_seconds(name, scenes[count]) for count in scenes]
        per_scene = (times[1] - times[0]) / (360 - 90)
        beams = len(settings(name, one)["lidar"]["azimuths"])
        print(f"{label} = {per_scene / beams:.3g}  ({name}: {per_scene:.3g} per scene, 20 "
              "trials each)")
    small = {"sampling.n": 256, "lidar.ranges": [100.0]}
    record = marginal("sathe2011_ti", small, "record.count", (2, 6))
    duration = settings("sathe2011_ti", small)["record"]["duration"]
    print(f"record_second = {record / duration:.3g}  (a record of {duration:g} s: "
          f"{record:.3g})")
