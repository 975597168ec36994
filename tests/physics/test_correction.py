"""What each correction model removes, as the results' correction_description says: the
per-scan models remove the velocity of the INS's own point, not the lever arm's
omega x r; pointwise removes both."""
import math

import numpy as np
import pytest

import uq
from uq.physics.correction import (CORRECTION_DESCRIPTIONS, CORRECTION_MODELS,
                                   describe_corrections)

AMPLITUDE_DEG, PERIOD_S, ARM_M = 5.0, 1000.0, 100.0


def lever_arm_scene(correction):
    """No wind; the INS point at rest; a slow roll (period 1000 s against a 4 s scan, so
    the roll rate is constant over the scan to 3e-4) swings a lidar 100 m above the INS
    at omega x r = A (2 pi / T) h = 0.0548 m/s towards starboard (east: heading north).
    The INS is exact, so any wind a correction reports is motion it did not remove."""
    scenario = {"name": "lever", "wind": {"speed": 0.0},
                "motion": {"roll": {"amplitude": AMPLITUDE_DEG, "period": PERIOD_S,
                                    "phase": 0.0}},
                "lidar": {"lever_arm": [0.0, 0.0, ARM_M]}, "correction": correction,
                "sampling": {"method": "none"}, "outputs": ["wind_speed", "wind_direction"]}
    with np.errstate(invalid="ignore", divide="ignore"):     # TI of a zero wind: NaN
        return uq.run(uq.load_scenario(scenario))


def test_full_leaves_the_lever_arm_velocity_in_the_wind():
    dataset = lever_arm_scene("full")
    omega_r = math.radians(AMPLITUDE_DEG) * 2 * math.pi / PERIOD_S * ARM_M
    # the roll rate over the 4 s scan is A w cos(w t), cos(2 pi 4 / 1000) = 1 - 3e-4; the
    # tilt it brings (A w t < 1e-3 rad) turns the error by less: 1e-3 relative bounds both
    assert float(dataset["wind_speed_nominal"]) == pytest.approx(omega_r, rel=1e-3)
    # the lidar moves east, so the apparent wind blows west: from the east (90 deg)
    assert float(dataset["wind_direction_nominal"]) == pytest.approx(90.0, abs=1e-6)
    assert "omega x r is not removed" in dataset.attrs["correction_description"]


def test_pointwise_removes_the_lever_arm_velocity():
    dataset = lever_arm_scene("pointwise")
    # exact INS, exact kinematics: rounding only (1e-12 m/s, tests/physics/test_timeresolved)
    assert abs(float(dataset["wind_speed_nominal"])) < 1e-12
    assert "plus the lever arm's omega x r" in dataset.attrs["correction_description"]


def test_every_model_is_described_and_a_sweep_describes_each_value():
    assert set(CORRECTION_DESCRIPTIONS) == set(CORRECTION_MODELS)
    text = describe_corrections(("none", "full"))
    assert text.startswith("none: no motion correction") and "; full: per scan" in text
    dataset = uq.run(uq.load_scenario({"name": "s", "sampling": {"method": "none"},
                                       "sweep": {"correction": ["none", "yaw", "full"]}}))
    for model in ("none", "yaw", "full"):
        assert f"{model}: {CORRECTION_DESCRIPTIONS[model]}" in \
            dataset.attrs["correction_description"]
