"""uq bench: the time-to-target rule on a hand-made result, and a tiny real run."""
import numpy as np
import pytest
import xarray as xr

from uq.bench import methods as bench


def synthetic(errors, times):
    """One scene, two methods, three sizes, four repeats."""
    return xr.Dataset({"relative_error": (("scene", "method", "n", "repeat"), errors),
                       "time_s": (("scene", "method", "n", "repeat"), times)},
                      coords={"scene": ["s"], "method": ["mc", "x"], "n": [1, 4, 16],
                              "repeat": range(4)})


def test_time_to_target_picks_the_first_size_and_extrapolates_otherwise():
    errors = np.zeros((1, 2, 3, 4))
    errors[0, 0] = [[8e-3] * 4, [4e-3] * 4, [2e-3] * 4]         # mc: never <= 1e-3
    errors[0, 1] = [[5e-3] * 4, [5e-4] * 4, [1e-4] * 4]         # x: reached at n = 4
    times = np.broadcast_to(np.array([1.0, 2.0, 4.0])[None, None, :, None], (1, 2, 3, 4))
    rows = bench.time_to_target(synthetic(errors, np.array(times)))
    assert rows["s", "x"] == (2.0, False)
    # error 2e-3 at the largest n, falling as n^-1/2: 4x the samples, so 4x the time
    assert rows["s", "mc"] == (16.0, True)


def test_quantile_not_median_decides():
    errors = np.full((1, 2, 3, 4), 1e-4)
    errors[0, 1, 0, 3] = 5e-3                  # one bad run in four at the smallest n
    rows = bench.time_to_target(synthetic(errors, np.ones((1, 2, 3, 4))))
    assert rows["s", "x"] == (1.0, False) and rows["s", "mc"] == (1.0, False)
    errors[0, 1, 0, :2] = 5e-3                 # half the runs bad: the next size
    times = np.broadcast_to(np.array([1.0, 2.0, 4.0])[None, None, :, None], (1, 2, 3, 4))
    assert bench.time_to_target(synthetic(errors, np.array(times)))["s", "x"] == (2.0, False)


def test_measure_gives_errors_against_the_reference(monkeypatch):
    monkeypatch.setattr(bench, "REFERENCE_SAMPLES", 2**17)
    monkeypatch.setattr(bench, "SCENES", {"rubio2022_case_i": bench.SCENES["rubio2022_case_i"]})
    result = bench.measure([2**12], repeats=2)
    assert dict(result.sizes) == {"scene": 1, "method": 5, "n": 1, "repeat": 2}
    # plain mc at 4096 trials: relative error of u ~ 1/sqrt(2 n) = 1.1 %; 10 % is > 8 sigma
    assert np.all(result["relative_error"] < 0.1) and np.all(result["time_s"] > 0)
    assert float(result["reference_relative_error"].max()) < 1e-3


def test_bench_file_passes_the_cf_checker(monkeypatch, tmp_path, cf_compliance):
    """Issue 16: bench.nc (here from a tiny run: one scene, 2^10 and 2^11 trials, two
    repeats) has valid attribute names (letters, digits, underscores: no '+cv' or
    '1e-3'), the time to target as variables, and passes compliance-checker CF 1.10."""
    import json
    import re

    from uq.bench.command import run_bench
    monkeypatch.setattr(bench, "REFERENCE_SAMPLES", 2**14)
    monkeypatch.setattr(bench, "SCENES", {"rubio2022_case_i": bench.SCENES["rubio2022_case_i"]})
    path = tmp_path / "bench.nc"
    (tmp_path / "bench.txt").write_text("not uq's")          # beside the outputs
    run_bench(path, quick=True, sizes=[2**10, 2**11], repeats=2, scale=2**-12)
    assert (tmp_path / "bench.txt").read_text() == "not uq's"
    cf_compliance(path)
    document = json.loads(path.with_suffix(".json").read_text())
    assert {"floating_lidar_full_mc_over_draw_floor", "pointwise_motion_over_static",
            "rubio2022_case_i_best_speedup"} <= set(document["targets"])
    assert document["machine_details"]["processor"] and document["command"] == "uq bench --quick"
    assert len(document["load_averages"]["start"]) == 3
    assert len(document["time_to_target"]) == 5                    # one scene, 5 methods
    run_bench(path, quick=True, sizes=[2**10, 2**11], repeats=2, scale=2**-12)  # replaced
    with xr.open_dataset(path) as ds:
        assert all(re.fullmatch(r"[A-Za-z][A-Za-z0-9_]*", name) for name in ds.attrs), \
            list(ds.attrs)
        assert "rubio2022_case_i_sobol_cv_time_to_1e_3_s" in ds.attrs
        assert ds["time_to_target"].sizes == {"scene": 1, "method": 5}
        assert ds["time_to_target_extrapolated"].dtype == bool
        assert ds.attrs["bench_command"] == "uq bench --quick" and "cores" in ds.attrs["machine"]


def test_the_numpy_scans_and_uq_measure_the_same_u():
    """The benchmark's two implementations of 4-beam scans with radial noise u = 0.1 m/s
    compute the same thing: u(Vh) = u / (sqrt(2) sin 28 deg) for a 10 m/s wind along a
    beam pair (first order; the cross-pair term adds (u/(2 sin))^2/(2 U) ~ 1e-3 of it).
    Tolerance: 4 sigma of a standard deviation from n draws, 4 / sqrt(2 n)."""
    from uq.bench import targets
    n = 2**16
    expected = 0.1 / (np.sqrt(2) * np.sin(np.deg2rad(28.0)))
    tolerance = 4 / np.sqrt(2 * n) + 2e-3          # sampling + the first-order neglect
    assert targets.numpy_scans(n) == pytest.approx(expected, rel=tolerance)
    result = targets.run(targets._scans(n, **{"wind.speed": 10.0, "wind.direction": 0.0}))
    assert float(result["wind_speed_mc_u"]) == pytest.approx(expected, rel=tolerance)


def test_the_draw_floor_replays_every_block_the_engine_draws():
    """A run of n trials of d scalar inputs draws n x d normals: the recorded blocks hold
    exactly that many (exact count: the floor replays neither more nor fewer)."""
    from uq.bench import targets
    from uq.engine.inputs import input_set
    from uq.pipeline.modelsetup import error_inputs, scene_from_settings
    scenario = targets._scans(3000)
    scene = scene_from_settings(scenario.settings)
    dimension = input_set(error_inputs(scenario.settings, scene.n_beams,
                                       len(scene.ranges))).dimension
    with targets.recorded_draws() as shapes:
        targets.run(scenario)
    assert sum(rows * columns for rows, columns in shapes) == 3000 * dimension
    assert targets.draw_floor(shapes, repeats=1) > 0


def test_the_scale_run_reports_its_own_peak_memory_not_its_parents():
    """Linux keeps ru_maxrss across fork and exec: a child of a 640 MB parent would report
    640 MB. The scale run reads its own high-water mark (VmHWM), so a 2000-trial run
    under such a parent reports what uq itself needs (~270 MB: Python and the
    libraries), well below the parent."""
    import sys
    if not sys.platform.startswith("linux"):
        pytest.skip("VmHWM is Linux's; elsewhere the scale run falls back to ru_maxrss")
    parent = np.ones(80_000_000)                       # 640 MB, touched
    _, megabytes = bench.scale(2000)
    assert parent[-1] == 1.0 and megabytes < 500, megabytes


def test_the_nacelle_figure_compares_like_with_like(caplog):
    """``nacelle_scans``: the nacelle lidar and the DBS of each pair differ in the mount
    alone (same beams' count for 4, the 4-beam DBS for 2), and both run the compiled
    models (no fall-back to numpy said at INFO, apart from the GUM's complex step)."""
    import logging
    from uq.bench import targets
    from uq.physics import modelinputs
    modelinputs._LOGGED.clear()
    with caplog.at_level(logging.INFO, logger="uq.physics.modelinputs"):
        times = targets.nacelle_scans(2**10, repeats=1)
    assert set(times) == {(4, "static"), (4, "motion"), (4, "motion_none"), (2, "static"),
                          (2, "motion")}
    assert all(nacelle > 0 and dbs > 0 and ratio > 0 for nacelle, dbs, ratio in times.values())
    declined = [r.getMessage() for r in caplog.records if "does not take" in r.getMessage()]
    assert declined and all("complex" in message for message in declined)


def test_the_nacelle_models_alone_run_compiled(caplog):
    """``nacelle_models``: the measurement model alone of the nacelle lidar and of the DBS,
    static and in motion, each the compiled one (no fall-back said at INFO)."""
    import logging
    from uq.bench import targets
    from uq.physics import modelinputs
    modelinputs._LOGGED.clear()
    with caplog.at_level(logging.INFO, logger="uq.physics.modelinputs"):
        times = targets.nacelle_models(2**10, repeats=1)
    assert set(times) == {"static", "motion", "motion_none"}
    assert all(nacelle > 0 and dbs > 0 and ratio > 0 for nacelle, dbs, ratio in times.values())
    assert not [r for r in caplog.records if "does not take" in r.getMessage()]


def test_paired_times_alternate_and_keep_each_side(monkeypatch):
    """``paired_cpu_times``: the calls alternate ABBA after one warm call of each, and each
    pair's times go back to their own side before the ratio (a clock that advances by a
    function's cost: 2 for the first, 1 for the second, gives 2, 1 and 2 exactly)."""
    from uq.bench import targets
    clock, order = [0.0], []

    def costing(name, cost):
        def function():
            order.append(name)
            clock[0] += cost
        return function
    monkeypatch.setattr(targets.time, "process_time", lambda: clock[0])
    result = targets.paired_cpu_times(costing("a", 2.0), costing("b", 1.0), 4)
    assert result == (2.0, 1.0, 2.0)
    assert "".join(order) == "ab" + "abba" * 2


def test_the_json_document_gives_each_figure_its_target_and_verdict():
    from uq.bench import report
    document = report.document({"pointwise_motion_over_static": 3.5,
                                "rubio2022_case_i_best_speedup": 12.0, "other_s": 1.0,
                                "first_run_worst_name": "x"},
                               {"pointwise_motion_over_static": (4.0, "max"),
                                "rubio2022_case_i_best_speedup": (20.0, "min")},
                               report.now(), {"start": [0.5, 0.4, 0.3]},
                               [("s", "mc", 1.5, True)])
    targets = document["targets"]
    assert targets["pointwise_motion_over_static"]["met"] is True
    assert targets["rubio2022_case_i_best_speedup"]["met"] is False
    assert targets["pointwise_motion_over_static"]["units"] == "1"
    assert document["figures"]["other_s"] == 1.0 and "other_s" not in targets
    assert document["notes"] == {"first_run_worst_name": "x"}
    assert document["time_to_target"] == [["s", "mc", 1.5, True]]
    assert document["machine_details"]["usable_cores"] >= 1
    assert document["load_average"] == "start 0.50, 0.40, 0.30"
    assert "usable cores" in document["machine"]


def test_every_target_is_described():
    from uq.bench import report, targets
    assert set(targets.TARGETS) <= set(report.DESCRIPTIONS)


def test_the_record_count_of_the_shipped_record_scenarios():
    """record.count per scene with wind, over the sweep's scenes (floating_lidar_ti: six
    intensities, two corrections, five records each)."""
    from uq.bench import records
    from uq.pipeline.scenario import load_scenario
    from uq.pipeline.shipped import scenario_path
    counts = {name: records.record_count(load_scenario(scenario_path(name)))
              for name in records.SCENARIOS}
    assert counts == {"sathe2011_ti": 8, "sathe2011_ti_cw": 4, "floating_lidar_ti": 60}
    # a sweep of two wind speeds: each scene its records (a calm scene, wind.speed 0, is
    # refused at validation: a frozen field needs a mean wind)
    two = load_scenario(scenario_path("sathe2011_ti"), {"sweep.wind.speed": [6.0, 8.0]})
    assert records.record_count(two) == 16


def test_the_first_run_figures_name_the_worst(monkeypatch):
    from uq.bench import firstrun
    rows = {"a": 1.5, "b": 4.0}
    monkeypatch.setattr(firstrun, "first_run", lambda name: {
        "cold_s": 2.0 + rows[name], "warm_s": 2.0, "over_warm_s": rows[name],
        "cold_load": 0.1, "background_after_s": 9.0, "background_after_warm_s": 0.0,
        "warm_compiled": True,
        "largest_difference": 1e-15})
    figures = firstrun.measure(["a", "b"])
    assert figures["first_run_worst_over_warm_s"] == 4.0
    assert figures["first_run_worst_name"] == "b"
    assert figures["first_run_a_warm_compiled"] == 1
    assert figures["first_run_a_pairs"] == figures["first_run_b_pairs"] == 1   # short runs


def test_a_long_first_run_is_the_median_of_its_pairs(monkeypatch):
    """A scenario whose warm run takes REPEATED_RUN_S or more is measured in
    PAIRS_OF_LONG_RUNS pairs and reported as the median difference, the spread beside it;
    whether it is repeated depends on its length, not on the difference (a short run
    over the target is measured once)."""
    from uq.bench import firstrun
    long_run = firstrun.REPEATED_RUN_S + 10.0
    script = {"long": iter([(long_run + 9.0, long_run), (long_run + 1.0, long_run + 2.0),
                            (long_run + 3.0, long_run)]),
              "short": iter([(8.0, 1.0)])}
    calls = []

    def fake(name):
        calls.append(name)
        cold, warm = next(script[name])
        return {"cold_s": cold, "warm_s": warm, "over_warm_s": cold - warm,
                "cold_load": 0.1, "background_after_s": 9.0,
                "background_after_warm_s": 0.0, "warm_compiled": name == "short",
                "largest_difference": {"long": 2e-15, "short": 1e-15}[name]}
    monkeypatch.setattr(firstrun, "first_run", fake)
    figures = firstrun.measure(["long", "short"])
    assert calls == ["long"] * firstrun.PAIRS_OF_LONG_RUNS + ["short"]
    assert firstrun.PAIRS_OF_LONG_RUNS == 3          # the script above has three pairs
    assert figures["first_run_long_pairs"] == 3
    assert figures["first_run_long_over_warm_s"] == 3.0        # median of 9, -1, 3
    assert (figures["first_run_long_over_warm_min_s"],
            figures["first_run_long_over_warm_max_s"]) == (-1.0, 9.0)
    assert figures["warm_run_long_s"] == long_run               # median of the warm runs
    assert figures["first_run_long_warm_compiled"] == 0          # not every warm run
    assert figures["first_run_long_largest_difference"] == 2e-15
    assert figures["first_run_short_pairs"] == 1
    assert figures["first_run_worst_name"] == "short"           # 7 s over, one pair
    assert figures["first_run_worst_over_warm_s"] == 7.0


def test_scale_out_is_bit_identical_to_one_process():
    """The scale-out benchmark's small sweep on a local cluster of 2 workers: the same
    bytes as in one process (the efficiency on a shared 2-core machine is not a test)."""
    from uq.bench import scaleout
    figures = scaleout.measure(workers=(2,), small=True, names=("rubio2022_misalignment",))
    row = figures["workloads"]["rubio2022_misalignment"]["workers"]["2"]
    assert row["identical"] is True and row["seconds"] > 0
    assert figures["machine"]["usable_cores"] >= 1


def test_a_child_s_peak_is_its_own_not_its_parents():
    """child_usage (the cold-start figures) reads the child's own high-water mark: under
    a 640 MB parent, ``uq list`` reports what it needs itself (~100 MB), not the parent."""
    import sys
    from uq.bench import targets
    if not sys.platform.startswith("linux"):
        pytest.skip("VmHWM is Linux's")
    parent = np.ones(80_000_000)                       # 640 MB, touched
    cpu, megabytes = targets.child_usage(["list"])
    assert parent[-1] == 1.0 and 0 < megabytes < 500 and cpu > 0, megabytes


def test_every_shipped_file_is_timed_with_the_command_that_runs_it(tmp_path):
    """A golden or campaign configuration is not a scenario: `uq run` refuses it (the
    full bench stopped at the shipped campaign). Each shipped file's command is the one
    its top-level section names, and that command validates it (`uq check` reads all
    three kinds)."""
    from uq.bench.targets import _command
    from uq.cli import main
    from uq.pipeline.shipped import shipped_names
    kinds = {name: _command(name, str(tmp_path))[0] for name in shipped_names()}
    assert kinds["golden_campaign"] == "golden" and kinds["campaign_buoy"] == "campaign"
    assert kinds["rubio2022_case_i"] == "run"
    assert set(kinds.values()) == {"run", "golden", "campaign"}
    for name, kind in kinds.items():
        if kind != "run":
            assert main(["check", name, "-q"]) == 0, name


def test_the_worst_end_to_end_ratio_leaves_out_the_files_that_work_on_records():
    """Record mode, campaigns and golden campaigns are the files whose time is their
    records' (their normals are a few of their random numbers): left out of the worst
    ratio to the draws, named; the worst is that of the files of Monte Carlo trials."""
    from uq.bench.targets import shipped_worst, works_on_records
    from uq.pipeline.shipped import shipped_folder
    names = sorted(p.stem for p in shipped_folder().glob("*.yaml"))
    on_records = [name for name in names if works_on_records(name)]
    assert on_records == ["campaign_buoy", "floating_lidar_ti", "golden_campaign",
                          "sathe2011_ti", "sathe2011_ti_cw"]
    figures = {f"shipped_{name}_over_floor_and_start": 1.0 + i for i, name in
               enumerate(names)}
    worst = shipped_worst(figures, names)
    trials = [name for name in names if name not in on_records]
    assert worst["shipped_worst_name"] == trials[-1]
    assert worst["shipped_worst_over_floor_and_start"] == 1.0 + names.index(trials[-1])
    assert worst["shipped_on_records"] == ", ".join(on_records)
