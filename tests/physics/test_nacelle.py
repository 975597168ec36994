"""The nacelle (tilted-mount) lidar against numbers derived independently: the clock
convention built from rotation matrices written here, closed forms of a static pitch,
and a second implementation of the kinematics (finite differences of the lidar's
position, rotations from scratch) for the forward radial velocities and the point-wise
corrected reconstruction.

Frames as in the model: (north, east, up) and (bow, starboard, up). The rotations below
are built from Rodrigues' formula about named axes, with their sense fixed by what they
do to named directions (asserted), not from :mod:`uq.physics.rotation`.
"""
import dataclasses

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from conftest import make_scene
from uq.physics.beams import beam_unit_vectors, mounted_unit_vectors
from uq.physics.measurement import beam_heights, measurement_model, true_values
from uq.physics.motion import Motion, MotionComponent
from uq.physics.nacelle import upper_lower, yaw_misalignment
from uq.physics.scene import TimeResolved
from uq.physics.timing import ScanTiming

d = np.deg2rad
FOUR = [0, 90, 180, 270]
TWO = [90, 270]
NACELLE_OUTPUTS = ("wind_speed", "wind_direction", "vertical_wind", "yaw_misalignment")


def rodrigues(axis, angle):
    """Right-hand rotation by `angle` [rad] about the unit `axis`, in the coordinates
    given (a plain 3 x 3 formula, independent of the code's rotations)."""
    k = np.asarray(axis, dtype=float) / np.linalg.norm(axis)
    cross = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    return np.eye(3) + np.sin(angle) * cross + (1 - np.cos(angle)) * cross @ cross


BOW, STARBOARD, UP = np.eye(3)


def tilt_rotation(tilt):
    """The rotation about the starboard axis that turns up towards the bow by `tilt`."""
    rotation = rodrigues(STARBOARD, tilt)
    assert np.allclose(rotation @ UP, [np.sin(tilt), 0, np.cos(tilt)])
    return rotation


def ship_to_earth(heading, pitch, roll):
    """Body to earth: roll about the bow (starboard down), then pitch about starboard
    (bow up), then heading about the vertical (clockwise from above), from scratch; the
    sense of each is asserted on a named direction."""
    roll_m, pitch_m, heading_m = (rodrigues(BOW, -roll), rodrigues(STARBOARD, -pitch),
                                  rodrigues(UP, heading))
    assert np.allclose(roll_m @ STARBOARD, [0, np.cos(roll), -np.sin(roll)])     # stbd down
    assert np.allclose(pitch_m @ BOW, [np.cos(pitch), 0, np.sin(pitch)])         # bow up
    assert np.allclose(heading_m @ BOW, [np.cos(heading), np.sin(heading), 0])   # N -> E
    return heading_m @ pitch_m @ roll_m


# --- the convention ----------------------------------------------------------------

def test_clock_positions_at_tilt_90():
    """0 up, 90 starboard, 180 down, 270 port about a boresight along the bow: each beam
    is the boresight opened by alpha towards its named direction."""
    alpha = d(15.0)
    beams = beam_unit_vectors(alpha, d(FOUR), 0.0, False, d(90.0))
    for beam, towards in zip(beams, [UP, STARBOARD, -UP, -STARBOARD]):
        np.testing.assert_allclose(beam, np.cos(alpha) * BOW + np.sin(alpha) * towards,
                                   atol=1e-15)       # rounding of cos(pi/2) = 6e-17


@given(st.floats(0.5, 90.0), st.floats(1.0, 40.0), st.floats(0.0, 360.0),
       st.floats(0.0, 360.0))
@settings(max_examples=60, deadline=None)
def test_tilted_frame_is_the_upward_frame_turned_about_starboard(tilt, cone, clock, turn):
    """The tilted frame is the upward (tilt 0) lidar's frame turned about the starboard
    axis by the tilt, with clock position phi = 180 - today's azimuth (the mirror image:
    today's azimuths run clockwise seen from above, the clock clockwise seen along the
    boresight); the misalignment turns it about the deck's vertical, clockwise from above.
    Rounding of a few sines: 1e-14."""
    today = beam_unit_vectors(d(cone), d([180.0 - clock]), 0.0, False)[0]
    expected = rodrigues(UP, d(turn)) @ tilt_rotation(d(tilt)) @ today
    got = beam_unit_vectors(d(cone), d([clock]), d(turn), False, d(tilt))[0]
    np.testing.assert_allclose(got, expected, atol=1e-14)


def test_upward_azimuths_are_clockwise_from_the_bow_seen_from_above():
    """Today's convention (tilt 0): azimuth 0 leans to the bow, 90 to starboard."""
    beams = beam_unit_vectors(d(30.0), d(FOUR), 0.0, False, 0.0)
    assert beams[0, 0] > 0.4 and beams[1, 1] > 0.4 and beams[2, 0] < -0.4 and beams[3, 1] < -0.4


def test_tilt_zero_is_todays_code_path():
    """tilt 0 returns the untilted formula's very array (bit for bit), whatever the beams."""
    a = beam_unit_vectors(d(28.0), d([0, 72, 144, 216, 288]), d(12.0), True)
    b = beam_unit_vectors(d(28.0), d([0, 72, 144, 216, 288]), d(12.0), True, 0.0)
    assert a.tobytes() == b.tobytes()
    plain = make_scene(**{"lidar.ranges": [40.0, 100.0], "ship.pitch": 3.0, "wind.shear": 0.2,
                          "ins.pitch": {"dist": "normal", "u": 0.1}})
    mounted = make_scene(**{"lidar.ranges": [40.0, 100.0], "ship.pitch": 3.0,
                            "wind.shear": 0.2, "lidar.mount": {"tilt": 0.0},
                            "ins.pitch": {"dist": "normal", "u": 0.1}})
    errors = {"ins_pitch": np.linspace(-0.3, 0.3, 7)}
    for compiled in (True, False):
        x = measurement_model(plain, compiled=compiled, **errors)
        y = measurement_model(mounted, compiled=compiled, **errors)
        assert all(x[q].tobytes() == y[q].tobytes() for q in x)


def test_upper_and_lower_beams():
    assert upper_lower(d(FOUR)) == (0, 2)
    assert upper_lower(d(TWO)) is None


def test_yaw_misalignment_wraps_about_the_rotor_axis():
    """wind direction minus heading, in [-180, 180): 350 from a bow at 10 is 20 to port."""
    np.testing.assert_allclose(yaw_misalignment(np.array([350.0, 30.0, 190.0]), d(10.0)),
                               [-20.0, 20.0, -180.0], atol=1e-12)


# --- static pitch: closed forms ----------------------------------------------------

def nacelle(azimuths, **changes):
    base = {"lidar.mount": {"tilt": 90.0}, "lidar.half_cone": 15.0, "lidar.azimuths": azimuths,
            "lidar.height": 150.0, "lidar.ranges": [50.0, 100.0, 200.0],
            "wind.reference_height": 150.0, "wind.speed": 10.0, "correction": "none"}
    return make_scene(**{**base, **changes})


@pytest.mark.parametrize("azimuths", [FOUR, TWO])
@pytest.mark.parametrize("pitch", [-4.0, 2.0, 7.5])
@pytest.mark.parametrize("gamma", [0.0, 8.0, -25.0, 130.0])
def test_static_pitch_without_correction(azimuths, pitch, gamma):
    """Uniform flow from gamma off the bow, static pitch p, no correction: the level-
    assumed lidar reconstructs the wind of its own pitched frame, R_y(p)^T u, so
    Vh' = U sqrt(cos^2 p cos^2 gamma + sin^2 gamma) and the yaw misalignment read is
    atan2(sin gamma, cos p cos gamma), for either layout (the two horizontal beams see no
    vertical component; the four-beam least squares is exact for a uniform wind). The
    four beams read w' = U sin p cos gamma. Rounding: 1e-9."""
    heading = 40.0
    scene = nacelle(azimuths, **{"ship.pitch": pitch, "ship.heading": heading,
                                 "wind.direction": heading + gamma})
    out = measurement_model(scene, NACELLE_OUTPUTS, compiled=False)
    p, g, u = d(pitch), d(gamma), 10.0
    speed = u * np.sqrt(np.cos(p)**2 * np.cos(g)**2 + np.sin(g)**2)
    np.testing.assert_allclose(out["wind_speed"][0] - u, speed - u, atol=1e-9)
    yaw = np.rad2deg(np.arctan2(np.sin(g), np.cos(p) * np.cos(g)))
    np.testing.assert_allclose(out["yaw_misalignment"][0], (yaw + 180) % 360 - 180, atol=1e-9)
    w = u * np.sin(p) * np.cos(g) if len(azimuths) == 4 else 0.0
    np.testing.assert_allclose(out["vertical_wind"][0], w, atol=1e-9)


@pytest.mark.parametrize("pitch", [-3.0, 0.0, 2.0, 6.0])
@pytest.mark.parametrize("tilt", [90.0, 80.0])
def test_point_heights_under_a_static_pitch(pitch, tilt):
    """The point at preview distance R on the beam at clock phi, on a lidar at H tilted tau
    and pitched p, is at z = H + (R / cos a) n_up with n_up the up component of
    R_pitch(p) n; at tau = 90: z = H + R (sin p + tan a cos phi cos p). Rounding: 1e-9 m."""
    scene = nacelle(FOUR, **{"ship.pitch": pitch, "lidar.mount": {"tilt": tilt}})
    attitude = ship_to_earth(0.0, d(pitch), 0.0)
    a, t, p = d(15.0), d(tilt), d(pitch)
    earth = np.array([attitude @ (np.cos(a) * (np.sin(t) * BOW + np.cos(t) * UP)
                                  + np.sin(a) * (np.cos(c) * (-np.cos(t) * BOW + np.sin(t) * UP)
                                                 + np.sin(c) * STARBOARD)) for c in d(FOUR)])
    ranges = np.array([50.0, 100.0, 200.0])
    expected = 150.0 + ranges / np.cos(a) * earth[:, 2:3]
    got = beam_heights(scene, earth)
    np.testing.assert_allclose(got, expected, atol=1e-9)
    if tilt == 90.0:
        closed = 150.0 + ranges * (np.sin(p) + np.tan(a) * np.cos(d(FOUR))[:, None] * np.cos(p))
        np.testing.assert_allclose(got, closed, atol=1e-9)


@pytest.mark.parametrize("pitch", [-4.0, 0.0, 1.5, 5.0])
@pytest.mark.parametrize("shear", [0.0, 0.14, 0.3])
def test_shear_exponent_under_a_static_pitch(pitch, shear):
    """Power-law shear alpha_s, wind along the rotor axis, static pitch p, no correction:
    the lidar believes its level heights H +- R tan a and reads U_k = U(z_k) cos(a +- p) /
    cos a on the upper (+) and lower (-) beam whose true heights are
    z = H + R (sin p +- tan a cos p). So
    alpha_hat = [alpha_s ln(z_up / z_dn) + ln(cos(a + p) / cos(a - p))]
                / ln((H + R tan a) / (H - R tan a)); at p = 0 exactly alpha_s. Rounding: 1e-9."""
    scene = nacelle(FOUR, **{"ship.pitch": pitch, "wind.shear": shear})
    out = measurement_model(scene, ("shear_exponent",), compiled=False)["shear_exponent"][0]
    a, p, h = d(15.0), d(pitch), 150.0
    r = np.array([50.0, 100.0, 200.0])
    z_up, z_dn = h + r * (np.sin(p) + np.tan(a) * np.cos(p)), h + r * (np.sin(p) - np.tan(a) * np.cos(p))
    expected = (shear * np.log(z_up / z_dn) + np.log(np.cos(a + p) / np.cos(a - p))) \
        / np.log((h + r * np.tan(a)) / (h - r * np.tan(a)))
    np.testing.assert_allclose(out, expected, atol=1e-9)


def test_true_values_of_a_nacelle_lidar():
    """The wind at hub height (tilt 90: the gates are at the lidar's height), the yaw
    misalignment and the scene's shear exponent."""
    scene = nacelle(FOUR, **{"wind.direction": 350.0, "ship.heading": 10.0, "wind.shear": 0.2,
                             "wind.reference_height": 100.0})
    truth = true_values(scene, ("wind_speed", "yaw_misalignment", "shear_exponent"))
    np.testing.assert_allclose(truth["gate_height"], 150.0, atol=1e-9)
    np.testing.assert_allclose(truth["wind_speed"], 10.0 * 1.5**0.2, rtol=1e-12)
    np.testing.assert_allclose(truth["yaw_misalignment"], -20.0, atol=1e-12)
    np.testing.assert_allclose(truth["shear_exponent"], 0.2)


# --- motion: an independent implementation of the kinematics ------------------------

class Kinematics:
    """The platform's motion written from its definition: harmonic degrees of freedom
    x_d(t) = A_d sin(w t + lag_d + phase) on top of the static attitude, the lidar at
    translation(t) + R(t) r, its velocity by central finite differences of that position,
    the beams R(t) n (n from the clock convention of the issue, rotated from scratch)."""

    def __init__(self, heading, pitch, roll, components, arm):
        self.static = (heading, pitch, roll)
        self.components, self.arm = components, np.asarray(arm, dtype=float)

    def dof(self, t):
        value = dict.fromkeys(("roll", "pitch", "yaw", "surge", "sway", "heave"), 0.0)
        for w, amplitudes, lags, phase in self.components:
            for name, a, lag in zip(value, amplitudes, lags):
                value[name] += a * np.sin(w * t + lag + phase)
        return value

    def attitude(self, t):
        x = self.dof(t)
        heading, pitch, roll = self.static
        return ship_to_earth(heading + x["yaw"], pitch + x["pitch"], roll + x["roll"])

    def position(self, t):
        """Lidar position relative to the INS's static position (north, east, up)."""
        x = self.dof(t)
        level = rodrigues(UP, self.static[0])        # the static heading's level frame
        return level @ np.array([x["surge"], x["sway"], x["heave"]]) + self.attitude(t) @ self.arm

    def velocity(self, t, h=1e-4):
        """Central difference: error h^2 |x'''| / 6 ~ 1e-8 * A w^3 (< 1e-9 m/s here)."""
        return (self.position(t + h) - self.position(t - h)) / (2 * h)


def wind_at(z, speed, direction, shear, ref, vertical=0.0):
    """Power-law wind (north, east, up) at height z, blowing from `direction` [rad]."""
    s = speed * (z / ref) ** shear
    return np.array([-s * np.cos(direction), -s * np.sin(direction), vertical])


MOTIONS = [  # (w, amplitudes roll, pitch, yaw [rad], surge, sway, heave [m], lags, phase)
    ((2 * np.pi / 25, (0.0, d(3.0), 0.0, 0.0, 0.0, 0.0), (0.0,) * 6, 0.7),
     (2 * np.pi / 8, (d(0.5), d(1.0), d(0.3), 1.0, 0.4, 0.6), (0.0, 0.3, 1.1, 0.2, 0.0, 2.0), 2.1)),
    ((2 * np.pi / 6, (d(2.0), d(4.0), d(1.0), 0.5, 1.5, 0.8), (1.0, 0.0, 0.5, 0.3, 0.7, 0.0), 4.0),),
]


def moving_nacelle(azimuths, motion, arm, correction, **changes):
    scene = nacelle(azimuths, **{"correction": correction, "ship.heading": 30.0,
                                 "ship.pitch": 1.0, "ship.roll": -0.5, "ship.sog": 0.3,
                                 "ship.cog": 70.0, "wind.direction": 41.0, **changes})
    components = tuple(MotionComponent(w, a, lags, phase) for w, a, lags, phase in motion)
    return dataclasses.replace(scene, time_resolved=TimeResolved(
        Motion(components, tuple(arm)), ScanTiming(0.25, "mid")))


def independent_radial(scene, motion, arm, azimuths):
    """Forward radial velocities b(t_k) . (u(z_k) - v_lidar(t_k)) at the beams' mid
    stamps t_k = (k + 1/2) 0.25 s, and the earth beams, positions and velocities."""
    kin = Kinematics(scene.heading, scene.pitch, scene.roll, motion, arm)
    ship_velocity = np.array([0.3 * np.cos(d(70.0)), 0.3 * np.sin(d(70.0)), 0.0])
    a = d(15.0)
    rows, beams, velocities = [], [], []
    for k, clock in enumerate(d(azimuths)):
        t = (k + 0.5) * 0.25
        n = np.cos(a) * BOW + np.sin(a) * (np.cos(clock) * UP + np.sin(clock) * STARBOARD)
        b = kin.attitude(t) @ n
        v = ship_velocity + kin.velocity(t)
        z = 150.0 + kin.position(t)[2] - (ship_to_earth(*kin.static) @ kin.arm)[2] \
            + np.array(scene.ranges) / np.cos(a) * b[2]
        rows.append([b @ (wind_at(zg, 10.0, scene.wind_direction, scene.shear, 150.0,
                                  scene.vertical_wind) - v) for zg in z])
        beams.append(b)
        velocities.append(v)
    return np.array(rows), np.array(beams), np.array(velocities), kin


@pytest.mark.parametrize("azimuths", [FOUR, TWO])
@pytest.mark.parametrize("motion", MOTIONS)
def test_forward_radial_velocities_against_the_kinematics(azimuths, motion):
    """The model's measured radial velocities (correction none removes nothing, so its
    radial output is what was measured) equal the independent kinematics' under shear,
    six degrees of freedom and a 150 m lever arm. Tolerance: the finite difference's
    1e-8 m/s (h^2 A w^3 / 6 with w <= 1.05 rad/s, A r <= 150 * 0.07) plus rounding."""
    arm = (2.0, -1.0, 150.0)
    scene = moving_nacelle(azimuths, motion, arm, "none", **{"wind.shear": 0.14})
    got = measurement_model(scene, ("radial_velocity",), compiled=False)["radial_velocity"][0]
    expected, *_ = independent_radial(scene, motion, arm, azimuths)
    np.testing.assert_allclose(got, expected, atol=1e-7)


@pytest.mark.parametrize("azimuths", [FOUR, TWO])
@pytest.mark.parametrize("motion", MOTIONS)
def test_pointwise_reconstruction_against_the_kinematics(azimuths, motion):
    """Point-wise correction with an exact continuous INS under shear: the model's wind
    equals the least squares written here on the independent beams and velocities
    (c_k = v_k + b_k . v_lidar,k; w = 0 for two beams), and its shear exponent the ratio
    of the upper and lower beams' speeds over their heights tracked with the lever arm.
    Tolerance as the forward test (1e-7 m/s of the finite differences)."""
    arm = (0.0, 0.0, 150.0)
    scene = moving_nacelle(azimuths, motion, arm, "pointwise", **{"wind.shear": 0.14})
    outputs = NACELLE_OUTPUTS + (("shear_exponent",) if len(azimuths) == 4 else ())
    got = measurement_model(scene, outputs, compiled=False)
    radial, beams, velocities, kin = independent_radial(scene, motion, arm, azimuths)
    corrected = radial + np.sum(beams * velocities, axis=1)[:, None]
    columns = beams if len(azimuths) == 4 else beams[:, :2]
    wind, *_ = np.linalg.lstsq(columns, corrected, rcond=None)
    if len(azimuths) == 4:      # the hub-height wind: the level beams 90, 270 with that w
        level = beams[[1, 3]]
        wind[:2] = np.linalg.solve(level[:, :2], corrected[[1, 3]] - np.outer(level[:, 2], wind[2]))
    speed = np.hypot(wind[0], wind[1])
    np.testing.assert_allclose(got["wind_speed"][0], speed, atol=1e-7)
    direction = np.rad2deg(np.arctan2(-wind[1], -wind[0])) % 360
    yaw = (direction - 30.0 + 180) % 360 - 180
    np.testing.assert_allclose(got["yaw_misalignment"][0], yaw, atol=1e-6)   # 1e-7 / U in rad
    if len(azimuths) == 4:
        np.testing.assert_allclose(got["vertical_wind"][0], wind[2], atol=1e-7)
        e = wind[:2] / speed
        speeds = corrected / (beams[:, :2] @ e)                # w = 0 assumed
        lift = [(kin.attitude((k + 0.5) * 0.25) @ kin.arm)[2]
                - (ship_to_earth(*kin.static) @ kin.arm)[2] for k in range(4)]
        heights = 150.0 + np.array(lift)[:, None] + np.array(scene.ranges) / np.cos(d(15.0)) \
            * beams[:, 2:3]
        alpha = np.log(speeds[0] / speeds[2]) / np.log(heights[0] / heights[2])
        np.testing.assert_allclose(got["shear_exponent"][0], alpha, atol=1e-6)
    else:
        np.testing.assert_allclose(got["vertical_wind"][0], 0.0, atol=0)


@settings(max_examples=25, deadline=None)
@given(st.sampled_from([FOUR, TWO]), st.sampled_from(MOTIONS),
       st.tuples(st.floats(-5, 5), st.floats(-5, 5), st.floats(50, 150)),
       st.floats(0, 359), st.floats(-40, 40), st.floats(3, 25))
def test_pointwise_with_an_exact_ins_recovers_u_yaw_and_w(azimuths, motion, arm, heading,
                                                          yaw, speed):
    """Uniform flow, harmonic motion in all six degrees of freedom, any lever arm, exact
    continuous INS: each beam is corrected with its own exact attitude and velocity, so
    u, the yaw misalignment and w (0 for two beams, where it is assumed; 0.3 m/s for
    four) come back to rounding: 1e-12 (m/s; the yaw misalignment in rad times U)."""
    w = 0.3 if len(azimuths) == 4 else 0.0
    scene = moving_nacelle(azimuths, motion, arm, "pointwise", **{
        "ship.heading": heading, "wind.direction": (heading + yaw) % 360,
        "wind.speed": speed, "wind.vertical": w})
    got = measurement_model(scene, NACELLE_OUTPUTS, compiled=False)
    assert np.all(np.abs(got["wind_speed"][0] - speed) < 1e-12)
    assert np.all(np.abs(d(got["yaw_misalignment"][0] - yaw)) * speed < 1e-12)
    assert np.all(np.abs(got["vertical_wind"][0] - w) < 1e-12)
