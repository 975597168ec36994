"""The figure of a nacelle lidar's correction sweep: u against the preview distance."""
import matplotlib

matplotlib.use("Agg")
import numpy as np  # noqa: E402
import yaml  # noqa: E402

import uq  # noqa: E402
from uq.outputs import motionfigures  # noqa: E402
from uq.outputs.figures import figure_plan  # noqa: E402
from pathlib import Path  # noqa: E402

SCENARIOS = Path(__file__).resolve().parents[2] / "scenarios"


def test_a_nacelle_sweep_draws_u_against_preview_distance():
    raw = yaml.safe_load((SCENARIOS / "nacelle_floating.yaml").read_text())
    raw["lidar"]["ranges"] = [50.0, 300.0]
    raw["sampling"] = {"n": 400, "seed": 1}
    ds = uq.run(raw)
    plan = dict(figure_plan(ds))
    assert "uncertainty_against_preview" in plan
    figure = plan["uncertainty_against_preview"](ds)
    axes = figure.axes
    assert [ax.get_xlabel() for ax in axes] == ["preview distance [m]"] * 3
    assert "pitch 3 deg at 25 s, pitch 1 deg at 8 s, surge 1 m at 8 s" in figure._suptitle.get_text()
    line = axes[0].get_lines()[0]                 # none: Monte Carlo markers at the gates
    np.testing.assert_allclose(line.get_xdata(), [50.0, 300.0])
    np.testing.assert_allclose(line.get_ydata(),
                               ds["wind_speed_mc_u"].sel(correction="none").values)
    motionfigures.plt.close(figure)
