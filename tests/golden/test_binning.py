"""Bins of the reference wind speed, against hand-computed values."""
import numpy as np
import pytest

from uq.golden.binning import bin_centres, bin_index, bin_statistics, sufficient_bins


def test_bin_edges_are_half_open_and_centred_on_multiples_of_half_a_metre():
    """[c - 0.25, c + 0.25): an edge belongs to the bin above it."""
    speeds = np.array([3.74, 3.75, 4.0, 4.2499, 4.25, 4.7499, 4.75, 0.0, np.nan])
    centres = 0.5 * bin_index(speeds)
    np.testing.assert_array_equal(centres[:8], [3.5, 4.0, 4.0, 4.0, 4.5, 4.5, 5.0, 0.0])
    assert bin_index(speeds)[-1] == -1                     # NaN: in no bin


def test_bin_centres_inclusive():
    np.testing.assert_allclose(bin_centres(4.0, 6.0), [4.0, 4.5, 5.0, 5.5, 6.0])
    np.testing.assert_allclose(bin_centres(3.9, 5.1), [4.0, 4.5, 5.0])


SMALL = dict(reference=np.array([4.0, 4.1, 4.3, 5.1, 5.2, np.nan]),
             unit=np.array([4.2, 4.0, 4.4, 5.0, 5.5, 7.0]))


def test_bin_statistics_hand_computed():
    """Bin 4.0: refs 4.0, 4.1, units 4.2, 4.0; bin 4.5: one record; bin 5.0: refs 5.1,
    5.2, units 5.0, 5.5; bin 5.5: empty; the NaN pair is left out."""
    s = bin_statistics(**SMALL, centres=np.array([4.0, 4.5, 5.0, 5.5]))
    np.testing.assert_array_equal(s["n_records"], [2, 1, 2, 0])
    np.testing.assert_allclose(s["reference_mean"][:3], [4.05, 4.3, 5.15])
    np.testing.assert_allclose(s["unit_mean"][:3], [4.1, 4.4, 5.25])
    np.testing.assert_allclose(s["unit_std"][[0, 2]], [np.sqrt(0.02), np.sqrt(0.125)])
    np.testing.assert_allclose(s["deviation_mean"][:3], [0.05, 0.1, 0.1])
    np.testing.assert_allclose(s["deviation_std"][[0, 2]], [np.sqrt(0.045), np.sqrt(0.08)])
    assert np.isnan(s["unit_std"][1]) and np.isnan(s["deviation_std"][1])   # one record
    assert all(np.isnan(s[k][3]) for k in s if k != "n_records")              # empty


def test_sufficient_and_required_bins():
    sufficient, required = sufficient_bins(np.array([6, 5, 0, 9]),
                                           np.array([3.5, 4.0, 16.0, 16.5]))
    np.testing.assert_array_equal(sufficient, [True, False, False, True])
    np.testing.assert_array_equal(required, [False, True, True, False])


@pytest.mark.parametrize("speed", [0.25, 4.25, 10.75, 15.75, 24.25])
def test_every_edge_of_the_grid_goes_up(speed):
    assert 0.5 * bin_index(speed) == pytest.approx(speed + 0.25)
