"""The scales a box does not resolve (uq.physics.unresolved), against numbers derived
apart from it: the interpolation's power averaged over a cell by quadrature, the
isotropic inertial range's variance outside a cube in closed radial form, and a
generated box sampled at random points."""
import numpy as np
import pytest

from uq import constants
from uq.physics import turbulencebox, unresolved


def test_interpolation_power_is_the_cell_average_of_the_linear_interpolant():
    # |(1 - s) + s exp(i theta)|^2 averaged over s in [0, 1] by a 64-node Gauss rule
    # (a polynomial of degree 2 in s: exact); the closed form 2/3 + cos(theta) / 3 to
    # rounding (1e-14)
    x, w = np.polynomial.legendre.leggauss(64)
    s, w = (x + 1) / 2, w / 2
    for theta in (0.0, 0.3, 1.0, np.pi / 2, 2.5, np.pi):
        direct = np.sum(w * np.abs((1 - s) + s * np.exp(1j * theta)) ** 2)
        assert unresolved.interpolation_power(theta) == pytest.approx(direct, abs=1e-14)
    assert unresolved.interpolation_power(np.pi) == pytest.approx(1 / 3, abs=1e-15)


def _outside_cube_isotropic(nyquist, reach, component):
    """An isotropic inertial range (E = k^(-5/3), Phi_ii = E / (4 pi k^2) (1 - k_i^2 /
    k^2)) between the cubes of half-widths K and reach K: along a direction n the cube's
    face is at K / m(n), m = max |n_a|, so the variance is the angular mean of (3/2)
    (K / m)^(-2/3) (1 - reach^(-2/3)) (1 - n_i^2), by a product rule on the sphere."""
    x, w = np.polynomial.legendre.leggauss(400)        # cos(polar angle)
    phi = (np.arange(800) + 0.5) * 2 * np.pi / 800      # azimuth (periodic: midpoints)
    c, a = np.meshgrid(x, phi, indexing="ij")
    s = np.sqrt(1 - c ** 2)
    n = np.stack([s * np.cos(a), s * np.sin(a), c])
    m = np.max(np.abs(n), axis=0)
    radial = 1.5 * (nyquist / m) ** (-2 / 3) * (1 - reach ** (-2 / 3))
    weight = w[:, None] * (2 * np.pi / 800) / (4 * np.pi)
    return float(np.sum(weight * radial * (1 - n[component] ** 2)))


def test_unresolved_point_variance_against_the_inertial_range_in_closed_form():
    # Gamma = 0 (no shear: isotropic von Karman) and L = 1e4 d (kL > 3e4 outside the
    # cube: E = k^(-5/3) to 1e-8); the panel rule against the radial closed form within
    # 0.3 % (the rule's own refinement moves it by less, test below; the sphere's product
    # rule converges to 1e-6)
    spacing, length = 1.0, 1e4
    nyquist = np.pi / spacing
    found = unresolved.unresolved_point_variances(spacing, 1.0, length, 0.0)
    for component in range(3):
        expected = _outside_cube_isotropic(nyquist, constants.UNRESOLVED_REACH, component)
        assert found[component] == pytest.approx(expected, rel=3e-3)


def test_a_generated_box_read_between_its_nodes_passes_the_interpolation_power():
    # a Mann box at a coarse spacing (L / 2: the interpolation removes ~10 % of u) read
    # by trilinear interpolation at 2e5 random points: its mean square against the
    # prediction from the same box's own Fourier power weighted by I(k1 d) I(k2 d)
    # I(k3 d) (exact in expectation over positions, the box given); the points' own
    # scatter is ~0.4 % (2 sigma ~ 1 %), the loss itself ~10 %: 1.5 %
    from uq.physics.turbulencebox import BoxGrid, mann_box
    from uq.physics.turbulencesampling import sample_velocity
    rng = np.random.default_rng(5)
    d = 16.8
    grid = BoxGrid(shape=(64, 32, 32), spacing=(d, d, d))
    box = mann_box(grid, 1.0, 33.6, 3.9, rng)
    u = np.asarray(box.velocity[0])
    power = np.abs(np.fft.fftn(u)) ** 2 / u.size ** 2
    k = [2 * np.pi * np.fft.fftfreq(n, d) for n in grid.shape]
    weight = (unresolved.interpolation_power(k[0] * d)[:, None, None]
              * unresolved.interpolation_power(k[1] * d)[None, :, None]
              * unresolved.interpolation_power(k[2] * d)[None, None, :])
    predicted = np.sum(power * weight)
    points = rng.uniform(0, 1, (200_000, 3)) * np.asarray(grid.lengths)
    sampled = sample_velocity(box, points, np.zeros(len(points)), 10.0)[:, 0]
    measured = np.mean(sampled ** 2)
    assert measured == pytest.approx(predicted, rel=0.015)
    assert predicted < 0.95 * np.mean(u ** 2)          # the loss is there to be seen


def test_unresolved_radial_variances_converge_and_vanish_for_a_fine_box():
    # a staring point probe along x, no dwell: the rule refined (8 panels per decade,
    # down to 1e-3 of the Nyquist wavenumber) moves the result by under 1 %
    # (constants.UNRESOLVED_PANELS' statement); and a box 8 times finer leaves less
    # (the inertial range: (1/8)^(2/3) = 1/4 of it, the interpolation's share falling
    # the same way): a quarter within 30 % (the energy range's curvature)
    from uq.physics.scangeometry import ScanGeometry
    geometry = ScanGeometry(np.array([[1.0, 0.0, 0.0]]), np.zeros((1, 1, 3)), np.zeros(1),
                            0.0, 1.0, np.zeros(1), np.ones((1, 1)), np.ones((1, 3, 1)),
                            10.0)
    def variance(spacing, panels=constants.UNRESOLVED_PANELS):
        rule = unresolved.axis_rule(np.pi / spacing, panels=panels)
        return unresolved.unresolved_radial_variances(spacing, geometry, np.zeros(1), None,
                                                      1.0, 33.6, 3.9, rule=rule)[0, 0]
    coarse = variance(4.2)
    assert variance(4.2, (8, 1e-3)) == pytest.approx(coarse, rel=0.01)
    assert variance(4.2 / 8) == pytest.approx(coarse / 4, rel=0.3)
