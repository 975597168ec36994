"""Two independent implementations of Mann's (1998) sheared spectral tensor agree.

:mod:`uq.physics.turbulencebox` builds the box from the spectral factor C(k) (Mann 1998,
Sec. 3) and :mod:`uq.physics.spectraltensor` writes Phi_ij(k) (Mann 1994, Eq. 3.13-3.16);
their algebra was written separately (they share only the exact eddy lifetime), so
``C C^T = Phi`` checks the algebra of both.
"""
import numpy as np
import pytest

from uq.physics import spectraltensor, turbulencebox

LENGTH, ANISOTROPY, ALPHA_EPSILON = 33.6, 3.9, 0.7       # IEC 61400-1 Mann parameters


def _wavenumbers(n=2000, seed=3):
    """Random k over four decades about 1/L, every octant, k1 != 0 (the tensor's zeta
    terms carry k2/k1)."""
    rng = np.random.default_rng(seed)
    return 10 ** rng.uniform(-3, 1, size=(3, n)) * rng.choice([-1, 1], size=(3, n))


def _factor_product(k):
    c = turbulencebox.mann1998_spectral_factor(*k, ALPHA_EPSILON, LENGTH, ANISOTROPY)
    c = np.moveaxis(c, (0, 1), (-2, -1))
    return c @ np.swapaxes(c, -1, -2)


def _relative_difference(a, b):
    return np.max(np.abs(a - b).max(axis=(-1, -2)) / np.abs(b).max(axis=(-1, -2)))


def test_factor_squared_is_the_tensor_with_the_exact_lifetime(monkeypatch):
    # with the same (exact, hypergeometric) eddy lifetime in both, only rounding differs:
    # ~100 flops per element in double precision, 1e-11 leaves a margin over ~1e-13
    monkeypatch.setattr(turbulencebox, "eddy_lifetime",
                        lambda kl, gamma, xp=np: spectraltensor.mann_eddy_lifetime(kl, 1.0, gamma))
    k = _wavenumbers()
    phi = spectraltensor.MannTensor(LENGTH, ANISOTROPY, ALPHA_EPSILON).matrix(*k)
    assert _relative_difference(_factor_product(k), phi) < 1e-11


def test_tabulated_lifetime_costs_what_its_table_says():
    # the box uses a tabulated lifetime (relative error 3.4e-6 at 200 nodes per decade,
    # uq.constants); Phi depends on beta through k30 = k3 + beta k1, with a sensitivity of
    # order (beta k1 / k0)^2 <= a few, so 1e-4 bounds the propagated difference
    k = _wavenumbers(seed=4)
    phi = spectraltensor.MannTensor(LENGTH, ANISOTROPY, ALPHA_EPSILON).matrix(*k)
    assert _relative_difference(_factor_product(k), phi) < 1e-4
    kl = np.sqrt(np.sum(k**2, axis=0)) * LENGTH
    exact = spectraltensor.mann_eddy_lifetime(kl / LENGTH, LENGTH, ANISOTROPY)
    assert np.max(np.abs(turbulencebox.eddy_lifetime(kl, ANISOTROPY) / exact - 1)) < 1e-5
