"""The orchestrator: scenario -> scenes of the sweep -> propagation -> Dataset.

For every scene of the sweep's outer product: build the nominal :class:`Scene`, the error
inputs, and run the measurement model through :func:`uq.propagate`; add the true values,
the error-free reconstruction and the Rubio & Gottschall (2022) model. Every scene uses
the same seed, and so the same underlying draws (common random numbers).
"""
import itertools
import time

import numpy as np
import xarray as xr

from . import __version__
from .distributions import error_distribution
from .inputs import Input
from .measurement import ANGULAR_NAVIGATION, Scene, measurement_model, true_values
from .metadata import COORDINATES, QUANTITIES, variable_attributes
from .propagate import propagate
from .rubio2022 import rubio2022_scene_uncertainty
from .sampling import new_seed
from .scenario import INS_KEYS, load_scenario
from .statistics import unwrap


def run(scenario, progress=None):
    """Run a scenario and return its results.

    Parameters
    ----------
    scenario : Scenario, dict, str or pathlib.Path
        Anything :func:`uq.load_scenario` accepts.
    progress : callable, optional
        Called as ``progress(done, total)`` after each scene.

    Returns
    -------
    xarray.Dataset
        The variables of CONTRACT.md ("Results").
    """
    started = time.perf_counter()
    scenario = load_scenario(scenario)
    sampling = scenario.sampling
    seed = sampling["seed"] if sampling["seed"] is not None else new_seed()
    keys = [key for key, _ in scenario.sweep]
    grid = list(itertools.product(*[values for _, values in scenario.sweep]))
    scenes = []
    for done, point in enumerate(grid, start=1):
        scenes.append(run_scene(scenario.with_values(dict(zip(keys, point))), seed))
        if progress:
            progress(done, len(grid))
    dataset = _combine(scenes, scenario.sweep)
    dataset.attrs.update(_global_attributes(scenario, seed, dataset, started))
    return dataset


def scene_from_settings(settings):
    """The nominal :class:`Scene` (SI, radians) of validated settings (degrees)."""
    w, s, lid = settings["wind"], settings["ship"], settings["lidar"]
    rad = np.deg2rad
    return Scene(
        wind_speed=w["speed"], wind_direction=rad(w["direction"]), vertical_wind=w["vertical"],
        shear=w["shear"], reference_height=w["reference_height"],
        sog=s["sog"], cog=rad(s["cog"]), heading=rad(s["heading"]), pitch=rad(s["pitch"]),
        roll=rad(s["roll"]), heave=s["heave"],
        lidar_height=lid["height"], ranges=tuple(lid["ranges"]), half_cone=rad(lid["half_cone"]),
        misalignment=rad(lid["misalignment"]), azimuths=tuple(rad(lid["azimuths"])),
        vertical_beam=lid["vertical_beam"], correction=settings["correction"])


def error_inputs(settings, n_beams, n_gates):
    """Engine inputs (name -> distribution, float or Input) of the declared errors."""
    inputs = {}
    beam_mode = settings["ins"]["correlation"] == "beam"
    for key in INS_KEYS:
        if key in settings["ins"]:
            dist = error_distribution(settings["ins"][key])
            inputs[f"ins_{key}"] = Input(dist, (n_beams,)) if beam_mode and not \
                isinstance(dist, float) else dist
    for key, spec in settings["lidar"]["errors"].items():
        dist = error_distribution(spec)
        shaped = key == "radial_velocity" and not isinstance(dist, float)
        inputs[f"lidar_{key}"] = Input(dist, (n_beams, n_gates)) if shaped else dist
    return inputs


def input_label(name):
    """Dotted scenario key of an engine input name (``ins_sog`` -> ``ins.sog``)."""
    section, key = name.split("_", 1)
    return f"ins.{key}" if section == "ins" else f"lidar.errors.{key}"


def run_scene(scenario, seed):
    """Results of one scene (no sweep dimensions)."""
    settings = scenario.settings
    scene = scene_from_settings(settings)
    outputs = scenario.outputs
    n_gates = len(scene.ranges)
    sampling = settings["sampling"]

    def model(**errors):
        return measurement_model(scene, outputs, **errors)

    engine = propagate(model, error_inputs(settings, scene.n_beams, n_gates),
                       n=sampling.get("n"), digits=sampling.get("digits"),
                       method=sampling["method"], seed=seed, circular=("wind_direction",),
                       output_dims={"wind_speed": ("range",), "wind_direction": ("range",),
                                    "vertical_wind": ("range",),
                                    "radial_velocity": ("beam", "range")},
                       interval=sampling["interval"], chunk_size=sampling.get("chunk_size"))
    return _scene_dataset(scene, settings, outputs, engine)


def _scene_dataset(scene, settings, outputs, engine):
    truth = true_values(scene)
    nominal = measurement_model(scene, outputs)
    paper = _paper_uncertainty(scene, settings, truth["wind_speed"])
    data = {}
    for q in outputs:
        dims = ("beam", "range") if q == "radial_velocity" else ("range",)
        data[f"{q}_true"] = (dims, truth[q])
        data[f"{q}_nominal"] = (dims, np.real(nominal[q][0]))
        data[f"{q}_paper_u"] = (dims, paper[q])
        bias = engine[f"{q}_mc_mean"].values - truth[q]
        if q == "wind_direction":
            bias = unwrap(bias, 0.0)
        data[f"{q}_mc_bias"] = (dims, bias)
    ds = engine.assign(data)
    ds = ds.assign_coords(input=[input_label(name) for name in ds["input"].values],
                          range=list(scene.ranges))
    if "beam" in ds.dims:
        azimuths = list(np.rad2deg(scene.azimuths)) + [np.nan] * int(scene.vertical_beam)
        ds = ds.assign_coords(beam=azimuths)
    ds["mc_n_samples"] = engine.attrs["n_samples"]
    return ds


def _paper_uncertainty(scene, settings, gate_speeds):
    """Rubio & Gottschall (2022) u per output; NaN outside their model."""
    ins = settings["ins"]
    u = {key: _standard_uncertainty(ins.get(key)) for key in INS_KEYS}
    u = {key: np.deg2rad(value) if key in ANGULAR_NAVIGATION else value
         for key, value in u.items()}
    per_gate = [rubio2022_scene_uncertainty(scene, speed, u["heading"], u["pitch"], u["roll"],
                                            u["sog"], u["cog"]) for speed in gate_speeds]
    return {"wind_speed": np.array([g["wind_speed"] for g in per_gate]),
            "wind_direction": np.array([g["wind_direction"] for g in per_gate]),
            "vertical_wind": np.full(len(gate_speeds), np.nan),
            "radial_velocity": np.stack([g["radial_velocity"] for g in per_gate], axis=-1)}


def _standard_uncertainty(spec):
    if spec is None:
        return 0.0
    dist = error_distribution(spec)
    return 0.0 if isinstance(dist, float) else float(dist.std())


def _combine(scenes, sweep):
    """Stack scenes along the sweep's dimensions (outer product, values in file order)."""
    combined = scenes[0]
    if sweep:
        names = [key.replace(".", "_") for key, _ in sweep]
        shape = tuple(len(values) for _, values in sweep)
        data = {var: (tuple(names) + scenes[0][var].dims,
                      np.stack([scene[var].values for scene in scenes]).reshape(
                          shape + scenes[0][var].shape))
                for var in scenes[0].data_vars}
        coords = {name: list(values) for name, (_, values) in zip(names, sweep)}
        coords.update({c: scenes[0][c] for c in scenes[0].coords})
        combined = xr.Dataset(data, coords=coords)
    if combined.sizes.get("range", 0) == 1:
        combined = combined.squeeze("range")
    return _annotate(combined, sweep)


def _annotate(ds, sweep):
    for name in ds.data_vars:
        quantity = next((q for q in QUANTITIES if name.startswith(q + "_")), None)
        if quantity:
            ds[name].attrs.update(variable_attributes(quantity, name[len(quantity) + 1:]))
    ds["mc_n_samples"].attrs.update(units="1", long_name="Monte Carlo trials used")
    for name, attrs in COORDINATES.items():
        if name in ds.coords:
            ds[name].attrs.update(attrs)
    for key, _ in sweep:
        ds[key.replace(".", "_")].attrs["long_name"] = f"swept scenario key {key}"
    return ds


def _global_attributes(scenario, seed, dataset, started):
    return {"title": f"uq results: {scenario.name}",
            "Conventions": "CF-1.10",
            "scenario": scenario.text,
            "uq_version": __version__,
            "sampling_method": scenario.sampling["method"],
            "n_samples": int(np.max(dataset["mc_n_samples"].values)),
            "seed": seed,
            "correction": scenario.settings["correction"],
            "ins_correlation": scenario.settings["ins"]["correlation"],
            "runtime_s": time.perf_counter() - started}
