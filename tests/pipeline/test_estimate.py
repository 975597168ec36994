"""``uq check``'s run size and time estimate (uq.pipeline.estimate): counted from the
scenario, costs calibrated per unit of work, never by running the model. Its structure is
tested (what it counts, how it scales), not wall time."""
import math
import subprocess
import sys

import pytest

from uq.cli import main
from uq.pipeline import estimate
from uq.pipeline.estimate import COSTS, run_size
from uq.pipeline.scenario import load_scenario

BASE = {"name": "e", "ins": {"heading": {"dist": "normal", "u": 0.1}},
        "lidar": {"ranges": [50.0, 100.0, 150.0]}, "sampling": {"n": 10_000, "seed": 1},
        "sweep": {"wind.direction": [0.0, 90.0], "wind.speed": [4.0, 8.0, 12.0]}}


def size(**changes):
    return run_size(load_scenario(BASE, changes))


def part(result, name):
    return dict(result.parts)[name]


def test_it_counts_scenes_trials_gates_and_beams():
    result = size()
    assert (result.scenes, result.trials, result.gates, result.beams) == (6, (10_000, 10_000),
                                                                          3, 4)
    assert result.describe() == "6 scenes x 10000 trials, 3 gates, 4 beams"
    assert part(result, "static model") == pytest.approx(6 * 10_000 * 3 * COSTS["static"])


def test_the_trials_part_is_linear_in_trials_and_scenes():
    one, more = size(), size(**{"sampling.n": 40_000, "sweep.wind.speed": [4.0] * 1 + [
        5.0, 6.0, 7.0, 8.0, 9.0]})
    assert part(more, "static model") == pytest.approx(4 * 2 * part(one, "static model"))
    assert part(more, "per scene") == pytest.approx(2 * part(one, "per scene"))
    assert one.seconds[0] == pytest.approx(sum(s for _, s in one.parts))


def test_without_monte_carlo_only_the_scenes_cost():
    result = size(sampling={"method": "none"})
    assert result.trials == (0, 0) and part(result, "static model") == 0
    assert "no Monte Carlo (GUM only)" in result.describe()


def test_adaptive_sampling_gives_a_range():
    result = size(sampling={"digits": 2, "seed": 1})
    low, high = result.trials
    assert low < high and result.seconds[0] < result.seconds[1]
    assert "(adaptive)" in result.describe() and " to " in result.estimate()


def test_motion_costs_per_component_and_beam():
    harmonic = {"amplitude": 1.0, "period": 8.0}
    one = size(motion={"roll": harmonic}, ins={"rate": 10})
    three = size(motion={"roll": [harmonic] * 3}, ins={"rate": 10})
    assert part(three, "motion components") == pytest.approx(3 * part(one, "motion components"))
    assert part(one, "motion components") == pytest.approx(
        6 * 10_000 * 4 * 1 * COSTS["component"])


def test_record_mode_counts_records_and_kaimal_is_not_estimated():
    records = {"turbulence": {"intensity": 0.1}, "record": {"duration": 600, "count": 4},
               "sweep": {}}
    mann = size(**records)
    assert (mann.records, mann.scans) == (4, 150)
    assert part(mann, "records") == pytest.approx(4 * 600 * COSTS["record"])
    assert "4 records of 150 scans" in mann.describe()
    kaimal = size(**records, **{"turbulence.model": "kaimal"})
    assert math.isnan(kaimal.seconds[0]) and "not estimated" in kaimal.estimate()


def test_the_model_seconds_leave_out_the_start_and_the_records():
    """What decides whether a first run's compile runs beside it (uq.cli.firstrun):
    the trials' and scenes' parts, not the command's start or the records."""
    plain = size()
    assert plain.model_seconds() == pytest.approx(
        part(plain, "static model") + part(plain, "per scene"))
    assert plain.model_seconds() == pytest.approx(plain.seconds[0] - COSTS["fixed"])
    records = size(**{"turbulence": {"intensity": 0.1},
                      "record": {"duration": 600, "count": 4}, "sweep": {}})
    assert records.model_seconds() == pytest.approx(
        records.seconds[0] - COSTS["fixed"] - part(records, "records"))
    assert records.model_seconds() < part(records, "records") / 100


def test_the_estimate_runs_no_model(monkeypatch):
    """Nothing of the model is called (the engine and the runner are replaced by
    functions that fail)."""
    def no(*args, **kwargs):
        raise AssertionError("the model ran")
    import uq.engine.propagate
    import uq.pipeline.runner
    monkeypatch.setattr(uq.engine.propagate, "propagate", no)
    monkeypatch.setattr(uq.pipeline.runner, "run", no)
    assert size().seconds[0] > 0


def test_uq_check_states_the_size_and_the_estimate_without_numba(tmp_path):
    """`uq check` said only 'N scene(s)'; it loads no compiled kernel (numba is not even
    imported)."""
    code = ("import sys; from uq.cli import main; status = main(['check', "
            "'rubio2022_misalignment']); print(status, 'numba' in sys.modules)")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          cwd=tmp_path, timeout=600)
    lines = done.stdout.strip().splitlines()
    assert lines[-1] == "0 False", done.stdout + done.stderr
    assert "3456 scenes x 10000 trials, 1 gate, 4 beams" in lines[0]
    assert lines[1].startswith("estimated run time ~") and "calibrated per-trial costs" in \
        lines[1] and "not by running the model" in lines[1]


def test_durations_read_in_the_right_unit():
    assert estimate._duration(12.0) == "12 s"
    assert estimate._duration(270.0) == "4.5 min"
    assert estimate._duration(4 * 3600.0) == "4 h"
