"""The ``motion`` section's bounds are on what the model takes as a whole: the attitude
(or displacement) all components of a degree of freedom can reach together, with the
static attitude, checked once at validation with one line naming the key."""
import math

import numpy as np
import pytest

from uq.errors import ScenarioError
from uq.pipeline.motionsection import (MAX_ANGULAR_AMPLITUDE_DEG, MAX_ATTITUDE_DEG,
                                       MAX_TRANSLATION_AMPLITUDE_M, _reach_by_source,
                                       time_resolved)
from uq.pipeline.scenario import load_scenario

BASE = {"name": "m", "ins": {"heading": {"dist": "normal", "u": 0.1}},
        "sampling": {"n": 100, "seed": 1}}


def harmonics(count, amplitude):
    return [{"amplitude": amplitude, "period": 5.0 + i, "phase": "random"}
            for i in range(count)]


def waves(hs, **response):
    return {"spectrum": {"hs": hs, "tp": 7.0},
            "response": {dof: {"factor": f} for dof, f in response.items()}}


def test_eight_pitch_harmonics_of_45_deg_are_refused():
    """Each within the bound of one harmonic (45 deg), 360 deg together: accepted before,
    all trials outside the model's domain."""
    with pytest.raises(ScenarioError) as refused:
        load_scenario({**BASE, "motion": {"pitch": harmonics(8, 45.0)}})
    assert refused.value.key == "motion.pitch"
    assert "360 deg" in str(refused.value) and "at most 45 deg" in str(refused.value)


def test_the_bound_is_on_the_sum_exactly():
    """Nine harmonics of 5 deg reach 45 deg: allowed; a tenth is not."""
    load_scenario({**BASE, "motion": {"roll": harmonics(9, MAX_ANGULAR_AMPLITUDE_DEG / 9)}})
    with pytest.raises(ScenarioError, match="motion.roll"):
        load_scenario({**BASE, "motion": {"roll": harmonics(10, MAX_ANGULAR_AMPLITUDE_DEG / 9)}})


def test_the_static_attitude_counts():
    """ship.pitch 86 with 4 deg of pitch motion reaches 90 deg, where the Euler angles
    are singular; 85 is allowed."""
    motion = {"pitch": harmonics(2, 2.0)}
    load_scenario({**BASE, "ship": {"pitch": MAX_ATTITUDE_DEG - 4.0}, "motion": motion})
    with pytest.raises(ScenarioError, match="on top of ship.pitch -86 deg"):
        load_scenario({**BASE, "ship": {"pitch": -86.0}, "motion": motion})


@pytest.mark.parametrize("changes, key", [
    ({"motion": waves(1e6, roll=4.0)}, "motion.response.roll.factor"),     # OverflowError
    ({"motion": waves(2.0, roll=1e100)}, "motion.response.roll.factor"),   # OverflowError
    ({"motion": waves(2.0, heave=1e100)}, "motion.response.heave.factor"),
    ({"motion": {"surge": {"amplitude": 1e100, "period": 8.0}}}, "motion.surge"),
])
def test_a_wave_spectrum_or_a_translation_beyond_the_model_is_one_line(changes, key):
    """hs 1e6 m and a response factor of 1e100 raised OverflowError in the dwell
    frequency at the run's start (even with dwell_average false)."""
    with pytest.raises(ScenarioError) as refused:
        load_scenario({**BASE, **changes})
    assert refused.value.key == key and "\n" not in str(refused.value)


def test_a_spectrum_reaches_the_sum_of_its_components():
    """The reach of a spectrum's roll is the sum over its components of factor times the
    wave amplitude (rad -> deg), the number the model's components carry."""
    settings = load_scenario({**BASE, "motion": waves(2.0, roll=4.0)}).settings
    components = time_resolved(settings).motion.components
    expected = math.degrees(sum(abs(c.amplitudes[0]) for c in components))
    reach = _reach_by_source(settings["motion"])["motion.response.roll.factor"][0]
    assert reach == pytest.approx(expected, rel=1e-12)   # the same sum, rounding only
    assert 0 < reach < MAX_ANGULAR_AMPLITUDE_DEG


def test_a_record_reaches_the_sum_of_its_fourier_components(tmp_path):
    times = np.arange(256) * 0.5
    roll = 30.0 * np.sin(2 * np.pi * times / 8.0) + 30.0 * np.sin(2 * np.pi * times / 16.0)
    (tmp_path / "buoy.csv").write_text("time,roll\n" + "".join(
        f"{t},{r}\n" for t, r in zip(times, roll)))
    with pytest.raises(ScenarioError) as refused:
        load_scenario({**BASE, "motion": {"series": {"file": str(tmp_path / "buoy.csv"),
                                                     "columns": {"roll": "roll"}}}})
    assert refused.value.key == "motion.series.columns.roll"
    assert "60 deg" in str(refused.value)                 # 30 + 30, lined up


def test_translations_up_to_the_bound():
    load_scenario({**BASE, "motion": {"heave": harmonics(2, MAX_TRANSLATION_AMPLITUDE_M / 2)}})


def test_a_swept_static_attitude_is_checked_with_the_motion():
    with pytest.raises(ScenarioError, match="ship.roll"):
        load_scenario({**BASE, "motion": {"roll": harmonics(1, 40.0)},
                       "sweep": {"ship.roll": [0.0, 50.0]}})
