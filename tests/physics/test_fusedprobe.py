"""The compiled probe volume (:mod:`uq.physics.fusedprobe`, in both compiled models)
against the numpy model's quadrature (:mod:`uq.physics.probe`), its independent
reference: the same trials give the same outputs to 1e-12 m/s.

Why 1e-12: the two evaluate the same nodes, weights and power law in float64 (libm's
erf against scipy's, SIMD log and exp against numpy's ``**``, U_ref times the weighted
mean of (z / z_ref)^alpha against the weighted mean of U): each weighted speed is a sum
of at most MAX_PROBE_NODES = 128 terms of ~10 m s-1 with a few ulp each, 2.2e-16 x 10 x
~300 ~ 1e-12 m s-1 at most (observed: ~1e-14); the reconstruction after it is the models'
own, checked to the same bound in test_fused.py and test_fusedmotion.py. Directions
compare as arc lengths (angle x speed, [m s-1]).
"""
import dataclasses

import numpy as np
import pytest

from uq.engine.inputs import input_set
from uq.physics import fused, fusedmotion
from uq.physics import probe as probe_volume
from uq.physics.measurement import measurement_model
from uq.pipeline.modelsetup import error_inputs, scene_from_settings
from uq.pipeline.scenario import load_scenario
from uq.pipeline.shipped import scenario_path

from conftest import with_changes

TOLERANCE = 1e-12           # [m s-1] the module docstring's rounding bound
WIND = ("wind_speed", "wind_direction", "vertical_wind")
#: Both kinds' parameters are given (as probe_volume does), so that either kind's errors
#: are valid; each kind uses its own.
PARAMETERS = {"gate_length": 30.0, "pulse_fwhm": 22.5, "wavelength": 1.565,
              "beam_radius": 28.0, "truncation": 0.02}
PULSED, CW = {**PARAMETERS, "kind": "pulsed"}, {**PARAMETERS, "kind": "cw"}
PROBE_ERRORS = {"gate_length": {"dist": "uniform", "half_width": 1.0},
                "pulse_fwhm": {"dist": "normal", "u": 1.0},
                "wavelength": {"dist": "normal", "u": 0.01},
                "beam_radius": {"dist": "normal", "u": 0.5}}


def trials(scenario, n, seed=5):
    """(resolved scene, errors) of n trials drawn from the scenario's engine inputs."""
    settings = scenario.settings
    scene = probe_volume.resolve(scene_from_settings(settings))
    inputs = error_inputs(settings, scene.n_beams, len(scene.ranges))
    constant = {k: v for k, v in inputs.items() if isinstance(v, float)}
    random = input_set({k: v for k, v in inputs.items() if not isinstance(v, float)})
    rng = np.random.default_rng(seed)
    errors = random.values(rng.standard_normal((n, random.dimension)))
    errors.update(constant)
    return scene, errors


def assert_same(fast, slow, outputs):
    speed = slow["wind_speed"]
    np.testing.assert_array_equal(np.isnan(fast["wind_speed"]), np.isnan(speed))
    finite = np.isfinite(speed)
    assert finite.mean() > 0.5                          # the comparison has substance
    for q in outputs:
        if q == "wind_direction":
            turn = (fast[q] - slow[q] + 180.0) % 360.0 - 180.0
            assert np.max(np.abs(np.deg2rad(turn[finite])) * speed[finite]) < TOLERANCE
        else:
            np.testing.assert_allclose(fast[q][np.isfinite(slow[q])],
                                       slow[q][np.isfinite(slow[q])], rtol=0, atol=TOLERANCE)


@pytest.mark.parametrize("kind", ["pulsed", "cw"])
@pytest.mark.parametrize("shear", [0.14, 0.2])
def test_the_shipped_probe_volume_scenario(kind, shear):
    """probe_volume as shipped (its errors: the probe's parameters and the radial noise),
    each kind and shear of its sweep, every output of the static model."""
    scenario = load_scenario(scenario_path("probe_volume"),
                             {"sweep": {}, "lidar.probe.kind": kind, "wind.shear": shear})
    scene, errors = trials(scenario, 400)
    outputs = WIND + ("radial_velocity", "gate_height")
    assert fused.applicable(scene, outputs, errors)
    fast = measurement_model(scene, outputs, **errors)
    slow = measurement_model(scene, outputs, compiled=False, **errors)
    assert_same(fast, slow, outputs)


TILTED = {"name": "t", "wind": {"speed": 9.0, "direction": 250.0, "vertical": 0.1,
                                "shear": 0.2, "reference_height": 100.0},
          "ship": {"heading": 35.0, "pitch": 3.0, "roll": -2.0, "sog": 1.0, "cog": 40.0},
          "ins": {"heading": {"dist": "normal", "u": 0.5}, "pitch": {"dist": "normal", "u": 0.1}},
          "lidar": {"height": 2.0, "ranges": [10.0, 40.0, 120.0, 250.0],
                    "vertical_beam": True,
                    "errors": {"half_cone": {"dist": "normal", "u": 0.2},
                               "height": {"dist": "normal", "u": 0.5},
                               "radial_velocity": {"dist": "normal", "u": 0.1},
                               **PROBE_ERRORS}},
          "correction": "full"}
MOTION = {"motion": {"roll": {"amplitude": 5.0, "period": 6.0},
                     "pitch": {"amplitude": 3.0, "period": 5.0, "phase": 20.0},
                     "heave": {"amplitude": 1.0, "period": 8.0}},
          "lidar.scan.beam_duration": 1.0, "lidar.lever_arm": [1.0, -0.5, 3.0]}


@pytest.mark.parametrize("probe", [PULSED, CW], ids=["pulsed", "cw"])
@pytest.mark.parametrize("changes", [{}, {"lidar.errors.half_cone": None,
                                      "lidar.errors.height": None}],
                         ids=["geometry errors", "probe errors only"])
def test_static_tilted_and_drifting_with_every_error(probe, changes):
    """A tilted, drifting buoy; the first gate's probe reaches the sea (NaN where numpy
    has NaN); the truth per trial (geometry and probe errors) or per trial for the probe
    alone."""
    settings = with_changes(TILTED, changes)
    scenario = load_scenario(settings, {"lidar.probe": probe})
    scene, errors = trials(scenario, 300)
    outputs = WIND + ("radial_velocity", "gate_height")
    assert fused.applicable(scene, outputs, errors)
    assert_same(measurement_model(scene, outputs, **errors),
                measurement_model(scene, outputs, compiled=False, **errors), outputs)


@pytest.mark.parametrize("probe", [PULSED, CW], ids=["pulsed", "cw"])
@pytest.mark.parametrize("correction", ["pointwise", "full"])
def test_time_resolved_pulsed_and_cw(probe, correction):
    """Roll, pitch and heave within the scan, a lever arm, dwell nodes at 1 s beams:
    the probe's points follow each node's true beam."""
    scenario = load_scenario(TILTED, {"lidar.probe": probe, "correction": correction,
                                      **MOTION})
    scene, errors = trials(scenario, 300)
    assert scene.time_resolved is not None
    assert fusedmotion.applicable(scene, WIND, errors)
    assert_same(measurement_model(scene, WIND, **errors),
                measurement_model(scene, WIND, compiled=False, **errors), WIND)


def test_a_probe_without_parameter_errors_shares_its_weights_and_agrees():
    """No probe errors: the weights are computed once per scene (and the truth too, with
    no geometry error); a batch of scenes of two shears and two heights."""
    scenario = load_scenario(TILTED, {"lidar.probe": PULSED, "lidar.errors": {
        "radial_velocity": {"dist": "normal", "u": 0.1}}})
    scene, errors = trials(scenario, 200)
    shear, height = np.meshgrid([0.0, 0.14, 0.3], [2.0, 25.0])         # (2, 3) scenes
    batch = dataclasses.replace(scene, shear=shear, lidar_height=height)
    fast = measurement_model(batch, WIND, **errors)
    slow = measurement_model(batch, WIND, compiled=False, **errors)
    assert fast["wind_speed"].shape == (200, 2, 3, 4)
    assert_same(fast, slow, WIND)


def test_a_probe_complex_step_runs_the_numpy_model():
    """The GUM's complex step through a probe stays with the numpy model (the reference
    differentiates through scipy's erf); real trials take the compiled one."""
    scenario = load_scenario(TILTED, {"lidar.probe": PULSED})
    scene, errors = trials(scenario, 3)
    complex_errors = {k: np.asarray(v) + 0j for k, v in errors.items()}
    assert "complex step" in fused.declined(scene, WIND, complex_errors)
    assert fused.declined(scene, WIND, errors) == ""
    gum = measurement_model(scene, WIND, **complex_errors)
    np.testing.assert_array_equal(gum["wind_speed"], measurement_model(
        scene, WIND, compiled=False, **complex_errors)["wind_speed"])
