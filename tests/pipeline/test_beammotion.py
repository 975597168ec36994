"""The Monte Carlo records sample the turbulence along the beams' true, moving positions
and directions (uq.pipeline.beammotion, records.moving_probes)."""
import math

import numpy as np
import pytest
from scipy.special import gamma as gamma_function, kv

from uq.physics import turbulencesampling
from uq.pipeline import records
from uq.pipeline.beammotion import moving_beams
from uq.pipeline.modelsetup import scene_from_settings
from uq.pipeline.scenario import load_scenario
from uq.pipeline.turbulencesection import scan_geometry

#: A level 4-beam DBS, point probe, beams 1 s apart (scan period 4 s), gates 100 m up
#: at the reference height.
LIDAR = {"height": 0.0, "ranges": [100.0], "half_cone": 30.0,
         "scan": {"beam_duration": 1.0}}


def setup(motion, heading=0.0, direction=270.0, lever_arm=(0.0, 0.0, 0.0), duration=60,
          turbulence=None, n_scans=None):
    settings = load_scenario({
        "wind": {"speed": 10.0, "direction": direction, "reference_height": 100.0},
        "ship": {"heading": heading}, "lidar": {**LIDAR, "lever_arm": list(lever_arm)},
        "motion": motion, "turbulence": turbulence or {"intensity": 0.1},
        "record": {"duration": duration, "count": 2}, "sampling": {"n": 64},
        "outputs": ["turbulence_intensity"]}).settings
    geometry = scan_geometry(settings)
    n_scans = n_scans or records.scans_per_record(settings)
    scene = records.probe_volume_resolved(scene_from_settings(settings))
    scene, phases = records.coherent_phases(scene, n_scans, geometry.scan_period,
                                            np.random.default_rng(0))
    return settings, geometry, scene, phases, n_scans


def beam_times(geometry, n_scans):
    """Record time of each beam's mid dwell [s], (n_scans, n_beams)."""
    return np.arange(n_scans)[:, None] * geometry.scan_period + np.asarray(geometry.times)


def hand_sampled(box, geometry, position, shifts, directions, times):
    """Radial velocities sampled by hand (point probe, no dwell): the gate at slant
    distance s of the nominal lidar `position` moved by `shifts` along `directions`."""
    slant = np.linalg.norm(np.asarray(geometry.gate_centres) - position, axis=-1)  # (B, G)
    points = (position + shifts[:, :, None, :]
              + slant[None, :, :, None] * directions[:, :, None, :])          # (S, B, G, 3)
    velocity = turbulencesampling.sample_velocity(box, points, times[:, :, None],
                                                  geometry.speed)
    return np.sum(velocity * directions[:, :, None, :], axis=-1)


def test_harmonic_surge_shifts_the_beams_along_the_bow():
    # surge a sin(w t + phi) along the bow (heading 30 deg, so the bow is (cos 30, sin 30,
    # 0) in (north, east, up)); the wind from the south (180) makes x north and y west:
    # the bow is (cos 30, -sin 30, 0) in the mean-wind frame. The phase advances with
    # the record's time t = s T_s + t_beam. Rounding only: 1e-12 m.
    a, period, phase = 0.8, 7.0, 40.0
    settings, geometry, scene, phases, n = setup(
        {"surge": {"amplitude": a, "period": period, "phase": phase}}, heading=30.0,
        direction=180.0)
    moved, directions = moving_beams(scene, scene.time_resolved.motion.unit_phases(phases),
                                     geometry, 180.0)
    surge = a * np.sin(2 * np.pi / period * beam_times(geometry, n) + math.radians(phase))
    bow = np.array([math.cos(math.radians(30.0)), -math.sin(math.radians(30.0)), 0.0])
    np.testing.assert_allclose(moved, surge[..., None] * bow, atol=1e-12)
    np.testing.assert_allclose(directions, np.broadcast_to(geometry.directions,
                                                           directions.shape), atol=1e-12)
    # the sampled turbulence is the box's at the nominal points shifted by that vector
    # (same interpolation: 1e-12 m/s is rounding)
    kwargs, margin = records.moving_probes(settings, scene, phases, geometry)
    # a pure translation moves every point by |x| (rounding: 1e-9)
    assert margin == pytest.approx(np.max(np.abs(surge)), rel=1e-9)
    box, _ = records.turbulence_box(settings, geometry, np.random.default_rng(1), margin)
    seen = turbulencesampling.record_radial_velocities(box, geometry, n, **kwargs)
    expected = hand_sampled(box, geometry, kwargs["position"], surge[..., None] * bow,
                            np.broadcast_to(geometry.directions, moved.shape),
                            beam_times(geometry, n))
    np.testing.assert_allclose(seen, expected, atol=1e-12)
    nominal = turbulencesampling.record_radial_velocities(box, geometry, n)
    assert np.max(np.abs(seen - nominal)) > 1e-3     # the shift is seen


def test_pitch_with_a_lever_arm_turns_the_beams_and_moves_the_lidar():
    # heading 0 (bow north), wind from the west (270): x east, y north, z up. A pitch
    # theta (bow up) maps a ship vector (b1, b2, b3) (bow, starboard, up) to (north,
    # east, up) = (b1 cos - b3 sin, b2, b1 sin + b3 cos); the lidar at lever arm r =
    # (r1, 0, r3) moves by R r - r. Written out by hand here, not through rotation.py.
    amplitude, period, phase, arm = 8.0, 9.0, 10.0, (3.0, 0.0, 5.0)
    settings, geometry, scene, phases, n = setup(
        {"pitch": {"amplitude": amplitude, "period": period, "phase": phase}},
        lever_arm=arm)
    moved, directions = moving_beams(scene, scene.time_resolved.motion.unit_phases(phases),
                                     geometry, 270.0)
    theta = math.radians(amplitude) * np.sin(2 * np.pi / period * beam_times(geometry, n)
                                             + math.radians(phase))
    c, s = np.cos(theta), np.sin(theta)
    ship = np.asarray(geometry.directions)[:, [1, 0, 2]]     # level, heading 0: ship = (y, x, z)
    north = ship[:, 0] * c - ship[:, 2] * s
    up = ship[:, 0] * s + ship[:, 2] * c
    east = np.broadcast_to(ship[:, 1], north.shape)
    np.testing.assert_allclose(directions, np.stack([east, north, up], axis=-1), atol=1e-12)
    shift = np.stack([np.zeros_like(theta), arm[0] * np.cos(theta) - arm[2] * np.sin(theta)
                      - arm[0], arm[0] * np.sin(theta) + arm[2] * np.cos(theta) - arm[2]],
                     axis=-1)
    np.testing.assert_allclose(moved, shift, atol=1e-12)
    kwargs, margin = records.moving_probes(settings, scene, phases, geometry)
    box, _ = records.turbulence_box(settings, geometry, np.random.default_rng(2), margin)
    seen = turbulencesampling.record_radial_velocities(box, geometry, n, **kwargs)
    expected = hand_sampled(box, geometry, kwargs["position"], shift, directions,
                            beam_times(geometry, n))
    np.testing.assert_allclose(seen, expected, atol=1e-12)
    # every moved point lies within the box's motion margin of its nominal one
    slant = np.linalg.norm(np.asarray(geometry.gate_centres) - kwargs["position"], axis=-1)
    points = kwargs["position"] + shift[:, :, None] + slant[..., None] * directions[:, :, None]
    assert np.max(np.linalg.norm(points - np.asarray(geometry.gate_centres), axis=-1)) \
        <= margin + 1e-9


def von_karman_transverse_correlation(r, length_scale):
    """g(r) of the isotropic von Karman field (Mann's tensor at Gamma = 0): with
    f(r) = 2^(2/3) / Gamma(1/3) xi^(1/3) K_1/3(xi), xi = r / L, the longitudinal
    correlation, g = f + (r / 2) f' = 2^(2/3) / Gamma(1/3) xi^(1/3) [K_1/3(xi) -
    (xi / 2) K_2/3(xi)] (d/dxi [xi^nu K_nu] = -xi^nu K_(nu-1), K_-nu = K_nu)."""
    xi = np.maximum(np.asarray(r, float), 1e-12) / length_scale
    return 2 ** (2 / 3) / gamma_function(1 / 3) * xi ** (1 / 3) * (
        kv(1 / 3, xi) - xi / 2 * kv(2 / 3, xi))


def test_strong_pitch_decorrelates_the_turbulence_the_beams_see():
    # Derivation. Lever arm 0: a beam turned from d to d' (|d' - d| = 2 sin(dtheta / 2))
    # samples at p' = p + R (d' - d), R the slant distance, so the separation r = R |d' -
    # d| is along d' - d, perpendicular to d to O(theta^2). Then
    #   v' - v = d . [u(p') - u(p)] + (d' - d) . u(p'),
    # and for an isotropic field (Mann, Gamma = 0; per-component variance sigma^2;
    # E[u_i(p) u_j(p + r)] = sigma^2 [(f - g) r_i r_j / r^2 + g delta_ij]) the first
    # term has mean square 2 sigma^2 (1 - g(r)) (transverse), the second |d' - d|^2
    # sigma^2, and their cross term vanishes (d . r = 0, and d . (d' - d) = O(theta^2)):
    #   E[(v' - v)^2] = sigma^2 [2 (1 - g(R |d' - d|)) + |d' - d|^2]       (continuous)
    # (1) Against the box's own field: the same separations and directions from
    # 200 random places of the box (moved along x by up to its length) give the
    # expectation of (d' . u(q + r) - d . u(q))^2; the record's 240 scan-beam samples
    # (each scan 40 m > L of advection from the last, beams 115 m apart: about
    # independent) have a mean square of relative standard error sqrt(2 / 240) = 0.09:
    # 3 of them, [0.73, 1.27].
    # (2) Against the continuous field: the box, with cells of L / 8 and periodic over a
    # few L, carries less structure at separations of 2-5 cells than the continuous
    # field (its smallest scales are missing and interpolation smooths; measured for
    # this box: 0.4-0.8 of 2 sigma^2 (1 - g)); the record's mean square is therefore
    # between 0.3 times the closed form and the closed form itself (plus its 3 standard
    # errors).
    length_scale, amplitude = 33.6, 10.0
    settings, geometry, scene, phases, n = setup(
        {"pitch": {"amplitude": amplitude, "period": 10.0, "phase": 0.0}}, duration=240,
        turbulence={"intensity": 0.1, "length_scale": length_scale, "anisotropy": 0.0})
    kwargs, margin = records.moving_probes(settings, scene, phases, geometry)
    box, _ = records.turbulence_box(settings, geometry, np.random.default_rng(3), margin)
    moving = turbulencesampling.record_radial_velocities(box, geometry, n, **kwargs)[..., 0]
    nominal = turbulencesampling.record_radial_velocities(box, geometry, n)[..., 0]
    measured = float(np.mean((moving - nominal) ** 2))
    turned, d = kwargs["directions"], np.asarray(geometry.directions)
    slant = np.linalg.norm(np.asarray(geometry.gate_centres)[:, 0] - kwargs["position"],
                           axis=-1)                                          # (B,)
    separation = slant[:, None] * (turned - d)                               # (S, B, 3)
    base = np.asarray(geometry.gate_centres)[:, 0] + np.random.default_rng(4).uniform(
        0, box.grid.shape[0] * box.grid.spacing[0], (200, 1, 1, 1)) * np.array([1, 0, 0])
    here = turbulencesampling.sample_velocity(box, base, 0.0, geometry.speed)
    there = turbulencesampling.sample_velocity(box, base + separation, 0.0, geometry.speed)
    expected = float(np.mean((np.sum(there * turned, -1) - np.sum(here * d, -1)) ** 2))
    assert 0.73 < measured / expected < 1.27, (measured, expected)
    sigma2 = (0.1 * 10.0) ** 2            # the model's point variance, each component
    closed = sigma2 * np.mean(2 * (1 - von_karman_transverse_correlation(
        np.linalg.norm(separation, axis=-1), length_scale))
        + np.sum((turned - d) ** 2, axis=-1))
    assert 0.3 < measured / closed < 1.27, (measured, closed)
    # the moving beams see another series, not a rescaled one: correlation below 1 by
    # about E[(v' - v)^2] / (2 var v)
    correlation = np.corrcoef(moving.ravel(), nominal.ravel())[0, 1]
    assert correlation < 1 - 0.5 * measured / (2 * np.var(nominal))
