"""Input files as a user has them (uq.campaign.config, recordsfile, motioninput): other
column names, time zones, stamps at the end of the period, missing records, other units;
and bad input: one line naming the file, the key or column and what is allowed."""
import numpy as np
import pandas as pd
import pytest

from uq.campaign.config import load_campaign_config
from uq.campaign.motioninput import load_motion
from uq.campaign.recordsfile import load_records, load_reference
from uq.cli import main
from uq.errors import DataFileError, ScenarioError

from campaigns import lidar_records, write_campaign


def test_local_stamps_at_the_end_of_the_period_are_utc_starts(tmp_path):
    """The logger's 01:20 at UTC+01:00, stamped at the end, is the period 00:10-00:20 UTC."""
    config = load_campaign_config(write_campaign(tmp_path))
    records = load_records(config.records)
    assert str(records["time"].values[0])[:16] == "2016-03-02T00:00"
    assert records.sizes == {"time": 24, "height": 2}
    assert records.attrs["n_missing"] == 0


@pytest.mark.parametrize("zone, stamp, expected", [
    ("Europe/Oslo", "2016-07-01 12:10", "2016-07-01T10:00"),     # summer time, UTC+2
    ("Europe/Oslo", "2016-01-04 12:10", "2016-01-04T11:00"),     # winter, UTC+1
    ("-05:30", "2016-01-04 12:10", "2016-01-04T17:30"),
    ("UTC", "2016-01-04T12:10+02:00", "2016-01-04T10:00"),      # a stamp's own offset wins
])
def test_time_zones(tmp_path, zone, stamp, expected):
    records = lidar_records(count=3)
    records["stamp"] = [pd.Timestamp(stamp.replace("T", " ")[:16]) + pd.Timedelta(minutes=10 * i)
                        for i in range(3)]
    records["stamp"] = [s.strftime("%Y-%m-%d %H:%M") + stamp[16:] for s in records["stamp"]]
    path = write_campaign(tmp_path, records, {"records.time_zone": zone}, waves=False,
                          reference=False)
    found = load_records(load_campaign_config(path).records)
    assert str(found["time"].values[0])[:16] == expected


def test_a_stamp_that_daylight_saving_makes_ambiguous_is_refused(tmp_path):
    records = lidar_records(count=12)
    records["stamp"] = pd.date_range("2016-10-30 01:30", periods=12, freq="10min").strftime(
        "%Y-%m-%d %H:%M")
    path = write_campaign(tmp_path, records, {"records.time_zone": "Europe/Oslo"},
                          waves=False, reference=False)
    with pytest.raises(DataFileError, match=r"lidar\.csv.*campaign\.records\.time.*ambiguous"):
        load_records(load_campaign_config(path).records)


def test_missing_records_are_nan_counted_and_flagged(tmp_path):
    """Rows absent (periods 3 and 4), an empty cell (a missing value; so is pandas' 'n/a')
    and a cell that is not a number: NaN, the absent periods counted as missing, the text
    as invalid."""
    records = lidar_records().drop(index=[3, 4]).reset_index(drop=True)
    records["ws40"] = records["ws40"].astype(object)
    records.loc[0, "ws40"] = ""
    records.loc[1, "ws40"] = "error"
    config = load_campaign_config(write_campaign(tmp_path, records, reference=False))
    found = load_records(config.records)
    assert found.attrs["n_missing"] == 2 and found.attrs["n_invalid"] == 1
    speed = found["speed"].sel(height=40).values
    assert np.isnan(speed[[0, 1, 3, 4]]).all() and np.isfinite(speed[[2, 5]]).all()
    assert found["availability"].values[3, 0] == 0.0         # a missing record: none


def test_other_units_are_converted(tmp_path):
    records = lidar_records(count=6)
    for h in (40, 80):
        records[f"ws{h}"] *= 3.6
        records[f"sd{h}"] *= 3.6
        records[f"av{h}"] = 1.0
    plain = load_records(load_campaign_config(write_campaign(tmp_path / "a", lidar_records(
        count=6), waves=False, reference=False)).records)
    path = write_campaign(tmp_path / "b", records, {"records.units": {
        "speed": "km/h", "availability": "fraction"}}, waves=False, reference=False)
    found = load_records(load_campaign_config(path).records)
    np.testing.assert_allclose(found["speed"], plain["speed"], rtol=1e-12)
    np.testing.assert_allclose(found["availability"], 1.0)


@pytest.mark.parametrize("change, match", [
    ({"records.heights.40.speed": "WS_40"}, r"lidar\.csv: campaign\.records\.heights\.40\.speed"
     r".*no column 'WS_40'; allowed: stamp, ws40"),
    ({"records.time": "Time"}, r"campaign\.records\.time.*no column 'Time'"),
])
def test_a_missing_column_names_file_key_and_columns(tmp_path, change, match):
    config = load_campaign_config(write_campaign(tmp_path, changes=change))
    with pytest.raises(DataFileError, match=match):
        load_records(config.records)


@pytest.mark.parametrize("edit, match", [
    (lambda t: t.assign(stamp=t["stamp"].where(t.index != 5, "2016-03-02 01:67")),
     r"stamp '2016-03-02 01:67' \(row 7\) is not a date"),
    (lambda t: t.assign(stamp=t["stamp"].where(t.index != 5, "2016-03-02 02:03")),
     "not on the ten-minute grid"),
    (lambda t: t.assign(stamp=t["stamp"].where(t.index != 5, t["stamp"][4])), "repeats"),
    (lambda t: t.assign(ws40=t["ws40"].where(t.index != 2, -1.0)), "negative value -1"),
    (lambda t: t.assign(ws40=t["ws40"] * 3.6), "looks like km/h or knots"),
    (lambda t: t.assign(wd40=t["wd40"].where(t.index != 2, 400.0)), "direction 400 deg"),
    (lambda t: t.assign(av40=t["av40"].where(t.index != 2, 130.0)), "availability"),
])
def test_bad_values_are_refused_naming_the_file_and_the_column(tmp_path, edit, match):
    path = write_campaign(tmp_path, edit(lidar_records()), waves=False, reference=False)
    with pytest.raises(DataFileError, match=r"lidar\.csv: campaign\.records") as raised:
        load_records(load_campaign_config(path).records)
    assert raised.match(match)


@pytest.mark.parametrize("change, match", [
    ({"records.heights.40.std": None}, r"campaign\.records\.heights\.40\.std: missing"),
    ({"filtering": "both"}, r"campaign\.filtering: 'both' is not allowed; allowed: "
     "spectral, none"),
    ({"records.time_zone": "Mars/Olympus"}, r"campaign\.records\.time_zone: 'Mars/Olympus' "
     "is not a time zone"),
    ({"motion.rate": 10}, r"campaign\.motion\.rate: does not apply to kind sea_state"),
    ({"motion.kind": "waves"}, r"campaign\.motion\.kind: 'waves' is not allowed"),
    ({"unknown": 1}, r"campaign\.unknown: unknown key"),
    ({"lidar": "nowhere.yaml"}, r"nowhere\.yaml"),
])
def test_a_bad_configuration_is_one_line_with_exit_2(tmp_path, capsys, change, match):
    path = write_campaign(tmp_path, changes=change)
    with pytest.raises((ScenarioError, DataFileError), match=match):
        load_campaign_config(path)
    assert main(["campaign", str(path), "-o", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1 and "Traceback" not in err
    assert not (tmp_path / "out").exists()


def test_a_tilted_lidar_is_refused(tmp_path):
    path = write_campaign(tmp_path, lidar_changes={"lidar.mount": {"tilt": 90},
                                                   "lidar.vertical_beam": False})
    with pytest.raises(ScenarioError, match="tilted .nacelle. lidar"):
        load_campaign_config(path)


def test_sea_states_on_the_records_periods(tmp_path):
    """The wave table in UTC (start stamps) on the lidar's grid; a period it lacks has no
    motion; a Tp out of the tables' reach is refused."""
    path = write_campaign(tmp_path)
    waves = pd.read_csv(tmp_path / "waves.csv").drop(index=[2])
    waves.to_csv(tmp_path / "waves.csv", index=False)
    config = load_campaign_config(path)
    times = load_records(config.records)["time"].values
    found, outside, off = load_motion(config.motion, times)
    assert found.valid.tolist() == [i != 2 for i in range(24)]
    assert off == 0 and np.all(outside == 0)
    waves.loc[0, "tp"] = 1.0
    waves.to_csv(tmp_path / "waves.csv", index=False)
    with pytest.raises(DataFileError, match=r"waves\.csv: campaign\.motion\.columns\.tp: "
                       r"value 1 is out of range; allowed: \[2, 30\] s"):
        load_motion(config.motion, times)


def test_statistics_give_one_harmonic_per_degree_of_freedom(tmp_path):
    """A standard deviation s is a harmonic of amplitude s sqrt(2): its power s^2."""
    path = write_campaign(tmp_path, changes={"motion": {
        "kind": "statistics", "file": "stats.csv", "time": "t",
        "columns": {"roll": {"std": "roll_sd", "period": "roll_t"},
                    "heave": {"amplitude": "heave_a", "period": "heave_t"}}}})
    starts = pd.read_csv(tmp_path / "waves.csv")["t"]
    pd.DataFrame({"t": starts, "roll_sd": 2.0, "roll_t": 6.0, "heave_a": 0.5,
                  "heave_t": 8.0}).to_csv(tmp_path / "stats.csv", index=False)
    config = load_campaign_config(path)
    found, _, _ = load_motion(config.motion, load_records(config.records)["time"].values)
    np.testing.assert_allclose(found.power[0], [np.radians(2.0) ** 2, 0.5 ** 2 / 2])
    np.testing.assert_allclose(found.frequency[0], [1 / 6, 1 / 8])


def test_a_reference_by_speed_and_std_or_by_ti(tmp_path):
    path = write_campaign(tmp_path)
    config = load_campaign_config(path)
    times = load_records(config.records)["time"].values
    ti, speed, off = load_reference(config.reference, times, [40.0, 80.0])
    records = pd.read_csv(tmp_path / "lidar.csv")
    np.testing.assert_allclose(ti[:, 0], records["sd40"] / records["ws40"], rtol=1e-12)
    assert np.isnan(speed).all() and off == 0
