"""uq fit: the shipped tilted, drifting floating-lidar scenario, coverage of naive and
propagated fits over repeated scans, Bayesian coverage, CSV input and bad input."""
import logging

import numpy as np
import pytest
import xarray as xr
from scipy.stats import binomtest

import uq
from pathlib import Path
from uq.fit.bayesfit import ProfilePosterior, posterior_summary, profile_data, sample_posterior
from uq.cli import main
from uq.engine.inputs import input_set
from uq.physics.measurement import measurement_model
from uq.pipeline.modelsetup import error_inputs, scene_from_settings
from uq.fit.command import fit_settings, fit_table
from uq.fit.fitting import combine_fits, fit_profile, profile_from_results
from uq.fit.plots import plot_corner
from uq.fit.profilefit import least_squares_profile
from uq.physics.profiles import power_law_profile

ROOT = Path(__file__).resolve().parents[2]
SCENARIO = ROOT / "scenarios" / "floating_lidar_profile.yaml"
FIXED = {"reference_height": 100.0}


@pytest.fixture(scope="module")
def results(tmp_path_factory):
    path = tmp_path_factory.mktemp("fit") / "profile.nc"
    assert main(["run", str(SCENARIO), "-o", str(path), "--quiet",
                 "--set", "sampling.n=40000"]) == 0
    return path


@pytest.fixture(scope="module")
def fitted(results):
    results.with_name("my_notes.txt").write_text("not uq's")     # beside the outputs
    assert main(["fit", str(results), "--set", "fit.ensembles=2"]) == 0
    return xr.open_dataset(results.with_name("profile_fit.nc")).load()


def test_fit_of_the_shipped_scenario_writes_everything(fitted, results):
    assert list(fitted["fit"].values) == ["propagated", "naive"]
    for name in ("posterior_median", "posterior_low95", "posterior_high68", "chain", "rhat",
                 "tau", "predictive_low95", "profile_high95", "least_squares_low95",
                 "true_value", "posterior_low95_mcse", "posterior_high95_mcse"):
        assert name in fitted
    assert results.with_name("profile_fit_profile.png").stat().st_size > 10_000
    assert results.with_name("profile_fit_corner.png").stat().st_size > 10_000
    assert results.with_name("my_notes.txt").read_text() == "not uq's"
    assert np.all(fitted["rhat"] < 1.01)
    # the predictive band holds the credible band of the mean profile
    assert np.all(fitted.predictive_low95 <= fitted.profile_low95)
    assert np.all(fitted.predictive_high95 >= fitted.profile_high95)


def test_propagated_fit_recovers_the_truth_and_naive_is_over_confident(fitted):
    """The common speed-over-ground error (0.1 m/s, correlation ~0.7 between gates)
    cannot average out over 8 gates: the naive fit's U_ref interval is too narrow by
    about sqrt(1 + 7 rho) / 1 ~ 2.4 (independent errors assumed); its shear interval is
    too wide, because a common error cancels in the profile's shape."""
    prop, naive = fitted.sel(fit="propagated"), fitted.sel(fit="naive")
    truth = fitted["true_value"]
    assert np.all((prop.posterior_low95 <= truth) & (truth <= prop.posterior_high95)
                  .sel(parameter=["reference_speed", "shear"]))
    width = prop.posterior_high95 - prop.posterior_low95
    naive_width = naive.posterior_high95 - naive.posterior_low95
    assert float(width.sel(parameter="reference_speed")
                 / naive_width.sel(parameter="reference_speed")) > 1.8
    assert float(width.sel(parameter="shear") / naive_width.sel(parameter="shear")) < 0.8


def scan_draws(results, n, seed):
    """n single-scan observations (speeds, gate heights) of the scenario's model."""
    scenario = uq.load_scenario(SCENARIO)
    scene = scene_from_settings(scenario.settings)
    inputs = input_set(error_inputs(scenario.settings, scene.n_beams, len(scene.ranges)))
    values = inputs.values(np.random.default_rng(seed).standard_normal((n, inputs.dimension)))
    out = measurement_model(scene, ("wind_speed", "gate_height"), **values, **inputs.constants)
    return np.real(out["wind_speed"]), np.real(out["gate_height"])


def test_coverage_over_repeated_scans(results):
    """Over R single scans with known truth, the 95 % interval of U_ref from the
    propagated covariance covers the truth at a rate consistent with 95 % (binomial test,
    p > 0.001), and the naive one does not (rate < 0.85). The generalised least-squares
    interval is the flat-prior posterior's for this Gaussian, near-linear model (checked
    against emcee in test_bayesfit)."""
    ds = xr.open_dataset(results).load()
    speeds, _ = scan_draws(results, 400, seed=11)
    truth = 9.0
    covered = {"propagated": 0, "naive": 0}
    for observed in speeds:
        for kind, heights, sigma in (
                ("propagated", ds.gate_height_mc_mean.values, ds.wind_speed_mc_covariance.values),
                ("naive", ds.gate_height_true.values, ds.wind_speed_mc_u.values)):
            fit = least_squares_profile("power_law", heights, observed, sigma=sigma, fixed=FIXED)
            covered[kind] += fit["parameter_low"][0] <= truth <= fit["parameter_high"][0]
    assert binomtest(covered["propagated"], 400, 0.95).pvalue > 0.001, covered
    assert covered["naive"] / 400 < 0.85, covered


@pytest.mark.slow
def test_bayesian_credible_intervals_cover_at_95_percent():
    """60 profiles with known truth and independent Gaussian noise (sigma 0.15 m/s,
    7 gates): the emcee 95 % credible intervals of the shear and of U_ref cover the truth
    at a rate consistent with 95 % (binomial test, p > 0.001 each)."""
    rng = np.random.default_rng(21)
    heights = np.array([30.0, 50.0, 70.0, 90.0, 110.0, 150.0, 190.0])
    hits, trials = np.zeros(2, int), 60
    for _ in range(trials):
        truth = np.array([rng.uniform(6, 12), rng.uniform(0.05, 0.2)])
        speeds = power_law_profile(heights, *truth) + rng.normal(0, 0.15, heights.size)
        data = profile_data(heights, speeds, speed_covariance=np.full(heights.size, 0.15))
        posterior = ProfilePosterior("power_law", data, fixed=FIXED, scatter=False)
        result = sample_posterior(posterior, seed=rng, ensembles=2, steps=1000)
        summary = posterior_summary(result["samples"], result["names"])
        for k, name in enumerate(("reference_speed", "shear")):
            hits[k] += summary[name]["low95"] <= truth[k] <= summary[name]["high95"]
    for count in hits:
        assert binomtest(int(count), trials, 0.95).pvalue > 0.001, hits


def test_csv_input_with_scatter(tmp_path, capfd):
    """10-min-like records at 4 heights: speed = power law + N(0, 0.4) per record; the
    fitted scatter's 95 % interval holds 0.4 and the shear's holds the truth."""
    rng = np.random.default_rng(3)
    heights = np.repeat([40.0, 60.0, 80.0, 100.0], 30)
    speeds = power_law_profile(heights, 8.0, 0.15) + rng.normal(0, 0.4, heights.size)
    speeds[5] = np.nan                                         # a missing record
    path = tmp_path / "mast.csv"
    np.savetxt(path, np.column_stack([heights, speeds]), delimiter=",",
               header="z,ws", comments="")
    config = tmp_path / "fit.yaml"
    config.write_text("fit: {columns: {height: z, speed: ws}, ensembles: 2}\n")
    assert main(["fit", str(path), "-c", str(config)]) == 0
    assert "WARNING" not in capfd.readouterr().err          # nothing leaks (issue 16)
    ds = xr.open_dataset(tmp_path / "mast_fit.nc").load()
    assert ds.attrs["rows_dropped_not_finite"] == 1
    row = ds.sel(fit="data")
    shear = row.sel(parameter="shear")
    assert float(shear.posterior_low95) <= 0.15 <= float(shear.posterior_high95)
    scatter = np.exp(row.sel(parameter="ln_sigma")[["posterior_low95", "posterior_high95"]])
    assert float(scatter.posterior_low95) <= 0.4 <= float(scatter.posterior_high95)


@pytest.mark.parametrize("arguments, message", [
    (["--set", "fit.walkers=8"], "fit.walkers"),
    (["--set", "fit.profile=cubic"], "fit.profile"),
    (["--set", "fit.priors.shear={dist: uniform, low: 1, high: 0}"], "fit.priors.shear"),
    (["--set", "sampling.n=3"], "allowed: fit.<key>"),
])
def test_bad_fit_settings_exit_2_with_one_line(results, capsys, arguments, message):
    assert main(["fit", str(results), "-o", str(results.with_name("bad_fit.nc"))]
                + arguments) == 2
    error = capsys.readouterr().err
    assert message in error and error.count("\n") == 1
    assert not results.with_name("bad_fit.nc").exists()


def test_results_without_gate_heights_are_refused(tmp_path, capsys):
    path = tmp_path / "plain.nc"
    assert main(["run", str(SCENARIO), "-o", str(path), "--quiet", "--set", "sampling.n=1000",
                 "--set", "outputs=[wind_speed]"]) == 0
    assert main(["fit", str(path)]) == 2
    assert "gate_height" in capsys.readouterr().err


def fake_fit(steps, rng, heavy_tail=False):
    """A Dataset shaped like fit_profile's (2 ensembles x `steps` x 32 walkers x 2
    parameters), draws N(0, 1) (with a few far outliers when `heavy_tail`)."""
    chain = rng.standard_normal((2, steps, 32, 2)) + np.array([8.0, 0.12])
    if heavy_tail:                                     # 15 draws (of the kept) far out
        chain[0, [100, 200, 300], :5] = 8.0 + 200.0 * rng.standard_normal((3, 5, 2))
    names = ["reference_speed", "shear"]
    summary = {f"posterior_{k}": ("parameter", np.quantile(chain.reshape(-1, 2), p, axis=0))
               for k, p in (("low95", 0.025), ("median", 0.5), ("high95", 0.975))}
    return xr.Dataset({**summary, "chain": (("ensemble", "step", "walker", "parameter"), chain),
                       "tau": ("parameter", [10.0, 10.0])},
                      coords={"parameter": names}, attrs={"burn": 20, "thin": 5,
                                                        "least_squares_basis": "known"})


def test_fits_of_different_chain_length_combine():
    """Issue 16, bug 1: `uq fit` crashed (AlignmentError on `step`) when the propagated
    and naive fits' chains ended at different lengths. Any pair must combine: the
    shorter chain is padded with NaN at its end, every value of both kept."""
    rng = np.random.default_rng(1)
    short, long = fake_fit(300, rng), fake_fit(700, rng)
    for first, second in ((short, long), (long, short)):
        combined = combine_fits({"a": first, "b": second})
        assert combined.sizes["step"] == 700
        for name, fit in (("a", first), ("b", second)):
            chain = combined["chain"].sel(fit=name).values
            n = fit.sizes["step"]
            np.testing.assert_array_equal(chain[:, :n], fit["chain"].values)
            assert np.isnan(chain[:, n:]).all()
        assert list(combined["burn"].values) == [20, 20]
        plot_corner(combined, "a" if first is short else "b").clf()   # NaN padding skipped


def test_corner_plot_shows_the_bulk_and_leaks_no_warning(caplog):
    """Issue 16, bug 4: with a few far draws (a short table gives heavy tails), the
    corner plot's histograms were spikes (the axis spanned the far tail), corner logged
    `Too few points to create valid contours` on the root logger, and the last title ran
    off the figure. Now: no log record, the tallest bin of each 1-D histogram holds less
    than a quarter of the draws (a N(0, 1) bulk over the central 99.5 % in >= 15 bins
    puts ~10 % in the tallest), and every title lies inside the figure."""
    dataset = combine_fits({"data": fake_fit(400, np.random.default_rng(2), heavy_tail=True)})
    with caplog.at_level(logging.WARNING):
        figure = plot_corner(dataset)
    assert not caplog.records, [r.getMessage() for r in caplog.records]
    figure.canvas.draw()
    box = figure.bbox
    diagonal = [ax for ax in figure.axes if ax.get_title()]
    assert len(diagonal) == 2
    for ax in diagonal:
        (histogram,) = ax.patches                   # a step outline: x0,0 x0,h0 x1,h0 x1,h1 ..
        counts = histogram.get_xy()[1:-1:2, 1]
        assert len(counts) >= 15 and counts.max() < 0.25 * counts.sum(), ax.get_title()
        extent = ax.title.get_window_extent()
        assert box.x0 <= extent.x0 and extent.x1 <= box.x1, ax.get_title()


def test_fit_file_passes_the_cf_checker(results, fitted, cf_compliance):
    """Issue 16: the file of `uq fit` has Conventions, a title and history, and a long
    name for every variable (units where one unit fits; the parameters' units beside
    them), and passes compliance-checker CF 1.10."""
    cf_compliance(results.with_name("profile_fit.nc"))
    assert fitted.attrs["Conventions"] == "CF-1.10" and "uq fit" in fitted.attrs["history"]
    assert all("long_name" in fitted[name].attrs for name in fitted.variables)
    assert list(fitted["parameter_units"].values) == ["m s-1", "1"]



def test_least_squares_interval_carries_the_data_uncertainty(results):
    """Issue 27, item 1: with fit.scatter: true the least-squares interval of U_ref had
    almost no width ([8.983, 8.984] against the posterior's [8.755, 9.207]): it took the
    scatter of Monte Carlo means about a smooth profile. It now rests on the propagated
    covariance (the Monte Carlo means lie on the profile: no extra scatter), says so, and
    is as wide as the posterior to within what the free scatter adds to the posterior
    (less than a factor 1.5: 8 gates leave 6 residual degrees of freedom to bound it)
    and the MCMC error of the posterior's ends (5 %)."""
    ds = xr.open_dataset(results).load()
    config = fit_settings(None, {"fit": {"scatter": True, "ensembles": 2}}, {})
    fit = combine_fits({"propagated": fit_profile(profile_from_results(ds), config)})
    prop = fit.sel(fit="propagated", parameter="reference_speed")
    least = float(prop.least_squares_high95 - prop.least_squares_low95)
    posterior = float(prop.posterior_high95 - prop.posterior_low95)
    assert posterior / 1.5 < least <= posterior * 1.05, (least, posterior)
    assert "least squares, propagated: the given covariance (it explains the residuals" \
        in fit_table(fit)


def test_fit_figures_are_readable(fitted):
    """The profile-fit figure and the corner plot pass the figure hygiene check (no
    clipped or overlapping text, legends that match what is drawn)."""
    import matplotlib.pyplot as plt
    from tests.outputs.figure_hygiene import problems
    from uq.fit.plots import plot_profile_fit
    for draw in (plot_profile_fit, plot_corner):
        figure = draw(fitted)
        try:
            assert problems(figure) == [], draw.__name__
        finally:
            plt.close(figure)
