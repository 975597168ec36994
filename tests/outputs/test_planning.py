"""Campaign-planning answers: hand-computed grids, and the paper's findings on the
shipped scenarios (GUM-only grids, so the checks are exact and fast)."""
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

import uq
from uq.outputs import planning

ROOT = Path(__file__).resolve().parents[2]


def scenario(name, **changes):
    return uq.load_scenario(ROOT / "scenarios" / f"{name}.yaml",
                            {"sampling.method": "none", **changes})


def test_velocity_ratio_on_a_hand_computed_grid():
    # u = 0.01 + 0.01 sog, the same at every Vh: u <= 0.05 up to sog = 4 (not 5).
    speeds, sogs = np.array([2.0, 4.0, 8.0]), np.arange(0.0, 7.0)
    u = np.broadcast_to(0.01 + 0.01 * sogs, (3, 7))
    ds = xr.Dataset({"wind_speed_gum_u": (("wind_speed", "ship_sog"), u)},
                    coords={"wind_speed": speeds, "ship_sog": sogs})
    answer = planning.velocity_ratio_answer(ds, 0.05)["gum_u"]
    assert answer == {"ratio": 4.0 / 8.0, "limiting_speed": 8.0}      # min over Vh of 4/Vh
    assert planning.velocity_ratio_answer(ds, 1.0)["gum_u"]["ratio"] == np.inf
    assert np.isnan(planning.velocity_ratio_answer(ds, 0.005)["gum_u"]["ratio"])


def test_misalignment_and_budget_on_hand_computed_grids():
    x = np.array([-90.0, -45.0, 0.0, 45.0, 90.0])
    ds = xr.Dataset({"wind_speed_gum_u": (("lidar_misalignment", "wind_direction"),
                                          np.array([[1, 3], [4, 4], [0.5, 1.5], [4, 6],
                                                    [2, 2]], dtype=float)),
                     "wind_speed_budget": (("input", "wind_direction"),
                                           np.array([[1.0, 3.0], [3.0, 1.0], [0.0, 0.0]]))},
                    coords={"lidar_misalignment": x, "wind_direction": [0.0, 180.0],
                            "input": ["a", "b", "c"]})
    answer = planning.misalignment_answer(ds)["gum_u"]
    assert (answer["best"], answer["worst"]) == (0.0, 45.0)
    assert answer["gain"] == pytest.approx(1 - 1.0 / 5.0)
    assert planning.budget_answer(ds) == [("a", 0.5), ("b", 0.5), ("c", 0.0)]


def test_paper_findings_hold_in_the_paper_model():
    """Acceptance: the findings of Sec. 3 hold in the paper-model curves of the shipped
    scenarios (misalignment, velocity ratio, tilt)."""
    runs = [uq.run(scenario("rubio2022_misalignment",
                            **{"sweep.wind.direction": {"start": 0, "stop": 360, "step": 30}})),
            uq.run(scenario("rubio2022_velocity_ratio")),
            uq.run(scenario("rubio2022_tilt")),
            uq.run(scenario("rubio2022_half_cone"))]
    rows = [row for ds in runs for row in planning.paper_findings(ds)
            if row["model"].startswith("paper") and "Theta" not in row["finding"]]
    assert len(rows) == 4 and all(row["holds"] for row in rows), rows


def test_physical_model_does_not_care_about_misalignment_with_one_reading_per_scan():
    """One INS reading per scan rotates the whole DBS wind: misalignment cannot matter.
    With independent readings per beam (the paper's assumption) it does, as the paper."""
    sweep = {"sweep.wind.direction": {"start": 0, "stop": 360, "step": 30}}
    scan = planning.misalignment_answer(uq.run(scenario("rubio2022_misalignment", **sweep)))
    assert scan["gum_u"]["gain"] < 1e-12           # rounding only
    beam = planning.misalignment_answer(uq.run(scenario(
        "rubio2022_misalignment", **sweep, **{"ins.correlation": "beam"})))
    # first order, point-wise correction == the paper's model (test_pipeline): same answer
    assert beam["gum_u"]["gain"] == pytest.approx(beam["paper_u"]["gain"], rel=1e-9)


def test_sog_error_reverses_the_tilt_finding_as_the_scenario_says():
    """rubio2022_tilt.yaml leaves u_sog out because, with Table B3's 0.1 m/s, the paper's
    own Eq. 12 makes u(Vh) grow with tilt (+10 % at 10 deg pitch), unlike its Fig. 6."""
    with_sog = uq.run(scenario("rubio2022_tilt", **{"ins.sog": {"dist": "normal", "u": 0.1}}))
    grid = with_sog["wind_speed_paper_u"].mean("wind_direction")
    change = float(grid.sel(ship_pitch=10.0, ship_roll=0.0) / grid.sel(ship_pitch=0.0,
                                                                         ship_roll=0.0)) - 1
    assert 0.09 < change < 0.105          # the +10 % the scenario description states
    assert not [r for r in planning.paper_findings(with_sog)
                if r["model"].startswith("paper") and "Vh" in r["finding"]][0]["holds"]


def test_disagreement_is_one_where_the_paper_is_the_first_order_physical_model():
    case_i = uq.run(scenario("rubio2022_case_i", **{"ins.correlation": "beam"}))
    answer = planning.disagreement_answer(case_i, "wind_speed")
    assert answer["reference"] == "gum_u"             # no Monte Carlo in a GUM-only run
    assert answer["min"] == pytest.approx(1, abs=1e-9) and answer["max"] == pytest.approx(1, abs=1e-9)


def test_bias_of_tilt2d_under_tilt_and_none_for_full():
    tilted = {"ship.pitch": 10.0, "ship.roll": 10.0}
    tilt2d = planning.bias_answer(uq.run(scenario("rubio2022_tilt", **tilted,
                                                  **{"sweep": {}})))
    full = planning.bias_answer(uq.run(scenario("rubio2022_tilt", **tilted, correction="full",
                                                **{"sweep": {}})))
    # tilt2d drops the lidar-frame vertical component: a systematic error of order
    # Vh (1 - cos tilt) + w sin tilt, ~0.1-0.4 m/s here; full correction is exact.
    assert abs(tilt2d["correction"]["value"]) > 0.05
    assert abs(full["correction"]["value"]) < 1e-12
