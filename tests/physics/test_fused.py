"""The compiled trial loop (uq.physics.fused) against the numpy measurement model.

The two are independent implementations of the same physics (scalar loop vs array
passes), so agreement over every correction model, error source, output, INS
correlation (one reading per scan or per beam), independent draws per scene and
complex-step evaluation (the GUM Jacobian) checks both.
"""
import dataclasses
import itertools

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from conftest import make_scene
from uq.physics import fused
from uq.engine.gum import complex_step_jacobian
from uq.engine.inputs import Input, input_set
from uq.physics.measurement import measurement_model
from uq.physics.scene import OUTPUTS

WIND = ("wind_speed", "wind_direction", "vertical_wind")
EVERY = OUTPUTS
# The two orders of summation differ by a few ulps of the largest term (the ship and
# wind velocities, <= ~20 m/s): 1e-12 m/s is ~50 ulps of 20 m/s.
ATOL = 1e-12


def errors(rng, n, scene, sources, per_beam=(), scenes=()):
    """Random errors of each named source, in the shapes of the measurement model: INS
    errors named in `per_beam` with one value per beam (n, beams), the others one per
    scan (n,); with `scenes` (the batch's shape) independent draws per scene, the scene
    axes after the first (INS errors then (n, *scenes, k))."""
    beams, gates = scene.n_beams, len(scene.ranges)

    def shape(name):
        if name == "lidar_radial_velocity":
            return (n, *scenes, beams, gates)
        if name.startswith("ins_"):
            if name in per_beam:
                return (n, *scenes, beams)
            return (n, *scenes, 1) if scenes else (n,)
        return (n, *scenes)
    scales = {"lidar_height": 0.5, "ins_sog": 0.2, "ins_heave": 0.1, "lidar_radial_velocity": 0.1}
    return {name: scales.get(name, 0.3) * rng.standard_normal(shape(name)) for name in sources}


def both(scene, outputs=EVERY, scene_draws=False, **err):
    compiled = measurement_model(scene, outputs, scene_draws, compiled=True, **err)
    plain = measurement_model(scene, outputs, scene_draws, compiled=False, **err)
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


def test_applicable_to_every_static_scene_and_output(complex_kernels):
    scene = make_scene()
    n = 3
    assert fused.applicable(scene, EVERY, {})
    assert fused.applicable(scene, EVERY, {"ins_heading": np.zeros((n, 4))})       # beam INS
    assert fused.applicable(scene, EVERY, {"ins_heading": np.zeros((n, 1))})       # scan INS
    assert fused.applicable(scene, EVERY, {"lidar_half_cone": np.zeros(n) + 1e-20j})  # GUM
    batch = dataclasses.replace(scene, wind_speed=np.full((2, 5), 5.0))
    assert fused.applicable(batch, EVERY, {"ins_sog": np.zeros((n, 2, 5, 1))}, scene_draws=True)
    # shapes it does not take go to the numpy model, which says what is wrong
    assert not fused.applicable(scene, EVERY, {"ins_heading": np.zeros((n, 3))})   # 3 of 4 beams
    assert not fused.applicable(batch, EVERY, {"ins_sog": np.zeros((n, 5, 2, 1))},
                                scene_draws=True)                               # wrong scenes
    assert not fused.applicable(scene, EVERY, {"lidar_radial_velocity": np.zeros((n, 4))})


def test_not_applicable_to_a_time_resolved_scene():
    """Motion within the scan is the numpy model of uq.physics.timeresolved."""
    from uq.physics.scene import TimeResolved
    scene = dataclasses.replace(make_scene(), time_resolved=TimeResolved())
    assert not fused.applicable(scene, EVERY, {})


@pytest.mark.parametrize("model", ["none", "yaw", "tilt2d", "full"])
@pytest.mark.parametrize("per_beam", [("ins_heading", "ins_pitch", "ins_roll", "ins_sog",
                                       "ins_cog", "ins_heave"), ("ins_sog",), ("ins_pitch",)])
def test_agrees_with_numpy_with_a_reading_per_beam(model, per_beam, rng):
    """ins.correlation beam (every INS error one value per beam) and a correlation time
    on some of them (those (n, beams), the others (n,)): point-wise correction, every
    output, every error source on, shear and tilt."""
    scene = make_scene(**{"correction": model, "wind.shear": 0.14, "ship.pitch": 4.0,
                          "ship.roll": -3.0, "ship.heading": 40.0, "ship.sog": 3.0,
                          "ship.cog": 60.0, "ship.heave": 0.3, "lidar.misalignment": 10.0,
                          "lidar.vertical_beam": True, "lidar.ranges": [40, 100, 160]})
    err = errors(rng, 300, scene, ALL_SOURCES, per_beam=per_beam)
    assert fused.applicable(scene, EVERY, err)
    assert_same(*both(scene, **err))


@pytest.mark.parametrize("model", ["yaw", "tilt2d", "full"])
@pytest.mark.parametrize("sources", [ALL_SOURCES, ("ins_heading", "ins_sog")])
def test_independent_draws_per_scene_agree_with_numpy(model, sources, rng):
    """scene_draws: each scene of a batch (2 x 3) its own draws (the errors carry the
    scene axes), with and without geometry errors (truth per trial or per scene), scan
    and per-beam readings; each scene's outputs are those of the scene alone with its
    slice of the draws."""
    base = make_scene(**{"correction": model, "wind.shear": 0.12, "ship.pitch": 2.0,
                         "lidar.ranges": [50, 120]})
    grid = np.ones((2, 3))
    batch = dataclasses.replace(base, wind_speed=np.array([[4.0], [8.0]]) * grid,
                                wind_direction=np.deg2rad([0.0, 90.0, 359.0]) * grid,
                                shear=np.array([0.0, 0.1, 0.2]) * grid)
    for per_beam in ((), ("ins_heading",)):
        err = errors(rng, 40, base, sources, per_beam=per_beam, scenes=(2, 3))
        assert fused.applicable(batch, EVERY, err, scene_draws=True)
        compiled, plain = both(batch, scene_draws=True, **err)
        assert compiled["radial_velocity"].shape == (40, 2, 3, base.n_beams, 2)
        assert_same(compiled, plain)
        single = dataclasses.replace(base, wind_speed=8.0, wind_direction=np.deg2rad(90.0),
                                     shear=0.1)
        alone = measurement_model(single, EVERY, **{k: v[:, 1, 1] for k, v in err.items()})
        for name in EVERY:
            np.testing.assert_array_equal(alone[name], compiled[name][:, 1, 1], err_msg=name)


@pytest.fixture
def complex_kernels(monkeypatch):
    """The compiled model takes complex steps of any number of scenes (by default it
    leaves those of fewer than COMPLEX_STEP_COMPILED_MIN_SCENES to the numpy model)."""
    monkeypatch.setattr(fused, "COMPLEX_STEP_COMPILED_MIN_SCENES", 1)


def _jacobians(scene, inputs):
    """Complex-step Jacobians of every output by the compiled and by the numpy model."""
    laid = input_set(inputs)
    assert fused.declined(scene, EVERY, {"ins_heading": np.zeros(1, complex)}) == ""
    return [complex_step_jacobian(
        lambda **e: measurement_model(scene, EVERY, compiled=compiled, **e), laid)
        for compiled in (True, False)]


@pytest.mark.parametrize("model", ["none", "yaw", "tilt2d", "full"])
@pytest.mark.parametrize("correlation", ["scan", "beam"])
def test_complex_step_jacobian_agrees_with_numpy(model, correlation, complex_kernels):
    """The GUM: complex errors run the compiled loop in complex arithmetic. Its value
    and Jacobian equal the numpy model's (every output, every error source, a batch of
    three scenes, geometry errors so the truth varies per perturbation). Tolerance
    1e-12 per unit of the input (m/s per deg, m per m, ...): the derivatives are at most
    ~3 (m of gate height per deg of half-cone at 160 m), the two implementations' sums
    differ by a few ulps of their terms."""
    from scipy import stats
    scene = make_scene(**{"correction": model, "wind.shear": 0.14, "ship.pitch": 4.0,
                          "ship.roll": -3.0, "ship.heading": 40.0, "ship.sog": 3.0,
                          "ship.cog": 60.0, "ship.heave": 0.3, "lidar.vertical_beam": True,
                          "lidar.ranges": [40, 100, 160]})
    batch = dataclasses.replace(scene, wind_direction=np.deg2rad([10.0, 100.0, 250.0]),
                                misalignment=np.deg2rad([0.0, 5.0, -30.0]))
    shape = (scene.n_beams,) if correlation == "beam" else ()
    inputs = {f"ins_{key}": Input(stats.norm(0.1, 0.2), shape) for key in
              ("heading", "pitch", "roll", "sog", "cog", "heave")}
    inputs.update(lidar_half_cone=stats.norm(0, 0.1), lidar_misalignment=stats.norm(0.2, 0.3),
                  lidar_height=stats.norm(-1.0, 0.5),
                  lidar_radial_velocity=Input(stats.norm(0, 0.1), (scene.n_beams, 3)))
    (value_c, jac_c), (value_n, jac_n) = _jacobians(batch, inputs)
    for name in EVERY:
        assert jac_c[name].shape == jac_n[name].shape == (input_set(inputs).dimension,) \
            + value_n[name].shape
        assert np.abs(jac_n[name]).max() > 0.01                    # the check can fail
        np.testing.assert_allclose(jac_c[name], jac_n[name], rtol=0, atol=ATOL, err_msg=name)
    assert_same(value_c, value_n)


def test_complex_step_of_a_large_grid_without_geometry_errors(complex_kernels):
    """A GUM grid (the truth per scene, INS errors only, the paper's Table B1): the
    compiled Jacobian of 500 scenes equals the numpy one."""
    from scipy import stats
    scene = make_scene(**{"correction": "yaw", "ship.sog": 2.0, "wind.speed": 5.0})
    rng = np.random.default_rng(3)
    batch = dataclasses.replace(scene, wind_direction=rng.uniform(0, 2 * np.pi, 500),
                                misalignment=rng.uniform(-np.pi, np.pi, 500))
    inputs = {"ins_heading": stats.norm(0, 0.1), "ins_sog": stats.norm(0, 0.1),
              "ins_cog": stats.norm(0, 0.1)}
    (value_c, jac_c), (value_n, jac_n) = _jacobians(batch, inputs)
    for name in EVERY:
        np.testing.assert_allclose(jac_c[name], jac_n[name], rtol=0, atol=ATOL, err_msg=name)
    assert_same(value_c, value_n)


def test_a_small_complex_step_runs_the_numpy_model():
    """The GUM's complex step of a few scenes is the numpy model's (cheaper than compiling
    the complex kernels, see COMPLEX_STEP_COMPILED_MIN_SCENES); of a large grid, the
    compiled loop's; real draws always the compiled loop's."""
    from uq.constants import COMPLEX_STEP_COMPILED_MIN_SCENES as least
    one = make_scene(**{"correction": "yaw"})
    grid = dataclasses.replace(one, wind_direction=np.linspace(0.0, 6.0, least))
    just_below = dataclasses.replace(one, wind_direction=np.linspace(0.0, 6.0, least - 1))
    step, draws = {"ins_heading": np.full(2, 0.1 + 1e-20j)}, {"ins_heading": np.full(2, 0.1)}
    assert "complex step (the GUM) of fewer than" in fused.declined(one, EVERY, step)
    assert "fewer than" in fused.declined(just_below, EVERY, step)
    assert fused.declined(grid, EVERY, step) == ""
    assert fused.declined(one, EVERY, draws) == ""


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
def test_reading_trigonometry_equals_libm(base, rng):
    """Taylor polynomials of the error (ins_trig) + angle addition within SMALL_ANGLE,
    libm beyond: cos and sin of base + error to 4 ulp of 1 (two roundings of the addition
    theorem, and the rounding of base + error that the direct call makes)."""
    from uq.constants import SMALL_ANGLE
    from uq.physics import fusedkernels as kernels
    errors_deg = np.concatenate([rng.normal(0, 3, 2000), [0.0, -0.0, np.nan, 1e-300],
                                 np.rad2deg([SMALL_ANGLE, -SMALL_ANGLE, 0.2499999, 0.2500001,
                                             1.0, -3.0, 100.0])])
    n = len(errors_deg)
    strided = np.repeat(errors_deg, 3)[::3].reshape(n, 1, 1)           # any stride
    zero = np.zeros((1, 1, 1))
    cos_x, sin_x = np.empty((4, 1, n)), np.empty((4, 1, n))
    ins_trig = kernels.compiled(float)["ins_trig"]
    ins_trig((strided, zero, zero, zero, zero, zero), np.zeros((1, 1)), 0, 1, 0, n, False,
             cos_x, sin_x, np.empty(n))
    cos, sin = np.array([kernels._angle.py_func(base, np.cos(base), np.sin(base),
                                                np.deg2rad(e), c, s)
                         for e, c, s in zip(errors_deg, cos_x[0, 0], sin_x[0, 0])]).T
    exact = base + np.deg2rad(errors_deg)
    np.testing.assert_allclose(cos, np.cos(exact), rtol=0, atol=4 * 2.2e-16)
    np.testing.assert_allclose(sin, np.sin(exact), rtol=0, atol=4 * 2.2e-16)
    assert np.isnan(cos[2002]) and np.isnan(sin[2002])


def test_a_nan_error_in_the_first_trial_stays_in_that_trial(rng):
    """An out-of-domain first trial (NaN geometry and INS errors) is NaN alone; the
    others equal the numpy model (the kernels once took their zero from trial 0's
    beams, so one NaN made every output NaN)."""
    scene = make_scene(**{"correction": "full", "wind.shear": 0.1, "lidar.vertical_beam": True,
                          "ship.pitch": 3.0})
    err = errors(rng, 300, scene, ALL_SOURCES)
    err["lidar_half_cone"][0] = err["ins_heading"][0] = np.nan
    compiled, plain = both(scene, **err)
    for name in ("wind_speed", "radial_velocity"):
        assert np.isnan(compiled[name][0]).all() and not np.isnan(compiled[name][1:]).any()
    assert_same({k: v[1:] for k, v in compiled.items()}, {k: v[1:] for k, v in plain.items()})


@pytest.mark.parametrize("sources", [("lidar_half_cone",), ALL_SOURCES])
def test_no_output_depends_on_uninitialised_memory(sources, monkeypatch, rng):
    """Every scratch buffer of the compiled model filled with NaN (numpy.empty gives
    whatever memory holds): the outputs are the same. A batch of four scenes in two
    rectangles of trials (truth per trial) and with common truth."""
    scene = make_scene(**{"correction": "none", "lidar.vertical_beam": True, "lidar.ranges": [40]})
    batch = dataclasses.replace(scene, wind_direction=np.deg2rad([10.0, 50.0, 90.0, 130.0]),
                                heading=np.deg2rad([0.0, 30.0, 60.0, 90.0]))
    err = errors(rng, 1719, scene, sources)                # 2 scenes per rectangle
    clean = measurement_model(batch, EVERY, **err)
    empty = np.empty

    def poisoned(*args, **kwargs):
        array = empty(*args, **kwargs)
        if array.dtype.kind in "fc":
            array.fill(np.nan)
        return array
    monkeypatch.setattr(fused.np, "empty", poisoned)
    dirty = measurement_model(batch, EVERY, **err)
    for name in EVERY:
        np.testing.assert_array_equal(dirty[name], clean[name], err_msg=name)


# ---- a tilted (nacelle) mount: lidar.mount.tilt > 0 (uq.physics.nacelle)

from uq.physics.scene import NACELLE_OUTPUTS          # noqa: E402

FOUR, TWO = [0, 90, 180, 270], [90, 270]


def nacelle_scene(azimuths, model, tilt=90.0, **changes):
    """A nacelle lidar (clock positions `azimuths`, half-cone 15 deg) at 150 m on a pitched,
    rolled, yawed, moving platform, power-law shear, the wind 20 deg off the bow."""
    return make_scene(**{"correction": model, "lidar.mount": {"tilt": tilt},
                         "lidar.half_cone": 15.0, "lidar.azimuths": azimuths,
                         "lidar.height": 150.0, "lidar.ranges": [50, 100, 300],
                         "lidar.misalignment": 2.0, "wind.shear": 0.14,
                         "wind.reference_height": 150.0, "wind.direction": 20.0,
                         "ship.heading": 30.0, "ship.pitch": 2.0, "ship.roll": -1.0,
                         "ship.sog": 1.0, "ship.cog": 60.0, "ship.heave": 0.2, **changes})


def nacelle_outputs(azimuths):
    """Every output a layout has (the shear exponent needs beams above and below)."""
    return EVERY + (NACELLE_OUTPUTS if 0 in azimuths else ("yaw_misalignment",))


def assert_nacelle_same(compiled, plain):
    """As :func:`assert_same`, the yaw misalignment compared on the circle like the
    direction (-180 vs 179.999... is a match), NaN shear exponents in the same trials."""
    for name in ("yaw_misalignment", "shear_exponent"):
        if name in plain:
            assert np.array_equal(np.isnan(compiled[name]), np.isnan(plain[name])), name
    rest = {name: value for name, value in plain.items() if name not in NACELLE_OUTPUTS}
    assert_same({name: compiled[name] for name in rest}, rest)
    if "yaw_misalignment" in plain:
        difference = np.mod(compiled["yaw_misalignment"] - plain["yaw_misalignment"] + 180.0,
                            360.0) - 180.0
        np.testing.assert_allclose(difference, 0.0, atol=ATOL)   # deg: as the direction's
    if "shear_exponent" in plain:    # [1]: ln ratios of ~0.3 from speeds and heights that
        # agree to 1e-12 relative: the quotient to ~1e-12 / 0.3 of itself (~0.14)
        np.testing.assert_allclose(compiled["shear_exponent"], plain["shear_exponent"],
                                   rtol=0, atol=ATOL, equal_nan=True)


@pytest.mark.parametrize("azimuths, model", [
    (azimuths, model) for azimuths in (FOUR, TWO, [0, 120, 240])
    for model in ("none", "yaw", "tilt2d", "full")
    if not (model == "tilt2d" and len(azimuths) == 2)])   # (refused: a 3-D correction)
@pytest.mark.parametrize("per_beam", [(), ("ins_heading", "ins_pitch", "ins_roll", "ins_sog",
                                           "ins_cog", "ins_heave"), ("ins_pitch",)])
def test_a_nacelle_lidar_agrees_with_numpy(azimuths, model, per_beam, rng):
    """The compiled model takes a tilted mount: clock-position beams, the 2-beam
    horizontal least squares (w = 0), the 4-beam hub-height wind of the level pair after
    the 3-D solve (a 3-beam layout without a level pair keeps the 3-D solve), the yaw
    misalignment and the shear exponent at the believed heights; one reading per scan or
    per beam, every error source on. Its outputs equal the numpy model's."""
    scene = nacelle_scene(azimuths, model)
    err = errors(rng, 300, scene, ALL_SOURCES, per_beam=per_beam)
    outputs = nacelle_outputs(azimuths)
    assert fused.declined(scene, outputs, err) == ""
    compiled, plain = both(scene, outputs, **err)
    assert_nacelle_same(compiled, plain)
    assert np.isfinite(compiled["wind_speed"]).all()               # the check can fail


@pytest.mark.parametrize("azimuths", [FOUR, TWO, [0, 120, 240]])
@pytest.mark.parametrize("model", ["none", "full"])
def test_a_nacelle_scan_with_the_truth_common_to_its_trials_agrees_with_numpy(azimuths,
                                                                            model, rng):
    """Without geometry errors the truth is the scene's: a scan's reading is one linear
    map of the radial velocities, ``none``'s (the configured heading) once per scene with
    its image of the truth, a trial adding its noise's (fusedkernels._reading_operator;
    without the radial velocities and the shear exponent, in rows over the trials:
    _folded_trials); with and without radial noise, three gates, a batch of two scenes."""
    base = nacelle_scene(azimuths, model)
    batch = dataclasses.replace(base, wind_speed=np.array([6.0, 12.0]))
    sources = ("lidar_radial_velocity",) + (("ins_pitch", "ins_heading") if model == "full"
                                            else ())
    for chosen, outputs in itertools.product(
            (sources, sources[1:]), (nacelle_outputs(azimuths), WIND + ("gate_height",))):
        err = errors(rng, 50, base, chosen)
        assert fused.applicable(batch, outputs, err)
        compiled, plain = both(batch, outputs, **err)
        assert_nacelle_same(compiled, plain)
        assert np.isfinite(compiled["wind_speed"]).all()           # the check can fail
        assert np.ptp(compiled["wind_speed"][:, 0]) > 0 or not chosen   # trials differ


@pytest.mark.parametrize("tilt", [90.0, 60.0])
def test_a_batch_of_nacelle_scenes_with_their_own_draws_agrees_with_numpy(tilt, rng):
    """A batch (2 x 3: wind speed, direction, shear) with independent draws per scene and
    a probe-free truth per trial (geometry errors), at a tilt between the two lidars."""
    base = nacelle_scene(FOUR, "full", tilt)
    grid = np.ones((2, 3))
    batch = dataclasses.replace(base, wind_speed=np.array([[4.0], [8.0]]) * grid,
                                wind_direction=np.deg2rad([0.0, 90.0, 359.0]) * grid,
                                shear=np.array([0.0, 0.1, 0.2]) * grid)
    err = errors(rng, 40, base, ALL_SOURCES, scenes=(2, 3))
    outputs = nacelle_outputs(FOUR)
    assert fused.applicable(batch, outputs, err, scene_draws=True)
    assert_nacelle_same(*both(batch, outputs, scene_draws=True, **err))


def test_a_nacelle_lidar_declines_what_it_does_not_compute():
    """The GUM's complex step of a tilted mount and the shear exponent of beams with no
    upper and lower one stay with the numpy model, and say so."""
    scene = nacelle_scene(FOUR, "full")
    assert "complex step" in fused.declined(scene, WIND, {"ins_pitch": np.ones(3) * 1j})
    two = nacelle_scene(TWO, "full")
    assert "upper and a lower" in fused.declined(two, ("shear_exponent",), {})
    assert "yaw_misalignment" in fused.declined(make_scene(), ("yaw_misalignment",), {})


# x^a by the binomial series against numpy's exp(a log x): the series is within half an
# ulp of (1 + d)^a; Horner's roundings (the sum is dominated by its first term, 1), x0^a
# and the product add ~3 more, numpy's own result is within ~1: 8 ulp of the result
# (values near 1, where a log x is small: the special values below).
POWER_RTOL = 8 * 2.2e-16
EPS = np.finfo(float).eps


def _numpy_power(values, exponent):
    with np.errstate(all="ignore"):
        return np.exp(np.reshape(exponent, (-1, 1)) * np.log(values))


def _exact_power(values, exponent):
    """x^a as exp(a log x) in long double (x86-64's 80-bit format, eps 1.1e-19: to a
    thousandth of a double's ulp), rounded to double."""
    x = np.asarray(values, dtype=np.longdouble)
    return np.exp(np.reshape(exponent, (-1, 1)).astype(np.longdouble) * np.log(x)).astype(float)


def _power_tolerance(values, exponent):
    """The kernel's error budget relative to x^a [1], per value: 4 ulp (the series within
    half an ulp, Horner's roundings, x0^a and the product), plus the error y = a log x
    carries into both paths (libm's log within 1 ulp of log x, the product half an ulp of
    y: 1.5 eps |y| absolute in y, as much relative in e^y). The reference's own budget is
    added in its precision (negligible in 80 bits; as large as the kernel's where long
    double is double). Another CPU's libm or numpy's SIMD log and exp move numpy's
    double exp(a log x) by several ulp where |y| is large (8 ulp at |y| = 8.3 on an
    AVX-512 machine): the reference is the exact value, not numpy's."""
    y = np.abs(np.reshape(exponent, (-1, 1)) * np.log(values))
    return (EPS + np.finfo(np.longdouble).eps) * (4.0 + 1.5 * y)


def _assert_power_near(values, exponent):
    actual, expected = _power_near(values, exponent), _exact_power(values, exponent)
    excess = np.abs(actual - expected) / (_power_tolerance(values, exponent)
                                          * np.abs(expected))
    assert np.all(excess <= 1.0), f"{excess.max():.2f} x the budget"


def _power_near(values, exponent):
    from uq.physics import fusedkernels as kernels
    out = np.array(values, dtype=float)
    kernels.compiled(float)["power_near"](out, np.broadcast_to(
        np.asarray(exponent, dtype=float), (len(out),)).copy())
    return out


@pytest.mark.parametrize("exponent", [-1.0, -0.3, 0.0, 0.12, 0.5, 1.0, 1.5, -2.0])
@pytest.mark.parametrize("spread", [0.0, 1e-6, 1e-3, 0.3, 30.0])
def test_power_near_equals_numpy_log_and_exp(exponent, spread, rng):
    """Ratios close together (a block of one scene's trials) and far apart (a sweep's
    scenes, over several binary exponents), the series (|a| <= 1) and libm (|a| > 1):
    x^a within the kernel's error budget of its exact value."""
    values = rng.uniform(0.2, 3.0, 15) * (1 + spread * rng.uniform(0, 1, (2048, 15)))
    _assert_power_near(values, exponent)


def test_the_power_budget_is_not_loose():
    """Where |a log x| is small the budget is under 5 ulp: a result 8 ulp off fails."""
    values = np.full((1, 3), 1.1)
    exact = _exact_power(values, 0.12)
    budget = _power_tolerance(values, 0.12) * np.abs(exact)
    assert np.all(budget < 5 * EPS * exact)
    assert np.all(np.abs(exact * (1 + 8 * EPS) - exact) > budget)


def test_power_near_with_an_exponent_per_row(rng):
    """Runs of rows of one exponent (a batch of scenes, each its own shear) and rows
    that change it every row."""
    values = rng.uniform(0.5, 2.0, (300, 4))
    exponent = np.repeat([0.1, 0.2, -0.4, 0.1], 75)
    exponent[-20:] = rng.uniform(-1, 1, 20)
    _assert_power_near(values, exponent)


def test_power_near_depends_on_the_value_alone(rng):
    """A value's result does not depend on the rest of its block (each takes its
    reference from its own bits): the bits of a block equal those of its rows one by
    one, and of its rows in another order (a scene alone gives its bits in a batch)."""
    values = 1.3 + 1e-3 * rng.standard_normal((64, 5))
    whole = _power_near(values, 0.14)
    one_by_one = np.concatenate([_power_near(row[None], 0.14) for row in values])
    order = rng.permutation(64)
    np.testing.assert_array_equal(whole, one_by_one)
    np.testing.assert_array_equal(whole[order], _power_near(values[order], 0.14))


def test_power_near_special_values_as_numpy(rng):
    """NaN (out of domain), +-inf, 0, negative and subnormal ratios anywhere in the
    block, also first: the same NaN, infinities and zeros as numpy's log and exp."""
    for row in (0, 7):
        values = 1.2 + 1e-3 * rng.standard_normal((64, 7))
        values[row] = [np.nan, np.inf, -np.inf, 0.0, -1.0, 5e-320, -0.0]
        for exponent in (0.14, -0.5):
            np.testing.assert_allclose(_power_near(values, exponent),
                                       _numpy_power(values, exponent), rtol=POWER_RTOL,
                                       atol=0)     # (NaN where numpy's is NaN, inf, 0)


@pytest.mark.parametrize("exponent", [-1.0, -0.7, 0.12, 0.5, 1.0 - 1e-9])
@pytest.mark.parametrize("deviation", [1e-6, 1e-3, 0.05, 0.25])
def test_binomial_terms_are_the_fewest_within_half_an_ulp(exponent, deviation):
    """The coefficients are scipy's C(a, k) (C(-1, k) = (-1)^k, where scipy's gamma
    ratio has a pole); with K terms the remainder's bound |C(a, K)| d^K / (1 - d)^2 is
    within half an ulp and with K - 1 it is not."""
    from scipy.special import binom
    from uq.physics import fusedkernels as kernels

    def exact(k):
        return (-1.0) ** k if exponent == -1.0 else binom(exponent, k)
    coefficients = np.empty(64)
    terms = kernels.binomial_terms(exponent, deviation, coefficients)
    np.testing.assert_allclose(coefficients[:terms], exact(np.arange(terms)), rtol=1e-13)
    # ^ the recurrence's roundings, ~k ulps; scipy's beta-function route a few ulps more

    def bound(count):
        return abs(exact(count)) * deviation ** count / (1 - deviation) ** 2
    assert bound(terms) <= 2.0 ** -53 < bound(terms - 1)
    assert terms <= 30                      # 27 at d = 0.25, a = -1
