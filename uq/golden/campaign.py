"""A synthetic verification campaign, made with the project's own measurement model.

Truth: one year of real 10-min records of the brightwind demo mast (40, 60, 80 m; MIT
licence, :func:`uq.data.brightwind_mast`). For every record:

* the **mast** reads that truth (speeds, vanes, temperature; turbulence intensity from the
  cups' standard deviations, shear exponent from 40 and 80 m);
* the wind at the **buoys' site** differs from the mast's by the spatial separation: one
  relative speed difference ~ N(0, ``site_separation``) and one direction difference
  ~ N(0, ``direction_separation``) per record, shared by the two collocated buoys;
* each **floating lidar** (a shipped ``uq run`` scenario) measures the site's wind, a power
  law of the record's shear through the measured speed at each height, through
  :func:`uq.measurement.measurement_model` with the scenario's motion, INS and lidar
  errors. A 10-min record is the mean of ``scans_per_record`` scans with independent
  errors: the effective number of independent INS readings in 10 min (600 s over the
  correlation time of the INS errors), not the lidar's scan count. A fraction
  ``outage`` of each lidar's records is lost at random (availability).

The lidars report the turbulence intensity and temperature of the mast (turbulence is not
simulated) and a shear exponent from their own 40 and 80 m speeds.
"""
import dataclasses
from pathlib import Path

import numpy as np
import pandas as pd
import yaml

from uq.constants import FULL_CIRCLE_DEG
from uq.data import brightwind_mast
from uq.engine.inputs import Input
from uq.physics.measurement import measurement_model
from uq.pipeline.modelsetup import error_inputs, scene_from_settings
from uq.pipeline.scenario import load_scenario
from uq.engine.statistics import circular_mean_deg

#: brightwind demo mast: height [m] -> (speed, its standard deviation, vane) columns.
MAST_COLUMNS = {80.0: ("Spd80mN", "Spd80mNStd", "Dir78mS"),
                60.0: ("Spd60mN", "Spd60mNStd", "Dir58mS"),
                40.0: ("Spd40mN", "Spd40mNStd", "Dir38mS")}
TEMPERATURE_COLUMN = "T2m"
PERCENT = 100.0
DEFAULTS = {"truth": "brightwind", "verification": ["2016-06-01", "2016-09-01"],
            "smc": ["2016-10-01", "2017-01-01"], "scans_per_record": 10,
            "site_separation": 0.02, "direction_separation": 2.0, "outage": 0.02,
            "seed": 1, "mast": {"calibration": {"absolute": 0.05, "relative": 0.005}}}


def validate_synthetic(check, raw, scenarios=None):
    """Validated ``golden.synthetic`` settings (defaults filled in); `scenarios` the
    overrides of the lidars' scenarios by role (``uq golden --set unit:KEY=VALUE``),
    whose roles are kept in ``overridden``."""
    from .overrides import load_lidar_scenario
    scenarios = scenarios or {}
    out = {**DEFAULTS, **raw}
    check.choice(out["truth"], "golden.synthetic.truth", ("brightwind",))
    for key in ("verification", "smc"):
        period = check.list(out[key], f"golden.synthetic.{key}")
        try:
            start, stop = (pd.Timestamp(str(p)) for p in period)
        except (ValueError, TypeError):
            check.fail(f"golden.synthetic.{key}", "allowed: [start, stop] dates")
        if not start < stop:
            check.fail(f"golden.synthetic.{key}", "allowed: start before stop")
    check.integer(out["scans_per_record"], "golden.synthetic.scans_per_record", low=1)
    check.number(out["site_separation"], "golden.synthetic.site_separation", low=0.0)
    check.number(out["direction_separation"], "golden.synthetic.direction_separation", low=0)
    check.number(out["outage"], "golden.synthetic.outage", low=0.0, high=1.0, high_open=True)
    check.integer(out["seed"], "golden.synthetic.seed", low=0)
    lidars = out.get("lidars")
    check.mapping(lidars, "golden.synthetic.lidars")
    if set(lidars) != {"unit", "golden"}:
        check.fail("golden.synthetic.lidars", "allowed: {unit: SCENARIO.yaml, golden: "
                   "SCENARIO.yaml} (the unit under test and the golden lidar)")
    base = Path(check.source).parent
    out["lidars"] = {role: load_lidar_scenario(base / check.text(
        path, f"golden.synthetic.lidars.{role}"), role, scenarios)
                     for role, path in lidars.items()}
    out["overridden"] = sorted(role for role in lidars if scenarios.get(role))
    return out


def mast_records(truth):
    """The mast's table: speeds, directions, TI [%] per height; shear; temperature."""
    table = pd.DataFrame(index=truth.index)
    for height, (speed, std, vane) in MAST_COLUMNS.items():
        table[f"speed_{height:g}"] = truth[speed]
        table[f"direction_{height:g}"] = truth[vane]
        with np.errstate(divide="ignore", invalid="ignore"):
            table[f"ti_{height:g}"] = PERCENT * truth[std] / truth[speed].where(truth[speed] > 0)
    table["shear"] = shear_exponent(table)
    table["temperature"] = truth[TEMPERATURE_COLUMN]
    return table


def shear_exponent(table, low=40.0, high=80.0):
    """Power-law exponent from the speeds at two heights [1]; NaN unless both > 0."""
    v_low, v_high = table[f"speed_{low:g}"], table[f"speed_{high:g}"]
    valid = (v_low > 0) & (v_high > 0)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.log(v_high / v_low).where(valid) / np.log(high / low)


def site_difference(n, rng, settings):
    """(relative speed factor, direction turn [deg]) of the buoys' site against the mast,
    one per record, shared by the collocated buoys."""
    return (1.0 + settings["site_separation"] * rng.standard_normal(n),
            settings["direction_separation"] * rng.standard_normal(n))


def lidar_records(scenario, mast, site, rng, settings, compiled=True):
    """One floating lidar's table over the mast's records, at the site whose wind differs
    from the mast's by `site` (:func:`site_difference`); see the module docstring
    (`compiled`: the compiled model, else numpy's: the same numbers to 1e-12)."""
    n = len(mast)
    site_speed, site_turn = site
    shear = np.nan_to_num(mast["shear"].to_numpy(), nan=0.0)
    table = pd.DataFrame(index=mast.index)
    for height in MAST_COLUMNS:
        speed, direction = lidar_at_height(
            scenario, height, mast[f"speed_{height:g}"].to_numpy() * site_speed,
            mast[f"direction_{height:g}"].to_numpy() + site_turn, shear, rng,
            settings["scans_per_record"], compiled)
        table[f"speed_{height:g}"], table[f"direction_{height:g}"] = speed, direction
        table[f"ti_{height:g}"] = mast[f"ti_{height:g}"]
    lost = rng.random(n) < settings["outage"]
    table.loc[lost, :] = np.nan
    table["shear"] = shear_exponent(table)
    table["temperature"] = mast["temperature"]
    return table


def lidar_at_height(scenario, height, speed, direction, shear, rng, scans, compiled=True):
    """10-min mean speed [m s-1] and direction [deg] of a lidar gate at `height` [m] for
    records of the site's `speed`, `direction` [deg] and `shear` (arrays, shape (n,))."""
    settings = scenario.settings
    base = scene_from_settings(settings)
    scene = dataclasses.replace(
        base, wind_speed=speed, wind_direction=np.deg2rad(direction), shear=shear,
        reference_height=height, ranges=(height - settings["lidar"]["height"],))
    draws = {name: _draw(spec, (scans, len(speed)), rng, name)
             for name, spec in sorted(error_inputs(settings, scene.n_beams, 1).items())}
    out = measurement_model(scene, ("wind_speed", "wind_direction"), scene_draws=True,
                            compiled=compiled, **draws)
    return (np.mean(out["wind_speed"][..., 0], axis=0),
            circular_mean_deg(out["wind_direction"][..., 0], axis=0) % FULL_CIRCLE_DEG)


def _draw(spec, leading, rng, name):
    """Independent draws of one error input, shape leading + its own shape (INS errors
    get the beams' axis k = 1 of the ``scan`` correlation)."""
    shape = spec.shape if isinstance(spec, Input) else ()
    dist = spec.distribution if isinstance(spec, Input) else spec
    if name.startswith("ins_") and not shape:
        shape = (1,)
    if isinstance(dist, float):
        return np.full(leading + shape, dist)
    return dist.ppf(rng.random(leading + shape))


def generate_campaign(config, directory, compiled=True):
    """Write the synthetic campaign's CSV files and its data configuration
    (``campaign.yaml``) into `directory`; returns the configuration's path (`compiled`:
    the lidars' compiled model, else numpy's; the same records to 1e-12, the same draws).
    """
    settings = config.synthetic
    directory = Path(directory)
    directory.mkdir(parents=True, exist_ok=True)
    rng = np.random.default_rng(settings["seed"])
    truth = brightwind_mast()
    tables = {}
    for period in ("verification", "smc"):
        start, stop = (pd.Timestamp(str(p)) for p in settings[period])
        mast = mast_records(truth[(truth.index >= start) & (truth.index < stop)])
        site = site_difference(len(mast), rng, settings)
        if period == "verification":
            tables["mast"] = mast
            for role, name in (("golden", "flsb"), ("unit", "flsa")):
                tables[name] = lidar_records(settings["lidars"][role], mast, site, rng,
                                             settings, compiled)
        else:
            tables["smc"] = lidar_records(settings["lidars"]["unit"], mast, site, rng,
                                          settings, compiled)
    for name, table in tables.items():
        table.to_csv(directory / f"{name}.csv", index_label="timestamp", float_format="%.5g")
    path = directory / "campaign.yaml"
    path.write_text(yaml.safe_dump({"golden": _data_config(config, directory)},
                                   sort_keys=False))
    return path


def _scenario_path(settings, role, directory=None):
    """The absolute path of a synthetic lidar's scenario (its geometry predicts the TI the
    lidar reads, :mod:`uq.golden.turbulence`); a scenario changed by ``--set`` is written
    into `directory` as it was run (``<role>.yaml``) and named relative to it."""
    scenario = settings["lidars"][role]
    if role in settings.get("overridden", ()) and directory is not None:
        path = Path(directory) / f"{role}.yaml"
        path.write_text(scenario.text)
        return path.name                     # beside campaign.yaml (the folder moves)
    return str(Path(scenario.source).resolve())


def _data_config(config, directory=None):
    settings = config.synthetic
    heights = {float(h): {"speed": f"speed_{h:g}", "direction": f"direction_{h:g}",
                          "environment": {"turbulence_intensity": f"ti_{h:g}"}}
               for h in MAST_COLUMNS}
    common = {"time": "timestamp", "heights": heights,
              "environment": {"shear": "shear", "temperature": "temperature"}}
    mast = {"file": "mast.csv", **common, "calibration": settings["mast"]["calibration"],
            "class_number": 0.0}
    return {"name": config.name, "description": config.description,
            "instruments": {"mast": mast,
                            "flsb": {"file": "flsb.csv", **common,
                                     "scenario": _scenario_path(settings, "golden",
                                                                directory)},
                            "flsa": {"file": "flsa.csv", **common,
                                     "scenario": _scenario_path(settings, "unit",
                                                                directory)}},
            "comparisons": [{"unit": "flsb", "reference": "mast"},
                            {"unit": "flsa", "reference": "mast"},
                            {"unit": "flsa", "reference": "flsb"}],
            "smc": {"file": "smc.csv", **common},
            "classification": {"variables": list(config.variables),
                               "significance": config.significance,
                               "ranges": {k: list(v) for k, v in config.ranges.items()},
                               "route": config.route},
            "bins": {"width": config.bin_width, "required": list(config.required),
                     "minimum_records": config.minimum_records},
            "kpi": {"availability": list(config.availability),
                    **({"turbulence": {"variable": config.ti_variable,
                                       "bands": {k: list(v) for k, v in
                                                 config.ti_bands.items()}}}
                       if config.ti_bands else {})}}
