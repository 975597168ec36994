"""uq plot and uq report: every figure renders from a result, with labelled axes and
units; the report is one self-contained HTML file; bad input exits 2."""
import base64
import re
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
import pytest
import xarray as xr
from matplotlib.collections import QuadMesh

import uq
from uq.cli import main
from uq.outputs.figures import figure_plan
from uq.files import write_netcdf as write_results
from uq.outputs.report import render_report

ROOT = Path(__file__).resolve().parents[2]
# scenario, its trimmed sweep, the figures it must give
CASES = {
    "rubio2022_misalignment": ({"lidar.misalignment": [-90, -45, 0, 45, 90],
                                "wind.direction": [0, 120, 240]},
                               ["fig2_speed_maps", "fig3_direction_against_misalignment"]),
    "rubio2022_velocity_ratio": ({"wind.speed": [2, 4, 6], "ship.sog": [0, 2, 4, 8, 12],
                                  "wind.direction": [0, 180]},
                                 ["fig4a_speed_against_velocities",
                                  "fig4b_relative_against_speed"]),
    "rubio2022_tilt": ({"ship.pitch": [-5, 0, 5], "ship.roll": [-5, 0, 5],
                        "wind.direction": [0, 180]},
                       ["fig5_radial_against_direction", "fig6_tilt_maps"]),
    "rubio2022_half_cone": ({"lidar.half_cone": [10, 30, 60], "wind.direction": [0, 180]},
                            ["fig7_half_cone"]),
    "rubio2022_case_i": ({"wind.direction": [0, 90, 180, 270]},
                         ["uncertainty_against_direction"]),
}


@pytest.fixture(scope="module")
def results():
    out = {}
    for name, (sweep, _) in CASES.items():
        scenario = uq.load_scenario(ROOT / "scenarios" / f"{name}.yaml",
                                    {"sampling.n": 2000, "sweep": {**sweep, **_links(name)}})
        out[name] = uq.run(scenario)
    return out


def _links(name):
    return {"ship.heading": {"same_as": "ship.cog"}, "ship.cog": [0, 45]} \
        if name == "rubio2022_misalignment" else {}


@pytest.mark.parametrize("name", CASES)
def test_each_scenario_gives_its_figures_with_labelled_axes(results, name):
    plan = figure_plan(results[name])
    assert [stem for stem, _ in plan] == CASES[name][1]
    for _, function in plan:
        figure = function(results[name])
        for ax in figure.axes:
            if ax.get_xlabel():                      # twin axes share the x label
                assert re.search(r"\[.+\]", ax.get_xlabel()), ax.get_xlabel()
        labels = [ax.get_ylabel() for ax in figure.axes if ax.get_ylabel()]
        assert any("u(" in label and "[" in label for label in labels), labels
        plt.close(figure)


def test_figures_show_three_models_when_sampled(results):
    figure = figure_plan(results["rubio2022_half_cone"])[0][1](results["rubio2022_half_cone"])
    legend = [t.get_text() for t in figure.axes[0].get_legend().get_texts()]
    assert legend == ["Rubio & Gottschall (2022)", "GUM, physical model",
                      "Monte Carlo, physical model"]
    plt.close(figure)


def test_plot_and_report_commands(results, tmp_path, capsys):
    path = write_results(results["rubio2022_tilt"], tmp_path / "tilt.nc")
    assert main(["plot", str(path), "-o", str(tmp_path / "figs"), "--format", "png",
                 "--format", "pdf"]) == 0
    written = sorted(p.name for p in (tmp_path / "figs").iterdir())
    assert written == ["fig5_radial_against_direction.pdf", "fig5_radial_against_direction.png",
                       "fig6_tilt_maps.pdf", "fig6_tilt_maps.png"]
    assert main(["report", str(path)]) == 0
    page = (tmp_path / "tilt_report.html").read_text()
    images = re.findall(r"src='data:image/png;base64,([^']+)'", page)
    assert len(images) == 2 and all(base64.b64decode(i)[:4] == b"\x89PNG" for i in images)
    for section in ("<h2>Each output", "Uncertainty budget", "Bias",
                    "Findings of Rubio", "Scenario as run", "tilt lowers u(Vh)"):
        assert section in page, section
    assert "http" not in page.replace("http-equiv", "")   # self-contained: no links out


def test_report_answers_the_planning_questions(results):
    page = render_report(results["rubio2022_velocity_ratio"], targets={"wind_speed": (0.06,)})
    assert "Largest velocity ratio" in page and "0.06" in page
    page = render_report(results["rubio2022_misalignment"])
    assert "Best misalignment" in page


@pytest.mark.parametrize("command", ["plot", "report"])
def test_bad_results_file_is_bad_input(tmp_path, capsys, command):
    assert main([command, str(tmp_path / "missing.nc")]) == 2
    assert "missing.nc" in capsys.readouterr().err
    xr.Dataset({"x": ("t", [1.0])}).to_netcdf(tmp_path / "other.nc")
    assert main([command, str(tmp_path / "other.nc")]) == 2
    assert "not a uq results file" in capsys.readouterr().err


def test_a_single_scene_has_figures_and_its_report_the_single_scene_ones(tmp_path, capsys):
    """Issue 16: `uq plot` of a run without a sweep draws the single-scene figures (it
    said "no figure for these sweep dimensions"); its report counts range gates, not
    scenes, and embeds the same figures, each with a caption."""
    single = uq.run(uq.load_scenario(ROOT / "scenarios" / "floating_lidar_full.yaml",
                                     {"sampling.n": 4000}))
    path = write_results(single, tmp_path / "one.nc")
    assert main(["plot", str(path)]) == 0
    assert sorted(p.name for p in (tmp_path / "one_figures").iterdir()) == [
        "budget.png", "histogram.png", "radial_velocity_per_beam.png",
        "uncertainty_against_gate.png"]
    page = render_report(single)
    assert len(re.findall("<img ", page)) == len(re.findall("<figcaption><b>[a-z_]+.</b> [A-Za-z]",
                                                             page)) == 4
    outputs = page.split("<h2>Each output")[1].split("<h2>Figures")[0]
    assert re.search(r"\d+ (validated|not validated|undecided)[a-z, 0-9]* of 3 "
                     r"\(3 range gates\)", outputs)
    assert "scene" not in outputs.split("<h2>Scene by scene")[0]


def test_every_requested_output_is_shown(tmp_path):
    """Issue 27, item 4: gate_height and radial_velocity (requested by
    floating_lidar_full) were in neither the figures nor the report, although clause 8
    refuses the GUM for the gate height (a flat-topped distribution from the uniform
    half-cone error). Each has its budget, bias and u table in the report and a figure
    panel; the histogram of each output shows the gate where the GUM fails."""
    from uq.outputs.plots import histogram_gate, sweep_quantities
    single = uq.run(uq.load_scenario(ROOT / "scenarios" / "floating_lidar_full.yaml",
                                     {"sampling.n": 4000}))
    page = render_report(single)
    for words in ("Gate height", "Radial velocity"):
        section = page.split(f"<h3>{words}</h3>")[1].split("<h3>")[0]
        assert "<h4>Uncertainty budget</h4>" in section and "<h4>Bias</h4>" in section
        assert f"<h3>u({words.lower()})" in page
    assert "beam at 90 deg" in page and "vertical beam" in page
    assert "gate_height" in sweep_quantities(single)
    failed = ~single["gate_height_gum_valid"].values
    gate = histogram_gate(single, "gate_height")
    assert failed[gate] if failed.any() else gate == single.sizes["range"] // 2
    valid = single.copy()
    valid["wind_speed_gum_valid"][:] = True
    valid["wind_speed_gum_valid"][2] = False
    assert histogram_gate(valid, "wind_speed") == 2            # not the middle gate


def test_report_says_zero_for_rounding_and_folds_the_scenario(results):
    """Yaw correction of a level ship is exact: its systematic error, ~1e-15 m/s of
    rounding, is reported as none (within NUMERICAL_ZERO), not as a finding; the vertical
    wind has no uncertainty at all and says so; the scenario is folded."""
    page = render_report(results["rubio2022_case_i"])
    speed = page.split("<h3>Wind speed</h3>")[1].split("<h3>")[0]
    bias = speed.split("<h4>Bias</h4>")[1].split("</p>")[0]
    assert "none (at most" in bias and "e-1" not in bias.split("within")[1]
    assert "No uncertainty in these scenes" in page
    assert re.search(r"<details><summary>the scenario's YAML \(\d+ lines", page)
    assert "<pre>name: rubio2022_case_i" in page.split("<details>")[1]


def test_paper_figures_show_their_effect(results):
    """Issue 16: fig4a and fig6 give each panel its own colour scale where one common
    scale would hide the velocity ratio's or the tilt's effect (each panel's colours span
    its own values); fig7 has linear axes; fig2's red line has its axis label; fig3's
    cog lines carry markers at different points, so that coinciding lines stay visible;
    Monte Carlo is drawn as markers on top of the GUM lines (fig4b, fig5)."""
    from uq.outputs import figures
    for name, function in (("rubio2022_velocity_ratio", figures.fig4a_speed_against_velocities),
                           ("rubio2022_tilt", figures.fig6_tilt_maps)):
        figure = function(results[name])
        meshes = [c for ax in figure.axes for c in ax.collections
                  if isinstance(c, QuadMesh) and ax.get_title()]
        # a panel flat to rounding (1e-9 relative) gets matplotlib's own widened scale
        varied = [m for m in meshes if np.ptp(m.get_array()) > 1e-9 * np.abs(m.get_array()).max()]
        assert varied
        for mesh in varied:
            values = mesh.get_array()
            assert mesh.get_clim() == pytest.approx((values.min(), values.max()), rel=1e-12)
        plt.close(figure)
    figure = figures.fig7_half_cone(results["rubio2022_half_cone"])
    assert {ax.get_yscale() for ax in figure.axes} == {"linear"}
    plt.close(figure)
    figure = figures.fig2_speed_maps(results["rubio2022_misalignment"])
    assert any("direction mean" in ax.get_ylabel() for ax in figure.axes
               if ax.get_ylabel() and ax.yaxis.get_label_position() == "right")
    plt.close(figure)
    figure = figures.fig3_direction_against_misalignment(results["rubio2022_misalignment"])
    cogs = [line for line in figure.axes[0].lines if line.get_label().startswith("cog")]
    assert len({line.get_markevery()[0] for line in cogs}) == len(cogs) == 2
    plt.close(figure)
    for name, function in (("rubio2022_velocity_ratio", figures.fig4b_relative_against_speed),
                           ("rubio2022_tilt", figures.fig5_radial_against_direction)):
        figure = function(results[name])
        lines = figure.axes[0].lines
        mc = [line for line in lines if line.get_marker() == "o"]
        gum = [line for line in lines if line.get_linestyle() == "--"]
        assert mc and gum and min(m.get_zorder() for m in mc) > max(g.get_zorder() for g in gum)
        plt.close(figure)


def test_report_gives_the_systematic_error_of_a_deterministic_scene():
    """A tilted VAD without correction and without random errors has no uncertainty but a
    systematic error: the closed form U [sqrt(cos^2 tau cos^2 D + sin^2 D) - 1] (D from
    the tilt plane), -0.152 m/s at D = 0 and none at D = 90 deg for tau = 10 deg, U =
    10 m/s; the report states that range instead of "nothing to report"."""
    vad = [i * 7.2 for i in range(50)]
    ds = uq.run({"wind": {"speed": 10.0}, "ship": {"pitch": 10.0},
                 "lidar": {"half_cone": 30.0, "azimuths": vad, "vertical_beam": False},
                 "correction": "none", "sampling": {"method": "none"},
                 "outputs": ["wind_speed"], "sweep": {"wind.direction": [0.0, 90.0]}})
    expected = 10.0 * (np.cos(np.deg2rad(10.0)) - 1.0)
    speed = render_report(ds).split("<h3>Wind speed</h3>")[1].split("</p>")[0]
    assert f"from {expected:+.3g} to +0 m/s" in speed, speed


def test_a_map_panel_does_not_stretch_noise_over_its_colour_bar():
    """A panel with its own colour scale spans at least MAP_MIN_RELATIVE_SPAN (1 %) of
    its mean: u = 0.1506 +- 1e-5 m/s (Monte Carlo noise) is drawn flat, centred; a real
    variation of 20 % keeps its own range."""
    from uq.outputs.plots import MAP_MIN_RELATIVE_SPAN, _panel_limits
    noisy = 0.1506 + np.array([-1e-5, 0.0, 1e-5])
    low, high = _panel_limits(noisy)
    assert high - low == pytest.approx(MAP_MIN_RELATIVE_SPAN * 0.1506, rel=1e-6)
    assert (low + high) / 2 == pytest.approx(0.1506, abs=1e-12)
    assert _panel_limits(np.array([0.1, 0.12])) == (0.1, 0.12)


def test_a_correction_sweep_gets_a_budget_column_per_correction():
    """Averaging a budget over correction models would mix them. Without correction no INS
    reading enters, so there is no variance to share ("-"); with the yaw correction the
    heading error turns the wind vector: it is the wind direction's whole budget."""
    ds = uq.run({"ins": {"heading": {"dist": "normal", "u": 1.0}},
                 "ship": {"sog": 2.0}, "sampling": {"method": "none"},
                 "outputs": ["wind_direction"], "sweep": {"correction": ["none", "yaw"]}})
    page = render_report(ds)
    budget = page.split("<h3>Wind direction</h3>")[1].split("</table>")[0]
    assert "share, none" in budget and "share, yaw" in budget
    assert "<td>ins.heading</td><td>-</td><td>100.0 %</td>" in budget, budget


def test_a_small_sweep_gets_its_answer_as_a_table():
    """Issue 27, items 5 and 7: a planner's small sweep (here correction x wind
    direction, 6 scenes) got ranges and maps, its numbers only in the netCDF, and the
    Run table named one correction. The report lists every scene: its keys, u, the 95 %
    interval and the bias, the result's own numbers to the 4 digits written; the
    attribute and the Run table say the correction is swept."""
    ds = uq.run(uq.load_scenario(ROOT / "scenarios" / "rubio2022_case_i.yaml", {
        "sampling.n": 2000, "sweep": {"correction": ["yaw", "full"],
                                      "wind.direction": [0, 90, 180]}}))
    assert ds.attrs["correction"] == "swept: yaw, full"
    page = render_report(ds)
    assert "<td>correction</td><td>swept: yaw, full</td>" in page
    table = page.split("<h2>Scene by scene</h2>")[1].split("</table>")[0]
    rows = re.findall(r"<tr>(.*?)</tr>", table)[1:]
    assert len(rows) == 6
    for row in rows:
        cells = re.findall(r"<td>(.*?)</td>", row)
        at = ds.sel(correction=cells[0], wind_direction=float(cells[1]))
        assert cells[2] == f"{float(at.wind_speed_mc_u):.4g}"
        assert cells[3] == f"[{float(at.wind_speed_mc_low):.4g}, " \
            f"{float(at.wind_speed_mc_high):.4g}]"
        assert cells[4] == f"{float(at.wind_speed_mc_bias):.4g}"
