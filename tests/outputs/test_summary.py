"""The summary table of uq run: readable columns, no empty ones, the verdict explained."""
import re

import numpy as np

import uq
from uq.outputs.summary import summary_table


def test_columns_never_run_together_and_empty_ones_are_dropped():
    ds = uq.run({"ins": {"heading": {"dist": "normal", "u": 0.1}}, "ship": {"sog": 2.0},
                 "sampling": {"n": 500, "seed": 1},
                 "sweep": {"wind.direction": [0.0, 90.0], "ship.pitch": [0.0, 5.0]}})
    lines = summary_table(ds).splitlines()
    header = lines[1]
    assert "paper_u" not in header               # tilted: outside the paper's case i/ii
    names = re.split(r"\s{3,}", header.strip())
    for line in lines[2:5]:
        cells = re.split(r"\s{3,}", line.strip())
        assert len(cells) == len(names), line          # every cell stands apart
    assert any("(n)" in line and "conclusive" in line for line in lines)
    assert "e-1" not in "\n".join(lines[2:5])          # rounding noise printed as 0


def test_report_states_the_apparent_turbulence_intensity():
    """sqrt(TI^2 + TI_motion^2): 6 % and 8 % make 10 %; the report of a motion result
    states it for the true TI asked for."""
    import numpy as np
    from uq.outputs.report import apparent_ti, render_report
    assert apparent_ti(0.06, 0.08) == np.float64(0.1)
    ds = uq.run({"motion": {"roll": {"amplitude": 3.0, "period": 5.0}},
                 "sampling": {"n": 500, "seed": 1}, "correction": "none"})
    ti = float(ds["wind_speed_motion_ti"])
    page = render_report(ds, true_ti=0.05)
    assert "Apparent turbulence intensity" in page and "5 %" in page
    assert f"{100 * np.hypot(0.05, ti):.2f} %" in page


def test_a_direction_at_north_is_one_value_not_a_sweep():
    """359.99999999999994 deg (atan2's rounding of north) and 1e-14 deg are the same
    direction: the summary shows 0, not "swept" or "360"; a real -0.03 deg shows as such."""
    from uq.outputs.summary import _cell, _shown
    north = np.array([359.99999999999994, 1e-14])
    assert _cell(_shown(north, "wind_direction", "true"), "true") == "0"
    assert _cell(_shown(np.array([359.97]), "wind_direction", "mc_mean"), "mc_mean") == "-0.03"
    assert _cell(_shown(np.array([359.97]), "wind_speed", "mc_mean"), "mc_mean") == "360"


def test_a_fixed_motion_phase_explains_its_zero_ti_increment():
    """Issue 27, item 6: tiana2017_vad (a buoy pitching up to 15 deg at a fixed phase)
    reported "motion-induced TI 0.00 %" without a word. Every scan sees the same motion:
    the summary and the report say so, and give the systematic error the motion makes
    instead; with a random phase the scatter is sampled (TI > 1 %) and no note."""
    from pathlib import Path
    from uq.outputs.report import render_report
    path = Path(__file__).resolve().parents[2] / "scenarios" / "tiana2017_vad.yaml"
    sweep = {"wind.direction": [0.0], "motion.pitch.amplitude": [15.0]}
    fixed = uq.run(uq.load_scenario(path, {"sweep": sweep}))
    line = next(l for l in summary_table(fixed).splitlines() if "turbulence-intensity" in l)
    assert "increment [%]: 0 (every motion phase is fixed (motion.pitch.phase: 180)" in line
    error = float(np.abs(fixed["wind_speed_nominal"] - fixed["wind_speed_true"]).max())
    assert error > 0.1 and f"{error:.3g} m/s" in line
    assert "Every motion phase is fixed" in render_report(fixed)
    sampled = uq.run(uq.load_scenario(path, {"sweep": sweep, "motion.pitch.phase": "random",
                                             "sampling.n": 2000}))
    assert float(sampled["wind_speed_motion_ti"].min()) > 0.01
    line = next(l for l in summary_table(sampled).splitlines() if "turbulence-intensity" in l)
    assert "fixed" not in line
