"""The summary table of uq run: readable columns, no empty ones, the verdict explained."""
import re

import numpy as np

import uq
from uq.outputs.summary import _number, summary_table


def _block(lines, title):
    """The header and rows of the table titled `title` (up to the next blank line)."""
    start = lines.index(title)
    end = next((i for i in range(start, len(lines)) if not lines[i]), len(lines))
    return lines[start + 1], lines[start + 2:end]


def test_each_scene_has_its_row_under_its_swept_values():
    """Up to MAX_SCENE_ROWS scenes: a row per scene, under the swept keys, with each
    stored statistic of that scene (not min..max over scenes that says which is which
    nowhere); columns never run together; empty ones are dropped."""
    ds = uq.run({"ins": {"heading": {"dist": "normal", "u": 0.1}}, "ship": {"sog": 2.0},
                 "sampling": {"n": 500, "seed": 1},
                 "sweep": {"wind.direction": [0.0, 90.0], "ship.pitch": [0.0, 5.0]}})
    header, rows = _block(summary_table(ds).splitlines(), "wind_speed")
    names = re.split(r"\s{3,}", header.strip())
    assert names[:2] == ["wind.direction", "ship.pitch"] and "paper_u" not in names
    assert len(rows) == 4
    for row in rows:
        cells = dict(zip(names, re.split(r"\s{3,}", row.strip())))
        assert len(cells) == len(names), row                  # every cell stands apart
        at = ds.sel(wind_direction=float(cells["wind.direction"]),
                    ship_pitch=float(cells["ship.pitch"]))
        assert cells["mc_u"] == _number(float(at["wind_speed_mc_u"]))
        assert cells["gum_u"] == _number(float(at["wind_speed_gum_u"]))
        assert cells["clause 8"] in ("validated", "not validated", "undecided")


def test_many_scenes_give_each_extent_with_its_scene():
    """Beyond MAX_SCENE_ROWS scenes: each statistic's smallest and largest value with the
    scene where it occurs."""
    from uq.outputs.summary import MAX_SCENE_ROWS
    directions = [float(d) for d in range(0, 360, 20)]
    assert len(directions) > MAX_SCENE_ROWS
    ds = uq.run({"ins": {"sog": {"dist": "normal", "u": 0.1}}, "ship": {"sog": 2.0},
                 "sampling": {"n": 500, "seed": 1}, "sweep": {"wind.direction": directions}})
    header, rows = _block(summary_table(ds).splitlines(), "wind_speed")
    row = next(r for r in rows if r.startswith("gum_u"))
    u = ds["wind_speed_gum_u"]
    smallest, largest = u.isel(wind_direction=int(np.argmin(u.values))), \
        u.isel(wind_direction=int(np.argmax(u.values)))
    assert f"{float(smallest):.4g}   wind.direction = " \
        f"{float(smallest['wind_direction']):g}" in re.sub(r"\s{3,}", "   ", row)
    assert f"{float(largest):.4g}   wind.direction = " \
        f"{float(largest['wind_direction']):g}" in re.sub(r"\s{3,}", "   ", row)
    assert any(line.startswith("clause 8: ") and line.endswith(f"of {len(directions)}")
               for line in rows)


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
    assert "The motion's turbulence-intensity increment" in page and "5 %" in page
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
