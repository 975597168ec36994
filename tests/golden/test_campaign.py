"""The shipped synthetic campaign (scenarios/golden_campaign.yaml) end to end: the seed's
finding, the physics of the lidars' shear sensitivity, and the written report."""
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import xarray as xr

from uq.cli import main
from uq.golden.findings import reference_comparison

ROOT = Path(__file__).resolve().parents[2]
CONFIG = ROOT / "scenarios" / "golden_campaign.yaml"


@pytest.fixture(scope="module")
def campaign(tmp_path_factory):
    folder = tmp_path_factory.mktemp("golden") / "out"
    assert main(["golden", str(CONFIG), "-o", str(folder)]) == 0
    return folder, xr.open_dataset(folder / "golden_campaign.nc").load()


def test_folder_holds_report_tables_figures_and_data(campaign):
    folder, _ = campaign
    for name in ("report.html", "report.md", "tables/per_bin.csv", "tables/kpi.csv",
                 "tables/sensitivity.csv", "figures/scatter.png", "figures/deviation.png",
                 "figures/uncertainty_terms.png", "data/campaign.yaml", "data/mast.csv"):
        assert (folder / name).stat().st_size > 0, name
    assert not list(folder.parent.glob(".*partial"))
    per_bin = pd.read_csv(folder / "tables" / "per_bin.csv")
    assert {"comparison", "height [m]", "framework", "bin [m s-1]", "calibration [m s-1]",
            "n_records [1]"} <= set(per_bin.columns), per_bin.columns
    for table in ("per_bin", "sensitivity", "kpi"):     # every number has its unit
        header = pd.read_csv(folder / "tables" / f"{table}.csv", nrows=0).columns
        numbers = pd.read_csv(folder / "tables" / f"{table}.csv").select_dtypes("number")
        assert all("[" in name for name in numbers.columns), (table, list(numbers.columns))
        assert len(header)


def test_report_gives_the_class_number_and_the_smc(campaign):
    """The golden report states each comparison's class number (it was only in
    tables/kpi.csv) and the SMC its configuration announces, from the stored values."""
    folder, ds = campaign
    report = (folder / "report.md").read_text()
    classes = report.split("## Classification (IEC 61400-12-1 Annex L)")[1].split("## ")[0]
    for k in ds["comparison"].values:
        for h in ds["height"].values:
            number = float(ds["class_number"].sel(comparison=k, height=h))
            assert f"| {k} | {h:g} | {number:.4f} |" in classes
    smc = report.split("## Specific measurement campaign (SMC) at 80 m")[1].split("## ")[0]
    records = int(ds["smc_n_records"].sel(height=80.0).isel(comparison=0).sum())
    assert f"{records} SMC records at 80 m" in smc


def test_golden_figures_are_readable(campaign):
    """Every golden figure passes the figure hygiene check (no clipped or overlapping
    text, legends that match what is drawn)."""
    import matplotlib.pyplot as plt
    from tests.outputs.figure_hygiene import problems
    from uq.golden import plots
    _, ds = campaign
    for draw in (plots.plot_scatter, plots.plot_deviation_against_environment,
                 plots.plot_uncertainty_terms, plots.plot_turbulence):
        figure = draw(ds, 80.0)
        try:
            assert problems(figure, dpi=90) == [], draw.__name__
        finally:
            plt.close(figure)


def test_seed_finding_same_type_reference_has_the_smaller_deviation_term(campaign):
    """FLSa against FLSb (same type, collocated) against FLSa against the mast: the mean
    deviation term over the required bins is smaller with FLSb, under both frameworks and
    at every height. The mast's comparison carries the site separation (2 % per record,
    shared by the buoys) and the type's shear bias; FLSb's only what differs between the
    units, so the margin (a factor ~2 IEC, ~3 LUSR) is far beyond the bin-to-bin noise."""
    _, ds = campaign
    for row in reference_comparison(ds, "flsa", "flsb", "mast"):
        assert row["bins"] == 25                          # 4-16 m/s, all sufficient
        assert row["deviation_golden"] < row["deviation_mast"], row


def test_chain_keeps_both_classification_terms(campaign):
    _, ds = campaign
    required = ds["required"].values
    chain = ds.sel(comparison="flsa-flsb").isel(bin=np.flatnonzero(required))
    assert (chain["reference_classification"] > 0).all()        # u_class,FLSb inside u_cal
    assert (chain["classification"] > 0).all()                   # u_class,FLSa in the total
    own = ds.sel(comparison="flsb-mast").isel(bin=np.flatnonzero(required))
    np.testing.assert_allclose(chain["reference_classification"].isel(framework=0),
                               own["classification"], rtol=1e-12)
    np.testing.assert_allclose(chain["reference_calibration"], own["calibration"],
                               rtol=1e-12)


@pytest.mark.parametrize("key, height_error", [("flsa-mast", -2.5), ("flsb-mast", -1.0)])
def test_shear_sensitivity_is_the_height_error(campaign, key, height_error):
    """A lidar riding e lower reads v (1 + e/h)^alpha: the percentage deviation against
    shear has slope 100 ln(1 + e/h) per unit of shear. Tolerance 4 standard errors of the
    regression (the site separation and the lidars' noise are independent of shear)."""
    _, ds = campaign
    for height in ds["height"].values:
        s = ds.sel(comparison=key, height=height, variable="shear")
        expected = 100 * np.log(1 + height_error / height)
        assert abs(float(s["slope"]) - expected) < 4 * float(s["slope_standard_error"])
        assert bool(s["slope_significant"])


def test_same_type_reference_sees_a_smaller_slope(campaign):
    """Seed Fig. 2: FLSa's slope against FLSb is smaller in magnitude than against the
    mast (the type's own sensitivity cancels)."""
    _, ds = campaign
    shear = ds["slope"].sel(variable="shear")
    assert (abs(shear.sel(comparison="flsa-flsb")) < abs(shear.sel(comparison="flsa-mast"))).all()


def test_report_states_the_finding_with_numbers(campaign):
    folder, ds = campaign
    text = (folder / "report.md").read_text()
    row = [r for r in reference_comparison(ds, "flsa", "flsb", "mast")
           if r["height"] == 80.0 and r["framework"] == "iec"][0]
    assert (f"the deviation term of flsa is {row['deviation_golden']:.4f} m/s with flsb as "
            f"reference and {row['deviation_mast']:.4f} m/s with the mast") in text
    assert "The chain keeps both classification terms" in text
    # the question "does a golden lidar lower the unit's calibration uncertainty", answered
    # from the stored per-bin values (bins required and sufficient in both comparisons)
    at = ds.sel(height=80.0, framework="iec")
    bins = (at["required"] & at["sufficient"].sel(comparison="flsa-flsb")
            & at["sufficient"].sel(comparison="flsa-mast")).values
    golden = float(at["calibration"].sel(comparison="flsa-flsb")[bins].mean())
    mast = float(at["calibration"].sel(comparison="flsa-mast")[bins].mean())
    verb = "lowers" if golden < mast else "does not lower"
    assert (f"**IEC 61400-12-1: the golden lidar {verb} flsa's calibration uncertainty** at "
            f"80 m: {golden:.4f} m/s with flsb as reference against {mast:.4f} m/s") in text
    assert "<img src='data:image/png;base64," in (folder / "report.html").read_text()


def test_kpis_of_the_synthetic_units(campaign):
    """FLSa's compass reads 0.8 deg low and FLSb's 0.3 deg high: the direction offset of
    FLSa against FLSb is about -1.1 deg (the regression's intercept, with a slope ~1)."""
    _, ds = campaign
    offset = ds["direction_offset"].sel(comparison="flsa-flsb")
    # per-record heading noise averages out over ~13,000 records (< 0.01 deg); the
    # intercept also absorbs (slope - 1) x mean direction, |4e-4 x 200| < 0.1 deg
    assert np.all(np.abs(offset + 1.1) < 0.3)
    assert (ds["speed_slope_verdict"] == "best practice").all()
    # 2 % outage: binomial sd sqrt(0.02 x 0.98 / 13248) = 0.0012, so 0.01 is 8 sd
    assert np.all(np.abs(ds["availability"] - 0.98) < 0.01)


def test_bad_config_exits_2_and_writes_nothing(tmp_path, capsys):
    bad = tmp_path / "bad.yaml"
    bad.write_text("golden: {name: x, synthetic: {lidars: {unit: nowhere.yaml}}}\n")
    assert main(["golden", str(bad), "-o", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err
    assert err.startswith("uq: error: ") and "golden.synthetic.lidars" in err
    assert len(err.strip().splitlines()) == 1
    assert not (tmp_path / "out").exists() and not list(tmp_path.glob(".*partial"))


def test_golden_file_passes_the_cf_checker(campaign, cf_compliance):
    """Issue 16: the campaign's netCDF file passes compliance-checker CF 1.10; its flags
    (bins with enough records, significant slopes) are CF flag variables."""
    folder, ds = campaign
    cf_compliance(folder / "golden_campaign.nc")
    assert ds["sufficient"].dtype == bool and ds["sufficient"].attrs["flag_meanings"]
    assert ds.attrs["title"] and "uq golden" in ds.attrs["history"]


def test_golden_figures_label_in_words_and_stack_variances(campaign):
    """Issue 16: axis labels in words with units (no column names such as
    turbulence_intensity), p-values rounded (p < 0.001, or two digits), and the stacked
    calibration terms drawn as variances (they add: the stack's top is u_cal^2 of the
    Dataset, rtol 1e-12) on an axis in (m/s)^2, not as shares on an axis in m/s."""
    import matplotlib.pyplot as plt

    from uq.golden import plots
    _, ds = campaign
    height = float(ds["height"].max())
    figure = plots.plot_deviation_against_environment(ds, height)
    for ax in figure.axes:
        assert "_" not in ax.get_xlabel() and "[" in ax.get_xlabel(), ax.get_xlabel()
        legend = next(t.get_text() for t in ax.get_legend().get_texts()
                      if t.get_text().startswith("slope"))
        p = legend.split(", p")[1]
        assert p == " < 0.001" or len(p.split("= ")[1].replace("0.", "").lstrip("0")) <= 2, legend
    plt.close(figure)
    figure = plots.plot_uncertainty_terms(ds, height)
    ax = figure.axes[0]
    assert "(m/s)$^2$" in ax.get_ylabel()
    bins = np.flatnonzero(ds["required"].values)
    shown = ds.sel(height=height).isel(bin=bins).isel(comparison=0, framework=0)
    tops = np.zeros(len(bins))
    for bar in ax.patches:                                  # 4 terms x bins, stacked
        index = int(np.argmin(np.abs(shown["bin"].values - bar.get_x() - bar.get_width() / 2)))
        tops[index] = max(tops[index], bar.get_y() + bar.get_height())
    np.testing.assert_allclose(tops, shown["calibration"].values ** 2, rtol=1e-12)
    plt.close(figure)
    assert plots.p_value_text(3e-17) == "p < 0.001" and plots.p_value_text(0.1432) == "p = 0.14"


def test_turbulence_kpis_and_prediction(campaign):
    """TI KPIs per bin and the TI uq predicts. The synthetic lidars carry the mast's TI
    (campaign docstring): that is no measurement of theirs, so their TI statistics are
    NaN (not an error of exactly 0 shown as measured), the figure draws no measured TI of
    the unit, and the report says why; FLSa and FLSb share a geometry, so the predicted
    ratio of one against the other is 1."""
    from uq.golden.turbulence import predicted_variance_ratio
    from uq.pipeline.scenario import load_scenario
    folder, ds = campaign
    assert (folder / "tables" / "turbulence.csv").exists()
    assert (folder / "figures" / "turbulence.png").exists()
    used = ds["ti_n_records"] > 0
    assert bool(ds["ti_unit_copies_reference"].all())
    assert np.isnan(ds["ti_mean_bias"].where(used)).all()
    assert np.isfinite(ds["ti_reference_mean"].where(used)).sum() > 0
    assert set(np.unique(ds["ti_rmse_verdict"].values)) == {"no data"}
    import matplotlib.pyplot as plt
    from uq.golden import plots
    figure = plots.plot_turbulence(ds, 80.0)
    labels = [line.get_label() for ax in figure.axes for line in ax.get_lines()]
    assert not any("measured" in label for label in labels), labels
    plt.close(figure)
    np.testing.assert_allclose(ds["ti_predicted_ratio"].sel(comparison="flsa-flsb"), 1.0)
    settings = load_scenario(ROOT / "scenarios" / "golden_flsb.yaml").settings
    assert float(ds["ti_predicted_ratio"].sel(comparison="flsb-mast", height=80.0)) == \
        pytest.approx(predicted_variance_ratio(settings, 80.0, 10.0), rel=1e-12)
    report = (folder / "report.md").read_text()
    assert "Turbulence intensity per bin" in report and "TI predicted [%]" in report
    assert "not a measurement, so no TI error is stated" in report
