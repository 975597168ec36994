"""Cost of a probe volume per Monte Carlo trial, against the point model, in one run.

    python scripts/bench_probe.py            # ~1 min on 2 cores
    python scripts/bench_probe.py --quick    # fewer trials and repeats

Scene: the shipped ``floating_lidar_full`` (tilted, drifting buoy, 23 inputs, 5 beams, 3
gates, every error source on). Three measurements, each the median of repeated runs,
point and probe alternating so that a drift of the machine's load hits both alike:

1. the measurement model alone (:func:`uq.physics.measurement.measurement_model`, numpy,
   ``compiled=False``) on the same drawn errors: point, pulsed (WindCube-like) and CW
   (ZephIR-like), with the default quadrature (:func:`uq.physics.probe.resolve`);
2. the same for the wind outputs only, the point model compiled (:mod:`uq.physics.fused`,
   what a point run of these outputs uses; a probe always runs the numpy model);
3. a whole ``uq.run`` (draws, model, statistics, GUM) of the scenario, point and pulsed.

The acceptance of issue 19: a pulsed probe with the default quadrature costs at most 16
times the point model per trial (1., the same implementation).
"""
import argparse
import copy
import dataclasses
import statistics
import time

import numpy as np

import uq
from uq.constants import (WINDCUBE_GATE_LENGTH, WINDCUBE_PULSE_FWHM, ZEPHIR_BEAM_RADIUS_MM,
                          ZEPHIR_TRUNCATION, ZEPHIR_WAVELENGTH_UM)
from uq.physics import probe as probe_volume
from uq.physics.measurement import measurement_model
from uq.physics.scene import COMPILED_OUTPUTS
from uq.pipeline.modelsetup import error_inputs, scene_from_settings
from uq.pipeline.scenario import load_scenario
from uq.pipeline.shipped import shipped_path

PULSED = {"kind": "pulsed", "gate_length": WINDCUBE_GATE_LENGTH,
          "pulse_fwhm": WINDCUBE_PULSE_FWHM}
CW = {"kind": "cw", "wavelength": ZEPHIR_WAVELENGTH_UM, "beam_radius": ZEPHIR_BEAM_RADIUS_MM,
      "truncation": ZEPHIR_TRUNCATION}
#: Ratio a pulsed probe may cost per trial against the point model (issue 19).
LIMIT = 16.0


def draws(settings, scene, n, seed=1):
    """Errors of every declared input, drawn once: name -> array (n, ...)."""
    rng = np.random.default_rng(seed)
    out = {}
    for name, spec in error_inputs(settings, scene.n_beams, len(scene.ranges)).items():
        shape = getattr(spec, "shape", ())
        dist = getattr(spec, "distribution", spec)
        if isinstance(dist, float):
            continue
        out[name] = dist.ppf(rng.uniform(size=(n,) + tuple(shape)))
    return out


def timed(function, repeats):
    """Median wall time [s] of `repeats` calls."""
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        function()
        times.append(time.perf_counter() - start)
    return statistics.median(times)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true")
    args = parser.parse_args(argv)
    n, repeats = (2**14, 5) if args.quick else (2**16, 9)
    base = load_scenario(shipped_path("floating_lidar_full"))
    settings = base.settings
    scene = scene_from_settings(settings)
    errors = draws(settings, scene, n)
    scenes = {"point": scene}
    for name, probe in (("pulsed", PULSED), ("cw", CW)):
        with_probe = load_scenario(base, {"lidar.probe": probe})
        scenes[name] = probe_volume.resolve(scene_from_settings(with_probe.settings))
    outputs = base.outputs
    print(f"floating_lidar_full, {n} trials, median of {repeats}")
    for name in ("pulsed", "cw"):
        probe = scenes[name].probe
        print(f"  {name}: {probe.nodes} Gauss-Legendre nodes per beam and gate "
              f"(estimated relative error {probe.quadrature_error:.1e})")

    def model(name, quantities, compiled=False):
        return lambda: measurement_model(scenes[name], quantities, compiled=compiled, **errors)

    for quantities, label in ((outputs, "all outputs"), (COMPILED_OUTPUTS, "wind outputs")):
        seconds = {name: 0.0 for name in scenes}
        for name in scenes:                         # warm-up (and numba's cache)
            model(name, quantities)()
        samples = {name: [] for name in scenes}
        for _ in range(repeats):                   # alternate, so that load hits all alike
            for name in scenes:
                samples[name].append(timed(model(name, quantities), 1))
        seconds = {name: statistics.median(values) for name, values in samples.items()}
        print(f"model alone, numpy, {label}:")
        for name, value in seconds.items():
            print(f"  {name:6s} {1e9 * value / n:8.0f} ns per trial   "
                  f"{value / seconds['point']:5.2f} x point")
        if quantities == COMPILED_OUTPUTS:
            compiled = timed(model("point", quantities, compiled=True), repeats)
            print(f"  point, compiled {1e9 * compiled / n:8.0f} ns per trial; pulsed "
                  f"{seconds['pulsed'] / compiled:5.2f} x, cw {seconds['cw'] / compiled:5.2f} x")
        if quantities == outputs:
            ratio = seconds["pulsed"] / seconds["point"]
    runs = {}
    for name, probe in (("point", None), ("pulsed", PULSED)):
        overrides = {"sampling.n": n}
        if probe:
            overrides["lidar.probe"] = copy.deepcopy(probe)
        scenario = load_scenario(base, overrides)
        uq.run(scenario)                                 # warm-up
        runs[name] = timed(lambda: uq.run(scenario), max(3, repeats // 3))
    print(f"whole uq.run ({n} trials): point {runs['point']:.3f} s, pulsed "
          f"{runs['pulsed']:.3f} s ({runs['pulsed'] / runs['point']:.2f} x)")
    verdict = "met" if ratio <= LIMIT else "NOT met"
    print(f"acceptance: pulsed / point per trial (model alone, all outputs) = {ratio:.2f} "
          f"<= {LIMIT:g}: {verdict}")
    return 0 if ratio <= LIMIT else 1


if __name__ == "__main__":
    raise SystemExit(main())
