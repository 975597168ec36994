"""The spectral path's rules: Filon weights, interpolation and the record's high-pass
against scipy's adaptive quadrature (QUADPACK)."""
import numpy as np
import pytest
from scipy import integrate

from uq.physics.spectralquadrature import (PanelRule, geometric_edges, mean_window,
                                           record_scans, record_weights, symmetric_edges)


def smooth(k):
    return np.exp(-k ** 2) / (1.0 + k)


def _quad(f, a, b, delta, points=None):
    """integral_a^b f(k) exp(i k delta) dk by QUADPACK (QAWO for the oscillating part)."""
    if delta == 0:
        return integrate.quad(f, a, b, limit=2000, points=points)[0]
    return (integrate.quad(f, a, b, weight="cos", wvar=delta, limit=2000)[0]
            + 1j * integrate.quad(f, a, b, weight="sin", wvar=delta, limit=2000)[0])


@pytest.mark.parametrize("delta", [0.0, 1.0, 50.0, 300.0, -231.0])
def test_filon_weights_integrate_any_separation(delta):
    # 16 panels of 8 nodes on [0, 3]: the error is the smooth part's interpolation error
    # alone (the exponential is exact): < 1e-9 of the integral's scale (0.6) whatever
    # delta, where 8 plain Gauss nodes a panel would need ~delta h / 2 (h up to 0.6)
    rule = PanelRule(geometric_edges(0.01, 3.0, 6), 8)
    assert smooth(rule.nodes) @ rule.filon(delta) == pytest.approx(
        _quad(smooth, 0, 3, delta), abs=1e-9)


def test_filon_weights_are_gauss_legendre_without_a_phase_and_symmetric_rules():
    rule = PanelRule(symmetric_edges(geometric_edges(1e-3, 10.0, 8)), 8)
    np.testing.assert_allclose(rule.filon(0.0).real, rule.weights, rtol=1e-14, atol=1e-18)
    assert rule.nodes[0] > -10 and rule.nodes[-1] < 10 and np.all(np.diff(rule.nodes) > 0)
    # an even function on a symmetric rule: the sine part vanishes to rounding, the
    # cosine part is the closed form sqrt(pi) exp(-delta^2 / 4) = 8.5e-6 (the Gaussian's
    # interpolation on panels up to 1.3 wide: < 1e-10)
    even = rule.filon(7.0) @ np.exp(-rule.nodes ** 2)
    assert abs(even.imag) < 1e-14 and even.real == pytest.approx(
        np.sqrt(np.pi) * np.exp(-49 / 4), abs=1e-10)


def test_interpolation_reproduces_polynomials_of_the_panels_degree():
    rule = PanelRule(geometric_edges(0.1, 5.0, 2), 6)
    points = np.linspace(0, 5, 37)
    cubic = lambda k: 1 - 2 * k + 0.5 * k ** 3 - 0.01 * k ** 5     # degree 5 < 6 nodes
    np.testing.assert_allclose(rule.interpolation(points) @ cubic(rule.nodes), cubic(points),
                               rtol=1e-10, atol=1e-10)
    assert not np.any(rule.interpolation([6.0]))                     # outside: 0


@pytest.mark.parametrize("duration, scan, delta", [
    (40.0, 4.0, 0.0), (40.0, 4.0, 231.0),             # 10 scans: exact terms
    (600.0, 4.0, 0.0), (600.0, 4.0, 231.0),           # 150 scans: peaks, aliasing
    (3600.0, 1.0, 0.0), (3600.0, 1.0, 115.0),
    (np.inf, 4.0, 231.0)])
def test_record_weights_against_adaptive_quadrature(duration, scan, delta):
    # integral_0^K g(k) cos(k delta) (1 - |D_N(k U / 2 pi)|^2) dk for a spectrum-like g
    # by QUADPACK with every peak of |D_N|^2 (the record mean's and the scans' aliasing,
    # each 1/T wide) a break point: the rule's error < 1e-6 of the integral's scale
    # (0.044); the peak approximations (module docstring) are < 1e-3 of the peaks' mass
    speed = 10.0
    g = lambda k: np.exp(-(20 * k) ** 2) * (1 + k)
    rule = PanelRule(geometric_edges(1e-5, 0.3, 3), 8)
    scans = record_scans(scan, duration)
    h = (lambda k: np.ones_like(k)) if scans == 0 else \
        (lambda k: 1 - mean_window(k * speed / (2 * np.pi), scan, scans))
    period = 2 * np.pi / (speed * scan)
    width = period / max(scans, 1)
    breaks = np.sort(np.concatenate([np.arange(0, 64) * width / 2,
                                     *[m * period + np.arange(-8, 9) * width / 2
                                       for m in range(1, 5)]]))
    breaks = breaks[(breaks > 0) & (breaks < 0.3)]
    edges = np.concatenate([[0.0], breaks, [0.3]])
    expected = sum(integrate.quad(lambda k: g(k) * h(k) * np.cos(k * delta), a, b,
                                  limit=400, epsabs=1e-13)[0]
                   for a, b in zip(edges[:-1], edges[1:]))
    found = (g(rule.nodes) @ record_weights(rule, delta, speed, scan, duration)).real
    assert found == pytest.approx(expected, abs=2e-6)
