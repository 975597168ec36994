"""Every writer keeps what it did not write: a foreign file beside its target survives, an
earlier output of its own is replaced whole, and new files get the umask's permissions."""
import os
import stat
from pathlib import Path

import pytest
import yaml

from uq.cli import main
from uq.files import MARKER, written_by_uq

ROOT = Path(__file__).resolve().parents[2]
GOOD = {"name": "tiny", "ins": {"heading": {"dist": "normal", "u": 0.1}},
        "sampling": {"n": 2000, "seed": 1}}


@pytest.fixture
def umask_022():
    previous = os.umask(0o022)
    yield
    os.umask(previous)


def mode(path):
    return stat.S_IMODE(path.stat().st_mode)


def plant(folder, name="earlier_run.nc", text="somebody else's data"):
    folder.mkdir(parents=True, exist_ok=True)
    (folder / name).write_text(text)
    return folder / name


def run_twice(argv, cwd, monkeypatch):
    monkeypatch.chdir(cwd)
    assert main(argv) == 0
    assert main(argv) == 0                       # replaces its own output


def test_run_keeps_foreign_files_and_replaces_its_own(tmp_path, monkeypatch, umask_022):
    (tmp_path / "s.yaml").write_text(yaml.safe_dump({**GOOD, "sweep": {"wind.speed": [4, 8]}}))
    foreign = plant(tmp_path / "results")
    run_twice(["run", "s.yaml", "--quiet"], tmp_path, monkeypatch)
    out = tmp_path / "results" / "tiny.nc"
    assert written_by_uq(out) and mode(out) == 0o644
    assert foreign.read_text() == "somebody else's data"
    assert sorted(p.name for p in (tmp_path / "results").iterdir()) == ["earlier_run.nc",
                                                                         "tiny.nc"]


def test_plot_report_keep_foreign_files(tmp_path, monkeypatch, umask_022):
    (tmp_path / "s.yaml").write_text(yaml.safe_dump({**GOOD, "sweep": {"wind.direction":
                                                                      [0, 90, 180]}}))
    monkeypatch.chdir(tmp_path)
    assert main(["run", "s.yaml", "--quiet", "-o", "r.nc"]) == 0
    beside = plant(tmp_path / "r_figures", "my_notes.png", "mine")
    run_twice(["plot", "r.nc"], tmp_path, monkeypatch)
    figures = [p for p in (tmp_path / "r_figures").iterdir() if p != beside]
    assert figures and all(written_by_uq(p) and mode(p) == 0o644 for p in figures)
    assert beside.read_text() == "mine"
    other = plant(tmp_path, "r_notes.html", "mine")
    run_twice(["report", "r.nc"], tmp_path, monkeypatch)
    report = tmp_path / "r_report.html"
    assert written_by_uq(report) and mode(report) == 0o644 and other.read_text() == "mine"


def test_golden_keeps_foreign_files_and_swaps_its_folder(tmp_path, monkeypatch, umask_022):
    foreign = plant(tmp_path / "results")
    run_twice(["golden", str(ROOT / "scenarios" / "golden_campaign.yaml")], tmp_path,
              monkeypatch)
    folder = tmp_path / "results" / "golden_campaign"
    assert (folder / MARKER).is_file() and (folder / "report.html").is_file()
    assert mode(folder / "report.html") == 0o644
    assert foreign.read_text() == "somebody else's data"
    assert sorted(p.name for p in (tmp_path / "results").iterdir()) == [
        "earlier_run.nc", "golden_campaign"]             # nothing aside, nothing partial
