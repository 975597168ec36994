"""Turbulence boxes: Mann's factor against the tensor derived anew, the box's variances and
spectra against the model, the Kaimal field against IEC 61400-1, sizing and limits."""
import functools

import numpy as np
import pytest
import scipy.integrate
import scipy.special

from uq.physics import turbulencebox as tb
from uq.physics.spectraltensor import mann_eddy_lifetime

GAMMA = 3.9


# --- an independent Mann (1994) tensor: the distortion integrated numerically ----------

def _lifetime(kl, gamma):
    """Mann (1994) Sec. 3.3, straight from scipy's 2F1."""
    return gamma * kl ** (-2 / 3) / np.sqrt(scipy.special.hyp2f1(1 / 3, 17 / 6, 4 / 3, -kl**-2))


def _distortion(k, beta):
    """Rapid distortion by a uniform shear dU/dz over a time beta / (dU/dz), integrated
    numerically (Mann 1994, Sec. 3.2): ``dZ_i / ds = (2 k_i k_1 / k^2 - delta_i1) Z_3`` with
    ``k_3(s) = k_30 - s k_1`` ending at k; returns the matrix D with Z(beta) = D Z(0) and
    k0."""
    k1, k2, k3 = k
    k30 = k3 + beta * k1
    k0sq = k1**2 + k2**2 + k30**2

    def ratio(s):                              # Z_3(s) / Z_3(0) = k0^2 / k(s)^2
        return k0sq / (k1**2 + k2**2 + (k30 - s * k1) ** 2)

    def rate(i, s):
        ks = np.array([k1, k2, k30 - s * k1])
        return (2 * ks[i] * k1 / (ks @ ks) - (i == 0)) * ratio(s)

    z1 = scipy.integrate.quad(lambda s: rate(0, s), 0, beta, epsabs=0, epsrel=1e-12)[0]
    z2 = scipy.integrate.quad(lambda s: rate(1, s), 0, beta, epsabs=0, epsrel=1e-12)[0]
    return np.array([[1, 0, z1], [0, 1, z2], [0, 0, ratio(beta)]]), np.array([k1, k2, k30])


def _tensor(k, ae, length, gamma):
    """Phi(k) = D Phi_iso(k0) D^T [m5 s-2], the von Karman isotropic tensor at k0."""
    kn = np.linalg.norm(k)
    d, k0 = _distortion(k, _lifetime(kn * length, gamma) if gamma else 0.0)
    k0n = np.linalg.norm(k0)
    energy = ae * length ** (5 / 3) * (k0n * length) ** 4 / (1 + (k0n * length) ** 2) ** (17 / 6)
    iso = energy / (4 * np.pi * k0n**4) * (k0n**2 * np.eye(3) - np.outer(k0, k0))
    return d @ iso @ d.T


def _explicit_tensor(k1, k2, k3, ae, length, gamma):
    """Mann (1994)'s closed-form components (11, 22, 33, 13), vectorised, with the
    branch-safe arctan2 (checked against _tensor below)."""
    k = np.sqrt(k1**2 + k2**2 + k3**2)
    beta = _lifetime(k * length, gamma)
    k30 = k3 + beta * k1
    k0sq = k1**2 + k2**2 + k30**2
    khsq = k1**2 + k2**2
    c1 = beta * k1**2 * (k0sq - 2 * k30**2 + beta * k1 * k30) / (k**2 * khsq)
    c2 = k2 * k0sq / khsq**1.5 * np.arctan2(beta * k1 * np.sqrt(khsq), k0sq - k30 * k1 * beta)
    z1, z2 = c1 - k2 / k1 * c2, k2 / k1 * c1 + c2
    e = ae * length ** (5 / 3) * (np.sqrt(k0sq) * length) ** 4 / (1 + k0sq * length**2) ** (17 / 6)
    f = e / (4 * np.pi * k0sq**2)
    return np.stack([f * (k0sq - k1**2 - 2 * k1 * k30 * z1 + khsq * z1**2),
                     f * (k0sq - k2**2 - 2 * k2 * k30 * z2 + khsq * z2**2),
                     e / (4 * np.pi * k**4) * khsq,
                     e / (4 * np.pi * k**2 * k0sq) * (-k1 * k30 + khsq * z1)])


@functools.lru_cache
def _tensor_integral(ae, length, gamma, nk=240, nmu=64, nphi=64):
    """Variances and u-w covariance [m2 s-2]: the tensor integrated over all k in
    spherical coordinates (Gauss-Legendre in ln k over 1e-5..1e7 / L and in cos theta)."""
    x, wx = np.polynomial.legendre.leggauss(nk)
    lo, hi = np.log(1e-5 / length), np.log(1e7 / length)
    logk, wk = lo + (x + 1) / 2 * (hi - lo), wx * (hi - lo) / 2
    mu, wmu = np.polynomial.legendre.leggauss(nmu)
    ph = (np.arange(nphi) + 0.5) * 2 * np.pi / nphi
    kk, mm, pp = np.meshgrid(np.exp(logk), mu, ph, indexing="ij")
    s = np.sqrt(1 - mm**2)
    values = _explicit_tensor(kk * s * np.cos(pp), kk * s * np.sin(pp), kk * mm, ae, length, gamma)
    weights = (wk * np.exp(3 * logk))[:, None, None] * wmu[None, :, None] * (2 * np.pi / nphi)
    return np.sum(values * weights, axis=(1, 2, 3))


# --- the factor ------------------------------------------------------------------------

def test_eddy_lifetime_table_and_asymptotes():
    kl = np.logspace(-7, 7, 4001)
    exact = mann_eddy_lifetime(kl, 1.0, GAMMA)
    # log-linear interpolation at 200 nodes per decade: |error| <= h^2 max|f''| / 8 with
    # h = ln 10 / 200; measured 3.4e-6, asserted below 1e-5
    np.testing.assert_allclose(tb.eddy_lifetime(kl, GAMMA), exact, rtol=1e-5)
    # the exact lifetime's own asymptotes (Mann 1994, Sec. 3.3): (kL)^(-2/3) at large kL
    assert exact[-1] == pytest.approx(GAMMA * kl[-1] ** (-2 / 3), rel=1e-9)


@pytest.mark.parametrize("k", [(0.3, -0.7, 0.2), (0.05, 0.02, -0.9), (-0.02, 0.5, 0.4),
                               (0.8, 0.1, -0.05), (1e-3, 0.2, -0.3), (0.0, 0.4, 0.3),
                               (2.0, -1.5, 3.0)])
@pytest.mark.parametrize("gamma", [0.0, GAMMA])
def test_factor_squares_to_the_distorted_tensor(k, gamma):
    # k = (1e-3, 0.2, -0.3) has kh^2 + k30 k3 < 0: the printed single arctan's wrong branch
    ae, length = 0.1, 33.6
    k = np.array(k) / length * 10
    c = tb.mann1998_spectral_factor(*(np.array(x) for x in k), ae, length, gamma)
    expected = _tensor(k, ae, length, gamma)
    # quad to 1e-12 and the lifetime table's 3.4e-6: agreement to 1e-4 of the largest
    np.testing.assert_allclose(c @ c.T, expected, rtol=0, atol=1e-4 * np.abs(expected).max())
    if k[0] != 0:
        explicit = _explicit_tensor(*k, ae, length, gamma)
        np.testing.assert_allclose(explicit, expected[[0, 1, 2, 0], [0, 1, 2, 2]],
                                   rtol=0, atol=1e-6 * np.abs(expected).max())


def test_tensor_integral_isotropic_closed_form():
    # Gamma = 0: sigma^2 = (2/3) int E dk = (2/3) ae L^(2/3) B(5/2, 1/3) / 2 per component
    closed = (2 / 3) * 0.5 * scipy.special.beta(2.5, 1 / 3)
    np.testing.assert_allclose(_tensor_integral(1.0, 1.0, 0.0)[:3], closed, rtol=1e-4)


# --- the box ---------------------------------------------------------------------------

def _graded_axis(half_cell, nyquist, ratio=1 / 4, panels=8):
    """Gauss nodes and weights on [-nyquist, nyquist] whose panels are graded towards
    both 0 and +-half_cell (an edge), so the origin cell is a union of panels."""
    edges = [nyquist]
    while edges[-1] * ratio > half_cell:
        edges.append(edges[-1] * ratio)
    edges += [half_cell] + [half_cell * ratio**j for j in range(1, panels)] + [0.0]
    x, w = np.polynomial.legendre.leggauss(3)
    nodes, weights = [], []
    for a, b in zip(edges[:-1], edges[1:]):
        nodes += [(a + b) / 2 + (a - b) / 2 * x]
        weights += [(a - b) / 2 * w]
    nodes, weights = np.concatenate(nodes), np.concatenate(weights)
    return np.concatenate([nodes, -nodes]), np.concatenate([weights, weights])


def _box_region_integral(grid, ae, length, gamma):
    """The tensor integrated (independently) over the wavenumbers a box represents: the
    Nyquist cuboid |k_i| < pi / d_i without the origin cell |k_i| < dk_i / 2 (the
    box's mean)."""
    dk = 2 * np.pi / np.array(grid.lengths)
    axes = [_graded_axis(dk[a] / 2, np.pi / grid.spacing[a]) for a in range(3)]
    k = np.meshgrid(*(a[0] for a in axes), indexing="ij")
    weight = axes[0][1][:, None, None] * axes[1][1][None, :, None] * axes[2][1][None, None, :]
    inside = (np.abs(k[0]) < dk[0] / 2) & (np.abs(k[1]) < dk[1] / 2) & (np.abs(k[2]) < dk[2] / 2)
    return np.sum(_explicit_tensor(*k, ae, length, gamma) * np.where(inside, 0.0, weight),
                  axis=(1, 2, 3))


@pytest.mark.parametrize("shape, spacing", [((2048, 16, 16), 0.25), ((256, 32, 32), 0.5)])
def test_box_variance_is_the_tensor_integral_over_the_boxs_wavenumbers(shape, spacing):
    """What a box keeps (the sum of its cells' tensor) is the tensor's integral over the
    wavenumbers it represents; the rest of the point variance is lost to its size and
    resolution (reported by box_variance, shown by the test of a too small box)."""
    grid = tb.BoxGrid(shape, (spacing,) * 3)
    kept = tb.box_variance(grid, 1.0, 1.0, GAMMA)
    region = _box_region_integral(grid, 1.0, 1.0, GAMMA)
    # the cells' midpoint values against the integral over each cell: second order in
    # dk L (<= 0.4 here) where the tensor is smooth, cell averages near the k1 axis;
    # 3 % of each variance bounds the difference
    np.testing.assert_allclose(kept, region, rtol=0.03)
    assert np.all(kept[:3] < _tensor_integral(1.0, 1.0, GAMMA)[:3])


def _seeds_box(grid, seeds, gamma=GAMMA, length=1.0):
    return [tb.mann_box(grid, 1.0, length, gamma, np.random.default_rng(s)).velocity
            for s in seeds]


def test_generated_variances_are_the_boxs_expected_variances():
    grid = tb.BoxGrid((256, 32, 32), (0.5,) * 3)
    boxes = _seeds_box(grid, range(12))
    # the spatial (co)variances of each box; the box's mean is zero by construction
    stats = np.array([[np.mean(v[0] ** 2), np.mean(v[1] ** 2), np.mean(v[2] ** 2),
                       np.mean(v[0] * v[2])] for v in boxes])
    assert np.abs(np.mean([v.mean(axis=(1, 2, 3)) for v in boxes])) < 1e-12
    expected = tb.box_variance(grid, 1.0, 1.0, GAMMA)
    # the variance of one box is random (few large eddies per box): 12 seeds, 4 standard
    # errors of their mean, the standard deviation taken from the seeds themselves
    error = stats.std(axis=0, ddof=1) / np.sqrt(len(stats))
    assert np.all(np.abs(stats.mean(axis=0) - expected) < 4 * error), (stats.mean(0), expected)


def _f11_model(k1, length, gamma):
    """u's one-dimensional spectrum F11(k1) [m3 s-2], two-sided: the test's tensor
    integrated over (k2, k3) in polar coordinates."""
    x, w = np.polynomial.legendre.leggauss(200)
    lo, hi = np.log(1e-4 / length), np.log(1e4 / length)
    kp = np.exp(lo + (x + 1) / 2 * (hi - lo))
    wk = w * (hi - lo) / 2 * kp**2
    theta = (np.arange(128) + 0.5) * 2 * np.pi / 128
    kk, th = np.meshgrid(kp, theta, indexing="ij")
    return np.array([np.sum(_explicit_tensor(q, kk * np.cos(th), kk * np.sin(th), 1.0, length,
                                             gamma)[0] * wk[:, None]) * 2 * np.pi / 128
                     for q in k1])


def test_one_dimensional_spectrum_and_the_inertial_slope():
    """u's spectrum along x follows the box's expectation at every wavenumber, and its
    log-log slope over the decade k1 L = 3..30 is the model's, -5/3."""
    length, d = 1.0, 1 / 24
    grid = tb.BoxGrid((256, 48, 48), (d,) * 3)
    k1 = 2 * np.pi * np.fft.rfftfreq(grid.shape[0], d)
    band = (k1 * length >= 3) & (k1 * length <= 30)
    spectra = np.array([np.mean(np.abs(np.fft.rfft(v[0], axis=0)) ** 2, axis=(1, 2))[band]
                        for v in _seeds_box(grid, range(6))])
    # the expectation: the box's cells' Phi_11 summed over (k2, k3), as the periodogram
    # |FFT|^2 = nx^2 sum |u_k|^2 (both signs of k1 give the same sum)
    # (the cells near the k1 axis carry the cell-averaged tensor the generator uses)
    # (Phi is even but not symmetric in k3 alone: sum over every k3, not the half)
    ky = 2 * np.pi * np.fft.fftfreq(grid.shape[1], d)[None, :, None]
    kz = 2 * np.pi * np.fft.fftfreq(grid.shape[2], d)[None, None, :]
    c = tb.mann1998_spectral_factor(k1[:, None, None], ky, kz, 1.0, length, GAMMA)
    phi11 = np.einsum("k...,k...->...", c[0], c[0])
    cells, factors = tb.cell_averaged_factors(grid, 1.0, length, GAMMA)
    averaged = np.sum(factors[0] ** 2, axis=0)
    for sign in (1, -1):                      # a cell, or its mirror -k, at k1 >= 0
        keep = sign * cells[:, 0] >= 0
        phi11[tuple((sign * cells[keep]).T)] = averaged[keep]
    dk = (2 * np.pi) ** 3 / np.prod(grid.lengths)
    expected = (np.sum(phi11, axis=(1, 2)) * dk * grid.shape[0] ** 2)[band]
    ratio = spectra / expected
    slope = [np.polyfit(np.log(k1[band]), np.log(s), 1)[0] for s in spectra]
    expected_slope = np.polyfit(np.log(k1[band]), np.log(expected), 1)[0]
    # 6 seeds: 4 standard errors (from the seeds' own scatter) of the mean ratio and slope
    assert abs(ratio.mean() - 1) < 4 * ratio.mean(axis=1).std(ddof=1) / np.sqrt(6)
    assert abs(np.mean(slope) - expected_slope) < 4 * np.std(slope, ddof=1) / np.sqrt(6)
    # the model's own slope over that decade (independent quadrature) tends to -5/3 only
    # as kL -> inf: a von Karman shape (1 + (kL)^2)^(-5/6) has the mean slope
    # -5/3 (1 - 0.022) = -1.63 over kL = 3..30, so 0.04
    model = _f11_model(k1[band][::4], length, GAMMA)
    assert np.polyfit(np.log(k1[band][::4]), np.log(model), 1)[0] == pytest.approx(-5 / 3, abs=0.04)
    # and the box's: its resolution (|k2|, |k3| < pi / d = 75 / L) cuts the integral over
    # (k2, k3) at the decade's top, steepening the slope; at d = L / 24 by less than 0.2
    assert np.mean(slope) == pytest.approx(-5 / 3, abs=0.2)


# --- Kaimal with IEC 61400-1 coherence -------------------------------------------------

def _iec_kaimal(f, sigma, length, speed):
    """IEC 61400-1 Annex B, Table B.1: f S(f) / sigma^2 = 4 f L / V / (1 + 6 f L / V)^(5/3)."""
    return sigma**2 * 4 * length / speed / (1 + 6 * f * length / speed) ** (5 / 3)


KAIMAL = dict(sigma_u=1.2, speed=10.0, scale_parameter=42.0)


def _kaimal_boxes(grid, seeds):
    return [tb.kaimal_box(grid, rng=np.random.default_rng(s), **KAIMAL).velocity for s in seeds]


def test_kaimal_point_spectra_follow_iec():
    speed, dx = KAIMAL["speed"], 2.5                    # 0.25 s per cell by Taylor
    grid = tb.BoxGrid((2048, 3, 2), (dx, 15.0, 15.0), periodic_yz=False)
    boxes = np.array(_kaimal_boxes(grid, range(8)))     # (seed, 3, nx, ny, nz)
    k1 = 2 * np.pi * np.fft.rfftfreq(grid.shape[0], dx)
    f = speed * k1 / (2 * np.pi)
    periodogram = np.mean(np.abs(np.fft.rfft(boxes, axis=2)) ** 2, axis=(3, 4))
    # E|FFT|^2 = nx^2 F(k1) dk1 with the two-sided F(k1) = S(f) V / (4 pi)
    dk1 = 2 * np.pi / grid.lengths[0]
    sigmas = KAIMAL["sigma_u"] * np.array([1.0, 0.8, 0.5])
    lengths = KAIMAL["scale_parameter"] * np.array([8.1, 2.7, 0.66])
    for c in range(3):
        density = _iec_kaimal(f, sigmas[c], lengths[c], speed) * speed / (4 * np.pi)
        expected = grid.shape[0] ** 2 * density * dk1
        for low, high in ((0.005, 0.05), (0.05, 0.5), (0.5, 2.0)):      # Hz
            band = (f >= low) & (f < high)
            ratio = periodogram[:, c, band].mean(axis=1) / expected[band].mean()
            # 8 seeds, 4 standard errors from their scatter
            assert abs(ratio.mean() - 1) < 4 * ratio.std(ddof=1) / np.sqrt(8), (c, low, ratio)
    # the variance: the spectrum's integral but for the box's mean (k1 = 0)
    variance = boxes.var(axis=2).mean(axis=(2, 3))      # (seed, component)
    for c in range(3):
        density = _iec_kaimal(f[1:], sigmas[c], lengths[c], speed) * speed / (4 * np.pi)
        weights = np.where(np.arange(1, f.size) == grid.shape[0] // 2, 1.0, 2.0)
        kept = np.sum(density * weights) * dk1
        assert abs(variance[:, c].mean() - kept) < 4 * variance[:, c].std(ddof=1) / np.sqrt(8)
        # the record-length box keeps most of sigma^2 (int S df = sigma^2 exactly)
        assert 0.7 * sigmas[c] ** 2 < kept < sigmas[c] ** 2


def test_kaimal_coherence_follows_iec():
    speed, dx, dy = KAIMAL["speed"], 2.5, 20.0
    grid = tb.BoxGrid((2048, 2, 2), (dx, dy, dy), periodic_yz=False)
    boxes = np.array(_kaimal_boxes(grid, range(8)))
    spectra = np.fft.rfft(boxes[:, 0], axis=1)          # u: (seed, k1, y, z)
    f = speed * np.fft.rfftfreq(grid.shape[0], dx)
    coherence_length = 8.1 * KAIMAL["scale_parameter"]
    for (a, b), r in ((((0, 0), (1, 0)), dy), (((0, 0), (1, 1)), dy * np.sqrt(2))):
        xa, xb = spectra[:, :, a[0], a[1]], spectra[:, :, b[0], b[1]]
        for low, high in ((0.002, 0.02), (0.02, 0.1)):
            band = (f >= low) & (f < high)
            co = np.mean(np.real(xa * np.conj(xb))[:, band])
            gamma = co / np.sqrt(np.mean(np.abs(xa[:, band]) ** 2) * np.mean(np.abs(xb[:, band]) ** 2))
            iec = np.mean(np.exp(-12 * np.sqrt((f[band] * r / speed) ** 2
                                              + (0.12 * r / coherence_length) ** 2)))
            # the co-coherence estimated from n periodogram ordinates has a standard
            # error (1 - gamma^2) / sqrt(2 n) (Bendat & Piersol 2010, Eq. 9.73 for the
            # coherence); 4 of them
            n = band.sum() * len(boxes)
            assert abs(gamma - iec) < 4 * (1 - iec**2) / np.sqrt(2 * n), (r, low, gamma, iec)


def test_a_kaimal_box_made_at_the_nodes_a_record_reads_has_their_statistics():
    # Veers' method at a subset of the (y, z) nodes (those a record reads): the same
    # coherence between two of them and the same spectra as the whole grid has there
    # (the coherence is point to point), zeros elsewhere; the cost falls as the cube of
    # the nodes (here 2 of 20)
    speed, dx, dy = KAIMAL["speed"], 2.5, 20.0
    grid = tb.BoxGrid((2048, 5, 4), (dx, dy, dy), periodic_yz=False)
    points = np.array([[0.0, 0.5 * dy, 0.5 * dy], [10.0, 1.5 * dy, 0.5 * dy]])
    nodes = tb.kaimal_nodes(grid, points)
    assert nodes.sum() == 6 and nodes[0, 0] and nodes[2, 1] and not nodes[4, 3]
    boxes = np.array([tb.kaimal_box(grid, rng=np.random.default_rng(s), nodes=nodes,
                                    **KAIMAL).velocity for s in range(8)])
    assert np.all(boxes[:, :, :, ~nodes] == 0)
    spectra = np.fft.rfft(boxes[:, 0], axis=1)
    f = speed * np.fft.rfftfreq(grid.shape[0], dx)
    xa, xb = spectra[:, :, 0, 0], spectra[:, :, 1, 0]
    band = (f >= 0.002) & (f < 0.02)
    co = np.mean(np.real(xa * np.conj(xb))[:, band])
    gamma = co / np.sqrt(np.mean(np.abs(xa[:, band]) ** 2) * np.mean(np.abs(xb[:, band]) ** 2))
    iec = np.mean(np.exp(-12 * np.sqrt((f[band] * dy / speed) ** 2
                                      + (0.12 * dy / (8.1 * KAIMAL["scale_parameter"])) ** 2)))
    n = band.sum() * len(boxes)           # the co-coherence's standard error, 4 of them
    assert abs(gamma - iec) < 4 * (1 - iec ** 2) / np.sqrt(2 * n)
    variance = boxes[:, 0][:, :, nodes].var(axis=1).mean()
    whole = np.array(_kaimal_boxes(grid, range(8)))[:, 0].var(axis=1).mean()
    assert variance == pytest.approx(whole, rel=0.15)     # 8 boxes' scatter: ~5 %


# --- seeds, memory, sizing -------------------------------------------------------------

def test_same_seed_same_box_whatever_the_slab():
    grid = tb.BoxGrid((64, 16, 8), (2.0, 2.0, 2.0))
    boxes = [tb.mann_box(grid, 0.1, 33.6, GAMMA, np.random.default_rng(7), slab_cells=cells)
             .velocity for cells in (64, 1000, 2**20)]
    assert np.array_equal(boxes[0], boxes[1]) and np.array_equal(boxes[0], boxes[2])
    other = tb.mann_box(grid, 0.1, 33.6, GAMMA, np.random.default_rng(8)).velocity
    assert not np.allclose(other, boxes[0])
    kgrid = tb.BoxGrid((64, 4, 3), (2.0, 5.0, 5.0), periodic_yz=False)
    kaimal = [tb.kaimal_box(kgrid, 1.0, 10.0, 42.0, np.random.default_rng(7), slab_cells=cells)
              .velocity for cells in (144, 2**20)]
    assert np.array_equal(kaimal[0], kaimal[1])


def test_a_real_field():
    grid = tb.BoxGrid((32, 16, 8), (2.0, 2.0, 2.0))
    box = tb.mann_box(grid, 0.1, 33.6, GAMMA, np.random.default_rng(1))
    assert box.velocity.shape == (3, 32, 16, 8) and box.velocity.dtype == np.float64


def test_memory_bound_is_refused_with_a_clear_message():
    with pytest.raises(ValueError, match=r"8192 x 1024 x 1024 = 8589934592 cells is above the limit"):
        tb.BoxGrid((8192, 1024, 1024), (1.0, 1.0, 1.0))
    # a Kaimal box's cost is its Cholesky factors: refused by its (y, z) points
    grid = tb.BoxGrid((16, 64, 32), (5.0, 5.0, 5.0), periodic_yz=False)
    with pytest.raises(ValueError, match="2048 .y, z. points is above the limit of 1024"):
        tb.kaimal_box(grid, 1.0, 10.0, 42.0, np.random.default_rng(0))


def _dbs(height=100.0, half_cone=30.0, speed=10.0, duration=600.0, dwell=1.0):
    """A 5-beam DBS seen in the mean-wind frame, wind along beam 0's azimuth; pulsed
    probe with 13 nodes over +-30 m."""
    from uq.physics.scangeometry import ScanGeometry
    a = np.radians(half_cone)
    az = np.radians([0.0, 90.0, 180.0, 270.0])
    d = np.array([[np.sin(a) * np.cos(q), np.sin(a) * np.sin(q), np.cos(a)] for q in az]
                 + [[0.0, 0.0, 1.0]])
    ranges = np.r_[[height / np.cos(a)] * 4, height]
    gates = (np.array([0.0, 0.0, -height]) + ranges[:, None] * d)[:, None, :]
    offsets = np.linspace(-30.0, 30.0, 13)
    weights = np.exp(-(offsets / 15.0) ** 2)
    return ScanGeometry(directions=d, gate_centres=gates, times=np.arange(5) * dwell + dwell / 2,
                        dwell=dwell, scan_period=5 * dwell, probe_offsets=offsets,
                        probe_weights=(weights / weights.sum())[None], speed=speed,
                        reconstruction=np.linalg.pinv(d)[None], record_duration=duration)


def test_box_for_holds_the_record():
    geometry = _dbs()
    grid = tb.box_for(geometry, 33.6)
    lengths, points = np.array(grid.lengths), geometry.probe_points().reshape(-1, 3)
    assert lengths[0] >= geometry.speed * 600.0 + np.ptp(points[:, 0])
    # y and z: the points plus 3 L on each side, less the half cell the box moves to put
    # the reference point (0, 0, 0) on a node
    for axis in (1, 2):
        assert lengths[axis] >= np.ptp(points[:, axis]) + 6 * 33.6
        low, half = grid.origin[axis], grid.spacing[axis] / 2
        assert low <= points[:, axis].min() - 3 * 33.6 + half + 1e-9
        assert low + (grid.shape[axis] - 1) * grid.spacing[axis] >= \
            points[:, axis].max() + 3 * 33.6 - half - 1e-9
        assert (0.0 - low) / grid.spacing[axis] == pytest.approx(
            round((0.0 - low) / grid.spacing[axis]), abs=1e-9)
    assert grid.spacing == (33.6 / 8,) * 3
    kaimal = tb.box_for(geometry, 42.0, model="kaimal")
    assert not kaimal.periodic_yz
    with pytest.raises(ValueError, match="above the limit"):
        tb.box_for(geometry, 33.6, record_duration=36000.0)
    with pytest.raises(ValueError, match="finite duration"):
        tb.box_for(_dbs(duration=np.inf), 33.6)


def test_a_too_small_box_loses_variance():
    """A box as small as the large eddies (4 L a side) holds a fraction of the point
    variance, in expectation (box_variance) and in the generated fields; the box that
    box_for sizes for a record keeps most of it."""
    total = _tensor_integral(1.0, 1.0, GAMMA)
    small = tb.BoxGrid((16, 16, 16), (0.25,) * 3)
    small_kept = tb.box_variance(small, 1.0, 1.0, GAMMA)
    assert np.all(small_kept[:3] < 0.65 * total[:3])
    boxes = _seeds_box(small, range(24))
    u_var = np.array([np.mean(v[0] ** 2) for v in boxes])
    # the generated boxes hold that fraction: 24 seeds, 4 standard errors
    assert abs(u_var.mean() - small_kept[0]) < 4 * u_var.std(ddof=1) / np.sqrt(24)
    assert u_var.mean() + 4 * u_var.std(ddof=1) / np.sqrt(24) < 0.7 * total[0]
    # the record's box (DBS at 100 m, U = 10 m/s, 600 s; lengths in units of L = 33.6 m)
    grid = tb.box_for(_dbs(), 33.6)
    scaled = tb.BoxGrid(grid.shape, tuple(np.array(grid.spacing) / 33.6))
    assert np.all(tb.box_variance(scaled, 1.0, 1.0, GAMMA)[:3] > 0.8 * total[:3])


def test_one_von_karman_energy_spectrum():
    # the box's energy spectrum is the spectral path's (one implementation), bit for bit,
    # on numpy arrays; and E(k) -> alpha eps^(2/3) L^(5/3) (kL)^4 as kL -> 0 (Sec. 3 [1]):
    # at kL = 1e-4 the correction (1 + (kL)^2)^(-17/6) is 1 - 2.8e-8
    from uq.physics.spectraltensor import von_karman_energy
    k = np.geomspace(1e-4, 10.0, 50)
    np.testing.assert_array_equal(tb.von_karman_energy_spectrum(k, 0.05, 33.6),
                                  von_karman_energy(k, 33.6, 0.05))
    small = 1e-4 / 33.6
    assert tb.von_karman_energy_spectrum(small, 0.05, 33.6) == pytest.approx(
        0.05 * 33.6 ** (5.0 / 3.0) * 1e-16, rel=1e-7)
