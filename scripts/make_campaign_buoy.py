"""Make the shipped synthetic campaign's tables (scenarios/campaign_buoy/): the buoy
lidar's records by uq's Monte Carlo records, the wave sensor's and the mast's tables
(uq.campaign.synthetic). About 1300 record-heights of a few seconds each: run it
once after a change of the Monte Carlo records (the turbulence box, the motion, the
measurement model); it keeps what it made in a partial file and resumes from it.

    python scripts/make_campaign_buoy.py [--folder scenarios/campaign_buoy]
"""
import argparse
import sys
import time
from pathlib import Path

import pandas as pd

from uq.campaign import synthetic
from uq.pipeline.scenario import load_scenario


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    root = Path(__file__).resolve().parents[1]
    parser.add_argument("--folder", default=str(root / "scenarios" / "campaign_buoy"))
    args = parser.parse_args(argv)
    folder = Path(args.folder)
    stretch = synthetic.Stretch()
    lidar = load_scenario(root / "scenarios" / "campaign_buoy_lidar.yaml").settings
    table = synthetic.plan(stretch)
    partial = folder / "records.partial.csv"
    done = pd.read_csv(partial, index_col=0, parse_dates=True) if partial.exists() else None
    started = time.time()

    def report(count, total, out):
        if count % 10 == 0 or count == total:
            out.to_csv(partial)
            rate = count / (time.time() - started)
            print(f"{count}/{total} records, {rate:.2f}/s", file=sys.stderr, flush=True)
    folder.mkdir(parents=True, exist_ok=True)
    records = synthetic.make_records(lidar, table, stretch, done, report)
    synthetic.write_files(table, records, folder)
    partial.unlink(missing_ok=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
