"""Trials drawn again for a figure are the trials of the scene the figure names: for every
scene of every shipped scenario run small, the redrawn trials' mean and standard deviation
equal the run's stored Monte Carlo mean and u within Monte Carlo error."""
import itertools

import numpy as np
import pytest

from uq.outputs.figures import sweep_dimensions
from uq.outputs.samples import can_redraw, scene_assignments, scene_trials
from tests.outputs.small_runs import measurement_names, small_result

#: Standard errors of a mean or a standard deviation allowed between the redrawn trials
#: and the run's stored statistics. Both are the same trials (the same seed and blocks),
#: so they agree far closer; 5 standard errors is the Monte Carlo bound the statistics
#: are promised to within, and a wrong scene (another wind direction, another
#: correction) misses it by hundreds.
K = 5.0


def scenes(dataset):
    """Each scene of a result as ``{dim: index}``."""
    dims = sweep_dimensions(dataset)
    return [dict(zip(dims, index)) for index in
            itertools.product(*(range(dataset.sizes[d]) for d in dims))]


@pytest.mark.parametrize("name", measurement_names())
def test_redrawn_trials_are_each_scenes_own(name):
    dataset = small_result(name)
    outputs = [q for q in ("wind_speed", "wind_direction", "vertical_wind")
               if f"{q}_mc_mean" in dataset]
    checked = 0
    for scene in scenes(dataset):
        at = dataset.isel(scene)
        if not can_redraw(at) or not outputs:
            continue
        trials = scene_trials(at, tuple(outputs))
        for q in outputs:
            values = trials[q].reshape(len(trials[q]), -1)
            stored_mean = np.atleast_1d(at[f"{q}_mc_mean"].values)
            stored_u = np.atleast_1d(at[f"{q}_mc_u"].values)
            if q == "wind_direction":        # circular: deviations from the stored mean
                values = (values - stored_mean + 180.0) % 360.0 - 180.0
                stored_mean = np.zeros_like(stored_mean)
            n = len(values)
            if n == 1:                        # no uncertain input: the one exact trial
                np.testing.assert_allclose(values[0], stored_mean, rtol=1e-12, atol=1e-12)
                continue
            mean, u = np.nanmean(values, axis=0), np.nanstd(values, axis=0, ddof=1)
            scale = np.maximum(stored_u, 1e-12)
            assert np.all(np.abs(mean - stored_mean) <= K * scale / np.sqrt(n)), (scene, q)
            assert np.all(np.abs(u - stored_u) <= K * scale / np.sqrt(2 * (n - 1))), \
                (scene, q, u, stored_u)
        checked += 1
    if dataset.attrs.get("sampling_method") != "none" and outputs:
        assert checked, f"{name}: no scene could be drawn again"


def test_assignments_take_every_swept_key_from_the_selected_scene():
    dataset = small_result("rubio2022_misalignment")
    at = dataset.isel(ship_cog=1, lidar_misalignment=2, wind_direction=1)
    assert scene_assignments(at) == {
        "ship.cog": float(at["ship_cog"]), "ship.heading": float(at["ship_cog"]),
        "lidar.misalignment": float(at["lidar_misalignment"]),
        "wind.direction": float(at["wind_direction"])}


def test_a_result_of_several_scenes_is_not_drawn_as_one():
    with pytest.raises(ValueError, match="select one scene"):
        scene_assignments(small_result("rubio2022_case_i"))
