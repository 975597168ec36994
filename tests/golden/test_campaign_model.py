"""The synthetic campaign with the numpy model (uq golden on a cold numba cache): the same
records as with the compiled model, to 1e-12 (tests/pipeline/test_model_switch.py says
why) from the same draws; ``uq golden`` simulates with numpy and starts the lidars'
compile in the background where a kernel is missing (uq.cli.firstrun)."""
import contextlib
from pathlib import Path

import numpy as np
import pandas as pd

from uq.cli import firstrun, main
from uq.compileguard import KernelNotCached
from uq.golden.campaign import lidar_at_height
from uq.golden.config import load_golden_config

ROOT = Path(__file__).resolve().parents[2]
CONFIG = ROOT / "scenarios" / "golden_campaign.yaml"


def test_numpy_and_compiled_lidars_agree():
    lidar = load_golden_config(CONFIG).synthetic["lidars"]["unit"]
    speed = np.array([4.0, 8.5, 15.0])
    direction, shear = np.array([10.0, 200.0, 359.0]), np.array([0.1, 0.0, 0.25])
    out = [lidar_at_height(lidar, 80.0, speed, direction, shear,
                           np.random.default_rng(4), 30, compiled)
           for compiled in (True, False)]
    np.testing.assert_allclose(out[0][0], out[1][0], rtol=0, atol=1e-12)     # m s-1
    gap = (out[0][1] - out[1][1] + 180.0) % 360.0 - 180.0                    # deg
    assert np.all(np.abs(np.deg2rad(gap) * speed) <= 1e-12)                  # arc length


def test_a_missing_kernel_simulates_with_numpy_and_compiles_beside(tmp_path, monkeypatch):
    started = []

    class Fake:
        pid = 4321

        def __init__(self, settings, model_seconds=0.0):
            started.append([s["name"] for s in settings])

        def ended(self):
            return False

    @contextlib.contextmanager
    def missing():
        raise KernelNotCached("uq.physics.fusedkernels.wind_scan")
        yield
    monkeypatch.setenv(firstrun.BACKGROUND_VARIABLE, "1")
    monkeypatch.setattr(firstrun, "BackgroundCompile", Fake)
    monkeypatch.setattr("uq.compileguard.cached_only", missing)
    folder = tmp_path / "cold"
    assert main(["golden", str(CONFIG), "-q", "-o", str(folder)]) == 0
    assert len(started) == 1 and sorted(started[0]) == ["golden_flsa", "golden_flsb"]
    monkeypatch.setenv(firstrun.BACKGROUND_VARIABLE, "0")                # compiled
    assert main(["golden", str(CONFIG), "-q", "-o", str(tmp_path / "warm")]) == 0
    for name in ("flsa", "flsb", "mast"):
        cold = pd.read_csv(folder / "data" / f"{name}.csv", index_col=0)
        warm = pd.read_csv(tmp_path / "warm" / "data" / f"{name}.csv", index_col=0)
        # written with 5 significant digits: equal to that rounding
        np.testing.assert_allclose(cold.to_numpy(), warm.to_numpy(), rtol=1e-5, atol=0)
