"""An IMU log at 10 Hz with gaps cut into records (uq.campaign.imu): each record's
cross-spectra hold the motion's covariance; a record short of samples has no motion."""
import numpy as np
import pandas as pd
import pytest

from uq.campaign import imu, motion
from uq.campaign.config import load_campaign_config
from uq.campaign.motioninput import load_motion
from uq.campaign.recordsfile import load_records

from campaigns import write_campaign

RATE = 10.0
ROLL, HEAVE = np.radians(2.0), 0.5            # amplitudes [rad, m]
F_ROLL, F_HEAVE = 0.125, 0.1                  # [Hz]
LAG = np.radians(60.0)                        # heave lags roll's phase by 60 deg at f_roll


def log_table(start, seconds, gaps):
    """A roll at 0.125 Hz and heave at 0.1 Hz (plus a roll-coherent heave part at
    0.125 Hz, 60 deg later), samples every 0.1 s with the `gaps` (start, stop) [s] cut
    out; time stamps in UTC."""
    t = np.arange(0.0, seconds, 1.0 / RATE)
    keep = np.ones(t.size, bool)
    for a, b in gaps:
        keep &= ~((t >= a) & (t < b))
    t = t[keep]
    roll = ROLL * np.sin(2 * np.pi * F_ROLL * t)
    heave = HEAVE * np.sin(2 * np.pi * F_HEAVE * t) + 0.2 * np.sin(2 * np.pi * F_ROLL * t + LAG)
    stamps = pd.Timestamp(start) + pd.to_timedelta(t, unit="s")
    return pd.DataFrame({"time": stamps.strftime("%Y-%m-%dT%H:%M:%S.%fZ"),
                         "roll_deg": np.degrees(roll), "heave_m": heave})


def campaign_with_log(tmp_path, gaps):
    path = write_campaign(tmp_path, changes={"motion": {
        "kind": "imu", "file": "imu.csv", "time": "time", "rate": RATE,
        "columns": {"roll": "roll_deg", "heave": "heave_m"}}})
    log_table("2016-03-02 00:00", 3 * 600.0, gaps).to_csv(tmp_path / "imu.csv", index=False)
    config = load_campaign_config(path)
    return config, load_records(config.records)["time"].values[:3]


def test_each_record_holds_its_motion_covariance(tmp_path):
    """Record 0 whole, record 1 with a 90 s gap (two segments), record 2 with 7 min
    missing (30 % covered: no motion). The covariance of the kept records equals the
    signal's: roll A^2/2, heave (0.5^2 + 0.2^2)/2, their cross term 0.2 A exp(-i LAG) / 2,
    to the finite segments' edge effects (a few cycles that do not close: 2 %)."""
    config, times = campaign_with_log(tmp_path, [(600 + 200, 600 + 290), (1200 + 60, 1200 + 480)])
    found, outside, off = load_motion(config.motion, times)
    assert found.valid.tolist() == [True, True, False]
    assert np.all(outside[:2] < 1e-3)
    for record in (0, 1):
        power = found.power[record]
        shapes = found.shapes[found.shape[record]]
        matrix = np.einsum("k,kd,ke->de", power, shapes, np.conj(shapes))
        roll, heave = 0, 5
        assert matrix[roll, roll].real == pytest.approx(ROLL ** 2 / 2, rel=0.02)
        assert matrix[heave, heave].real == pytest.approx((HEAVE ** 2 + 0.2 ** 2) / 2, rel=0.02)
        # M_de = a_d conj(a_e) / 2 (uq.campaign.motion). Over the whole record the lines
        # close whole cycles (exact to rounding); over record 1's segments of 200 and 310 s
        # the 0.1 and 0.125 Hz lines are orthogonal only to 1 / (2 pi 0.025 Hz 310 s) =
        # 2 % of the product of their amplitudes
        tolerance = 1e-12 if record == 0 else 0.02 * ROLL * HEAVE / 2
        assert matrix[roll, heave] == pytest.approx(0.2 * ROLL * np.exp(-1j * LAG) / 2,
                                                    abs=tolerance)
    assert np.all(found.power[2] == 0)


def test_segments_split_at_gaps():
    times = np.concatenate([np.arange(0, 10, 0.1), np.arange(10.5, 20, 0.1)])
    assert imu.segments(times, RATE) == [(0, 100), (100, 195)]


def test_the_imu_motion_variance_is_the_harmonics_gum(tmp_path):
    """The log's motion through the campaign's model from its cross-spectra, against the
    GUM of its harmonics themselves: the coherent line at 0.125 Hz (roll and the heave 60
    deg after it) and the heave at 0.1 Hz. Whole cycles in the record: the cross-spectra
    hold the lines exactly at their own frequencies (2 % allowed for the rounding of the
    lines' power into neighbouring Fourier frequencies: none here, measured 1e-9)."""
    from uq.campaign import adapter, model
    from uq.pipeline.scenario import load_scenario
    config, times = campaign_with_log(tmp_path, [])
    found, _, _ = load_motion(config.motion, times[:1])
    lidar = load_scenario(tmp_path / "lidar.yaml").settings
    turbulence = {"model": "mann", "anisotropy": 3.9}
    heave = motion.statistics({"heave": np.array([HEAVE])}, {"heave": np.array([10.0])})
    imu_terms = model.direct_terms(lidar, 80.0, 33.6, turbulence, 600.0, 9.0, 250.0,
                                   found.take(np.array([0])))
    heave_terms = model.direct_terms(lidar, 80.0, 33.6, turbulence, 600.0, 9.0, 250.0, heave)
    # the coherent 0.2 m heave at the roll's frequency adds to the roll's line: compare
    # the line sums through the GUM of the whole 0.125 Hz component
    settings = adapter.gate_settings(lidar, [80.0], {**turbulence, "length_scale": 33.6},
                                     600.0, 9.0, 250.0)
    line = np.zeros(6, complex)
    line[0], line[5] = ROLL, 0.2 * np.exp(1j * LAG)
    coherent = np.abs(adapter.motion_jacobian(settings, np.array([F_ROLL]), line[None])[0]) ** 2 / 2
    high_pass = adapter.record_high_pass(F_ROLL, adapter.scan_period(settings), 600.0)
    expected = coherent * high_pass + heave_terms["motion_variance"]
    assert imu_terms["motion_variance"] == pytest.approx(expected, rel=0.02)
