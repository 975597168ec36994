"""Platform motion: harmonic components, attitude rates, the lever arm (hand-computed
cases and finite differences)."""
import dataclasses

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from conftest import make_scene
from uq.physics.motion import DEGREES_OF_FREEDOM, Motion, MotionComponent, \
    degrees_of_freedom, platform_kinematics
from uq.physics.rotation import attitude_matrix, attitude_matrix_rate, \
    interpolate_rotation, rotation_from_vector

d = np.deg2rad


def component(dof, amplitude, period, phase=0.0, lag=0.0):
    amplitudes = [0.0] * 6
    lags = [0.0] * 6
    amplitudes[DEGREES_OF_FREEDOM.index(dof)] = amplitude
    lags[DEGREES_OF_FREEDOM.index(dof)] = lag
    return MotionComponent(2 * np.pi / period, tuple(amplitudes), tuple(lags), phase)


def test_a_harmonic_is_a_sine_from_its_phase():
    """x(t) = A sin(w t + phi): the unit-phase form reproduces it and its derivative."""
    motion = Motion((component("pitch", 0.1, 4.0, phase=0.7),))
    t = np.linspace(0, 9, 50)[None]
    value, rate = degrees_of_freedom(motion, motion.unit_phases(), t)
    w = 2 * np.pi / 4.0
    np.testing.assert_allclose(value["pitch"], 0.1 * np.sin(w * t + 0.7), atol=1e-15)
    np.testing.assert_allclose(rate["pitch"], 0.1 * w * np.cos(w * t + 0.7), atol=1e-15)
    assert value["roll"] == 0.0 and rate["heave"] == 0.0


def test_random_phases_give_the_covariance_of_the_issue():
    """Over uniform phases, Cov(x(t), x(s)) = (A^2 / 2) cos(w (t - s)): sample average of
    the product over 2000 equally spaced phases (exact for a trigonometric polynomial of
    degree 2 < 2000)."""
    amplitude, period = 0.2, 6.0
    motion = Motion((component("roll", amplitude, period, phase=None),))
    phases = np.linspace(0, 2 * np.pi, 2000, endpoint=False)
    unit = np.stack([np.cos(phases), np.sin(phases)], axis=-1)[:, None, :]
    t = np.array([[0.0, 1.0, 2.5]])
    value, _ = degrees_of_freedom(motion, motion.unit_phases(unit), t)
    covariance = value["roll"].T @ value["roll"] / len(phases)
    w = 2 * np.pi / period
    expected = amplitude**2 / 2 * np.cos(w * (t.T - t))
    np.testing.assert_allclose(covariance, expected, atol=1e-15)


@settings(max_examples=40, deadline=None)
@given(st.floats(0, 359), st.floats(-20, 20), st.floats(-20, 20), st.floats(-1, 1),
       st.floats(-1, 1), st.floats(-1, 1))
def test_attitude_rate_is_the_derivative(heading, pitch, roll, dh, dp, dr):
    """dR/dt against a central difference of attitude_matrix along the rates (step 1e-6:
    truncation ~1e-12 of the second derivative, rounding ~1e-10)."""
    h, p, r = d(heading), d(pitch), d(roll)
    step = 1e-6
    numeric = (attitude_matrix(h + dh * step, p + dp * step, r + dr * step)
               - attitude_matrix(h - dh * step, p - dp * step, r - dr * step)) / (2 * step)
    np.testing.assert_allclose(attitude_matrix_rate(h, p, r, dh, dp, dr), numeric, atol=1e-8)


@pytest.mark.parametrize("rates, expected", [
    # roll rate 0.1 rad/s (starboard going down), lidar 2 m up: the mast top moves to
    # starboard = east at heading 0: omega x r = 0.1 x 2 = 0.2 m/s
    ((0.0, 0.0, 0.1), (0.0, 0.2, 0.0)),
    # pitch rate 0.1 rad/s (bow going up): the mast top moves aft (south): -0.2 m/s north
    ((0.0, 0.1, 0.0), (-0.2, 0.0, 0.0)),
    # yaw rate 0.1 rad/s clockwise with the lidar 3 m forward: moves east at 0.3 m/s
    ((0.1, 0.0, 0.0), (0.0, 0.3, 0.0)),
])
def test_lever_arm_velocity_is_omega_cross_r(rates, expected):
    arm = np.array([0.0, 0.0, 2.0]) if rates[0] == 0 else np.array([3.0, 0.0, 0.0])
    velocity = attitude_matrix_rate(0.0, 0.0, 0.0, *rates) @ arm
    np.testing.assert_allclose(velocity, expected, atol=1e-15)


def test_lever_arm_velocity_in_the_kinematics():
    """A roll of 5 deg at 5 s, lidar 2 m above the INS: at t = 0 (phase 0) the roll rate is
    A w and the lidar moves to starboard at A w r."""
    scene = make_scene()
    amplitude, period, arm = d(5.0), 5.0, 2.0
    motion = Motion((component("roll", amplitude, period),), lever_arm=(0.0, 0.0, arm))
    kin = platform_kinematics(scene, motion, motion.unit_phases(), np.zeros((1, 1)))
    w = 2 * np.pi / period
    np.testing.assert_allclose(kin["lidar_velocity"][0, 0], [0.0, amplitude * w * arm, 0.0],
                               atol=1e-15)
    np.testing.assert_allclose(kin["ins_velocity"][0, 0], [0.0, 0.0, 0.0], atol=1e-15)


def test_translation_follows_the_static_heading():
    """Surge 1 m along the bow at heading 90 deg moves the lidar east."""
    scene = dataclasses.replace(make_scene(), heading=d(90.0))
    motion = Motion((component("surge", 1.0, 8.0, phase=np.pi / 2),))     # at its crest
    kin = platform_kinematics(scene, motion, motion.unit_phases(), np.zeros((1, 1)))
    np.testing.assert_allclose(kin["lidar_offset"][0, 0], [0.0, 1.0, 0.0], atol=1e-15)


@settings(max_examples=30, deadline=None)
@given(st.floats(-0.5, 0.5), st.floats(-0.5, 0.5), st.floats(-0.5, 0.5), st.floats(0, 1))
def test_slerp_moves_at_constant_rate_on_the_shortest_path(a, b, c, fraction):
    """interpolate_rotation(R0, R0 exp(v), f) = R0 exp(f v): exact to rounding."""
    start = attitude_matrix(0.3, -0.2, 0.1)
    v = np.array([a, b, c])
    end = start @ rotation_from_vector(v)
    np.testing.assert_allclose(interpolate_rotation(start, end, fraction),
                               start @ rotation_from_vector(fraction * v), atol=1e-13)


def test_slerp_is_analytic_at_equal_rotations():
    """Complex-step through equal samples (the GUM's linearisation point): finite."""
    start = attitude_matrix(0.3, -0.2, 0.1) + 0j
    out = interpolate_rotation(start, start, 0.5 + 1e-30j)
    assert np.all(np.isfinite(out)) and np.allclose(out.real, start.real, atol=1e-15)
