"""``uq run --model numpy|compiled`` and ``uq.run(model=...)``: the numpy reference model
reproduces the compiled model's results.

Tolerance 1e-12 m s-1 (deg for directions, times the speed: an arc length): the two
models compute the same float64 products and sums of O(10) terms of 1-30 m s-1 in another
order (see tests/physics/test_fused.py and test_fusedmotion.py), and the engine's
statistics of identical draws then differ by the same rounding; every statistic below is
a mean, a standard deviation or an order statistic of those values.
"""
import subprocess
import sys

import numpy as np
import pytest
import xarray as xr

from uq.pipeline.runner import run
from uq.pipeline.scenario import load_scenario
from uq.pipeline.shipped import scenario_path

TOLERANCE = 1e-12          # [m s-1] (module docstring)
VARIABLES = ("mc_mean", "mc_u", "mc_low", "mc_high", "gum_u", "nominal")


def _assert_agree(one, two, speed):
    for quantity in ("wind_speed", "wind_direction", "vertical_wind"):
        for statistic in VARIABLES:
            name = f"{quantity}_{statistic}"
            if name not in one:
                continue
            scale = np.deg2rad(speed) if quantity == "wind_direction" else 1.0
            gap = np.abs(one[name].values - two[name].values) * scale
            assert np.nanmax(gap) <= TOLERANCE, (name, float(np.nanmax(gap)))


@pytest.mark.parametrize("name, changes", [
    ("floating_lidar_full", {"sampling.n": 3000}),
    ("rubio2022_misalignment", {"sampling.n": 2000,
                                "sweep.wind.direction": [0.0, 120.0, 240.0],
                                "sweep.lidar.misalignment": [-10.0, 10.0]}),
    ("floating_lidar_waves", {"sampling.n": 2000}),
])
def test_numpy_reproduces_the_compiled_model(name, changes):
    scenario = load_scenario(scenario_path(name), changes)
    compiled, numpy = run(scenario), run(scenario, model="numpy")
    assert "model" not in compiled.attrs and numpy.attrs["model"].startswith("numpy")
    _assert_agree(compiled, numpy, scenario.settings["wind"]["speed"])


def test_an_unknown_model_is_refused():
    with pytest.raises(ValueError, match="model must be one of compiled, numpy"):
        run({"sampling": {"n": 100}}, model="fortran")


def test_the_command_line_switch(tmp_path):
    """``uq run --model numpy`` writes the numpy model's results; a bad value is exit 2."""
    common = [sys.executable, "-m", "uq.cli", "run", "rubio2022_case_i", "--quiet",
              "--set", "sampling.n=500", "--set", "sweep.wind.direction=[0, 90]"]
    done = subprocess.run(common + ["--model", "numpy", "-o", "n.nc"], cwd=tmp_path,
                          capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    with xr.open_dataset(tmp_path / "n.nc") as numpy:
        assert numpy.attrs["model"].startswith("numpy")
        compiled = run(load_scenario(scenario_path("rubio2022_case_i"), {
            "sampling.n": 500, "sweep.wind.direction": [0, 90]}), model="compiled")
        _assert_agree(compiled, numpy.load(), 5.0)     # the scenario's wind speed
    bad = subprocess.run(common + ["--model", "gpu"], cwd=tmp_path, capture_output=True,
                         text=True)
    assert bad.returncode == 2 and "invalid choice: 'gpu'" in bad.stderr
    assert len(bad.stderr.strip().splitlines()) <= 2 and "Traceback" not in bad.stderr
