"""Frames and rotations: named directions, round trips, the Rubio & Gottschall mapping."""
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from uq.physics.rotation import (attitude_from_matrix, attitude_from_rubio2022_angles, attitude_matrix,
                         rotate_vectors, rotation_about_vertical, rotation_pitch,
                         rotation_roll, rubio2022_angles_from_attitude,
                         rubio2022_rotation)

BOW, STARBOARD, UP = np.eye(3)
NORTH, EAST = BOW, STARBOARD
d = np.deg2rad
angle = st.floats(-80, 80)


@pytest.mark.parametrize("heading, bow", [(0, NORTH), (90, EAST), (180, -NORTH), (270, -EAST)])
def test_heading_points_the_bow_clockwise_from_north(heading, bow):
    np.testing.assert_allclose(attitude_matrix(d(heading), 0, 0) @ BOW, bow, atol=1e-15)


def test_positive_pitch_lifts_the_bow():
    bow = attitude_matrix(0, d(10), 0) @ BOW
    assert bow[2] == pytest.approx(np.sin(d(10)))


def test_positive_roll_lowers_starboard():
    starboard = attitude_matrix(0, 0, d(10)) @ STARBOARD
    assert starboard[2] == pytest.approx(-np.sin(d(10)))


def test_roll_then_pitch_order():
    # roll is applied first (about the bow), so the bow does not feel roll
    bow = attitude_matrix(0, d(20), d(30)) @ BOW
    np.testing.assert_allclose(bow, [np.cos(d(20)), 0, np.sin(d(20))], atol=1e-15)


def test_clockwise_yaw_adds_to_azimuth():
    vector = np.array([np.cos(d(30)), np.sin(d(30)), 0])
    np.testing.assert_allclose(rotation_about_vertical(d(40)) @ vector,
                               [np.cos(d(70)), np.sin(d(70)), 0], atol=1e-15)


@settings(max_examples=200, deadline=None)
@given(st.floats(0, 359.9), angle, angle)
def test_attitude_round_trip(heading, pitch, roll):
    matrix = attitude_matrix(d(heading), d(pitch), d(roll))
    np.testing.assert_allclose(matrix @ matrix.T, np.eye(3), atol=1e-14)
    assert np.linalg.det(matrix) == pytest.approx(1.0)
    back = attitude_from_matrix(matrix)
    np.testing.assert_allclose(np.cos(back[0] - d(heading)), 1.0, atol=1e-12)
    np.testing.assert_allclose(back[1:], [d(pitch), d(roll)], atol=1e-12)


def test_heading_wraps_at_north():
    heading = attitude_from_matrix(attitude_matrix(d(-0.01), 0, 0))[0]
    assert np.rad2deg(heading) == pytest.approx(359.99)


@settings(max_examples=200, deadline=None)
@given(st.floats(0, 359.9), angle, angle)
def test_rubio2022_mapping_round_trip_and_matrix(heading, pitch, roll):
    gamma, delta, beta = rubio2022_angles_from_attitude(d(heading), d(pitch), d(roll))
    np.testing.assert_allclose(rubio2022_rotation(delta, beta, gamma),
                               attitude_matrix(d(heading), d(pitch), d(roll)), atol=1e-14)
    back = attitude_from_rubio2022_angles(gamma, delta, beta)
    np.testing.assert_allclose(np.cos(back[0] - d(heading)), 1.0, atol=1e-12)
    np.testing.assert_allclose(back[1:], [d(pitch), d(roll)], atol=1e-12)


def test_rubio2022_angles_to_first_order():
    # delta is positive bow down (their Sec. 3.3), beta positive starboard down
    gamma, delta, beta = rubio2022_angles_from_attitude(0.0, d(1e-3), d(2e-3))
    np.testing.assert_allclose([delta, beta], [-d(1e-3), d(2e-3)], rtol=1e-5)
    assert np.cos(gamma) == pytest.approx(1.0)
    gamma, delta, beta = rubio2022_angles_from_attitude(d(30), d(5.0), 0.0)
    np.testing.assert_allclose([gamma, delta, beta], [d(30), -d(5.0), 0.0], atol=1e-15)


def test_rubio2022_second_order_yaw_of_combined_tilt():
    gamma, _, _ = rubio2022_angles_from_attitude(0.0, d(10), d(10))
    yaw = np.rad2deg(np.mod(gamma + np.pi, 2 * np.pi) - np.pi)
    # Closed form: tan(gamma) = -M01 / M11 = -sin p sin r / cos r  at heading 0
    assert yaw == pytest.approx(np.rad2deg(np.arctan(-np.sin(d(10)) * np.tan(d(10)))))


def test_rubio2022_rotation_reproduces_eq7_beam():
    theta, phi, delta, beta = d(28), d(60), d(7), d(-4)
    beam = np.array([np.sin(theta) * np.cos(phi), np.sin(theta) * np.sin(phi), np.cos(theta)])
    north = np.cos(delta) * np.sin(theta) * np.cos(phi) + np.sin(delta) * np.cos(theta)
    east = (np.sin(theta) * (np.cos(beta) * np.sin(phi) - np.sin(beta) * np.sin(delta) * np.cos(phi))
            + np.sin(beta) * np.cos(delta) * np.cos(theta))
    np.testing.assert_allclose((rubio2022_rotation(delta, beta) @ beam)[:2], [north, east],
                               atol=1e-15)


@pytest.mark.parametrize("matrix_shape, vector_shape", [
    ((3, 3), (5, 3, 2)), ((1, 3, 3), (5, 3, 1)), ((1, 1, 3, 3), (5, 4, 3, 2)),
    ((3, 4), (7, 4, 1)), ((2, 3, 3), (5, 2, 3, 1)), ((6, 1, 3, 3), (6, 2, 3, 1))])
def test_apply_matrix_equals_matmul(matrix_shape, vector_shape):
    """Both paths (one BLAS product for a single matrix, einsum for stacks) are matmul,
    up to the order of three additions (a few ulps)."""
    from uq.physics.rotation import apply_matrix
    rng = np.random.default_rng(3)
    matrix, vectors = rng.random(matrix_shape), rng.random(vector_shape)
    np.testing.assert_allclose(apply_matrix(matrix, vectors), matrix @ vectors, rtol=1e-14)


def test_attitude_matrix_is_the_product_of_the_elementary_rotations():
    """The written-out matrix equals Rz(heading) Ry(pitch) Rx(roll) multiplied out, for
    angles in every quadrant and complex-step input (1e-15: a few roundings)."""
    rng = np.random.default_rng(0)
    heading, pitch, roll = (rng.uniform(-np.pi, np.pi, 50) for _ in range(3))
    product = rotation_about_vertical(heading) @ rotation_pitch(pitch) @ rotation_roll(roll)
    np.testing.assert_allclose(attitude_matrix(heading, pitch, roll), product, atol=1e-15)
    stepped = attitude_matrix(heading + 1e-20j, pitch, roll)
    # d Rz / d psi = P Rz(psi + 90 deg) with P = diag(1, 1, 0): the product, last row zero
    derivative = rotation_about_vertical(heading + np.pi / 2) @ rotation_pitch(pitch) \
        @ rotation_roll(roll)
    derivative[..., 2, :] = 0.0
    np.testing.assert_allclose(stepped.imag / 1e-20, derivative, atol=1e-14)


def test_rotate_vectors_one_matrix_and_a_stack_agree_with_matmul():
    rng = np.random.default_rng(1)
    vectors = rng.normal(size=(7, 2, 5, 3))
    one = attitude_matrix(0.3, 0.1, -0.2)
    np.testing.assert_allclose(rotate_vectors(one, vectors), vectors @ one.T, atol=1e-15)
    stack = attitude_matrix(rng.normal(size=2), 0.1, -0.2)   # (2, 3, 3): one per scene S
    expected = np.einsum("sij,nskj->nski", stack, vectors)
    np.testing.assert_allclose(rotate_vectors(stack, vectors), expected, atol=1e-15)
    np.testing.assert_allclose(expected[:, 1, 2], vectors[:, 1, 2] @ stack[1].T, atol=1e-15)
