"""How fast a campaign is corrected, and how far the fast path is from the direct one.

* :func:`scaled_campaign`: the shipped campaign (``campaign_buoy``) repeated in time
  until it holds a given number of record-heights (its three tables shifted by whole
  days), written as a user's files; :func:`time_command` runs ``uq campaign`` on it as
  shipped (reading, tables, correction, netCDF, CSV, figures, report) and times it.
* :func:`direct_against_fast`: some record-heights of a campaign corrected twice, with
  the model's terms from the tables (the fast path) and from the spectral path and the
  measurement model run for each record (the direct path): the records per second of
  each and their largest differences.

``scripts/bench_campaign.py`` runs both and prints one JSON object.
"""
import time

import numpy as np
import pandas as pd
import yaml

from uq.campaign import analysis, correction, model, surrogate
from uq.campaign.config import length_scales, load_campaign_config


def scaled_campaign(config_path, folder, record_heights):
    """The campaign of `config_path` repeated in time (whole days) into `folder` until
    it holds at least `record_heights` record-heights; returns the new configuration's
    path. Each repetition shifts every table's stamps by the same whole number of days."""
    from pathlib import Path
    config_path, folder = Path(config_path), Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    raw = yaml.safe_load(config_path.read_text())
    section = raw["campaign"]
    heights = len(section["records"]["heights"])
    records = pd.read_csv(config_path.parent / section["records"]["file"])
    copies = int(np.ceil(record_heights / (len(records) * heights)))
    span = _span_days(records, section["records"])
    for key in ("records", "motion", "reference"):
        if section.get(key) is None:
            continue
        spec = section[key]
        table = pd.read_csv(config_path.parent / spec["file"])
        stamps = pd.to_datetime(table[spec.get("time", "time")], format="mixed")
        parts = []
        for copy in range(copies):
            part = table.copy()
            shifted = stamps + pd.Timedelta(days=span * copy)
            part[spec.get("time", "time")] = shifted.dt.strftime("%Y-%m-%dT%H:%M:%S") + (
                "Z" if stamps.dt.tz is not None else "")
            parts.append(part)
        name = f"{key}.csv"
        pd.concat(parts).to_csv(folder / name, index=False)
        spec["file"] = name
    section["lidar"] = str((config_path.parent / section["lidar"]).resolve())
    section["name"] = f"{section.get('name', 'campaign')}_x{copies}"
    path = folder / "campaign.yaml"
    path.write_text(yaml.safe_dump(raw, sort_keys=False))
    return path


def _span_days(records, spec):
    """Whole days the records span (their last period's end included)."""
    stamps = pd.to_datetime(records[spec.get("time", "time")], format="mixed")
    return int(np.ceil((stamps.max() - stamps.min() + pd.Timedelta(minutes=10))
                       / pd.Timedelta(days=1)))


def time_command(config_path, folder, client=None):
    """(wall seconds of ``uq campaign`` on `config_path` into `folder`, the CPU seconds
    of this process in it, record-heights, the results' Dataset attributes)."""
    import io
    import xarray as xr
    from uq.campaign.command import run_campaign
    started, cpu = time.perf_counter(), time.process_time()
    out = run_campaign(config_path, folder, stream=io.StringIO(), client=client)
    wall, cpu = time.perf_counter() - started, time.process_time() - cpu
    name = load_campaign_config(config_path).name
    with xr.open_dataset(out / f"{name}.nc") as ds:
        return wall, cpu, int(ds.attrs["n_record_heights"]), dict(ds.attrs)


def direct_against_fast(config_path, count=12, seed=0):
    """`count` corrected record-heights of the campaign drawn at random (`seed`):
    the fast path's and the direct path's seconds per record and their largest relative
    differences of the corrected TI, of F and of the motion variance."""
    config = load_campaign_config(config_path)
    from uq.campaign.recordsfile import load_records
    records = load_records(config.records)
    motions, outside, _ = analysis.motion_of(config, records["time"].values)
    flags = analysis.input_flags(config, records, motions, outside)
    usable = (flags & correction.INVALIDATING) == 0
    rows, columns = np.nonzero(usable)
    pick = np.random.default_rng(seed).choice(rows.size, size=min(count, rows.size),
                                              replace=False)
    rows, columns = rows[pick], columns[pick]
    scales = length_scales(config)
    turbulence = {"model": "mann", "anisotropy": config.anisotropy}
    speed = records["speed"].values
    lidar = config.lidar.settings
    started = time.perf_counter()
    tables = surrogate.build_tables(lidar, list(config.heights), scales, turbulence, 600.0,
                                    (config.minimum_speed, float(np.nanmax(
                                        np.where(usable, speed, np.nan))) * 1.05),
                                    motions.shapes)
    tables_seconds = time.perf_counter() - started
    direction = analysis.record_directions(config, records, tables)
    started = time.perf_counter()
    fast = model.fast_terms(tables, columns, speed[rows, columns], direction[rows, columns],
                            motions.take(rows), config.filtering == "spectral")
    fast_seconds = time.perf_counter() - started
    started = time.perf_counter()
    direct = [model.direct_terms(lidar, config.heights[c], scales[c], turbulence, 600.0,
                                 speed[r, c], direction[r, c], motions.take(np.array([r])),
                                 config.filtering == "spectral")
              for r, c in zip(rows, columns)]
    direct_seconds = time.perf_counter() - started
    direct = {name: np.array([d[name] for d in direct]) for name in model.TERMS}
    ti = [correction.correct(speed[rows, columns], records["std"].values[rows, columns],
                             terms["filtering"], terms["spread"], terms["motion_variance"],
                             terms["motion_bias"], terms["noise_variance"], tables.n_scans,
                             config.records.ddof, motion_cross=terms["motion_cross"],
                             motion_phase=terms["motion_phase"]
                             )["turbulence_intensity_corrected"]
          for terms in (fast, direct)]
    both = np.isfinite(ti[0]) & np.isfinite(ti[1])
    return {"records": int(rows.size),
            "tables_seconds": tables_seconds,
            "fast_records_per_second": rows.size / max(fast_seconds, 1e-9),
            "direct_records_per_second": rows.size / direct_seconds,
            "largest_ti_difference": float(np.max(np.abs(ti[0][both] / ti[1][both] - 1))),
            "largest_filtering_difference": float(np.max(np.abs(
                fast["filtering"] / direct["filtering"] - 1))),
            "largest_motion_variance_difference": float(np.max(np.abs(
                fast["motion_variance"] - direct["motion_variance"])
                / np.maximum(direct["motion_variance"], 1e-12)))}
