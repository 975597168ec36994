"""Sweeps: vectorised chunks equal scene-by-scene runs, common random numbers, linked
keys, GUM-only grids, checkpoints and resume, dask scale-out."""
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

import uq
import uq.pipeline.sweep
from uq.pipeline.checkpoint import Checkpoint
from uq.errors import CheckpointError, ScenarioError
from uq.pipeline.sweep import sweep_plan

ROOT = Path(__file__).resolve().parents[2]
FLOATING = ROOT / "scenarios" / "floating_lidar_full.yaml"
# Scene-by-scene and vectorised evaluation do the same arithmetic element by element; only
# the order of a few matrix-product sums may differ, a few ulps of the terms.
RTOL = 1e-10


def small(path=FLOATING, **changes):
    return uq.load_scenario(path, {"sampling.n": 3000, **changes})


def data_equal(a, b):
    """Every variable and coordinate identical (attributes such as runtime_s aside)."""
    xr.testing.assert_equal(a.drop_attrs(), b.drop_attrs())


def test_vector_sweep_equals_scene_by_scene():
    sweep = {"wind.direction": [10.0, 200.0], "lidar.misalignment": [0.0, 45.0],
             "ship.pitch": [-4.0, 6.0]}
    scenario = small(**{"ins.correlation": "beam", "sweep": sweep})
    swept = uq.run(scenario)
    assert swept["wind_speed_mc_u"].dims == ("wind_direction", "lidar_misalignment",
                                             "ship_pitch", "range")
    for direction in sweep["wind.direction"]:
        for misalignment in sweep["lidar.misalignment"]:
            for pitch in sweep["ship.pitch"]:
                one = uq.run(small(**{"ins.correlation": "beam", "wind.direction": direction,
                                      "lidar.misalignment": misalignment, "ship.pitch": pitch}))
                point = swept.sel(wind_direction=direction, lidar_misalignment=misalignment,
                                  ship_pitch=pitch)
                for name in one.data_vars:
                    np.testing.assert_allclose(point[name].values, one[name].values,
                                               rtol=RTOL, atol=1e-13, err_msg=name)


def test_compiled_sweep_equals_the_numpy_model_in_single_scene_chunks(monkeypatch):
    """Wind outputs, scan INS: the compiled model, several scenes per chunk. The numpy
    model scene by scene gives the same results to the ulps of two implementations."""
    sweep = {"wind.direction": [0.0, 120.0, 359.0], "ship.pitch": [-4.0, 6.0]}
    scenario = small(**{"sampling.n": 2**14, "sweep": sweep,
                        "outputs": ["wind_speed", "wind_direction", "vertical_wind"]})
    assert uq.pipeline.sweep.scenes_per_chunk(scenario) > 1
    compiled = uq.run(scenario)
    monkeypatch.setattr(uq.pipeline.sweep, "SWEEP_CHUNK_ELEMENTS_COMPILED", 1)       # 1 per chunk
    monkeypatch.setattr("uq.physics.fused.applicable", lambda *args, **kwargs: False)
    assert uq.pipeline.sweep.scenes_per_chunk(scenario) == 1
    plain = uq.run(scenario)
    for name in plain.data_vars:
        np.testing.assert_allclose(compiled[name].values, plain[name].values,
                                   rtol=RTOL, atol=1e-12, err_msg=name)


def test_common_random_numbers_across_scenes_and_groups():
    """Identical scenes in a sweep, whether vectorised (wind.direction) or in separate
    groups (ins.sog.u), see the same draws: identical results, not ~1/sqrt(N) apart."""
    sweep = {"ins.sog.u": [0.02, 0.02], "wind.direction": [30.0, 30.0]}
    result = uq.run(small(**{"sweep": sweep}))["wind_speed_mc_u"].values
    assert np.all(result == result[0, 0])
    other_seed = uq.run(small(**{"sweep": sweep, "sampling.seed": 7}))["wind_speed_mc_u"]
    assert np.all(other_seed.values != result)       # the check can fail: seeds matter


def test_structural_sweep_keys_keep_file_order():
    sweep = {"ins.heading.u": [0.1, 1.0], "wind.direction": [0.0, 90.0, 180.0]}
    result = uq.run(small(**{"sweep": sweep}))
    assert result["wind_speed_mc_u"].dims[:2] == ("ins_heading_u", "wind_direction")
    one = uq.run(small(**{"ins.heading.u": 1.0, "wind.direction": 90.0}))
    np.testing.assert_allclose(result["wind_speed_gum_u"].sel(ins_heading_u=1.0,
                                                              wind_direction=90.0),
                               one["wind_speed_gum_u"], rtol=RTOL)


def test_linked_key_follows_its_leader():
    sweep = {"ship.cog": [0.0, 90.0], "ship.heading": {"same_as": "ship.cog"}}
    result = uq.run(small(**{"sweep": sweep}))
    assert "ship_heading" in result.coords and result["ship_heading"].dims == ("ship_cog",)
    one = uq.run(small(**{"ship.cog": 90.0, "ship.heading": 90.0}))
    np.testing.assert_allclose(result["wind_speed_gum_u"].sel(ship_cog=90.0),
                               one["wind_speed_gum_u"], rtol=RTOL)


@pytest.mark.parametrize("sweep, key", [
    ({"ship.heading": {"same_as": "ship.cog"}}, "sweep.ship.heading.same_as"),
    ({"ship.cog": [0, 90], "lidar.errors.misalignment.u": {"same_as": "ship.cog"}},
     "sweep.lidar.errors.misalignment.u.same_as")])
def test_bad_links_are_rejected(sweep, key):
    with pytest.raises(ScenarioError, match=key.replace(".", r"\.")):
        small(**{"sweep": sweep})


def test_gum_only_grid_has_no_monte_carlo():
    sweep = {"wind.direction": [0.0, 120.0, 240.0]}
    gum_only = uq.run(small(**{"sweep": sweep, "sampling.method": "none",
                               "sampling.n": None}))      # (n does not apply: removed)
    sampled = uq.run(small(**{"sweep": sweep}))
    assert not [name for name in gum_only.data_vars if "_mc_" in name]
    # the contract's q_gum_valid is there, False: without Monte Carlo nothing validates it
    assert not any(gum_only[name].any() for name in gum_only.data_vars if "valid" in name)
    assert np.all(gum_only["mc_n_samples"] == 0)
    for name in ("wind_speed_gum_u", "wind_direction_gum_u", "wind_speed_budget",
                 "wind_speed_true", "wind_speed_nominal"):
        np.testing.assert_allclose(gum_only[name], sampled[name], rtol=RTOL)


def test_results_do_not_depend_on_sampling_chunk_size():
    sweep = {"wind.direction": [0.0, 90.0]}
    a = uq.run(small(**{"sweep": sweep, "sampling.n": 140_000}))
    b = uq.run(small(**{"sweep": sweep, "sampling.n": 140_000, "sampling.chunk_size": 1}))
    data_equal(a, b)


@pytest.fixture
def many_chunks(monkeypatch):
    """One scene per chunk, so a short sweep has several chunks."""
    monkeypatch.setattr(uq.pipeline.sweep, "SWEEP_CHUNK_ELEMENTS", 1)
    monkeypatch.setattr(uq.pipeline.sweep, "SWEEP_CHUNK_ELEMENTS_COMPILED", 1)
    return small(**{"sweep": {"wind.direction": [0.0, 90.0, 180.0, 270.0],
                              "ins.heading.u": [0.2, 0.5]}, "sampling.seed": None})


def test_interrupted_run_resumes_to_the_uninterrupted_result(tmp_path, many_chunks):
    assert len(sweep_plan(many_chunks).chunks) == 8
    directory = tmp_path / "out.nc.partial"

    def interrupt_after_three(done, total):
        if done == 3:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        uq.run(many_chunks, progress=interrupt_after_three, checkpoint=Checkpoint(directory))
    assert len(list(directory.glob("chunk-*.nc"))) == 3
    seen = []
    resumed = uq.run(many_chunks, progress=lambda done, total: seen.append(done),
                     checkpoint=Checkpoint(directory, resume=True))
    assert seen == [3, 4, 5, 6, 7, 8]                # only the missing chunks computed
    seed = resumed.attrs["seed"]                    # drawn fresh, kept by the checkpoint
    data_equal(resumed, uq.run(many_chunks.with_values({"sampling.seed": seed})))


def test_resume_refuses_a_checkpoint_of_another_run(tmp_path, many_chunks):
    directory = tmp_path / "out.nc.partial"
    uq.run(many_chunks.with_values({"sampling.seed": 1}), checkpoint=Checkpoint(directory))
    with pytest.raises(CheckpointError, match="different scenario"):
        uq.run(many_chunks.with_values({"sampling.seed": 2}),
               checkpoint=Checkpoint(directory, resume=True))


@pytest.fixture(scope="module")
def cluster():
    """A client of uq's local cluster of 2 worker processes (the 'test' extra installs
    dask: no silent skip), shared by the module's distributed tests."""
    from uq.pipeline.cluster import local_cluster
    with local_cluster(2, host="127.0.0.1") as client:
        yield client


def test_distributed_run_is_identical_to_single_process(many_chunks, cluster):
    scenario = many_chunks.with_values({"sampling.seed": 11})
    remote = uq.run(scenario, client=cluster)
    data_equal(remote, uq.run(scenario))


class RecordingClient:
    """A dask client that records what each task is submitted with."""

    def __init__(self, client):
        self.client, self.submitted = client, []

    def submit(self, function, *arguments, **options):
        self.submitted.append(arguments)
        return self.client.submit(function, *arguments, **options)

    def __getattr__(self, name):
        return getattr(self.client, name)


#: Bytes of a task's own arguments (its chunk, seed, model switch and the checkpoint's
#: digest: ~250 bytes pickled); the scenario and the plan (a few kB, growing with the
#: grid) go to the cluster once.
TASK_BYTES = 1024


def test_the_driver_evaluates_no_scene_and_encodes_no_chunk(tmp_path, many_chunks, cluster,
                                                            monkeypatch):
    """A distributed run with a checkpoint, as uq run --workers makes it: the driving
    process evaluates no model (Monte Carlo, GUM, paper model) and encodes no checkpoint
    file; each task carries its chunk and a few hundred bytes, the scenario and the plan
    are sent once; the chunks the workers encoded resume to the same result."""
    import pickle
    from distributed import Future
    import uq.pipeline.checkpoint
    import uq.pipeline.runner
    scenario = many_chunks.with_values({"sampling.seed": 11})
    local = uq.run(scenario)

    def in_the_driver(*arguments, **options):
        raise AssertionError("work of a chunk done in the driving process")
    for name in ("run_chunk", "run_scene", "_propagate", "_paper_uncertainty",
                 "encode_chunk"):
        monkeypatch.setattr(uq.pipeline.runner, name, in_the_driver)
    monkeypatch.setattr(uq.pipeline.checkpoint, "encode_chunk", in_the_driver)
    monkeypatch.setattr(uq.pipeline.checkpoint, "write_netcdf", in_the_driver)
    client = RecordingClient(cluster)
    directory = tmp_path / "out.nc.partial"
    data_equal(uq.run(scenario, client=client, checkpoint=Checkpoint(directory)), local)
    assert len(client.submitted) == len(sweep_plan(scenario).chunks) == 8
    for arguments in client.submitted:
        shared, own = arguments[:2], arguments[2:]
        assert all(isinstance(item, Future) for item in shared)
        assert len(pickle.dumps(own)) < TASK_BYTES
    assert len(list(directory.glob("chunk-*.nc"))) == 8
    seen = []                           # every chunk from the workers' files, none computed
    resumed = uq.run(scenario, progress=lambda done, total: seen.append(done),
                     checkpoint=Checkpoint(directory, resume=True))
    assert seen == [8]
    data_equal(resumed, local)


def test_the_local_cluster_slows_dask_housekeeping(cluster):
    """uq.pipeline.cluster's settings reach the worker processes."""
    import dask
    from uq.pipeline.cluster import CLUSTER_SETTINGS
    seen = cluster.run(lambda: {key: dask.config.get(key) for key in CLUSTER_SETTINGS})
    assert list(seen.values()) == [CLUSTER_SETTINGS] * 2
