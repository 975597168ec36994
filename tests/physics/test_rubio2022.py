"""Rubio & Gottschall (2022): every implemented equation against an independent derivation.

Chain of evidence: Eqs. 6-7 equal the physical model's radial velocities (independent
code, uq.physics.measurement); Eq. 13/16 equals the physical model's correction (uq.physics.correction);
every partial derivative (Eqs. 9-11, A.1-A.20, corrected) equals the complex-step
derivative of those equations, to machine precision.
"""
import numpy as np
import pytest

from conftest import make_scene
from uq.physics import modelinputs
from uq.physics.correction import reconstruct_wind
from uq.physics.beams import least_squares_operator
from uq.physics.measurement import true_values
from uq.physics.rotation import rubio2022_angles_from_attitude
from uq.physics.rubio2022 import (RUBIO2022_AZIMUTHS, rubio2022_domain,
                          rubio2022_radial_velocity_case_i, rubio2022_radial_velocity_case_ii,
                          rubio2022_radial_velocity_uncertainty_case_i,
                          rubio2022_radial_velocity_uncertainty_case_ii,
                          rubio2022_reconstruction, rubio2022_wind_sensitivities_case_i,
                          rubio2022_wind_sensitivities_case_ii)

d = np.deg2rad
H = 1e-30            # complex step: exact derivative, no cancellation
# Derivatives agree to a few ulps of the terms they sum; 1e-12 relative is ~5000 ulps.
RTOL = 1e-12
POINTS = [dict(speed=5.0, direction=d(30), sog=2.0, cog=d(20), yaw=d(50), cone=d(28)),
          dict(speed=11.0, direction=d(250), sog=6.0, cog=d(300), yaw=d(10), cone=d(15)),
          dict(speed=3.0, direction=d(359), sog=0.5, cog=d(181), yaw=d(200), cone=d(60))]
TILTS = [(d(7), d(-4)), (d(-10), d(10)), (d(3), d(0))]


def derivative(function, x):
    return np.imag(function(x + 1j * H)) / H


def radial_i(p, **override):
    q = {**p, **override}
    return rubio2022_radial_velocity_case_i(q["speed"], q["direction"], q["sog"], q["cog"],
                                            q["yaw"], q["cone"], RUBIO2022_AZIMUTHS)


@pytest.mark.parametrize("p", POINTS)
def test_eq6_equals_physical_model(p):
    # physical model, ship at rest in the wind's frame: level lidar, yaw = heading
    scene = make_scene(**{"wind.speed": p["speed"], "wind.direction": np.rad2deg(p["direction"]),
                          "ship.sog": p["sog"], "ship.cog": np.rad2deg(p["cog"]),
                          "ship.heading": np.rad2deg(p["yaw"]), "lidar.half_cone": np.rad2deg(p["cone"]),
                          "wind.reference_height": 100.0, "lidar.height": 0.0,
                          "lidar.ranges": [100.0], "correction": "yaw"})
    from uq.physics.measurement import _measure
    measured, _, _ = _measure(scene, {n: np.zeros(1) if not n.startswith("ins_") else np.zeros((1, 1))
                                   for n in modelinputs.names(modelinputs.STATIC)}, 1)
    np.testing.assert_allclose(measured[0, :, 0], radial_i(p), rtol=1e-13, atol=1e-13)


@pytest.mark.parametrize("p", POINTS)
def test_eqs_9_to_11_are_derivatives_of_eq6(p):
    args = (p["speed"], p["direction"], p["sog"], p["cog"], p["yaw"], p["cone"], RUBIO2022_AZIMUTHS)
    for name, key in (("u_yaw", "yaw"), ("u_sog", "sog"), ("u_cog", "cog")):
        u = {"u_yaw": 0.0, "u_sog": 0.0, "u_cog": 0.0, name: 1.0}
        printed = rubio2022_radial_velocity_uncertainty_case_i(*args, **u)
        exact = np.abs(derivative(lambda x: radial_i(p, **{key: x}), p[key]))
        np.testing.assert_allclose(printed, exact, rtol=RTOL, atol=1e-14)


def radial_ii(p, tilt_delta, tilt_beta, **override):
    q = {**p, "delta": tilt_delta, "beta": tilt_beta, **override}
    return rubio2022_radial_velocity_case_ii(q["speed"], q["direction"], q["sog"], q["cog"],
                                             q["delta"], q["beta"], q["cone"], RUBIO2022_AZIMUTHS)


@pytest.mark.parametrize("p", POINTS)
@pytest.mark.parametrize("tilt", TILTS)
def test_eq7_equals_physical_model(p, tilt):
    from uq.physics.rotation import attitude_from_rubio2022_angles
    heading, pitch, roll = attitude_from_rubio2022_angles(0.0, *tilt)
    scene = make_scene(**{"wind.speed": p["speed"], "wind.direction": np.rad2deg(p["direction"]),
                          "ship.sog": p["sog"], "ship.cog": np.rad2deg(p["cog"]),
                          "ship.heading": np.rad2deg(heading), "ship.pitch": np.rad2deg(pitch), "ship.roll": np.rad2deg(roll),
                          "lidar.half_cone": np.rad2deg(p["cone"]), "correction": "tilt2d"})
    from uq.physics.measurement import _measure
    measured, _, _ = _measure(scene, {n: np.zeros(1) if not n.startswith("ins_") else np.zeros((1, 1))
                                   for n in modelinputs.names(modelinputs.STATIC)}, 1)
    np.testing.assert_allclose(measured[0, :, 0], radial_ii(p, *tilt), rtol=1e-12, atol=1e-13)


@pytest.mark.parametrize("p", POINTS)
@pytest.mark.parametrize("tilt", TILTS)
def test_a1_to_a4_are_derivatives_of_eq7(p, tilt):
    delta, beta = tilt
    args = (p["speed"], p["direction"], p["sog"], p["cog"], delta, beta, p["cone"], RUBIO2022_AZIMUTHS)
    for name, key in (("u_delta", "delta"), ("u_beta", "beta"), ("u_sog", "sog"), ("u_cog", "cog")):
        u = {"u_delta": 0.0, "u_beta": 0.0, "u_sog": 0.0, "u_cog": 0.0, name: 1.0}
        printed = rubio2022_radial_velocity_uncertainty_case_ii(*args, **u)
        exact = np.abs(derivative(lambda x: radial_ii(p, delta, beta, **{key: x}),
                                  {"delta": delta, "beta": beta}.get(key, p.get(key))))
        np.testing.assert_allclose(printed, exact, rtol=RTOL, atol=1e-14)


def test_printed_a3_sign_is_a_misprint():
    # A.3 as printed: -sin(cog)[E] + cos(cog)[N]. (For the untilted N, E, S, W beams its
    # magnitude happens to equal Eq. 10's, so the misprint shows only under tilt.)
    p, (delta, beta) = POINTS[0], TILTS[0]
    from uq.physics.rubio2022 import _tilted_beam
    north, east = _tilted_beam(p["cone"], RUBIO2022_AZIMUTHS, delta, beta)
    printed = -np.sin(p["cog"]) * east + np.cos(p["cog"]) * north
    exact = derivative(lambda x: radial_ii(p, delta, beta, sog=x), p["sog"])
    assert not np.allclose(np.abs(printed), np.abs(exact), rtol=1e-3)


@pytest.mark.parametrize("p", POINTS)
def test_eq16_equals_physical_yaw_correction(p):
    radial = radial_i(p)
    north, east = rubio2022_reconstruction(radial, p["sog"], p["cog"], p["cone"], yaw=p["yaw"])
    scene = make_scene(**{"lidar.half_cone": np.rad2deg(p["cone"])})
    units = scene.nominal_unit_vectors()
    nav = {"heading": np.array([[p["yaw"]]]), "pitch": np.zeros((1, 1)), "roll": np.zeros((1, 1)),
           "sog": np.array([[p["sog"]]]), "cog": np.array([[p["cog"]]]), "heave": np.zeros((1, 1))}
    wind = reconstruct_wind(radial[None, :, None], "yaw", units, least_squares_operator(units), nav)
    np.testing.assert_allclose([north, east], wind[0, :2, 0], rtol=1e-13, atol=1e-13)
    # at the nominal point the correction is exact (Eqs. 4-5)
    np.testing.assert_allclose([north, east], [-p["speed"] * np.cos(p["direction"]),
                                               -p["speed"] * np.sin(p["direction"])], atol=1e-12)


@pytest.mark.parametrize("tilt", TILTS)
def test_case_ii_reconstruction_equals_physical_tilt2d(tilt):
    from uq.physics.rotation import attitude_from_rubio2022_angles
    p = POINTS[0]
    heading, pitch, roll = attitude_from_rubio2022_angles(0.0, *tilt)
    radial = radial_ii(p, *tilt)
    north, east = rubio2022_reconstruction(radial, p["sog"], p["cog"], p["cone"],
                                           delta=tilt[0], beta=tilt[1])
    scene = make_scene(**{"lidar.half_cone": np.rad2deg(p["cone"])})
    units = scene.nominal_unit_vectors()
    nav = {"heading": np.array([[heading]]), "pitch": np.array([[pitch]]), "roll": np.array([[roll]]),
           "sog": np.array([[p["sog"]]]), "cog": np.array([[p["cog"]]]), "heave": np.zeros((1, 1))}
    wind = reconstruct_wind(radial[None, :, None], "tilt2d", units, least_squares_operator(units), nav)
    np.testing.assert_allclose([north, east], wind[0, :2, 0], rtol=1e-12, atol=1e-12)


def wind_derivatives(radial, function):
    """Complex-step d(speed)/dv_i and d(direction)/dv_i of a reconstruction."""
    speed, direction = [], []
    for i in range(4):
        v = radial.astype(complex)
        v[i] += 1j * H
        north, east = function(v)
        speed.append(np.imag(np.sqrt(north**2 + east**2)) / H)
        # d atan2(-e, -n) = (n de - e dn) / (n^2 + e^2)
        n, e = north.real, east.real
        direction.append((n * np.imag(east) - e * np.imag(north)) / H / (n**2 + e**2))
    return np.array(speed), np.array(direction)


@pytest.mark.parametrize("p", POINTS)
def test_a5_to_a8_and_a13_to_a16_corrected_are_derivatives(p):
    radial = radial_i(p)
    exact = wind_derivatives(radial, lambda v: rubio2022_reconstruction(
        v, p["sog"], p["cog"], p["cone"], yaw=p["yaw"]))
    ours = rubio2022_wind_sensitivities_case_i(radial, p["speed"], p["direction"], p["sog"],
                                               p["cog"], p["yaw"], p["cone"])
    np.testing.assert_allclose(ours[0], exact[0], rtol=1e-11, atol=1e-14)
    np.testing.assert_allclose(ours[1], exact[1], rtol=1e-11, atol=1e-14)
    # the printed A.6 (cos instead of sin) and A.15 (Theta + gamma) are not derivatives
    s = np.sin(p["cone"])
    printed_a6 = (radial[1] - radial[3] + 2 * s * np.cos(p["cog"] - p["yaw"]) * p["sog"]) / (
        4 * p["speed"] * s**2)
    printed_a15 = np.sin(p["direction"] + p["yaw"]) / (2 * p["speed"] * s)
    assert not np.isclose(printed_a6, exact[0][1], rtol=1e-3)
    assert not np.isclose(printed_a15, exact[1][2], rtol=1e-3)


@pytest.mark.parametrize("p", POINTS)
@pytest.mark.parametrize("tilt", TILTS)
def test_a9_to_a12_and_a17_to_a20_corrected_are_derivatives(p, tilt):
    delta, beta = tilt
    radial = radial_ii(p, delta, beta)
    function = lambda v: rubio2022_reconstruction(v, p["sog"], p["cog"], p["cone"],  # noqa: E731
                                                  delta=delta, beta=beta)
    north, east = function(radial)
    speed, direction = np.hypot(north, east), np.arctan2(-east, -north)
    exact = wind_derivatives(radial, function)
    ours = rubio2022_wind_sensitivities_case_ii(radial, speed, direction, p["sog"], p["cog"],
                                                delta, beta, p["cone"])
    np.testing.assert_allclose(ours[0], exact[0], rtol=1e-11, atol=1e-14)
    np.testing.assert_allclose(ours[1], exact[1], rtol=1e-11, atol=1e-14)


def test_domain():
    assert rubio2022_domain(make_scene(correction="yaw")) == "i"
    assert rubio2022_domain(make_scene(correction="tilt2d", **{"ship.pitch": 5.0})) == "ii"
    assert rubio2022_domain(make_scene(correction="yaw", **{"ship.pitch": 5.0})) is None
    assert rubio2022_domain(make_scene(correction="full")) is None
    assert rubio2022_domain(make_scene(correction="tilt2d", **{"ship.heading": 30.0})) is None
    assert rubio2022_domain(make_scene(correction="yaw", **{"lidar.azimuths": [0, 120, 240]})) is None
    assert rubio2022_domain(make_scene(correction="yaw", **{"lidar.azimuths": [90, 0, 270, 180],
                                                             "lidar.vertical_beam": True})) == "i"


def paper_by_complex_step(scene, u):
    """The paper's model rebuilt from Eqs. 6/7 and 13-18 alone: u(v_i) from complex-step
    derivatives of the radial velocity with respect to the INS angles, then Eqs. 19-20
    with complex-step derivatives of the reconstruction. Independent of Eq. 8/12, A.*."""
    speed, cog, sog, cone = scene.wind_speed, scene.cog, scene.sog, scene.half_cone
    if scene.correction == "yaw":
        angles = {"yaw": scene.heading + scene.misalignment}
        radial = lambda a, s, c: rubio2022_radial_velocity_case_i(   # noqa: E731
            speed, scene.wind_direction, s, c, a["yaw"], cone, RUBIO2022_AZIMUTHS)
        recon = lambda v: rubio2022_reconstruction(v, sog, cog, cone, yaw=angles["yaw"])  # noqa: E731
        u_angles = {"yaw": u["heading"]}
    else:
        _, delta, beta = rubio2022_angles_from_attitude(0.0, scene.pitch, scene.roll)
        angles = {"delta": delta, "beta": beta}
        radial = lambda a, s, c: rubio2022_radial_velocity_case_ii(  # noqa: E731
            speed, scene.wind_direction, s, c, a["delta"], a["beta"], cone, RUBIO2022_AZIMUTHS)
        recon = lambda v: rubio2022_reconstruction(v, sog, cog, cone, delta=delta, beta=beta)  # noqa: E731
        u_angles = {"delta": u["pitch"], "beta": u["roll"]}
    variance = np.zeros(4)
    for name, u_angle in u_angles.items():
        shifted = {**angles, name: angles[name] + 1j * H}
        variance += (np.imag(radial(shifted, sog, cog)) / H * u_angle) ** 2
    variance += (np.imag(radial(angles, sog + 1j * H, cog)) / H * u["sog"]) ** 2
    variance += (np.imag(radial(angles, sog, cog + 1j * H)) / H * u["cog"]) ** 2
    sens = wind_derivatives(radial(angles, sog, cog), recon)
    return (np.sqrt(np.sum(sens[0] ** 2 * variance)),
            np.rad2deg(np.sqrt(np.sum(sens[1] ** 2 * variance))), np.sqrt(variance))


SCENES = [dict(correction="yaw", **{"ship.sog": 3.0, "ship.cog": 40.0, "ship.heading": 10.0,
                                    "lidar.misalignment": 35.0, "wind.direction": 200.0}),
          dict(correction="tilt2d", **{"ship.pitch": 6.0, "ship.roll": -8.0, "ship.sog": 2.0,
                                       "ship.cog": 130.0, "wind.direction": 75.0}),
          dict(correction="tilt2d", **{"ship.pitch": -10.0, "ship.roll": 10.0, "ship.sog": 4.0,
                                       "wind.direction": 300.0, "lidar.half_cone": 15.0})]


@pytest.mark.parametrize("changes", SCENES)
def test_scene_uncertainty_equals_independent_evaluation(changes):
    from uq.physics.rubio2022 import rubio2022_scene_uncertainty
    scene = make_scene(**changes)
    u = {"heading": d(0.3), "pitch": d(0.2), "roll": d(0.1), "sog": 0.1, "cog": d(0.5)}
    ours = rubio2022_scene_uncertainty(scene, scene.wind_speed, u["heading"], u["pitch"],
                                       u["roll"], u["sog"], u["cog"])
    speed, direction, radial = paper_by_complex_step(scene, u)
    # both are exact first-order evaluations; 1e-10 leaves room for the sums of terms
    np.testing.assert_allclose(ours["wind_speed"], speed, rtol=1e-10)
    np.testing.assert_allclose(ours["wind_direction"], direction, rtol=1e-10)
    np.testing.assert_allclose(ours["radial_velocity"], radial, rtol=1e-10)


def test_scene_uncertainty_of_a_batch_equals_scene_by_scene():
    import dataclasses
    from uq.physics.rubio2022 import rubio2022_scene_uncertainty
    base = make_scene(correction="tilt2d", **{"ship.sog": 2.0})
    fields = {"pitch": d(np.array([-10.0, 0.0, 4.0])), "roll": d(np.array([3.0, 0.0, -7.0])),
              "wind_direction": d(np.array([10.0, 120.0, 350.0])),
              "heading": d(np.array([0.0, 0.0, 30.0]))}           # the last is outside case ii
    batch = rubio2022_scene_uncertainty(dataclasses.replace(base, **fields), 5.0,
                                        0.001, 0.002, 0.003, 0.1, 0.002)
    for i in range(3):
        one = rubio2022_scene_uncertainty(
            dataclasses.replace(base, **{k: v[i] for k, v in fields.items()}), 5.0,
            0.001, 0.002, 0.003, 0.1, 0.002)
        for q in one:   # same arithmetic element by element: equal to rounding
            np.testing.assert_allclose(batch[q][i], one[q], rtol=1e-14)
    assert np.isnan(batch["wind_speed"][2]) and np.all(np.isnan(batch["radial_velocity"][2]))
