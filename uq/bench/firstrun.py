"""The first run after an install, as a user times it: ``uq run NAME`` (``uq golden`` or
``uq campaign`` for their configurations) in a new process with numba's cache empty (a fresh
``NUMBA_CACHE_DIR``), then, once the background compile it started has ended
(:mod:`uq.cli.firstrun`), the same command with that cache filled. Wall times of the
whole commands, from the same run; the target is the difference: a first run within
5 s of the same run with a filled cache (on an idle 2-core machine).

The background compile runs at a low priority beside the first run (that is the user's
first run as shipped); the second run starts only after it has ended. Each command's
results are compared: the second run must have run the compiled model (its results
carry no ``model`` attribute) and agree with the first (the numpy model's) to 1e-12 in
the wind outputs' Monte Carlo mean and u.
"""
import os
import subprocess
import sys
import tempfile
import time

import numpy as np

from uq.pipeline.shipped import shipped_command

#: Variables compared between the first and the second run (each output's).
COMPARED = ("mc_mean", "mc_u", "mc_low", "mc_high")
#: Outputs compared (speed, direction as arc length at the scene's speed is not needed:
#: the absolute differences in m s-1 or deg are reported).
COMPARED_OUTPUTS = ("wind_speed", "vertical_wind")


def _command(name, folder):
    from uq.bench.targets import _command as command, uq_command
    return uq_command() + command(name, folder)


def _timed(command, env):
    """Wall time [s] of `command` in a new process (its output discarded)."""
    started = time.perf_counter()
    subprocess.run(command, env=env, check=True, stdout=subprocess.DEVNULL,
                   stderr=subprocess.DEVNULL)
    return time.perf_counter() - started


def _wait_for_background(cache):
    """Wait until the background compile of numba's cache in `cache` has ended; the
    seconds waited."""
    from uq.compileguard import wait_for_background
    started = time.perf_counter()
    wait_for_background(cache)
    return time.perf_counter() - started


def _results(name, folder):
    import xarray as xr
    path = os.path.join(folder, f"{name}.nc")
    with xr.open_dataset(path) as dataset:
        return dataset.load()


def first_run(name):
    """{cold wall [s], background wall after the cold run [s], warm wall [s], the
    difference, whether the warm run was compiled, the largest difference of the
    compared statistics} of one shipped scenario (see the module docstring)."""
    with tempfile.TemporaryDirectory(prefix="uq-first-run-") as folder:
        cache = os.path.join(folder, "numba")
        env = {**os.environ, "NUMBA_CACHE_DIR": cache, "UQ_BACKGROUND_COMPILE": "1"}
        out = {}
        for kind in ("cold", "warm"):
            target = os.path.join(folder, kind)
            os.makedirs(target)
            load = os.getloadavg()[0]
            out[f"{kind}_s"] = _timed(_command(name, target), env)
            out[f"{kind}_load"] = load
            # (after the warm run too: a compile it started would otherwise run on
            # beside the next scenario's runs)
            waited = _wait_for_background(cache)
            out["background_after_s" if kind == "cold" else "background_after_warm_s"] = waited
        out["over_warm_s"] = out["cold_s"] - out["warm_s"]
        out["command"] = f"uq {shipped_command(name)}"
        if shipped_command(name) == "run":            # a folder's file has other names
            cold, warm = (_results(name, os.path.join(folder, k)) for k in ("cold", "warm"))
            out["warm_compiled"] = "model" not in warm.attrs
            out["cold_numpy"] = cold.attrs.get("model", "").startswith("numpy")
            out["largest_difference"] = max(
                (float(np.nanmax(np.abs(cold[v].values - warm[v].values)))
                 for q in COMPARED_OUTPUTS for v in (f"{q}_{s}" for s in COMPARED)
                 if v in cold and np.isfinite(cold[v].values).any()), default=0.0)
    return out


def shipped_names():
    """Every shipped scenario, by name."""
    from uq.pipeline.shipped import shipped_folder
    return sorted(p.stem for p in shipped_folder().glob("*.yaml"))


def measure(names=None, progress=None):
    """{figure: value} of :func:`first_run` for each scenario of `names` (default every
    shipped one): ``first_run_<name>_s``, ``warm_run_<name>_s``,
    ``first_run_<name>_over_warm_s`` and the worst difference,
    ``first_run_worst_over_warm_s`` (with ``first_run_worst_name``)."""
    say = progress or (lambda text: None)
    figures, worst = {}, (-np.inf, None)
    for name in names or shipped_names():
        row = first_run(name)
        figures.update({f"first_run_{name}_s": row["cold_s"],
                        f"warm_run_{name}_s": row["warm_s"],
                        f"first_run_{name}_over_warm_s": row["over_warm_s"],
                        f"first_run_{name}_load": row["cold_load"],
                        f"first_run_{name}_background_after_s": row["background_after_s"],
                        f"first_run_{name}_background_after_warm_s":
                            row["background_after_warm_s"]})
        if "warm_compiled" in row:
            figures[f"first_run_{name}_warm_compiled"] = int(row["warm_compiled"])
            figures[f"first_run_{name}_largest_difference"] = row["largest_difference"]
        worst = max(worst, (row["over_warm_s"], name))
        say(f"{row.get('command', 'uq run')} {name}: first run {row['cold_s']:.1f} s "
            f"(load {row['cold_load']:.1f}), then the background compile {row['background_after_s']:.1f} s more, a warm "
            f"run {row['warm_s']:.1f} s")
    figures["first_run_worst_over_warm_s"], figures["first_run_worst_name"] = worst
    return figures


if __name__ == "__main__":
    import json
    print(json.dumps(measure(sys.argv[1:] or None, progress=lambda t: print(t, file=sys.stderr)),
                     indent=1))
