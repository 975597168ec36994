"""uq plot and uq report: every figure renders from a result, with labelled axes and
units; the report is one self-contained HTML file; bad input exits 2."""
import base64
import re
from pathlib import Path

import matplotlib.pyplot as plt
import pytest
import xarray as xr

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
    for section in ("Campaign-planning answers", "Uncertainty budget", "Bias",
                    "Findings of Rubio", "Scenario as run", "tilt lowers u(Vh)"):
        assert section in page, section
    assert "http" not in page.replace("http-equiv", "")   # self-contained: no links out


def test_report_answers_the_planning_questions(results):
    page = render_report(results["rubio2022_velocity_ratio"], targets=(0.06,))
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


def test_no_figure_for_a_result_without_a_sweep(tmp_path, capsys):
    single = uq.run(uq.load_scenario({"name": "one", "sampling": {"n": 1000, "seed": 1}}))
    path = write_results(single, tmp_path / "one.nc")
    assert main(["plot", str(path)]) == 2
    assert "no figure for these sweep dimensions" in capsys.readouterr().err
