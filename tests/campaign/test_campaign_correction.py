"""One record corrected (uq.campaign.correction): the identity, the motion alone, the
inversion of Eq. 1, the interval's ends, records the model cannot take."""
import numpy as np
import pytest
from scipy import optimize

from uq.campaign import correction, spectra

N = 120


def correct(**changes):
    arguments = dict(speed=np.array([8.0, 10.0, 12.5]), std=np.array([0.6, 1.1, 0.9]),
                     filtering=1.0, spread=0.03, motion_variance=0.0, motion_bias=0.0,
                     noise_variance=0.0, n_scans=N, ddof=1)
    arguments.update(changes)
    return correction.correct(**arguments)


@pytest.mark.parametrize("ddof", [0, 1])
def test_without_motion_filtering_or_scan_errors_the_correction_is_the_identity(ddof):
    out = correct(ddof=ddof)
    np.testing.assert_allclose(out["turbulence_intensity_corrected"],
                               out["turbulence_intensity_measured"], rtol=1e-14)
    np.testing.assert_array_equal(out["wind_speed_corrected"], [8.0, 10.0, 12.5])
    assert np.all(out["turbulence_intensity_corrected_low"]
                  < out["turbulence_intensity_corrected"])
    assert np.all(out["turbulence_intensity_corrected"]
                  < out["turbulence_intensity_corrected_high"])


def test_motion_alone_subtracts_its_variance():
    """TI^2 U^2 (N - ddof) / N = s^2 (N - ddof) / N - V_m: the variance over N scans
    less the motion's, given back over N - ddof; the mean less the bias."""
    motion = np.array([0.05, 0.4, 0.2])
    out = correct(motion_variance=motion, motion_bias=np.array([0.01, 0.02, -0.01]))
    speed = np.array([8.0, 10.0, 12.5]) - [0.01, 0.02, -0.01]
    expected = np.sqrt((np.array([0.6, 1.1, 0.9]) ** 2 * (N - 1) / N - motion) * N / (N - 1)) \
        / speed
    np.testing.assert_allclose(out["turbulence_intensity_corrected"], expected, rtol=1e-14)
    np.testing.assert_allclose(out["wind_speed_corrected"], speed, rtol=1e-15)


def test_the_filtering_factor_and_the_scan_errors_are_inverted():
    out = correct(filtering=0.8, motion_variance=0.1, noise_variance=0.01)
    variance = (np.array([0.6, 1.1, 0.9]) ** 2 * (N - 1) / N - 0.1 - 0.01 * (N - 1) / N) / 0.8
    np.testing.assert_allclose(out["variance_corrected"], variance, rtol=1e-14)


def test_the_interval_ends_solve_their_quantile_equations():
    """Each end is the variance under which the record's x is the 2.5 % (97.5 %)
    quantile of its scaled chi-square: checked by a root finder of its own."""
    spread, noise = 0.03, 0.02
    x, noise_part = correction.lidar_part(np.array([1.0]), 0.1, noise, N, 1)

    def quantile_gap(lidar, p):
        mean = lidar + noise_part
        var = spectra.variance_of_variance(lidar, spread, noise, N)
        dof = spectra.degrees_of_freedom(mean, var)
        return mean * correction.chi_square_quantile(p, dof) - x[0]
    for p in (0.025, 0.975):
        found = correction.interval_end(x, noise_part, spread, noise, N, p)[0]
        expected = optimize.brentq(quantile_gap, 1e-9, 10.0, args=(p,), xtol=1e-14)
        # the fixed point stops at a relative step of 1e-9
        assert found == pytest.approx(expected, rel=1e-8)


def test_a_record_with_less_variance_than_its_motion_is_nan():
    out = correct(std=np.array([0.1, 1.1, 0.9]), motion_variance=0.5)
    assert np.isnan(out["turbulence_intensity_corrected"][0])
    assert not out["consistent"][0] and out["consistent"][1:].all()
    assert np.isfinite(out["turbulence_intensity_corrected"][1:]).all()


def test_a_small_variance_keeps_a_lower_end_at_zero():
    """x within the central 95 % of what the scan errors alone give at V = 0 (x = 1.07
    times their mean; N - 1 = 119 degrees of freedom put the 97.5 % quantile at ~1.25):
    a consistent record whose interval reaches down to zero TI."""
    out = correct(std=np.array([0.3]), speed=np.array([8.0]), motion_variance=0.085,
                  noise_variance=0.004)
    assert out["consistent"][0]
    assert out["turbulence_intensity_corrected_low"][0] == 0.0
    assert out["turbulence_intensity_corrected_high"][0] > 0.0


def test_stated_uncertainties_of_the_filtering_and_motion_widen_the_interval():
    plain = correct(filtering=0.8, motion_variance=0.1)
    wide = correct(filtering=0.8, motion_variance=0.1, filtering_u=0.05, motion_u=0.2)
    assert np.all(wide["turbulence_intensity_corrected_high"]
                  > plain["turbulence_intensity_corrected_high"])
    assert np.all(wide["turbulence_intensity_corrected_low"]
                  < plain["turbulence_intensity_corrected_low"])
    assert np.all(wide["turbulence_intensity_corrected_u"]
                  > plain["turbulence_intensity_corrected_u"])
    np.testing.assert_array_equal(wide["turbulence_intensity_corrected"],
                                  plain["turbulence_intensity_corrected"])


def test_flag_bits_are_distinct_powers_of_two():
    bits = [bit for bit, _, _, _ in correction.FLAGS]
    assert sorted(bits) == [2 ** i for i in range(len(bits))]
    assert correction.INVALIDATING & correction.FLAG_BITS["motion_clause8"] == 0
