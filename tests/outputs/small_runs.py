"""Every shipped scenario run small, once per test process, for the tests that check what
a person reads (figures, reports, summaries, trials drawn again) against the run.

Small: a few hundred trials, at most :data:`SWEEP_VALUES` values of each swept key
(its first, last and middle value: the sweep's extent, so the figures a full run draws
are drawn), and for record mode two short records at one turbulence intensity. The
scenario's own structure (its keys, sweep dimensions, corrections, probe, motion) is
kept, so every kind of figure and report section a shipped scenario makes is made.
"""
import copy
import functools

import yaml

import uq
from uq.pipeline.scenario import load_scenario
from uq.pipeline.shipped import shipped_names, shipped_path

#: Trials per scene: enough for a histogram and clause 8's intervals to be drawn.
TRIALS = 600
#: Values kept of each swept key.
SWEEP_VALUES = 3
#: Records and their length [s] of a record-mode scenario run small.
RECORDS, RECORD_SECONDS = 2, 120.0


def measurement_names():
    """The shipped scenarios that `uq run` takes (not the golden-lidar configuration)."""
    return [name for name in shipped_names()
            if "wind" in (yaml.safe_load(shipped_path(name).read_text()) or {})]


def small_mapping(name):
    """The scenario mapping of shipped scenario `name`, made small."""
    raw = yaml.safe_load(shipped_path(name).read_text())
    raw = copy.deepcopy(raw)
    raw["sampling"] = {**raw.get("sampling", {}), "n": TRIALS}
    raw["sampling"].pop("digits", None)
    sweep = {}
    for key, values in (raw.get("sweep") or {}).items():
        if isinstance(values, dict) and {"start", "stop", "step"} <= set(values):
            count = int(-(-(values["stop"] - values["start"]) // values["step"]))
            values = [values["start"] + i * values["step"] for i in range(count)]
        if isinstance(values, list):
            values = _spread(values)
            if key == "turbulence.intensity":
                values = values[:1]
        sweep[key] = values
    if sweep:
        raw["sweep"] = sweep
    if "record" in raw:
        raw["record"] = {**raw["record"], "count": RECORDS, "duration": RECORD_SECONDS}
    return raw


def _spread(values):
    """The first, middle and last of `values` (all of them where there are few)."""
    if len(values) <= SWEEP_VALUES:
        return list(values)
    return [values[0], values[len(values) // 2], values[-1]]


@functools.lru_cache(maxsize=None)
def small_result(name):
    """The Dataset of shipped scenario `name` run small (cached per process)."""
    return uq.run(load_scenario(small_mapping(name)))
