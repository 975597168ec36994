"""Benchmark of ``uq campaign``: the shipped campaign scaled to RECORDS record-heights,
corrected by the command as shipped (wall time, record-heights per second), and some
record-heights corrected by the fast path (the tables) and the direct path (the spectral
path and the measurement model per record): records per second of each and their
largest differences. Prints one JSON object (with the machine's load at the start).

    python scripts/bench_campaign.py [--records 100000] [--workers N] [--direct 12]
"""
import argparse
import json
import os
import sys
import tempfile
from pathlib import Path

from uq.campaign import benchmark


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--records", type=int, default=100_000)
    parser.add_argument("--workers", type=int, default=None)
    parser.add_argument("--direct", type=int, default=12,
                        help="record-heights corrected by both paths (0: none)")
    args = parser.parse_args(argv)
    root = Path(__file__).resolve().parents[1]
    config = root / "scenarios" / "campaign_buoy.yaml"
    out = {"load_average": os.getloadavg(), "cpus": os.cpu_count()}
    if args.direct:
        out.update(benchmark.direct_against_fast(config, args.direct))
    with tempfile.TemporaryDirectory() as folder:
        scaled = benchmark.scaled_campaign(config, Path(folder) / "in", args.records)
        client = None
        if args.workers:
            from uq.pipeline.cluster import local_cluster
            cluster = local_cluster(args.workers, host="127.0.0.1")
            client = cluster.__enter__()
        try:
            wall, cpu, count, attrs = benchmark.time_command(scaled, Path(folder) / "out",
                                                             client)
        finally:
            if client is not None:
                cluster.__exit__(None, None, None)
    out.update(command_seconds=wall, command_cpu_seconds_driver=cpu, record_heights=count,
               record_heights_corrected=attrs["n_corrected"],
               command_runtime_s=attrs["runtime_s"],
               record_heights_per_second=count / wall, workers=args.workers or 1,
               surrogate_ti_error=attrs["surrogate_ti_error"],
               load_average_after=os.getloadavg())
    print(json.dumps(out, indent=1, default=_plain))
    return 0


def _plain(value):
    """A numpy scalar (a Dataset's attribute) as the Python number JSON takes."""
    return value.item() if hasattr(value, "item") else str(value)


if __name__ == "__main__":
    sys.exit(main())
