"""Scale-out on a many-core machine, in one command:

    python -m uq.bench.scaleout [--workers 1,2,4,8,16] [-o results/scaleout.json] [--small]

For each number of dask workers N (a local cluster, one single-threaded process per
worker, :func:`uq.pipeline.cluster.local_cluster`) and each workload, the wall time of
:func:`uq.run` (the cluster's start excluded: the client is made first, then the run
is timed), the speed-up S(N) = T(1) / T(N) against the same run in one process without
a cluster, the efficiency S(N) / N (target >= 0.6 up to 8 workers), and whether the
results are bit-identical to the single process's (every variable's bytes; each
chunk's draws come from the seed alone) and their largest difference otherwise.

Workloads:

* ``rubio2022_misalignment`` at 10^5 trials per scene (3,456 scenes), as the issue of
  the distributed sweep;
* a record-mode sweep: ``floating_lidar_ti`` as shipped (6 intensities x 2
  corrections, 5 records each).

``--small`` shrinks both (10^3 trials per scene on 192 scenes; two intensities, two
records of 60 s) for a check on a small machine; ``--workers`` takes any list.
Writes JSON with the machine, its load before and after each run, the date and every
figure. The numba cache should be filled first (``uq warmup``): the workers then load
the kernels instead of compiling them.
"""
import argparse
import json
import os
import sys
import time

import numpy as np

#: Target efficiency S(N) / N up to :data:`TARGET_WORKERS` workers [1].
TARGET_EFFICIENCY, TARGET_WORKERS = 0.6, 8


def workloads(small=False):
    """name -> scenario of the workloads (module docstring)."""
    from uq.pipeline.scenario import load_scenario
    from uq.pipeline.shipped import scenario_path
    if small:
        return {"rubio2022_misalignment": load_scenario(
                    scenario_path("rubio2022_misalignment"), {
                        "sampling.n": 1000, "sweep.ship.cog": [0, 90],
                        "sweep.lidar.misalignment": {"start": -180, "stop": 180, "step": 45},
                        "sweep.wind.direction": {"start": 0, "stop": 360, "step": 30}}),
                "floating_lidar_ti": load_scenario(scenario_path("floating_lidar_ti"), {
                    "sweep.turbulence.intensity": [0.06, 0.1], "record.count": 2,
                    "record.duration": 60, "sampling.n": 256})}
    return {"rubio2022_misalignment": load_scenario(
                scenario_path("rubio2022_misalignment"), {"sampling.n": 100_000}),
            "floating_lidar_ti": load_scenario(scenario_path("floating_lidar_ti"))}


def largest_difference(one, other):
    """The largest absolute difference of the numeric variables two results share."""
    gaps = [float(np.nanmax(np.abs(one.variables[name].values.astype(float)
                                   - other.variables[name].values.astype(float))))
            for name in set(one.variables) & set(other.variables)
            if one.variables[name].dtype.kind in "fiu" and one.variables[name].size
            and np.isfinite(one.variables[name].values.astype(float)).any()]
    return max(gaps, default=0.0)


def identical(one, other):
    """Whether two results hold the same variables with the same bytes."""
    if set(one.variables) != set(other.variables):
        return False
    return all(np.array_equal(one.variables[name].values, other.variables[name].values,
                              equal_nan=one.variables[name].dtype.kind in "fc")
               for name in one.variables)


def machine():
    """What the figures were measured on."""
    from uq.bench.report import machine_description
    return machine_description()


def measure(workers=(1, 2, 4, 8, 16), small=False, progress=None, names=None):
    """Every figure, as a dict (module docstring); `names`: only these workloads."""
    from uq.pipeline.cluster import local_cluster
    from uq.pipeline.runner import run
    say = progress or (lambda text: None)
    from uq.bench.report import now
    from uq.files import SIGNATURE
    out = {"title": "uq scale-out", "generator": SIGNATURE, "machine": machine(),
           "date": now(), "small": small, "workloads": {}}
    for name, scenario in workloads(small).items():
        if names is not None and name not in names:
            continue
        load = os.getloadavg()
        started = time.perf_counter()
        single = run(scenario)
        base = time.perf_counter() - started
        rows = {"single_process_s": base, "single_process_load": load, "workers": {}}
        say(f"{name}: one process {base:.1f} s (load {load[0]:.1f})")
        for count in workers:
            with local_cluster(count) as client:
                load = os.getloadavg()
                started = time.perf_counter()
                result = run(scenario, client=client)
                seconds = time.perf_counter() - started
            speedup = base / seconds
            rows["workers"][str(count)] = {
                "seconds": seconds, "speedup": speedup, "efficiency": speedup / count,
                "load_before": load, "load_after": os.getloadavg(),
                "identical": identical(single, result),
                "largest_difference": largest_difference(single, result)}
            say(f"{name}: {count} workers {seconds:.1f} s, speed-up {speedup:.2f} "
                f"({speedup / count:.2f} N), identical {rows['workers'][str(count)]['identical']}")
        rows["target_met"] = all(row["efficiency"] >= TARGET_EFFICIENCY and row["identical"]
                                 for key, row in rows["workers"].items()
                                 if int(key) <= TARGET_WORKERS)
        out["workloads"][name] = rows
    return out


def main(argv=None):
    parser = argparse.ArgumentParser(prog="python -m uq.bench.scaleout",
                                     description=__doc__.split("\n\n")[0])
    parser.add_argument("--workers", default="1,2,4,8,16",
                        help="numbers of dask workers, comma-separated")
    parser.add_argument("-o", "--output", default="results/scaleout.json")
    parser.add_argument("--small", action="store_true", help="small workloads")
    args = parser.parse_args(argv)
    import logging
    for name in ("distributed", "tornado", "asyncio"):     # the cluster's own chatter
        logging.getLogger(name).setLevel(logging.ERROR)
    workers = [int(value) for value in args.workers.split(",")]
    figures = measure(workers, args.small, progress=lambda text: print(text, file=sys.stderr))
    from uq.files import write_text
    os.makedirs(os.path.dirname(os.path.abspath(args.output)), exist_ok=True)
    write_text(args.output, json.dumps(figures, indent=1) + "\n")
    print(f"wrote {args.output}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
