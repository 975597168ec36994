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
