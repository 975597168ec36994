"""Mann's sheared tensor and the Kaimal spectra against independent numbers."""
import numpy as np
import pytest
from scipy import integrate, special

from uq.physics.spectraltensor import (KaimalSpectra, MannTensor, WavenumberGrid,
                                       iec_mann_parameters, isotropic_variance_factor,
                                       kaimal_exponential_integral, mann_eddy_lifetime,
                                       mann_tensor_for_intensity, mann_variance_factors,
                                       point_variances, von_karman_energy)


def _random_k(n, seed=3):
    rng = np.random.default_rng(seed)
    return 10.0 ** rng.uniform(-2.5, 1.5, size=(3, n)) * rng.choice([-1, 1], size=(3, n))


def test_isotropic_limit_has_the_closed_form_variance():
    # Gamma = 0: each component's variance is (1/3) B(5/2, 1/3) alpha eps^(2/3) L^(2/3)
    # (Mann 1994 Eq. 2.8); the default grid's truncation (k L < 1e6 and the polar range)
    # leaves < 5e-4 (measured 4e-4: the inertial tail (1e6)^(-2/3) = 1e-4 and the radius)
    values = point_variances(MannTensor(1.0, 0.0))
    assert isotropic_variance_factor() == pytest.approx(0.5 * special.beta(2.5, 1 / 3) * 2 / 3)
    np.testing.assert_allclose(values, isotropic_variance_factor(), rtol=1e-3)


@pytest.mark.parametrize("k1", [0.01, 0.3, 3.0, 30.0])
def test_isotropic_one_dimensional_spectra(k1):
    # von Karman 1-D spectra (Mann 1994 Eq. 2.9 context; Hinze): F11 = 9/55 ae
    # (L^-2 + k1^2)^(-5/6), F22 = 3/110 ae (3 L^-2 + 8 k1^2) / (L^-2 + k1^2)^(11/6), L = 1
    tensor, grid = MannTensor(1.0, 0.0), WavenumberGrid(1.0)
    k2, k3, w = grid.cross_section(np.array([k1]))
    phi = tensor.matrix(np.full_like(k2, k1), k2, k3)
    f11, f22 = np.sum(w * phi[..., 0, 0]), np.sum(w * phi[..., 1, 1])
    # the polar grid's truncation and nodes: 2e-4 measured; 1e-3 allowed
    assert f11 == pytest.approx(9 / 55 * (1 + k1 ** 2) ** (-5 / 6), rel=1e-3)
    assert f22 == pytest.approx(3 / 110 * (3 + 8 * k1 ** 2) / (1 + k1 ** 2) ** (11 / 6), rel=1e-3)


def _printed_components(k1, k2, k3, gamma, length=1.0):
    """Mann (1994) Eqs. 3.17-3.20 component by component (an independent transcription;
    C2 with the arctangent difference, see the module docstring)."""
    k = np.sqrt(k1 ** 2 + k2 ** 2 + k3 ** 2)
    beta = mann_eddy_lifetime(k, length, gamma)
    k30 = k3 + beta * k1
    k0 = np.sqrt(k1 ** 2 + k2 ** 2 + k30 ** 2)
    kh2 = k1 ** 2 + k2 ** 2
    c1 = beta * k1 ** 2 * (k0 ** 2 - 2 * k30 ** 2 + beta * k1 * k30) / (k ** 2 * kh2)
    c2 = k2 * k0 ** 2 / kh2 ** 1.5 * (np.arctan(k30 / np.sqrt(kh2)) - np.arctan(k3 / np.sqrt(kh2)))
    z1, z2 = c1 - k2 / k1 * c2, k2 / k1 * c1 + c2
    e = von_karman_energy(k0, length) / (4 * np.pi * k0 ** 4)
    return {
        (0, 0): e * (k0 ** 2 - k1 ** 2 - 2 * k1 * k30 * z1 + kh2 * z1 ** 2),
        (1, 1): e * (k0 ** 2 - k2 ** 2 - 2 * k2 * k30 * z2 + kh2 * z2 ** 2),
        (2, 2): von_karman_energy(k0, length) / (4 * np.pi * k ** 4) * kh2,
        (0, 1): e * (-k1 * k2 - k1 * k30 * z2 - k2 * k30 * z1 + kh2 * z1 * z2),
        (0, 2): von_karman_energy(k0, length) / (4 * np.pi * k0 ** 2 * k ** 2)
        * (-k1 * k30 + kh2 * z1),
        (1, 2): von_karman_energy(k0, length) / (4 * np.pi * k0 ** 2 * k ** 2)
        * (-k2 * k30 + kh2 * z2),
    }


def test_tensor_matches_the_printed_components_and_is_solenoidal():
    k1, k2, k3 = _random_k(400)
    tensor = MannTensor(1.0, 3.9)
    phi = tensor.matrix(k1, k2, k3)
    for (i, j), value in _printed_components(k1, k2, k3, 3.9).items():
        # the same algebra two ways: equal to rounding (1e-9 relative of the largest entry)
        np.testing.assert_allclose(phi[:, i, j], value, rtol=1e-9,
                                   atol=1e-12 * np.abs(phi).max())
        np.testing.assert_allclose(phi[:, j, i], value, rtol=1e-9,
                                   atol=1e-12 * np.abs(phi).max())
    # incompressibility k . u(k) = 0, so k_i Phi_ij = 0; positive semi-definite
    kv = np.stack([k1, k2, k3], axis=-1)
    scale = np.linalg.norm(kv, axis=-1) * np.abs(phi).max(axis=(1, 2))
    assert np.all(np.abs(np.einsum("ni,nij->nj", kv, phi)) <= 1e-10 * scale[:, None])
    assert np.all(np.linalg.eigvalsh(phi) >= -1e-12 * np.abs(phi).max(axis=(1, 2))[:, None])
    # the quadratic form equals g Phi g^H
    g = np.exp(1j * kv)
    direct = np.einsum("ni,nij,nj->n", g, phi, g.conj()).real
    np.testing.assert_allclose(tensor.quadratic_form(g, k1, k2, k3), direct, rtol=1e-9,
                               atol=1e-12 * np.abs(direct).max())


def test_arctangent_difference_is_the_right_branch():
    # where k0^2 - k30 k1 beta < 0 the printed atan(...) is off by pi from the lifetime
    # integral int_0^beta k1 kh / (kh^2 + (k3 + b k1)^2) db = atan(k30/kh) - atan(k3/kh)
    k1, k2, k3, gamma = 0.05, 0.02, -0.9, 3.9
    k = np.sqrt(k1 ** 2 + k2 ** 2 + k3 ** 2)
    beta = mann_eddy_lifetime(k, 1.0, gamma)
    kh = np.hypot(k1, k2)
    integral = integrate.quad(lambda b: k1 * kh / (kh ** 2 + (k3 + b * k1) ** 2), 0, beta)[0]
    k30 = k3 + beta * k1
    assert np.arctan(k30 / kh) - np.arctan(k3 / kh) == pytest.approx(integral, rel=1e-9)


def test_eddy_lifetime_limits():
    # kL >> 1: 2F1 -> 1, beta -> Gamma (kL)^(-2/3); kL << 1: beta ~ (kL)^(-1)
    assert mann_eddy_lifetime(1e4, 1.0, 2.0) == pytest.approx(2.0 * 1e4 ** (-2 / 3), rel=1e-6)
    small = mann_eddy_lifetime(np.array([1e-4, 1e-5]), 1.0, 1.0)
    assert small[1] / small[0] == pytest.approx(10.0, rel=1e-3)


def test_iec_sigma_iso_and_intensity():
    # IEC 61400-1:2005 Annex B.1: with Gamma = 3.9, sigma_iso = 0.55 sigma_1 (2 digits
    # printed: +-0.005), and sigma_v / sigma_u ~ 0.7, sigma_w / sigma_u ~ 0.5 (the Kaimal
    # ratios of Table B.1 are 0.8 and 0.5; Mann's tensor gives its own)
    su, sv, sw = mann_variance_factors(3.9)
    assert np.sqrt(isotropic_variance_factor() / su) == pytest.approx(0.55, abs=0.01)
    assert np.sqrt(sv / su) == pytest.approx(0.7, abs=0.05)
    assert np.sqrt(sw / su) == pytest.approx(0.5, abs=0.05)
    tensor = mann_tensor_for_intensity(0.1, 10.0, 33.6, 3.9)
    assert np.sqrt(point_variances(tensor)[0]) / 10.0 == pytest.approx(0.1, rel=1e-9)
    assert iec_mann_parameters(100.0) == (pytest.approx(33.6), 3.9)


def test_point_variance_converges():
    # doubling every node count and widening the ranges moves sigma_u^2 by < 2e-3
    fine = WavenumberGrid(1.0, (-7.0, 7.0), (-6.0, 5.0), 16, 12, 64)
    coarse = point_variances(MannTensor(1.0, 3.9))
    np.testing.assert_allclose(coarse, point_variances(MannTensor(1.0, 3.9), fine), rtol=2e-3)


def test_point_variances_in_blocks_of_k1_equal_the_whole_grid_at_once(monkeypatch):
    # Each k1's integral over (k2, k3) is the same sum in either case: bit-identical
    from uq.physics import spectraltensor
    tensor = MannTensor(1.0, 3.9)
    blocks = point_variances(tensor, spectral_filter=lambda k1: 1.0 - np.exp(-k1 ** 2))
    monkeypatch.setattr(spectraltensor, "K1_PER_BLOCK", 10 ** 6)
    whole = point_variances(tensor, spectral_filter=lambda k1: 1.0 - np.exp(-k1 ** 2))
    np.testing.assert_array_equal(blocks, whole)


def test_point_variances_memory_is_bounded():
    # A bound on memory, not time: the whole grid's (144 x 3456, 3, 3) tensor at once
    # took 211 MB of numpy temporaries (the peak of a `uq golden` run); a block of
    # K1_PER_BLOCK = 12 k1 takes 12/144 of that (~18 MB, measured 16 MB); 60 MB leaves
    # room for numpy's own choices and is far below the whole grid's.
    import tracemalloc
    tracemalloc.start()
    try:
        point_variances(MannTensor(1.0, 3.9))
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak < 60e6


def test_kaimal_spectrum_and_coherence():
    spectra = KaimalSpectra.iec(0.1, 10.0, 340.2)
    for j, sigma in enumerate(spectra.sigmas):
        total = integrate.quad(lambda f: spectra.spectrum(j, f), 0, np.inf, limit=400)[0]
        assert total == pytest.approx(sigma ** 2, rel=1e-6)   # quad's own tolerance
    assert spectra.coherence(0.0, 0.3) == 1.0
    assert spectra.coherence(50.0, 0.0) == pytest.approx(np.exp(-12 * 0.12 * 50 / 340.2))


@pytest.mark.parametrize("b", [0.01, 0.3, 2.0, 10.0])
def test_generalised_exponential_integral(b):
    direct = integrate.quad(lambda t: t ** (-5 / 3) * np.exp(-b * t), 1, np.inf)[0]
    assert kaimal_exponential_integral(5 / 3, b) == pytest.approx(direct, rel=1e-8)
