"""The path-to-path check's false-alarm rate over seeds, at a scenario's record count.

    python scripts/false_alarms.py SCENARIO [--seeds 50] [--set KEY=VALUE ...]

Runs the scenario once per seed (``sampling.seed`` 1..N, everything else as given) and
counts the gates whose ``turbulence_intensity_spectral_valid`` is false: where the two
paths agree, a binomial of N (x gates) draws with the check's nominal 5 %. Prints the
count, the rate, its binomial 95 % interval (Clopper-Pearson) and the mean z.
"""
import argparse
import sys
import time

import numpy as np
import yaml
from scipy import stats

from uq.pipeline.runner import run
from uq.pipeline.scenario import load_scenario
from uq.pipeline.shipped import scenario_path


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scenario")
    parser.add_argument("--seeds", type=int, default=50)
    parser.add_argument("--set", action="append", default=[], metavar="KEY=VALUE")
    args = parser.parse_args(argv)
    overrides = {}
    for item in args.set:
        key, value = item.split("=", 1)
        overrides[key] = yaml.safe_load(value)
    path = args.scenario if args.scenario.endswith(".yaml") else scenario_path(args.scenario)
    start = time.process_time()
    z, valid = [], []
    for seed in range(1, args.seeds + 1):
        ds = run(load_scenario(path, {**overrides, "sampling.seed": seed}))
        z.append(np.ravel(ds["turbulence_intensity_spectral_z"].values))
        valid.append(np.ravel(ds["turbulence_intensity_spectral_valid"].values))
        print(f"seed {seed}: z {np.round(z[-1], 2).tolist()}", flush=True)
    z, valid = np.concatenate(z), np.concatenate(valid).astype(bool)
    alarms, n = int(np.sum(~valid)), valid.size
    low, high = stats.binomtest(alarms, n).proportion_ci(0.95)
    limit = float(np.ravel(ds["turbulence_intensity_spectral_z_limit"].values)[0])
    print(f"{path}: {alarms} false alarms in {n} checks ({args.seeds} seeds, record.count "
          f"{int(ds.attrs.get('record_count', 0)) or 'as given'}, |z| limit {limit:.3f}): "
          f"rate {alarms / n:.3f}, 95 % interval [{low:.3f}, {high:.3f}] (nominal 0.05); "
          f"mean z {z.mean():+.2f}, sd {z.std(ddof=1):.2f}; "
          f"{time.process_time() - start:.0f} s CPU")
    return 0


if __name__ == "__main__":
    sys.exit(main())
