"""Record mode through uq.run: the spectral path's turbulence intensities."""
import math

import numpy as np
import pytest

from uq.pipeline.runner import run

WIND = {"speed": 10.0, "direction": 180.0, "reference_height": 100.0}


def scenario(lidar, **extra):
    return {"wind": WIND, "lidar": {"scan": {"beam_duration": 1e-3}, **lidar},
            "turbulence": {"intensity": 0.1}, "sampling": {"method": "none"},
            "outputs": ["turbulence_intensity"], **extra}


def test_absent_turbulence_adds_nothing():
    ds = run({"sampling": {"method": "none"}, "outputs": ["wind_speed"]})
    assert not [name for name in ds.data_vars if name.startswith("turbulence_")]


def test_a_lidar_shrunk_to_a_point_sees_the_true_variance():
    # gates 0.1 m from the lidar at the reference height, point probe, beams 1 ms apart:
    # the beams sample the reference point. The difference from 1 is the structure
    # function of w across the opposite beams' separation r = 0.115 m, amplified by the
    # DBS's cot(theta)^2 / 4 = 0.75: about 0.75 (r / L)^(2/3) = 0.017 of the variance (L =
    # 33.6 m); 0.03 bounds it.
    ds = run(scenario({"height": 99.9, "ranges": [0.1], "half_cone": 30.0,
                       "vertical_beam": True}))
    assert float(ds["turbulence_intensity_u_ratio"]) == pytest.approx(1.0, abs=0.03)
    ratio = (ds["turbulence_intensity_spectral"] / ds["turbulence_intensity_true"]) ** 2
    assert float(ratio) == pytest.approx(float(ds["turbulence_intensity_u_ratio"]), rel=1e-12)
    for name in ("turbulence_intensity_true", "turbulence_intensity_spectral"):
        assert ds[name].attrs["units"] == "1" and ds[name].attrs["long_name"]


def test_probe_volume_lowers_the_apparent_variance():
    # Sathe et al. (2011), as issue 24 cites them: a lidar sees 5-45 % less u-variance
    # than a point; the point-probe DBS is above 1 (w leaks into u through cot(theta))
    point = run(scenario({"height": 0.0, "ranges": [100.0], "half_cone": 30.0,
                          "vertical_beam": True}))
    pulsed = run(scenario({"height": 0.0, "ranges": [100.0], "half_cone": 30.0,
                           "vertical_beam": True, "probe": {
                               "kind": "pulsed", "gate_length": 18.75, "pulse_fwhm": 24.75}}))
    assert 0.55 < float(pulsed["turbulence_intensity_u_ratio"]) < 0.95
    assert float(pulsed["turbulence_intensity_u_ratio"]) < \
        float(point["turbulence_intensity_u_ratio"])


def test_scan_errors_add_in_quadrature():
    # radial noise sigma_r on a 4-beam DBS with the wind along a beam pair: u_x =
    # (v_1 - v_3) / (2 sin theta) has variance sigma_r^2 / (2 sin^2 theta), which is the
    # variance of Vh (linear: the GUM of method none is exact here); it adds to the
    # filtered turbulence's variance, independent scan by scan
    sigma_r, cone = 0.2, 30.0
    ds = run(scenario({"height": 0.0, "ranges": [100.0], "half_cone": cone, "errors": {
        "radial_velocity": {"dist": "normal", "u": sigma_r}}},
        outputs=["wind_speed", "turbulence_intensity"]))
    noise = sigma_r ** 2 / (2 * math.sin(math.radians(cone)) ** 2) / WIND["speed"] ** 2
    expected = np.sqrt(ds["turbulence_intensity_spectral_turbulence"] ** 2 + noise)
    np.testing.assert_allclose(ds["turbulence_intensity_spectral"], expected, rtol=1e-12)


def surge_scenario(correction, phase):
    # a nearly still atmosphere (I = 1e-4: u-variance 1e-6 m2 s-2 against the surge's
    # 0.1) with a long length scale (a coarse, cheap box); a level 4-beam DBS, the wind
    # from the south along the beams at azimuths 0 and 180 (the bow, heading 0)
    return {"wind": {"speed": 10.0, "direction": 180.0, "reference_height": 100.0},
            "lidar": {"height": 0.0, "ranges": [100.0], "half_cone": 30.0,
                      "scan": {"beam_duration": 1.0}},
            "motion": {"surge": {"amplitude": 0.5, "period": 7.0, "phase": phase}},
            "correction": correction,
            "turbulence": {"intensity": 1e-4, "length_scale": 400.0},
            "record": {"duration": 600, "count": 2},
            "sampling": {"n": 64, "seed": 5}, "outputs": ["wind_speed", "turbulence_intensity"]}


def test_harmonic_surge_advances_coherently_from_scan_to_scan():
    # The DBS u = (v_1 - v_3) / (2 sin theta) of a surge a sin(w t + phi) uncorrected
    # errs by the platform velocity seen by beams 1 and 3, 2 s apart: record variance
    # (a w cos(w dt / 2))^2 / 2 (lidarspectral Eq. 7, derived there) for a long record.
    # A fixed phase gives it only if the phase advances by w T_s from scan to scan (the
    # same phase in every scan would give 0). 150 scans: the record's own mean removes
    # |D_N|^2 < 1e-3 of it; s^2 with ddof 1 is N / (N - 1) = 1.0067 times the 1/N one;
    # 2 % covers both and the turbulence's 1e-5.
    from uq.physics.lidarspectral import dbs_surge_variance
    ds = run(surge_scenario("none", 0.0))
    variance = float(ds["turbulence_intensity_mc_mean"]) ** 2 * 10.0 ** 2
    assert variance == pytest.approx(dbs_surge_variance(0.5, 7.0, 2.0), rel=0.02)
    # the same at a random phase per record; the correction removes the surge
    random = run(surge_scenario("none", "random"))
    assert float(random["turbulence_intensity_mc_mean"]) == pytest.approx(
        float(ds["turbulence_intensity_mc_mean"]), rel=0.02)
    corrected = run(surge_scenario("pointwise", 0.0))
    assert float(corrected["turbulence_intensity_mc_mean"]) < 0.01 * float(
        ds["turbulence_intensity_mc_mean"])


def test_spectral_and_monte_carlo_agree_on_a_fixed_dbs():
    # a fixed 5-beam DBS with a pulsed probe, Mann field; 12 records of 60 s. The
    # spectral TI^2 against the records' mean TI^2: within 3 standard errors of that
    # mean plus what the box leaves out of the variance (1 - box_kept, a bound on the
    # box's deficit: it removes that share of the point variance, less of the lidar's,
    # which filters the small scales the box also misses)
    ds = run({"wind": {"speed": 10.0, "direction": 180.0, "reference_height": 100.0},
              "lidar": {"height": 0.0, "ranges": [100.0], "half_cone": 30.0,
                        "vertical_beam": True, "scan": {"beam_duration": 0.5},
                        "probe": {"kind": "pulsed", "gate_length": 18.75,
                                  "pulse_fwhm": 24.75}},
              "turbulence": {"intensity": 0.1}, "record": {"duration": 60, "count": 12},
              "sampling": {"n": 64, "seed": 11}, "outputs": ["turbulence_intensity"]})
    spectral = float(ds["turbulence_intensity_spectral"]) ** 2
    z = float(ds["turbulence_intensity_spectral_z"])
    deficit = (1 - float(ds["turbulence_intensity_box_kept"])) * spectral
    # the standard error of the records' mean TI^2 by the delta method, 2 TI u(TI) / sqrt(n)
    standard_error = 2 * float(ds["turbulence_intensity_mc_mean"] * ds[
        "turbulence_intensity_mc_u"]) / np.sqrt(12)
    assert abs(z) <= 3 + deficit / standard_error
    assert float(ds["turbulence_intensity_mc_low"]) < float(ds["turbulence_intensity_mc_mean"]) \
        < float(ds["turbulence_intensity_mc_high"])
    assert ds["wind_speed_record_u"].attrs["units"] == "m s-1"


def test_sweeps_of_scene_values_and_of_the_intensity():
    # the spectral variance is alpha eps^(2/3) times the filter's integral, and alpha
    # eps^(2/3) goes as the intensity squared: the TIs scale with the intensity exactly;
    # a swept direction (a scene value: the scenes of one chunk) gives each scene its
    # own geometry: the wind along a beam pair (0) and between the pairs (45) differ
    ds = run(scenario({"height": 0.0, "ranges": [100.0], "half_cone": 30.0},
                      sweep={"turbulence.intensity": [0.05, 0.1],
                             "wind.direction": [0.0, 45.0, 90.0]}))
    ti = ds["turbulence_intensity_spectral"]
    assert ti.dims == ("turbulence_intensity", "wind_direction")
    np.testing.assert_allclose(ti.isel(turbulence_intensity=0), ti.isel(
        turbulence_intensity=1) / 2, rtol=1e-12)
    np.testing.assert_allclose(ti.sel(wind_direction=0.0), ti.sel(wind_direction=90.0),
                               rtol=1e-6)          # the 4-beam DBS's symmetry
    assert abs(float(ti.isel(turbulence_intensity=1).sel(wind_direction=45.0)
                     / ti.isel(turbulence_intensity=1).sel(wind_direction=0.0)) - 1) > 1e-3


# --- unit records and the records' spectra (issue 26) ----------------------------------------

SMALL = {"wind": {"speed": 10.0, "direction": 180.0, "reference_height": 100.0},
         "lidar": {"height": 0.0, "ranges": [60.0, 100.0], "half_cone": 30.0,
                   "scan": {"beam_duration": 0.5},
                   "errors": {"radial_velocity": {"dist": "normal", "u": 0.05}}},
         "turbulence": {"intensity": 0.1}, "record": {"duration": 30, "count": 3},
         "sampling": {"n": 64, "seed": 7}, "outputs": ["wind_speed"]}


def _record(settings, record=0, spectra=False):
    from uq.pipeline import records
    from uq.pipeline.turbulencesection import scan_geometry, scans_per_record
    geometry = scan_geometry(settings)
    return records.monte_carlo_record(settings, geometry, scans_per_record(settings),
                                      records.record_generator(7, record), True,
                                      records.rest_generator(7, record) if spectra else None)


def test_a_reused_unit_record_is_the_one_drawn_again():
    # the same record from an empty cache and from the cache (the second call reuses the
    # first's box): identical bits, and the generator left where the box's draw leaves
    # it (the scan errors drawn after the box are the same)
    from uq.pipeline import records
    from uq.pipeline.scenario import load_scenario
    settings = load_scenario(SMALL).settings
    records._UNIT_RECORDS.clear()
    fresh = _record(settings)
    assert len(records._UNIT_RECORDS) == 1
    again = _record(settings)
    records._UNIT_RECORDS.clear()
    drawn = _record(settings)
    for name in ("speed", "lateral", "vertical", "reference", "kept"):
        one, two, three = (getattr(r, name) for r in (fresh, again, drawn))
        np.testing.assert_array_equal(one, two)
        np.testing.assert_array_equal(one, three)


def test_a_record_sampled_part_by_part_is_its_whole_box_sampled(monkeypatch):
    # the record's box in 3 parts of its half spectra (RECORD_SPECTRA_BYTES lowered), each
    # part's field sampled and the samples summed: the whole window box sampled, to the
    # rounding of a sum of 3 parts (1e-13 of the largest value: ~1e-16 per operation,
    # a margin of ~100), with the moving beams' (at rest) and the reference's samples
    from uq.pipeline import records
    from uq.pipeline.scenario import load_scenario
    from uq.pipeline.turbulencesection import scan_geometry, scans_per_record
    from uq.physics import turbulencesampling as ts
    from uq.physics.turbulencebox import box_for
    settings = load_scenario(SMALL).settings
    geometry, n_scans = scan_geometry(settings), scans_per_record(settings)
    grid = box_for(geometry, settings["turbulence"]["length_scale"], "mann")
    half_spectra = 3 * grid.shape[0] * grid.shape[1] * (grid.shape[2] // 2 + 1) * 16
    monkeypatch.setattr(records, "RECORD_SPECTRA_BYTES", half_spectra // 3 + 1)
    parts, _ = records.unit_box_parts(settings, geometry, records.record_generator(7, 0))
    assert len(list(parts)) == 3
    rng = records.record_generator(7, 0)
    drawn = records._draw_unit_record(settings, geometry, n_scans, rng, {}, 0.0, True)
    again = records.record_generator(7, 0)
    box, kept = records.unit_box(settings, geometry, again)
    # the reference: the box's line, and the scales below its cells drawn after the box
    drawn_beside = records.reference_complement(settings, geometry, grid)
    complement = again.standard_normal((n_scans, 3)) @ drawn_beside.factor.T
    # then the scales below the cells at each beam and gate, the same at rest
    beams = again.standard_normal((n_scans, geometry.n_beams, geometry.n_gates)) \
        * records.beam_complement(settings, geometry, grid)
    # then the band of eddies larger than the box: one trend, at the reference point and
    # along each beam's nominal direction
    trend = np.outer(records.band_trend(n_scans), drawn_beside.band @ again.standard_normal(3))
    beams = beams + (trend @ np.asarray(geometry.directions).T)[:, :, None]
    whole = (ts.record_radial_velocities(box, geometry, n_scans) + beams,
             ts.reference_line_series(box, geometry.speed, ts.scan_times(geometry, n_scans))
             + complement + trend)
    for part_sum, sampled in zip((drawn.radial, drawn.reference, drawn.at_rest),
                                 whole + whole[:1]):
        assert np.max(np.abs(part_sum - sampled)) <= 1e-13 * np.max(np.abs(sampled))
    assert drawn.kept == kept
    assert drawn.state == again.bit_generator.state        # where one draw leaves it


def test_a_chunk_draws_its_boxes_before_its_scans_and_each_once(monkeypatch):
    # draw_first_records draws the first scene's records before the per-scan Monte Carlo
    # (so that its kernels compile after the boxes: memory), and the records' loop then
    # reuses them: each of the 3 records' boxes is drawn once for the sweep's 2 scenes
    from uq.pipeline import records, runner
    drawn, seen = [], []
    draw, scans = records._draw_unit_record, runner.run_scene
    monkeypatch.setattr(records, "_draw_unit_record",
                        lambda *a, **k: drawn.append(1) or draw(*a, **k))
    monkeypatch.setattr(runner, "run_scene",
                        lambda *a, **k: seen.append(len(drawn)) or scans(*a, **k))
    records._UNIT_RECORDS.clear()
    run({**SMALL, "sweep": {"turbulence.intensity": [0.05, 0.1]}})
    records._UNIT_RECORDS.clear()
    assert seen and set(seen) == {3} and len(drawn) == 3      # (a chunk per scene or one)


def test_the_field_scales_with_the_intensity():
    # Mann's field is linear in sqrt(alpha eps^(2/3)), which goes as the intensity: a
    # record at twice the intensity (the same unit box, reused) has twice the field's u'
    # at the reference point, to rounding (1e-12 relative of u': float64 products)
    from uq.pipeline import records
    from uq.pipeline.scenario import load_scenario
    low = load_scenario(SMALL).settings
    high = load_scenario({**SMALL, "turbulence": {"intensity": 0.2}}).settings
    assert records.field_scale(high) == pytest.approx(2 * records.field_scale(low), rel=1e-14)
    one, two = _record(low), _record(high)
    np.testing.assert_allclose(two.reference - [10.0, 0, 0], 2 * (one.reference - [10.0, 0, 0]),
                               rtol=1e-12, atol=0)
    assert two.kept == pytest.approx(one.kept, rel=1e-14)      # the box keeps the same share


def test_same_results_from_an_empty_and_a_warm_cache_and_any_chunking():
    # a sweep of the intensity and of the correction reuses each record's box across its
    # scenes; the run from an empty cache, again from the warm one, and its scenes run
    # one by one give the same numbers bit for bit
    from uq.pipeline import records
    sweep = {**SMALL, "sweep": {"turbulence.intensity": [0.05, 0.1],
                                "correction": ["none", "full"]}}
    records._UNIT_RECORDS.clear()
    cold = run(sweep)
    warm = run(sweep)
    records._UNIT_RECORDS.clear()
    alone = run({**SMALL, "turbulence": {"intensity": 0.1}, "correction": "none"})
    for name in ("turbulence_intensity_mc_mean", "wind_speed_record_bias",
                 "record_psd_wind_speed", "record_psd_u_true"):
        np.testing.assert_array_equal(cold[name].values, warm[name].values)
        np.testing.assert_array_equal(
            cold[name].sel(turbulence_intensity=0.1, correction="none").values,
            alone[name].values)


def test_stored_spectra_hold_the_records_variance():
    # Parseval: the one-sided periodogram summed over its frequencies (df = 1 / (N T_s))
    # is the record's variance about its mean (1/N), so the stored mean spectrum sums to
    # the mean over the records of that variance (float64 sums: 1e-12)
    from uq.pipeline import records
    from uq.pipeline.scenario import load_scenario
    ds = run(SMALL)
    frequency = ds["record_frequency"]
    assert frequency.attrs["units"] == "Hz"
    for name in ("record_psd_u_true", "record_psd_wind_speed", "record_psd_radial_velocity"):
        assert ds[name].attrs["units"] == "m2 s-2 Hz-1" and ds[name].attrs["long_name"]
        assert "record_frequency" in ds[name].dims
    assert "record_psd_wind_speed_at_rest" not in ds            # no motion
    settings = load_scenario(SMALL).settings
    series = [_record(settings, r) for r in range(3)]
    step = float(frequency[1] - frequency[0])
    expected = np.mean([r.speed.var(axis=0) for r in series], axis=0)
    np.testing.assert_allclose(ds["record_psd_wind_speed"].sum("record_frequency") * step,
                               expected, rtol=1e-12)
    expected = np.mean([r.reference[:, 0].var() for r in series])
    assert float(ds["record_psd_u_true"].sum() * step) == pytest.approx(expected, rel=1e-12)
    assert records.spectrum_axis(settings) == (2.0, 15)


def test_scenes_differing_only_outside_the_spectral_path_share_its_computation(monkeypatch):
    from uq.pipeline import records
    from uq.pipeline.scenario import load_scenario
    from uq.pipeline.shipped import scenario_path
    base = load_scenario(scenario_path("sathe2011_ti")).settings
    scenes = [base, {**base, "correction": "none"},
              {**base, "wind": {**base["wind"], "direction": 300.0}}]
    computed, original = [], records.spectral_variances
    monkeypatch.setattr(records, "_SPECTRAL_PATHS", type(records._SPECTRAL_PATHS)())
    monkeypatch.setattr(records, "spectral_variances", lambda settings, intensity=None: (
        computed.append(settings), original(settings, intensity))[1])
    paths = records.scene_spectral_paths(scenes, len(base["lidar"]["ranges"]))
    assert [s is base for s in computed] == [True, False] and computed[1] is scenes[2]
    # the shared computation gives the second scene exactly what its own would
    alone = original(scenes[1], 1.0)[0]
    square = base["turbulence"]["intensity"] ** 2
    assert np.array_equal(paths["lidar"][1], alone.lidar * square)
    assert np.array_equal(paths["true"][1], alone.true * square)
    assert np.array_equal(paths["lidar"][0], paths["lidar"][1])


@pytest.mark.parametrize("model", ["mann", "kaimal"])
def test_a_scene_s_spectral_path_scaled_from_another_intensity_equals_its_own(model,
                                                                             monkeypatch):
    # both spectral models are proportional to (I U)^2: scaled and computed agree to
    # rounding (1e-13 relative: a few operations' rounding, far below the paths' use)
    from uq.pipeline import records
    from uq.pipeline.scenario import load_scenario
    from uq.pipeline.shipped import scenario_path
    base = load_scenario(scenario_path("sathe2011_ti"),        # one gate: a cheap path
                         {"turbulence.model": model, "lidar.ranges": [100.0],
                          "sampling.method": "none"}).settings
    other = {**base, "turbulence": {**base["turbulence"], "intensity": 0.17}}
    monkeypatch.setattr(records, "_SPECTRAL_PATHS", type(records._SPECTRAL_PATHS)())
    n_gates = len(base["lidar"]["ranges"])
    paths = records.scene_spectral_paths([base, other], n_gates)
    own = records.spectral_variances(other)[0]
    np.testing.assert_allclose(paths["lidar"][1], own.lidar, rtol=1e-13)
    np.testing.assert_allclose(paths["true"][1], own.true, rtol=1e-13)
    assert not np.allclose(paths["lidar"][0], paths["lidar"][1])   # the intensity matters


def test_the_spectral_path_is_computed_once_for_a_run_s_chunks(monkeypatch):
    from uq.pipeline import records
    from uq.pipeline.scenario import load_scenario
    from uq.pipeline.shipped import scenario_path
    monkeypatch.setattr(records, "_SPECTRAL_PATHS", type(records._SPECTRAL_PATHS)())
    base = load_scenario(scenario_path("sathe2011_ti"), {"lidar.ranges": [100.0]}).settings
    computed, original = [], records.spectral_variances
    monkeypatch.setattr(records, "spectral_variances", lambda settings, intensity=None: (
        computed.append(settings), original(settings, intensity))[1])
    for intensity in (0.05, 0.1):                   # two chunks, one scene each
        other = {**base, "turbulence": {**base["turbulence"], "intensity": intensity}}
        records.scene_spectral_paths([other], 1)
    assert len(computed) == 1


@pytest.mark.parametrize("count", [4, 5, 8, 16, 48])
def test_the_path_to_path_check_fails_at_its_nominal_rate_where_the_paths_agree(count):
    # the check's statistic on records whose mean TI^2 is the spectral one: a record's
    # TI^2 is a sample variance of a correlated series, a scaled chi-square of ~10-100
    # effective degrees of freedom (skewed); 20000 checks of `count` such records each
    # (nu = 20) fail at 5 % +- the skew's ~1.5 % and the binomial's 4 sigma
    # (sqrt(0.05 0.95 / 20000) = 1.5e-3); |z| <= 2 failed 9-15 % of them at 4-8 records
    from uq.pipeline import records
    rng = np.random.default_rng(count)
    squares = rng.chisquare(20, size=(20000, count)) / 20
    z = (1.0 - squares.mean(axis=1)) / (squares.std(axis=1, ddof=1) / np.sqrt(count))
    rate = np.mean(np.abs(z) > records.valid_z(count))
    assert abs(rate - records.VALID_LEVEL) <= 0.015 + 4 * np.sqrt(0.05 * 0.95 / 20000)
    if count <= 8:
        assert np.mean(np.abs(z) > 2.0) > 0.08          # the former limit: not nominal


def test_the_records_truth_carries_the_field_s_record_variance():
    # the reference point's series of 32 records of 60 s (a Mann field, L 33.6 m): the
    # mean over the records of its sample variance (u, v, w) against the spectral path's
    # expected sample variance (the record's high-pass, scans of 4 s), within 4 standard
    # errors of the mean; the box alone (its discrete wavenumbers, read trilinearly
    # between nodes) gave 0.78-0.88 of u's
    from uq.pipeline import records
    from uq.pipeline.scenario import load_scenario
    from uq.pipeline.turbulencesection import scan_geometry, scans_per_record
    settings = load_scenario({**SMALL, "record": {"duration": 60, "count": 32}}).settings
    geometry, n_scans = scan_geometry(settings), scans_per_record(settings)
    series = [records.monte_carlo_record(settings, geometry, n_scans,
                                         records.record_generator(11, r)).reference
              for r in range(32)]
    variances = np.array([s.var(axis=0, ddof=1) for s in series])            # (32, 3)
    expected = records.unit_spectral_variances(settings).true \
        * settings["turbulence"]["intensity"] ** 2 * n_scans / (n_scans - 1)
    error = variances.std(axis=0, ddof=1) / np.sqrt(32)
    assert np.all(np.abs(variances.mean(axis=0) - expected) <= 4 * error), (
        variances.mean(axis=0) / expected, error / expected)


def test_a_nacelle_lidar_s_records_agree_with_its_spectral_path():
    # a nacelle lidar (4 beams at 15 deg about a horizontal boresight, 100 m preview,
    # radial noise) in a Mann field, 48 records of 120 s: the check's |z| within 3.3 (a
    # false alarm once in ~500 runs where the paths agree: one seed's check, not its
    # 5 % level, which scripts/record_check.py measured over seeds: z = +0.73, -0.14, +0.36
    # with 96 records), and the spectral TI is not the upward lidar's (the scan geometry
    # of the tilted mount; with it the u-variance ratio is 0.57 over 120 s, 0.62 over
    # 600 s; the upward lidar's with these beams 2.5)
    raw = {"wind": {"speed": 10.0, "direction": 0.0, "reference_height": 150.0},
           "lidar": {"height": 150.0, "ranges": [100.0], "half_cone": 15.0,
                     "azimuths": [0, 90, 180, 270], "mount": {"tilt": 90},
                     "scan": {"beam_duration": 1.0},
                     "errors": {"radial_velocity": {"dist": "normal", "u": 0.1}}},
           "correction": "none", "turbulence": {"intensity": 0.08},
           "record": {"duration": 120, "count": 48}, "sampling": {"n": 2000, "seed": 5},
           "outputs": ["wind_speed"]}
    ds = run(raw)
    assert abs(float(ds["turbulence_intensity_spectral_z"])) <= 3.3
    # the probe volumes and the beams' separation filter u: the tilted lidar's ratio is
    # below 1 (the records above check its value), the upward lidar's geometry is not
    # the nacelle's
    assert 0.0 < float(ds["turbulence_intensity_u_ratio"]) < 1.0
    upward = run({**raw, "lidar": {**raw["lidar"], "mount": {"tilt": 0}},
                  "sampling": {"method": "none"}, "record": {"duration": 120}})
    assert float(upward["turbulence_intensity_u_ratio"]) > 2.0


#: Record-mode variables named turbulence_intensity_* that are not turbulence
#: intensities: the spectral path's ratios and the check's statistics.
NOT_A_TI = ("_ratio", "_ratio_error", "_z", "_valid", "_z_limit", "_check_resolution",
            "_box_kept", "_box_resolved")


def test_each_turbulence_intensity_carries_its_one_name_in_the_file(tmp_path, cf_compliance):
    # a record-mode sweep of the point TI written by `uq run`: every turbulence intensity
    # in the file (the swept point TI, the field's over a record, the records' field TI,
    # the lidar's apparent TIs and their statistics) has a long_name led by one of the
    # report's names and a comment with that name and what it is; the file passes the
    # CF checker
    from uq.cli import main
    from uq.outputs.report import TI_NAMES as REPORT_NAMES
    from uq.pipeline.metadata import TI_NAMES
    from uq.pipeline.shipped import scenario_path
    path = tmp_path / "records.nc"
    assert main(["run", str(scenario_path("sathe2011_ti")), "-o", str(path), "--quiet",
                 "--set", "lidar.ranges=[100.0]", "--set", "sampling.n=256",
                 "--set", "record.duration=60", "--set", "record.count=3",
                 "--set", "sweep={turbulence.intensity: [0.06, 0.1]}"]) == 0
    cf_compliance(path)
    assert REPORT_NAMES == TI_NAMES
    names = {name for name, _ in TI_NAMES.values()}
    import xarray as xr
    with xr.open_dataset(path) as ds:
        intensities = [v for v in ds.variables if v.startswith("turbulence_intensity")
                       and not v.endswith(NOT_A_TI)]
        assert {"turbulence_intensity", "turbulence_intensity_true",
                "turbulence_intensity_true_mc_mean", "turbulence_intensity_spectral",
                "turbulence_intensity_mc_mean"} <= set(intensities)
        used = set()
        for variable in intensities:
            attrs = ds[variable].attrs
            name = next((n for n in names if attrs["long_name"].startswith(n)), None)
            assert name is not None, (variable, attrs["long_name"])
            meaning = dict(TI_NAMES.values())[name]
            assert attrs["comment"] == f"{name}: {meaning}", variable
            used.add(name)
        assert used == names                # each name on the variables it names


def _shipped_record_scenarios():
    from uq.pipeline.shipped import scenario_path, shipped_names
    from uq.pipeline.yamlfile import read_yaml
    out = []
    for name in shipped_names():
        try:
            raw = read_yaml(scenario_path(name))
        except Exception:           # the golden and campaign configurations: not scenarios
            continue
        if isinstance(raw, dict) and "record" in raw and "turbulence" in raw:
            out.append(name)
    return out


@pytest.mark.parametrize("name", _shipped_record_scenarios())
def test_the_records_field_keeps_the_models_variance_where_the_beams_read_it(name):
    # every shipped record scenario: the box, the scales below its cells (drawn at each
    # beam) and the band of eddies larger than the box (a trend) keep the model's
    # u-variance over a record (1 to rounding: the three parts add up to the field's
    # record covariance); the band is a positive share under 2.5 % (0.3-1.9 % of u's
    # at ten minutes, the docstring of reference_complement); the box alone resolves
    # less (the scales below its cells, ~5 % of u's at L / 8), and each beam and gate
    # reads a positive share of those scales
    from uq.pipeline import records
    from uq.pipeline.scenario import load_scenario
    from uq.pipeline.shipped import scenario_path
    from uq.pipeline.turbulencesection import scan_geometry
    settings = load_scenario(scenario_path(name)).settings
    geometry = scan_geometry(settings)
    grid = records.record_grid(settings, geometry)
    complement = records.reference_complement(settings, geometry, grid)
    kept, resolved = complement.kept, complement.resolved
    assert kept == pytest.approx(1.0, abs=1e-9)
    band = complement.band @ complement.band.T
    assert np.all(np.linalg.eigvalsh(band) >= -1e-12 * band[0, 0])
    assert 0.0 < complement.band_share < 0.025
    assert resolved < kept - 0.02
    deviation = records.beam_complement(settings, geometry, grid)
    assert deviation.shape == (geometry.n_beams, geometry.n_gates)
    assert np.all(deviation > 0)


def test_a_kaimal_box_draws_no_beam_complement():
    # Veers' field is made at the box's nodes across the wind: what it lacks along the
    # wind is stated (kept = resolved), not drawn at the beams
    from uq.pipeline import records
    from uq.pipeline.scenario import load_scenario
    from uq.pipeline.turbulencesection import scan_geometry
    raw = {**SMALL, "turbulence": {"model": "kaimal", "intensity": 0.1}}
    settings = load_scenario(raw).settings
    geometry = scan_geometry(settings)
    grid = records.record_grid(settings, geometry)
    assert records.beam_complement(settings, geometry, grid) is None
    complement = records.reference_complement(settings, geometry, grid)
    assert complement.kept == complement.resolved and complement.band is None


@pytest.mark.parametrize("n_scans", [2, 3, 150, 151])
def test_the_band_s_trend_has_zero_mean_and_unit_record_variance(n_scans):
    # the band of eddies larger than the box is drawn as a linear trend whose record
    # variance (about the record's mean, over N scans) is exactly 1: a band's draw has
    # the band's record covariance in expectation; closed forms, to rounding
    from uq.pipeline import records
    trend = records.band_trend(n_scans)
    assert trend.shape == (n_scans,)
    assert abs(trend.mean()) <= 1e-14
    assert trend.var() == pytest.approx(1.0, rel=1e-13)
    assert np.all(np.diff(trend) > 0)                     # a trend: rising scan by scan
    assert records.band_trend(1).tolist() == [0.0]
