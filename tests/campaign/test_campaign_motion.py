"""Each record's motion as harmonic components (uq.campaign.motion)."""
import numpy as np
import pytest

from uq.campaign import motion
from uq.physics.motion import DEGREES_OF_FREEDOM
from uq.physics.waves import jonswap_components

RESPONSE = {"roll": (4.0, 90.0), "pitch": (3.0, 0.0), "heave": (1.0, 0.0)}


def test_a_sea_state_is_uq_waves_jonswap_scaled_to_its_hs_and_tp():
    """The unit spectrum scaled (amplitudes with Hs, frequencies with 1/Tp) equals the
    JONSWAP components of that sea computed directly: the normalised spectrum has one
    shape in f / fp (to rounding)."""
    found = motion.sea_state(np.array([2.3]), np.array([7.5]), RESPONSE, 3.3, 24,
                             (0.5, 4.0))
    direct = jonswap_components(2.3, 7.5, 3.3, 24, (0.5 / 7.5, 4.0 / 7.5),
                                {d: (f, np.radians(lag)) for d, (f, lag) in RESPONSE.items()})
    np.testing.assert_allclose(found.frequency[0],
                               [c.angular_frequency / (2 * np.pi) for c in direct], rtol=1e-12)
    amplitude = np.sqrt(2 * found.power[0])[:, None] * found.shapes[0]
    expected = np.array([np.array(c.amplitudes) * np.exp(1j * np.array(c.lags)) for c in direct])
    np.testing.assert_allclose(amplitude, expected, rtol=1e-9, atol=1e-15)


def test_a_sea_state_carries_its_significant_height():
    """The heave of a unit response: 4 sqrt(sum P) = Hs."""
    found = motion.sea_state(np.array([1.0, 3.0]), np.array([6.0, 9.0]), {"heave": (1.0, 0.0)},
                             3.3, 32, (0.5, 4.0))
    np.testing.assert_allclose(4 * np.sqrt(found.power.sum(axis=1)), [1.0, 3.0], rtol=1e-12)
    unknown = motion.sea_state(np.array([np.nan]), np.array([6.0]), {"heave": (1.0, 0.0)},
                               3.3, 8, (0.5, 4.0))
    assert not unknown.valid[0] and np.all(unknown.power == 0)


def test_statistics_are_one_component_per_degree_of_freedom():
    found = motion.statistics({"roll": np.array([0.05, np.nan]), "heave": np.array([0.4, 0.3])},
                              {"roll": np.array([6.0, 6.0]), "heave": np.array([8.0, 8.0])})
    assert found.labels == ("roll", "heave")
    np.testing.assert_allclose(found.power[0], [0.05 ** 2 / 2, 0.4 ** 2 / 2])
    np.testing.assert_allclose(found.frequency[0], [1 / 6, 1 / 8])
    assert found.valid.tolist() == [True, False]
    assert found.shapes[1][DEGREES_OF_FREEDOM.index("heave")] == 1.0


def test_the_polarisation_basis_represents_any_hermitian_matrix(rng):
    dofs = [0, 1, 5]
    shapes, labels = motion.polarisation_shapes(dofs)
    assert len(labels) == len(shapes) == 9
    a = rng.normal(size=(4, 3, 3)) + 1j * rng.normal(size=(4, 3, 3))
    local = a @ np.conj(np.swapaxes(a, -1, -2))                 # Hermitian (4, 3, 3)
    full = np.zeros((4, 6, 6), complex)
    full[np.ix_(range(4), dofs, dofs)] = local
    power = motion.polarisation_powers(full, dofs)
    rebuilt = np.einsum("ns,sd,se->nde", power, shapes, np.conj(shapes))
    np.testing.assert_allclose(rebuilt, full, atol=1e-12)


def test_within_drops_the_components_outside_and_reports_their_share():
    found = motion.statistics({"roll": np.array([0.1]), "heave": np.array([0.1])},
                              {"roll": np.array([6.0]), "heave": np.array([0.2])})
    kept, share = found.within(0.005, 2.0)
    assert share[0] == pytest.approx(0.5)
    assert kept.power[0, 1] == 0.0 and kept.power[0, 0] == found.power[0, 0]
    np.testing.assert_allclose(motion.motion_variance(np.array([[2.0, 3.0]]), kept.power,
                                                      1.0), [4 * 0.1 ** 2 / 2], rtol=1e-15)
