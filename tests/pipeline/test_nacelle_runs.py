"""Nacelle lidars through the pipeline: the issue's held-out keys through ``uq run``, a
two-beam lidar's w = 0, harmonics as a list, and the GUM against Monte Carlo (JCGM 101
clause 8) for small and large pitch (validation: test_mountsection.py)."""
import numpy as np
import pytest
import xarray as xr
import yaml

import uq
from uq.cli import main

#: The issue's held-out check: a 4-beam nacelle lidar (tilt 90, half-cone 15, clock
#: positions 0/90/180/270, range 100 m) at 150 m, lever arm [0, 0, 150], 0.25 s per beam,
#: pitch 3 deg at 25 s with a random phase; outputs wind_speed and wind_direction.
HELD_OUT = {
    "name": "nacelle_held_out",
    "wind": {"speed": 10.0, "direction": 0.0, "reference_height": 150.0},
    "ship": {"heading": 0.0},
    "motion": {"pitch": {"amplitude": 3.0, "period": 25.0, "phase": "random"}},
    "lidar": {"height": 150.0, "ranges": [100.0], "half_cone": 15.0,
              "azimuths": [0, 90, 180, 270], "mount": {"tilt": 90},
              "lever_arm": [0, 0, 150], "scan": {"beam_duration": 0.25}},
    "correction": "pointwise",
    "sampling": {"n": 2000, "seed": 25},
    "outputs": ["wind_speed", "wind_direction"],
}


def run_cli(tmp_path, scenario, *extra):
    path = tmp_path / "held_out.yaml"
    path.write_text(yaml.safe_dump(scenario))
    out = tmp_path / "out.nc"
    assert main(["run", str(path), "-o", str(out), *extra]) == 0
    with xr.open_dataset(out) as ds:
        return ds.load()


@pytest.mark.parametrize("correction", ["none", "pointwise"])
def test_the_held_out_keys_run_through_uq_run(tmp_path, correction):
    """Exactly the held-out keys run; without motion errors point-wise correction (a
    continuous exact INS) returns the true wind in every trial (its Monte Carlo spread is
    rounding, 1e-12), while no correction sees the nacelle's fore-aft velocity omega r A:
    u(Vh) = 150 m * (2 pi / 25 s) * 3 deg / sqrt(2) = 1.40 m/s to first order (the
    random phase's sin has variance 1/2); 10 % for the Monte Carlo's 2000 trials
    (relative u of a standard deviation ~ 1/sqrt(2 n) = 1.6 %, times 3) and the second
    order."""
    ds = run_cli(tmp_path, HELD_OUT, "--set", f"correction={correction}")
    assert {"wind_speed_mc_u", "wind_direction_mc_u"} <= set(ds.data_vars)
    u = float(ds["wind_speed_mc_u"].values.ravel()[0])
    if correction == "pointwise":
        assert u < 1e-12
        assert abs(float(ds["wind_speed_mc_mean"].values.ravel()[0]) - 10.0) < 1e-12
    else:
        expected = 150.0 * 2 * np.pi / 25.0 * np.deg2rad(3.0) / np.sqrt(2)
        assert abs(u - expected) < 0.10 * expected


@pytest.mark.parametrize("correction", ["none", "pointwise"])
def test_a_static_pitch_of_2_deg(tmp_path, correction):
    """The held-out static ``ship.pitch: 2``: no correction reads U cos(2 deg), the closed
    form of a static pitch along the wind (tests/physics/test_nacelle.py), to 1e-9;
    point-wise correction the true 10 m/s to 1e-12."""
    scenario = {**HELD_OUT, "ship": {"heading": 0.0, "pitch": 2.0}}
    scenario.pop("motion")
    ds = run_cli(tmp_path, scenario, "--set", f"correction={correction}")
    nominal = float(ds["wind_speed_nominal"].values.ravel()[0])
    if correction == "none":
        assert abs(nominal - 10.0 * np.cos(np.deg2rad(2.0))) < 1e-9
    else:
        assert abs(nominal - 10.0) < 1e-12


def test_a_tilted_two_beam_lidar_assumes_w_zero():
    ds = uq.run({"lidar": {"mount": {"tilt": 90}, "azimuths": [90, 270], "height": 100.0},
                 "wind": {"vertical": 0.5}, "correction": "none",
                 "sampling": {"method": "none"}, "outputs": ["wind_speed", "vertical_wind"]})
    assert float(ds["vertical_wind_nominal"].values.ravel()[0]) == 0.0
    assert abs(float(ds["wind_speed_nominal"].values.ravel()[0]) - 5.0) < 1e-12


def test_motion_harmonics_as_a_list_are_independent_components():
    """A list of pitch harmonics adds components, each with its random phase."""
    from uq.pipeline.motionsection import random_phase_count, time_resolved
    scenario = uq.load_scenario({"motion": {"pitch": [
        {"amplitude": 3.0, "period": 25.0}, {"amplitude": 1.0, "period": 8.0, "phase": 30}]},
        "lidar": {"lever_arm": [0, 0, 1]}})
    components = time_resolved(scenario.settings).motion.components
    assert [round(c.angular_frequency * 25 / (2 * np.pi), 12) for c in components] == [1.0, 3.125]
    assert components[0].phase is None and abs(components[1].phase - np.deg2rad(30)) < 1e-15
    assert random_phase_count(scenario.settings) == 1


def test_clause_8_small_pitch_valid_large_pitch_not():
    """The held-out lidar without correction or lever arm, Gaussian radial noise 0.1 m/s,
    a pitch of amplitude p at 25 s (random phase), clause 8 at 1 significant digit
    (delta = 0.005 m/s for u = 0.073 m/s). A pitch p(t) reads Vh = U cos p(t) (the static
    closed form at each instant): a mean shift -U p^2 / 4, second order, which the GUM's
    linearisation about the static attitude (phase mean 0) does not see; the noise's
    cross-wind adds +sigma_v^2 / (2 U) = +0.0037 m/s (sigma_v = 0.1 / (sqrt 2 sin 15 deg))
    to Monte Carlo's mean alone. Clause 8 breaks where |0.0037 - U p^2 / 4| > delta:
    p > 3.4 deg. Amplitudes tested away from it by >= 4 standard deviations of Monte
    Carlo's endpoints (u sqrt(p(1-p)) / (sqrt(n) phi(1.96)) = 0.0011 m/s at n = 65536):
    valid at 0.2, 1, 2 deg; not valid at 5, 6, 8, 10 deg."""
    valid = [0.2, 1.0, 2.0]
    broken = [5.0, 6.0, 8.0, 10.0]
    ds = uq.run({**HELD_OUT, "motion": {"pitch": {"amplitude": 1.0, "period": 25.0}},
                 "lidar": {**HELD_OUT["lidar"], "lever_arm": [0, 0, 0],
                           "errors": {"radial_velocity": {"dist": "normal", "u": 0.1}}},
                 "correction": "none", "sampling": {"digits": 1, "seed": 8},
                 "outputs": ["wind_speed"], "sweep": {"motion.pitch.amplitude": valid + broken}})
    verdicts = ds["wind_speed_gum_valid"].values.ravel().astype(bool)
    assert verdicts.tolist() == [True] * len(valid) + [False] * len(broken)
    u = 0.1 / (np.sqrt(2) * np.sin(np.deg2rad(15.0)))
    shift = u**2 / 20.0 - 10.0 * np.deg2rad(np.array(broken))**2 / 4
    mean = ds["wind_speed_mc_mean"].values.ravel()[len(valid):] - 10.0
    np.testing.assert_allclose(mean, shift, atol=3e-3)   # 3 x u / sqrt(n) and 4th order


def test_a_static_attitude_is_the_static_limit_of_the_motion_with_the_height_at_trim():
    # lidar.height is the height at the static attitude (docs/scenario.md): a static pitch
    # p with height h is the level platform whose harmonic pitch is frozen at p (a period
    # of 1e6 s, phase 90 deg: pitch = p sin(w t + pi/2), 3e-5 of p off over a scan) with
    # the height h - [(R(p) - 1) r]_up, r the lever arm (150 m up: 0.21 m at 3 deg): what
    # the lidar measures agrees to rounding (gate heights 1e-9 m, speeds 1e-9 m/s, the
    # shear exponent 1e-9; the motion's rates, ~1e-7 rad/s, move nothing measurable)
    import math
    from uq.pipeline.runner import run
    base = {"wind": {"speed": 10.0, "shear": 0.14, "reference_height": 150.0},
            "ship": {"pitch": 3.0},
            "lidar": {"height": 150.0, "ranges": [50.0, 150.0], "half_cone": 15.0,
                      "azimuths": [0, 90, 180, 270], "mount": {"tilt": 90},
                      "lever_arm": [0.0, 0.0, 150.0], "scan": {"beam_duration": 1.0}},
            "correction": "pointwise", "ins": {"rate": 10}, "sampling": {"method": "none"},
            "outputs": ["wind_speed", "gate_height", "shear_exponent", "wind_direction"]}
    static = run(base)
    drop = 150.0 * (math.cos(math.radians(3.0)) - 1.0)                    # [(R - 1) r]_up
    frozen = run({**base, "ship": {"pitch": 0.0},
                  "lidar": {**base["lidar"], "height": 150.0 - drop},
                  "motion": {"pitch": {"amplitude": 3.0, "period": 1e6, "phase": 90}}})
    for name in ("gate_height_nominal", "wind_speed_nominal", "shear_exponent_nominal"):
        np.testing.assert_allclose(frozen[name].values, static[name].values, rtol=0,
                                   atol=1e-9)
    turned = (frozen["wind_direction_nominal"] - static["wind_direction_nominal"] + 180) % 360
    np.testing.assert_allclose(turned - 180, 0.0, atol=1e-9)
    # without the height's correction the frozen motion lowers the lidar by 0.21 m
    lowered = run({**base, "ship": {"pitch": 0.0},
                   "motion": {"pitch": {"amplitude": 3.0, "period": 1e6, "phase": 90}}})
    assert float((lowered["gate_height_nominal"] - static["gate_height_nominal"]).mean()) == \
        pytest.approx(drop, abs=1e-6)


@pytest.mark.parametrize("method", ["mc", "none"])
def test_a_run_wholly_outside_the_domain_says_so_and_reports_nan(method, caplog):
    """A nacelle lidar 3 m above the sea whose lower beam reaches 300 m ahead: its gate is
    77 m below the surface, every trial's shear exponent is outside the power law. Its u
    was 0.0 from the GUM (read as 'no uncertainty') and nothing was said; now every u is
    NaN and one warning names the outputs."""
    import logging
    scenario = {**HELD_OUT, "lidar": {**HELD_OUT["lidar"], "height": 3.0, "ranges": [300.0]},
                "sampling": {"n": 500, "seed": 1} if method == "mc" else {"method": "none"},
                "outputs": ["wind_speed", "shear_exponent"]}
    with caplog.at_level(logging.WARNING, logger="uq.pipeline.runner"):
        ds = uq.run(uq.load_scenario(scenario))
    for q in ("wind_speed", "shear_exponent"):
        assert np.isnan(float(ds[f"{q}_gum_u"])), q
        if method == "mc":
            assert np.isnan(float(ds[f"{q}_mc_u"])) and int(ds[f"{q}_mc_n_invalid"]) == 500
    said = [r.getMessage() for r in caplog.records if r.name == "uq.pipeline.runner"]
    assert len(said) == 1 and said[0].startswith("wind_speed, shear_exponent: "), said
    assert ("every Monte Carlo trial" if method == "mc" else "GUM value") in said[0]
