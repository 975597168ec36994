"""The compiled time-resolved model (:mod:`uq.physics.fusedmotion`) against the numpy
model of :mod:`uq.physics.timeresolved`, its second implementation: the same trials
(inputs drawn from the scenario's own engine inputs) give the same outputs to 1e-12 m/s.

Why 1e-12: both compute the same products and sums of O(1-30) terms in float64 in a
different order (the compiled model turns phase vectors where numpy evaluates sin(w t +
psi) afresh, uses a Cholesky solve where numpy multiplies by A+, and SIMD polynomial sines
to 1 ulp); each step loses a few ulp of the 10-30 m s-1 values, 2.2e-16 x 30 x ~100
operations ~ 1e-12 m s-1 at most. Directions compare as angles times the speed (an
arc length [m s-1]), so that a direction is held to the same 1e-12 m s-1.
"""
import dataclasses

import numpy as np
import pytest

from uq.engine.inputs import input_set
from uq.physics import fusedmotion
from uq.physics.measurement import measurement_model
from uq.pipeline.modelsetup import error_inputs, scene_from_settings
from uq.pipeline.scenario import load_scenario

from conftest import with_changes as merged

OUTPUTS = ("wind_speed", "wind_direction", "vertical_wind")
VAD = [i * 7.2 for i in range(50)]
TOLERANCE = 1e-12          # [m s-1] the module docstring's rounding bound

BASE = {"wind": {"speed": 12.0, "direction": 210.0, "vertical": 0.1, "shear": 0.14},
        "ship": {"heading": 35.0, "pitch": 1.0, "roll": -2.0, "sog": 1.2, "cog": 50.0},
        "lidar": {"ranges": [40.0, 100.0, 200.0], "scan": {"beam_duration": 1.0},
                  "lever_arm": [1.5, -0.8, 4.0],
                  "errors": {"radial_velocity": {"dist": "normal", "u": 0.1}}},
        "motion": {"roll": {"amplitude": 6.0, "period": 7.0},
                   "pitch": {"amplitude": 4.0, "period": 5.5, "phase": 30.0},
                   "heave": {"amplitude": 1.0, "period": 7.0}},
        "ins": {"heading": {"dist": "normal", "u": 0.5}, "pitch": {"dist": "normal", "u": 0.1},
                "roll": {"dist": "normal", "u": 0.1}, "sog": {"dist": "normal", "u": 0.05},
                "cog": {"dist": "normal", "u": 1.0}},
        "correction": "pointwise"}


def both(changes, n=300, seed=7, scene_draws=False, batch=None):
    """(compiled, numpy) outputs of `n` trials of the scenario BASE + `changes`, the same
    inputs for both, drawn from the scenario's engine inputs; `batch` (field -> array)
    makes a batch of scenes of the scene's fields."""
    settings = load_scenario({"name": "t", **merged(BASE, changes)}).settings
    scene = dataclasses.replace(scene_from_settings(settings), **(batch or {}))
    inputs = error_inputs(settings, scene.n_beams, len(scene.ranges))
    constant = {k: v for k, v in inputs.items() if isinstance(v, float)}
    random = input_set({k: v for k, v in inputs.items() if not isinstance(v, float)})
    rng = np.random.default_rng(seed)
    axes = scene.shape if scene_draws else ()
    errors = random.values(rng.standard_normal((n * int(np.prod(axes)), random.dimension)))
    if scene_draws:
        errors = {k: v.reshape((n,) + axes + v.shape[1:]) for k, v in errors.items()}
    errors.update(constant)
    assert fusedmotion.applicable(scene, OUTPUTS, errors, scene_draws)
    fast = measurement_model(scene, OUTPUTS, scene_draws, **errors)
    slow = measurement_model(scene, OUTPUTS, scene_draws, compiled=False, **errors)
    return fast, slow


def assert_same(fast, slow):
    speed = slow["wind_speed"]
    assert np.all(np.isfinite(speed))
    np.testing.assert_allclose(fast["wind_speed"], speed, rtol=0, atol=TOLERANCE)
    np.testing.assert_allclose(fast["vertical_wind"], slow["vertical_wind"], rtol=0,
                               atol=TOLERANCE)
    turn = (fast["wind_direction"] - slow["wind_direction"] + 180.0) % 360.0 - 180.0
    assert np.max(np.abs(np.deg2rad(turn)) * speed) < TOLERANCE


CASES = {
    "pointwise, continuous INS": {},
    "pointwise, 10 Hz linear INS": {"ins.rate": 10.0, "ins.interpolation": "linear"},
    "pointwise, 10 Hz nearest INS": {"ins.rate": 10.0, "ins.interpolation": "nearest"},
    "pointwise, clock offset": {"ins.clock_offset": {"dist": "normal", "u": 0.02}},
    "pointwise, Gauss-Markov INS": {"ins.heading.correlation_time": 3.0,
                                    "ins.sog.correlation_time": 2.0},
    "pointwise, beam INS": {"ins.correlation": "beam"},
    "pointwise, dwell average": {"lidar.scan.dwell_average": True},
    "pointwise, dwell average over panels": {"lidar.scan.dwell_average": True,
                                             "lidar.scan.beam_duration": 20.0},
    "pointwise, end stamps": {"lidar.scan.timestamp": "end"},
    "full (one reading per scan)": {"correction": "full"},
    "yaw": {"correction": "yaw"},
    "tilt2d": {"correction": "tilt2d"},
    "none": {"correction": "none"},
    "no shear": {"wind.shear": 0.0},
    "no lever arm": {"lidar.lever_arm": None},
    "all six degrees of freedom": {
        "motion.yaw": {"amplitude": 2.0, "period": 9.0},
        "motion.surge": {"amplitude": 0.5, "period": 6.0, "phase": "random"},
        "motion.sway": {"amplitude": 0.7, "period": 8.0}},
    "geometry errors": {"lidar.errors.half_cone": {"dist": "normal", "u": 0.1},
                        "lidar.errors.misalignment": {"dist": "normal", "u": 0.5},
                        "lidar.errors.height": {"dist": "normal", "u": 0.2}},
    "VAD of 50 lines of sight": {"lidar.azimuths": VAD, "lidar.vertical_beam": False,
                                 "lidar.scan.beam_duration": 0.02},
    "JONSWAP sea": {"motion": {"spectrum": {"kind": "jonswap", "hs": 2.0, "tp": 8.0,
                                            "gamma": 3.3, "components": 12},
                               "response": {"roll": {"factor": 2.0, "lag": 90},
                                            "pitch": {"factor": 1.5},
                                            "heave": {"factor": 1.0}}},
                    "ins.rate": 10.0, "ins.interpolation": "linear"},
}


@pytest.mark.parametrize("changes", CASES.values(), ids=CASES.keys())
def test_compiled_equals_numpy(changes):
    assert_same(*both(changes))


#: Which inputs a held evaluation replaces: the reconstruction's alone (the compiled
#: model shares the kinematics), or the truth's too (a second evaluation).
HELD_CASES = {
    "pointwise, INS and noise held": ({}, ("ins_heading", "ins_pitch", "ins_roll", "ins_sog",
                                           "ins_cog", "lidar_radial_velocity")),
    "linear INS, clock offset held": ({"ins.rate": 10.0, "ins.interpolation": "linear",
                                       "ins.clock_offset": {"dist": "normal", "u": 0.02}},
                                      ("ins_clock_offset", "ins_heading")),
    "full, noise held": ({"correction": "full"}, ("lidar_radial_velocity",)),
    "geometry held": (CASES["geometry errors"], ("lidar_half_cone", "lidar_height",
                                                 "lidar_radial_velocity")),
}


@pytest.mark.parametrize("changes, names", HELD_CASES.values(), ids=HELD_CASES.keys())
def test_the_held_speed_is_a_second_evaluation(changes, names):
    """``held``: the wind speed of the same trials with some inputs at fixed values
    (``wind_speed_held``) is, bit for bit, the compiled model's speed evaluated with
    those inputs replaced (on the shared kinematics, or by a second evaluation where a
    held input moves the truth), and the numpy model's to the rounding bound; the other
    outputs are those of the call without `held`."""
    settings = load_scenario({"name": "t", **merged(BASE, changes)}).settings
    scene = scene_from_settings(settings)
    inputs = error_inputs(settings, scene.n_beams, len(scene.ranges))
    random = input_set({k: v for k, v in inputs.items() if not isinstance(v, float)})
    errors = random.values(np.random.default_rng(5).standard_normal((300, random.dimension)))
    held = {name: 0.01 * (k + 1) for k, name in enumerate(names)}   # not the means: any value
    shared = fusedmotion.shares_kinematics(held, errors)
    assert shared == ("lidar_half_cone" not in names)
    fast = measurement_model(scene, OUTPUTS, held=held, **errors)
    _held_speed_agrees(scene, held, errors, fast)


def _held_speed_agrees(scene, held, errors, fast):
    """`fast` (a run with `held`) has the held speed of a separate evaluation with the held
    values, bit for bit, different from its own speed; its other outputs are those of a
    run without `held`, bit for bit; and its held speed is the numpy model's to
    TOLERANCE."""
    alone = measurement_model(scene, ("wind_speed",), **{**errors, **held})["wind_speed"]
    np.testing.assert_array_equal(fast["wind_speed_held"], alone)
    assert not np.allclose(fast["wind_speed_held"], fast["wind_speed"], rtol=0, atol=1e-6)
    plain = measurement_model(scene, OUTPUTS, **errors)
    for q in OUTPUTS:
        np.testing.assert_array_equal(fast[q], plain[q])
    slow = measurement_model(scene, OUTPUTS, compiled=False, held=held, **errors)
    np.testing.assert_allclose(fast["wind_speed_held"], slow["wind_speed_held"], rtol=0,
                               atol=TOLERANCE)


#: Scans whose held speed (radial noise alone held) shares the reading: point-wise at the
#: truth's nodes, point-wise between the samples of a linear INS (the reading's own
#: rows), at a dwell average, and one reading per scan through A^+ (none, full).
SHARED_CASES = {"pointwise, continuous INS": {}, "pointwise, no INS errors": {"ins": None},
                "pointwise, 10 Hz linear INS": CASES["pointwise, 10 Hz linear INS"],
                "pointwise, dwell average": CASES["pointwise, dwell average"],
                "none": CASES["none"], "full": CASES["full (one reading per scan)"]}


@pytest.mark.parametrize("per_trial", [False, True], ids=["held at a value", "held noise drawn"])
@pytest.mark.parametrize("changes", SHARED_CASES.values(), ids=SHARED_CASES.keys())
def test_held_noise_alone_shares_the_reading(changes, per_trial):
    """Where `held` replaces the radial noise alone (and holds an absent INS error at its
    0), the held speed is a second right-hand side on the reading's least-squares factor
    in the same kernel call (the path counted "shared reading"), and equals, bit for bit,
    a separate evaluation with the noise replaced: the same operations in the same order
    on the same numbers (the factor of the same B^T B, the same dwell mean plus the held
    noise); the numpy model's held speed to the rounding bound TOLERANCE."""
    settings = load_scenario({"name": "t", **merged(BASE, changes)}).settings
    scene = scene_from_settings(settings)
    inputs = error_inputs(settings, scene.n_beams, len(scene.ranges))
    random = input_set({k: v for k, v in inputs.items() if not isinstance(v, float)})
    rng = np.random.default_rng(8)
    errors = random.values(rng.standard_normal((300, random.dimension)))
    noise = errors["lidar_radial_velocity"]
    held = {"lidar_radial_velocity": rng.normal(0.0, 0.3, noise.shape) if per_trial
            else 0.02, "ins_heave": 0.0}                    # (ins_heave is not drawn: 0)
    assert "ins_heave" not in errors and fusedmotion.shares_reading(held, errors)
    before = fusedmotion.HELD_PATHS.copy()
    fast = measurement_model(scene, OUTPUTS, held=held, **errors)
    taken = fusedmotion.HELD_PATHS - before
    assert taken == {"shared reading": 1}
    _held_speed_agrees(scene, held, errors, fast)


@pytest.mark.parametrize("azimuths", [[0, 90, 180, 270], [90, 270]], ids=["4 beams", "2 beams"])
@pytest.mark.parametrize("changes", SHARED_CASES.values(), ids=SHARED_CASES.keys())
def test_a_nacelle_lidar_s_held_noise_shares_the_reading(changes, azimuths):
    """A tilted mount's held noise shares the reading too (issue 25's speed line: the
    run's motion-only speed is no second reconstruction): its level pair's (or 2 beams')
    held corrected velocities are kept beside its own and solved with the held side's w,
    so its held speed is bit for bit a separate evaluation with the noise replaced, the
    other outputs (the shear exponent's kept rows among them) bit for bit a run without
    `held`, and the numpy model's held speed to TOLERANCE."""
    settings = load_scenario({"name": "t", **merged(BASE, {
        **NACELLE, "lidar.azimuths": azimuths, **changes})}).settings
    scene = scene_from_settings(settings)
    inputs = error_inputs(settings, scene.n_beams, len(scene.ranges))
    random = input_set({k: v for k, v in inputs.items() if not isinstance(v, float)})
    rng = np.random.default_rng(9)
    errors = random.values(rng.standard_normal((300, random.dimension)))
    held = {"lidar_radial_velocity": rng.normal(0.0, 0.3, errors["lidar_radial_velocity"].shape)}
    outputs = NACELLE_OUTPUTS if 0 in azimuths else NACELLE_OUTPUTS[:-1]
    before = fusedmotion.HELD_PATHS.copy()
    fast = measurement_model(scene, outputs, held=held, **errors)
    assert fusedmotion.HELD_PATHS - before == {"shared reading": 1}
    _held_speed_agrees(scene, held, errors, fast)
    plain = measurement_model(scene, outputs, **errors)
    for q in outputs:                       # (the shear exponent's too)
        np.testing.assert_array_equal(fast[q], plain[q])


def test_a_held_reading_error_is_a_second_reconstruction():
    """An INS error held at a value other than the run's (here an absent one held away from
    0) changes the reading: no shared factor, a second reconstruction."""
    scene, = _case_scene()
    errors = _case_errors()
    held = {"lidar_radial_velocity": 0.0, "ins_heave": 0.05}
    assert fusedmotion.shares_kinematics(held, errors)
    assert not fusedmotion.shares_reading(held, errors)
    before = fusedmotion.HELD_PATHS.copy()
    fast = measurement_model(scene, ("wind_speed",), held=held, **errors)
    assert fusedmotion.HELD_PATHS - before == {"second reconstruction": 1}
    alone = measurement_model(scene, ("wind_speed",), **{**errors, **held})["wind_speed"]
    np.testing.assert_array_equal(fast["wind_speed_held"], alone)


def test_nothing_held_is_the_speed_itself():
    """``held={}`` replaces nothing: the second reconstruction is the first, bit for bit."""
    fast = measurement_model(*_case_scene(), ("wind_speed",), held={}, **_case_errors())
    np.testing.assert_array_equal(fast["wind_speed_held"], fast["wind_speed"])


def _case_scene():
    settings = load_scenario({"name": "t", **BASE}).settings
    return (scene_from_settings(settings),)


def _case_errors():
    settings = load_scenario({"name": "t", **BASE}).settings
    scene = scene_from_settings(settings)
    random = input_set(error_inputs(settings, scene.n_beams, len(scene.ranges)))
    return random.values(np.random.default_rng(6).standard_normal((200, random.dimension)))


_DIRECTION, _ROLL = np.meshgrid([0.0, 120.0, 250.0], [-5.0, 0.0, 3.0], indexing="ij")
BATCH = {"wind_direction": np.deg2rad(_DIRECTION), "roll": np.deg2rad(_ROLL)}  # 3 x 3 [rad]


@pytest.mark.parametrize("scene_draws", [False, True], ids=["common draws", "scene draws"])
def test_a_batch_of_scenes(scene_draws):
    """A batch (swept wind direction x static roll): with common draws, and with each
    scene's own draws (``scene_draws``)."""
    assert_same(*both({}, n=64, scene_draws=scene_draws, batch=BATCH))


def test_a_complex_step_takes_the_numpy_model():
    """The GUM's complex steps are not compiled: applicable says no (the numpy model
    alone evaluates them)."""
    settings = load_scenario({"name": "t", **BASE}).settings
    scene = scene_from_settings(settings)
    assert not fusedmotion.applicable(scene, OUTPUTS, {"ins_sog": np.array([1e-20j])})
    assert not fusedmotion.applicable(scene, OUTPUTS + ("radial_velocity",), {})


def test_a_measured_record(tmp_path):
    """A measured record (motion.series): its window start is the input
    ``motion_window``, beside random phases of a harmonic."""
    times = np.arange(0.0, 120.0, 0.1)
    rng = np.random.default_rng(1)
    with open(tmp_path / "rec.csv", "w") as file:
        file.write("t,r,h\n")
        for t, noise in zip(times, rng.normal(0.0, 0.3, len(times))):
            file.write(f"{t},{3 * np.sin(2 * np.pi * t / 6) + noise},{np.cos(t / 3)}\n")
    assert_same(*both({"motion": {"series": {"file": str(tmp_path / "rec.csv"), "time": "t",
                                             "columns": {"roll": "r", "heave": "h"},
                                             "components": 20},
                                  "pitch": {"amplitude": 2.0, "period": 5.0}}}))


# ---- a tilted (nacelle) mount: lidar.mount.tilt > 0 (uq.physics.nacelle)

#: The nacelle lidar of nacelle_floating: boresight along the bow at 150 m, half-cone 15
#: deg, 0.25 s per line of sight, the INS 150 m below (lever arm), preview 50-300 m.
NACELLE = {"lidar.mount": {"tilt": 90.0}, "lidar.half_cone": 15.0,
           "lidar.vertical_beam": False, "lidar.height": 150.0,
           "wind.reference_height": 150.0, "lidar.lever_arm": [0.0, 0.0, 150.0],
           "lidar.scan.beam_duration": 0.25, "lidar.ranges": [50.0, 100.0, 300.0],
           "motion.surge": {"amplitude": 1.0, "period": 8.0, "phase": "random"}}
NACELLE_OUTPUTS = OUTPUTS + ("yaw_misalignment", "shear_exponent")
#: The cases of CASES that a nacelle lidar meets too (a VAD is not one), each with 4
#: beams (up, starboard, down, port) and with 2 (starboard, port; tilt2d, a 3-D
#: correction, is refused on two beams).
NACELLE_CASES = {f"{name}, {len(azimuths)} beams": (changes, azimuths)
                 for name, changes in CASES.items() if "VAD" not in name
                 for azimuths in ([0, 90, 180, 270], [90, 270])
                 if not (len(azimuths) == 2 and changes.get("correction") == "tilt2d")}


def both_nacelle(changes, azimuths, n=200, outputs=None):
    """(compiled, numpy) outputs of the nacelle lidar: every output its layout has (or
    `outputs`)."""
    settings = load_scenario({"name": "t", **merged(BASE, {
        **NACELLE, "lidar.azimuths": azimuths, **changes})}).settings
    scene = scene_from_settings(settings)
    inputs = error_inputs(settings, scene.n_beams, len(scene.ranges))
    constant = {k: v for k, v in inputs.items() if isinstance(v, float)}
    random = input_set({k: v for k, v in inputs.items() if not isinstance(v, float)})
    errors = random.values(np.random.default_rng(3).standard_normal((n, random.dimension)))
    errors.update(constant)
    outputs = outputs or (NACELLE_OUTPUTS if 0 in azimuths else NACELLE_OUTPUTS[:-1])
    assert fusedmotion.declined(scene, outputs, errors) == ""
    return (measurement_model(scene, outputs, **errors),
            measurement_model(scene, outputs, compiled=False, **errors))


@pytest.mark.parametrize("changes, azimuths", NACELLE_CASES.values(), ids=NACELLE_CASES.keys())
def test_a_nacelle_lidar_compiled_equals_numpy(changes, azimuths):
    """The compiled model takes a tilted mount: the clock-position beams (and their
    geometry errors), the 2-beam horizontal least squares (w = 0), the 4-beam hub-height
    wind of the level pair after the 3-D solve, the yaw misalignment, and the shear
    exponent at the believed heights (point-wise: lifted by the lever arm at the attitude
    read). Yaw misalignment as the direction (an arc length at the speed); the shear
    exponent [1] to 1e-12: ln ratios of ~0.3 from speeds and heights that agree to
    ~1e-13 relative."""
    fast, slow = both_nacelle(changes, azimuths)
    assert_same(fast, slow)
    turn = (fast["yaw_misalignment"] - slow["yaw_misalignment"] + 180.0) % 360.0 - 180.0
    assert np.max(np.abs(np.deg2rad(turn)) * slow["wind_speed"]) < TOLERANCE
    if "shear_exponent" in slow:
        assert np.array_equal(np.isnan(fast["shear_exponent"]), np.isnan(slow["shear_exponent"]))
        np.testing.assert_allclose(fast["shear_exponent"], slow["shear_exponent"], rtol=0,
                                   atol=TOLERANCE, equal_nan=True)


@pytest.mark.parametrize("case", ["pointwise, continuous INS", "pointwise, clock offset",
                                  "full (one reading per scan)", "yaw", "tilt2d", "none"])
def test_a_four_beam_nacelle_lidar_without_the_shear_exponent_equals_numpy(case):
    """Without the shear exponent a tilted mount keeps no believed lift (the level pair's
    wind alone, its speed in the same pass: fusedmotionkernels.mounted_wind); its
    outputs equal the numpy model's to TOLERANCE, as with every output."""
    fast, slow = both_nacelle(CASES[case], [0, 90, 180, 270],
                              outputs=("wind_speed", "wind_direction", "vertical_wind",
                                       "yaw_misalignment"))
    assert "shear_exponent" not in fast
    assert_same(fast, slow)
    assert np.isfinite(fast["wind_speed"]).all()                   # the check can fail


def test_a_nacelle_lidar_declines_what_it_does_not_compute():
    """tilt2d on two beams (numpy refuses it too) and a shear exponent without upper and
    lower beams stay with the numpy model, and say why."""
    settings = load_scenario({"name": "t", **merged(BASE, {
        **NACELLE, "lidar.azimuths": [90, 270]})}).settings
    scene = scene_from_settings(settings)
    assert "upper and a lower" in fusedmotion.declined(scene, NACELLE_OUTPUTS, {})
    two = dataclasses.replace(scene, correction="tilt2d")
    assert "tilt2d" in fusedmotion.declined(two, OUTPUTS, {})
    assert fusedmotion.declined(scene, NACELLE_OUTPUTS[:-1], {}) == ""
