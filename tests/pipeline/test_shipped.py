"""Names on the command line: shipped scenarios, runs in results/, and "did you mean"."""
import shutil

import pytest

from uq.cli import main
from uq.errors import DataFileError, ScenarioError
from uq.pipeline import shipped


def test_closest_offers_the_nearest_names_only():
    names = shipped.shipped_names()
    assert shipped.closest("rubio2022_cas_i", names) == ["rubio2022_case_i"]
    assert shipped.closest("floating_lidar_ful", names) == ["floating_lidar_full"]
    assert shipped.closest("something else", names) == []


def test_a_mistyped_scenario_name_is_refused_with_the_closest(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    with pytest.raises(ScenarioError, match="did you mean 'rubio2022_case_i'"):
        shipped.scenario_path("rubio2022_cas_i")
    with pytest.raises(ScenarioError, match="uq list"):
        shipped.scenario_path("nothing_like_it")
    assert shipped.scenario_path("rubio2022_case_i") == shipped.shipped_path("rubio2022_case_i")
    assert str(shipped.scenario_path("missing/x.yaml")) == "missing/x.yaml"   # a path


def test_a_run_name_finds_results_and_a_typo_is_refused(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "results").mkdir()
    (tmp_path / "results" / "my_run.nc").write_bytes(b"")
    assert str(shipped.results_path("my_run")) == "results/my_run.nc"
    assert str(shipped.results_path("my_run.nc")) == "results/my_run.nc"
    with pytest.raises(DataFileError, match="did you mean 'my_run'"):
        shipped.results_path("my_rnu")
    with pytest.raises(DataFileError, match="run it first"):
        shipped.results_path("rubio2022_case_i")        # shipped, but not run here


@pytest.mark.parametrize("argv", [["run", "rubio2022_cas_i"], ["check", "rubio2022_cas_i"],
                                  ["golden", "golden_campain"], ["plot", "rubio2022_cas_i"],
                                  ["report", "rubio2022_cas_i"],
                                  ["export", "rubio2022_cas_i"], ["fit", "rubio2022_cas_i"]])
def test_every_command_that_takes_a_name_says_did_you_mean(argv, tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    assert main(argv) == 2
    err = capsys.readouterr().err
    meant = "golden_campaign" if argv[0] == "golden" else "rubio2022_case_i"
    assert len(err.splitlines()) == 1 and f"did you mean '{meant}'" in err, err
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("columns", [60, 100, 200])
def test_uq_list_shows_every_whole_description_wrapped(columns, capsys, monkeypatch):
    """Each scenario's name, then its whole description (it was cut at ~45 characters)
    wrapped to the terminal's width (COLUMNS), continued under the description's column."""
    monkeypatch.setenv("COLUMNS", str(columns))
    assert main(["list"]) == 0
    lines = capsys.readouterr().out.splitlines()
    names = shipped.shipped_names()
    starts = [i for i, line in enumerate(lines) if not line.startswith(" ")]
    assert [lines[i].split()[0] for i in starts] == names
    assert all(len(line) <= columns for line in lines)
    width = max(map(len, names)) + 2
    for name, start, stop in zip(names, starts, starts[1:] + [len(lines)]):
        description = shipped.describe(shipped.shipped_path(name))
        shown = " ".join([lines[start][width:]] + [line[width:] for line in
                                                   lines[start + 1:stop]])
        assert description and shown.split() == description.split(), name
        assert all(line[:width].isspace() for line in lines[start + 1:stop])


def test_report_and_plot_find_a_run_by_its_name(tmp_path, monkeypatch, capsys):
    """`uq report NAME` reads results/NAME.nc (here a run of the shipped case i, one
    direction, few trials) and writes its report beside it."""
    monkeypatch.chdir(tmp_path)
    assert main(["run", "rubio2022_case_i", "-q", "--set", "sweep={}",
                 "--set", "sampling.n=2000"]) == 0
    assert main(["report", "rubio2022_case_i", "-q"]) == 0
    assert (tmp_path / "results" / "rubio2022_case_i_report.html").is_file()
    shutil.rmtree(tmp_path / "results")
    assert main(["plot", "rubio2022_case_i"]) == 2
    assert "run it first" in capsys.readouterr().err
