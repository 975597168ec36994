"""The probe volume against closed forms, limiting cases and brute-force integrals.

Every expected value here comes from outside :mod:`uq.physics.probe`'s quadrature: the
closed forms of the module docstring, Taylor's series of the power law, and adaptive
integration (``scipy.integrate.quad``) of the weighting functions written out again below.
"""
import dataclasses
import math
from pathlib import Path

import numpy as np
import pytest
from scipy import integrate, special

from conftest import make_scene
from uq.constants import (PROBE_QUADRATURE_TOLERANCE, WINDCUBE_GATE_LENGTH,
                          WINDCUBE_PULSE_FWHM, ZEPHIR_BEAM_RADIUS_MM, ZEPHIR_TRUNCATION,
                          ZEPHIR_WAVELENGTH_UM)
from uq.physics import probe as P
from uq.physics.beams import slant_distances
from uq.physics.measurement import measurement_model, true_radial_velocity, true_values
from uq.physics.rotation import attitude_matrix, rotate_vectors

PULSED = {"lidar.probe": {"kind": "pulsed", "gate_length": WINDCUBE_GATE_LENGTH,
                          "pulse_fwhm": WINDCUBE_PULSE_FWHM}}
CW = {"lidar.probe": {"kind": "cw", "wavelength": ZEPHIR_WAVELENGTH_UM,
                      "beam_radius": ZEPHIR_BEAM_RADIUS_MM, "truncation": ZEPHIR_TRUNCATION}}
LN2 = math.log(2.0)
#: Absolute accuracy asked of scipy's adaptive quadrature; the weightings are smooth
#: (erf) or have a kink only at the cut, given as a break point, so it is met.
QUAD = {"epsabs": 1e-13, "epsrel": 1e-13, "limit": 500}


def windcube():
    return P.PulsedProbe(WINDCUBE_GATE_LENGTH, WINDCUBE_PULSE_FWHM)


def zephir():
    return P.ContinuousWaveProbe(ZEPHIR_WAVELENGTH_UM * 1e-6, ZEPHIR_BEAM_RADIUS_MM * 1e-3,
                                 ZEPHIR_TRUNCATION)


def pulse(s, pulse_fwhm):
    """The seed's Eq. 2.18 with r_p from Eq. 2.20: exp(-s^2/r_p^2) / (sqrt(pi) r_p)."""
    r_p = pulse_fwhm / (2 * math.sqrt(LN2))
    return np.exp(-(s / r_p) ** 2) / (math.sqrt(math.pi) * r_p)


def pulsed_by_convolution(s, gate_length, pulse_fwhm):
    """W_p as the seed's Eq. 2.23, first line: the pulse averaged over the gate window,
    integrated numerically (a second implementation of Eq. (1))."""
    return integrate.quad(lambda u: pulse(s + u, pulse_fwhm), -gate_length / 2,
                          gate_length / 2, **QUAD)[0] / gate_length


def lorentzian(s, rayleigh, half_length):
    """The on-axis intensity w0^2 / w(s)^2 (seed Eq. 2.9), cut at |s| <= L, unnormalised."""
    return np.where(np.abs(s) <= half_length, 1.0 / (1.0 + (s / rayleigh) ** 2), 0.0)


# --- the weighting functions ------------------------------------------------------------------

def test_pulse_fwhm_is_the_width_at_half_maximum():
    """r_p = dr / (2 sqrt(ln 2)) puts the pulse at half its peak at s = dr / 2 (Eq. 2.20),
    and the 150 ns WindCube pulse is the seed's 22.5 m (Delta r = sqrt(ln 2) c sigma_p)."""
    fwhm = WINDCUBE_PULSE_FWHM
    assert pulse(fwhm / 2, fwhm) / pulse(0.0, fwhm) == pytest.approx(0.5, rel=1e-14)
    tau, c = 150e-9, 299_792_458.0                       # seed Eq. 2.16: sigma_p
    sigma_p = tau / (2 * math.sqrt(LN2))
    assert math.sqrt(LN2) * c * sigma_p == pytest.approx(fwhm, rel=1e-3)   # c rounded


@pytest.mark.parametrize("gate, fwhm", [(30.0, 22.5), (18.0, 30.0), (50.0, 10.0)])
def test_pulsed_weighting_is_the_convolution_integrates_to_one_and_has_its_variance(gate, fwhm):
    for s in (-40.0, -15.0, 0.0, 7.5, 33.0):
        assert P.pulsed_weight(s, gate, fwhm) == pytest.approx(
            pulsed_by_convolution(s, gate, fwhm), abs=1e-13)
    reach = gate / 2 + 12 * fwhm                 # beyond it the pulse's tail is < 1e-40
    mass = integrate.quad(P.pulsed_weight, -reach, reach, args=(gate, fwhm), **QUAD)[0]
    second = integrate.quad(lambda s: s * s * P.pulsed_weight(s, gate, fwhm), -reach, reach,
                            **QUAD)[0]
    assert mass == pytest.approx(1.0, abs=1e-12)
    # Eq. (2): the rectangle's dp^2/12 plus the pulse's r_p^2/2 = dr^2/(8 ln 2)
    closed = gate ** 2 / 12 + fwhm ** 2 / (8 * LN2)
    assert second == pytest.approx(closed, rel=1e-12)
    assert P.pulsed_variance(gate, fwhm) == pytest.approx(closed, rel=1e-14)


def test_the_printed_second_line_of_eq_2_23_doubles_the_pulse_variance():
    """The printed erf((r +- dp/2) / (sqrt(2) r_p)) is the distribution function of a
    Gaussian of variance r_p^2: the pulse's variance r_p^2 / 2 is doubled."""
    gate, fwhm = WINDCUBE_GATE_LENGTH, WINDCUBE_PULSE_FWHM
    r_p = fwhm / (2 * math.sqrt(LN2))

    def printed(s):
        return (special.erf((s + gate / 2) / (math.sqrt(2) * r_p))
                - special.erf((s - gate / 2) / (math.sqrt(2) * r_p))) / (2 * gate)

    reach = gate / 2 + 20 * r_p
    variance = integrate.quad(lambda s: s * s * printed(s), -reach, reach, **QUAD)[0]
    assert variance - gate ** 2 / 12 == pytest.approx(r_p ** 2, rel=1e-12)
    assert P.pulsed_variance(gate, fwhm) - gate ** 2 / 12 == pytest.approx(r_p ** 2 / 2,
                                                                         rel=1e-12)


@pytest.mark.parametrize("half_length", [100.0, 45.3, 20.0, 8.0])
def test_pulsed_moments_cut_at_the_lens(half_length):
    gate, fwhm = WINDCUBE_GATE_LENGTH, WINDCUBE_PULSE_FWHM
    mass = integrate.quad(P.pulsed_weight, -half_length, half_length, args=(gate, fwhm),
                          **QUAD)[0]
    second = integrate.quad(lambda s: s * s * P.pulsed_weight(s, gate, fwhm), -half_length,
                            half_length, **QUAD)[0]
    closed_mass, closed_second = P.pulsed_moments(half_length, gate, fwhm)
    # the antiderivatives cancel terms of size ~L^3 / sigma: a few ulps of those
    assert closed_mass == pytest.approx(mass, abs=1e-12)
    assert closed_second == pytest.approx(second, rel=1e-11)
    assert P.pulsed_variance(gate, fwhm, half_length) == pytest.approx(second / mass,
                                                                      rel=1e-11)


@pytest.mark.parametrize("focus", [45.3, 113.3, 226.5, 400.0])
def test_cw_weighting_integrates_to_one_and_has_its_variance(focus):
    probe = zephir()
    rayleigh = probe.rayleigh(focus)
    half = probe.half_length(focus)
    # the cut: W(L) = truncation W(0) unless the lens comes first
    cut = math.sqrt(1 / ZEPHIR_TRUNCATION - 1) * rayleigh
    assert half == pytest.approx(min(cut, focus), rel=1e-15)
    if cut < focus:
        assert lorentzian(half, rayleigh, half) == pytest.approx(ZEPHIR_TRUNCATION, rel=1e-12)
    weight = lambda s: P.cw_weight(s, rayleigh, half)      # noqa: E731
    mass = integrate.quad(weight, -half, half, points=[0.0], **QUAD)[0]
    second = integrate.quad(lambda s: s * s * weight(s), -half, half, points=[0.0], **QUAD)[0]
    assert mass == pytest.approx(1.0, abs=1e-12)
    # Eq. (4) against the plain integral of the unnormalised Lorentzian
    raw = integrate.quad(lambda s: lorentzian(s, rayleigh, half), -half, half, **QUAD)[0]
    raw2 = integrate.quad(lambda s: s * s * lorentzian(s, rayleigh, half), -half, half,
                          **QUAD)[0]
    assert second == pytest.approx(raw2 / raw, rel=1e-11)
    assert probe.variance(focus) == pytest.approx(raw2 / raw, rel=1e-11)


def test_rayleigh_length_of_the_focused_gaussian_beam():
    """A beam of radius a at the lens focused at F: waist w0 = lambda F / (pi a) (far
    field), z_R = pi w0^2 / lambda (Eq. 2.11), where the beam is sqrt(2) w0 wide (Eq. 2.9);
    and the CW weighting halves there (the Lorentzian's half width)."""
    lam, a, focus = ZEPHIR_WAVELENGTH_UM * 1e-6, ZEPHIR_BEAM_RADIUS_MM * 1e-3, 100.0
    waist = lam * focus / (math.pi * a)
    rayleigh = P.rayleigh_length(lam, a, focus)
    assert rayleigh == pytest.approx(math.pi * waist ** 2 / lam, rel=1e-15)
    assert P.cw_weight(rayleigh, rayleigh, 10 * rayleigh) / P.cw_weight(
        0.0, rayleigh, 10 * rayleigh) == pytest.approx(0.5, rel=1e-15)


# --- the quadrature ------------------------------------------------------------------------------

def brute_force_speed(probe, centre, vertical, focus, shear):
    """U_w / U(z_c) by adaptive integration of the weighting written out above (cut at
    the lens, renormalised) times (z / z_c)^alpha."""
    profile = lambda s: ((centre + s * vertical) / centre) ** shear      # noqa: E731
    if probe.kind == "pulsed":
        half = float(probe.half_length(focus))
        weight = lambda s: P.pulsed_weight(s, probe.gate_length, probe.pulse_fwhm)  # noqa: E731
        points = [-probe.gate_length / 2, 0.0, probe.gate_length / 2]
    else:
        rayleigh, half = float(probe.rayleigh(focus)), float(probe.half_length(focus))
        weight = lambda s: lorentzian(s, rayleigh, half)                 # noqa: E731
        points = [-rayleigh, 0.0, rayleigh]
    points = [p for p in points if -half < p < half]
    top = integrate.quad(lambda s: weight(s) * profile(s), -half, half, points=points, **QUAD)
    bottom = integrate.quad(weight, -half, half, points=points, **QUAD)
    return top[0] / bottom[0]


#: Geometries: lidar height [m], range [m], beam up component, shear. They span the
#: typical floating lidar (2-20 m above the sea, gates 10-300 m, half-cone 28 deg or a
#: vertical beam) and shears from unstable to very stable, including the hardest case
#: (CW at 300 m from 2 m under a negative shear: its probe reaches the lens, 2 m above the
#: power law's branch point at the sea, where the speed rises steeply).
GEOMETRIES = [(2.0, 10.0, 0.883, 0.14), (2.0, 40.0, 0.883, 0.2), (20.0, 100.0, 0.883, -0.1),
              (2.0, 200.0, 0.883, 0.14), (3.0, 300.0, 1.0, 0.4), (20.0, 60.0, 0.7, 0.6),
              (2.0, 300.0, 0.883, -0.3)]


@pytest.mark.parametrize("probe", [windcube(), zephir()], ids=["pulsed", "cw"])
@pytest.mark.parametrize("height, rng_, vertical, shear", GEOMETRIES)
def test_chosen_node_count_meets_the_tolerance_and_one_fewer_does_not(probe, height, rng_,
                                                                   vertical, shear):
    centre, focus = height + rng_ * vertical, rng_
    nodes, estimate = P.node_count(probe, centre, vertical, focus, shear)
    exact = brute_force_speed(probe, centre, vertical, focus, shear)

    def rule(n):
        return float(probe.average(lambda z: (z / centre) ** shear, centre, vertical, focus,
                                   nodes=n))

    # the brute force is good to ~1e-13 (QUAD), far inside the tolerance's margin
    assert abs(rule(nodes) / exact - 1) <= PROBE_QUADRATURE_TOLERANCE + 1e-12
    # the estimate is against the 256-node rule, itself good to 1e-12 in the hardest case
    assert abs(rule(nodes) / exact - 1) == pytest.approx(estimate, abs=1e-11)
    if nodes > 1:                  # the fewest: one node fewer misses (at it or the next)
        assert max(abs(rule(nodes - 1) / exact - 1),
                   abs(rule(nodes) / exact - 1)) > PROBE_QUADRATURE_TOLERANCE - 1e-12


def test_node_count_follows_the_geometry_not_a_fixed_guess():
    counts = {P.node_count(zephir(), 2 + r * 0.883, 0.883, r, 0.14)[0] for r in (10, 100, 300)}
    assert len(counts) == 3
    # a uniform or linear profile is integrated exactly by any symmetric rule: 1 node
    assert P.node_count(windcube(), 42.0, 0.883, 40.0, 0.0)[0] == 1
    assert P.node_count(zephir(), 200.0, 0.883, 200.0, 1.0)[0] == 1


# --- through the measurement model ----------------------------------------------------------

def scene(probe=None, **changes):
    base = {"lidar.height": 2.0, "lidar.ranges": [10.0, 40.0, 100.0, 200.0, 300.0],
            "wind.speed": 10.0, "wind.reference_height": 100.0, "wind.direction": 30.0}
    return make_scene(**{**base, **(probe or {}), **changes})


def horizontal_speed(s, **errors):
    return np.real(measurement_model(s, ("wind_speed",), compiled=False, **errors)[
        "wind_speed"][0])


@pytest.mark.parametrize("probe", [PULSED, CW], ids=["pulsed", "cw"])
@pytest.mark.parametrize("shear", [0.0, 1.0])
def test_uniform_and_linear_profiles_have_no_probe_bias(probe, shear):
    """Tilted, turned and moving, with geometry errors, static and time-resolved: a
    symmetric weighting averages a linear profile to its centre value; only rounding is
    left (sums of ~50 terms of ~10 m/s: ~1e-14 relative)."""
    changes = {"wind.shear": shear, "ship.pitch": 7.0, "ship.roll": -4.0, "ship.sog": 3.0,
               "ship.heading": 40.0, "ship.heave": 0.3, "lidar.vertical_beam": True}
    moving = {"motion.roll": {"amplitude": 5.0, "period": 6.0, "phase": 30.0},
              "motion.heave": {"amplitude": 1.0, "period": 8.0, "phase": 0.0},
              "correction": "pointwise"}
    errors = {"lidar_half_cone": np.array([0.3, -0.2]), "lidar_misalignment": np.array([1, 2.0])}
    for extra in ({}, moving):
        with_probe, point = scene(probe, **changes, **extra), scene(None, **changes, **extra)
        got, expected = horizontal_speed(with_probe, **errors), horizontal_speed(point, **errors)
        np.testing.assert_allclose(got, expected, rtol=1e-13)


def second_and_fourth_order(probe, shear, vertical, centre, focus):
    """Eq. (5) and the next (fourth-order) term of Taylor's series,
    binom(alpha, 4) mu_4 b_z^4 / z^4, with the weighting's fourth moment mu_4 in closed
    form (untruncated pulsed: E(u + g)^4 of a uniform plus a Gaussian; CW: z_R^4 (c^3/3 - c
    + atan c) / atan c from x^4 / (1 + x^2) = x^2 - 1 + 1 / (1 + x^2))."""
    if probe.kind == "pulsed":
        h, sigma2 = probe.gate_length / 2, P.pulse_radius(probe.pulse_fwhm) ** 2 / 2
        variance, fourth = h * h / 3 + sigma2, h ** 4 / 5 + 2 * h * h * sigma2 + 3 * sigma2 ** 2
    else:
        rayleigh = float(probe.rayleigh(focus))
        c = float(probe.half_length(focus)) / rayleigh
        variance = float(probe.variance(focus))
        fourth = rayleigh ** 4 * (c ** 3 / 3 - c + math.atan(c)) / math.atan(c)
    binomial4 = shear * (shear - 1) * (shear - 2) * (shear - 3) / 24
    return (P.second_order_bias(shear, variance, vertical, centre),
            binomial4 * fourth * vertical ** 4 / centre ** 4)


@pytest.mark.parametrize("probe, kind", [(PULSED, "pulsed"), (CW, "cw")])
@pytest.mark.parametrize("shear", [0.14, 0.2, -0.3])
def test_power_law_bias_is_the_second_order_expansion_where_small_and_the_integral_everywhere(
        probe, kind, shear):
    """Level four-beam lidar: every beam sees the same weighted speed, so the DBS speed
    is it and its relative bias is U_w / U(z_c) - 1."""
    s = scene(probe, **{"wind.shear": shear})
    bias = horizontal_speed(s) / true_values(s)["wind_speed"] - 1
    physics = windcube() if kind == "pulsed" else zephir()
    vertical = math.cos(math.radians(28.0))
    for gate, rng_ in enumerate(s.ranges):
        centre, focus = 2.0 + rng_, rng_ / vertical
        exact = brute_force_speed(physics, centre, vertical, focus, shear) - 1
        # everywhere: the quadrature's stated tolerance (brute force good to ~1e-13)
        assert bias[gate] == pytest.approx(exact, abs=PROBE_QUADRATURE_TOLERANCE)
        second, fourth = second_and_fourth_order(physics, shear, vertical, centre, focus)
        small = abs(fourth) < 0.05 * abs(second)    # the series converges fast here
        # the pulsed moments above are those of the uncut weighting: not where the lens cuts
        whole = kind == "pulsed" and physics.half_length(focus) < focus
        if small and (kind == "cw" or whole):
            # the remainder after the second order is the fourth-order term plus terms
            # smaller by (probe extent / height)^2; 2x the fourth order bounds it, plus
            # the quadrature's tolerance
            assert abs(bias[gate] - second) <= 2 * abs(fourth) + PROBE_QUADRATURE_TOLERANCE


def test_expansion_is_checked_at_several_gates():
    """The comparison above is not vacuous: the second order applies at 3 of 5 gates for
    each kind (pulsed far, CW near)."""
    vertical = math.cos(math.radians(28.0))
    for physics, expected in ((windcube(), 3), (zephir(), 3)):
        small = 0
        for rng_ in (10.0, 40.0, 100.0, 200.0, 300.0):
            second, fourth = second_and_fourth_order(physics, 0.14, vertical, 2 + rng_,
                                                     rng_ / vertical)
            focus = rng_ / vertical
            at_lens = physics.kind == "pulsed" and physics.half_length(focus) >= focus
            small += abs(fourth) < 0.05 * abs(second) and not at_lens
        assert small == expected


@pytest.mark.parametrize("shear", [0.14, 0.2])
def test_cw_bias_grows_with_range_and_pulsed_falls(shear):
    ranges = [40.0, 60.0, 80.0, 100.0, 140.0, 200.0, 250.0]
    biases = {}
    for name, probe in (("pulsed", PULSED), ("cw", CW)):
        s = scene(probe, **{"wind.shear": shear, "lidar.ranges": ranges})
        biases[name] = np.abs(horizontal_speed(s) / true_values(s)["wind_speed"] - 1)
    assert np.all(np.diff(biases["cw"]) > 0)
    assert np.all(np.diff(biases["pulsed"]) < 0)


def test_radial_velocities_of_a_tilted_moving_lidar_against_brute_force():
    """Per beam and gate, on the true tilted beams (pitch 8, roll -5) of a moving lidar:
    the probe-weighted radial velocity is the brute-force weighted horizontal speed at
    the probe points' true heights, projected, plus the vertical wind and minus the
    lidar's velocity along the beam."""
    for probe, physics in ((PULSED, windcube()), (CW, zephir())):
        s = P.resolve(scene(probe, **{"ship.pitch": 8.0, "ship.roll": -5.0, "ship.sog": 2.0,
                                      "wind.vertical": 0.4, "wind.shear": 0.25,
                                      "lidar.ranges": [40.0, 150.0]}))
        beams = rotate_vectors(attitude_matrix(s.heading, s.pitch, s.roll),
                               s.nominal_unit_vectors())
        ship = np.array([s.sog * np.cos(s.cog), s.sog * np.sin(s.cog), 0.0])
        radial, _ = true_radial_velocity(s, beams, ship, 0.0, s.probe)
        slant = slant_distances(s.ranges, s.half_cone, 4, False)
        to_wind = -np.array([np.cos(s.wind_direction), np.sin(s.wind_direction)])
        for b in range(4):
            for g in range(2):
                up = beams[b, 2]
                centre = s.lidar_height + slant[b, g] * up
                u_c = s.wind_speed * (centre / s.reference_height) ** s.shear
                speed = u_c * brute_force_speed(physics, centre, up, slant[b, g], s.shear)
                expected = speed * beams[b, :2] @ to_wind + up * 0.4 - beams[b] @ ship
                assert radial[b, g] == pytest.approx(expected, abs=PROBE_QUADRATURE_TOLERANCE
                                                     * s.wind_speed * 2)


def test_time_resolved_model_without_motion_is_the_static_model():
    """The two implementations of the probe (static and time-resolved) agree when the
    platform does not move within the scan (a pointwise correction, a static tilt)."""
    for probe in (PULSED, CW):
        common = {"ship.pitch": 6.0, "ship.roll": 3.0, "wind.shear": 0.2}
        static = scene(probe, **common)
        resolved = scene(probe, **common, **{"lidar.lever_arm": [0.0, 0.0, 0.0]})
        assert resolved.time_resolved is not None
        errors = {"lidar_gate_length": np.array([1.0, -2.0]),
                  "lidar_beam_radius": np.array([1.5, -0.5])}
        np.testing.assert_allclose(horizontal_speed(resolved, **errors),
                                   horizontal_speed(static, **errors), rtol=1e-13)


def test_probe_parameter_errors_change_the_bias_as_the_closed_form_says():
    """A gate-length error changes the pulsed bias by the derivative of its series: of
    Eq. (5), alpha (alpha - 1) b_z^2 / (2 z^2) dVar/d(dp) with dVar/d(dp) = dp / 6, and of
    the fourth-order term, binom(alpha, 4) b_z^4 / z^4 dmu_4/d(dp) with dmu_4/d(dp) = (4 h^3
    / 5 + 4 h sigma^2) / 2; the complex-step derivative (what the GUM uses) equals a
    central difference of the model (its error is second order in the step: ~1e-7)."""
    s = scene(PULSED, **{"wind.shear": 0.2, "lidar.ranges": [200.0, 300.0]})
    # 128 nodes: the default rule's error (1e-6 of U) is ~1 % of this derivative's scale
    s = dataclasses.replace(s, probe=s.probe.with_nodes(128))
    truth = true_values(s)["wind_speed"]
    h = 1e-20
    complex_step = np.imag(measurement_model(s, ("wind_speed",), compiled=False,
                                             lidar_gate_length=np.array([1j * h]))[
        "wind_speed"][0]) / h
    step = 1e-3
    plus = horizontal_speed(s, lidar_gate_length=np.array([step]))
    minus = horizontal_speed(s, lidar_gate_length=np.array([-step]))
    np.testing.assert_allclose(complex_step, (plus - minus) / (2 * step), rtol=1e-6)
    vertical, alpha = math.cos(math.radians(28.0)), 0.2
    height = 2.0 + np.array(s.ranges)
    h, sigma2 = WINDCUBE_GATE_LENGTH / 2, P.pulse_radius(WINDCUBE_PULSE_FWHM) ** 2 / 2
    binomial4 = alpha * (alpha - 1) * (alpha - 2) * (alpha - 3) / 24
    closed = truth * (alpha * (alpha - 1) * vertical ** 2 / (2 * height ** 2)
                      * WINDCUBE_GATE_LENGTH / 6
                      + binomial4 * vertical ** 4 / height ** 4 * (4 * h ** 3 / 5
                                                                   + 4 * h * sigma2) / 2)
    # the sixth-order term's derivative is ~(extent / height)^2 ~ 1e-3 of the fourth's
    np.testing.assert_allclose(complex_step, closed, rtol=1e-4)
    # a CW beam-radius error: a larger radius focuses more sharply, a smaller bias
    c = scene(CW, **{"wind.shear": 0.2, "lidar.ranges": [200.0]})
    sharper = horizontal_speed(c, lidar_beam_radius=np.array([2.0]))
    assert abs(sharper - true_values(c)["wind_speed"]) < abs(
        horizontal_speed(c) - true_values(c)["wind_speed"])


def test_a_probe_runs_the_compiled_model_and_its_complex_step_the_numpy_model(monkeypatch):
    """Real trials of a probe take the compiled loop (uq.physics.fusedprobe; compared
    with this module's quadrature in test_fusedprobe.py); the GUM's complex step does not."""
    from uq.physics import fused
    calls = []
    original = fused.evaluate                 # counts the calls the compiled loop takes

    def counted(*args, **kwargs):
        result = original(*args, **kwargs)
        if result is not None:
            calls.append(1)
        return result
    monkeypatch.setattr(fused, "evaluate", counted)
    point = scene(None)
    measurement_model(point, ("wind_speed",), lidar_radial_velocity=np.zeros((3, 4, 5)))
    assert calls == [1]                       # a point scene takes the compiled path
    for probe in (PULSED, CW):
        measurement_model(scene(probe), ("wind_speed",),
                          lidar_radial_velocity=np.zeros((3, 4, 5)))
    assert calls == [1, 1, 1]
    for probe in (PULSED, CW):                # the complex step: numpy
        measurement_model(scene(probe), ("wind_speed",),
                          lidar_radial_velocity=np.zeros((3, 4, 5)) + 1e-20j)
    assert calls == [1, 1, 1]


def test_resolve_keeps_a_chosen_node_count_and_a_batch_takes_the_largest():
    one = P.resolve(scene(CW, **{"lidar.ranges": [40.0], "wind.shear": 0.14}))
    far = P.resolve(scene(CW, **{"lidar.ranges": [40.0, 250.0], "wind.shear": 0.14}))
    assert far.probe.nodes > one.probe.nodes
    assert P.resolve(far) is far
    batch = dataclasses.replace(scene(CW, **{"lidar.ranges": [250.0], "wind.shear": 0.14}),
                                lidar_height=np.array([2.0, 30.0]))
    nodes = [P.resolve(dataclasses.replace(batch, lidar_height=h)).probe.nodes
             for h in (2.0, 30.0)]
    assert P.resolve(batch).probe.nodes == max(nodes)


def test_guide_table_is_the_model():
    """The user guide's table of relative biases (docs/use-cases/probe-volume.md: level
    lidar 2 m above the sea, half-cone 28 deg, 10 m/s at 100 m; gates 40, 100, 200 m) is
    what the model gives, to the
    printed 3 decimals of a per cent; the gates of ``scenarios/probe_volume.yaml``, whose
    node count (the largest any gate needs) the table's numbers come from."""
    readme = (Path(__file__).resolve().parents[2] / "docs" / "use-cases"
              / "probe-volume.md").read_text()
    gates = [40.0, 60.0, 80.0, 100.0, 120.0, 140.0, 160.0, 180.0, 200.0]
    shown = [gates.index(r) for r in (40.0, 100.0, 200.0)]
    for probe in (PULSED, CW):
        for shear in (0.14, 0.2):
            s = scene(probe, **{"wind.shear": shear, "lidar.ranges": gates})
            relative = 100 * (horizontal_speed(s) / true_values(s)["wind_speed"] - 1)
            row = f"| {shear:.2f} | " + " | ".join(
                f"{value:.3f} %".replace("-", "\u2212") for value in relative[shown]) + " |"
            assert row in readme, row


def test_the_probe_moves_with_the_beam_in_a_time_resolved_scan():
    """Roll and heave during the scan: each beam at its time stamp t_k = k + 1/2 s has
    the attitude (roll + 5 deg sin(2 pi t / 6 + 30 deg)) and the height (+ 1 m sin(2 pi t
    / 8)) written out here; the pointwise-corrected radial velocity (no errors: the
    lidar's own velocity removed exactly) is the brute-force weighted speed along that
    beam, projected, plus the vertical wind."""
    roll = {"amplitude": 5.0, "period": 6.0, "phase": 30.0}
    heave = {"amplitude": 1.0, "period": 8.0, "phase": 0.0}
    for probe, physics in ((PULSED, windcube()), (CW, zephir())):
        s = scene(probe, **{"motion.roll": roll, "motion.heave": heave, "ship.pitch": 3.0,
                            "correction": "pointwise", "wind.shear": 0.2,
                            "wind.vertical": 0.3, "lidar.ranges": [40.0, 150.0]})
        out = measurement_model(s, ("radial_velocity",))["radial_velocity"][0]
        slant = slant_distances(s.ranges, s.half_cone, 4, False)
        to_wind = -np.array([np.cos(s.wind_direction), np.sin(s.wind_direction)])
        for k in range(4):
            t = k + 0.5
            rolled = s.roll + math.radians(5.0) * math.sin(2 * math.pi * t / 6 + math.radians(30))
            beam = attitude_matrix(s.heading, s.pitch, rolled) @ s.nominal_unit_vectors()[k]
            lidar = s.lidar_height + math.sin(2 * math.pi * t / 8)
            for g in range(2):
                centre = lidar + slant[k, g] * beam[2]
                u_c = s.wind_speed * (centre / s.reference_height) ** s.shear
                speed = u_c * brute_force_speed(physics, centre, beam[2], slant[k, g], s.shear)
                expected = speed * beam[:2] @ to_wind + beam[2] * 0.3
                # the quadrature's tolerance, relative to the speed (~10 m/s)
                assert out[k, g] == pytest.approx(expected, abs=2 * PROBE_QUADRATURE_TOLERANCE
                                                  * s.wind_speed)
