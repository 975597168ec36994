"""Record-mode figures: the budget's arithmetic, the aliasing of the motion's peak, the plan."""
import matplotlib
import numpy as np
import pytest
import xarray as xr

matplotlib.use("Agg")

import uq  # noqa: E402
from uq.outputs import figures, recordfigures  # noqa: E402
from uq.pipeline.records import spectral_variances  # noqa: E402
from uq.pipeline.scenario import load_scenario  # noqa: E402

DBS = {"wind": {"speed": 10.0, "direction": 180.0, "reference_height": 100.0},
       "lidar": {"height": 0.0, "ranges": [60.0, 100.0], "half_cone": 30.0,
                 "vertical_beam": True, "scan": {"beam_duration": 1.0},
                 "probe": {"kind": "pulsed", "gate_length": 18.75, "pulse_fwhm": 24.75}},
       "turbulence": {"intensity": 0.1}, "sampling": {"method": "none"}}


def test_budget_steps_add_up_to_the_spectral_variance():
    settings = load_scenario(DBS).settings
    names, values = recordfigures.geometry_contributions(settings)
    assert names[0].startswith("true")
    total = values[0] + values[1] + values[2] + values[3]
    # the steps telescope: true + (each step minus the one before) = the last step,
    # the spectral path of the scan as it is (same quadrature: to rounding)
    np.testing.assert_allclose(total, spectral_variances(settings)[0].lidar[:, 0],
                               rtol=1e-10)
    assert np.all(values[3] < 0)               # the probe volume removes variance


@pytest.mark.parametrize("frequency, sampling, seen", [
    (1 / 7, 1 / 5, 1 / 5 - 1 / 7),            # a 7-s wave in 5-s scans: 0.0571 Hz
    (0.05, 0.2, 0.05),                         # below Nyquist: where it is
    (0.4, 0.2, 0.0),                           # twice the sampling rate: at 0
])
def test_aliased_motion_peak(frequency, sampling, seen):
    assert recordfigures.aliased(frequency, sampling) == pytest.approx(seen, abs=1e-12)


def test_motion_peak():
    assert recordfigures.motion_peak({"motion": {"spectrum": {"tp": 7.0}}}) == 1 / 7
    assert recordfigures.motion_peak({"motion": {
        "surge": {"amplitude": 0.5, "period": 7.0}, "heave": {"amplitude": 1.0,
                                                               "period": 9.0}}}) == 1 / 9
    assert recordfigures.motion_peak({}) is None


def test_record_plan_only_in_record_mode():
    assert recordfigures.record_plan(xr.Dataset()) == []
    record = xr.Dataset({"turbulence_intensity_spectral": ("turbulence_intensity", [0.1, 0.2])},
                        coords={"turbulence_intensity": [0.1, 0.2]})
    assert [name for name, _ in recordfigures.record_plan(record)] == [
        "record_spectra", "ti_budget", "apparent_against_true_ti"]
    assert "record_plan" in dir(figures.recordfigures)


SMALL = {"name": "small", "wind": {"speed": 10.0, "direction": 180.0, "reference_height": 100.0},
         "lidar": {"height": 0.0, "ranges": [60.0, 100.0], "half_cone": 30.0,
                   "scan": {"beam_duration": 0.5},
                   "errors": {"radial_velocity": {"dist": "normal", "u": 0.05}}},
         "turbulence": {"intensity": 0.1}, "record": {"duration": 30, "count": 3},
         "sampling": {"n": 64, "seed": 7}, "outputs": ["wind_speed"],
         "sweep": {"turbulence.intensity": [0.05, 0.1]}}


def test_summary_lists_each_scenes_turbulence_intensities():
    """A record-mode sweep's summary has a row per scene and gate under its swept values,
    each TI the stored one, named for what it is (the field's point TI, the field's over a
    record, the lidar's spectral and records' TI)."""
    from uq.outputs.summary import TI_COLUMNS, TI_LEGEND, summary_table
    ds = uq.run(SMALL)
    lines = summary_table(ds).splitlines()
    start = lines.index(TI_LEGEND)
    header = lines[start + 1].split()
    assert header[:3] == ["turbulence.intensity", "range", "gate"]
    rows = [line.split() for line in lines[start + 2:start + 6]]
    for row, (intensity, gate) in zip(rows, [(0.05, 60.0), (0.05, 100.0), (0.1, 60.0),
                                              (0.1, 100.0)]):
        at = ds.sel(turbulence_intensity=intensity, range=gate)
        assert row[:3] == [f"{intensity:g}", f"{gate:g}", f"{100 * intensity:.4g}"]
        assert row[3:3 + 6] == [f"{100 * float(at[n]):.4g}" for n in TI_COLUMNS.values()]


def test_spectra_figure_reads_what_the_run_stored_and_an_older_file_draws_it_again(capsys):
    # the figure takes the stored mean periodograms at the file's scene (intensity 0.1);
    # a result without them (written before runs stored them) draws the same records
    # again from its seed, says so on stderr, and gets the same spectra (the same code
    # and random streams: bit for bit)
    import matplotlib.pyplot as plt
    from uq.pipeline.runner import run
    ds = run({**SMALL, "turbulence": {"intensity": 0.1}})
    settings, chosen, words = recordfigures.shown_scene(ds, lines=("correction",))
    assert chosen == {"turbulence_intensity": 0.1} and words == "turbulence.intensity = 0.1"
    stored = recordfigures.spectra_lines(recordfigures.record_spectra_data(ds, settings),
                                         chosen, settings)
    np.testing.assert_array_equal(stored[1], ds["record_psd_u_true"].sel(
        turbulence_intensity=0.1).values)
    assert list(stored[2]) == ["lidar, fixed"]
    assert capsys.readouterr().err == ""
    older = ds.drop_vars([name for name in ds.variables if name.startswith("record_")])
    again = recordfigures.spectra_lines(recordfigures.record_spectra_data(older, settings),
                                        chosen, settings)
    assert "no stored record spectra" in capsys.readouterr().err
    for one, two in zip(stored, again):
        if isinstance(one, dict):
            assert list(one) == list(two)
            one, two = list(one.values()), list(two.values())
        np.testing.assert_array_equal(one, two)
    plt.close(recordfigures.record_spectra(ds))


def test_record_figures_draw_the_selected_scene():
    """`uq plot --select turbulence_intensity=0.05`: the spectra are that scene's stored
    ones and the budget that scene's (not the file's intensity, 0.1), and the titles
    say which scene they draw."""
    import matplotlib.pyplot as plt
    from uq.outputs.figures import select_scenes
    ds = uq.run({**SMALL, "turbulence": {"intensity": 0.1}})
    at = select_scenes(ds, {"turbulence_intensity": "0.05"})
    settings, chosen, words = recordfigures.shown_scene(at, lines=("correction",))
    assert settings["turbulence"]["intensity"] == 0.05 and chosen == {}
    lines = recordfigures.spectra_lines(recordfigures.record_spectra_data(at, settings),
                                        chosen, settings)
    np.testing.assert_array_equal(lines[1], ds["record_psd_u_true"].sel(
        turbulence_intensity=0.05).values)
    for function in (recordfigures.record_spectra, recordfigures.ti_budget):
        figure = function(at)
        titles = [figure._suptitle.get_text() if figure._suptitle else ""] + \
            [ax.get_title() for ax in figure.axes]
        assert any("turbulence.intensity = 0.05" in t.replace("\n", " ") for t in titles)
        plt.close(figure)
