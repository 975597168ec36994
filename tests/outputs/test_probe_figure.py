"""The probe-volume figure and the shipped comparison scenario (issue 19)."""
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
import pytest

import uq
from uq.outputs import figures, plots
from uq.pipeline.scenario import load_scenario

ROOT = Path(__file__).resolve().parents[2]
SHIPPED = ROOT / "scenarios" / "probe_volume.yaml"


@pytest.fixture(scope="module")
def comparison():
    """The shipped scenario, with fewer trials and gates (the figure needs neither)."""
    return uq.run(load_scenario(SHIPPED, {"sampling.n": 2000,
                                          "lidar.ranges": [40.0, 100.0, 200.0]}))


def test_the_shipped_scenario_compares_point_pulsed_and_cw_for_two_shears(comparison):
    assert list(comparison["lidar_probe_kind"].values) == ["point", "pulsed", "cw"]
    assert list(comparison["wind_shear"].values) == [0.14, 0.2]
    bias = comparison["wind_speed_probe_bias"]
    assert not bias.sel(lidar_probe_kind="point").any()
    cw, pulsed = (np.abs(bias.sel(lidar_probe_kind=k)).values for k in ("cw", "pulsed"))
    assert (np.diff(cw, axis=-1) > 0).all() and (np.diff(pulsed, axis=-1) < 0).all()


def test_the_figure_draws_the_bias_of_each_kind_against_range(comparison):
    names = [name for name, _ in figures.figure_plan(comparison)]
    assert names == ["uncertainty_against_sweep", "probe_bias_against_range"]
    figure = plots.plot_probe_bias(comparison)
    top = figure.axes[:2]                    # m s-1, one column per shear
    for ax, shear in zip(top, (0.14, 0.2)):
        lines = {line.get_label(): line for line in ax.get_lines() if
                 not line.get_label().startswith("_")}
        assert set(lines) == {"point", "pulsed", "cw"}
        for kind, line in lines.items():
            np.testing.assert_array_equal(line.get_xdata(), [40.0, 100.0, 200.0])
            np.testing.assert_array_equal(line.get_ydata(), comparison[
                "wind_speed_probe_bias"].sel(lidar_probe_kind=kind, wind_shear=shear).values)
    plt.close(figure)
    assert "falls with height" in figures.caption("probe_bias_against_range")


def test_a_single_scene_gets_the_figure_and_a_3d_sweep_only_after_select(comparison):
    single = comparison.sel(lidar_probe_kind="cw", wind_shear=0.2)
    assert plots.probe_panels(single) is None
    assert plots.probe_panels(comparison.isel(range=0)) is False      # one gate
    figure = plots.plot_probe_bias(single)
    assert [line.get_label() for line in figure.axes[0].get_lines()][0] == "cw"
    plt.close(figure)


def test_the_comparison_file_passes_the_cf_checker(tmp_path, cf_compliance, comparison):
    """Written by uq run's writer: the probe's variables, attributes and the text
    coordinate of the swept kind pass compliance-checker CF 1.10."""
    from uq.files import write_netcdf
    cf_compliance(write_netcdf(comparison, tmp_path / "probe.nc"))


def test_a_probe_results_trials_are_drawn_again_compiled_with_its_stored_node_count(
        monkeypatch):
    """uq plot's histogram of a CW buoy: the trials drawn again are the run's own (their
    mean and u are the stored ones, rtol 1e-12: the same numbers summed in another
    order), through the compiled model, with the node count the run stored (the numpy
    search of :func:`uq.physics.probe.node_count` is not run again)."""
    from uq.outputs.samples import scene_trials
    from uq.physics import fused, probe
    result = uq.run(load_scenario(SHIPPED, {"sweep": {}, "lidar.probe.kind": "cw",
                                            "sampling.n": 1000,
                                            "lidar.ranges": [40.0, 200.0]}))
    assert int(result["probe_nodes"]) > 1

    def no_search(*args, **kwargs):
        raise AssertionError("the node count was searched again")
    monkeypatch.setattr(probe, "node_count", no_search)
    compiled = []
    original = fused.evaluate

    def counted(*args):                       # the calls the compiled model takes
        out = original(*args)
        compiled.extend([1] if out is not None else [])
        return out
    monkeypatch.setattr(fused, "evaluate", counted)
    trials = scene_trials(result, ("wind_speed",))["wind_speed"]
    assert compiled and len(trials) == 1000
    np.testing.assert_allclose(trials.mean(axis=0), result["wind_speed_mc_mean"], rtol=1e-12)
    np.testing.assert_allclose(trials.std(axis=0, ddof=1), result["wind_speed_mc_u"],
                               rtol=1e-12)
