"""uq golden on a hand-made six-record campaign: the golden-lidar chain against
hand-computed numbers, and every bad-input check of the records and the configuration."""
import numpy as np
import pandas as pd
import pytest
import yaml

from uq.errors import DataFileError, ScenarioError
from uq.golden.analysis import analyse
from uq.golden.config import load_golden_config

MAST = np.array([4.0, 4.1, 4.5, 4.6, 5.0, 5.1])
SHEAR = np.array([0.0, 0.2, 0.1, 0.3, 0.2, 0.0])
FLSB = MAST * (1 - 5.0 * SHEAR / 100)                 # exactly -5 % per unit of shear
FLSA = FLSB + np.array([0.02, -0.02, 0.02, -0.02, 0.02, -0.02])


def write_campaign(directory, tables=None, **changes):
    """CSV files and a configuration; `changes` replace entries of the golden section."""
    times = pd.date_range("2024-01-01", periods=6, freq="10min")
    tables = tables or {"mast": MAST, "flsb": FLSB, "flsa": FLSA}
    for name, speed in tables.items():
        pd.DataFrame({"time": times, "v80": speed, "d80": 10.0, "shear": SHEAR}).to_csv(
            directory / f"{name}.csv", index=False)
    columns = {"time": "time", "heights": {80: {"speed": "v80", "direction": "d80"}},
               "environment": {"shear": "shear"}}
    golden = {"name": "six", "instruments": {
        "mast": {"file": "mast.csv", **columns, "calibration": {"absolute": 0.1},
                 "class_number": 0.0},
        "flsb": {"file": "flsb.csv", **columns}, "flsa": {"file": "flsa.csv", **columns}},
        "comparisons": [{"unit": "flsb", "reference": "mast"},
                        {"unit": "flsa", "reference": "flsb"}],
        "classification": {"variables": ["shear"], "ranges": {"shear": [0.0, 0.4]},
                           "route": "class_number"},
        "bins": {"required": [4.0, 5.0], "minimum_records": 2}}
    golden.update(changes)
    path = directory / "campaign.yaml"
    path.write_text(yaml.safe_dump({"golden": golden}))
    return path


@pytest.fixture()
def six(tmp_path):
    return analyse(load_golden_config(write_campaign(tmp_path)))


def test_chain_by_hand(six):
    """Bin 4.0 m/s (mast 4.0, 4.1). FLSb against the mast: sigma/sqrt(N) = 0.059/2,
    |dv| = 0.0205, u_cal,mast = 0.1, so u_cal,FLSb = sqrt(0.01 + 0.0295^2 + 0.0205^2)
    (IEC) and sqrt(0.01 + 0.0205^2) (LUSR). FLSb's slope is exactly -5 %/unit shear,
    class number 5 * 0.4 / 2 = 1, u_class,FLSb = 4.0 * 1 % / sqrt(3). FLSa against FLSb:
    sigma/sqrt(N) = 0.019/2, |dv| = 0 (IEC); sigma_dev/sqrt(N) = 0.02 (LUSR)."""
    b = six.sel(height=80.0, bin=4.0)
    flsb, flsa = b.sel(comparison="flsb-mast"), b.sel(comparison="flsa-flsb")
    assert float(flsb["slope"].sel(variable="shear")) == pytest.approx(-5.0)
    assert float(flsb["class_number"]) == pytest.approx(1.0)
    u_cal_b = {"iec": np.sqrt(0.01 + 0.0295 ** 2 + 0.0205 ** 2),
               "lusr": np.sqrt(0.01 + 0.0205 ** 2)}
    u_class_b = 0.04 / np.sqrt(3)
    u_dev_a = {"iec": 0.0095, "lusr": 0.02}
    for fw in ("iec", "lusr"):
        assert float(flsb["calibration"].sel(framework=fw)) == pytest.approx(u_cal_b[fw])
        assert float(flsa["reference_calibration"].sel(framework=fw)) == pytest.approx(
            u_cal_b[fw])
        assert float(flsa["reference_classification"].sel(framework=fw)) == pytest.approx(
            u_class_b)
        assert float(flsa["deviation"].sel(framework=fw)) == pytest.approx(u_dev_a[fw])
        assert float(flsa["calibration"].sel(framework=fw)) == pytest.approx(
            np.sqrt(u_cal_b[fw] ** 2 + u_class_b ** 2 + u_dev_a[fw] ** 2))
    assert float(flsb["reference_classification"].sel(framework="iec")) == 0.0   # the mast


def test_bins_and_flags(six):
    c = six.sel(comparison="flsb-mast", height=80.0)
    assert c["n_records"].sel(bin=[4.0, 4.5, 5.0]).values.tolist() == [2, 2, 2]
    assert c["sufficient"].sel(bin=[4.0, 4.5, 5.0]).all()
    assert c["coverage_verdict"].item() == "best practice"
    assert c["availability"].item() == pytest.approx(1.0)


def test_thin_bin_is_flagged(tmp_path):
    ds = analyse(load_golden_config(write_campaign(
        tmp_path, bins={"required": [4.0, 5.0], "minimum_records": 3})))
    c = ds.sel(comparison="flsb-mast", height=80.0)
    assert not c["sufficient"].sel(bin=4.0) and c["coverage_verdict"].item() == "fail"


def _error(tmp_path, match, error=DataFileError, **kwargs):
    with pytest.raises(error, match=match):
        analyse(load_golden_config(write_campaign(tmp_path, **kwargs)))


def test_missing_column(tmp_path):
    path = write_campaign(tmp_path)
    frame = pd.read_csv(tmp_path / "flsa.csv").drop(columns="v80")
    frame.to_csv(tmp_path / "flsa.csv", index=False)
    with pytest.raises(DataFileError, match=r"flsa.csv: instruments.flsa.heights.80.speed: "
                                            r"no column 'v80'; allowed: time, d80, shear"):
        analyse(load_golden_config(path))


def test_directions_in_radians(tmp_path):
    path = write_campaign(tmp_path)
    frame = pd.read_csv(tmp_path / "flsb.csv")
    frame["d80"] = np.linspace(0.1, 6.0, 6)
    frame.to_csv(tmp_path / "flsb.csv", index=False)
    with pytest.raises(DataFileError, match="radians"):
        analyse(load_golden_config(path))


def test_speeds_in_km_per_hour(tmp_path):
    _error(tmp_path, "km/h", tables={"mast": MAST, "flsb": FLSB * 3.6 * 2, "flsa": FLSA})


def test_negative_speed(tmp_path):
    _error(tmp_path, "negative wind speed", tables={"mast": MAST, "flsb": -FLSB, "flsa": FLSA})


def test_timestamps_that_do_not_match(tmp_path):
    path = write_campaign(tmp_path)
    frame = pd.read_csv(tmp_path / "flsa.csv")
    frame["time"] = pd.date_range("2025-01-01", periods=6, freq="10min")
    frame.to_csv(tmp_path / "flsa.csv", index=False)
    with pytest.raises(DataFileError, match="share no timestamp.*time zone"):
        analyse(load_golden_config(path))


@pytest.mark.parametrize("times, match", [
    (["2024-01-01 00:00"] * 2 + [f"2024-01-01 00:{m}" for m in (20, 30, 40, 50)], "repeats"),
    ([f"2024-01-01 {h:02d}:00" for h in range(6)], "60 min apart"),
    (["yesterday"] + [f"2024-01-01 00:{m}" for m in (10, 20, 30, 40, 50)], "not a date")])
def test_bad_timestamps(tmp_path, times, match):
    path = write_campaign(tmp_path)
    frame = pd.read_csv(tmp_path / "mast.csv")
    frame["time"] = times
    frame.to_csv(tmp_path / "mast.csv", index=False)
    with pytest.raises(DataFileError, match=match):
        analyse(load_golden_config(path))


def test_non_numbers_are_counted_not_dropped(tmp_path):
    path = write_campaign(tmp_path)
    frame = pd.read_csv(tmp_path / "flsa.csv")
    frame["v80"] = frame["v80"].astype(object)
    frame.loc[2, "v80"] = "err"
    frame.to_csv(tmp_path / "flsa.csv", index=False)
    ds = analyse(load_golden_config(path))
    assert ds.attrs["n_invalid"] == 1
    assert int(ds.sel(comparison="flsa-flsb", height=80.0)["n_records"].sum()) == 5


@pytest.mark.parametrize("changes, match", [
    ({"comparisons": [{"unit": "flsa", "reference": "flsb"}]},
     "instruments.flsb.calibration: a reference needs a stated calibration"),
    ({"comparisons": [{"unit": "flsa", "reference": "flsa"}]}, "the same instrument"),
    ({"comparisons": [{"unit": "flsx", "reference": "mast"}]},
     r"comparisons\[0\].unit: 'flsx' is not allowed; allowed: flsa, flsb, mast"),
    ({"bins": {"width": 0}}, r"golden.bins.width: 0 is out of range"),
    ({"classification": {"route": "guess"}}, "allowed: per_variable, class_number"),
    ({"colour": "red"}, "golden.colour: unknown key")])
def test_configuration_errors(tmp_path, changes, match):
    with pytest.raises(ScenarioError, match=match):
        load_golden_config(write_campaign(tmp_path, **changes))


def test_unknown_variable_and_missing_smc(tmp_path):
    _error(tmp_path, "'wave_height' is not an environmental variable of flsa; allowed: shear",
           ScenarioError, classification={"variables": ["wave_height"], "route": "class_number"})
    _error(tmp_path, "golden.smc: missing", ScenarioError, classification={"variables": ["shear"]})


def test_per_variable_route_with_an_smc(tmp_path):
    """Eq. 1 through the analysis: the SMC sees the same speeds with shear 0.1 higher in
    every bin, FLSb's slope is -5 %/unit, so u_class,FLSb = v_i |-5 x 0.1| / 100."""
    path = write_campaign(tmp_path, classification={"variables": ["shear"]},
                          smc={"file": "smc.csv", "time": "time", "heights": {
                              80: {"speed": "v80"}}, "environment": {"shear": "shear"}})
    times = pd.date_range("2024-03-01", periods=6, freq="10min")
    pd.DataFrame({"time": times, "v80": MAST, "shear": SHEAR + 0.1}).to_csv(
        tmp_path / "smc.csv", index=False)
    ds = analyse(load_golden_config(path))
    flsb = ds.sel(comparison="flsb-mast", height=80.0, bin=[4.0, 4.5, 5.0])
    np.testing.assert_allclose(flsb["classification"], [0.02, 0.0225, 0.025], rtol=1e-9)
    chained = ds.sel(comparison="flsa-flsb", height=80.0, bin=[4.0, 4.5, 5.0],
                     framework="lusr")["reference_classification"]
    np.testing.assert_allclose(chained, [0.02, 0.0225, 0.025], rtol=1e-9)


def test_netcdf_records_read_like_csv(tmp_path, six):
    """An instrument's records may be netCDF (a time coordinate and one variable per
    column); the result is the same as from CSV."""
    path = write_campaign(tmp_path)
    frame = pd.read_csv(tmp_path / "mast.csv", parse_dates=["time"]).set_index("time")
    frame.to_xarray().to_netcdf(tmp_path / "mast.nc")
    text = path.read_text().replace("file: mast.csv", "file: mast.nc")
    path.write_text(text)
    ds = analyse(load_golden_config(path))
    np.testing.assert_allclose(ds["calibration"], six["calibration"], rtol=1e-12)


def test_direction_out_of_range(tmp_path):
    path = write_campaign(tmp_path)
    frame = pd.read_csv(tmp_path / "flsb.csv")
    frame.loc[3, "d80"] = 400.0
    frame.to_csv(tmp_path / "flsb.csv", index=False)
    with pytest.raises(DataFileError, match=r"direction 400 is out of range; allowed: "
                                            r"degrees in \[-360, 360\]"):
        analyse(load_golden_config(path))


def test_timestamps_only_in_one_instrument_are_counted(tmp_path):
    path = write_campaign(tmp_path)
    frame = pd.read_csv(tmp_path / "flsa.csv")
    extra = frame.iloc[[-1]].assign(time="2024-01-01 01:00:00")
    pd.concat([frame, extra]).to_csv(tmp_path / "flsa.csv", index=False)
    ds = analyse(load_golden_config(path))
    assert int(ds["records_only_unit"].sel(comparison="flsa-flsb").max()) == 1
    assert int(ds["records_only_reference"].sel(comparison="flsa-flsb").max()) == 0


def test_thin_bins_are_named_on_stderr(tmp_path, capsys):
    from uq.cli import main
    path = write_campaign(tmp_path, bins={"required": [4.0, 5.5], "minimum_records": 2})
    assert main(["golden", str(path), "-o", str(tmp_path / "out")]) == 0
    err = capsys.readouterr().err
    assert "uq golden: warning: flsb-mast at 80 m: required bins with too few records: " \
           "5.5 m/s (0)" in err
    assert "5.5 m/s (0)" in (tmp_path / "out" / "report.md").read_text()


def test_variables_of_several_units_claim_none(six):
    """Issue 27, item 5: golden_campaign.nc gave the bin means of temperature (and every
    other environmental variable) units = "1" and the slopes "percent" (they are percent
    per unit of the variable). One netCDF variable along `variable` holds several units
    the configuration does not name: no units attribute, and the long name says whose."""
    for name in ("verification_mean", "slope", "slope_standard_error", "paired_environment"):
        if name in six:
            assert "units" not in six[name].attrs, name
            assert "unit" in six[name].attrs["long_name"], name
    assert six["slope_intercept"].attrs["units"] == "percent"
