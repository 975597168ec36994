"""The compiled trial loop (uq.physics.fused) against the numpy measurement model.

The two are independent implementations of the same physics (scalar loop vs array
passes), so agreement over every correction model and error source checks both.
"""
import dataclasses

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from conftest import make_scene
from uq.physics import fused
from uq.physics.measurement import measurement_model

WIND = ("wind_speed", "wind_direction", "vertical_wind")
# The two orders of summation differ by a few ulps of the largest term (the ship and
# wind velocities, <= ~20 m/s): 1e-12 m/s is ~50 ulps of 20 m/s.
ATOL = 1e-12


def errors(rng, n, scene, sources):
    """Random errors of each named source, in the shapes of the measurement model."""
    shapes = {"lidar_radial_velocity": (n, scene.n_beams, len(scene.ranges))}
    scales = {"lidar_height": 0.5, "ins_sog": 0.2, "ins_heave": 0.1, "lidar_radial_velocity": 0.1}
    return {name: scales.get(name, 0.3) * rng.standard_normal(shapes.get(name, (n,)))
            for name in sources}


def both(scene, outputs=WIND, **err):
    compiled = measurement_model(scene, outputs, compiled=True, **err)
    plain = measurement_model(scene, outputs, compiled=False, **err)
    return compiled, plain


def assert_same(compiled, plain):
    for name in plain:
        assert compiled[name].shape == plain[name].shape, name
        if name == "wind_direction":       # compare on the circle: 359.99... vs 0.0 is a match
            difference = np.mod(compiled[name] - plain[name] + 180.0, 360.0) - 180.0
            np.testing.assert_allclose(difference, 0.0, atol=ATOL * 1e3, err_msg=name)
            # ^ degrees: an 1e-12 m/s vector error at >= 0.1 m/s is <= 6e-10 deg
        else:
            np.testing.assert_allclose(compiled[name], plain[name], rtol=0, atol=ATOL,
                                       err_msg=name)


ALL_SOURCES = ("lidar_half_cone", "lidar_misalignment", "lidar_height", "ins_heading",
               "ins_pitch", "ins_roll", "ins_sog", "ins_cog", "ins_heave",
               "lidar_radial_velocity")


@pytest.mark.parametrize("model", ["none", "yaw", "tilt2d", "full"])
@pytest.mark.parametrize("shear", [0.0, 0.14])
@pytest.mark.parametrize("vertical_beam", [False, True])
def test_agrees_with_numpy_for_every_correction(model, shear, vertical_beam, rng):
    scene = make_scene(**{"correction": model, "wind.shear": shear, "ship.pitch": 4.0,
                          "ship.roll": -3.0, "ship.heading": 40.0, "ship.sog": 3.0,
                          "ship.cog": 60.0, "ship.heave": 0.3, "lidar.misalignment": 10.0,
                          "lidar.vertical_beam": vertical_beam, "lidar.ranges": [40, 100, 160]})
    err = errors(rng, 500, scene, ALL_SOURCES)
    assert fused.applicable(scene, WIND, err)
    assert_same(*both(scene, **err))


@pytest.mark.parametrize("source", ALL_SOURCES)
def test_agrees_with_numpy_for_each_error_alone(source, rng):
    """One source per run exercises the loop's shortcuts (fixed truth, fixed reading)."""
    scene = make_scene(**{"correction": "full", "wind.shear": 0.1, "ship.pitch": 2.0,
                          "ship.sog": 2.0, "lidar.ranges": [50, 120]})
    assert_same(*both(scene, **errors(rng, 200, scene, (source,))))


def test_agrees_without_any_error():
    scene = make_scene(**{"correction": "full", "ship.roll": 5.0})
    assert_same(*both(scene))


@settings(max_examples=40, deadline=None)
@given(st.floats(0, 359.999), st.floats(0, 20), st.floats(-15, 15), st.floats(-15, 15),
       st.floats(0, 359.9), st.floats(5, 60), st.sampled_from(["none", "yaw", "tilt2d", "full"]))
def test_agrees_over_scenes_and_directions(direction, speed, pitch, roll, heading, cone, model):
    scene = make_scene(**{"wind.direction": direction, "wind.speed": speed, "ship.pitch": pitch,
                          "ship.roll": roll, "ship.heading": heading, "lidar.half_cone": cone,
                          "wind.shear": 0.2, "correction": model})
    rng = np.random.default_rng(7)
    compiled, plain = both(scene, **errors(rng, 50, scene, ALL_SOURCES))
    assert_same(compiled, plain)
    assert np.all((compiled["wind_direction"] >= 0) & (compiled["wind_direction"] < 360))


@pytest.mark.parametrize("direction", [0.0, 1e-9, 359.999999999, 360.0 - 1e-13])
def test_direction_wraps_into_0_360(direction):
    """Wind from (almost) north: the direction stays in [0, 360), never 360."""
    scene = make_scene(**{"wind.direction": direction, "correction": "yaw"})
    compiled, plain = both(scene)
    assert 0.0 <= compiled["wind_direction"].item() < 360.0
    assert_same(compiled, plain)


def test_height_below_the_sea_is_nan_in_both():
    """A gate under the surface is outside the power law: NaN, as in the numpy model."""
    scene = make_scene(**{"wind.shear": 0.14, "lidar.height": 2.0, "lidar.ranges": [40, 100]})
    err = {"lidar_height": np.array([0.0, -150.0, -60.0])}     # -> all, then the lowest gate
    compiled, plain = both(scene, **err)
    for name in WIND:
        np.testing.assert_array_equal(np.isnan(compiled[name]), np.isnan(plain[name]))
    assert np.isnan(compiled["wind_speed"][1]).all() and not np.isnan(compiled["wind_speed"][0]).any()
    assert np.isnan(compiled["wind_speed"][2, 0]) and not np.isnan(compiled["wind_speed"][2, 1])
    assert_same({k: np.nan_to_num(v) for k, v in compiled.items()},
                {k: np.nan_to_num(v) for k, v in plain.items()})


def test_only_requested_outputs():
    scene = make_scene()
    out = measurement_model(scene, ("wind_speed",), lidar_half_cone=np.zeros(3))
    assert set(out) == {"wind_speed"} and out["wind_speed"].shape == (3, 1)


def test_not_applicable_where_the_numpy_model_is_needed():
    scene = make_scene()
    assert not fused.applicable(scene, ("radial_velocity",), {})
    assert not fused.applicable(scene, WIND, {"ins_heading": np.zeros((3, 4))})   # beam INS
    assert not fused.applicable(scene, WIND, {"lidar_half_cone": np.zeros(3) + 1e-20j})
    assert not fused.applicable(scene, WIND, {}, scene_draws=True)
    assert fused.applicable(scene, WIND, {"ins_heading": np.zeros((3, 1))})    # scan INS
    # a large batch (a GUM grid): the numpy model vectorises over its scenes
    from uq.constants import FUSED_MAX_SCENES
    for scenes, expected in ((FUSED_MAX_SCENES, True), (FUSED_MAX_SCENES + 1, False)):
        batch = dataclasses.replace(scene, wind_speed=np.full(scenes, 5.0))
        assert fused.applicable(batch, WIND, {}) is expected


@pytest.mark.parametrize("model", ["yaw", "full"])
def test_a_batch_of_scenes_agrees_with_numpy_scene_by_scene(model, rng):
    """A sweep's batch (S = (2, 3); heading the same for all): every scene sees the
    same draws, in the numpy model's layout (n, *S, gates)."""
    base = make_scene(**{"correction": model, "wind.shear": 0.1, "ship.pitch": 2.0,
                         "lidar.ranges": [50, 120]})
    grid = np.ones((2, 3))
    batch = dataclasses.replace(base, wind_speed=np.array([[4.0], [8.0]]) * grid,
                                wind_direction=np.deg2rad([0.0, 90.0, 359.0]) * grid,
                                heading=0.3)
    err = errors(rng, 100, base, ALL_SOURCES)
    assert fused.applicable(batch, WIND, err)
    compiled, plain = both(batch, **err)
    assert compiled["wind_speed"].shape == (100, 2, 3, 2)
    assert_same(compiled, plain)
    single = dataclasses.replace(base, wind_speed=8.0, wind_direction=np.deg2rad(90.0),
                                 heading=0.3)
    alone = measurement_model(single, WIND, **err)
    np.testing.assert_array_equal(alone["wind_speed"], compiled["wind_speed"][:, 1, 1])


@pytest.mark.parametrize("base", [0.0, 0.5, -2.0, 3.1])
def test_angle_trig_equals_libm(base, rng):
    """Taylor polynomials + angle addition within SMALL_ANGLE, libm beyond: cos and sin
    of base + error to 4 ulp of 1 (two roundings of the addition theorem, and the
    rounding of base + error that the direct call makes)."""
    from uq.constants import SMALL_ANGLE
    from uq.physics.fusedkernels import angle_trig
    errors_deg = np.concatenate([rng.normal(0, 3, 2000), [0.0, -0.0, np.nan, 1e-300],
                                 np.rad2deg([SMALL_ANGLE, -SMALL_ANGLE, 0.2499999, 0.2500001,
                                             1.0, -3.0, 100.0])])
    strided = np.repeat(errors_deg, 3)[::3]                        # any stride
    cos, sin = np.empty(len(errors_deg)), np.empty(len(errors_deg))
    angle_trig(strided, base, 0, len(errors_deg), cos, sin)
    exact = base + np.deg2rad(errors_deg)
    np.testing.assert_allclose(cos, np.cos(exact), rtol=0, atol=4 * 2.2e-16)
    np.testing.assert_allclose(sin, np.sin(exact), rtol=0, atol=4 * 2.2e-16)
    assert np.isnan(cos[2002]) and np.isnan(sin[2002])


def test_angle_trig_of_a_constant_error_fills_the_block():
    from uq.physics.fusedkernels import angle_trig
    cos, sin = np.full(5, -9.0), np.full(5, -9.0)
    angle_trig(np.array([30.0]), 0.0, 10, 14, cos, sin)
    np.testing.assert_allclose(cos[:4], np.cos(np.deg2rad(30.0)), rtol=1e-15)
    np.testing.assert_allclose(sin[:4], 0.5, rtol=1e-15)
    assert cos[4] == -9.0                                  # nothing past the block
