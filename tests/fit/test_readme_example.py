"""The README's `uq fit` example runs as written, on the files it names (shipped in
examples/mast), and fits what the table says."""
import re
import shlex
import shutil
from pathlib import Path

import pandas as pd
import xarray as xr

from uq.cli import main

ROOT = Path(__file__).resolve().parents[2]


def readme_fit_commands():
    """The `uq fit` command lines of the README that take a table (.csv)."""
    text = (ROOT / "README.md").read_text()
    return [shlex.split(line.split("#")[0])[1:] for line in
            re.findall(r"^uq fit \S+\.csv.*$", text, flags=re.MULTILINE)]


def test_the_readme_fit_example_runs_on_its_shipped_files(tmp_path, monkeypatch, capsys):
    commands = readme_fit_commands()
    assert commands == [["fit", "examples/mast/mast.csv", "-c", "examples/mast/fit.yaml"]]
    shutil.copytree(ROOT / "examples", tmp_path / "examples")     # writes beside its input
    monkeypatch.chdir(tmp_path)
    assert main(commands[0] + ["-q"]) == 0
    table = pd.read_csv(ROOT / "examples" / "mast" / "mast.csv")
    with xr.open_dataset(tmp_path / "examples" / "mast" / "mast_fit.nc") as fit:
        median = float(fit["posterior_median"].sel(fit="data", parameter="reference_speed"))
        low = float(fit["posterior_low95"].sel(fit="data", parameter="reference_speed"))
        high = float(fit["posterior_high95"].sel(fit="data", parameter="reference_speed"))
    # the speed at the reference height (80 m) is about the mean of the 80 m rows: the
    # 95 % interval holds it (the power law through three heights passes near each mean)
    at_80 = table.loc[table["height_m"] == 80.0, "speed_ms"].mean()
    assert low < at_80 < high and abs(median - at_80) < 0.5 * (high - low)
    for name in ("mast_fit_profile.png", "mast_fit_corner.png"):
        assert (tmp_path / "examples" / "mast" / name).is_file()
