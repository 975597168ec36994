"""The measurement model against closed forms and limiting cases."""
import dataclasses

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from conftest import make_scene
from uq.physics.beams import beam_unit_vectors, least_squares_operator
from uq.physics.measurement import measurement_model, true_values
from uq.pipeline.scenario import BEAM_RANK_TOLERANCE

d = np.deg2rad


def reconstruct(scene, **errors):
    out = measurement_model(scene, **errors)
    return {q: np.real(v[0]) for q, v in out.items()}


azimuth_sets = st.lists(st.floats(0, 359), min_size=3, max_size=8, unique=True).filter(
    lambda a: np.linalg.matrix_rank(beam_unit_vectors(d(28), d(np.array(a)))) == 3)


@settings(max_examples=60, deadline=None)
@given(azimuth_sets, st.booleans(), st.floats(5, 60), st.floats(0, 359.9), st.floats(0.5, 25),
       st.sampled_from(["none", "yaw", "tilt2d", "full"]))
def test_no_motion_no_error_returns_true_wind(azimuths, vertical, cone, direction, speed, model):
    # geometries the scenario validator accepts (beams that determine the 3-D wind)
    singular = np.linalg.svd(beam_unit_vectors(d(cone), d(np.array(azimuths)), 0.0, vertical),
                             compute_uv=False)
    assume(singular[-1] >= BEAM_RANK_TOLERANCE * singular[0])
    scene = make_scene(**{"lidar.azimuths": azimuths, "lidar.vertical_beam": vertical,
                          "lidar.half_cone": cone, "wind.direction": direction,
                          "wind.speed": speed, "wind.vertical": 0.3, "correction": model})
    out, truth = reconstruct(scene), true_values(scene)
    # least squares loses ~cond(A) machine epsilons; nearly coplanar beams are ill-conditioned
    tolerance = 100 * np.finfo(float).eps * np.linalg.cond(scene.nominal_unit_vectors())
    np.testing.assert_allclose(out["wind_speed"], truth["wind_speed"], rtol=tolerance)
    angle_error = np.mod(out["wind_direction"] - truth["wind_direction"] + 180, 360) - 180
    assert abs(np.deg2rad(angle_error)) * speed < tolerance * (speed + 0.3)
    np.testing.assert_allclose(out["vertical_wind"], 0.3, atol=tolerance * (speed + 0.3))


@pytest.mark.parametrize("tilt", [2.0, 5.0, 10.0, 20.0])
def test_static_tilt_without_correction_tiana2017(tilt):
    """Tiana-Alsina et al. (2017): a tilt underestimates the wind along the tilt plane by
    cos(tilt) and leaves the wind along the tilt axis unchanged (level-assumed lidar)."""
    along = make_scene(**{"ship.pitch": tilt, "wind.direction": 180.0, "correction": "none"})
    across = make_scene(**{"ship.pitch": tilt, "wind.direction": 90.0, "correction": "none"})
    assert reconstruct(along)["wind_speed"][0] == pytest.approx(5.0 * np.cos(d(tilt)), rel=1e-12)
    assert reconstruct(across)["wind_speed"][0] == pytest.approx(5.0, rel=1e-12)
    rolled = make_scene(**{"ship.roll": tilt, "wind.direction": 270.0, "correction": "none"})
    assert reconstruct(rolled)["wind_speed"][0] == pytest.approx(5.0 * np.cos(d(tilt)), rel=1e-12)


@settings(max_examples=80, deadline=None)
@given(st.floats(0, 359.9), st.floats(-30, 30), st.floats(-30, 30), st.floats(0, 359.9),
       st.floats(0, 8), st.floats(0, 359.9), st.floats(-1, 1), st.floats(0, 0.3))
def test_full_correction_recovers_true_wind_under_any_static_attitude(
        heading, pitch, roll, cog, sog, direction, heave, shear):
    scene = make_scene(**{"ship.heading": heading, "ship.pitch": pitch, "ship.roll": roll,
                          "ship.cog": cog, "ship.sog": sog, "ship.heave": heave,
                          "wind.direction": direction, "wind.vertical": 0.2,
                          "correction": "full"})
    out, truth = reconstruct(scene), true_values(scene)
    np.testing.assert_allclose(out["wind_speed"], truth["wind_speed"], rtol=1e-10)
    np.testing.assert_allclose(out["vertical_wind"], 0.2, atol=1e-10)
    assert abs(np.mod(out["wind_direction"] - truth["wind_direction"] + 180, 360) - 180) < 1e-8


def test_yaw_correction_is_exact_without_tilt():
    scene = make_scene(**{"ship.heading": 123.0, "ship.sog": 4.0, "ship.cog": 117.0,
                          "wind.direction": 300.0, "correction": "yaw"})
    assert reconstruct(scene)["wind_speed"][0] == pytest.approx(5.0, rel=1e-12)


def test_tilt2d_is_biased_under_tilt_and_full_is_not():
    changes = {"ship.pitch": 10.0, "wind.direction": 180.0, "ship.sog": 2.0}
    tilt2d = reconstruct(make_scene(**changes, correction="tilt2d"))["wind_speed"][0]
    full = reconstruct(make_scene(**changes, correction="full"))["wind_speed"][0]
    assert full == pytest.approx(5.0, rel=1e-12)
    # tilt2d drops the lidar-frame vertical of the relative wind. Here the relative wind is
    # 5 - 2 = 3 m/s towards north (wind from the south, ship going north at 2 m/s); in the
    # lidar frame it is (3 cos p, 0, -3 sin p); rotating back only (3 cos p, 0, 0) gives a
    # north component 3 cos^2 p, plus the ship's 2 m/s.
    relative = 5.0 - 2.0                       # relative wind towards north [m s-1]
    expected = relative * np.cos(d(10)) ** 2 + 2.0
    assert tilt2d == pytest.approx(expected, rel=1e-12)


def test_beam_mode_with_equal_readings_equals_scan_mode():
    for model in ("none", "yaw", "tilt2d", "full"):
        scene = make_scene(**{"ship.heading": 40.0, "ship.pitch": 4.0, "ship.roll": -3.0,
                              "ship.sog": 3.0, "ship.cog": 50.0, "wind.direction": 10.0,
                              "correction": model})
        errors = {"ins_heading": 0.7, "ins_pitch": -0.3, "ins_roll": 0.2, "ins_sog": 0.1,
                  "ins_cog": 1.0}
        scan = reconstruct(scene, **{k: np.full(2, v) for k, v in errors.items()})
        beam = reconstruct(scene, **{k: np.full((2, 4), v) for k, v in errors.items()})
        for q in scan:
            np.testing.assert_allclose(beam[q], scan[q], rtol=1e-12, atol=1e-12)


def test_least_squares_operator_is_classical_dbs():
    beams = beam_unit_vectors(d(28), d(np.array([0.0, 90, 180, 270])))
    operator = least_squares_operator(beams)
    v = np.array([1.0, 2.0, -0.5, 0.3])
    assert (operator @ v)[0] == pytest.approx((v[0] - v[2]) / (2 * np.sin(d(28))))   # Eq. 14
    assert (operator @ v)[1] == pytest.approx((v[1] - v[3]) / (2 * np.sin(d(28))))   # Eq. 15
    assert (operator @ v)[2] == pytest.approx(v.sum() / (4 * np.cos(d(28))))
    with pytest.raises(ValueError):
        least_squares_operator(beams[:2])


def test_radial_velocity_sign_positive_away():
    # ship at rest, wind from the south blows north: the north beam sees positive v_r
    scene = make_scene(**{"wind.direction": 180.0})
    radial = true_values(scene)["radial_velocity"][:, 0]
    assert radial[0] == pytest.approx(5.0 * np.sin(d(28)))
    assert radial[2] == pytest.approx(-5.0 * np.sin(d(28)))


def test_shear_with_tilt_uses_true_beam_heights():
    scene = make_scene(**{"wind.shear": 0.2, "ship.pitch": 10.0, "lidar.height": 0.0,
                          "lidar.ranges": [100.0], "wind.direction": 90.0, "correction": "none"})
    radial = true_values(scene)["radial_velocity"][:, 0]
    slant = 100.0 / np.cos(d(28))
    assert radial[0] == pytest.approx(0.0, abs=1e-12)   # wind from east, north beam in the N-up plane
    east_height = slant * np.cos(d(28)) * np.cos(d(10))  # pitch tilts the east beam's up component
    assert radial[1] == pytest.approx(-5.0 * (east_height / 100.0) ** 0.2 * np.sin(d(28)),
                                      rel=1e-12)


@pytest.mark.parametrize("pitch, roll", [(0.0, 0.0), (10.0, 0.0), (0.0, -7.0), (6.0, 4.0)])
def test_gate_height_of_a_tilted_lidar(pitch, roll):
    """Four beams at 0/90/180/270 deg, half-cone theta, tilt by pitch p (bow up): the fore
    and aft beams point cos(theta -+ p) up and the side beams cos(theta) cos(p), so the
    mean gate height is H + r cos(p) (and with roll r_o too, H + r cos(p) cos(r_o),
    because the mean of the four beams is the cone axis times cos(theta)). Level: H + r."""
    scene = make_scene(**{"ship.pitch": pitch, "ship.roll": roll, "lidar.height": 3.0,
                          "lidar.ranges": [40.0, 100.0]})
    height = reconstruct(scene)["gate_height"]
    expected = 3.0 + np.array([40.0, 100.0]) * np.cos(d(pitch)) * np.cos(d(roll))
    np.testing.assert_allclose(height, expected, rtol=1e-12)
    np.testing.assert_allclose(true_values(scene)["gate_height"], 3.0 + np.array([40.0, 100.0]))


def test_half_cone_error_moves_the_gates():
    """The gate is placed at r / cos(theta) along the configured cone; a true cone
    theta + e puts it at r cos(theta + e) / cos(theta)."""
    scene = make_scene(**{"lidar.height": 0.0, "lidar.ranges": [100.0]})
    height = reconstruct(scene, lidar_half_cone=np.array([1.0]))["gate_height"]
    assert height[0] == pytest.approx(100.0 * np.cos(d(29)) / np.cos(d(28)), rel=1e-12)


@pytest.mark.parametrize("correction", ["none", "yaw", "full"])
def test_height_error_reads_the_wind_of_another_height(correction):
    """A level lidar that sits e lower than configured measures, at every gate, the power
    law at H + r - e: V ((H + r + e) / z_ref)^alpha (the reconstruction is exact
    otherwise), and its gate height says so."""
    scene = make_scene(**{"wind.shear": 0.14, "wind.reference_height": 80.0,
                          "lidar.height": 3.0, "lidar.ranges": [37.0, 77.0],
                          "correction": correction})
    out = reconstruct(scene, lidar_height=np.array([-2.0]))
    heights = 3.0 - 2.0 + np.array([37.0, 77.0])
    np.testing.assert_allclose(out["wind_speed"], 5.0 * (heights / 80.0) ** 0.14, rtol=1e-12)
    np.testing.assert_allclose(out["gate_height"], heights, rtol=1e-12)


def test_scene_draws_are_per_scene_and_equal_common_draws_when_equal():
    """scene_draws: errors shaped (n, *S, ...) give each scene its own draws; a scene's
    result equals that scene run alone with its draws, and replicating one set of draws
    over the scenes equals the common-random-numbers call."""
    speeds = np.array([4.0, 9.0, 14.0])
    scene = make_scene(**{"wind.shear": 0.1, "lidar.ranges": [60.0, 100.0]})
    batch = dataclasses.replace(scene, wind_speed=speeds)
    rng = np.random.default_rng(3)
    draws = {"ins_heading": rng.normal(0, 1, (5, 3, 1)), "ins_sog": rng.normal(0, .1, (5, 3, 1)),
             "lidar_half_cone": rng.normal(0, .5, (5, 3)), "lidar_height": rng.normal(0, 1, (5, 3)),
             "lidar_radial_velocity": rng.normal(0, .1, (5, 3, 4, 2))}
    together = measurement_model(batch, scene_draws=True, **draws)
    for i, speed in enumerate(speeds):
        alone = measurement_model(dataclasses.replace(scene, wind_speed=speed),
                                  **{k: v[:, i] for k, v in draws.items()})
        for q in ("wind_speed", "wind_direction", "gate_height"):
            np.testing.assert_allclose(together[q][:, i], alone[q], rtol=1e-13)
    common = {k: v[:, :1] for k, v in draws.items()}
    crn = measurement_model(batch, **{k: v[:, 0] for k, v in common.items()})
    replicated = measurement_model(batch, scene_draws=True, **{
        k: np.repeat(v, 3, axis=1) for k, v in common.items()})
    np.testing.assert_allclose(replicated["wind_speed"], crn["wind_speed"], rtol=1e-13)


@pytest.mark.parametrize("correction", ["yaw", "tilt2d", "full"])
def test_a_velocity_read_per_beam_is_corrected_point_wise(correction):
    """A correlation time on the velocity only (sog one value per beam, heading one per
    scan): each beam is freed of its own reading. Before the fix the scan formula took
    beam 0's reading for every beam, so beam 2's reading changed nothing."""
    scene = make_scene(**{"correction": correction, "ship.sog": 2.0, "wind.speed": 5.0})
    n = 3
    heading = np.full((n, 1), 0.1)
    base = measurement_model(scene, ("wind_speed",), compiled=False, ins_heading=heading,
                             ins_sog=np.zeros((n, 4)))["wind_speed"]
    sog = np.zeros((n, 4))
    sog[:, 2] = 0.2                                   # only beam 2 reads a faster ship
    moved = measurement_model(scene, ("wind_speed",), compiled=False, ins_heading=heading,
                              ins_sog=sog)["wind_speed"]
    assert np.all(np.abs(moved - base) > 0.05)
    # equal readings: the point-wise result is the scan formula's (least squares
    # commutes with the common rotation), to the rounding of the 3 x 3 solve
    same = measurement_model(scene, ("wind_speed",), compiled=False, ins_heading=heading,
                             ins_sog=np.full((n, 4), 0.2))["wind_speed"]
    scan = measurement_model(scene, ("wind_speed",), compiled=False, ins_heading=heading,
                             ins_sog=np.full((n, 1), 0.2))["wind_speed"]
    np.testing.assert_allclose(same, scan, rtol=0, atol=1e-13)


@pytest.mark.parametrize("compiled", [True, False], ids=["compiled", "numpy"])
def test_a_held_evaluation_of_a_static_scene_is_a_second_evaluation(compiled):
    """``held`` on a static scene (nothing to share): ``wind_speed_held`` is, bit for bit,
    the speed of a call with the held inputs replaced; the other outputs are the plain
    call's."""
    scene = make_scene()
    rng = np.random.default_rng(4)
    errors = {"ins_heading": rng.normal(0, 0.5, 200), "ins_sog": rng.normal(0, 0.1, 200)}
    held = {"ins_heading": 0.0}
    out = measurement_model(scene, ("wind_speed", "wind_direction"), compiled=compiled,
                            held=held, **errors)
    alone = measurement_model(scene, ("wind_speed",), compiled=compiled,
                              **{**errors, **held})
    plain = measurement_model(scene, ("wind_speed", "wind_direction"), compiled=compiled,
                              **errors)
    np.testing.assert_array_equal(out["wind_speed_held"], alone["wind_speed"])
    assert not np.array_equal(out["wind_speed_held"], out["wind_speed"])
    for q in ("wind_speed", "wind_direction"):
        np.testing.assert_array_equal(out[q], plain[q])
