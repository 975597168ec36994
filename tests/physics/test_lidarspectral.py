"""The spectral path against limits, closed forms and an independent evaluation."""
import dataclasses
import warnings

import numpy as np
import pytest
from scipy import integrate, interpolate

from uq.physics.lidarspectral import (PairResolution, cut_lorentzian_transfer, dbs_surge_variance,
                                      harmonic_motion_variance, kaimal_block_average_ratio,
                                      kaimal_lidar_variances, lidar_variances,
                                      lorentzian_transfer, mann_lidar_variances,
                                      probe_transfer_for, pulsed_transfer, quadrature_transfer,
                                      record_filter, staring_cw_kaimal_ratio,
                                      vad_surge_variance)
from uq.physics.probe import ContinuousWaveProbe, PulsedProbe, legendre, pulsed_weight
from uq.physics.scangeometry import ScanGeometry, conical_scan
from uq.physics.spectraltensor import (KaimalSpectra, WavenumberGrid,
                                       mann_tensor_for_intensity)

SPEED = 10.0
SATHE_PROBE = PulsedProbe(18.75, 24.75)        # Sathe et al. (2011): WindCube gate, pulse


def dbs_geometry(heights, **options):
    """A fixed, level DBS (:func:`uq.physics.scangeometry.conical_scan`) in a wind of
    :data:`SPEED`."""
    return conical_scan(heights, speed=SPEED, **options)


@pytest.fixture(scope="module")
def tensor():
    return mann_tensor_for_intensity(0.1, SPEED, 33.6, 3.9)


def test_record_filter_is_the_expected_sample_variance():
    # a sinusoid of frequency f and uniform phase sampled every T over N samples: the mean
    # over phases of (1/N) sum (x - mean)^2 divided by its variance 1/2 (brute force; the
    # phase average of a degree-2 trigonometric polynomial is exact on 8 equal phases)
    period, n = 1.7, 13
    for f in (0.003, 0.05, 0.21, 1 / period):
        phases = 2 * np.pi * np.arange(8) / 8
        x = np.cos(2 * np.pi * f * period * np.arange(n)[:, None] + phases)
        brute = np.mean(np.var(x, axis=0)) / 0.5
        assert record_filter(f, period, n * period) == pytest.approx(brute, abs=1e-12)
    assert record_filter(0.3, 1.0, 1.0) == 0.0
    assert record_filter(0.3, 1.0, np.inf) == 1.0


def test_point_probe_simultaneous_colocated_beams_see_the_true_variance(tensor):
    # a point probe, beams at one instant, all at the reference point: the reconstruction
    # inverts the directions exactly, so each component's variance is the field's (the
    # colocated pairs are the point tensor's 1-D spectra on both sides: to rounding; 1e-4
    # leaves room for the reconstruction's rounding)
    g = dbs_geometry([100.0], vertical=True)
    g = dataclasses.replace(g, gate_centres=np.zeros_like(g.gate_centres),
                            times=np.zeros(g.n_beams), dwell=0.0)
    result = mann_lidar_variances(g, tensor)
    np.testing.assert_allclose(result.lidar[0], result.true, rtol=1e-4)
    # one beam along n: its radial velocity's variance is n Phi n integrated
    n = np.array([0.5, 0.0, np.sqrt(0.75)])
    single = dataclasses.replace(g, directions=n[None], gate_centres=np.zeros((1, 1, 3)),
                                 times=np.zeros(1), reconstruction=np.ones((1, 3, 1)))
    along = mann_lidar_variances(single, tensor).lidar[0, 0]
    unit = dataclasses.replace(single, directions=np.eye(3), gate_centres=np.zeros((3, 1, 3)),
                               times=np.zeros(3), reconstruction=np.eye(3)[None])
    # cross terms: n Phi n = sum n_i n_j Phi_ij; var(u), var(w) from the point and
    # cov(u, w) from var of (u + w)/sqrt 2 along a 45 deg beam
    diag = mann_lidar_variances(unit, tensor).lidar[0]
    diagonal = dataclasses.replace(single, directions=np.array([[1, 0, 1]]) / np.sqrt(2.0))
    cov = mann_lidar_variances(diagonal, tensor).lidar[0, 0] - (diag[0] + diag[2]) / 2
    # single beams and one point: the left-out points drop the same terms on both sides
    # but for the cross term's weighting, < 3e-6 tr(Phi) each: 1e-4
    assert along == pytest.approx(n[0] ** 2 * diag[0] + n[2] ** 2 * diag[2]
                                  + 2 * n[0] * n[2] * cov, rel=1e-4)
    assert cov < 0      # the shear makes u and w anti-correlated (momentum flux)


# --- an independent integration of Eq. (3) -------------------------------------------------
# Each beam pair's covariance C_bd = integral n_b Phi n_d P_b P_d exp(i k . delta) H d^3k is
# taken along its separation: the plane normal to delta integrated on a log-polar rule
# about the plane's origin (MannTensor.matrix, the full 3 x 3 tensor, numpy), tabulated
# along delta, splined in log k, and the oscillating integral along delta by QUADPACK's
# QAWO (scipy.integrate.quad, weight="cos"); the record's high-pass with every record
# peak a break point. No part of it is the spectral path's (Cartesian rules, Filon
# weights, compiled sums, peak weights).

def _plane_rule(per_decade=10, angles=48, decades=(-6.0, 4.0)):
    """Log-polar nodes rho / s (s = sqrt(k^2 + L^-2) at k along the axis), angles and
    weights in rho drho dtheta per s^2."""
    x, w = np.polynomial.legendre.leggauss(per_decade)
    edges = np.arange(decades[0], decades[1])
    u = (edges[:, None] + (x + 1) / 2).ravel()
    rho = 10.0 ** u
    theta = 2 * np.pi * np.arange(angles) / angles
    weight = (np.tile(w / 2, len(edges)) * np.log(10.0) * rho ** 2)[:, None] \
        * np.full(angles, 2 * np.pi / angles)
    return rho, theta, weight


def _chi(tensor, axis, pairs, directions, probe, k_along, rule):
    """chi_bd(k) = integral over the plane normal to `axis` at k along it, (len(k), pairs)."""
    axis = np.asarray(axis, float) / np.linalg.norm(axis)
    helper = np.array([0, 0, 1.0]) if abs(axis[2]) < 0.9 else np.array([1.0, 0, 0])
    e1 = np.cross(axis, helper)
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(axis, e1)
    rho, theta, weight = rule
    plane = rho[:, None, None] * (np.cos(theta)[None, :, None] * e1
                                  + np.sin(theta)[None, :, None] * e2)
    out = np.zeros((len(k_along), len(pairs)))
    for i, kp in enumerate(k_along):
        scale = np.hypot(kp, 1.0 / tensor.length_scale)
        k = kp * axis + scale * plane
        phi = tensor.matrix(k[..., 0], k[..., 1], k[..., 2])
        for j, (b, d) in enumerate(pairs):
            projection = np.einsum("i,raij,j->ra", directions[b], phi, directions[d])
            out[i, j] = scale ** 2 * np.sum(weight * projection * probe(k @ directions[b])
                                            * probe(k @ directions[d]))
    return out


def _along(k_along, chi, delta, highpass=None, width=None, speed=None, scan_period=None):
    """2 integral_0^inf chi(k) H(k) cos(k delta) dk (chi even: F(-k) = F(k) for a real
    probe), chi splined in log k (k chi), QAWO on panels, the peaks of H break points."""
    spline = interpolate.CubicSpline(np.log(k_along), k_along * chi)

    def f(k):
        return spline(np.log(k)) / k * (1.0 if highpass is None else highpass(k))
    edges = np.geomspace(k_along[0], k_along[-1], 61)
    if width is not None:       # the record's peak at 0 and the scans' aliasing notches
        edges = np.union1d(edges, np.arange(1, 128) * width / 2)
        if scan_period is not None:
            notch = 2 * np.pi / (speed * scan_period)
            edges = np.union1d(edges, (np.arange(1, 9)[:, None] * notch
                                       + np.arange(-8, 9) * width / 2).ravel())
    edges = edges[(edges >= k_along[0]) & (edges <= k_along[-1])]
    x, w = np.polynomial.legendre.leggauss(24)          # delta = 0: 24 nodes a piece
    centre, half = (edges[1:] + edges[:-1]) / 2, (edges[1:] - edges[:-1]) / 2
    plain = np.sum(half[:, None] * w * f(centre[:, None] + half[:, None] * x))
    if delta == 0:
        return 2 * plain
    total = 0.0
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", integrate.IntegrationWarning)
        for a, b in zip(edges[:-1], edges[1:]):
            total += integrate.quad(f, a, b, weight="cos", wvar=delta, limit=200,
                                    epsabs=1e-10 * abs(plain), epsrel=1e-8)[0]
    return 2 * total


def _independent_variances(tensor, geometry, probe, record=np.inf, components=(0, 1, 2)):
    """The lidar's variances of `components` (u, v, w) at the geometry's one gate and the
    point field's, from the pair covariances taken along their separations (above);
    only the pairs those components weight."""
    speed = geometry.speed
    length = tensor.length_scale
    k_lidar = np.geomspace(1e-6 / length, 1e4 / length, 161)
    k_point = np.geomspace(1e-6 / length, 1e7 / length, 209)
    rule = _plane_rule()
    directions = np.asarray(geometry.directions)
    first, second = np.triu_indices(geometry.n_beams)
    delta = (geometry.gate_centres[first, 0] - geometry.gate_centres[second, 0]
             - np.outer(speed * (geometry.times[first] - geometry.times[second]), [1, 0, 0]))
    highpass, width = None, None
    if np.isfinite(record) or geometry.dwell > 0:      # functions of k1 alone: H, dwell
        def highpass(k):
            return (record_filter(k * speed / (2 * np.pi), geometry.scan_period, record)
                    * np.sinc(k * speed * geometry.dwell / (2 * np.pi)) ** 2)
        width = 2 * np.pi / (speed * min(record, 1e9))
    covariance = np.zeros((geometry.n_beams, geometry.n_beams))
    r = np.asarray(geometry.reconstruction)[0][list(components)]
    axes = {}
    for p, (b, d) in enumerate(zip(first, second)):
        if np.all(np.abs(r[:, b] * r[:, d]) < 1e-12):
            continue
        size = np.linalg.norm(delta[p])
        # no separation: along the beam, where its probe is a function of k along it alone
        # (along x where H or the dwell, functions of k1, are taken along the axis)
        # (along x where H or the dwell, functions of k1, are taken along the axis, or
        # where the beam is vertical: the plane k3 = const meets k1 = k2 = 0, where the
        # sheared tensor is not defined)
        along_beam = directions[b] if highpass is None and abs(directions[b, 2]) < 0.99 \
            else np.array([1.0, 0, 0])
        axis = delta[p] / size if size > 1e-9 else along_beam
        key = tuple(np.round(axis * np.sign(axis[np.argmax(np.abs(axis))]), 9) + 0.0)
        axes.setdefault(key, []).append((p, b, d, size))
    for key, members in axes.items():
        if highpass is not None:    # H(k1) is a function of k along the axis: x only
            assert key == (1.0, 0.0, 0.0)
        # a plane holding the k1 axis (separations across the wind) meets the probes'
        # bands at all angles: 192 angles there (48 -> 96 -> 192 moved v's ratio by 4e-3,
        # then 1e-3; 192 -> 384 by < 3e-4)
        chi = _chi(tensor, key, [(b, d) for _, b, d, _ in members], directions, probe,
                   k_lidar, rule if key == (1.0, 0.0, 0.0) else _plane_rule(angles=192))
        for j, (p, b, d, size) in enumerate(members):
            covariance[b, d] = covariance[d, b] = _along(
                k_lidar, chi[:, j], size, highpass, width, speed, geometry.scan_period)
    lidar = np.einsum("cb,bd,cd->c", r, covariance, r)
    chi = _chi(tensor, [1, 0, 0], [(c, c) for c in components], np.eye(3),
               lambda k: np.ones_like(k), k_point, rule)
    point = None if highpass is None else (lambda k: record_filter(
        k * speed / (2 * np.pi), geometry.scan_period, record))        # no dwell
    true = np.array([_along(k_point, chi[:, j], 0.0, point, width, speed, geometry.scan_period)
                     for j in range(len(components))])
    return lidar, true


@pytest.fixture(scope="module")
def held_out():
    """The held-out scene: a fixed level pulsed DBS of 4 beams at 30 deg, gate 18.75 m,
    pulse 24.75 m, 1 s a beam, the wind along beam 0, Mann L 33.6 m, Gamma 3.9, I = 0.1:
    the spectral path and the independent integration, by (height, record)."""
    tensor = mann_tensor_for_intensity(0.1, SPEED, 33.6, 3.9)
    found = {}
    for height, record in ((40.0, 600.0), (100.0, 600.0), (200.0, 600.0), (200.0, 3600.0)):
        g = dbs_geometry([height], beam_duration=1.0, record=record)
        ours = mann_lidar_variances(g, tensor, probe_transfer_for(SATHE_PROBE, [height]))
        lidar, true = _independent_variances(
            tensor, g, lambda k: pulsed_transfer(k, 18.75, 24.75), record, components=(0,))
        found[height, record] = ours, lidar / true
    return found


@pytest.mark.parametrize("height, record", [(40.0, 600.0), (100.0, 600.0), (200.0, 600.0),
                                            (200.0, 3600.0)])
def test_held_out_dbs_ratios_against_an_independent_integration(held_out, height, record):
    ours, independent = held_out[height, record]
    # u (the beams in the wind's plane: their separation along x, 1 s apart): the
    # acceptance is 0.6 %; the independent integration's own rules hold ~3e-4, and the
    # spectral path's error estimate with them bounds the difference
    difference = abs(ours.ratios()[0, 0] - independent[0])
    assert difference <= 6e-3 * independent[0]
    if height < 200.0:
        # 40 and 100 m, where the former log-polar grid was resolved: within 0.1 % of the
        # independent integration (measured 7e-5; the former grid read 100 m 0.17 % low,
        # 40 m 0.03 %: that grid's error, not a change of the physics)
        assert difference <= 1e-3 * independent[0]
    assert difference <= ours.ratio_errors()[0, 0] + 3e-4 * independent[0]
    # Sathe et al. (2011): a pulsed DBS removes 5-45 % of the u-variance
    assert 0.55 < ours.ratios()[0, 0] < 0.95


def test_v_and_w_ratios_against_an_independent_integration():
    # the 5-beam DBS at 100 m (least squares: w from all five beams, so pairs 173 m apart
    # diagonally as well as along x and y), simultaneous beams, no record: the acceptance
    # is 0.6 %; the independent rules hold ~3e-4
    tensor = mann_tensor_for_intensity(0.1, SPEED, 33.6, 3.9)
    g = dataclasses.replace(dbs_geometry([100.0], vertical=True, record=np.inf),
                            times=np.zeros(5), dwell=0.0)
    ours = mann_lidar_variances(g, tensor, probe_transfer_for(SATHE_PROBE, [100.0]))
    lidar, true = _independent_variances(tensor, g, lambda k: pulsed_transfer(k, 18.75, 24.75))
    np.testing.assert_allclose(ours.ratios()[0], lidar / true, rtol=6e-3)
    assert np.all(np.abs(ours.ratios()[0] - lidar / true)
                  <= ours.ratio_errors()[0] + 3e-4 * lidar / true)


def test_refinement_moves_the_ratios_less_than_their_stated_error():
    # a pulsed DBS at 40-300 m (two beams up to 346 m apart), 600-s records: the ratios
    # of the default rules and of two refinements (two nodes more a panel; then a panel
    # more a decade) agree to 1e-3, and each change is within the stated error
    # (the study over 40, 100, 200, 300 m and a nacelle's previews: scripts/
    # spectral_convergence.py)
    tensor = mann_tensor_for_intensity(0.1, SPEED, 33.6, 3.9)
    heights = [40.0, 300.0]
    g = dbs_geometry(heights, beam_duration=1.0, vertical=True)
    transfer = probe_transfer_for(SATHE_PROBE, heights)
    default = mann_lidar_variances(g, tensor, transfer)
    assert default.converged
    for resolution in (PairResolution(2, 8),):
        finer = mann_lidar_variances(g, tensor, transfer, resolution)
        change = np.abs(finer.ratios() - default.ratios())
        assert np.all(change <= 1e-3 * default.ratios())
        assert np.all(change <= default.ratio_errors())


def test_ratio_falls_with_height_and_quadrature_probe_agrees_where_resolved(tensor):
    heights = [40.0, 100.0, 160.0]
    g = dbs_geometry(heights)
    analytic = mann_lidar_variances(g, tensor, probe_transfer_for(SATHE_PROBE, heights))
    assert np.all(np.diff(analytic.ratio()) < 0)      # a wider scan circle filters more
    # a 64-node probe quadrature resolves the pulsed transform to kappa = 0.4 rad/m
    # (What < 3e-3 beyond): the default (quadrature) transfer then agrees to 5e-3
    x, w = legendre(64)
    half = float(SATHE_PROBE.half_length(np.inf))
    weights = w * pulsed_weight(half * x, 18.75, 24.75)
    weights = np.tile(weights / weights.sum(), (3, 1))
    sampled = dataclasses.replace(g, probe_offsets=half * x, probe_weights=weights)
    np.testing.assert_allclose(mann_lidar_variances(sampled, tensor).ratio(),
                               analytic.ratio(), atol=5e-3)


def test_probe_transfers():
    kappa = np.linspace(0, 0.4, 41)
    # the pulsed transform against direct quadrature of the weighting
    direct = [integrate.quad(lambda s: pulsed_weight(s, 18.75, 24.75) * np.cos(k * s),
                             -200, 200, limit=400)[0] for k in kappa]
    np.testing.assert_allclose(pulsed_transfer(kappa, 18.75, 24.75), direct, atol=1e-9)
    # the cut Lorentzian tends to exp(-z_R |kappa|) as the cut widens: cut at c = 1000 z_R
    # the tail mass is m = (2/pi) atan(1/c) = 6.4e-4 and |What_cut - What| <= 2m / (1 - m)
    np.testing.assert_allclose(cut_lorentzian_transfer(kappa, 10.0, 1e4, nodes=4096),
                               lorentzian_transfer(kappa, 10.0), atol=1.3e-3)
    probe = ContinuousWaveProbe(1.565e-6, 0.028, 0.02)
    transfer = probe_transfer_for(probe, [100.0, 200.0])(kappa)
    assert transfer.shape == (2, 41) and np.all(transfer[:, 0] == pytest.approx(1.0))
    assert transfer[1, 10] < transfer[0, 10]          # farther focus, longer probe
    point = dbs_geometry([100.0])
    assert np.all(quadrature_transfer(point)(kappa) == 1.0)


def _kaimal(length_u=340.2):
    return KaimalSpectra((1.0, 0.8, 0.5), (length_u, length_u / 3, length_u / 12),
                         length_u, SPEED)


def test_staring_cw_beam_along_the_wind_closed_form():
    # F = (2/3) e^b E_5/3(b), b = 2 pi Gamma_CW / (3 L): the uncut Lorentzian of half width
    # z_R (nodes z_R tan(theta), theta at the midpoints of (-pi/2, pi/2), equal weights)
    z, n = 30.0, 200
    theta = ((np.arange(n) + 0.5) / n - 0.5) * np.pi
    g = ScanGeometry(np.array([[1.0, 0, 0]]), np.zeros((1, 1, 3)), np.zeros(1), 0.0, 1.0,
                     z * np.tan(theta), np.full((1, n), 1.0 / n),
                     np.array([1.0, 0, 0])[None, :, None], SPEED, np.inf)
    result = kaimal_lidar_variances(g, _kaimal())
    # 200 midpoint nodes of the uncut Lorentzian: 4e-4 from 400 and 800 nodes; the
    # frequency grid's truncation 2e-4: 2e-3 allowed
    assert result.lidar[0, 0] / result.true[0] == pytest.approx(
        staring_cw_kaimal_ratio(z, 340.2), rel=2e-3)
    b = 2 * np.pi * z / (3 * 340.2)
    direct = 2 / 3 * integrate.quad(lambda x: (1 + x) ** (-5 / 3) * np.exp(-b * x), 0,
                                    np.inf)[0]
    assert staring_cw_kaimal_ratio(z, 340.2) == pytest.approx(direct, rel=1e-10)


@pytest.mark.parametrize("block", [1.0, 4.0, 30.0])
def test_block_average_closed_form(block):
    # n beams along x one after another at the reference point, reconstruction their mean:
    # the block average of u over a scan of `block` seconds (midpoint rule, n = 200: error
    # (pi f T / n)^2 / 24 where the spectrum matters, < 1e-5)
    n = 200
    g = ScanGeometry(np.tile([[1.0, 0, 0]], (n, 1)), np.zeros((n, 1, 3)),
                     (np.arange(n) + 0.5) / n * block, 0.0, block, np.zeros(1), np.ones((1, 1)),
                     np.concatenate([np.full((1, 1, n), 1.0 / n), np.zeros((1, 2, n))], axis=1),
                     SPEED, np.inf)
    result = kaimal_lidar_variances(g, _kaimal())
    expected = kaimal_block_average_ratio(block, SPEED, 340.2)
    c = np.pi * block * SPEED / (6 * 340.2)
    direct = 2 / 3 * integrate.quad(lambda x: (1 + x) ** (-5 / 3) * np.sinc(c * x / np.pi) ** 2,
                                    0, np.inf, limit=1000)[0]
    assert expected == pytest.approx(direct, rel=1e-6)   # the Laplace form, Eq. (6)
    # the frequency grid (truncation 2e-4 of the variance on each side): 1e-3 allowed
    assert result.lidar[0, 0] / result.true[0] == pytest.approx(expected, rel=1e-3)


def test_harmonic_surge_closed_forms():
    a, period = 0.5, 7.0
    omega = 2 * np.pi / period
    # DBS, 4 beams 1 s apart: beams 0 and 2 (in the wind's plane) are 2 s apart
    g = dbs_geometry([100.0], beam_duration=1.0, record=np.inf)
    variance = harmonic_motion_variance(g, [a * omega, 0, 0], period)[0, 0]
    assert variance == pytest.approx(dbs_surge_variance(a, period, 2.0), rel=1e-12)
    # VAD: 720 lines of sight in one 1-s revolution (beam along the wind at t = 0), least
    # squares = the Fourier coefficient; the midpoint sum differs from Eq. (8) by O(n^-2)
    n, scan = 720, 1.0
    az = 2 * np.pi * (np.arange(n) + 0.5) / n
    phi = np.radians(30.0)
    d = np.stack([np.sin(phi) * np.cos(az), np.sin(phi) * np.sin(az), np.full(n, np.cos(phi))], -1)
    vad = ScanGeometry(d, np.zeros((n, 1, 3)), az / (2 * np.pi) * scan, 0.0, scan, np.zeros(1),
                       np.ones((1, 1)), np.linalg.pinv(d)[None], SPEED, np.inf)
    variance = harmonic_motion_variance(vad, [a * omega, 0, 0], period)[0, 0]
    assert variance == pytest.approx(vad_surge_variance(a, period, scan), rel=1e-5)
    # the example: 0.5 m at 7 s under a 1-s VAD, 4 % below the unfiltered (a w)^2/2
    assert vad_surge_variance(a, period, scan) / ((a * omega) ** 2 / 2) == pytest.approx(
        0.925, abs=0.002)


def test_harmonic_record_variance_brute_force():
    # the record variance of the reconstructed u error, averaged over 8 phases (exact for
    # a sinusoid), equals Eq. (7) with the record's high-pass
    a, period, record = 0.3, 5.3, 40.0
    omega = 2 * np.pi / period
    g = dbs_geometry([80.0], beam_duration=0.7, vertical=True, record=record)
    n_scans = int(record // g.scan_period)
    phases = 2 * np.pi * np.arange(8) / 8
    t = np.arange(n_scans)[:, None, None] * g.scan_period + g.times[None, :, None]
    radial = -g.directions[:, 0][None, :, None] * a * omega * np.cos(omega * t + phases)
    u = np.einsum("b,sbp->sp", g.reconstruction[0, 0], radial)
    brute = np.mean(np.var(u, axis=0))
    assert harmonic_motion_variance(g, [a * omega, 0, 0], period)[0, 0] == pytest.approx(
        brute, rel=1e-10)


def test_dispatch_and_cpu_work(tensor):
    g = dbs_geometry([100.0])
    assert lidar_variances(g, tensor).lidar.shape == (1, 3)
    assert lidar_variances(g, _kaimal()).true.shape == (3,)
    with pytest.raises(TypeError, match="unknown turbulence model"):
        lidar_variances(g, object())


def test_beam_pairs_and_component_vectors_agree(tensor, monkeypatch):
    # the two evaluations of Eq. (2)-(3) (beam pairs with Filon weights on Cartesian
    # rules; the vectors G_c with their phases at the nodes of the log-polar grid) agree
    # within their stated errors where the polar grid resolves the phases (beams up to
    # 140 m apart)
    from uq.physics import lidarspectral
    g = dbs_geometry([60.0, 120.0], beam_duration=0.5, vertical=True)
    transfer = probe_transfer_for(SATHE_PROBE, [60.0, 120.0])
    by_pairs = mann_lidar_variances(g, tensor, transfer)
    monkeypatch.setattr(lidarspectral, "PAIR_BEAMS", 0)
    vectors = mann_lidar_variances(g, tensor, transfer)
    np.testing.assert_array_equal(vectors.true, by_pairs.true)
    assert np.all(np.abs(vectors.lidar - by_pairs.lidar)
                  <= vectors.lidar_error + by_pairs.lidar_error)


def test_kaimal_gates_with_their_nodes_side_by_side_equal_each_gate_alone():
    # a pulsed lidar's gates at different foci put every gate's probe nodes side by side,
    # each gate weighting only its own: each gate's variance must be that of the same
    # lidar with that gate alone (1e-12: the same terms, summed in another order)
    from uq.pipeline import records
    from uq.pipeline.scenario import load_scenario
    from uq.pipeline.shipped import scenario_path
    from uq.pipeline.turbulencesection import default_length_scale

    def variances(ranges):
        # Kaimal's own length scale at 100 m (IEC 61400-1: 8.1 Lambda_1), not the
        # scenario's Mann length, whose cells would not fit the records' box
        settings = load_scenario(scenario_path("sathe2011_ti"), {
            "turbulence.model": "kaimal", "lidar.ranges": ranges,
            "turbulence.length_scale": default_length_scale("kaimal", 100.0)}).settings
        return records.spectral_variances(settings)[0]
    both = variances([40.0, 100.0])
    for g, height in enumerate((40.0, 100.0)):
        alone = variances([height])
        np.testing.assert_allclose(both.lidar[g], alone.lidar[0], rtol=1e-12)


@pytest.mark.parametrize("sign", [1.0, -1.0])
def test_a_beam_staring_along_the_wind_sees_the_along_beam_probe_filter_alone(tensor, sign):
    # one pulsed beam along x (a nacelle lidar's boresight looks against the wind: -x),
    # u its radial velocity: k . n = +-k1, so the lidar's u-variance is the 1-D spectrum
    # F11(k1) filtered by |What(k1)|^2 and the record's high-pass: a 1-D integral on the
    # log-polar cross-section's 1-D spectra (not the Cartesian pair sums), with scipy's
    # adaptive quadrature in k1 over a cubic spline of log F11; within the stated error
    from scipy import interpolate as interp
    from uq.physics.lidarspectral import _one_dimensional_spectra
    g = ScanGeometry(np.array([[sign, 0, 0]]), np.array([[[sign * 120.0, 0, 0]]]),
                     np.zeros(1), 0.0, 1.0, np.zeros(1), np.ones((1, 1)),
                     np.array([[[sign], [0.0], [0.0]]]), SPEED, 600.0)
    ours = mann_lidar_variances(g, tensor, probe_transfer_for(SATHE_PROBE, [120.0]))
    k = np.geomspace(1e-6 / 33.6, 1e6 / 33.6, 241)
    f11 = np.concatenate([_one_dimensional_spectra(tensor, WavenumberGrid(33.6, angle_nodes=64,
                                                                          radius_per_decade=12),
                                                   k[i:i + 12])[:, 0, 0]
                          for i in range(0, k.size, 12)])
    spline = interp.CubicSpline(np.log(k), np.log(f11))

    def integral(filtered):
        def f(x):
            value = np.exp(spline(np.log(x))) * record_filter(x * SPEED / (2 * np.pi), 1.0,
                                                             600.0)
            return value * (pulsed_transfer(x, 18.75, 24.75) ** 2 if filtered else 1.0)
        edges = np.union1d(np.geomspace(k[0], k[-1], 49),
                           np.arange(1, 64) * np.pi / (SPEED * 600.0))
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", integrate.IntegrationWarning)
            return 2 * sum(integrate.quad(f, a, b, limit=200, epsrel=1e-9)[0]
                           for a, b in zip(edges[:-1], edges[1:]))
    expected = integral(True) / integral(False)
    # the stated error plus the spline's and the record peak's quadrature (~2e-4)
    assert abs(ours.ratios()[0, 0] - expected) <= ours.ratio_errors()[0, 0] + 2e-4 * expected
    assert 0.6 < expected < 0.95
