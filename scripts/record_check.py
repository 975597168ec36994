"""The two turbulence paths of record mode side by side, over many records.

    python scripts/record_check.py SCENARIO [--count N] [--set KEY=VALUE ...]

Runs the scenario (``uq run``'s code path) with ``record.count`` N and prints, per gate,
the spectral path's apparent TI and the Monte Carlo records' mean with its standard
error, the field's true TI both ways, the check's z and the box's kept fraction. The
numbers quoted in the report and in tests/pipeline/test_records.py come from it.
"""
import argparse
import sys
import time

import numpy as np
import yaml

from uq.pipeline.runner import run
from uq.pipeline.scenario import load_scenario
from uq.pipeline.shipped import scenario_path


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scenario")
    parser.add_argument("--count", type=int, default=48)
    parser.add_argument("--set", action="append", default=[], metavar="KEY=VALUE")
    args = parser.parse_args(argv)
    overrides = {"record.count": args.count}
    for item in args.set:
        key, value = item.split("=", 1)
        overrides[key] = yaml.safe_load(value)
    path = args.scenario if args.scenario.endswith(".yaml") else scenario_path(args.scenario)
    scenario = load_scenario(path, overrides)
    start = time.process_time()
    ds = run(scenario)
    cpu = time.process_time() - start
    squeeze = {d: 0 for d in ds["turbulence_intensity_spectral"].dims if d not in ("range",)}
    at = ds.isel(squeeze)
    n = args.count
    print(f"{scenario.name}: {n} records, {cpu:.0f} s CPU; box kept "
          f"{float(at['turbulence_intensity_box_kept']):.4f}")
    true_mc = float(at["turbulence_intensity_true_mc_mean"])
    print(f"  true TI: spectral {float(at['turbulence_intensity_true']):.5f}, records "
          f"{true_mc:.5f}")
    for g, gate in enumerate(np.atleast_1d(at["range"].values)):
        one = at.isel(range=g) if "range" in at.dims else at
        mean, spread = float(one["turbulence_intensity_mc_mean"]), float(
            one["turbulence_intensity_mc_u"])
        print(f"  {gate:g} m: spectral {float(one['turbulence_intensity_spectral']):.5f}, "
              f"records {mean:.5f} +- {spread / np.sqrt(n):.5f}; z "
              f"{float(one['turbulence_intensity_spectral_z']):+.2f} (limit "
              f"{float(one['turbulence_intensity_spectral_z_limit']):.2f}); ratios u v w "
              f"{float(one['turbulence_intensity_u_ratio']):.4f} "
              f"{float(one['turbulence_v_ratio']):.4f} {float(one['turbulence_w_ratio']):.4f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
