"""Make the shipped synthetic campaign's tables (scenarios/campaign_buoy/): the buoy
lidar's records by uq's Monte Carlo records, the wave sensor's and the mast's tables
(uq.campaign.synthetic). About 400 record-heights of a few seconds of CPU each: run it
once after a change of the Monte Carlo records (the turbulence box, the motion, the
measurement model); it keeps what it made in partial files and resumes from them.

    python scripts/make_campaign_buoy.py [--part I/N] [--folder scenarios/campaign_buoy]

``--part I/N`` makes only the records whose index is I modulo N (N processes side by
side); the last to finish writes the tables once every part is made.
"""
import argparse
import sys
import time
from pathlib import Path

import numpy as np
import pandas as pd

from uq.campaign import synthetic
from uq.pipeline.scenario import load_scenario


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    root = Path(__file__).resolve().parents[1]
    parser.add_argument("--folder", default=str(root / "scenarios" / "campaign_buoy"))
    parser.add_argument("--part", default="0/1")
    args = parser.parse_args(argv)
    index, count = (int(v) for v in args.part.split("/"))
    folder = Path(args.folder)
    folder.mkdir(parents=True, exist_ok=True)
    stretch = synthetic.Stretch()
    lidar = load_scenario(root / "scenarios" / "campaign_buoy_lidar.yaml").settings
    table = synthetic.plan(stretch)
    partial = folder / f"records.partial.{index}.csv"
    done = _read(partial, table) if partial.exists() else None
    started = time.time()

    def report(made, total, out):
        if made % 5 == 0 or made == total:
            out.to_csv(partial)
            print(f"part {index}: {made}/{total} records, {made / (time.time() - started):.3f}/s",
                  file=sys.stderr, flush=True)
    out = synthetic.make_records(lidar, table, stretch, done, report, (index, count))
    out.to_csv(partial)
    parts = [_read(folder / f"records.partial.{i}.csv", table) for i in range(count)
             if (folder / f"records.partial.{i}.csv").exists()]
    merged = parts[0].combine_first(pd.concat(parts[1:]).groupby(level=0).first()) \
        if len(parts) > 1 else parts[0]
    missing = [h for h in synthetic.HEIGHTS
               if np.any(table[f"made_{h:g}"] & ~np.isfinite(merged[f"mean_{h:g}"]))]
    if len(parts) == count and not missing:
        synthetic.write_files(table, merged, folder, lidar)
        for i in range(count):
            (folder / f"records.partial.{i}.csv").unlink(missing_ok=True)
        print("wrote the campaign's tables", file=sys.stderr)
    return 0


def _read(path, table):
    found = pd.read_csv(path, index_col=0, parse_dates=True)
    return found.reindex(table.index)


if __name__ == "__main__":
    sys.exit(main())
