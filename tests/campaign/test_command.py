"""``uq campaign`` end to end on small campaigns (tables of few nodes where only the
plumbing is tested): the folder, the CF file, the tables' units, the flags, the
identity and the motion alone against the GUM, the same numbers on a dask cluster."""
import copy

import numpy as np
import pandas as pd
import pytest
import xarray as xr

import uq
from uq.campaign import command
from uq.cli import main
from uq.pipeline.scenario import load_scenario

from campaigns import LIDAR, coarse_tables, lidar_records, write_campaign  # noqa: F401

CONTRACT = ("turbulence_intensity_measured", "turbulence_intensity_corrected",
            "turbulence_intensity_corrected_u", "turbulence_intensity_corrected_low",
            "turbulence_intensity_corrected_high", "wind_speed_corrected",
            "turbulence_intensity_reference")


@pytest.fixture(scope="module")
def small(tmp_path_factory):
    """A campaign of 24 periods at 40 and 80 m with a sea state and a reference, two
    records lost and one of low availability, run once with coarse tables."""
    from uq.campaign import surrogate
    folder = tmp_path_factory.mktemp("small")
    records = lidar_records().drop(index=[4, 5]).reset_index(drop=True)
    records.loc[7, "av40"] = 50.0
    path = write_campaign(folder, records, {"records.minimum_availability": 80})
    patch = pytest.MonkeyPatch()
    for name, value in (("SPEED_NODES", 2), ("SPECTRAL_DIRECTIONS", 3),
                        ("CURVATURE_STEP", 0.2)):
        patch.setattr(surrogate, name, value)
    try:
        out = command.run_campaign(path, folder / "out", stream=open("/dev/null", "w"))
    finally:
        patch.undo()
    return path, out, xr.open_dataset(out / "mini.nc").load()


def test_the_folder_holds_report_tables_figures_and_the_file(small):
    _, folder, ds = small
    for name in ("report.html", "report.md", "mini.nc", "tables/records.csv",
                 "tables/bins.csv", "tables/heights.csv", "figures/bins.png",
                 "figures/scatter.png", "figures/bin_errors.png", "figures/time_series.png"):
        assert (folder / name).stat().st_size > 0, name
    assert not list(folder.parent.glob(".*partial"))
    assert set(CONTRACT) <= set(ds.data_vars)


def test_the_tables_carry_their_units_in_the_header(small):
    _, folder, ds = small
    records = pd.read_csv(folder / "tables" / "records.csv")
    assert "turbulence_intensity_corrected [1]" in records.columns
    assert "wind_speed_corrected [m s-1]" in records.columns
    assert "time [UTC, start of period]" in records.columns
    assert len(records) == ds.sizes["time"] * ds.sizes["height"]
    bins = pd.read_csv(folder / "tables" / "bins.csv")
    assert {"bin [m s-1]", "height [m]", "ti_mean_bias_corrected [1]"} <= set(bins.columns)


def test_the_file_passes_the_cf_checker(small, cf_compliance):
    _, folder, _ = small
    cf_compliance(folder / "mini.nc")


def test_lost_and_thin_records_are_nan_counted_and_flagged(small):
    _, _, ds = small
    flags = ds["record_flags"].values
    assert ds.attrs["n_periods_missing"] == 2 and ds.attrs["n_missing"] == 4
    assert ds.attrs["n_low_availability"] == 1
    assert flags[9, 0] & 2                                     # row 7 of the file
    invalid = (flags & 31) != 0
    assert np.isnan(ds["turbulence_intensity_corrected"].values[invalid]).all()
    assert np.isfinite(ds["turbulence_intensity_corrected"].values[~invalid]).all()
    meanings = ds["record_flags"].attrs["flag_meanings"].split()
    assert meanings[:3] == ["missing", "low_availability", "low_speed"]


def test_the_report_states_the_fast_paths_error(small):
    _, folder, ds = small
    text = (folder / "report.md").read_text()
    assert f"TI {100 * ds.attrs['surrogate_ti_error']:.2f} %" in text
    assert "| missing | 4 |" in text


def test_without_motion_filtering_or_errors_uq_campaign_is_the_identity(tmp_path,
                                                                       coarse_tables):
    """A lidar with no radial noise, no motion, filtering none: every corrected TI is the
    measured one, every corrected speed the measured speed."""
    path = write_campaign(tmp_path, changes={"filtering": "none", "motion": None},
                          lidar_changes={"lidar.errors": {}})
    out = command.run_campaign(path, tmp_path / "out", stream=open("/dev/null", "w"))
    ds = xr.open_dataset(out / "mini.nc")
    np.testing.assert_allclose(ds["turbulence_intensity_corrected"],
                               ds["turbulence_intensity_measured"], rtol=1e-13)
    np.testing.assert_array_equal(ds["wind_speed_corrected"], ds["wind_speed_measured"])


def test_the_motion_alone_is_its_gum_variance_subtracted(tmp_path, coarse_tables):
    """filtering none, no scan errors, a roll of 2 deg standard deviation at 7 s: the
    corrected variance (over N scans) is the measured one less the GUM's motion variance
    of uq run (its wind_speed_motion_ti_gum at the record's wind), times the record's
    high-pass at 1/7 Hz (1 - 1e-4). The tables are exact in U and direction, cubic in
    f (5e-5 of the response): 1e-4 allowed."""
    records = lidar_records(count=3, heights=(80,))
    path = write_campaign(tmp_path, records, {"filtering": "none", "motion": {
        "kind": "statistics", "file": "stats.csv", "time": "t",
        "columns": {"roll": {"std": "sd", "period": "period"}}}, "reference": None},
        lidar_changes={"lidar.errors": {}}, waves=False, reference=False)
    starts = pd.to_datetime(records["stamp"]) - pd.Timedelta(hours=1, minutes=10)
    pd.DataFrame({"t": starts.dt.strftime("%Y-%m-%d %H:%M"), "sd": 2.0, "period": 7.0}
                 ).to_csv(tmp_path / "stats.csv", index=False)
    out = command.run_campaign(path, tmp_path / "out", stream=open("/dev/null", "w"))
    ds = xr.open_dataset(out / "mini.nc").isel(height=0)
    n = ds.attrs["n_scans"]
    lidar = load_scenario(LIDAR).settings
    from uq.campaign import adapter
    high_pass = adapter.record_high_pass(1 / 7.0, ds.attrs["scan_period"], 600.0)
    for i in range(3):
        raw = copy.deepcopy(lidar)
        raw.update(sampling={"method": "none"}, motion={"roll": {
            "amplitude": 2.0 * np.sqrt(2), "period": 7.0, "phase": "random"}})
        raw["lidar"] = {**raw["lidar"], "errors": {}, "ranges": [77.0]}
        raw["wind"] = {**raw["wind"], "speed": float(ds["wind_speed_measured"][i]),
                       "direction": float(ds["wind_direction"][i]), "reference_height": 80.0}
        run = uq.run(load_scenario(raw))
        gum = float((run["wind_speed_motion_ti_gum"] * run["wind_speed_true"]) ** 2)
        measured = float(ds["wind_speed_std_measured"][i]) ** 2 * (n - 1) / n
        corrected = float(ds["turbulence_intensity_corrected"][i] * ds["wind_speed_corrected"][i]
                          ) ** 2 * (n - 1) / n
        assert measured - corrected == pytest.approx(gum * high_pass, rel=1e-4)


def test_a_dask_cluster_gives_the_same_numbers(tmp_path, coarse_tables):
    """uq campaign --workers 2 (the tables' nodes and the records' chunks on two worker
    processes) writes the numbers of one process."""
    path = write_campaign(tmp_path, lidar_records(count=8, heights=(60,)))
    assert main(["campaign", str(path), "-o", str(tmp_path / "one"), "-q"]) == 0
    from uq.pipeline.cluster import local_cluster
    with local_cluster(2, host="127.0.0.1") as client:
        command.run_campaign(path, tmp_path / "two", stream=open("/dev/null", "w"),
                             client=client)
    one, two = (xr.open_dataset(tmp_path / name / "mini.nc") for name in ("one", "two"))
    for name in one.data_vars:
        np.testing.assert_array_equal(one[name].values, two[name].values, err_msg=name)


def test_threads_give_the_numbers_of_one_thread(tmp_path, coarse_tables, monkeypatch):
    """Without a client the tables' nodes and the records' chunks run on threads
    (analysis.local_threads); with none (one CPU) in order: the same numbers, bit for
    bit (each task a fixed computation, its result put in its own place)."""
    from uq.campaign import analysis
    path = write_campaign(tmp_path, lidar_records(count=8, heights=(60,)))
    assert analysis.local_threads() is None or analysis.local_threads()._max_workers >= 2
    command.run_campaign(path, tmp_path / "threads", stream=open("/dev/null", "w"))
    monkeypatch.setattr(analysis, "local_threads", lambda: None)
    command.run_campaign(path, tmp_path / "one", stream=open("/dev/null", "w"))
    one, threads = (xr.open_dataset(tmp_path / name / "mini.nc") for name in ("one", "threads"))
    for name in one.data_vars:
        np.testing.assert_array_equal(one[name].values, threads[name].values, err_msg=name)


def test_a_folder_uq_did_not_write_is_not_replaced(tmp_path, capsys):
    path = write_campaign(tmp_path)
    (tmp_path / "mine").mkdir()
    (tmp_path / "mine" / "notes.txt").write_text("mine")
    assert main(["campaign", str(path), "-o", str(tmp_path / "mine")]) == 2
    assert "was not written by uq" in capsys.readouterr().err
    assert (tmp_path / "mine" / "notes.txt").read_text() == "mine"


def test_uq_golden_takes_the_campaigns_corrected_ti(small, tmp_path):
    """A golden configuration whose unit is the campaign's results file: uq golden's TI
    KPIs use the corrected TI (its bins' unit mean is the corrected TI's, in percent),
    the speed the corrected speed, and the report says so."""
    import yaml
    _, folder, ds = small
    reference = ds["turbulence_intensity_reference"]
    mast = pd.DataFrame({"time": pd.DatetimeIndex(ds["time"].values).strftime(
        "%Y-%m-%dT%H:%MZ")})
    for h in ds["height"].values:
        mast[f"ws{h:g}"] = ds["wind_speed_measured"].sel(height=h).values * 1.01
        mast[f"wd{h:g}"] = ds["wind_direction"].sel(height=h).values
        mast[f"ti{h:g}"] = 100 * reference.sel(height=h).values
    mast.to_csv(tmp_path / "mast.csv", index=False)
    config = {"golden": {
        "name": "with_campaign",
        "instruments": {
            "buoy": {"campaign": str(folder / "mini.nc")},
            "mast": {"file": "mast.csv", "calibration": {"absolute": 0.05},
                     "class_number": 0.0,
                     "heights": {float(h): {"speed": f"ws{h:g}", "direction": f"wd{h:g}",
                                            "environment": {"turbulence_intensity": f"ti{h:g}"}}
                                 for h in ds["height"].values}}},
        "comparisons": [{"unit": "buoy", "reference": "mast"}],
        "classification": {"route": "class_number"},
        "bins": {"minimum_records": 1}}}
    path = tmp_path / "golden.yaml"
    path.write_text(yaml.safe_dump(config))
    assert main(["golden", str(path), "-o", str(tmp_path / "golden"), "-q"]) == 0
    golden = xr.open_dataset(tmp_path / "golden" / "with_campaign.nc")
    from uq.golden import binning
    h = float(ds["height"].values[-1])
    corrected = ds["turbulence_intensity_corrected"].sel(height=h).values
    speed = ds["wind_speed_measured"].sel(height=h).values * 1.01
    keep = np.isfinite(corrected) & np.isfinite(reference.sel(height=h).values)
    index = binning.bin_index(np.where(keep, speed, np.nan))
    g = golden.sel(comparison="buoy-mast", height=h)
    for k, b in enumerate(g["bin"].values):
        chosen = index == int(round(b / 0.5))
        if chosen.any():
            assert float(g["ti_unit_mean"].values[k]) == pytest.approx(
                100 * corrected[chosen].mean(), rel=1e-4)       # written with 5 digits
    assert "is uq campaign's" in (tmp_path / "golden" / "report.md").read_text()


def test_the_scatter_shows_every_record_and_counts_the_intervals_past_its_top():
    # 200 records of TI ~ 0.1 and one at 0.44 measured: every point inside the axes; an
    # interval beyond the 99.5 % quantile of their upper ends runs off the top and the
    # title says so
    import matplotlib.pyplot as plt
    import xarray as xr
    from uq.campaign.figures import plot_scatter
    rng = np.random.default_rng(3)
    reference = 0.1 + 0.02 * rng.random((200, 1))
    measured, corrected = reference * 1.05, reference * 0.98
    measured[0, 0] = 0.44
    high = corrected * 1.3
    high[:1, 0] = 2.0
    ds = xr.Dataset({name: (("time", "height"), value) for name, value in {
        "turbulence_intensity_reference": reference, "turbulence_intensity_measured": measured,
        "turbulence_intensity_corrected": corrected, "turbulence_intensity_corrected_low":
        corrected * 0.8, "turbulence_intensity_corrected_high": high}.items()},
        coords={"height": [80.0]})
    fig = plot_scatter(ds)
    ax = fig.axes[0]
    assert ax.get_ylim()[1] >= 44.0 and ax.get_xlim()[1] >= 12.0
    assert "1 interval runs past the top" in ax.get_title()
    plt.close(fig)


def test_a_first_campaign_runs_the_numpy_motion_model_with_the_same_numbers(
        tmp_path, coarse_tables, monkeypatch):
    """Where numba's cache lacks the motion model's kernels (a first campaign after an
    install, here made so), ``uq campaign`` asks once for their compile elsewhere and
    runs the numpy model: the compiled model's numbers to rounding. Tolerance: the
    motion's bias is a second difference of the model at a phase step of 1e-3
    (adapter.CURVATURE_SCALE), which magnifies the models' last-bit differences
    (~1e-15 of 10 m s-1) by 1e6: 1e-6 of each variable's largest value (measured on
    campaign_buoy: 1.8e-7 for the bias, 1e-10 of the corrected TI)."""
    from uq.campaign import adapter
    from uq.compileguard import KernelNotCached
    path = write_campaign(tmp_path, lidar_records(count=8, heights=(60,)))
    command.run_campaign(path, tmp_path / "compiled", stream=open("/dev/null", "w"))
    asked, used = [], []
    monkeypatch.setattr(adapter, "motion_kernels_missing",
                        lambda settings: KernelNotCached("uq.physics.fusedmotionkernels.x"))
    real = adapter.scan_speeds

    def scan_speeds(*args):
        used.append(adapter._NUMPY_MOTION[0])
        return real(*args)
    monkeypatch.setattr(adapter, "scan_speeds", scan_speeds)
    command.run_campaign(path, tmp_path / "numpy", stream=open("/dev/null", "w"),
                         kernels_missing=lambda error, settings: asked.append(
                             (str(error), settings[0]["name"])))
    assert asked == [("uq.physics.fusedmotionkernels.x", "campaign_buoy_lidar")]
    assert used and all(used)                       # every scan by the numpy model
    compiled, numpy = (xr.open_dataset(tmp_path / name / "mini.nc") for name in
                       ("compiled", "numpy"))
    for name in compiled.data_vars:
        values = compiled[name].values
        if values.dtype.kind == "f" and np.isfinite(values).any():
            gap = np.nanmax(np.abs(numpy[name].values - values))
            assert gap <= 1e-6 * np.nanmax(np.abs(values)) + 1e-12, (name, gap)
        else:
            np.testing.assert_array_equal(numpy[name].values, values, err_msg=name)
    assert not adapter._NUMPY_MOTION[0]             # left as it was


def test_the_motion_kernels_missing_from_a_new_cache_are_named_and_not_compiled(tmp_path):
    import os
    import subprocess
    import sys
    from tests.conftest import child_failure, cpu_limited
    code = ("from uq.campaign import adapter\n"
            "from uq.pipeline.scenario import load_scenario\n"
            f"lidar = load_scenario({str(LIDAR)!r}).settings\n"
            "settings = adapter.gate_settings(lidar, [60.0], {'model': 'mann', "
            "'anisotropy': 3.9, 'length_scale': 42.0}, 600.0)\n"
            "print(adapter.motion_kernels_missing(settings))\n")
    env = {**os.environ, "NUMBA_CACHE_DIR": str(tmp_path / "numba"),
           "PYTHONPATH": str(LIDAR.parents[1])}
    done = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True,
                          text=True, preexec_fn=cpu_limited())
    assert done.returncode == 0, child_failure(done)
    assert done.stdout.strip().startswith("uq.physics.fused")
    assert not list((tmp_path / "numba").rglob("*.nbi"))
