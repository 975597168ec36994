"""A figure for every run (issue 16): a single scene, any 1-D and 2-D sweep, 3-D with a
short third dimension, more dimensions with --select; what each figure draws is checked
against the numbers of the result it draws."""
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
import pytest
from matplotlib.collections import QuadMesh
from scipy.stats import norm

import uq
from uq.errors import ScenarioError
from uq.outputs import plots
from uq.outputs.figures import figure_plan, make_figures, no_figure_reason
from uq.outputs.plots import histogram_gate, plot_budget, plot_histogram, shared_scale
from uq.outputs.samples import scene_trials

ROOT = Path(__file__).resolve().parents[2]
CASE_I = ROOT / "scenarios" / "rubio2022_case_i.yaml"


def run(path, sweep=None, n=2000, **values):
    return uq.run(uq.load_scenario(path, {"sampling.n": n, "sweep": sweep or {}, **values}))


@pytest.fixture(scope="module")
def single():
    """One scene with three range gates, a vertical beam and every error source."""
    return run(ROOT / "scenarios" / "floating_lidar_full.yaml", n=4000)


@pytest.fixture(scope="module")
def sweeps():
    """The user's own sweeps of 1 to 4 dimensions (none of the paper's)."""
    axes = {"lidar.misalignment": [0, 45, 90], "wind.direction": [0, 120, 240],
            "ship.sog": [1, 4], "wind.speed": [4, 8]}
    names = list(axes)
    return {k: run(CASE_I, {key: axes[key] for key in names[:k]} if k > 1 else
                   {"ship.sog": [0, 2, 4]}) for k in (1, 2, 3, 4)}


def labelled(figure):
    """Every axis with a label has its unit in brackets (or is a probability density)."""
    for ax in figure.axes:
        for label in (ax.get_xlabel(), ax.get_ylabel()):
            if label and "density" not in label and ax.get_label() != "<colorbar>":
                assert "[" in label and "]" in label, label
    return True


def test_single_scene_gets_budget_gate_and_histogram_figures(single):
    plan = figure_plan(single)
    assert [stem for stem, _ in plan] == ["budget", "uncertainty_against_gate", "histogram",
                                          "radial_velocity_per_beam"]
    for _, function in plan:
        figure = function(single)
        assert labelled(figure)
        plt.close(figure)


def test_budget_bars_are_each_inputs_contribution_in_the_outputs_unit(single):
    """Bars |c_i| u_i [m s-1] = sqrt of the stored variance budget, per input and gate;
    their squares add to the GUM u^2 (the bars add in quadrature: rtol 1e-12, rounding)."""
    figure = plot_budget(single)
    ax = figure.axes[0]                                       # wind speed
    inputs = [t.get_text() for t in ax.get_yticklabels()]
    gates = len(single["range"])
    widths = np.array([bar.get_width() for bar in ax.patches]).reshape(gates, len(inputs))
    expected = np.sqrt(single["wind_speed_budget"].sel(input=inputs).values.T)
    np.testing.assert_allclose(widths, expected, rtol=1e-12)
    np.testing.assert_allclose(np.sum(widths**2, axis=1), single["wind_speed_gum_u"] ** 2,
                               rtol=1e-12)
    assert "m s$^{-1}$" in ax.get_xlabel()
    plt.close(figure)


def test_histogram_draws_the_runs_own_trials_and_both_intervals(single):
    """The trials drawn again from the file's scenario and seed are the run's: their
    mean and standard deviation are the stored Monte Carlo mean and u (rtol 1e-12: the
    same numbers summed in another order). The panel draws the GUM's Gaussian (its peak
    1/(u sqrt(2 pi)), to the grid's resolution, rtol 1e-3) and the four interval ends."""
    trials = scene_trials(single, ("wind_speed",), n_max=10**6)
    assert len(trials["wind_speed"]) == int(single["mc_n_samples"])
    np.testing.assert_allclose(trials["wind_speed"].mean(axis=0), single["wind_speed_mc_mean"],
                               rtol=1e-12)
    np.testing.assert_allclose(trials["wind_speed"].std(axis=0, ddof=1), single["wind_speed_mc_u"],
                               rtol=1e-12)
    figure = plot_histogram(single, trials)
    ax = figure.axes[0]
    gate = single.isel(range=histogram_gate(single, "wind_speed"))
    u, value = float(gate.wind_speed_gum_u), float(gate.wind_speed_gum_value)
    curve = next(line for line in ax.lines if len(line.get_xdata()) > 2)
    assert np.max(curve.get_ydata()) == pytest.approx(1 / (u * np.sqrt(2 * np.pi)), rel=1e-3)
    ends = sorted(float(line.get_xdata()[0]) for line in ax.lines if len(line.get_xdata()) == 2)
    k = norm.ppf(0.975)
    np.testing.assert_allclose(ends, sorted([float(gate.wind_speed_mc_low),
                                             float(gate.wind_speed_mc_high),
                                             value - k * u, value + k * u]), rtol=1e-12)
    assert "validated" in ax.get_title()
    plt.close(figure)


def test_any_1d_and_2d_sweep_gets_figures(sweeps):
    assert [stem for stem, _ in figure_plan(sweeps[1])] == ["uncertainty_against_sweep"]
    stems = [stem for stem, _ in figure_plan(sweeps[2])]
    assert stems == ["uncertainty_against_sweep"]        # 3 x 3 scenes: lines, not maps
    for k in (1, 2):
        for _, function in figure_plan(sweeps[k]):
            figure = function(sweeps[k])
            assert labelled(figure)
            plt.close(figure)


def test_a_short_third_dimension_gives_rows_of_maps(sweeps):
    _, function = figure_plan(sweeps[3])[0]
    figure = function(sweeps[3])
    meshes = [ax for ax in figure.axes if ax.get_title()       # not the colour bars
              and any(isinstance(c, QuadMesh) for c in ax.collections)]
    assert len(meshes) == 2 * 3                       # 2 sog values x 3 models
    assert any("ship speed over ground" in ax.get_title() for ax in meshes)
    plt.close(figure)


def test_more_dimensions_name_the_select_that_gives_figures(sweeps, tmp_path):
    assert figure_plan(sweeps[4]) == []
    reason = no_figure_reason(sweeps[4])
    assert "--select ship_sog=1" in reason and "--select wind_speed=4" in reason
    written = make_figures(sweeps[4], tmp_path, select={"ship_sog": "4", "wind_speed": 8})
    assert [p.name for p in written] == ["uncertainty_against_sweep_ship_sog_4_wind_speed_8.png"]
    assert no_figure_reason(sweeps[2]) is None
    with pytest.raises(ScenarioError, match="no such sweep dimension"):
        figure_plan(sweeps[4], select={"ship_cog": 0})
    with pytest.raises(ScenarioError, match="a number"):
        figure_plan(sweeps[4], select={"ship_sog": "fast"})


def test_a_run_without_uncertainty_says_why():
    quiet = uq.run(uq.load_scenario({"name": "quiet", "sampling": {"n": 1000, "seed": 1}}))
    assert figure_plan(quiet) == []
    assert "no output has an uncertainty" in no_figure_reason(quiet)


def test_shared_colour_scale_only_where_every_panel_shows_its_variation():
    """Shared when each panel spans >= 30 % of the common range (SHARED_SCALE_FRACTION)."""
    assert shared_scale([np.array([0.0, 1.0]), np.array([0.5, 1.2])])
    # the paper's 6 % effect beside a model 40 % higher: one scale would flatten both
    assert not shared_scale([np.array([1.0, 1.06]), np.array([1.4, 1.48])])
    assert shared_scale([np.zeros(3), np.zeros(3)])


def test_report_of_many_dimensions_says_how_to_get_figures(sweeps):
    from uq.outputs.report import render_report
    page = render_report(sweeps[4])
    assert "--select" in page.split("<h2>Figures</h2>")[1] and "<img" not in page
    page = render_report(sweeps[4], select={"ship_sog": 4, "wind_speed": 8})
    assert page.count("<img") == 1


def test_flat_panels_do_not_force_a_scale_each():
    """A panel flat to rounding has no variation to show: it does not count (two flat
    models that differ share one scale, so their difference shows)."""
    assert shared_scale([np.full(4, 0.0707), np.full(4, 0.1)])
    assert not shared_scale([np.full(4, 0.0707), np.array([0.1, 0.1001])])


def test_monte_carlo_error_bars_fall_back_to_the_normal_standard_error(sweeps):
    """2000 trials make no two batches of 2^10: the stored standard error of u is NaN and
    the error bars use that of the standard deviation of N normal draws, u/sqrt(2(N-1))."""
    from uq.outputs.plots import u_standard_error
    ds = sweeps[1]
    assert np.isnan(ds["wind_speed_mc_u_standard_error"]).all()
    np.testing.assert_allclose(u_standard_error(ds, "wind_speed"),
                               ds["wind_speed_mc_u"] / np.sqrt(2 * (2000 - 1)), rtol=1e-15)


def _mesh_of(figure, title):
    ax = next(ax for ax in figure.axes if ax.get_title().startswith(title))
    return ax, next(c for c in ax.collections if isinstance(c, QuadMesh))


@pytest.mark.parametrize("effect, averaged", [(0.9, True), (6.0, False)])
def test_monte_carlo_noise_draws_no_structure(sweeps, effect, averaged):
    """Issue 27, item 3: common random numbers make the Monte Carlo noise of
    neighbouring scenes alike, and a colour map stretched over it drew "blobs" over
    misalignment where the model has no effect. A Monte Carlo variation along a swept
    key within +-2 standard errors (here a smooth one of `effect` x 2 SE peak to peak
    over misalignment: 0.9 x 2 = 1.8 SE < 4 SE) is averaged away, and the panel says so;
    a larger one (6 x 2 SE = 12 SE) is drawn."""
    from uq.outputs.plots import plot_maps
    ds = sweeps[2].copy()
    se = ds["wind_speed_mc_u_standard_error"].fillna(
        ds["wind_speed_mc_u"] / np.sqrt(2 * (ds["mc_n_samples"] - 1)))
    shape = np.sin(np.deg2rad(2 * ds["lidar_misalignment"]))       # 0 .. 1 .. 0
    ds["wind_speed_mc_u"] = ds["wind_speed_gum_u"] + effect * 2 * se * shape
    figure = plot_maps(ds, "wind_speed", "lidar_misalignment", "wind_direction")
    ax, mesh = _mesh_of(figure, "Monte Carlo")
    drawn = np.asarray(mesh.get_array()).reshape(ds.sizes["wind_direction"],
                                                 ds.sizes["lidar_misalignment"])
    along = np.ptp(drawn, axis=1)                    # spread over misalignment, per row
    notes = [t.get_text() for t in ax.texts]
    if averaged:
        # the mean of each row, to rounding of the float64 mean (1e-12 relative)
        np.testing.assert_allclose(along, 0, atol=1e-12 * float(np.max(drawn)))
        assert notes and "±2 Monte Carlo standard errors" in notes[0]
        assert "lidar misalignment" in notes[0]
    else:
        assert np.all(along > 0) and not notes
    plt.close(figure)


def test_a_small_sweep_draws_lines_not_maps(sweeps):
    """Issue 27, item 7: a small sweep (here 3 x 3 scenes) drew maps of 3-valued axes.
    It draws u against one key with a line per value of the other, each line the
    result's own numbers."""
    ds = sweeps[2]
    (stem, function), = figure_plan(ds)
    figure = function(ds)
    ax = figure.axes[0]
    lines = {line.get_label(): line for line in ax.get_lines()}
    for value in ds["lidar_misalignment"].values:
        label = f"GUM, physical model, lidar misalignment {value:g}"
        np.testing.assert_array_equal(lines[label].get_ydata(), ds["wind_speed_gum_u"].sel(
            lidar_misalignment=value).values)
        np.testing.assert_array_equal(lines[label].get_xdata(), ds["wind_direction"].values)
    texts = [t.get_text() for legend in figure.legends for t in legend.get_texts()]
    assert plots.ERROR_BAR_LABEL in texts                          # the bars say what they are
    plt.close(figure)


def test_the_motion_is_named_in_words_with_units():
    """Issue 27, item 5: a measured motion record was titled "harmonic motion: ;"."""
    from uq.outputs.motionfigures import _sea
    record = {"motion": {"series": {"file": "data/buoy_imu.csv", "components": 128}}}
    assert _sea(record).startswith("measured motion record buoy_imu.csv (128 harmonics")
    harmonic = {"motion": {"pitch": {"amplitude": 5.0, "period": 6.0, "phase": "random"},
                           "heave": {"amplitude": 0.5, "period": 8.0, "phase": 0}}}
    assert _sea(harmonic) == "harmonic motion: pitch 5 deg at 6 s, heave 0.5 m at 8 s"


def test_a_selection_is_in_the_figure_title(sweeps):
    """Issue 27, item 5: `--select` figures did not say which scenes they show."""
    from uq.outputs.figures import figure_plan, mark_selection, select_scenes
    select = {"ship_sog": "4", "wind_speed": 7}
    chosen = select_scenes(sweeps[4], select)
    (stem, function), = figure_plan(chosen)
    figure = mark_selection(function(chosen), chosen, select)
    title = figure._suptitle.get_text()
    assert "selected: ship speed over ground = 4" in title and "wind speed = 8" in title
    plt.close(figure)


def test_the_bench_figure_shows_measurements_not_fits_through_noise():
    """The bench figure fitted power laws through a handful of noisy wall times (slopes
    near -5, where Monte Carlo error falls as n^-1/2 to n^-1). It draws the runs and
    their medians (the measured values, nothing fitted), a guide of slope -1/2 through
    plain Monte Carlo's largest run (exactly: errors e (t / t0)^-1/2 from it, 1e-12), the
    reference's floor and the 1e-3 target, each in the legend, and passes the hygiene
    check."""
    import xarray as xr
    from tests.outputs.figure_hygiene import problems
    from uq.outputs.plots import plot_bench
    times = np.array([1e-3, 1e-2, 1e-1, 1.0, 10.0])
    noisy = 1e-4 * times ** -0.5 * np.array([1.0, 3.0, 0.4, 2.0, 1.0])   # no clean law
    floor = 2e-6
    shape = (1, 1, times.size, 2)
    ds = xr.Dataset({"relative_error": (("scene", "method", "n", "repeat"),
                                        np.broadcast_to(noisy[:, None], shape[2:])[None, None]),
                     "time_s": (("scene", "method", "n", "repeat"),
                                np.broadcast_to(times[:, None], shape[2:])[None, None]),
                     "reference_relative_error": ("scene", [floor])},
                    coords={"scene": ["s"], "method": ["mc"], "n": range(times.size),
                            "repeat": range(2)})
    figure = plot_bench(ds)
    ax = figure.axes[0]
    lines = {line.get_label(): line for line in ax.get_lines()}
    np.testing.assert_allclose(lines["mc: medians"].get_ydata(), noisy, rtol=1e-12)
    guide = lines["slope -1/2 (error ~ time^-1/2)"]
    np.testing.assert_allclose(guide.get_ydata(), noisy[-1] * np.sqrt(
        times[-1] / guide.get_xdata()), rtol=1e-12)
    assert len([line for line in ax.get_lines() if line.get_linestyle() == "-"]) == 1
    assert problems(figure) == []
    plt.close(figure)
