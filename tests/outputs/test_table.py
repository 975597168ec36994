"""uq export: a results file as a CSV table, one row per scene and range gate, a column
per variable with its unit in the header; values read back equal the Dataset's."""
import os
import stat

import numpy as np
import pandas as pd
import pytest
import yaml

from uq.cli import main
from uq.outputs import table
from uq.pipeline.results import read_results

#: Two wind directions x two gates, one output with a `beam` dimension.
SWEEP = {"name": "tiny", "ins": {"heading": {"dist": "normal", "u": 0.1}},
         "lidar": {"ranges": [80.0, 120.0],
                   "errors": {"radial_velocity": {"dist": "normal", "u": 0.05}}},
         "outputs": ["wind_speed", "radial_velocity"],
         "sampling": {"n": 2000, "seed": 1},
         "sweep": {"wind.direction": [0.0, 90.0]}}


@pytest.fixture
def results(tmp_path, monkeypatch):
    (tmp_path / "tiny.yaml").write_text(yaml.safe_dump(SWEEP))
    monkeypatch.chdir(tmp_path)
    assert main(["run", "tiny.yaml", "-q"]) == 0          # results/tiny.nc
    return tmp_path / "results" / "tiny.nc"


def read(path):
    return pd.read_csv(path, comment="#")


def test_one_row_per_scene_and_gate_with_units_in_the_header(results):
    assert main(["export", str(results), "-q"]) == 0
    frame = read(results.with_suffix(".csv"))
    dataset = read_results(results)
    assert len(frame) == 2 * 2
    assert frame["wind_direction [degree]"].tolist() == [0.0, 0.0, 90.0, 90.0]
    assert frame["range [m]"].tolist() == [80.0, 120.0, 80.0, 120.0]
    for row in frame.itertuples(index=False):
        scene = dataset.sel({"wind_direction": row[0], "range": row[1]})
        values = dict(zip(frame.columns, row))
        # written with Python's round-trip repr: read back exactly
        assert values["wind_speed_mc_u [m s-1]"] == float(scene["wind_speed_mc_u"])
        assert values["wind_speed_gum_u [m s-1]"] == float(scene["wind_speed_gum_u"])
        for beam in dataset["beam"].values:
            assert values[f"radial_velocity_mc_u[beam={beam}] [m s-1]"] == float(
                scene["radial_velocity_mc_u"].sel(beam=beam))
    # every variable of the results is in the table, each column named with its unit
    names = {column.split("[")[0].split(" ")[0] for column in frame.columns}
    assert set(dataset.data_vars) <= names
    for name, variable in dataset.data_vars.items():
        if "units" in variable.attrs and variable.dims == ("wind_direction", "range"):
            assert f"{name} [{variable.attrs['units']}]" in frame.columns


def test_a_table_is_written_atomically_and_replaces_only_its_own(results, tmp_path):
    previous = os.umask(0o022)
    try:
        target = tmp_path / "mine.csv"
        target.write_text("somebody else's table\n")
        assert main(["export", str(results), "-o", str(target)]) == 2
        assert target.read_text() == "somebody else's table\n"
        assert main(["export", str(results), "-o", str(target), "--force", "-q"]) == 0
        assert len(read(target)) == 4
        assert main(["export", str(results), "-o", str(target), "-q"]) == 0   # its own
        assert stat.S_IMODE(target.stat().st_mode) == 0o644
        assert not list(tmp_path.glob(".*.part"))
    finally:
        os.umask(previous)


def test_export_takes_the_name_of_a_run_and_a_selection(results, capsys):
    assert main(["export", "tiny", "-o", "one.csv", "--select", "wind_direction=90"]) == 0
    assert "wrote one.csv" in capsys.readouterr().out
    frame = read("one.csv")
    assert frame["wind_direction [degree]"].tolist() == [90.0, 90.0]


def test_a_table_too_large_is_refused_before_it_is_built(results, monkeypatch, capsys):
    rows, columns = table.table_size(read_results(results))
    assert rows == 4
    monkeypatch.setattr(table, "MAX_TABLE_CELLS", rows * columns - 1)
    assert main(["export", "tiny"]) == 2
    err = capsys.readouterr().err
    assert "results/tiny.nc" in err and "--select" in err and len(err.splitlines()) == 1
    assert not results.with_suffix(".csv").exists()


def test_table_size_counts_the_columns_results_table_builds(results):
    dataset = read_results(results)
    assert table.table_size(dataset) == table.results_table(dataset).shape
    single = dataset.isel(wind_direction=0, range=0, drop=True)
    frame = table.results_table(single)
    assert len(frame) == 1 and np.isfinite(frame["wind_speed_mc_u [m s-1]"]).all()
