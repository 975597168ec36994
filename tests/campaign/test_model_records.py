"""The correction against records that hold exactly what its model says: the lidar's
turbulence a Gaussian series of the spectral path's covariance between scans, the
platform's motion the time-resolved measurement model's own speed error scan by scan
(its JONSWAP sea with random phases advancing from scan to scan, nonlinear), white
radial noise. Its intervals, its mean bias and the measured TI's predicted bias hold
on them; the shipped campaign's Monte Carlo records add the turbulence box's own
deficit (tests/campaign/test_campaign_buoy.py)."""
import numpy as np
import pytest
from scipy import linalg, special, stats

from uq.campaign import adapter, correction, model, motion, spectra
from uq.pipeline.scenario import load_scenario

from campaigns import LIDAR

RECORDS = 400
SPEED, DIRECTION, HEIGHT = 9.0, 250.0, 60.0
TURBULENCE = {"model": "mann", "length_scale": 33.6, "anisotropy": 3.9}


@pytest.fixture(scope="module")
def records():
    return model_records()


def model_records():
    """400 records at 60 m of a wind of 9 m/s: TI 6-16 %, Hs 0.5-3.5 m (Tp 6.5 s), each
    corrected with the model's terms (the direct path's, once: one wind)."""
    rng = np.random.default_rng(37)
    lidar = load_scenario(LIDAR).settings
    settings = adapter.gate_settings(lidar, [HEIGHT], TURBULENCE, 600.0, SPEED, DIRECTION)
    terms = adapter.spectral_terms(settings).gate(0)
    n = adapter.scans_per_record(settings)
    covariance = spectra.scan_covariance(terms, n)              # at intensity 0.1
    factor = linalg.cholesky(linalg.toeplitz(covariance), lower=True)
    lidar_record, point_record = spectra.record_variances(terms)
    noise = adapter.scan_noise_variance(settings)
    response = {d: (v["factor"], v["lag"]) for d, v in lidar["motion"]["response"].items()}
    truth = rng.uniform(0.06, 0.16, RECORDS)                    # TI over N - 1 scans
    hs = rng.uniform(0.5, 3.5, RECORDS)
    sea = motion.sea_state(hs, np.full(RECORDS, 6.5), response, 3.3, 24, (0.5, 4.0))
    shape = sea.shapes[0]
    y = adapter.motion_jacobian(settings, sea.frequency[0], np.tile(shape, (24, 1)))
    g = 2 * adapter.motion_shift(settings, sea.frequency[0], np.tile(shape, (24, 1)))
    q = spectra.cross_response(covariance, terms.scan_period,
                               spectra.folded(sea.frequency[0], terms.scan_period))
    components = adapter.components_of(sea.frequency[0], np.tile(shape, (24, 1)))
    times = np.arange(n) * terms.scan_period
    out = {"truth": truth, "measured": [], "terms": []}
    for r in range(RECORDS):
        # the terms are of a field of intensity 0.1: the field whose point record
        # variance over N - 1 scans is (TI U)^2 is theirs times this ratio of sigmas
        scale = truth[r] * SPEED * np.sqrt((n - 1) / n / point_record)
        turbulence = factor @ rng.standard_normal(n) * scale
        amplitude = np.sqrt(2 * sea.power[r])
        start = rng.uniform(0, 2 * np.pi, 24)
        phase = start + 2 * np.pi * sea.frequency[0] * times[:, None]
        unit = np.stack([np.cos(phase), np.sin(phase)], axis=-1) * amplitude[None, :, None]
        speed = adapter.scan_speeds(settings, components, np.concatenate([unit, np.zeros(
            (1, 24, 2))]))
        series = speed[:-1] - speed[-1] + SPEED + turbulence + np.sqrt(noise) * \
            rng.standard_normal(n)
        out["measured"].append((series.mean(), series.std(ddof=1)))
        found = model.motion_terms(y, g, q, sea.power[r], sea.frequency[0],
                                   terms.scan_period, 600.0, True)
        out["terms"].append(found)
    measured = np.array(out["measured"])
    terms_of = {name: np.array([t[name] for t in out["terms"]]) for name in out["terms"][0]}
    corrected = correction.correct(measured[:, 0], measured[:, 1],
                                   spectra.filtering_factor(terms),
                                   spectra.toeplitz_spread(covariance),
                                   terms_of["motion_variance"], terms_of["motion_bias"], noise,
                                   n, 1, motion_cross=terms_of["motion_cross"],
                                   motion_phase=terms_of["motion_phase"])
    return {"truth": truth, "measured": measured, "corrected": corrected, "n": n,
            "filtering": spectra.filtering_factor(terms), "terms": terms_of, "noise": noise,
            "spread": spectra.toeplitz_spread(covariance)}


def test_the_intervals_cover_the_truth_as_often_as_they_say(records):
    """Two-sided binomial test of the share of 400 intervals that hold the true TI
    against 95 %, at the 1 % level."""
    c = records["corrected"]
    covered = (records["truth"] >= c["turbulence_intensity_corrected_low"]) & \
        (records["truth"] <= c["turbulence_intensity_corrected_high"])
    assert np.isfinite(c["turbulence_intensity_corrected"]).all()
    assert stats.binomtest(int(covered.sum()), RECORDS, 0.95).pvalue > 0.01, covered.mean()


def test_the_corrected_mean_bias_is_zero_within_its_stated_uncertainty(records):
    """mean(TI - TI_true) within 3 of its stated u, sqrt(sum u_i^2) / n (the records
    independent); the estimator's own bias (the square root of a variance estimate, its
    relative variance ~0.03-0.1: -1 % of TI) is below that u."""
    c = records["corrected"]
    bias = np.mean(c["turbulence_intensity_corrected"] - records["truth"])
    u = np.sqrt(np.sum(c["turbulence_intensity_corrected_u"] ** 2)) / RECORDS
    assert abs(bias) <= 3 * u, (bias, u)


def test_the_measured_ti_is_high_as_the_model_predicts(records):
    """Uncorrected, the TI is the motion's and the filtering's: its mean bias against
    the truth has the sign and size the model predicts (the mean of each record's
    predicted TI, correction.predicted_measured), within 3 standard errors of the
    records' own spread (the second-order delta method: its neglected fourth order is
    below 1e-3 of TI here)."""
    c, n = records["corrected"], records["n"]
    terms = records["terms"]
    mean, spread = correction.predicted_measured(
        records["truth"], c["wind_speed_corrected"], records["filtering"],
        records["spread"], terms["motion_variance"], records["noise"], n, 1,
        terms["motion_cross"], terms["motion_phase"])
    measured = c["turbulence_intensity_measured"]
    predicted_bias = np.mean(mean - records["truth"])
    assert predicted_bias > 0.01                      # the motion wins: +1 percentage point
    se = np.sqrt(np.sum(spread ** 2)) / RECORDS
    assert np.mean(measured - records["truth"]) == pytest.approx(predicted_bias, abs=3 * se)
