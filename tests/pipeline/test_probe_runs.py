"""The probe volume through scenario files, runs and results (issue 19)."""
import math

import numpy as np
import pytest

import uq
from uq.constants import (WINDCUBE_GATE_LENGTH, WINDCUBE_PULSE_FWHM, ZEPHIR_BEAM_RADIUS_MM,
                          ZEPHIR_TRUNCATION, ZEPHIR_WAVELENGTH_UM)
from uq.errors import ScenarioError
from uq.pipeline.scenario import load_scenario

PROBE = {"kind": "pulsed", "gate_length": WINDCUBE_GATE_LENGTH,
         "pulse_fwhm": WINDCUBE_PULSE_FWHM, "wavelength": ZEPHIR_WAVELENGTH_UM,
         "beam_radius": ZEPHIR_BEAM_RADIUS_MM, "truncation": ZEPHIR_TRUNCATION}
BASE = {"name": "probe", "wind": {"speed": 9.0, "direction": 200.0, "shear": 0.2},
        "ship": {"pitch": 4.0, "roll": -3.0, "sog": 1.0},
        "ins": {"heading": {"dist": "normal", "u": 0.2}},
        "lidar": {"height": 3.0, "ranges": [40.0, 120.0, 200.0], "vertical_beam": True,
                  "errors": {"radial_velocity": {"dist": "normal", "u": 0.1}}},
        "sampling": {"n": 4096, "seed": 7},
        "outputs": ["wind_speed", "wind_direction", "vertical_wind", "radial_velocity"]}


def scenario(**changes):
    raw = {**BASE, "lidar": {**BASE["lidar"], **changes.pop("lidar", {})}, **changes}
    return load_scenario(raw)


def test_a_point_probe_is_todays_model_bit_for_bit():
    today = uq.run(scenario())
    point = uq.run(scenario(lidar={"probe": {"kind": "point"}}))
    assert set(today.data_vars) < set(point.data_vars)
    for name in today.data_vars:
        np.testing.assert_array_equal(point[name].values, today[name].values, err_msg=name)
    assert not np.any(point["wind_speed_probe_bias"].values)
    assert (point["probe_nodes"].values == 1).all()


def test_kind_sweep_keeps_nominal_minus_true_and_states_the_truncation():
    """q_nominal - q_true is the probe's bias plus the correction's own systematic error
    (that of the point probe), for every kind, under tilt; the CW truncation is stated."""
    ds = uq.run(scenario(lidar={"probe": PROBE},
                         sweep={"lidar.probe.kind": ["point", "pulsed", "cw"]}))
    assert ds["wind_speed_probe_bias"].dims == ("lidar_probe_kind", "range")
    point = ds.sel(lidar_probe_kind="point")
    for quantity in ("wind_speed", "vertical_wind"):
        systematic = ds[f"{quantity}_nominal"] - ds[f"{quantity}_true"]
        own = point[f"{quantity}_nominal"] - point[f"{quantity}_true"]
        # a difference of numbers of ~10 m/s: a few ulps
        np.testing.assert_allclose(systematic - ds[f"{quantity}_probe_bias"],
                                   own.broadcast_like(systematic), atol=1e-13)
    bias = ds["wind_speed_probe_bias"]
    assert (bias.sel(lidar_probe_kind="pulsed") < 0).all()      # alpha (alpha - 1) < 0
    assert (bias.sel(lidar_probe_kind="cw") < 0).all()
    assert "truncated where W < 0.02 W(0)" in ds.attrs["probe"]
    assert ds.attrs["probe_truncation"] == ZEPHIR_TRUNCATION
    assert ds["probe_nodes"].sel(lidar_probe_kind="point") == 1
    assert (ds["probe_nodes"].sel(lidar_probe_kind=["pulsed", "cw"]) > 1).all()
    assert (ds["probe_quadrature_error"] <= 1e-6).all()
    assert ds["wind_speed_probe_bias"].attrs["units"] == "m s-1"


def test_probe_parameter_errors_are_monte_carlo_inputs_like_any_other():
    """u(Vh) from a gate-length error alone: Monte Carlo and the GUM agree within the
    sampling error of u (3 u / sqrt(2 N)) plus the bias's curvature (Var is quadratic in
    the gate length: a relative u_dp^2 / (2 dp^2) = 0.5 % for u_dp = 3 m)."""
    ds = uq.run(scenario(lidar={"probe": PROBE, "errors": {
        "gate_length": {"dist": "normal", "u": 3.0},
        "beam_radius": {"dist": "normal", "u": 1.0}}},
        ins={}, sampling={"n": 20000, "seed": 3}))
    assert "lidar.errors.gate_length" in ds["input"].values
    budget = ds["wind_speed_budget"].sel(input="lidar.errors.beam_radius")
    assert not budget.any()                       # a pulsed probe has no beam radius
    assert "without effect where lidar.probe.kind is pulsed" in ds.attrs["skipped"]
    mc, gum = ds["wind_speed_mc_u"].values, ds["wind_speed_gum_u"].values
    n = ds.attrs["n_samples"]
    assert np.all(gum > 0)
    np.testing.assert_array_less(np.abs(mc - gum), 3 * gum / math.sqrt(2 * n) + 0.005 * gum)


@pytest.mark.parametrize("probe, key", [
    ({"kind": "flash"}, "lidar.probe.kind"),
    ({"kind": "pulsed", "gate_length": 30.0}, "lidar.probe.pulse_fwhm"),
    ({"kind": "pulsed", "gate_length": -1.0, "pulse_fwhm": 20.0}, "lidar.probe.gate_length"),
    ({"kind": "cw", "wavelength": 1.5, "beam_radius": 28.0, "truncation": 1.0},
     "lidar.probe.truncation"),
    ({"kind": "cw", "wavelength": 1.5, "beam_radius": 28.0, "truncation": 0.0},
     "lidar.probe.truncation"),
    ({"kind": "point", "focus": 100.0}, "lidar.probe.focus"),
    # the far field of a 2 mm beam ends at 0.25 pi a^2 / lambda = 2 m
    ({"kind": "cw", "wavelength": 1.565, "beam_radius": 2.0, "truncation": 0.02},
     "lidar.probe.beam_radius"),
])
def test_bad_probes_are_refused_naming_the_key(probe, key):
    with pytest.raises(ScenarioError, match=key.replace(".", r"\.")):
        scenario(lidar={"probe": probe})


def test_a_probe_error_needs_its_parameter():
    with pytest.raises(ScenarioError, match=r"lidar\.errors\.wavelength"):
        scenario(lidar={"probe": {"kind": "point"},
                        "errors": {"wavelength": {"dist": "normal", "u": 0.01}}})
