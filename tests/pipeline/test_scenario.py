"""Scenario keys that change nothing in their scene are warned of (one line naming the
file and the key), and the warnings say true things: the scene's numbers without the
key are the same. lidar.azimuths as {start, stop, step}."""
import logging

import numpy as np
import pytest
import yaml

import uq
from uq.cli import main
from uq.errors import ScenarioError
from uq.pipeline.scenario import keys_without_effect, load_scenario

BASE = {"name": "t", "ship": {"sog": 2.0, "pitch": 3.0},
        "ins": {"heading": {"dist": "normal", "u": 0.5}, "sog": {"dist": "normal", "u": 0.1},
                "pitch": {"dist": "normal", "u": 0.2}},
        "lidar": {"errors": {"radial_velocity": {"dist": "normal", "u": 0.05}}},
        "sampling": {"n": 4096, "seed": 3}, "outputs": ["wind_speed", "vertical_wind"]}


def with_(section, key, value):
    scenario = yaml.safe_load(yaml.safe_dump(BASE))
    if key:
        scenario.setdefault(section, {})[key] = value
    else:
        scenario[section] = value
    return scenario


def warned(scenario):
    return [key for key, _ in keys_without_effect(load_scenario(scenario).settings)]


def test_each_key_without_effect_is_warned_of_once_on_one_line(tmp_path, capsys):
    path = tmp_path / "w.yaml"
    path.write_text("name: w\nins: {rate: 10}\nlidar: {half_cone: 0.49, scan: "
                    "{beam_duration: 1}}\ncorrection: pointwise\n")
    assert main(["check", str(path)]) == 0
    lines = capsys.readouterr().err.splitlines()
    assert [line.split(": ")[3] for line in lines] == ["ins.rate", "lidar.scan", "correction",
                                                     "lidar.half_cone"]
    assert all(line.startswith(f"uq: warning: {path}: ") for line in lines)
    assert "0.49 rad would be 28.1 deg" in lines[-1]


def test_a_scene_with_motion_is_not_warned_of():
    moving = with_("motion", "", {"roll": {"amplitude": 2.0, "period": 6.0}})
    moving["ins"]["rate"] = 10.0
    moving["correction"] = "pointwise"
    moving["lidar"]["scan"] = {"beam_duration": 1.0}
    assert warned(moving) == []
    timed = with_("lidar", "scan", {"beam_duration": 1.0})
    timed["ins"]["sog"]["correlation_time"] = 2.0
    assert warned(timed) == []
    assert warned(BASE) == []


def test_what_the_warnings_say_is_true(caplog):
    """Without motion: lidar.scan changes no number; pointwise gives full's numbers (to
    rounding: another implementation of the same sums, 1e-12 relative); ins.rate gives
    the same GUM (the same model; its Monte Carlo draws differ)."""
    with caplog.at_level(logging.WARNING):
        plain = uq.run(load_scenario(BASE))
        scanned = uq.run(load_scenario(with_("lidar", "scan", {"beam_duration": 2.0})))
        pointwise = uq.run(load_scenario(with_("correction", "", "pointwise")))
        sampled = uq.run(load_scenario(with_("ins", "rate", 10.0)))
    for name in ("wind_speed_mc_u", "wind_speed_mc_mean", "vertical_wind_mc_u",
                 "wind_speed_gum_u", "vertical_wind_gum_u"):
        assert float(scanned[name]) == float(plain[name])
        assert float(pointwise[name]) == pytest.approx(float(plain[name]), rel=1e-12)
    for name in ("wind_speed_gum_u", "vertical_wind_gum_u"):
        assert float(sampled[name]) == pytest.approx(float(plain[name]), rel=1e-12)


def test_azimuths_as_start_stop_step():
    lidar = load_scenario({"lidar": {"azimuths": {"start": 0, "stop": 360, "step": 7.2}}}
                          ).settings["lidar"]
    assert len(lidar["azimuths"]) == 50
    np.testing.assert_allclose(lidar["azimuths"], np.arange(50) * 7.2, rtol=0, atol=1e-12)
    with pytest.raises(ScenarioError, match="lidar.azimuths: start, stop, step give 3600 "
                                            "beams; allowed: at most 1000"):
        load_scenario({"lidar": {"azimuths": {"start": 0, "stop": 360, "step": 0.1}}})
    with pytest.raises(ScenarioError, match="lidar.azimuths: start, stop, step give no"):
        load_scenario({"lidar": {"azimuths": {"start": 0, "stop": 360, "step": -10}}})
    with pytest.raises(ScenarioError, match="lidar.azimuths: expected a list of angles"):
        load_scenario({"lidar": {"azimuths": {"start": 0, "stop": 360}}})
