"""Record mode through uq.run: the spectral path's turbulence intensities."""
import math

import numpy as np
import pytest

from uq.pipeline.runner import run

WIND = {"speed": 10.0, "direction": 180.0, "reference_height": 100.0}


def scenario(lidar, **extra):
    return {"wind": WIND, "lidar": {"scan": {"beam_duration": 1e-3}, **lidar},
            "turbulence": {"intensity": 0.1}, "sampling": {"method": "none"},
            "outputs": ["turbulence_intensity"], **extra}


def test_absent_turbulence_adds_nothing():
    ds = run({"sampling": {"method": "none"}, "outputs": ["wind_speed"]})
    assert not [name for name in ds.data_vars if name.startswith("turbulence_")]


def test_a_lidar_shrunk_to_a_point_sees_the_true_variance():
    # gates 0.1 m from the lidar at the reference height, point probe, beams 1 ms apart:
    # the beams sample the reference point. The difference from 1 is the structure
    # function of w across the opposite beams' separation r = 0.115 m, amplified by the
    # DBS's cot(theta)^2 / 4 = 0.75: about 0.75 (r / L)^(2/3) = 0.017 of the variance (L =
    # 33.6 m); 0.03 bounds it.
    ds = run(scenario({"height": 99.9, "ranges": [0.1], "half_cone": 30.0,
                       "vertical_beam": True}))
    assert float(ds["turbulence_intensity_u_ratio"]) == pytest.approx(1.0, abs=0.03)
    ratio = (ds["turbulence_intensity_spectral"] / ds["turbulence_intensity_true"]) ** 2
    assert float(ratio) == pytest.approx(float(ds["turbulence_intensity_u_ratio"]), rel=1e-12)
    for name in ("turbulence_intensity_true", "turbulence_intensity_spectral"):
        assert ds[name].attrs["units"] == "1" and ds[name].attrs["long_name"]


def test_probe_volume_lowers_the_apparent_variance():
    # Sathe et al. (2011), Fig. 6: a pulsed DBS at 100 m sees 5-45 % less u-variance
    # than a point; the point-probe DBS is above 1 (w leaks into u through cot(theta))
    point = run(scenario({"height": 0.0, "ranges": [100.0], "half_cone": 30.0,
                          "vertical_beam": True}))
    pulsed = run(scenario({"height": 0.0, "ranges": [100.0], "half_cone": 30.0,
                           "vertical_beam": True, "probe": {
                               "kind": "pulsed", "gate_length": 18.75, "pulse_fwhm": 24.75}}))
    assert 0.55 < float(pulsed["turbulence_intensity_u_ratio"]) < 0.95
    assert float(pulsed["turbulence_intensity_u_ratio"]) < \
        float(point["turbulence_intensity_u_ratio"])


def test_scan_errors_add_in_quadrature():
    # radial noise sigma_r on a 4-beam DBS with the wind along a beam pair: u_x =
    # (v_1 - v_3) / (2 sin theta) has variance sigma_r^2 / (2 sin^2 theta), which is the
    # variance of Vh (linear: the GUM of method none is exact here); it adds to the
    # filtered turbulence's variance, independent scan by scan
    sigma_r, cone = 0.2, 30.0
    ds = run(scenario({"height": 0.0, "ranges": [100.0], "half_cone": cone, "errors": {
        "radial_velocity": {"dist": "normal", "u": sigma_r}}},
        outputs=["wind_speed", "turbulence_intensity"]))
    noise = sigma_r ** 2 / (2 * math.sin(math.radians(cone)) ** 2) / WIND["speed"] ** 2
    expected = np.sqrt(ds["turbulence_intensity_spectral_turbulence"] ** 2 + noise)
    np.testing.assert_allclose(ds["turbulence_intensity_spectral"], expected, rtol=1e-12)
