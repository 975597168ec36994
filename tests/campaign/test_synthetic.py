"""The shipped synthetic campaign's mast: what an ideal cup reads of a record's field."""
import numpy as np
import pytest


def _record_u_and_v(speed, scan, duration):
    """(u, v) record variances and the whole point v-variance of a unit Mann field of
    the campaign's L and Gamma, by the spectral path's own quadrature (a second
    implementation of the record's high-pass, uq.physics.lidarspectral)."""
    from uq.campaign.synthetic import TURBULENCE
    from uq.physics.lidarspectral import _point_matrix
    from uq.physics.scangeometry import ScanGeometry
    from uq.physics.spectraltensor import MannTensor, point_variances
    tensor = MannTensor(TURBULENCE["length_scale"], TURBULENCE["anisotropy"])
    point = ScanGeometry(np.array([[1.0, 0, 0]]), np.zeros((1, 1, 3)), np.zeros(1), 0.0,
                         scan, np.zeros(1), np.ones((1, 1)), np.ones((1, 3, 1)), speed,
                         duration)
    record = _point_matrix(point, tensor, dwell=False)
    return record[0, 0], record[1, 1], point_variances(tensor)[1]


@pytest.mark.parametrize("speed, ti", [(4.0, 0.20), (8.0, 0.14), (14.0, 0.10)])
def test_the_cup_reads_the_mean_vector_plus_the_lateral_turbulence_s_share(speed, ti):
    # the cup's mean is U + sigma_v^2 / (2 U), sigma_v^2 the whole point v-variance of the
    # field whose record u-variance (N - 1 scans) is (TI U)^2: against the spectral
    # path's record variances (another quadrature of the same tensor: 0.5 % of the
    # shift, the two quadratures' ~0.1 % apart); the standard deviation's fourth-order
    # lateral terms raise it by less than TI^2 of itself
    from uq.campaign import synthetic
    scan, duration = 4.0, 600.0
    mean, deviation = synthetic.cup_reading(np.array([speed]), np.array([ti]), scan, duration)
    n = int(duration / scan)
    u_record, _, v_whole = _record_u_and_v(speed, scan, duration)
    scale = (ti * speed) ** 2 * (n - 1) / n / u_record
    assert mean[0] - speed == pytest.approx(v_whole * scale / (2 * speed), rel=5e-3)
    assert 1.0 < deviation[0] / (ti * speed) < 1.0 + ti ** 2


def test_the_cup_s_second_order_mean_is_the_gaussian_field_s():
    # Monte Carlo of the exact reading |(U + u, v)| for Gaussian u, v of the variances
    # cup_reading states (TI 0.2 at 4 m/s, the campaign's most turbulent records): its
    # mean within 4 standard errors of 2e6 draws plus the fourth-order terms the
    # second-order value leaves out, sigma_v^2 sigma_u^2 / (2 U^3) - 3 sigma_v^4 / (8 U^3)
    # (the expansion of a (1 + v^2 / a^2)^(1/2), a = U + u, one order further)
    from uq.campaign import synthetic
    speed, ti = 4.0, 0.20
    mean, _ = synthetic.cup_reading(np.array([speed]), np.array([ti]), 4.0)
    v_whole, u_whole = 2.0 * speed * (mean[0] - speed), (ti * speed) ** 2
    rng = np.random.default_rng(5)
    u = rng.standard_normal(2_000_000) * np.sqrt(u_whole)
    v = rng.standard_normal(2_000_000) * np.sqrt(v_whole)
    reading = np.hypot(speed + u, v)
    error = reading.std() / np.sqrt(reading.size)
    fourth = abs(v_whole * u_whole / 2 - 3 * v_whole ** 2 / 8) / speed ** 3
    assert abs(reading.mean() - mean[0]) <= 4 * error + fourth
    assert mean[0] - speed > 10 * (4 * error + fourth)      # the share it tests is seen


def test_the_cup_is_nan_where_the_mast_is():
    from uq.campaign import synthetic
    mean, deviation = synthetic.cup_reading(np.array([np.nan, 8.0]), np.array([0.1, np.nan]),
                                            4.0)
    assert np.all(np.isnan(mean)) and np.all(np.isnan(deviation))
