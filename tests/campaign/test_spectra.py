"""A record's variance and its spread from per-wavenumber terms (uq.campaign.spectra),
against closed forms of a spectrum whose autocovariance is known, and against a
simulation of Gaussian records."""
import numpy as np
import pytest
from scipy import linalg, stats

from uq.campaign import correction, spectra
from uq.campaign.adapter import SpectralTerms
from uq.physics.spectraltensor import WavenumberGrid


def exponential_terms(sigma2, length, speed=8.0, scan=5.0, duration=600.0, lidar=None):
    """Terms of u with the autocovariance ``sigma2 exp(-|x| / length)`` (x = U tau): the
    one-sided density in k1 is ``sigma2 (2 / pi) length / (1 + (k1 length)^2)``; a term
    is half of it times the node's weight (the weights hold the factor 2)."""
    k1, weight = WavenumberGrid(length).k1()
    terms = weight * sigma2 / np.pi * length / (1.0 + (k1 * length) ** 2)
    return SpectralTerms(k1, terms if lidar is None else lidar * terms, terms, weight,
                         speed, scan, duration)


def test_the_covariance_between_scans_is_the_spectrum_transformed():
    """R(k T_s) of the exponential spectrum is sigma2 exp(-k U T_s / length) (its Fourier
    pair), to the quadrature's accuracy: 1e-3 of sigma2 (the grid's 12 nodes a decade
    and the fine grid's 16 points a period, both measured here well below that)."""
    terms = exponential_terms(1.7, 120.0)
    lags = np.arange(120) * 5.0
    np.testing.assert_allclose(spectra.scan_covariance(terms, 120),
                               1.7 * np.exp(-8.0 * lags / 120.0), atol=1.7e-3)


def test_the_record_variance_and_its_spread_of_white_noise():
    """White noise (no correlation between scans): <s^2> = (N-1)/N sigma^2 and var(s^2) =
    2 (N-1) sigma^4 / N^2, exactly (the chi-square of N - 1 degrees of freedom)."""
    n, sigma2 = 120, 0.3
    var = spectra.variance_of_variance(0.0, 0.0, sigma2, n)
    assert var == pytest.approx(2 * (n - 1) * sigma2 ** 2 / n ** 2, rel=1e-14)


def test_the_spread_matches_simulated_gaussian_records(rng):
    """Records drawn from the exponential covariance (Cholesky of the Toeplitz matrix):
    the sample variance of their s^2 against 2 spread <s^2>^2. 4000 records: the
    variance of a variance estimate of near-normal values has a relative standard error
    sqrt(2 / 4000) (~2.2 %, s^2 is skewed a little more); 4 standard errors allowed."""
    n, sigma2 = 120, 1.0
    terms = exponential_terms(sigma2, 120.0)
    covariance = linalg.toeplitz(spectra.scan_covariance(terms, n))
    records = rng.standard_normal((4000, n)) @ np.linalg.cholesky(covariance).T
    s2 = records.var(axis=1)
    expected_mean = np.trace(covariance - covariance.mean(axis=0)) / n
    assert s2.mean() == pytest.approx(expected_mean, rel=4 * s2.std() / np.sqrt(4000)
                                      / expected_mean)
    predicted = 2 * spectra.variance_spread(terms, n) * expected_mean ** 2
    assert s2.var(ddof=1) == pytest.approx(predicted, rel=4 * np.sqrt(2 / 4000) * 1.2)


def test_filtering_factor_is_the_ratio_of_the_record_variances():
    terms = exponential_terms(1.0, 80.0, lidar=0.8)
    assert spectra.filtering_factor(terms) == pytest.approx(0.8, rel=1e-12)
    lidar, point = spectra.record_variances(terms)
    high_pass = spectra.high_pass(terms)
    assert point == pytest.approx(np.sum(terms.point * high_pass), rel=1e-14)
    assert 0 < spectra.point_fraction(terms) < 1            # the record's high-pass


def test_the_interval_covers_simulated_records_as_often_as_it_says(rng):
    """The correction's interval (Neyman's construction on the scaled chi-square) of the
    variance of records simulated from a Gaussian process with white noise added: the
    share of 3000 intervals that hold the true variance is consistent with 95 % (two-
    sided binomial test at 1 %; the chi-square approximation's own error is below what
    3000 records resolve, +-0.8 % at 2 sigma)."""
    n, sigma2, noise = 120, 0.5, 0.02
    terms = exponential_terms(sigma2, 150.0)
    covariance = linalg.toeplitz(spectra.scan_covariance(terms, n))
    lidar = np.trace(covariance - covariance.mean(axis=0)) / n
    spread = spectra.variance_spread(terms, n)
    records = rng.standard_normal((3000, n)) @ np.linalg.cholesky(covariance).T
    records += np.sqrt(noise) * rng.standard_normal(records.shape)
    std = records.std(axis=1, ddof=1)
    out = correction.correct(np.full(3000, 10.0), std, 1.0, spread, 0.0, 0.0, noise, n,
                             ddof=1)
    low, high = out["variance_corrected"], None
    ends = [correction.interval_end(*correction.lidar_part(std, 0.0, noise, n, 1), spread,
                                    noise, n, p) for p in (0.975, 0.025)]
    low = np.where(np.isnan(ends[0]), 0.0, ends[0])
    covered = np.sum((lidar >= low) & (lidar <= ends[1]))
    assert stats.binomtest(int(covered), 3000, 0.95).pvalue > 0.01, covered / 3000


def test_the_motions_cross_term_in_the_spread(rng):
    """Gaussian records plus a harmonic of random phase at 0.013 Hz (where this
    turbulence's cross response is large) and white noise: the sample variance of s^2
    over 6000 records against the formula with its cross terms, within 4 standard errors
    (sqrt(2 / 6000) relative, with 20 % for s^2's skew); without the cross terms it is
    29 % lower."""
    n, scan, amplitude, noise = 120, 5.0, 1.2, 0.05
    terms = exponential_terms(1.0, 300.0)
    covariance = spectra.scan_covariance(terms, n)
    c = linalg.toeplitz(covariance)
    records = rng.standard_normal((6000, n)) @ np.linalg.cholesky(c).T
    phase = rng.uniform(0, 2 * np.pi, (6000, 1))
    times = np.arange(n) * scan
    records += amplitude * np.sin(2 * np.pi * 0.013 * times + phase)
    records += np.sqrt(noise) * rng.standard_normal(records.shape)
    s2 = records.var(axis=1)
    lidar = (n * covariance[0] - np.sum(c) / n) / n
    harmonic = amplitude ** 2 / 2
    high_pass = float(spectra.record_high_pass(0.013, scan, n * scan))
    cross = harmonic * spectra.cross_response(covariance, scan, np.array([0.013]))[0]
    predicted = spectra.variance_of_variance(lidar, spectra.toeplitz_spread(covariance), noise,
                                             n, cross, harmonic * high_pass)
    assert s2.var(ddof=1) == pytest.approx(predicted, rel=4 * np.sqrt(2 / 6000) * 1.2)
    assert spectra.variance_of_variance(lidar, spectra.toeplitz_spread(covariance), noise,
                                        n) < 0.75 * predicted      # the cross terms: 29 %
