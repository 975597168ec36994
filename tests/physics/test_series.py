"""A measured motion record as its Fourier series, read from a random window."""
import numpy as np
import pytest

import uq
from uq.errors import DataFileError
from uq.physics.motion import Motion, degrees_of_freedom
from uq.physics.series import WindowStart, series_components

STEP = 0.1
TIMES = 3.0 + np.arange(2000) * STEP          # 200 s at 10 Hz, starting at 3 s


def record(rng=np.random.default_rng(2)):
    roll = np.deg2rad(4 * np.sin(2 * np.pi * TIMES / 5 + 0.3) + 0.5) \
        + 0.01 * rng.standard_normal(TIMES.size)
    heave = 0.8 * np.sin(2 * np.pi * TIMES / 8)
    return {"roll": roll, "heave": heave}


def test_all_harmonics_give_the_record_back():
    """Every harmonic kept: the series equals the record at its samples (less its mean),
    to rounding (1e-12 of a 0.07 rad roll), and nothing was dropped."""
    values = record()
    components, kept = series_components(TIMES, values, 1000)
    assert kept == pytest.approx(1.0, abs=1e-12)
    motion = Motion(components)
    value, _ = degrees_of_freedom(motion, motion.unit_phases(), TIMES[None])
    np.testing.assert_allclose(value["roll"][0], values["roll"] - values["roll"].mean(),
                               atol=1e-12)
    np.testing.assert_allclose(value["heave"][0], values["heave"], atol=1e-12)


def test_a_pure_sinusoid_is_one_harmonic_with_its_analytic_rate():
    """heave = 0.8 sin(2 pi t / 8): 200 s hold 25 periods, so one harmonic carries it;
    the rate is 0.8 (2 pi / 8) cos(.) exactly (no finite difference)."""
    components, kept = series_components(TIMES, {"heave": record()["heave"]}, 1)
    assert kept == pytest.approx(1.0, abs=1e-12)
    assert components[0].angular_frequency == pytest.approx(2 * np.pi / 8, rel=1e-12)
    motion = Motion(components)
    t = np.array([[0.37, 11.2]])
    _, rate = degrees_of_freedom(motion, motion.unit_phases(), t)
    np.testing.assert_allclose(rate["heave"], 0.8 * 2 * np.pi / 8 * np.cos(2 * np.pi * t / 8),
                               atol=1e-12)


def test_the_window_start_has_the_moments_of_random_phases():
    """Over a start uniform on [0, T) (here 4000 equally spaced starts: exact for
    harmonics of 1/T below 2000), c_k has mean 0, covariance I/2, no cross-covariance."""
    w = 2 * np.pi * np.array([1, 2, 5, 17]) / 200.0
    start = WindowStart(w, 200.0)
    tau = (np.arange(4000) + 0.5) / 4000 * 200.0
    c = np.stack([np.cos(tau[:, None] * w), np.sin(tau[:, None] * w)], axis=-1)
    flat = c.reshape(len(tau), -1)
    np.testing.assert_allclose(flat.mean(axis=0), 0, atol=1e-12)
    np.testing.assert_allclose(flat.T @ flat / len(tau), np.eye(8) / 2, atol=1e-12)
    assert start.mean() == 0 and start.std() == pytest.approx(1 / np.sqrt(2))


def test_a_record_in_a_scenario(tmp_path):
    """A record of pure sinusoids and the same harmonics with random phases give the same
    u of Vh (the window start moves all phases together, with the same moments);
    Monte Carlo at 2e4 trials: 3 x sqrt(2 / (4 N)) = 1.5 % on each."""
    import pandas as pd
    pd.DataFrame({"t": TIMES, "r": 4 * np.sin(2 * np.pi * TIMES / 5)}).to_csv(
        tmp_path / "rec.csv", index=False)
    base = {"wind": {"speed": 8.0, "direction": 30.0}, "correction": "none",
            "sampling": {"n": 20_000, "seed": 1}, "outputs": ["wind_speed"]}
    recorded = uq.run({**base, "motion": {"series": {"file": str(tmp_path / "rec.csv"),
                                                     "time": "t", "columns": {"roll": "r"}}}})
    harmonic = uq.run({**base, "motion": {"roll": {"amplitude": 4.0, "period": 5.0}}})
    assert float(recorded["wind_speed_mc_u"]) == pytest.approx(
        float(harmonic["wind_speed_mc_u"]), rel=2 * 3 * np.sqrt(2 / 80_000))
    assert float(recorded["wind_speed_gum_u"]) == pytest.approx(
        float(harmonic["wind_speed_gum_u"]), rel=1e-9)


@pytest.mark.parametrize("content, key", [
    ("t,r\n0,1\n0.1,2\n", "t"),                                    # too short
    ("t,r\n" + "".join(f"{0.1 * i * (1 + i % 2)},{i}\n" for i in range(40)), "t"),  # uneven
    ("t,r\n" + "".join(f"{0.1 * i},{'x' if i == 5 else i}\n" for i in range(40)), "r"),
    ("t,q\n" + "".join(f"{0.1 * i},{i}\n" for i in range(40)), "motion.series.columns"),
    ("time,r\n" + "".join(f"{0.1 * i},{i}\n" for i in range(40)), "motion.series.time: no "
     "column 't'"),                                # the time column is named by its key
])
def test_bad_records(tmp_path, content, key):
    (tmp_path / "rec.csv").write_text(content)
    with pytest.raises(DataFileError, match=key):
        uq.load_scenario({"motion": {"series": {"file": str(tmp_path / "rec.csv"),
                                                "time": "t", "columns": {"roll": "r"}}}})


def write_csv(path, times, values):
    path.write_text("t,r\n" + "".join(f"{t:.12g},{v:.12g}\n" for t, v in zip(times, values)))


def test_a_record_in_milliseconds_is_refused(tmp_path):
    """10 Hz samples with the time in ms (100 apart): refused, naming the time column and
    asking for seconds."""
    write_csv(tmp_path / "rec.csv", TIMES * 1000, 4 * np.sin(2 * np.pi * TIMES / 5))
    with pytest.raises(DataFileError, match=r"rec.csv: t: samples 100 apart.*seconds"):
        uq.load_scenario({"motion": {"series": {"file": str(tmp_path / "rec.csv"),
                                                "time": "t", "columns": {"roll": "r"}}}})


def test_a_record_of_slow_roll_is_warned_about(tmp_path, caplog):
    """1 kHz samples with the time in ms (1 apart, as if 1 Hz in s): a 5 s roll looks like
    a 5000 s one, far slower than waves: a warning names the column and what was
    expected; a record of a 5 s roll in seconds passes without one."""
    import logging
    times = np.arange(4000.0)
    write_csv(tmp_path / "ms.csv", times, 4 * np.sin(2 * np.pi * times / 5000))
    write_csv(tmp_path / "s.csv", TIMES, 4 * np.sin(2 * np.pi * TIMES / 5))
    with caplog.at_level(logging.WARNING, logger="uq.pipeline.motionsection"):
        for name in ("ms.csv", "s.csv"):
            uq.load_scenario({"motion": {"series": {"file": str(tmp_path / name),
                                                    "time": "t", "columns": {"roll": "r"}}}})
    assert len(caplog.records) == 1
    assert "ms.csv: column r (roll)" in caplog.text and "milliseconds" in caplog.text


def test_a_record_shorter_than_a_scan_is_refused(tmp_path):
    """20 s of record under a scan of 4 beams of 10 s (40 s): it would repeat within the
    scan; refused naming the time column. 40 s of record is accepted."""
    times = np.arange(200) * 0.1
    write_csv(tmp_path / "rec.csv", times, 4 * np.sin(2 * np.pi * times / 5))
    spec = {"motion": {"series": {"file": str(tmp_path / "rec.csv"), "time": "t",
                                  "columns": {"roll": "r"}}},
            "lidar": {"scan": {"beam_duration": 10.0}}}
    with pytest.raises(DataFileError, match=r"rec.csv: t: the record lasts 20 s, shorter "
                                            r"than one scan \(4 beams of 10 s\)"):
        uq.load_scenario(spec)
    uq.load_scenario({**spec, "lidar": {"scan": {"beam_duration": 5.0}}})
