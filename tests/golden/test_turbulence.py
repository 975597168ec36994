"""TI KPIs of a verification campaign and the TI uq predicts (uq.golden.turbulence)."""
import numpy as np
import pytest

from uq.cli import main
from uq.errors import ScenarioError
from uq.golden.config import _turbulence
from uq.golden.kpi import BEST, FAIL, MINIMUM, NO_DATA
from uq.golden.turbulence import (INFORMATIONAL, band_verdicts, predicted_variance_ratio,
                                  representative_ti, scenario_geometry, ti_bin_kpis)
from uq.pipeline.scenario import Checker
from uq.physics.lidarspectral import mann_lidar_variances, probe_transfer_for
from uq.physics.probe import PulsedProbe
from uq.physics.spectraltensor import mann_tensor_for_intensity


def test_bin_kpis_by_hand():
    ref = np.array([10.0, 12.0, 8.0, 9.0, np.nan, 11.0])
    unit = np.array([11.0, 12.5, 7.0, 9.5, 10.0, np.nan])
    speed = np.array([5.1, 4.9, 5.2, 8.0, 5.0, 5.0])
    out = ti_bin_kpis(ref, unit, speed, [5.0, 8.0, 12.0], 0.5)
    # bin 5: pairs (10, 11), (12, 12.5), (8, 7); the NaN records are left out
    d = np.array([1.0, 0.5, -1.0])
    assert out["n_records"].tolist() == [3, 1, 0]
    assert out["mean_bias"][0] == pytest.approx(d.mean())
    assert out["relative_error"][0] == pytest.approx(d.mean() / 10.0)
    assert out["rmse"][0] == pytest.approx(np.sqrt(np.mean(d ** 2)))
    rep = (lambda x: np.mean(x) + 1.28 * np.std(x, ddof=1))
    assert out["representative_error"][0] == pytest.approx(rep([11, 12.5, 7]) - rep([10, 12, 8]))
    assert np.isnan(out["representative_error"][1])        # one record: no sd
    assert np.isnan(out["mean_bias"][2])
    assert representative_ti([1.0, 3.0]) == pytest.approx(2.0 + 1.28 * np.sqrt(2.0))


def test_band_verdicts():
    values = [0.1, -0.4, 0.9, np.nan]
    assert band_verdicts(values, None).tolist() == [INFORMATIONAL] * 3 + [NO_DATA]
    assert band_verdicts(values, (0.2, 0.5)).tolist() == [BEST, MINIMUM, FAIL, NO_DATA]


def test_bands_are_validated():
    check = Checker("campaign.yaml")
    assert _turbulence(check, {"bands": {"rmse": [1.0, 2.0]}})["ti_bands"] == {"rmse": (1.0, 2.0)}
    with pytest.raises(ScenarioError, match="golden.kpi.turbulence.bands.rmse"):
        _turbulence(check, {"bands": {"rmse": [2.0, 1.0]}})
    with pytest.raises(ScenarioError, match="golden.kpi.turbulence.bands"):
        _turbulence(check, {"bands": {"bias": [1.0, 2.0]}})


def test_bad_band_exits_2_with_one_line(tmp_path, capsys):
    bad = tmp_path / "bad.yaml"
    bad.write_text("golden: {name: x, kpi: {turbulence: {bands: {rmse: [3, 1]}}}, "
                   "synthetic: {lidars: {unit: a.yaml, golden: b.yaml}}}\n")
    assert main(["golden", str(bad), "-o", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err
    assert "bad.yaml" in err and "golden.kpi.turbulence.bands.rmse" in err
    assert len(err.strip().splitlines()) == 1


def _settings(direction=250.0, heading=250.0, probe=None, duration=0.001):
    lidar = {"height": 0.0, "ranges": [100.0], "half_cone": 30.0,
             "azimuths": [0, 90, 180, 270], "vertical_beam": True,
             "scan": {"beam_duration": duration}}
    if probe:
        lidar["probe"] = probe
    return {"wind": {"direction": direction}, "ship": {"heading": heading}, "lidar": lidar}


def test_scenario_geometry_convention():
    # heading 250, azimuth 0: the first beam points towards 250 deg, where a wind "from"
    # 250 comes from: upwind, -x in the mean-wind frame; azimuth 90 points to 340 deg,
    # 90 deg counter-clockwise (seen from above) of the downwind 70 deg: +y
    geometry, slant = scenario_geometry(_settings(), 100.0, 10.0)
    np.testing.assert_allclose(geometry.directions[0], [-0.5, 0.0, np.sqrt(0.75)], atol=1e-12)
    np.testing.assert_allclose(geometry.directions[1], [0.0, 0.5, np.sqrt(0.75)], atol=1e-12)
    assert slant == pytest.approx(100.0 / np.sqrt(0.75))
    np.testing.assert_allclose(geometry.gate_centres[:, 0, 2], 0.0, atol=1e-12)


def test_prediction_is_the_spectral_path_of_the_held_out_scene():
    # the held-out DBS (pulsed 18.75 / 24.75 m, 1 ms beams, wind along a beam) at 100 m in
    # the IEC Mann field (L = 33.6 m above 60 m, Gamma 3.9): the same ratio as the spectral
    # path for the mirrored scan (wind blowing along beam 0 instead of towards it: the DBS is
    # mirror-symmetric, only the beams' order differs, 1 ms apart: < 1e-4 measured 4e-5)
    probe = {"kind": "pulsed", "gate_length": 18.75, "pulse_fwhm": 24.75}
    ratio = predicted_variance_ratio(_settings(probe=probe), 100.0, 10.0)
    geometry, slant = scenario_geometry(_settings(direction=180.0, heading=0.0), 100.0, 10.0)
    direct = mann_lidar_variances(geometry, mann_tensor_for_intensity(0.1, 10.0, 33.6, 3.9),
                                  probe_transfer_for(PulsedProbe(18.75, 24.75), [slant]))
    assert ratio == pytest.approx(float(direct.ratio()[0]), rel=1e-4)
    assert 0.75 < ratio < 0.9      # tests/physics/test_lidarspectral.py: 0.826 at 100 m
