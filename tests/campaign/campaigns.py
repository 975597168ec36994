"""Small campaigns written as a user holds them, for the campaign's tests."""
import copy
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
import yaml

ROOT = Path(__file__).resolve().parents[2]
LIDAR = ROOT / "scenarios" / "campaign_buoy_lidar.yaml"


@pytest.fixture
def coarse_tables(monkeypatch):
    """Tables of few nodes (for the plumbing: their error is measured and large): the
    spectral path at 2 speeds x 3 directions, the motion's curvature every 0.2 Hz (the
    motion's response and noise keep their nine directions: exact in direction)."""
    from uq.campaign import surrogate
    monkeypatch.setattr(surrogate, "SPEED_NODES", 2)
    monkeypatch.setattr(surrogate, "SPECTRAL_DIRECTIONS", 3)
    monkeypatch.setattr(surrogate, "CURVATURE_STEP", 0.2)


def lidar_records(count=24, heights=(40, 80), seed=3, start="2016-03-02 00:10"):
    """A lidar's table: columns ``ws<h>``, ``sd<h>``, ``wd<h>``, ``av<h>``, stamps at the
    end of each period in local time (UTC+01:00) as text."""
    rng = np.random.default_rng(seed)
    times = pd.date_range(start, periods=count, freq="10min")
    table = pd.DataFrame({"stamp": (times + pd.Timedelta(hours=1)).strftime("%Y-%m-%d %H:%M")})
    for h in heights:
        speed = 8.0 + 2.0 * rng.standard_normal(count)
        table[f"ws{h}"] = speed
        table[f"sd{h}"] = speed * (0.12 + 0.01 * rng.standard_normal(count))
        table[f"wd{h}"] = rng.uniform(0, 360, count)
        table[f"av{h}"] = 100.0
    return table


def write_campaign(folder, records=None, changes=None, lidar_changes=None, waves=True,
                   reference=True):
    """Files of a small campaign in `folder` and its configuration; returns its path.
    `changes`: dotted keys of the ``campaign`` mapping (None removes); `lidar_changes`:
    the lidar scenario's."""
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    records = lidar_records() if records is None else records
    records.to_csv(folder / "lidar.csv", index=False)
    lidar = yaml.safe_load(LIDAR.read_text())
    for dotted, value in (lidar_changes or {}).items():
        _assign(lidar, dotted, value)
    (folder / "lidar.yaml").write_text(yaml.safe_dump(lidar))
    starts = pd.to_datetime(records["stamp"], errors="coerce", format="mixed") - \
        pd.Timedelta(hours=1, minutes=10)
    heights = sorted(int(c[2:]) for c in records.columns if c.startswith("ws"))
    config = {"name": "mini", "lidar": "lidar.yaml",
              "turbulence": {"length_scale": 33.6},
              "records": {"file": "lidar.csv", "time": "stamp", "time_zone": "+01:00",
                          "stamp": "end",
                          "heights": {h: {"speed": f"ws{h}", "std": f"sd{h}",
                                          "direction": f"wd{h}", "availability": f"av{h}"}
                                      for h in heights}}}
    if waves:
        rng = np.random.default_rng(5)
        pd.DataFrame({"t": starts.dt.strftime("%Y-%m-%dT%H:%MZ"),
                      "hs": rng.uniform(0.5, 2.0, len(starts)),
                      "tp": rng.uniform(4.0, 8.0, len(starts))}).to_csv(folder / "waves.csv",
                                                                        index=False)
        config["motion"] = {"kind": "sea_state", "file": "waves.csv", "time": "t",
                            "columns": {"hs": "hs", "tp": "tp"},
                            "response": {"roll": {"factor": 4.0, "lag": 90},
                                         "pitch": {"factor": 3.0}, "heave": {"factor": 1.0},
                                         "surge": {"factor": 0.5, "lag": 90}}}
    if reference:
        mast = pd.DataFrame({"t": starts.dt.strftime("%Y-%m-%d %H:%M")})
        for h in heights:
            mast[f"ti{h}"] = 100 * records[f"sd{h}"] / records[f"ws{h}"]
        mast.to_csv(folder / "mast.csv", index=False)
        config["reference"] = {"file": "mast.csv", "time": "t",
                               "heights": {h: {"ti": f"ti{h}"} for h in heights}}
    for dotted, value in (changes or {}).items():
        _assign(config, dotted, value)
    path = folder / "campaign.yaml"
    path.write_text(yaml.safe_dump({"campaign": config}, sort_keys=False))
    return path


def _assign(mapping, dotted, value):
    node = mapping
    *parents, last = [int(p) if p.isdigit() else p for p in dotted.split(".")]
    for part in parents:
        node = node.setdefault(part, {})
    if value is None:
        node.pop(last, None)
    else:
        node[last] = copy.deepcopy(value)
